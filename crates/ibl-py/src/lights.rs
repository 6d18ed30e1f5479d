//! Light extraction with every method (`ibl lights`), the light set as numpy arrays and as its
//! JSON, and light files in every format `ibl lights -o` writes.

use std::path::PathBuf;

use ibl_core::FramePreset;
use ibl_extract::ExtractOptions;
use ibl_io::light_file::LightsFile;
use ibl_light::{LightSet, Method};
use numpy::ndarray::Array1;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::arrays::{directions_from, image_from, rows_to};
use crate::errors::{bad, lib};
use crate::progress::PyProgress;

/// A set of directional lights in iblkit's world frame: each light's direction (unit, towards
/// the light), radiance `L` and solid angle `A` (sr) of the region it stands for, and its
/// irradiance `I = L A` on a surface facing it. `len(lights)`; `lights.to_json()` is the light
/// file `ibl lights -o lights.json` writes.
#[pyclass(name = "LightSet", module = "iblkit._native", frozen)]
pub struct PyLightSet {
    pub set: LightSet,
}

fn column(set: &LightSet, f: impl Fn(&ibl_light::Light) -> [f64; 3]) -> Vec<[f64; 3]> {
    set.lights.iter().map(f).collect()
}

#[pymethods]
impl PyLightSet {
    /// Unit directions towards the lights, (N, 3) float64, world frame.
    #[getter]
    fn directions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows_to(py, &column(&self.set, |l| l.direction.to_array()))
    }

    /// Radiance L of each light's region, (N, 3).
    #[getter]
    fn radiance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows = column(&self.set, |l| l.radiance.to_array().map(f64::from));
        rows_to(py, &rows)
    }

    /// Irradiance I = L A of each light on a surface facing it, (N, 3).
    #[getter]
    fn irradiance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows_to(py, &column(&self.set, |l| l.irradiance.to_array()))
    }

    /// Solid angle of each light's region, sr, (N,).
    #[getter]
    fn solid_angles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self.set.lights.iter().map(|l| l.solid_angle_sr).collect();
        Array1::from(v).into_pyarray(py)
    }

    /// Solid angle of the uniform cone that sizes each light's soft shadow, sr, (N,): its
    /// measured spread (the cone with the light's half-energy angle) within its region's solid
    /// angle, or the solid angle where the method measures no spread.
    #[getter]
    fn shadow_solid_angles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .set
            .lights
            .iter()
            .map(|l| l.shadow_solid_angle_sr())
            .collect();
        Array1::from(v).into_pyarray(py)
    }

    /// Share of each light's power in that cone (its core), (N,): the rest spreads as a halo
    /// over the light's solid angle; 1 where the method measures no spread.
    #[getter]
    fn shadow_core_fractions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .set
            .lights
            .iter()
            .map(|l| l.shadow_cones().halo.map_or(1.0, |(_, share)| 1.0 - share))
            .collect();
        Array1::from(v).into_pyarray(py)
    }

    /// The extraction method's name.
    #[getter]
    fn method(&self) -> String {
        self.set.provenance.extraction.name().to_string()
    }

    /// Total power `sum I` per channel.
    #[getter]
    fn total_power(&self) -> [f64; 3] {
        self.set.total_power()
    }

    /// Irradiance the lights give on surfaces of these normals, (M, 3) from (M, 3), no shadows:
    /// `E(n) = sum_i I_i max(0, n . d_i)`.
    fn irradiance_at<'py>(
        &self,
        py: Python<'py>,
        normals: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let normals = directions_from(normals, "normals")?;
        let e: Vec<[f64; 3]> = normals.iter().map(|n| self.set.irradiance_at(*n)).collect();
        Ok(rows_to(py, &e))
    }

    /// The light file's JSON (`iblkit.lights/1`, directions in `frame`: gltf, paper, threejs,
    /// blender).
    #[pyo3(signature = (frame="gltf"))]
    fn to_json(&self, frame: &str) -> PyResult<String> {
        Ok(lights_file(&self.set, frame)?.to_json())
    }

    /// Writes the lights in the format of the extension: .json, .gltf, .glb, .xml (Mitsuba 3),
    /// .pbrt (pbrt-v4), directions in `frame`; `lux_per_unit` scales glTF intensities.
    #[pyo3(signature = (path, frame="gltf", lux_per_unit=1.0))]
    fn write(&self, path: PathBuf, frame: &str, lux_per_unit: f64) -> PyResult<()> {
        if !(lux_per_unit.is_finite() && lux_per_unit > 0.0) {
            return Err(bad("lux_per_unit must be a finite positive number"));
        }
        let file = lights_file(&self.set, frame)?;
        ibl_io::write_light_file(&path, &file, lux_per_unit).map_err(lib)
    }

    fn __len__(&self) -> usize {
        self.set.lights.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "LightSet({} lights by {})",
            self.set.lights.len(),
            self.set.provenance.extraction.name()
        )
    }
}

/// The set as a light file with directions in the named frame preset.
fn lights_file(set: &LightSet, frame: &str) -> PyResult<LightsFile> {
    let frame = FramePreset::from_name(frame).ok_or_else(|| {
        bad(format!(
            "unknown frame `{frame}` (gltf, paper, threejs, blender)"
        ))
    })?;
    Ok(LightsFile {
        set: set.transformed(frame.preset_from_world().as_dmat3()),
        frame,
        ambient: None,
    })
}

/// Approximates a lat-long probe (H, W, 3) by `n` directional lights with `method`
/// (median-cut, adaptive-median-cut, lightgen, variance-minimization, irradiance-optimization);
/// `seed` drives the randomised methods; `fit_domain` is what irradiance optimisation fits
/// (`hemispheres`: above and below the horizon apart, `sphere`: the paper's one fit). Median cut
/// makes a power of two. Releases the GIL.
#[pyfunction]
#[pyo3(signature = (probe, n, method="median-cut", seed=None, fit_domain="hemispheres"))]
fn extract_lights(
    py: Python<'_>,
    probe: &Bound<'_, PyAny>,
    n: usize,
    method: &str,
    seed: Option<u64>,
    fit_domain: &str,
) -> PyResult<PyLightSet> {
    let image = image_from(probe, "probe")?;
    let method: Method = method
        .parse()
        .map_err(|e: ibl_light::MethodError| bad(e.to_string()))?;
    let options = ExtractOptions {
        seed: seed.unwrap_or(ExtractOptions::default().seed),
        fit_domain: fit_domain.parse().map_err(lib)?,
    };
    let set = py
        .detach(|| ibl_extract::extract(&image, method, n, &options))
        .map_err(lib)?;
    Ok(PyLightSet { set })
}

/// Reads a light file (`ibl lights -o x.json`) as a light set in the world frame.
#[pyfunction]
fn read_lights(path: PathBuf) -> PyResult<PyLightSet> {
    let set = ibl_io::light_file::read_light_set(&path).map_err(lib)?;
    Ok(PyLightSet { set })
}

/// `ibl lights` itself: reads the probe (any mapping, through the probe loader), extracts and
/// writes every output (`outputs`: light files by extension; `overlay`: a PNG), as the command
/// does. Returns the light set.
#[pyfunction]
#[pyo3(signature = (probe, n, outputs, method="median-cut", seed=None, mapping=None, overlay=None, ambient_sh=None, progress=None, fit_domain="hemispheres"))]
#[allow(clippy::too_many_arguments)]
fn lights_job(
    py: Python<'_>,
    probe: PathBuf,
    n: usize,
    outputs: Vec<PathBuf>,
    method: &str,
    seed: Option<u64>,
    mapping: Option<&str>,
    overlay: Option<PathBuf>,
    ambient_sh: Option<usize>,
    progress: Option<Py<PyAny>>,
    fit_domain: &str,
) -> PyResult<PyLightSet> {
    let options = ibl_pipeline::lights::LightsOptions {
        probe,
        mapping: crate::images::env_mapping(mapping)?,
        count: n,
        method: method
            .parse()
            .map_err(|e: ibl_light::MethodError| bad(e.to_string()))?,
        seed: seed.unwrap_or(ExtractOptions::default().seed),
        fit_domain: fit_domain.parse().map_err(lib)?,
        outputs,
        frame: FramePreset::Gltf,
        lux_per_unit: 1.0,
        overlay,
        ambient_sh,
    };
    let reporter = PyProgress::new(progress);
    let result = py.detach(|| ibl_pipeline::lights::lights(&options, &reporter));
    reporter.finish()?;
    Ok(PyLightSet {
        set: result.map_err(crate::errors::to_py)?.set,
    })
}

/// Adds this module's class and functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLightSet>()?;
    m.add_function(wrap_pyfunction!(extract_lights, m)?)?;
    m.add_function(wrap_pyfunction!(read_lights, m)?)?;
    m.add_function(wrap_pyfunction!(lights_job, m)?)?;
    Ok(())
}
