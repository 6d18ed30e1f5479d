//! Irradiance from a lat-long probe (`ibl irradiance`; CONVENTIONS sections 4-5): on M Fibonacci
//! normals as `nx,ny,nz,r,g,b` CSV rows (the ground truth of Madsen & Laursen 2006 section 5) and
//! as an irradiance environment map in any mapping that covers the sphere: each texel holds
//! `E(n)` for the texel's direction `n`. Methods: exact (every pixel), fast (the probe reduced to
//! 64 x 32 energy-conserving blocks) or spherical harmonics (Lambert convolution of B bands).
//! Every approximate run states its error against the exact ground truth on 20000 normals.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use ibl_core::glam::DVec3;
use ibl_core::{Image, Rgb, fibonacci_normals};
use ibl_io::WriteOptions;
use ibl_mapping::Mapping;
use ibl_metrics::IrradianceError;
use ibl_sh::{MAX_BANDS, Window, project_latlong};
use serde::Serialize;

use crate::envmap_files::{self, EnvMapping};
use crate::error::{Context, PipelineError, Result};
use crate::probe_input::{LoadedProbe, ProbeDetection, load_probe};
use crate::progress::{self, Progress};

/// How to compute the irradiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum IrradianceMethod {
    /// Brute force over every pixel (the ground truth).
    Exact,
    /// The probe reduced to 64 x 32 energy-conserving blocks first (mean error under 0.1 %).
    Fast,
    /// Spherical harmonics: the probe projected on `bands` bands, Lambert-convolved.
    Sh,
}

impl IrradianceMethod {
    /// The method [`IrradianceMethod::name`] names.
    pub fn from_name(name: &str) -> Option<IrradianceMethod> {
        [
            IrradianceMethod::Exact,
            IrradianceMethod::Fast,
            IrradianceMethod::Sh,
        ]
        .into_iter()
        .find(|m| m.name() == name)
    }

    /// `exact`, `fast` or `sh`.
    pub fn name(self) -> &'static str {
        match self {
            IrradianceMethod::Exact => "exact",
            IrradianceMethod::Fast => "fast",
            IrradianceMethod::Sh => "sh",
        }
    }
}

/// What to compute and where to write it.
#[derive(Clone, Debug, PartialEq)]
pub struct IrradianceOptions {
    /// The probe, in any mapping ([`crate::probe_input`]).
    pub probe: PathBuf,
    /// Mapping of the probe (`None`: detected from its shape).
    pub mapping: Option<EnvMapping>,
    /// How.
    pub method: IrradianceMethod,
    /// SH bands (`Sh` only).
    pub bands: usize,
    /// SH window against ringing (`Sh` only).
    pub window: Window,
    /// CSV of `nx,ny,nz,r,g,b` on Fibonacci normals.
    pub csv: Option<PathBuf>,
    /// Number of Fibonacci normals of the CSV.
    pub normals: usize,
    /// Irradiance map (a `{face}` pattern for cube faces).
    pub output: Option<PathBuf>,
    /// Mapping of the map.
    pub to: EnvMapping,
    /// Width of the map in pixels.
    pub width: usize,
}

/// Largest number of normals accepted (the CSV is about 100 bytes a row).
pub const MAX_NORMALS: usize = 10_000_000;

/// Largest irradiance-map width accepted.
pub const MAX_WIDTH: usize = 16_384;

/// Normals on which approximate methods are scored against the exact ground truth.
pub const CHECK_NORMALS: usize = 20_000;

/// What a run did (the JSON of `ibl irradiance --json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IrradianceSummary {
    /// The probe, as given.
    pub probe: String,
    /// The method.
    pub method: IrradianceMethod,
    /// SH bands (`sh` only).
    pub bands: Option<usize>,
    /// SH window (`sh` only).
    pub window: Option<&'static str>,
    /// Seconds to compute and write.
    pub seconds: f64,
    /// Mean irradiance over `mean_over_normals` Fibonacci normals, per channel.
    pub mean_irradiance: [f64; 3],
    /// How many normals the mean is over: the CSV's own when its values serve (an exact CSV is
    /// already the answer), else [`CHECK_NORMALS`].
    pub mean_over_normals: usize,
    /// Error against the exact ground truth on [`CHECK_NORMALS`] Fibonacci normals (approximate
    /// methods), per cent of the mean irradiance.
    pub mean_err_pct: Option<f64>,
    /// Largest error, per cent of the mean irradiance.
    pub max_err_pct: Option<f64>,
    /// Files written.
    pub outputs: Vec<String>,
    /// What the probe loader detected and did.
    pub probe_input: ProbeDetection,
}

/// An irradiance evaluator for one probe and method.
enum Evaluator<'a> {
    /// Rows streamed through the cache, all normals per row ([`ibl_core::irradiance_exact`]).
    Exact(&'a Image<Rgb>),
    Fast(&'a Image<Rgb>),
    Sh(ibl_sh::IrradianceSh),
}

impl Evaluator<'_> {
    fn irradiance(&self, dirs: &[DVec3]) -> Vec<[f64; 3]> {
        match self {
            Evaluator::Exact(probe) => ibl_core::irradiance_exact(probe, dirs),
            Evaluator::Fast(probe) => {
                ibl_eval::irradiance_fast(probe, dirs, ibl_eval::FAST_DEFAULT_SIZE)
            }
            Evaluator::Sh(sh) => sh.eval_many(dirs),
        }
    }
}

/// Checks the options before any work.
fn check(o: &IrradianceOptions) -> Result<()> {
    if o.csv.is_none() && o.output.is_none() {
        return Err(PipelineError::parameter(
            "say where to write: --csv FILE (Fibonacci normals) and/or -o FILE (irradiance map)",
        ));
    }
    if o.normals == 0 || o.normals > MAX_NORMALS {
        return Err(PipelineError::parameter(format!(
            "--normals must be between 1 and {MAX_NORMALS}"
        )));
    }
    if o.width == 0 || o.width > MAX_WIDTH {
        return Err(PipelineError::parameter(format!(
            "--width must be between 1 and {MAX_WIDTH}"
        )));
    }
    if o.bands == 0 || o.bands > MAX_BANDS {
        return Err(PipelineError::parameter(format!(
            "--bands must be between 1 and {MAX_BANDS}"
        )));
    }
    if matches!(
        o.to,
        EnvMapping::Single(Mapping::Fisheye { .. } | Mapping::DualFisheye { .. })
    ) {
        return Err(PipelineError::parameter(
            "--to: fisheye mappings do not cover the sphere; use latlong, a cube or angular",
        ));
    }
    let inputs = [o.probe.as_path()];
    for out in o.csv.iter().chain(&o.output) {
        crate::output_paths::check_output_path(out, &inputs)?;
    }
    if o.csv.is_some() && o.csv == o.output {
        return Err(PipelineError::parameter("--csv and -o name the same file"));
    }
    Ok(())
}

/// Computes the irradiance and writes the CSV and the map asked for.
pub fn irradiance(o: &IrradianceOptions, progress: &dyn Progress) -> Result<IrradianceSummary> {
    check(o)?;
    let LoadedProbe { env, detection } = load_probe(&o.probe, o.mapping, progress)?;
    let label = format!("{} irradiance", o.method.name());
    progress::task(progress, &label, || compute(o, &env.image, detection))
}

fn compute(
    o: &IrradianceOptions,
    probe: &Image<Rgb>,
    detection: ProbeDetection,
) -> Result<IrradianceSummary> {
    let start = Instant::now();
    let evaluator = match o.method {
        IrradianceMethod::Exact => Evaluator::Exact(probe),
        IrradianceMethod::Fast => Evaluator::Fast(probe),
        IrradianceMethod::Sh => Evaluator::Sh(
            project_latlong(probe, o.bands)
                .context(o.probe.display().to_string())?
                .irradiance(o.window),
        ),
    };
    let mut outputs = Vec::new();
    // The CSV's values, kept when its normals are the summary's (no second evaluation).
    let mut reusable: Option<Vec<[f64; 3]>> = None;
    if let Some(csv) = &o.csv {
        let normals = fibonacci_normals(o.normals);
        let e = evaluator.irradiance(&normals);
        let mut text = String::with_capacity(normals.len() * 100 + 32);
        text.push_str("nx,ny,nz,r,g,b\n");
        for (n, v) in normals.iter().zip(&e) {
            let _ = writeln!(text, "{},{},{},{},{},{}", n.x, n.y, n.z, v[0], v[1], v[2]);
        }
        ibl_io::write_atomically(csv, text.as_bytes())?;
        outputs.push(csv.display().to_string());
        if o.method == IrradianceMethod::Exact || o.normals == CHECK_NORMALS {
            reusable = Some(e);
        }
    }
    if let Some(out) = &o.output {
        let map = irradiance_map(&evaluator, o.to.in_memory(), o.width);
        let written = envmap_files::save(
            out,
            &map,
            o.to,
            &WriteOptions::default(),
            &[o.probe.as_path()],
        )?;
        outputs.extend(written.iter().map(|p| p.display().to_string()));
    }
    let seconds = start.elapsed().as_secs_f64();
    // The mean irradiance, and for approximate methods the error against the exact ground truth,
    // on the CSV's own values when they serve: an exact CSV is already the answer (its mean is
    // over its own normals), and an approximate one on the 20000 check normals is the check.
    let check = match reusable {
        Some(values) => values,
        None => evaluator.irradiance(&fibonacci_normals(CHECK_NORMALS)),
    };
    let mean_over_normals = check.len();
    let mean = ibl_core::channel_means(&check);
    let errors = (o.method != IrradianceMethod::Exact).then(|| {
        let truth = ibl_core::irradiance_exact(probe, &fibonacci_normals(CHECK_NORMALS));
        IrradianceError::between(&truth, &check)
    });
    let is_sh = o.method == IrradianceMethod::Sh;
    Ok(IrradianceSummary {
        probe: o.probe.display().to_string(),
        method: o.method,
        bands: is_sh.then_some(o.bands),
        window: is_sh.then_some(o.window.name()),
        seconds,
        mean_irradiance: mean,
        mean_over_normals,
        mean_err_pct: errors.as_ref().map(|e| e.mean_err_pct),
        max_err_pct: errors.as_ref().map(|e| e.max_err_pct),
        outputs,
        probe_input: detection,
    })
}

/// The irradiance map of a lat-long probe in memory (the Python bindings' `irradiance_map`): the
/// job's evaluators and texel directions, without files.
pub fn irradiance_map_of(
    probe: &Image<Rgb>,
    method: IrradianceMethod,
    bands: usize,
    window: Window,
    to: Mapping,
    width: usize,
) -> Result<Image<Rgb>> {
    if width == 0 || width > MAX_WIDTH {
        return Err(PipelineError::parameter(format!(
            "the map width must be between 1 and {MAX_WIDTH}"
        )));
    }
    let evaluator = match method {
        IrradianceMethod::Exact => Evaluator::Exact(probe),
        IrradianceMethod::Fast => Evaluator::Fast(probe),
        IrradianceMethod::Sh => Evaluator::Sh(project_latlong(probe, bands)?.irradiance(window)),
    };
    Ok(irradiance_map(&evaluator, to, width))
}

/// The irradiance map: `E(n)` at every texel centre's direction of `mapping` at `width`
/// (texels outside a disc mapping's disc, or in an unused cross cell, are black). O(texels) calls
/// of the evaluator, which runs them in parallel.
fn irradiance_map(evaluator: &Evaluator, mapping: Mapping, width: usize) -> Image<Rgb> {
    let (w, h) = mapping.size_for_width(width);
    let mut dirs = Vec::with_capacity(w * h);
    let mut index = Vec::with_capacity(w * h);
    for j in 0..h {
        for i in 0..w {
            if let Some(d) = mapping.pixel_dir(w, h, i as f64 + 0.5, j as f64 + 0.5) {
                dirs.push(d);
                index.push((i, j));
            }
        }
    }
    let e = evaluator.irradiance(&dirs);
    let mut img = Image::filled(w, h, Rgb::ZERO);
    for ((i, j), v) in index.into_iter().zip(e) {
        *img.get_mut(i, j) = Rgb::new(v[0] as f32, v[1] as f32, v[2] as f32);
    }
    img
}
