//! `ibl irradiance`: the irradiance a Lambertian surface receives from a lat-long probe, on
//! Fibonacci normals (CSV) or as an irradiance map in any mapping (`ibl_pipeline::irradiance`).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use ibl_pipeline::EnvMapping;
use ibl_pipeline::irradiance::{CHECK_NORMALS, IrradianceMethod, IrradianceOptions, irradiance};
use ibl_sh::Window;

use crate::probe_arg::ProbeMappingArgs;
use crate::progress::Bars;
use crate::values;

/// How to compute the irradiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Brute force over every pixel (the ground truth).
    Exact,
    /// The probe reduced to 64 x 32 energy-conserving blocks first (mean error under 0.1 %).
    Fast,
    /// Spherical harmonics: the probe projected on `--bands` bands, Lambert-convolved.
    Sh,
}

/// Arguments of `ibl irradiance`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl irradiance assets/probes/sky.exr --csv sky-E.csv               20000 normals, exact
  ibl irradiance probe.hdr --normals 2000 --method fast --csv E.csv
  ibl irradiance probe.exr -o irr.exr                                 lat-long map, 128 x 64, exact
  ibl irradiance probe.exr -o irr.exr --method sh --bands 3           the usual SH9 irradiance map
  ibl irradiance probe.exr -o irr.hdr --to cube-hcross --width 256    cube cross, faces 64 x 64")]
pub struct IrradianceArgs {
    /// The probe (.exr, .hdr, .pfm, .png, .jpg), lat-long or any mapping `--mapping` names.
    pub probe: PathBuf,
    #[command(flatten)]
    pub probe_mapping: ProbeMappingArgs,
    /// Exact (every pixel), fast (reduced probe) or sh (Lambert-convolved spherical harmonics).
    #[arg(long, value_enum, default_value = "exact")]
    pub method: MethodArg,
    /// SH bands for `--method sh` (3 = the 9 coefficients engines use).
    #[arg(long, default_value_t = 3, value_name = "B")]
    pub bands: usize,
    /// SH window against ringing: none, lanczos or hann.
    #[arg(long, default_value = "none", value_name = "WINDOW", value_parser = values::window)]
    pub window: Window,
    /// Output CSV: a header line, then `nx,ny,nz,r,g,b` per Fibonacci normal (k = 0..M-1).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Number of Fibonacci normals M for `--csv`.
    #[arg(long, default_value_t = ibl_core::fibonacci::DEFAULT_NORMAL_COUNT, value_name = "M")]
    pub normals: usize,
    /// Output irradiance map (.exr, .hdr, .pfm; `{face}` pattern with `--to cube-faces`).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Mapping of the irradiance map: latlong, cube-hcross, cube-vcross, cube-strip, cube-vstrip,
    /// cube-faces, angular, mirror-ball.
    #[arg(long, default_value = "latlong", value_name = "MAPPING")]
    pub to: String,
    /// Width of the irradiance map in pixels (irradiance is smooth: small maps suffice).
    #[arg(long, default_value_t = 128, value_name = "W")]
    pub width: usize,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `ibl irradiance`.
pub fn run(args: &IrradianceArgs) -> anyhow::Result<()> {
    let options = IrradianceOptions {
        probe: args.probe.clone(),
        mapping: args.probe_mapping.mapping()?,
        method: match args.method {
            MethodArg::Exact => IrradianceMethod::Exact,
            MethodArg::Fast => IrradianceMethod::Fast,
            MethodArg::Sh => IrradianceMethod::Sh,
        },
        bands: args.bands,
        window: args.window,
        csv: args.csv.clone(),
        normals: args.normals,
        output: args.output.clone(),
        to: EnvMapping::parse(&args.to, 180.0)?,
        width: args.width,
    };
    let summary = irradiance(&options, &Bars::default())?;
    if !super::print_json(args.json, &summary)? {
        let what = match summary.window {
            Some(window) => format!("sh irradiance ({} bands, window {window})", args.bands),
            None => format!("{} irradiance", options.method.name()),
        };
        let mean = summary.mean_irradiance;
        println!(
            "{what} in {:.2} s; mean E = {:.5e} {:.5e} {:.5e} (over {} normals)",
            summary.seconds, mean[0], mean[1], mean[2], summary.mean_over_normals
        );
        if let (Some(m), Some(x)) = (summary.mean_err_pct, summary.max_err_pct) {
            println!(
                "error against the exact ground truth on {CHECK_NORMALS} normals: mean {m:.3} %, max {x:.3} % of the mean irradiance"
            );
        }
    }
    for o in &summary.outputs {
        eprintln!("wrote {o}");
    }
    Ok(())
}
