//! Helpers shared by the end-to-end tests of the `ibl` binary (each `tests/*.rs` is its own crate
//! and uses a subset, hence the `dead_code` allowance).

#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the built `ibl` binary with `args`.
pub fn ibl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ibl"))
        .args(args)
        .output()
        .expect("run ibl")
}

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Path of a bundled probe (`assets/probes/<name>`), as a string argument.
pub fn probe(name: &str) -> String {
    repo()
        .join("assets/probes")
        .join(name)
        .display()
        .to_string()
}

/// The process's stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
