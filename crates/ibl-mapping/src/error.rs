//! Why a mapping cannot be used: an image shape that does not fit it, or a parameter out of range.
//! A leaf module, shared by every mapping module.

/// Why a mapping cannot be used with an image or a parameter.
#[derive(Debug, thiserror::Error)]
pub enum MappingError {
    /// The image size does not fit the mapping.
    #[error(
        "{} image cannot be {width} x {height}: {reason}",
        with_article(mapping)
    )]
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

/// A mapping's name with its indefinite article, for messages: `a latlong`, `an angular`
/// (issue 13: "not a angular image").
pub fn with_article(name: &str) -> String {
    let article = if name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {name}")
}

impl MappingError {
    /// Always true: a shape that does not fit its mapping, or a parameter out of range, is the
    /// caller's input.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_errors_take_the_right_article() {
        let e = |mapping: &str| MappingError::Shape {
            mapping: mapping.to_string(),
            width: 3,
            height: 2,
            reason: "r".to_string(),
        };
        assert_eq!(
            e("angular").to_string(),
            "an angular image cannot be 3 x 2: r"
        );
        assert_eq!(
            e("latlong").to_string(),
            "a latlong image cannot be 3 x 2: r"
        );
        assert_eq!(with_article("equirect"), "an equirect");
    }
}
