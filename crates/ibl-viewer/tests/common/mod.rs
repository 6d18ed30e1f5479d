//! Shared by the viewer's GPU tests: the device, or a clear skip.

#![allow(dead_code)]

use std::path::PathBuf;

use ibl_viewer::GpuContext;

/// Whether this is a CI run (`CI` set, and not to `false` or `0`).
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The GPU, or `None` (with a message) when no adapter exists outside CI. Under CI a missing
/// adapter fails the test: a skipped GPU suite in CI would hide a broken install.
pub fn gpu_or_skip(test: &str) -> Option<GpuContext> {
    match GpuContext::headless() {
        Ok(gpu) => Some(gpu),
        Err(e) => {
            assert!(
                !in_ci(),
                "{test}: no GPU adapter under CI ({e}); .ci/run must install mesa-vulkan-drivers \
                 and libvulkan1 so that the GPU tests run"
            );
            eprintln!("{test}: SKIPPED, no GPU adapter ({e})");
            None
        }
    }
}

/// The repository's `assets/` folder.
pub fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

/// A folder under `target/` for images a failing test leaves to look at.
pub fn failure_dir(test: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../target/viewer-test-failures")
        .join(test);
    let _ = std::fs::create_dir_all(&dir);
    dir
}
