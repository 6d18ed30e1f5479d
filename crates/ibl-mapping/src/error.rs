//! Why a mapping cannot be used: an image shape that does not fit it, or a parameter out of range.
//! A leaf module, shared by every mapping module.

/// Why a mapping cannot be used with an image or a parameter.
#[derive(Debug, thiserror::Error)]
pub enum MappingError {
    /// The image size does not fit the mapping.
    #[error("a {mapping} image cannot be {width} x {height}: {reason}")]
    Shape {
        /// The mapping's name.
        mapping: String,
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
        /// What the mapping needs.
        reason: String,
    },
    /// A parameter (field of view, rotation matrix, size) is out of range.
    #[error("{0}")]
    Parameter(String),
}

impl MappingError {
    /// Always true: a shape that does not fit its mapping, or a parameter out of range, is the
    /// caller's input.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}
