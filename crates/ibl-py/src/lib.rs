//! `iblkit._native`: the Python bindings of iblkit (issue 19), a thin layer over the same
//! libraries and `ibl-pipeline` jobs the `ibl` command line tool calls, so a Python call and the
//! command of the same name give the same numbers.
//!
//! - Images are numpy `float32` arrays of shape `(H, W, 3)`, linear radiance, row 0 at the top
//!   (`arrays`). Any array-like is accepted and converted (a copy); results are new arrays.
//! - Directions are in iblkit's world frame (docs/CONVENTIONS.md: +Y up, -Z forward, +X right).
//! - Errors are `errors::BadInputError` (a `ValueError`: the caller's file or argument) or
//!   `errors::InternalError` (a `RuntimeError`: ours), with the same messages as `ibl`.
//! - Long calls release the GIL (`Python::detach`) and report progress through an optional
//!   Python callable `progress(label, done, total)` (`progress`).
//!
//! Modules: `images` (read, write, convert, probes, info), `lights` (extraction, light sets
//! and their files), `sh` (projection and every tool's convention), `evaluation` (ground
//! truth and error metrics), `maps` (irradiance and prefiltered maps), `scene` (renders),
//! `batch` (the batch job's three steps, for `iblkit.batch`).

mod arrays;
mod batch;
mod errors;
mod evaluation;
mod images;
mod lights;
mod maps;
mod progress;
mod scene;
mod sh;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("IblError", py.get_type::<errors::IblError>())?;
    m.add("BadInputError", py.get_type::<errors::BadInputError>())?;
    m.add("InternalError", py.get_type::<errors::InternalError>())?;
    images::register(m)?;
    lights::register(m)?;
    sh::register(m)?;
    evaluation::register(m)?;
    maps::register(m)?;
    scene::register(m)?;
    batch::register(m)?;
    Ok(())
}
