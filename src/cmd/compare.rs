//! `ibl compare`: error metrics of a test image against a reference of the same size (a render
//! against the path-traced ground truth, a light set's render against the probe's, ...). Prints
//! RMSE, relative MSE (`(a - b)^2 / (b^2 + 0.01)`), mean and largest absolute error, PSNR and the
//! FLIP perceptual difference (mean and percentiles; `ibl_eval::flip`), over every pixel or over a
//! mask; optionally writes a per-pixel error image of one metric, false-coloured (.png, .jpg) or
//! raw (.exr, .hdr, .pfm).
//!
//! FLIP runs in its LDR mode when both inputs are 8-bit pictures (PNG or JPEG) and in its HDR mode
//! (a bracket of tone-mapped exposures) otherwise. Cost O(W H) for the pixel metrics plus
//! O(n W H k) for FLIP (n exposures, k filter taps).

use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::{Args, ValueEnum};
use ibl_core::{Image, Rgb};
use ibl_eval::flip::{MAX_PIXELS_PER_DEGREE, MIN_PIXELS_PER_DEGREE};
use ibl_eval::{
    DEFAULT_PIXELS_PER_DEGREE, FlipOptions, FlipRange, ImageDifference, MapStatistics,
    RELATIVE_MSE_EPSILON,
};
use ibl_io::{ImageFormat, LoadedImage, WriteOptions};
use serde::Serialize;

use crate::failure::usage;

/// The per-pixel metric of `--error-image`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
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

/// Smallest mask luminance that selects a pixel.
const MASK_THRESHOLD: f32 = 0.5;

/// FLIP part of the summary.
#[derive(Serialize)]
struct FlipSummary {
    mean: f64,
    p50: f64,
    p90: f64,
    p99: f64,
    max: f64,
    pixels_per_degree: f64,
    /// `ldr` or `hdr`.
    range: &'static str,
    /// Exposures of the HDR mode, stops.
    exposures: Vec<f64>,
}

/// The error image written.
#[derive(Serialize)]
struct ErrorImage {
    path: String,
    metric: MetricArg,
    /// `false-colour` or `raw`.
    encoding: &'static str,
    /// Value drawn as the top colour (false colour only).
    scale_top: Option<f64>,
}

/// What `--json` prints.
#[derive(Serialize)]
struct Summary {
    test: String,
    reference: String,
    mask: Option<String>,
    width: usize,
    height: usize,
    /// Pixels compared (all, or those in the mask).
    pixels: u64,
    rmse: f64,
    relative_mse: f64,
    relative_mse_epsilon: f64,
    mean_abs: f64,
    max_abs: f64,
    /// `10 log10(peak^2 / mse)`, peak = largest reference channel value; null when identical.
    psnr_db: Option<f64>,
    flip: FlipSummary,
    error_image: Option<ErrorImage>,
}

/// Runs `ibl compare`.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    if !(MIN_PIXELS_PER_DEGREE..=MAX_PIXELS_PER_DEGREE).contains(&args.ppd) {
        return Err(usage(format!(
            "--ppd must be between {MIN_PIXELS_PER_DEGREE} and {MAX_PIXELS_PER_DEGREE}"
        )));
    }
    let mut inputs = vec![args.test.as_path(), args.reference.as_path()];
    inputs.extend(args.mask.as_deref());
    let out_format = match &args.error_image {
        Some(out) => {
            ibl_io::ensure_output_is_not_input(out, &inputs)?;
            Some(ImageFormat::from_path(out).ok_or_else(|| {
                usage(format!(
                    "{}: an error image is written as .png, .jpg, .exr, .hdr or .pfm",
                    out.display()
                ))
            })?)
        }
        None => None,
    };
    let test = ibl_io::read_image(&args.test)?;
    let reference = ibl_io::read_image(&args.reference)?;
    let (w, h) = (reference.image.width(), reference.image.height());
    if (test.image.width(), test.image.height()) != (w, h) {
        return Err(usage(format!(
            "{} is {} x {} but the reference {} is {w} x {h}; compare needs equal sizes",
            args.test.display(),
            test.image.width(),
            test.image.height(),
            args.reference.display(),
        )));
    }
    let mask = args
        .mask
        .as_deref()
        .map(|path| load_mask(path, w, h))
        .transpose()?;
    let in_files = |e: ibl_eval::DifferenceError| {
        usage(format!(
            "{} against {}: {e}",
            args.test.display(),
            args.reference.display()
        ))
    };
    let difference =
        ImageDifference::between(&test.image, &reference.image, mask.as_ref()).map_err(in_files)?;

    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message("FLIP");
    spinner.enable_steady_tick(Duration::from_millis(120));
    let range = if is_ldr(&test) && is_ldr(&reference) {
        FlipRange::Ldr
    } else {
        FlipRange::Hdr
    };
    let options = FlipOptions {
        pixels_per_degree: args.ppd,
        range,
    };
    let flip = ibl_eval::flip(&test.image, &reference.image, &options).map_err(in_files)?;
    let flip_stats = MapStatistics::of(&flip.map, mask.as_ref()).map_err(in_files)?;
    spinner.finish_and_clear();

    let error_image = match (&args.error_image, out_format) {
        (Some(out), Some(format)) => {
            let map = match args.metric {
                MetricArg::Flip => flip.map.clone(),
                MetricArg::Relmse => {
                    ibl_eval::relative_squared_error_map(&test.image, &reference.image)
                        .map_err(in_files)?
                }
                MetricArg::Abs => {
                    ibl_eval::absolute_error_map(&test.image, &reference.image).map_err(in_files)?
                }
            };
            Some(write_error_image(
                out,
                format,
                &map,
                args.metric,
                mask.as_ref(),
            )?)
        }
        _ => None,
    };

    let summary = Summary {
        test: args.test.display().to_string(),
        reference: args.reference.display().to_string(),
        mask: args.mask.as_ref().map(|m| m.display().to_string()),
        width: w,
        height: h,
        pixels: difference.pixels,
        rmse: difference.rmse,
        relative_mse: difference.relative_mse,
        relative_mse_epsilon: RELATIVE_MSE_EPSILON,
        mean_abs: difference.mean_abs,
        max_abs: difference.max_abs,
        psnr_db: difference.psnr_db,
        flip: FlipSummary {
            mean: flip_stats.mean,
            p50: flip_stats.p50,
            p90: flip_stats.p90,
            p99: flip_stats.p99,
            max: flip_stats.max,
            pixels_per_degree: args.ppd,
            range: range.name(),
            exposures: flip.exposures,
        },
        error_image,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_text(&summary);
    }
    if let Some(e) = &summary.error_image {
        eprintln!("wrote {}", e.path);
    }
    Ok(())
}

/// Whether an input is an 8-bit picture (display-referred).
fn is_ldr(loaded: &LoadedImage) -> bool {
    matches!(loaded.format, ImageFormat::Png | ImageFormat::Jpeg)
}

/// Reads a mask: true where the luminance is at least [`MASK_THRESHOLD`]; its size must be
/// `w` x `h`.
fn load_mask(path: &Path, w: usize, h: usize) -> anyhow::Result<Image<bool>> {
    let image = ibl_io::read_image(path)?.image;
    if (image.width(), image.height()) != (w, h) {
        return Err(usage(format!(
            "{}: the mask is {} x {} but the images are {w} x {h}",
            path.display(),
            image.width(),
            image.height()
        )));
    }
    Ok(image.map(|p| p.luminance() >= MASK_THRESHOLD))
}

/// Writes the error map: false colour for 8-bit formats (top of the scale 1 for FLIP and relMSE,
/// the 99th percentile for the absolute error), grey raw values otherwise.
fn write_error_image(
    out: &Path,
    format: ImageFormat,
    map: &Image<f32>,
    metric: MetricArg,
    mask: Option<&Image<bool>>,
) -> anyhow::Result<ErrorImage> {
    let path = out.display().to_string();
    match format {
        ImageFormat::Png | ImageFormat::Jpeg => {
            let top = match metric {
                MetricArg::Flip | MetricArg::Relmse => 1.0,
                MetricArg::Abs => {
                    let s =
                        MapStatistics::of(map, mask).map_err(|e| usage(format!("{path}: {e}")))?;
                    if s.p99 > 0.0 { s.p99 } else { s.max }
                }
            };
            let picture = ibl_eval::false_colour(map, top, mask);
            let bytes = if format == ImageFormat::Png {
                ibl_io::ldr::encode_png(&picture)
            } else {
                ibl_io::ldr::encode_jpeg(&picture, ibl_io::ldr::JPEG_QUALITY)
            }
            .map_err(|e| e.with_path(out))?;
            ibl_io::write_atomically(out, &bytes)?;
            Ok(ErrorImage {
                path,
                metric,
                encoding: "false-colour",
                scale_top: Some(top),
            })
        }
        ImageFormat::Exr
        | ImageFormat::Hdr
        | ImageFormat::Pfm
        | ImageFormat::Ktx2
        | ImageFormat::Dds => {
            let grey = map.map(|&v| Rgb::splat(v));
            ibl_io::write_image(out, &grey, &WriteOptions::default())?;
            Ok(ErrorImage {
                path,
                metric,
                encoding: "raw",
                scale_top: None,
            })
        }
    }
}

fn print_text(s: &Summary) {
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
