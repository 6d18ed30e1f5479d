//! Renders of a scene file (`ibl render`): the CPU renderer's reference, lights and hybrid
//! modes, composited into the probe panorama or the background photo by differential rendering.

use std::path::PathBuf;

use ibl_pipeline::render::RenderJob;
use ibl_scene::RenderMode;
use numpy::PyArray3;
use pyo3::prelude::*;

use crate::arrays::image_to;
use crate::errors::{bad, lib, to_py};
use crate::images::json_to_py;
use crate::progress::PyProgress;

/// Renders `scene` (TOML, docs/SCENES.md) to `output` (.exr, .hdr, .pfm, .png) as `ibl render`
/// does, with the scene's settings unless given: `mode` (reference, lights, hybrid), `lights`
/// (how many to extract), `method`, `spp`, `width`, `seed`. Returns the composite as an array
/// and the render's summary. Releases the GIL.
#[pyfunction]
#[pyo3(signature = (scene, output, mode=None, lights=None, method=None, spp=None, width=None, seed=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn render_scene<'py>(
    py: Python<'py>,
    scene: PathBuf,
    output: PathBuf,
    mode: Option<&str>,
    lights: Option<usize>,
    method: Option<&str>,
    spp: Option<u32>,
    width: Option<u32>,
    seed: Option<u64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyAny>)> {
    let mode = mode
        .map(|m| {
            RenderMode::from_name(m)
                .ok_or_else(|| bad(format!("unknown mode `{m}` (reference, lights, hybrid)")))
        })
        .transpose()?;
    let job = RenderJob {
        scene,
        output: output.clone(),
        mode,
        method: method
            .map(str::parse)
            .transpose()
            .map_err(|e: ibl_light::MethodError| bad(e.to_string()))?,
        lights,
        spp,
        width,
        seed,
        ..RenderJob::default()
    };
    let reporter = PyProgress::new(progress);
    let summary = py.detach(|| ibl_pipeline::render::render_scene(&job, &reporter));
    reporter.finish()?;
    let summary = summary.map_err(to_py)?;
    let image = py.detach(|| ibl_io::read_image(&output)).map_err(lib)?;
    Ok((image_to(py, &image.image), json_to_py(py, &summary)?))
}

/// Adds this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(render_scene, m)?)?;
    Ok(())
}
