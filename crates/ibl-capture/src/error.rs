//! Errors of the capture pipeline, split by cause so the CLI can tell bad input (exit 2) from an
//! internal failure (exit 1).

/// Why a capture step failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CaptureError {
    /// The photographs cannot make a probe: sizes differ, exposure times missing or not positive,
    /// every pixel saturated or black, no ball found, ... (the user's input is at fault).
    #[error("{0}")]
    Invalid(String),
    /// A parameter is out of range (field of view, smoothness, circle, ...).
    #[error("{0}")]
    Parameter(String),
    /// A numerical step failed (a singular system, a fit that did not converge).
    #[error("{0}")]
    Numerical(String),
}

impl CaptureError {
    /// Whether the input or the parameters are at fault (exit status 2), not the program.
    pub fn is_bad_input(&self) -> bool {
        matches!(self, CaptureError::Invalid(_) | CaptureError::Parameter(_))
    }
}
