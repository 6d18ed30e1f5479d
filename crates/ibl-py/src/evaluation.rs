//! Exact ground truth and the error metrics (`ibl eval`, `ibl compare`): irradiance by brute
//! force over every texel, the four irradiance-error metrics of Madsen & Laursen 2006 section 5
//! (docs/CONVENTIONS.md section 5), and RMSE, relative MSE and HDR-FLIP between images.

use ibl_core::fibonacci_normals as fibonacci;
use ibl_metrics::{FlipOptions, ImageDifference, IrradianceError};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{directions_from, image_from, rows_to};
use crate::errors::{bad, lib};
use crate::lights::PyLightSet;

/// Largest number of normals accepted.
const MAX_NORMALS: usize = 10_000_000;

/// `m` Fibonacci-sphere unit normals (the scoring normals of `ibl eval`), (m, 3).
#[pyfunction]
fn fibonacci_normals(py: Python<'_>, m: usize) -> PyResult<Bound<'_, PyArray2<f64>>> {
    if m == 0 || m > MAX_NORMALS {
        return Err(bad(format!("m must be between 1 and {MAX_NORMALS}")));
    }
    let rows: Vec<[f64; 3]> = fibonacci(m).iter().map(|n| n.to_array()).collect();
    Ok(rows_to(py, &rows))
}

/// The exact irradiance of a lat-long probe (H, W, 3) on surfaces of these normals (M, 3), by
/// summing every texel `L cos(theta) dOmega` (the ground truth of `ibl eval`): (M, 3). Releases
/// the GIL.
#[pyfunction]
fn ground_truth_irradiance<'py>(
    py: Python<'py>,
    probe: &Bound<'py, PyAny>,
    normals: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let image = image_from(probe, "probe")?;
    let normals = directions_from(normals, "normals")?;
    let e = py.detach(|| ibl_core::irradiance_exact(&image, &normals));
    Ok(rows_to(py, &e))
}

fn rows(a: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    let view = a.as_array();
    if view.ncols() != 3 {
        return Err(bad(format!(
            "{what}: expected shape (M, 3), got {:?}",
            view.shape()
        )));
    }
    Ok(view
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect())
}

fn error_dict<'py>(py: Python<'py>, e: &IrradianceError) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("mean_err_pct", e.mean_err_pct)?;
    d.set_item("max_err_pct", e.max_err_pct)?;
    d.set_item("rel_mean_err_pct", e.rel_mean_err_pct)?;
    d.set_item("rel_max_err_pct", e.rel_max_err_pct)?;
    Ok(d)
}

/// The four irradiance-error metrics, per cent, of `approx` against `truth` (both (M, 3), same
/// normals): mean_err_pct, max_err_pct (of the mean irradiance), rel_mean_err_pct and
/// rel_max_err_pct (of each value).
#[pyfunction]
fn irradiance_error<'py>(
    py: Python<'py>,
    truth: PyReadonlyArray2<'py, f64>,
    approx: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, a) = (rows(&truth, "truth")?, rows(&approx, "approx")?);
    if t.len() != a.len() || t.is_empty() {
        return Err(bad(format!(
            "truth has {} rows and approx {}: give the same normals",
            t.len(),
            a.len()
        )));
    }
    error_dict(py, &IrradianceError::between(&t, &a))
}

/// A light set scored against the probe it approximates, as `ibl eval` scores it: the exact
/// irradiance and the lights' on `normals` Fibonacci normals, and the four metrics. Releases
/// the GIL.
#[pyfunction]
#[pyo3(signature = (probe, lights, normals=2000))]
fn evaluate_lights<'py>(
    py: Python<'py>,
    probe: &Bound<'py, PyAny>,
    lights: &PyLightSet,
    normals: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if normals == 0 || normals > MAX_NORMALS {
        return Err(bad(format!("normals must be between 1 and {MAX_NORMALS}")));
    }
    let image = image_from(probe, "probe")?;
    let error = py.detach(|| {
        let n = fibonacci(normals);
        let truth = ibl_core::irradiance_exact(&image, &n);
        let approx: Vec<[f64; 3]> = n.iter().map(|d| lights.set.irradiance_at(*d)).collect();
        IrradianceError::between(&truth, &approx)
    });
    let d = error_dict(py, &error)?;
    d.set_item("normals", normals)?;
    d.set_item("lights", lights.set.lights.len())?;
    Ok(d)
}

/// `ibl compare`: RMSE, relative MSE (epsilon 0.01), mean and largest absolute error, PSNR and
/// the mean HDR-FLIP of `test` against `reference` (both (H, W, 3), same size).
#[pyfunction]
fn compare_images<'py>(
    py: Python<'py>,
    test: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, r) = (
        image_from(test, "test")?,
        image_from(reference, "reference")?,
    );
    let (diff, flip) = py.detach(|| {
        let diff = ImageDifference::between(&t, &r, None);
        let flip = ibl_metrics::flip(&t, &r, &FlipOptions::default());
        (diff, flip)
    });
    let (diff, flip) = (diff.map_err(lib)?, flip.map_err(lib)?);
    let d = PyDict::new(py);
    d.set_item("pixels", diff.pixels)?;
    d.set_item("rmse", diff.rmse)?;
    d.set_item("relative_mse", diff.relative_mse)?;
    d.set_item("mean_abs", diff.mean_abs)?;
    d.set_item("max_abs", diff.max_abs)?;
    d.set_item("psnr_db", diff.psnr_db)?;
    d.set_item("flip_mean", flip.mean())?;
    Ok(d)
}

/// Adds this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fibonacci_normals, m)?)?;
    m.add_function(wrap_pyfunction!(ground_truth_irradiance, m)?)?;
    m.add_function(wrap_pyfunction!(irradiance_error, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_lights, m)?)?;
    m.add_function(wrap_pyfunction!(compare_images, m)?)?;
    Ok(())
}
