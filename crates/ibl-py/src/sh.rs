//! Spherical harmonics (`ibl sh`): projection of a lat-long probe, Lambert convolution, and
//! conversion to and from every tool's convention (three.js, Filament, Unity, WebXR, ARKit,
//! glTF's extension) through the same formatter and parser as the command line's files.
//!
//! Coefficients are `(bands^2, 3)` float64 arrays of radiance in iblkit's convention (real
//! orthonormal SH without the Condon-Shortley phase, index `l*l + l + m`, world frame;
//! docs/CONVENTIONS.md section 5b).

use ibl_io::ShFileFormat;
use ibl_io::sh_file::{SH_CONVENTION, SH_FORMAT, ShFile, ShQuantity, format_sh, parse_sh};
use ibl_sh::{RadianceSh, Window};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::arrays::{directions_from, image_from, rows_to};
use crate::errors::{bad, lib};

fn format(name: &str) -> PyResult<ShFileFormat> {
    ShFileFormat::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = ShFileFormat::ALL.iter().map(|f| f.name()).collect();
        bad(format!("unknown SH format `{name}` ({})", names.join(", ")))
    })
}

fn window(name: &str) -> PyResult<Window> {
    name.parse().map_err(bad)
}

/// `(bands^2, 3)` coefficients from Python as a radiance expansion.
fn radiance_from(coefficients: PyReadonlyArray2<'_, f64>) -> PyResult<RadianceSh> {
    let view = coefficients.as_array();
    let n = view.nrows();
    let bands = (n as f64).sqrt().round() as usize;
    if view.ncols() != 3 || bands * bands != n || n == 0 {
        return Err(bad(format!(
            "coefficients: expected shape (bands^2, 3), got {:?}",
            view.shape()
        )));
    }
    let rows: Vec<[f64; 3]> = view
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect();
    if rows.iter().flatten().any(|v| !v.is_finite()) {
        return Err(bad("coefficients: NaN or infinite values"));
    }
    RadianceSh::new(bands, rows).map_err(lib)
}

/// Projects a lat-long probe (H, W, 3) on `bands` bands (3 = SH9): radiance coefficients,
/// (bands^2, 3). With `irradiance=True`, the Lambert-convolved coefficients `A_l c_lm` (and the
/// window's weights) instead. Releases the GIL.
#[pyfunction]
#[pyo3(signature = (probe, bands=3, window="none", irradiance=false))]
fn sh_project<'py>(
    py: Python<'py>,
    probe: &Bound<'py, PyAny>,
    bands: usize,
    window: &str,
    irradiance: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let image = image_from(probe, "probe")?;
    let w = self::window(window)?;
    if bands == 0 || bands > ibl_sh::MAX_BANDS {
        return Err(bad(format!(
            "bands must be between 1 and {}",
            ibl_sh::MAX_BANDS
        )));
    }
    let sh = py
        .detach(|| ibl_sh::project_latlong(&image, bands))
        .map_err(lib)?;
    let rows = if irradiance {
        sh.irradiance(w).coefficients().to_vec()
    } else {
        ibl_pipeline::sh::windowed(&sh, w)
    };
    Ok(rows_to(py, &rows))
}

/// Radiance coefficients (bands^2, 3) as the text of an SH file in `format` (json, threejs,
/// filament, unity, webxr, arkit, gltf-ext); every format but json holds exactly 3 bands.
#[pyfunction]
fn sh_to_format(coefficients: PyReadonlyArray2<'_, f64>, format: &str) -> PyResult<String> {
    let sh = radiance_from(coefficients)?;
    let format = self::format(format)?;
    let file = ShFile {
        format: SH_FORMAT.to_string(),
        convention: SH_CONVENTION.to_string(),
        frame: "gltf".to_string(),
        quantity: ShQuantity::Radiance,
        bands: sh.bands(),
        window: Window::None.name().to_string(),
        probe: None,
        coefficients: sh.coefficients().to_vec(),
    };
    format_sh(format, &file).map_err(|e| bad(format!("format {}: {e}", format.name())))
}

/// The text of an SH file in `format` as iblkit's radiance coefficients (bands^2, 3).
#[pyfunction]
fn sh_from_format<'py>(
    py: Python<'py>,
    text: &str,
    format: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let format = self::format(format)?;
    let file = parse_sh(format, text).map_err(|e| bad(format!("{}: {e}", format.name())))?;
    Ok(rows_to(py, &file.coefficients))
}

/// Irradiance on surfaces of these normals (M, 3) from radiance coefficients, through the
/// Lambert convolution (and `window`): (M, 3).
#[pyfunction]
#[pyo3(signature = (coefficients, normals, window="none"))]
fn sh_irradiance<'py>(
    py: Python<'py>,
    coefficients: PyReadonlyArray2<'py, f64>,
    normals: &Bound<'py, PyAny>,
    window: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let sh = radiance_from(coefficients)?.irradiance(self::window(window)?);
    let normals = directions_from(normals, "normals")?;
    Ok(rows_to(py, &py.detach(|| sh.eval_many(&normals))))
}

/// Adds this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sh_project, m)?)?;
    m.add_function(wrap_pyfunction!(sh_to_format, m)?)?;
    m.add_function(wrap_pyfunction!(sh_from_format, m)?)?;
    m.add_function(wrap_pyfunction!(sh_irradiance, m)?)?;
    Ok(())
}
