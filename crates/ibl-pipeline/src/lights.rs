//! Directional lights from a probe (`ibl lights`): any extraction method for any N (Madsen &
//! Laursen 2006), written as the JSON light set of CONVENTIONS section 7, glTF 2.0
//! (`KHR_lights_punctual`, `.gltf`/`.glb`), a Mitsuba 3 scene or a pbrt-v4 fragment
//! (`ibl_io::light_export`), directions in any frame preset; optionally hybrid lighting (the
//! lights plus an SH ambient carrying the rest of the probe) and a picture of the regions and
//! lights on the tone-mapped probe (`ibl_eval::overlay`, the paper's Figure 3).
//!
//! Everything is checked before the probe is read (options, output extensions, outputs naming an
//! input), so a mistake costs no extraction time; every file is written atomically.

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_core::FramePreset;
use ibl_extract::{ExtractOptions, FitDomain};
use ibl_io::LightFormat;
use ibl_io::light_file::{AmbientRecord, LightsFile};
use ibl_light::{LightSet, MAX_MEDIAN_CUT_SPLITS, Method, ProbeRef};
use ibl_mapping::Mapping;

use crate::envmap_files::EnvMapping;
use crate::error::{Context, PipelineError, Result};
use crate::probe_input::{LoadedProbe, ProbeDetection, load_probe};
use crate::progress::{self, Progress};

/// What to extract and where to write it.
#[derive(Clone, Debug, PartialEq)]
pub struct LightsOptions {
    /// The probe, in any mapping ([`crate::probe_input`]).
    pub probe: PathBuf,
    /// Mapping of the probe (`None`: detected from its shape).
    pub mapping: Option<EnvMapping>,
    /// Number of lights.
    pub count: usize,
    /// Extraction method.
    pub method: Method,
    /// Seed of the methods' random choices.
    pub seed: u64,
    /// What irradiance optimisation fits.
    pub fit_domain: FitDomain,
    /// Light files, format by extension (`.json`, `.gltf`, `.glb`, `.xml`, `.pbrt`).
    pub outputs: Vec<PathBuf>,
    /// Frame preset of the written directions.
    pub frame: FramePreset,
    /// glTF only: lux per unit of a light's luminance `Y(I)`.
    pub lux_per_unit: f64,
    /// A PNG of the lights and regions over the tone-mapped probe.
    pub overlay: Option<PathBuf>,
    /// Hybrid lighting: an SH ambient of this many bands, written to `.json` outputs only.
    pub ambient_sh: Option<usize>,
}

/// What an extraction made.
#[derive(Clone, Debug, PartialEq)]
pub struct LightsResult {
    /// The lights in iblkit's frame, with their provenance (the probe file recorded).
    pub set: LightSet,
    /// Seconds the extraction took.
    pub seconds: f64,
    /// The probe's power `sum L dOmega` per channel.
    pub probe_power: [f64; 3],
    /// The method's parameters as JSON numbers (as the light file holds them).
    pub parameters: serde_json::Value,
    /// What the probe loader detected and did.
    pub probe: ProbeDetection,
}

impl LightsResult {
    /// What `ibl lights` prints: the count and power, then the five strongest lights.
    pub fn summary_text(&self) -> String {
        let set = &self.set;
        let (p, q) = (set.total_power(), self.probe_power);
        let mut text = format!(
            "{} lights by {}; power {:.5e} {:.5e} {:.5e} (probe {:.5e} {:.5e} {:.5e})\n",
            set.lights.len(),
            set.provenance.extraction.name(),
            p[0],
            p[1],
            p[2],
            q[0],
            q[1],
            q[2]
        );
        let mut order: Vec<usize> = (0..set.lights.len()).collect();
        let lum = |i: &usize| set.lights[*i].irradiance.luminance();
        order.sort_by(|a, b| lum(b).total_cmp(&lum(a)));
        text.push_str("strongest lights (world direction, solid angle sr, irradiance I = L A):\n");
        for l in order.iter().take(5).map(|i| &set.lights[*i]) {
            let (d, e) = (l.direction, l.irradiance);
            text.push_str(&format!(
                "  ({:+.4}, {:+.4}, {:+.4})  {:.3e}  {:.4e} {:.4e} {:.4e}\n",
                d[0], d[1], d[2], l.solid_angle_sr, e[0], e[1], e[2]
            ));
        }
        text
    }
}

/// The options' outputs with their formats, checked before any work.
fn check(o: &LightsOptions) -> Result<Vec<(&Path, LightFormat)>> {
    if o.outputs.is_empty() && o.overlay.is_none() {
        return Err(PipelineError::parameter(
            "say where to write: -o FILE (light set) and/or --overlay FILE.png",
        ));
    }
    if !(o.lux_per_unit.is_finite() && o.lux_per_unit > 0.0) {
        return Err(PipelineError::parameter(format!(
            "--lux-per-unit must be a finite positive number (got {})",
            o.lux_per_unit
        )));
    }
    if o.count == 0 {
        return Err(PipelineError::parameter(
            "-n 0: the number of lights must be N >= 1",
        ));
    }
    if !o.method.accepts(o.count) {
        return Err(PipelineError::parameter(match o.method {
            Method::MedianCut => format!(
                "-n {}: median cut makes a power of two lights (1, 2, 4, ... up to {}); use \
                 --method adaptive-median-cut (or any other method) for other counts",
                o.count,
                1u64 << MAX_MEDIAN_CUT_SPLITS
            ),
            m => format!("-n {}: {m} needs at least one light", o.count),
        }));
    }
    let outputs = o
        .outputs
        .iter()
        .map(|path| {
            let format = LightFormat::from_path(path).ok_or_else(|| {
                PipelineError::parameter(format!(
                    "{}: unknown light-set format (expected {})",
                    path.display(),
                    LightFormat::EXPECTED
                ))
            })?;
            Ok((path.as_path(), format))
        })
        .collect::<Result<Vec<_>>>()?;
    if let Some(bands) = o.ambient_sh {
        if bands == 0 || bands > ibl_sh::MAX_BANDS {
            return Err(PipelineError::parameter(format!(
                "--ambient-sh must be between 1 and {}",
                ibl_sh::MAX_BANDS
            )));
        }
        if let Some((path, format)) = outputs.iter().find(|(_, f)| *f != LightFormat::Json) {
            return Err(PipelineError::parameter(format!(
                "{}: {} has no place for an SH ambient; write the hybrid to a .json file \
                 (and the probe's SH with `ibl sh --format ...`)",
                path.display(),
                format.name()
            )));
        }
    }
    if let Some(overlay) = &o.overlay
        && !matches!(
            ibl_io::ImageFormat::from_path(overlay),
            Some(ibl_io::ImageFormat::Png)
        )
    {
        return Err(PipelineError::parameter(format!(
            "{}: the overlay is written as .png",
            overlay.display()
        )));
    }
    let all: Vec<&Path> = o
        .outputs
        .iter()
        .chain(&o.overlay)
        .map(PathBuf::as_path)
        .collect();
    for (i, path) in all.iter().enumerate() {
        if all[..i].contains(path) {
            return Err(PipelineError::parameter(format!(
                "{}: named twice as an output",
                path.display()
            )));
        }
        crate::output_paths::check_output_path(path, &[o.probe.as_path()])?;
    }
    Ok(outputs)
}

/// Extracts the lights and writes every output; what it does on the way goes to
/// `progress` as notes.
pub fn lights(o: &LightsOptions, progress: &dyn Progress) -> Result<LightsResult> {
    let outputs = check(o)?;
    let method = o.method;
    if o.frame != FramePreset::Gltf {
        for (path, format) in &outputs {
            if matches!(format, LightFormat::Gltf | LightFormat::Glb) {
                progress.note(&format!(
                    "note: {}: glTF is defined in the gltf frame; writing the directions in the \
                     {} preset's axes as asked",
                    path.display(),
                    o.frame.name()
                ));
            }
        }
    }

    let LoadedProbe { env, detection } = load_probe(&o.probe, o.mapping, progress)?;
    let start = Instant::now();
    let label = format!("{method}: {} lights", o.count);
    let extracted = progress::task(progress, &label, || {
        ibl_extract::extract(
            &env.image,
            method,
            o.count,
            &ExtractOptions {
                seed: o.seed,
                fit_domain: o.fit_domain,
            },
        )
    });
    let seconds = start.elapsed().as_secs_f64();
    let mut set = extracted.context(format!("{}: {method}", o.probe.display()))?;
    progress.note(&format!(
        "{method}: {} lights in {seconds:.2} s",
        set.lights.len()
    ));
    if set.lights.len() != o.count {
        // Median cut, for one, cannot cut a region of one pixel.
        progress.note(&format!(
            "note: {method} made {} lights, not the {} asked",
            set.lights.len(),
            o.count
        ));
    }
    set.provenance.probe = Some(ProbeRef {
        path: o.probe.display().to_string(),
        width: env.image.width(),
        height: env.image.height(),
        sha256: ibl_io::light_file::sha256_file(&o.probe)?,
    });

    let file_from_world = o.frame.preset_from_world().as_dmat3();
    let ambient = match o.ambient_sh {
        Some(bands) => {
            let hybrid = ibl_extract::Hybrid::from_probe(
                &env.image,
                set.clone(),
                bands,
                ibl_sh::Window::None,
            )
            .context(o.probe.display().to_string())?;
            Some(AmbientRecord {
                convention: ibl_io::sh_file::SH_CONVENTION.to_string(),
                bands,
                radiance: hybrid
                    .ambient
                    .transformed(file_from_world)
                    .coefficients()
                    .to_vec(),
            })
        }
        None => None,
    };
    let file = LightsFile {
        set: set.transformed(file_from_world),
        frame: o.frame,
        ambient,
    };
    for (path, format) in &outputs {
        ibl_io::write_light_file(path, &file, o.lux_per_unit)?;
        progress.note(&format!(
            "wrote {} ({}, {} lights, {} frame)",
            path.display(),
            format.name(),
            set.lights.len(),
            o.frame.name()
        ));
    }
    if let Some(path) = &o.overlay {
        let picture = ibl_eval::overlay::draw_overlay(
            &env.image,
            &set,
            &ibl_eval::overlay::OverlayOptions::default(),
        );
        let png = ibl_io::ldr::encode_png(&picture).map_err(|e| e.with_path(path))?;
        ibl_io::write_atomically(path, &png)?;
        progress.note(&format!(
            "wrote {} ({} x {} overlay)",
            path.display(),
            picture.width(),
            picture.height()
        ));
    }
    Ok(LightsResult {
        parameters: ibl_io::light_file::parameters_json(&set.provenance.extraction.parameters()),
        probe_power: ibl_mapping::power(&env.image, Mapping::LatLong),
        seconds,
        set,
        probe: detection,
    })
}
