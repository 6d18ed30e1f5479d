//! `ibl preview`: an 8-bit sRGB picture of an HDR image, with exposure in stops and a tone curve
//! (`ibl_pipeline::preview`).

use std::path::PathBuf;

use clap::Args;
pub use ibl_viewer::command_line::CurveArg;

/// Arguments of `ibl preview`.
#[derive(Args)]
#[command(after_help = "\
Without --exposure the exposure is automatic (the log-average luminance maps to middle grey).

Examples:
  ibl preview probe.exr probe.png
  ibl preview probe.hdr probe.png --exposure -2 --tonemap clamp
  ibl preview render.exr render.jpg --tonemap aces")]
pub struct PreviewArgs {
    /// HDR input.
    pub input: PathBuf,
    /// 8-bit output (.png or .jpg).
    pub output: PathBuf,
    /// Exposure in stops (the image is multiplied by 2^STOPS).
    #[arg(
        long,
        value_name = "STOPS",
        allow_hyphen_values = true,
        conflicts_with = "auto_exposure"
    )]
    pub exposure: Option<f32>,
    /// Choose the exposure from the image (the default when --exposure is not given).
    #[arg(long)]
    pub auto_exposure: bool,
    /// Tone curve.
    #[arg(long, value_enum, default_value = "reinhard")]
    pub tonemap: CurveArg,
}

/// Runs `ibl preview`.
pub fn run(args: &PreviewArgs) -> anyhow::Result<()> {
    let stops = ibl_pipeline::preview::preview(
        &args.input,
        &args.output,
        args.exposure,
        args.tonemap.into(),
    )?;
    eprintln!(
        "wrote {} (exposure {stops:+.2} stops, {:?})",
        args.output.display(),
        args.tonemap
    );
    Ok(())
}
