//! Errors of the viewer, split by cause so that a front end can tell bad input (exit status 2: a
//! file that cannot be read, a bad setting) from a missing or failing GPU and internal failures
//! (exit status 1).

use std::path::PathBuf;

/// Why the viewer cannot do what was asked.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No GPU adapter exists (or none can render the viewer's formats).
    #[error(
        "no usable GPU adapter: {0} (for software rendering install Mesa's Vulkan driver, e.g. \
         `apt-get install mesa-vulkan-drivers libvulkan1`)"
    )]
    NoAdapter(String),
    /// The adapter exists but its device could not be opened.
    #[error("the GPU device could not be opened: {0}")]
    Device(String),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(#[from] ibl_io::IoError),
    /// A marks or room file could not be read or used (the message names the file and field).
    #[error(transparent)]
    Room(#[from] ibl_pipeline::PipelineError),
    /// A file was read but cannot be viewed (the message says why).
    #[error("{}: {problem}", path.display())]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A setting is out of range.
    #[error("{0}")]
    Parameter(String),
    /// The lights could not be made.
    #[error("lighting: {0}")]
    Lighting(String),
    /// The window could not be opened or failed (no display, a screenshot that never came).
    #[error("the viewer window: {0}")]
    Window(String),
    /// The GPU reported an error (validation, out of memory, lost device).
    #[error("the GPU reported an error: {0}")]
    Gpu(String),
}

impl ViewerError {
    /// Whether the input (a file or a setting) is at fault rather than the machine or the code.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ViewerError::Io(e) => e.is_bad_input(),
            ViewerError::Room(e) => e.is_bad_input(),
            ViewerError::Input { .. } | ViewerError::Parameter(_) | ViewerError::Lighting(_) => {
                true
            }
            ViewerError::NoAdapter(_)
            | ViewerError::Device(_)
            | ViewerError::Window(_)
            | ViewerError::Gpu(_) => false,
        }
    }
}
