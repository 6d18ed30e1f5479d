//! Irradiance maps (`ibl irradiance -o`) and engine-ready prefiltered maps (`ibl prefilter`):
//! the GGX specular chain per roughness level, the irradiance cube, and the split-sum DFG
//! table, as numpy arrays. Cube faces are `(6, S, S, 3)` in GL order `+X -X +Y -Y +Z -Z`.

use ibl_core::{Image, Rgb};
use ibl_mapping::prefilter::{DfgOptions, PrefilterOptions, SpecularOptions};
use ibl_mapping::{DfgLayout, EngineTarget};
use ibl_pipeline::Progress;
use ibl_pipeline::irradiance::IrradianceMethod;
use numpy::ndarray::{Array3, Array4};
use numpy::{IntoPyArray, PyArray3, PyArray4};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::{image_from, image_to};
use crate::errors::{bad, lib, to_py};
use crate::images::mapping;
use crate::progress::PyProgress;

/// The irradiance of a lat-long probe (H, W, 3) at every texel of a map of `mapping` and
/// `width` pixels: `method` exact (brute force), fast (64 x 32 blocks, mean error < 0.1 %) or
/// sh (`bands` bands). Releases the GIL.
#[pyfunction]
#[pyo3(signature = (probe, width=64, method="exact", mapping="latlong", bands=3))]
fn irradiance_map<'py>(
    py: Python<'py>,
    probe: &Bound<'py, PyAny>,
    width: usize,
    method: &str,
    mapping: &str,
    bands: usize,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let image = image_from(probe, "probe")?;
    let method = IrradianceMethod::from_name(method)
        .ok_or_else(|| bad(format!("unknown method `{method}` (exact, fast, sh)")))?;
    let to = self::mapping(mapping)?;
    let map = py.detach(|| {
        ibl_pipeline::irradiance::irradiance_map_of(
            &image,
            method,
            bands,
            ibl_sh::Window::None,
            to,
            width,
        )
    });
    Ok(image_to(py, &map.map_err(to_py)?))
}

fn faces_to<'py>(py: Python<'py>, faces: &[Image<Rgb>; 6]) -> Bound<'py, PyArray4<f32>> {
    let s = faces[0].width();
    let mut data = Vec::with_capacity(6 * s * s * 3);
    for f in faces {
        for y in 0..f.height() {
            for p in f.row(y) {
                data.extend_from_slice(&p.to_array());
            }
        }
    }
    Array4::from_shape_vec((6, s, s, 3), data)
        .unwrap_or_else(|_| Array4::zeros((6, s, s, 3)))
        .into_pyarray(py)
}

/// The prefiltered maps of a lat-long probe (H, W, 3), as `ibl prefilter` makes them: a dict
/// with `roughness` (per level, in `target`'s convention: filament, khronos, unreal, unity,
/// babylon) and `specular` (a list of (6, S, S, 3) cubes, level 0 of `face_size` first, GGX with
/// `samples` samples per texel); `latlong` (lat-long levels) when `latlong_width` is given;
/// `irradiance` (a (6, S, S, 3) cube of E / pi) when `irradiance_face` is given. Releases the
/// GIL.
#[pyfunction]
#[pyo3(signature = (probe, face_size=64, samples=64, target="filament", latlong_width=None, irradiance_face=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn prefilter<'py>(
    py: Python<'py>,
    probe: &Bound<'py, PyAny>,
    face_size: usize,
    samples: usize,
    target: &str,
    latlong_width: Option<usize>,
    irradiance_face: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let image = image_from(probe, "probe")?;
    let target = EngineTarget::from_name(target).ok_or_else(|| {
        let names: Vec<&str> = EngineTarget::ALL.iter().map(|t| t.name()).collect();
        bad(format!("unknown target `{target}` ({})", names.join(", ")))
    })?;
    let options = PrefilterOptions {
        specular: Some(SpecularOptions {
            face_size,
            target,
            samples,
            latlong_width,
        }),
        irradiance_face,
        dfg: None,
    };
    let reporter = PyProgress::new(progress);
    let made = py.detach(|| {
        reporter.begin("prefiltering", 0);
        let made = ibl_mapping::prefilter::prefilter(
            &image,
            ibl_mapping::Mapping::LatLong,
            &options,
            &ibl_pipeline::progress::rows(&reporter),
        );
        reporter.end();
        made
    });
    reporter.finish()?;
    let made = made.map_err(lib)?;
    let d = PyDict::new(py);
    if let Some(chain) = &made.specular {
        d.set_item("roughness", chain.roughness.clone())?;
        let cubes = PyList::empty(py);
        for level in &chain.cube {
            cubes.append(faces_to(py, level))?;
        }
        d.set_item("specular", cubes)?;
        if !chain.latlong.is_empty() {
            let maps = PyList::empty(py);
            for level in &chain.latlong {
                maps.append(image_to(py, level))?;
            }
            d.set_item("latlong", maps)?;
        }
    }
    if let Some(faces) = &made.irradiance {
        d.set_item("irradiance", faces_to(py, faces))?;
    }
    Ok(d)
}

/// The split-sum DFG table (Karis 2013), (size, size, 2): row 0 at roughness near 0, column 0
/// at `n.v` near 0; `layout` scale-bias (`A`, `B`) or multi-scatter (`B`, `A + B`).
#[pyfunction]
#[pyo3(signature = (size=128, samples=1024, layout="scale-bias"))]
fn dfg_table<'py>(
    py: Python<'py>,
    size: usize,
    samples: usize,
    layout: &str,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let layout = DfgLayout::from_name(layout).ok_or_else(|| {
        bad(format!(
            "unknown DFG layout `{layout}` (scale-bias, multiscatter)"
        ))
    })?;
    let options = PrefilterOptions {
        dfg: Some(DfgOptions {
            size,
            samples,
            layout,
        }),
        ..PrefilterOptions::default()
    };
    let probe = Image::filled(2, 1, Rgb::ZERO);
    let made = py
        .detach(|| {
            ibl_mapping::prefilter::prefilter(
                &probe,
                ibl_mapping::Mapping::LatLong,
                &options,
                &|_, _| {},
            )
        })
        .map_err(lib)?;
    let dfg = made.dfg.ok_or_else(|| bad("no DFG table made"))?;
    let data: Vec<f32> = dfg.texels.iter().flatten().copied().collect();
    Ok(Array3::from_shape_vec((dfg.size, dfg.size, 2), data)
        .unwrap_or_else(|_| Array3::zeros((dfg.size, dfg.size, 2)))
        .into_pyarray(py))
}

/// Adds this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(irradiance_map, m)?)?;
    m.add_function(wrap_pyfunction!(prefilter, m)?)?;
    m.add_function(wrap_pyfunction!(dfg_table, m)?)?;
    Ok(())
}
