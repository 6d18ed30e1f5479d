//! numpy arrays to and from iblkit's images and vectors.
//!
//! An image is `float32 (H, W, 3)`, C order, linear radiance, row 0 at the top. Input arrays of
//! any float or integer dtype are converted by `numpy.ascontiguousarray(a, dtype=float32)`; an
//! array of another shape, or with NaN or infinite values, is refused by name (iblkit's readers
//! clamp those on reading a file; an array from Python is taken as the caller means it).

use ibl_core::glam::DVec3;
use ibl_core::{Image, Rgb};
use numpy::ndarray::{Array2, Array3};
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::bad;

/// Largest image accepted from Python, pixels (as the file readers' default limit).
const MAX_PIXELS: usize = 1 << 28;

/// `obj` as a C-contiguous numpy array of `dtype`.
fn contiguous<'py>(obj: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    np.call_method1("ascontiguousarray", (obj, dtype))
}

/// An `(H, W, 3)` array as an image; `what` names the argument in messages.
pub fn image_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Image<Rgb>> {
    let array = contiguous(obj, "float32")?;
    let array = array
        .cast::<PyArray3<f32>>()
        .map_err(|_| bad(format!("{what}: expected an array of shape (H, W, 3)")))?;
    let view = array.readonly();
    let shape = view.shape();
    let (h, w, c) = (shape[0], shape[1], shape[2]);
    if c != 3 || h == 0 || w == 0 {
        return Err(bad(format!(
            "{what}: expected shape (H, W, 3) with H, W >= 1, got ({h}, {w}, {c})"
        )));
    }
    if w.saturating_mul(h) > MAX_PIXELS {
        return Err(bad(format!(
            "{what}: {w} x {h} pixels is over the limit of {MAX_PIXELS}"
        )));
    }
    let data = view
        .as_slice()
        .map_err(|_| bad(format!("{what}: not contiguous")))?;
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        return Err(bad(format!(
            "{what}: value {i} is {} (NaN and infinities are not radiance)",
            data[i]
        )));
    }
    let pixels = data
        .chunks_exact(3)
        .map(|p| Rgb::new(p[0], p[1], p[2]))
        .collect();
    Image::from_vec(w, h, pixels).map_err(|e| bad(format!("{what}: {e}")))
}

/// An image as a new `(H, W, 3)` float32 array.
pub fn image_to<'py>(py: Python<'py>, image: &Image<Rgb>) -> Bound<'py, PyArray3<f32>> {
    let (w, h) = (image.width(), image.height());
    let mut data = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for p in image.row(y) {
            data.extend_from_slice(&p.to_array());
        }
    }
    Array3::from_shape_vec((h, w, 3), data)
        .unwrap_or_else(|_| Array3::zeros((h, w, 3)))
        .into_pyarray(py)
}

/// An `(N, 3)` array of directions (normalised; a zero or non-finite row is refused).
pub fn directions_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<DVec3>> {
    let array = contiguous(obj, "float64")?;
    let array: PyReadonlyArray2<f64> = array
        .extract()
        .map_err(|_| bad(format!("{what}: expected an array of shape (N, 3)")))?;
    let view = array.as_array();
    if view.ncols() != 3 {
        return Err(bad(format!(
            "{what}: expected shape (N, 3), got {:?}",
            view.shape()
        )));
    }
    view.rows()
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            let d = DVec3::new(r[0], r[1], r[2]);
            let len = d.length();
            if len.is_finite() && len > 0.0 {
                Ok(d / len)
            } else {
                Err(bad(format!("{what}: row {i} is not a direction")))
            }
        })
        .collect()
}

/// Rows of three numbers as a new `(N, 3)` float64 array.
pub fn rows_to<'py>(py: Python<'py>, rows: &[[f64; 3]]) -> Bound<'py, PyArray2<f64>> {
    let data: Vec<f64> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), 3), data)
        .unwrap_or_else(|_| Array2::zeros((rows.len(), 3)))
        .into_pyarray(py)
}
