//! Maps errors to messages and exit codes: 2 when the input or the arguments are at fault (a
//! corrupt file, an unknown mapping, an output that would overwrite an input), 1 for everything
//! else (an internal failure, a full disk). The libraries' errors say which
//! ([`ibl_pipeline::PipelineError::is_bad_input`]); argument errors are clap's (exit 2 in
//! `main`). Every message names the file it concerns.

use std::process::ExitCode;

/// Exit status for bad input or arguments.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit status for internal failures.
pub const EXIT_INTERNAL: u8 = 1;

/// Whether the error says the input was at fault: the verdict of the outermost library error in
/// the chain (anything else, e.g. failing to print, is internal).
pub fn is_bad_input(err: &anyhow::Error) -> bool {
    err.chain()
        .find_map(|cause| {
            if let Some(e) = cause.downcast_ref::<ibl_pipeline::PipelineError>() {
                return Some(e.is_bad_input());
            }
            cause
                .downcast_ref::<ibl_io::IoError>()
                .map(ibl_io::IoError::is_bad_input)
        })
        .unwrap_or(false)
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
