//! Maps errors to messages and exit codes: 2 when the input or the arguments are at fault (a
//! corrupt file, an unknown mapping, an output that would overwrite an input), 1 for everything
//! else (an internal failure, a full disk). Every message names the file it concerns.

use std::process::ExitCode;

/// Exit status for bad input or arguments.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit status for internal failures.
pub const EXIT_INTERNAL: u8 = 1;

/// A problem with the command line itself (a value the parser accepted but that makes no sense).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Shorthand for returning a [`UsageError`].
pub fn usage(msg: impl Into<String>) -> anyhow::Error {
    UsageError(msg.into()).into()
}

/// Whether any error in the chain says the input was at fault.
pub fn is_bad_input(err: &anyhow::Error) -> bool {
    err.chain().any(|cause| {
        if let Some(e) = cause.downcast_ref::<ibl_io::IoError>() {
            return e.is_bad_input();
        }
        if let Some(e) = cause.downcast_ref::<ibl_viewer::ViewerError>() {
            return e.is_bad_input();
        }
        cause.is::<UsageError>() || cause.is::<ibl_mapping::MappingError>()
    })
}

/// The error and its causes joined by `: `, leaving out a cause whose text the message already
/// holds (errors that name a file print their operating-system cause in their own text).
pub fn message(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let c = cause.to_string();
        if text.is_empty() {
            text = c;
        } else if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

/// Prints `ibl: <error>: <cause>...` to stderr and returns the exit code for it.
pub fn report(err: &anyhow::Error) -> ExitCode {
    eprintln!("ibl: {}", message(err));
    ExitCode::from(if is_bad_input(err) {
        EXIT_BAD_INPUT
    } else {
        EXIT_INTERNAL
    })
}
