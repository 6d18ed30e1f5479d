//! Output paths checked before any work (issue 13, item 5): a job that would fail at its last
//! step, after minutes of extraction, because the output folder is missing or read-only, must
//! refuse at once, naming the path the user gave (never the hidden temporary file the atomic
//! write uses), and say it is the input's fault (exit status 2).
//!
//! The folder is probed by creating and removing an empty file in it: permission bits do not
//! tell (root writes through them, a read-only mount or `/proc` refuses root too), an attempt
//! does. The probe file is a temporary file like any other (`ibl_io::temp_files`):
//! `.iblkit-tmp-<pid>-check`, listed while it exists, so an interrupt during the check removes
//! it too.

use std::fs::OpenOptions;
use std::path::Path;

use crate::error::{PipelineError, Result};

/// Checks that `output` can be written: not one of `inputs`, not a folder, and its folder exists,
/// is a folder and takes new files. Cost: two file-system calls and one create/remove.
pub fn check_output_path(output: &Path, inputs: &[&Path]) -> Result<()> {
    ibl_io::ensure_output_is_not_input(output, inputs)?;
    let shown = output.display();
    if output.is_dir() {
        return Err(PipelineError::parameter(format!(
            "{shown}: is a folder; name a file to write"
        )));
    }
    let folder = match output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.exists() {
        return Err(PipelineError::parameter(format!(
            "{shown}: the folder {} does not exist (create it first)",
            folder.display()
        )));
    }
    if !folder.is_dir() {
        return Err(PipelineError::parameter(format!(
            "{shown}: {} is not a folder",
            folder.display()
        )));
    }
    check_folder_takes_files(folder)
        .map_err(|e| PipelineError::parameter(format!("{shown}: cannot write there: {e}")))
}

/// Refuses an output image of `width x height` pixels (`what` names it, e.g. `--width 30000`)
/// that the readers would refuse: over [`ibl_io::Limits::default`]'s width, height or pixel count
/// (2^28 pixels unless `--max-pixels` or `IBL_MAX_PIXELS` set another). Called before any work,
/// so a mistyped width fails at once instead of after minutes and gigabytes.
pub fn check_output_pixels(what: &str, width: usize, height: usize) -> Result<()> {
    let limits = ibl_io::Limits::default();
    let pixels = width.checked_mul(height);
    let fits = width <= limits.max_width
        && height <= limits.max_height
        && pixels.is_some_and(|p| p <= limits.max_pixels);
    if fits {
        return Ok(());
    }
    Err(PipelineError::parameter(format!(
        "{what}: the output would be {width} x {height} pixels, over the limit of {} pixels \
         ({} x {} at most; --max-pixels or IBL_MAX_PIXELS sets the pixel limit)",
        limits.max_pixels, limits.max_width, limits.max_height
    )))
}

/// Checks that `folder` (an existing folder) takes a new file, by creating and removing one.
pub fn check_folder_takes_files(folder: &Path) -> std::io::Result<()> {
    let probe = folder.join(format!("{}check", ibl_io::temp_files::temp_prefix()));
    let _listed = ibl_io::temp_files::TempRegistration::new(&probe);
    OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)?;
    std::fs::remove_file(&probe)
}

/// Checks an output folder before any work: it exists and takes files, or does not exist yet and
/// its nearest existing ancestor takes files (it will be created).
pub fn check_output_folder(folder: &Path) -> Result<()> {
    let shown = folder.display();
    let mut existing = folder;
    while !existing.exists() && existing != Path::new(".") {
        existing = match existing.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
    }
    if !existing.is_dir() {
        return Err(PipelineError::parameter(format!(
            "{shown}: {} is not a folder",
            existing.display()
        )));
    }
    check_folder_takes_files(existing)
        .map_err(|e| PipelineError::parameter(format!("{shown}: cannot write there: {e}")))
}
