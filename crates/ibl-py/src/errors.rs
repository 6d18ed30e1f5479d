//! Typed exceptions: the caller's fault or ours, as the command line's exit statuses 2 and 1
//! (`PipelineError::is_bad_input` decides, never the message).

use ibl_pipeline::PipelineError;
use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::PyException;

create_exception!(
    _native,
    IblError,
    PyException,
    "Base class of every iblkit error."
);
create_exception!(
    _native,
    BadInputError,
    IblError,
    "The input is at fault: a missing, corrupt or unsupported file, a bad argument, an output \
     that would overwrite an input (the `ibl` command's exit status 2)."
);
create_exception!(
    _native,
    InternalError,
    IblError,
    "iblkit failed on good input: a bug, or the machine (a full disk) (exit status 1)."
);

/// A pipeline error as the exception of its cause.
pub fn to_py(e: PipelineError) -> PyErr {
    if e.is_bad_input() {
        BadInputError::new_err(e.to_string())
    } else {
        InternalError::new_err(e.to_string())
    }
}

/// Any library error, through the pipeline's error (which knows every library's causes).
pub fn lib<E: Into<PipelineError>>(e: E) -> PyErr {
    to_py(e.into())
}

/// A bad argument.
pub fn bad(message: impl Into<String>) -> PyErr {
    BadInputError::new_err(message.into())
}
