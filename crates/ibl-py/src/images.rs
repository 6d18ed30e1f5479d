//! Images: read and write every format `ibl` reads and writes, the one probe loader, mapping
//! conversion (energy-conserving resampling, with rotation), and `ibl info`'s statistics.

use std::path::PathBuf;

use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_core::{EulerDegrees, FramePreset};
use ibl_io::WriteOptions;
use ibl_mapping::Mapping;
use ibl_pipeline::EnvMapping;
use ibl_pipeline::Progress;
use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{image_from, image_to};
use crate::errors::{bad, lib, to_py};
use crate::progress::PyProgress;

/// Largest output width of `convert`.
const MAX_WIDTH: usize = 16_384;

/// A mapping by `ibl`'s name (`latlong`, `angular`, `mirror-ball`, `cube-hcross`, ...).
pub fn mapping(name: &str) -> PyResult<Mapping> {
    Mapping::parse(name, 180.0).ok_or_else(|| {
        bad(format!(
            "unknown mapping `{name}` (one of {})",
            ibl_mapping::MAPPING_NAMES.join(", ")
        ))
    })
}

/// An optional probe mapping (`None`: from the file's shape).
pub fn env_mapping(name: Option<&str>) -> PyResult<Option<EnvMapping>> {
    name.map(|n| EnvMapping::parse(n, 180.0).map_err(to_py))
        .transpose()
}

/// A serialisable value as a Python object, through its JSON text and the `json` module: the
/// same text `ibl ... --json` prints (f32 fields as their shortest f32 digits), so the numbers
/// a script gets are the command's.
pub fn json_to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| crate::errors::InternalError::new_err(format!("to JSON: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Reads an image file as stored (.exr, .hdr, .pfm, .png, .jpg, .ktx2, .dds): float32 (H, W, 3)
/// linear values (8-bit files are decoded from sRGB). NaN, infinite and negative values are
/// clamped to 0, as `ibl` does.
#[pyfunction]
fn read_image<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let loaded = py.detach(|| ibl_io::read_image(&path)).map_err(lib)?;
    Ok(image_to(py, &loaded.image))
}

/// Reads a light probe through `ibl`'s one probe loader: the mapping named, or detected from the
/// image's shape (an image whose shape names none is refused), converted to lat-long
/// (energy-conserving) when it is not one. Returns the lat-long array and what was detected.
#[pyfunction]
#[pyo3(signature = (path, mapping=None, progress=None))]
fn read_probe<'py>(
    py: Python<'py>,
    path: PathBuf,
    mapping: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyAny>)> {
    let mapping = env_mapping(mapping)?;
    let reporter = PyProgress::new(progress);
    let loaded = py.detach(|| ibl_pipeline::load_probe(&path, mapping, &reporter));
    reporter.finish()?;
    let loaded = loaded.map_err(to_py)?;
    Ok((
        image_to(py, &loaded.env.image),
        json_to_py(py, &loaded.detection)?,
    ))
}

/// Writes an image, format by extension, atomically. HDR formats store the values; .png and .jpg
/// apply the exposure in stops (automatic when None: the log-average luminance to middle grey)
/// and the tone curve (clamp, reinhard, aces), then sRGB.
#[pyfunction]
#[pyo3(signature = (path, image, exposure=None, curve="reinhard"))]
fn write_image(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    exposure: Option<f32>,
    curve: &str,
) -> PyResult<()> {
    let image = image_from(image, "image")?;
    let curve = ToneCurve::from_name(curve).ok_or_else(|| {
        bad(format!(
            "unknown tone curve `{curve}` (clamp, reinhard, aces)"
        ))
    })?;
    if exposure.is_some_and(|e| !e.is_finite()) {
        return Err(bad("exposure must be a finite number of stops"));
    }
    py.detach(|| {
        let options = WriteOptions {
            display: Display {
                exposure_stops: exposure.unwrap_or_else(|| auto_exposure_stops(&image)),
                curve,
            },
            ..WriteOptions::default()
        };
        ibl_io::write_image(&path, &image, &options)
    })
    .map_err(lib)
}

/// Resamples an environment map from one mapping to another (energy-conserving supersampling, as
/// `ibl convert --to`). `width` defaults to the size that keeps the source's angular resolution;
/// `rotation` is (yaw, pitch, roll) in degrees, world_from_probe.
#[pyfunction]
#[pyo3(signature = (image, source, target="latlong", width=None, rotation=(0.0, 0.0, 0.0), progress=None))]
fn convert<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    source: &str,
    target: &str,
    width: Option<usize>,
    rotation: (f32, f32, f32),
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let image = image_from(image, "image")?;
    let (from, to) = (mapping(source)?, mapping(target)?);
    from.check_shape(image.width(), image.height())
        .map_err(lib)?;
    let (w, h) = match width {
        Some(w) if w == 0 || w > MAX_WIDTH => {
            return Err(bad(format!("width must be between 1 and {MAX_WIDTH}")));
        }
        Some(w) => to.size_for_width(w),
        None => to.default_size_for(from, image.width(), image.height()),
    };
    let (yaw_deg, pitch_deg, roll_deg) = rotation;
    let rotation = EulerDegrees {
        yaw_deg,
        pitch_deg,
        roll_deg,
    }
    .world_from_probe();
    let reporter = PyProgress::new(progress);
    let out = py.detach(|| {
        reporter.begin("resampling", h as u64);
        let out = ibl_mapping::resample(
            &image,
            from,
            to,
            w,
            h,
            rotation,
            &ibl_pipeline::progress::rows(&reporter),
        );
        reporter.end();
        out
    });
    reporter.finish()?;
    Ok(image_to(py, &out.map_err(lib)?))
}

/// The mapping an image of this shape is taken for (2:1 lat-long, 1:1 angular, the cube
/// layouts), or None when the shape names none.
#[pyfunction]
fn detect_mapping(width: usize, height: usize) -> Option<String> {
    Mapping::detect_from_shape(width, height).map(|m| m.name())
}

/// `ibl info --json`: size, format, mapping, range, clamped values, power per channel, dynamic
/// range and the brightest pixel's direction.
#[pyfunction]
#[pyo3(signature = (path, mapping=None))]
fn info<'py>(py: Python<'py>, path: PathBuf, mapping: Option<&str>) -> PyResult<Bound<'py, PyAny>> {
    let mapping = env_mapping(mapping)?;
    let info = py
        .detach(|| ibl_pipeline::info::probe_info(&path, mapping, FramePreset::Gltf))
        .map_err(to_py)?;
    json_to_py(py, &info)
}

/// The names `ibl` gives its mappings, formats and methods.
#[pyfunction]
fn names<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("mappings", ibl_mapping::MAPPING_NAMES.to_vec())?;
    d.set_item("methods", ibl_light::Method::ALL.map(|m| m.name()).to_vec())?;
    d.set_item(
        "sh_formats",
        ibl_io::ShFileFormat::ALL.map(|f| f.name()).to_vec(),
    )?;
    d.set_item(
        "prefilter_targets",
        ibl_mapping::EngineTarget::ALL.map(|t| t.name()).to_vec(),
    )?;
    d.set_item("tone_curves", ToneCurve::ALL.map(|c| c.name()).to_vec())?;
    Ok(d)
}

/// Adds this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(read_probe, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(convert, m)?)?;
    m.add_function(wrap_pyfunction!(detect_mapping, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(names, m)?)?;
    Ok(())
}
