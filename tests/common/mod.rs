//! Helpers shared by the end-to-end tests of the `ibl` binary (each `tests/*.rs` is its own crate
//! and uses a subset, hence the `dead_code` allowance).

#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// Whether the tests run under CI (`CI` set and not `false` or `0`), where a GPU adapter must exist.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The `ibl` binary under test: the one cargo built, or `IBL_TEST_BIN` when set (to run a new
/// test against an older build and see it fail, as issue 13 asks of every fix).
pub fn ibl_binary() -> PathBuf {
    std::env::var_os("IBL_TEST_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_ibl")))
}

/// Runs the `ibl` binary under test with `args`.
pub fn ibl(args: &[&str]) -> Output {
    Command::new(ibl_binary())
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
