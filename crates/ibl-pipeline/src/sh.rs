//! Spherical-harmonic lighting (`ibl sh`): projected from a lat-long probe and written in iblkit's
//! JSON or in another tool's convention (three.js, Filament, Unity, WebXR, ARKit, glTF
//! `EXT_lights_image_based`), or read back from any of them. The conversions and their sources
//! are in `ibl-io::sh_file` and docs/CONVENTIONS.md section 5b.

use std::path::{Path, PathBuf};

use ibl_io::sh_file::{SH_CONVENTION, SH_FORMAT, format_sh};
use ibl_io::{ShFile, ShFileFormat, ShQuantity};
use ibl_light::ProbeRef;
use ibl_sh::{MAX_BANDS, RadianceSh, Window, project_latlong};

use crate::envmap_files::EnvMapping;
use crate::error::{Context, PipelineError, Result};
use crate::probe_input::load_probe;
use crate::progress::Progress;

/// Where the coefficients come from.
#[derive(Clone, Debug, PartialEq)]
pub enum ShSource {
    /// A probe in any mapping (`None`: detected from its shape), projected.
    Probe(PathBuf, Option<EnvMapping>),
    /// An SH file in a tool's format.
    File(PathBuf, ShFileFormat),
}

/// What to write.
#[derive(Clone, Debug, PartialEq)]
pub struct ShOptions {
    /// The probe or SH file.
    pub source: ShSource,
    /// Output format.
    pub format: ShFileFormat,
    /// Bands to project (formats other than json take 3).
    pub bands: usize,
    /// Radiance coefficients, or irradiance `A_l c_lm` (json only).
    pub quantity: ShQuantity,
    /// Window against ringing (projection only).
    pub window: Window,
}

/// The coefficients in iblkit's convention and as the requested format's text.
#[derive(Clone, Debug, PartialEq)]
pub struct ShOutput {
    /// In iblkit's convention.
    pub file: ShFile,
    /// The text of the requested format.
    pub text: String,
    /// Bands the text holds (3 for every format but json).
    pub bands_written: usize,
}

/// Projects or reads, converts, and formats. `output`, when given, is checked against the input
/// first and written atomically.
pub fn spherical_harmonics(
    o: &ShOptions,
    output: Option<&Path>,
    progress: &dyn Progress,
) -> Result<ShOutput> {
    if o.bands == 0 || o.bands > MAX_BANDS {
        return Err(PipelineError::parameter(format!(
            "--bands must be between 1 and {MAX_BANDS}"
        )));
    }
    if o.format != ShFileFormat::Json && (o.bands != 3 || o.quantity == ShQuantity::Irradiance) {
        // Issue 13: `--bands 5` used to write 3 bands silently.
        return Err(PipelineError::parameter(format!(
            "--format {} holds exactly 3 bands of radiance (9 coefficients); got --bands {}{} \
             (use --format json for other band counts and for irradiance)",
            o.format.name(),
            o.bands,
            if o.quantity == ShQuantity::Irradiance {
                " and --irradiance"
            } else {
                ""
            }
        )));
    }
    let input = match &o.source {
        ShSource::Probe(p, _) | ShSource::File(p, _) => p,
    };
    if let Some(out) = output {
        crate::output_paths::check_output_path(out, &[input.as_path()])?;
    }
    let file = match &o.source {
        ShSource::File(path, from) => read_back(o, path, *from)?,
        ShSource::Probe(path, mapping) => project(o, path, *mapping, progress)?,
    };
    let text = format_sh(o.format, &file)
        .map_err(|e| PipelineError::parameter(format!("--format {}: {e}", o.format.name())))?;
    if let Some(out) = output {
        ibl_io::write_atomically(out, text.as_bytes())?;
    }
    Ok(ShOutput {
        bands_written: if o.format == ShFileFormat::Json {
            file.bands
        } else {
            3
        },
        file,
        text,
    })
}

/// Projects the probe and applies the window (and the Lambert factors for irradiance).
fn project(
    o: &ShOptions,
    path: &Path,
    mapping: Option<EnvMapping>,
    progress: &dyn Progress,
) -> Result<ShFile> {
    let env = load_probe(path, mapping, progress)?.env;
    let sh = project_latlong(&env.image, o.bands).context(path.display().to_string())?;
    let coefficients = match o.quantity {
        ShQuantity::Irradiance => sh.irradiance(o.window).coefficients().to_vec(),
        ShQuantity::Radiance => windowed(&sh, o.window),
    };
    Ok(ShFile {
        format: SH_FORMAT.to_string(),
        convention: SH_CONVENTION.to_string(),
        frame: "gltf".to_string(),
        quantity: o.quantity,
        bands: o.bands,
        window: o.window.name().to_string(),
        probe: Some(ProbeRef {
            path: path.display().to_string(),
            width: env.image.width(),
            height: env.image.height(),
            sha256: ibl_io::light_file::sha256_file(path)?,
        }),
        coefficients,
    })
}

/// Radiance coefficients with band `l` times the window's weight (`ibl sh`'s radiance output).
pub fn windowed(sh: &RadianceSh, window: Window) -> Vec<[f64; 3]> {
    let bands = sh.bands();
    sh.coefficients()
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let l = (k as f64).sqrt() as usize;
            c.map(|v| v * window.weight(l, bands))
        })
        .collect()
}

/// Reads an SH file back into iblkit's convention (radiance; irradiance when asked).
fn read_back(o: &ShOptions, path: &Path, from: ShFileFormat) -> Result<ShFile> {
    let mut file = ibl_io::read_sh_file(path, from)?;
    if o.window != Window::None {
        return Err(PipelineError::parameter(
            "--window applies when projecting a probe, not with --from",
        ));
    }
    if o.quantity == ShQuantity::Irradiance && file.quantity == ShQuantity::Radiance {
        let sh = RadianceSh::new(file.bands, file.coefficients.clone())
            .map_err(|e| PipelineError::parameter(format!("{}: {e}", path.display())))?;
        file.coefficients = sh.irradiance(Window::None).coefficients().to_vec();
        file.quantity = ShQuantity::Irradiance;
    }
    Ok(file)
}
