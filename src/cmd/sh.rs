//! `ibl sh`: spherical-harmonic lighting from a lat-long probe in iblkit's JSON or another tool's
//! convention, and read back from any of them (`ibl_pipeline::sh`).

use std::path::PathBuf;

use clap::Args;
use ibl_io::{ShFileFormat, ShQuantity};
use ibl_pipeline::sh::{ShOptions, ShSource, spherical_harmonics};
use ibl_sh::Window;

use crate::probe_arg::ProbeMappingArgs;
use crate::progress::Bars;
use crate::values;

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
    /// The probe (lat-long or any mapping `--mapping` names), or with `--from` an SH file.
    pub input: PathBuf,
    #[command(flatten)]
    pub probe_mapping: ProbeMappingArgs,
    /// Read `INPUT` as an SH file in this format instead of projecting a probe.
    #[arg(long, value_name = "FORMAT", value_parser = values::sh_format)]
    pub from: Option<ShFileFormat>,
    /// Output format.
    #[arg(long, default_value = "json", value_name = "FORMAT", value_parser = values::sh_format)]
    pub format: ShFileFormat,
    /// Bands to project (3 = 9 coefficients; formats other than json take 3).
    #[arg(long, default_value_t = 3, value_name = "B")]
    pub bands: usize,
    /// Write irradiance coefficients `A_l c_lm` instead of radiance (json only).
    #[arg(long)]
    pub irradiance: bool,
    /// Window the bands against ringing: none, lanczos or hann.
    #[arg(long, default_value = "none", value_name = "WINDOW", value_parser = values::window)]
    pub window: Window,
    /// Output file (default: stdout).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// Runs `ibl sh`.
pub fn run(args: &ShArgs) -> anyhow::Result<()> {
    let options = ShOptions {
        source: match args.from {
            Some(format) => ShSource::File(args.input.clone(), format),
            None => ShSource::Probe(args.input.clone(), args.probe_mapping.mapping()?),
        },
        format: args.format,
        bands: args.bands,
        quantity: if args.irradiance {
            ShQuantity::Irradiance
        } else {
            ShQuantity::Radiance
        },
        window: args.window,
    };
    let out = spherical_harmonics(&options, args.output.as_deref(), &Bars::default())?;
    match &args.output {
        Some(path) => eprintln!(
            "wrote {} ({} SH, {} bands)",
            path.display(),
            args.format.name(),
            out.bands_written
        ),
        None => print!("{}", out.text),
    }
    Ok(())
}
