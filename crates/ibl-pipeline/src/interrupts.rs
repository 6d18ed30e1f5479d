//! How a command-line process ends when it is interrupted or its reader goes away; the `ibl`
//! binary calls [`install`] first thing (a library used from Python leaves signals to Python).
//!
//! - **SIGINT, SIGTERM, SIGHUP**: the temporary files of writes in progress are removed
//!   (`ibl_io::temp_files`), then the signal's default action ends the process (so the shell
//!   sees 130 for Ctrl-C, 143 for SIGTERM). Before, an interrupted write left a hidden
//!   `.iblkit-XXXX.tmp` of up to 400 MB in the output folder.
//! - **A closed standard output** (`ibl compare --json | head -1`): Rust ignores SIGPIPE, so
//!   printing to a pipe whose reader has exited fails, and `println!` panics with a backtrace.
//!   The panic hook recognises that failure and ends the process quietly with status 141, what a
//!   process killed by SIGPIPE reports, as other command-line tools do.

/// Installs the handlers; call once, first thing in a binary's `main`.
pub fn install() {
    #[cfg(unix)]
    remove_temporary_files_on_signals();
    end_quietly_on_closed_stdout();
}

#[cfg(unix)]
fn remove_temporary_files_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    // Without the handler an interrupt still ends the process; only the clean-up is lost.
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            ibl_io::temp_files::remove_live_temp_files();
            // Resets the handler and raises the signal again: the default action ends us.
            let _ = signal_hook::low_level::emulate_default_handler(signal);
            std::process::exit(128 + signal);
        }
    });
}

/// Status of a process ended by SIGPIPE (128 + 13).
const EXIT_BROKEN_PIPE: i32 = 141;

fn end_quietly_on_closed_stdout() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        // std's message for a failed `print!`; EPIPE is error 32 on Linux and macOS.
        if message.starts_with("failed printing to stdout") && message.contains("os error 32") {
            ibl_io::temp_files::remove_live_temp_files();
            std::process::exit(EXIT_BROKEN_PIPE);
        }
        default(info);
    }));
}
