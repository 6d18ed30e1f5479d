//! Error metrics of a test image against a reference of the same size (`ibl compare`): RMSE,
//! relative MSE (`(a - b)^2 / (b^2 + 0.01)`), mean and largest absolute error, PSNR and the FLIP
//! perceptual difference (mean and percentiles; `ibl_metrics::flip`), over every pixel or over a
//! mask; optionally a per-pixel error image of one metric, false-coloured (.png, .jpg) or raw
//! (.exr, .hdr, .pfm).
//!
//! FLIP runs in its LDR mode when both inputs are 8-bit pictures (PNG or JPEG) and in its HDR mode
//! (a bracket of tone-mapped exposures) otherwise. Cost O(W H) for the pixel metrics plus
//! O(n W H k) for FLIP (n exposures, k filter taps).

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_io::{ImageFormat, LoadedImage, WriteOptions};
use ibl_metrics::flip::{MAX_PIXELS_PER_DEGREE, MIN_PIXELS_PER_DEGREE};
use ibl_metrics::{
    FlipOptions, FlipRange, ImageDifference, MapStatistics, RELATIVE_MSE_EPSILON,
    absolute_error_map, relative_squared_error_map,
};
use serde::Serialize;

use crate::error::{Context, PipelineError, Result};
use crate::progress::{self, Progress};

/// The per-pixel metric of an error image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ErrorMetric {
    /// FLIP perceptual difference, in [0, 1].
    Flip,
    /// Relative squared error `(a - b)^2 / (b^2 + 0.01)`, mean over channels.
    Relmse,
    /// Absolute error `|a - b|`, mean over channels, in image units.
    Abs,
}

/// What to compare.
#[derive(Clone, Debug, PartialEq)]
pub struct CompareOptions {
    /// The image under test.
    pub test: PathBuf,
    /// The reference, same size.
    pub reference: PathBuf,
    /// Where to write a per-pixel error image.
    pub error_image: Option<PathBuf>,
    /// The metric the error image shows.
    pub metric: ErrorMetric,
    /// Compare only where this image has luminance >= [`MASK_THRESHOLD`].
    pub mask: Option<PathBuf>,
    /// FLIP viewing condition, pixels per degree.
    pub pixels_per_degree: f64,
}

/// Smallest mask luminance that selects a pixel.
pub const MASK_THRESHOLD: f32 = 0.5;

/// FLIP part of the summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FlipSummary {
    /// Mean of the map.
    pub mean: f64,
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest value.
    pub max: f64,
    /// Viewing condition.
    pub pixels_per_degree: f64,
    /// `ldr` or `hdr`.
    pub range: &'static str,
    /// Exposures of the HDR mode, stops.
    pub exposures: Vec<f64>,
}

/// The error image written.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorImage {
    /// Where.
    pub path: String,
    /// Which metric.
    pub metric: ErrorMetric,
    /// `false-colour` or `raw`.
    pub encoding: &'static str,
    /// Value drawn as the top colour (false colour only).
    pub scale_top: Option<f64>,
}

/// Everything a comparison measured (the JSON of `ibl compare --json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompareSummary {
    /// The test image, as given.
    pub test: String,
    /// The reference, as given.
    pub reference: String,
    /// The mask, as given.
    pub mask: Option<String>,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Pixels compared (all, or those in the mask).
    pub pixels: u64,
    /// Root mean squared error, image units.
    pub rmse: f64,
    /// Relative MSE.
    pub relative_mse: f64,
    /// Its `eps`.
    pub relative_mse_epsilon: f64,
    /// Mean absolute error.
    pub mean_abs: f64,
    /// Largest absolute error.
    pub max_abs: f64,
    /// `10 log10(peak^2 / mse)`, peak = largest reference channel value; null when identical.
    pub psnr_db: Option<f64>,
    /// FLIP.
    pub flip: FlipSummary,
    /// The error image, if one was written.
    pub error_image: Option<ErrorImage>,
}

/// Measures and writes the error image.
pub fn compare(o: &CompareOptions, progress: &dyn Progress) -> Result<CompareSummary> {
    if !(MIN_PIXELS_PER_DEGREE..=MAX_PIXELS_PER_DEGREE).contains(&o.pixels_per_degree) {
        return Err(PipelineError::parameter(format!(
            "--ppd must be between {MIN_PIXELS_PER_DEGREE} and {MAX_PIXELS_PER_DEGREE}"
        )));
    }
    let mut inputs = vec![o.test.as_path(), o.reference.as_path()];
    inputs.extend(o.mask.as_deref());
    let out_format = match &o.error_image {
        Some(out) => {
            crate::output_paths::check_output_path(out, &inputs)?;
            Some(ImageFormat::from_path(out).ok_or_else(|| {
                PipelineError::parameter(format!(
                    "{}: an error image is written as .png, .jpg, .exr, .hdr or .pfm",
                    out.display()
                ))
            })?)
        }
        None => None,
    };
    let test = ibl_io::read_image(&o.test)?;
    let reference = ibl_io::read_image(&o.reference)?;
    let (w, h) = (reference.image.width(), reference.image.height());
    if (test.image.width(), test.image.height()) != (w, h) {
        return Err(PipelineError::parameter(format!(
            "{} is {} x {} but the reference {} is {w} x {h}; compare needs equal sizes",
            o.test.display(),
            test.image.width(),
            test.image.height(),
            o.reference.display(),
        )));
    }
    let mask = o
        .mask
        .as_deref()
        .map(|path| load_mask(path, w, h))
        .transpose()?;
    let pair = format!("{} against {}", o.test.display(), o.reference.display());
    let difference =
        ImageDifference::between(&test.image, &reference.image, mask.as_ref()).context(&pair)?;
    let range = if is_ldr(&test) && is_ldr(&reference) {
        FlipRange::Ldr
    } else {
        FlipRange::Hdr
    };
    let options = FlipOptions {
        pixels_per_degree: o.pixels_per_degree,
        range,
    };
    let (flip, flip_stats) = progress::task(progress, "FLIP", || {
        let flip = ibl_metrics::flip(&test.image, &reference.image, &options)?;
        let stats = MapStatistics::of(&flip.map, mask.as_ref())?;
        Ok::<_, ibl_metrics::DifferenceError>((flip, stats))
    })
    .context(&pair)?;

    let error_image = match (&o.error_image, out_format) {
        (Some(out), Some(format)) => {
            let map = match o.metric {
                ErrorMetric::Flip => flip.map.clone(),
                ErrorMetric::Relmse => {
                    relative_squared_error_map(&test.image, &reference.image).context(&pair)?
                }
                ErrorMetric::Abs => {
                    absolute_error_map(&test.image, &reference.image).context(&pair)?
                }
            };
            Some(write_error_image(
                out,
                format,
                &map,
                o.metric,
                mask.as_ref(),
            )?)
        }
        _ => None,
    };
    Ok(CompareSummary {
        test: o.test.display().to_string(),
        reference: o.reference.display().to_string(),
        mask: o.mask.as_ref().map(|m| m.display().to_string()),
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
            pixels_per_degree: o.pixels_per_degree,
            range: range.name(),
            exposures: flip.exposures,
        },
        error_image,
    })
}

/// Whether an input is an 8-bit picture (display-referred).
fn is_ldr(loaded: &LoadedImage) -> bool {
    matches!(loaded.format, ImageFormat::Png | ImageFormat::Jpeg)
}

/// Reads a mask: true where the luminance is at least [`MASK_THRESHOLD`]; its size must be
/// `w` x `h`.
fn load_mask(path: &Path, w: usize, h: usize) -> Result<Image<bool>> {
    let image = ibl_io::read_image(path)?.image;
    if (image.width(), image.height()) != (w, h) {
        return Err(PipelineError::parameter(format!(
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
    metric: ErrorMetric,
    mask: Option<&Image<bool>>,
) -> Result<ErrorImage> {
    let path = out.display().to_string();
    match format {
        ImageFormat::Png | ImageFormat::Jpeg => {
            let top = match metric {
                ErrorMetric::Flip | ErrorMetric::Relmse => 1.0,
                ErrorMetric::Abs => {
                    let s = MapStatistics::of(map, mask).context(&path)?;
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
