//! `ibl compare`: error metrics of an image against a reference of the same size (RMSE, relative
//! MSE, absolute errors, PSNR, FLIP) and an optional error image (`ibl_pipeline::compare`).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use ibl_metrics::DEFAULT_PIXELS_PER_DEGREE;
use ibl_pipeline::compare::{CompareOptions, CompareSummary, ErrorMetric, compare};

use crate::progress::Bars;

/// The per-pixel metric of `--error-image`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MetricArg {
    /// FLIP perceptual difference, in [0, 1].
    Flip,
    /// Relative squared error `(a - b)^2 / (b^2 + 0.01)`, mean over channels.
    Relmse,
    /// Absolute error `|a - b|`, mean over channels, in image units.
    Abs,
}

/// Arguments of `ibl compare`.
#[derive(Args)]
#[command(after_help = "\
The second image is the reference. Both must have the same size; any readable format.
Error images: .png/.jpg show the metric on the viridis scale (0 dark purple; yellow at 1 for flip
and relmse, at the 99th percentile for abs); .exr/.hdr/.pfm hold the raw per-pixel values (grey).
Mask: pixels whose luminance is at least 0.5 are compared.

Examples:
  ibl compare render.exr reference.exr
  ibl compare render.exr reference.exr --error-image flip.png
  ibl compare render.exr reference.exr --metric relmse --error-image relmse.exr
  ibl compare a.png b.png --mask object.png --json | jq .flip.mean
  ibl compare render.exr reference.exr --ppd 30      # a phone held at arm's length")]
pub struct CompareArgs {
    /// The image under test (.exr, .hdr, .pfm, .png, .jpg).
    pub test: PathBuf,
    /// The reference image, same size.
    pub reference: PathBuf,
    /// Write a per-pixel error image of `--metric` (.png/.jpg false colour, .exr/.hdr/.pfm raw).
    #[arg(long, value_name = "FILE")]
    pub error_image: Option<PathBuf>,
    /// Metric shown in the error image.
    #[arg(long, value_enum, default_value = "flip")]
    pub metric: MetricArg,
    /// Compare only the pixels where this image (same size) has luminance >= 0.5.
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// FLIP viewing condition, pixels per degree (67: 0.7 m from a 0.7 m wide 4K monitor).
    #[arg(long, default_value_t = DEFAULT_PIXELS_PER_DEGREE, value_name = "PPD")]
    pub ppd: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `ibl compare`.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let options = CompareOptions {
        test: args.test.clone(),
        reference: args.reference.clone(),
        error_image: args.error_image.clone(),
        metric: match args.metric {
            MetricArg::Flip => ErrorMetric::Flip,
            MetricArg::Relmse => ErrorMetric::Relmse,
            MetricArg::Abs => ErrorMetric::Abs,
        },
        mask: args.mask.clone(),
        pixels_per_degree: args.ppd,
    };
    let summary = compare(&options, &Bars::default())?;
    if !super::print_json(args.json, &summary)? {
        print_text(&summary);
    }
    if let Some(e) = &summary.error_image {
        eprintln!("wrote {}", e.path);
    }
    Ok(())
}

fn print_text(s: &CompareSummary) {
    println!("test        {}", s.test);
    println!("reference   {}", s.reference);
    let masked = s
        .mask
        .as_ref()
        .map(|m| format!(" (mask {m})"))
        .unwrap_or_default();
    println!(
        "size        {} x {}, {} pixels compared{masked}",
        s.width, s.height, s.pixels
    );
    println!("rmse        {:.6e}", s.rmse);
    println!(
        "rel. mse    {:.6e}   (a - b)^2 / (b^2 + {})",
        s.relative_mse, s.relative_mse_epsilon
    );
    println!("mean |a-b|  {:.6e}", s.mean_abs);
    println!("max |a-b|   {:.6e}", s.max_abs);
    match s.psnr_db {
        Some(p) => println!("psnr        {p:.3} dB   (peak = largest reference value)"),
        None => println!("psnr        -   (identical, or black reference)"),
    }
    let f = &s.flip;
    let exposures = match (f.exposures.first(), f.exposures.last()) {
        (Some(a), Some(b)) => format!(", {} exposures {a:+.2} .. {b:+.2} stops", f.exposures.len()),
        _ => String::new(),
    };
    println!(
        "flip        mean {:.5}, p50 {:.5}, p90 {:.5}, p99 {:.5}, max {:.5}   ({}, {} ppd{exposures})",
        f.mean, f.p50, f.p90, f.p99, f.max, f.range, f.pixels_per_degree
    );
}
