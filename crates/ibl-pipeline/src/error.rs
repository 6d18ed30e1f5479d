//! Why a job failed, by cause: each library's own error as it is, a parameter out of range, or
//! one of those with what the job was doing (`context`). [`PipelineError::is_bad_input`] asks the
//! cause, so a front end maps errors to "your input" (exit status 2) or "our failure" (1)
//! without looking at messages.

use ibl_capture::CaptureError;
use ibl_eval::sweep::SweepError;
use ibl_eval::{PlotError, StudyError};
use ibl_extract::ExtractError;
use ibl_io::IoError;
use ibl_mapping::MappingError;
use ibl_metrics::DifferenceError;
use ibl_outdoor::OutdoorError;
use ibl_render::RenderError;
use ibl_room::RoomError;
use ibl_scene::DescriptionError;
use ibl_sh::ShError;

/// Why a job failed.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A mapping that does not fit an image, or its parameters.
    #[error(transparent)]
    Mapping(#[from] MappingError),
    /// Light extraction.
    #[error(transparent)]
    Extract(#[from] ExtractError),
    /// Spherical harmonics.
    #[error(transparent)]
    Sh(#[from] ShError),
    /// A render.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A render study.
    #[error(transparent)]
    Study(#[from] StudyError),
    /// The comparison sweep.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// Drawing a chart or figure (always internal).
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// HDR capture.
    #[error(transparent)]
    Capture(#[from] CaptureError),
    /// Comparing two images.
    #[error(transparent)]
    Difference(#[from] DifferenceError),
    /// A scene description.
    #[error(transparent)]
    Description(#[from] DescriptionError),
    /// A room, marks file or room estimate (Grosch 2005).
    #[error(transparent)]
    Room(#[from] RoomError),
    /// The outdoor pipeline (Jensen, Andersen & Madsen 2006).
    #[error(transparent)]
    Outdoor(#[from] OutdoorError),
    /// An option the caller gave is out of range or contradicts another (the message says which
    /// and why): always the input's fault.
    #[error("{0}")]
    Parameter(String),
    /// Any of the above, with what the job was doing or which file it concerns.
    #[error("{context}: {source}")]
    Context {
        /// What was being done, e.g. `--response recover` or a file name.
        context: String,
        /// The cause.
        source: Box<PipelineError>,
    },
}

impl PipelineError {
    /// Whether the caller's input (files, options) is at fault rather than iblkit.
    pub fn is_bad_input(&self) -> bool {
        match self {
            PipelineError::Io(e) => e.is_bad_input(),
            PipelineError::Mapping(e) => e.is_bad_input(),
            PipelineError::Extract(e) => e.is_bad_input(),
            PipelineError::Sh(e) => e.is_bad_input(),
            PipelineError::Render(e) => e.is_bad_input(),
            PipelineError::Study(e) => e.is_bad_input(),
            PipelineError::Sweep(e) => e.is_bad_input(),
            PipelineError::Plot(e) => e.is_bad_input(),
            PipelineError::Capture(e) => e.is_bad_input(),
            PipelineError::Difference(e) => e.is_bad_input(),
            PipelineError::Description(e) => e.is_bad_input(),
            PipelineError::Room(e) => e.is_bad_input(),
            PipelineError::Outdoor(e) => e.is_bad_input(),
            PipelineError::Parameter(_) => true,
            PipelineError::Context { source, .. } => source.is_bad_input(),
        }
    }

    /// A [`PipelineError::Parameter`].
    pub fn parameter(message: impl Into<String>) -> PipelineError {
        PipelineError::Parameter(message.into())
    }

    /// This error with what the job was doing.
    pub fn context(self, context: impl Into<String>) -> PipelineError {
        PipelineError::Context {
            context: context.into(),
            source: Box::new(self),
        }
    }
}

/// `Result` with a [`PipelineError`].
pub type Result<T> = std::result::Result<T, PipelineError>;

/// Adds context to any error that converts into a [`PipelineError`].
pub trait Context<T> {
    /// The error with `context` (a file name, an option) in front of it.
    fn context(self, context: impl Into<String>) -> Result<T>;
}

impl<T, E: Into<PipelineError>> Context<T> for std::result::Result<T, E> {
    fn context(self, context: impl Into<String>) -> Result<T> {
        self.map_err(|e| e.into().context(context))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cause_decides_and_context_keeps_it() {
        let bad = PipelineError::parameter("--n 0");
        assert!(bad.is_bad_input());
        let internal: PipelineError = PlotError("no font".into()).into();
        assert!(!internal.is_bad_input());
        let wrapped = internal.context("plots/average.svg");
        assert!(!wrapped.is_bad_input());
        assert_eq!(wrapped.to_string(), "plots/average.svg: no font");
    }
}
