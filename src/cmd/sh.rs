//! `ibl sh`: spherical-harmonic lighting from a lat-long probe, written in iblkit's JSON or in the
//! convention of another tool (three.js, Filament, Unity, WebXR, ARKit, glTF
//! `EXT_lights_image_based`), and read back from any of them (`--from`). The conversions and their
//! sources are in `ibl-io::sh_file` and docs/CONVENTIONS.md section 5b.

use std::path::PathBuf;

use clap::Args;
use ibl_io::light_file::ProbeRef;
use ibl_io::sh_file::{SH_CONVENTION, SH_FORMAT, format_sh};
use ibl_io::{ShFile, ShFileFormat, ShQuantity};
use ibl_mapping::Mapping;
use ibl_sh::{MAX_BANDS, RadianceSh, Window, project_latlong};

use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

/// Arguments of `ibl sh`.
#[derive(Args)]
#[command(after_help = "\
Formats (all but json hold 3 bands, 9 coefficients):
  json       iblkit, any bands, radiance or irradiance
  threejs    three.js LightProbe JSON
  filament   cmgen's sh.txt (pre-scaled irradiance)
  unity      SphericalHarmonicsL2, 27 channel-major floats, Unity's frame
  webxr      27 floats, RGB per coefficient
  arkit      27 floats, channel-major
  gltf-ext   an EXT_lights_image_based light to merge into a glTF file

Examples:
  ibl sh probe.exr                                   SH9 radiance, iblkit JSON on stdout
  ibl sh probe.exr --bands 5 --irradiance -o e.json  irradiance coefficients, 5 bands
  ibl sh probe.exr --format filament -o sh.txt       Filament's pre-scaled irradiance
  ibl sh probe.exr --format threejs -o probe.json    three.js ObjectLoader / LightProbe.fromJSON
  ibl sh --from filament sh.txt --format unity       convert between tools")]
pub struct ShArgs {
    /// Lat-long probe (.exr, .hdr, .pfm), or with `--from` an SH file.
    pub input: PathBuf,
    /// Read `INPUT` as an SH file in this format instead of projecting a probe.
    #[arg(long, value_name = "FORMAT")]
    pub from: Option<String>,
    /// Output format.
    #[arg(long, default_value = "json", value_name = "FORMAT")]
    pub format: String,
    /// Bands to project (3 = 9 coefficients; formats other than json take 3).
    #[arg(long, default_value_t = 3, value_name = "B")]
    pub bands: usize,
    /// Write irradiance coefficients `A_l c_lm` instead of radiance (json only).
    #[arg(long)]
    pub irradiance: bool,
    /// Window the bands against ringing: none, lanczos or hann.
    #[arg(long, default_value = "none", value_name = "WINDOW")]
    pub window: String,
    /// Output file (default: stdout).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// Parses a format name, as a usage error naming the option when unknown.
fn parse_format(name: &str, option: &str) -> anyhow::Result<ShFileFormat> {
    ShFileFormat::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = ShFileFormat::ALL.iter().map(|f| f.name()).collect();
        usage(format!(
            "{option} {name}: unknown SH format (expected one of: {})",
            names.join(", ")
        ))
    })
}

/// Runs `ibl sh`.
pub fn run(args: &ShArgs) -> anyhow::Result<()> {
    let format = parse_format(&args.format, "--format")?;
    let window: Window = args.window.parse().map_err(usage)?;
    if args.bands == 0 || args.bands > MAX_BANDS {
        return Err(usage(format!("--bands must be between 1 and {MAX_BANDS}")));
    }
    if format != ShFileFormat::Json && (args.bands < 3 || args.irradiance) {
        return Err(usage(format!(
            "--format {}: holds 3 bands of radiance (use --bands 3 or more, and no --irradiance)",
            format.name()
        )));
    }
    if let Some(out) = &args.output {
        ibl_io::ensure_output_is_not_input(out, &[args.input.as_path()])?;
    }
    let file = match &args.from {
        Some(from) => read_back(args, parse_format(from, "--from")?, window)?,
        None => project(args, window)?,
    };
    let text =
        format_sh(format, &file).map_err(|e| usage(format!("--format {}: {e}", format.name())))?;
    match &args.output {
        Some(out) => {
            ibl_io::write_atomically(out, text.as_bytes())?;
            eprintln!(
                "wrote {} ({} SH, {} bands)",
                out.display(),
                format.name(),
                if format == ShFileFormat::Json {
                    file.bands
                } else {
                    3
                }
            );
        }
        None => print!("{text}"),
    }
    Ok(())
}

/// Projects the probe and applies the window (and the Lambert factors with `--irradiance`).
fn project(args: &ShArgs, window: Window) -> anyhow::Result<ShFile> {
    let env = envmap_files::load(&args.input, Some(MappingArg::Single(Mapping::LatLong)))?;
    crate::cmd::convert::report_clamped(&env);
    let sh = project_latlong(&env.image, args.bands)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.input.display()))?;
    let coefficients = if args.irradiance {
        sh.irradiance(window).coefficients().to_vec()
    } else {
        windowed(&sh, window)
    };
    Ok(ShFile {
        format: SH_FORMAT.to_string(),
        convention: SH_CONVENTION.to_string(),
        frame: "gltf".to_string(),
        quantity: if args.irradiance {
            ShQuantity::Irradiance
        } else {
            ShQuantity::Radiance
        },
        bands: args.bands,
        window: window.name().to_string(),
        probe: Some(ProbeRef {
            path: args.input.display().to_string(),
            width: env.image.width(),
            height: env.image.height(),
            sha256: ibl_io::light_file::sha256_file(&args.input)?,
        }),
        coefficients,
    })
}

/// Radiance coefficients with band `l` times the window's weight.
fn windowed(sh: &RadianceSh, window: Window) -> Vec<[f64; 3]> {
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

/// Reads an SH file back into iblkit's convention (radiance; irradiance with `--irradiance`).
fn read_back(args: &ShArgs, from: ShFileFormat, window: Window) -> anyhow::Result<ShFile> {
    let mut file = ibl_io::read_sh_file(&args.input, from)?;
    if window != Window::None {
        return Err(usage(
            "--window applies when projecting a probe, not with --from",
        ));
    }
    if args.irradiance && file.quantity == ShQuantity::Radiance {
        let sh = RadianceSh::new(file.bands, file.coefficients.clone())
            .map_err(|e| usage(format!("{}: {e}", args.input.display())))?;
        file.coefficients = sh.irradiance(Window::None).coefficients().to_vec();
        file.quantity = ShQuantity::Irradiance;
    }
    Ok(file)
}
