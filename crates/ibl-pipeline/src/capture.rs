//! Merging bracketed exposures into an HDR probe (`ibl capture merge`; Debevec & Malik 1997):
//! exposure times from EXIF or given; the camera's response recovered, linear or read from a CSV;
//! optional alignment (Ward 2003, median threshold bitmaps) and ghost suppression; then the HDR
//! image, its preview, the response curve (CSV, SVG and PNG chart) and the range the merge
//! covers. Mirror balls and fisheye pairs are [`crate::capture_views`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_capture::align::{AlignOptions, align_bracket, apply_shift};
use ibl_capture::ghost::{GhostOptions, ghost_weights};
use ibl_capture::merge::{MergeOptions, Weighting, merge};
use ibl_capture::response::{RecoverOptions, ResponseCurve};
use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_io::WriteOptions;
use serde::Serialize;

use crate::error::{Context, PipelineError, Result};
use crate::exposure_list::{TimeUnit, parse_times_file};

/// How the camera's response is known.
#[derive(Clone, Debug, PartialEq)]
pub enum Response {
    /// Recovered from the exposures (Debevec & Malik), with this smoothness weight lambda.
    Recover {
        /// Smoothness weight of the recovery.
        smoothness: f64,
    },
    /// Linear (RAW-like data).
    Linear,
    /// A curve written earlier (`<stem>-response.csv`).
    Given(PathBuf),
}

impl Response {
    /// `recover`, `linear` or the curve file, as the user named it.
    pub fn name(&self) -> String {
        match self {
            Response::Recover { .. } => "recover".to_string(),
            Response::Linear => "linear".to_string(),
            Response::Given(path) => path.display().to_string(),
        }
    }
}

/// Where the exposure times come from.
#[derive(Clone, Debug, PartialEq)]
pub enum ExposureTimes {
    /// Every photo's EXIF.
    Exif,
    /// Given, in seconds, one per image in order.
    Given(Vec<f64>),
    /// A file of numbers or fractions, or of `name value` lines ([`crate::exposure_list`]), in
    /// the unit given (`None`: seconds, or what a two-column file's name says).
    File(PathBuf, Option<TimeUnit>),
}

/// What to merge.
#[derive(Clone, Debug, PartialEq)]
pub struct MergeJob {
    /// The exposures (PNG or JPEG, same size), any order.
    pub images: Vec<PathBuf>,
    /// Output HDR image.
    pub output: PathBuf,
    /// Where the exposure times come from.
    pub times: ExposureTimes,
    /// The camera's response.
    pub response: Response,
    /// Where to write the response curve (CSV; an SVG and a PNG chart beside it); default
    /// `<output stem>-response.csv`.
    pub response_out: Option<PathBuf>,
    /// Weighting of the exposures.
    pub weighting: Weighting,
    /// Codes at or below this carry no information.
    pub black: u8,
    /// Codes at or above this are saturated.
    pub saturation: u8,
    /// Align hand-held exposures first.
    pub align: bool,
    /// Suppress ghosts.
    pub deghost: bool,
}

/// What a merge did (the JSON of `ibl capture merge --json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MergeSummary {
    /// Exposures merged.
    pub images: usize,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Exposure times, seconds.
    pub exposure_times_s: Vec<f64>,
    /// `--times`, `--times-file` or `EXIF`.
    pub times_from: &'static str,
    /// The response: `recover`, `linear` or the curve file.
    pub response: String,
    /// Shift of each exposure, pixels (zero without alignment).
    pub shifts: Vec<(i32, i32)>,
    /// Pixels saturated in every exposure.
    pub saturated_pixels: usize,
    /// Pixels black in every exposure.
    pub black_pixels: usize,
    /// `log2` of the largest over the smallest positive luminance.
    pub dynamic_range_stops: f64,
    /// Seconds the merge took.
    pub seconds: f64,
    /// Files written.
    pub outputs: Vec<String>,
}

/// Largest exposure-times or response-curve file read, bytes.
const MAX_TEXT_BYTES: u64 = 1 << 20;

/// `<stem><suffix>` beside `path`.
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or("out".to_string(), |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}{suffix}"))
}

/// Writes `image` and a tone-mapped PNG preview beside it (automatic exposure, Reinhard);
/// returns the preview's path.
pub fn write_with_preview(path: &Path, image: &Image<Rgb>) -> Result<PathBuf> {
    ibl_io::write_image(path, image, &WriteOptions::default())?;
    let preview = path.with_extension("png");
    let display = WriteOptions {
        display: Display {
            exposure_stops: auto_exposure_stops(image),
            curve: ToneCurve::Reinhard,
        },
        ..WriteOptions::default()
    };
    ibl_io::write_image(&preview, image, &display)?;
    Ok(preview)
}

/// Merges the bracket and writes the HDR image, its preview and the response curve.
pub fn merge_bracket(job: &MergeJob) -> Result<MergeSummary> {
    let started = Instant::now();
    let csv = job
        .response_out
        .clone()
        .unwrap_or_else(|| sibling(&job.output, "-response.csv"));
    let outputs = vec![
        job.output.clone(),
        job.output.with_extension("png"),
        csv.clone(),
        csv.with_extension("svg"),
        csv.with_extension("png"),
    ];
    let mut inputs: Vec<&Path> = job.images.iter().map(PathBuf::as_path).collect();
    if let ExposureTimes::File(t, _) = &job.times {
        inputs.push(t);
    }
    if let Response::Given(c) = &job.response {
        inputs.push(c);
    }
    for out in &outputs {
        crate::output_paths::check_output_path(out, &inputs)?;
    }

    let photos = job
        .images
        .iter()
        .map(|p| ibl_io::photo::read_photo(p))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let Some(first) = photos.first() else {
        return Err(PipelineError::parameter(
            "a bracket needs at least one image",
        ));
    };
    let (w, h) = (first.codes.width(), first.codes.height());
    for (p, photo) in job.images.iter().zip(&photos) {
        if (photo.codes.width(), photo.codes.height()) != (w, h) {
            return Err(PipelineError::parameter(format!(
                "{}: {} x {}, but {} is {w} x {h}: a bracket's exposures must have the same size",
                p.display(),
                photo.codes.width(),
                photo.codes.height(),
                job.images[0].display()
            )));
        }
    }
    let (times, times_from) = exposure_times(job, &photos)?;

    let mut codes: Vec<Image<[u8; 3]>> = photos.into_iter().map(|p| p.codes).collect();
    let mut valid: Option<Vec<Image<bool>>> = None;
    let mut shifts = vec![(0, 0); codes.len()];
    if job.align {
        let found =
            align_bracket(&codes, &AlignOptions::default()).context("aligning the exposures")?;
        let mut masks = Vec::new();
        for (image, shift) in codes.iter_mut().zip(&found) {
            let (aligned, mask) = apply_shift(image, *shift);
            *image = aligned;
            masks.push(mask);
        }
        shifts = found.iter().map(|s| (s.dx, s.dy)).collect();
        valid = Some(masks);
    }

    let curve = match &job.response {
        Response::Recover { smoothness } => ResponseCurve::recover(
            &codes,
            &times,
            &RecoverOptions {
                smoothness: *smoothness,
                ..RecoverOptions::default()
            },
        )
        .context("--response recover")?,
        Response::Linear => ResponseCurve::linear(256).context("the linear response")?,
        Response::Given(path) => {
            let text = ibl_io::read_text(path, MAX_TEXT_BYTES)?;
            ResponseCurve::from_csv(&text).context(path.display().to_string())?
        }
    };

    let mut weights: Option<Vec<Image<f32>>> = valid.map(|masks| {
        masks
            .iter()
            .map(|m| m.map(|&ok| if ok { 1.0 } else { 0.0 }))
            .collect()
    });
    if job.deghost {
        let times32: Vec<f32> = times.iter().map(|&t| t as f32).collect();
        let exposure = |channel: usize, code: u8| curve.exposure_of(code as usize)[channel];
        let ghosts = ghost_weights(&codes, &times32, &exposure, &GhostOptions::default())
            .context("suppressing ghosts")?;
        weights = Some(match weights {
            None => ghosts,
            Some(w) => w
                .iter()
                .zip(&ghosts)
                .map(|(a, b)| {
                    Image::from_fn_par(a.width(), a.height(), |x, y| a.get(x, y) * b.get(x, y))
                })
                .collect(),
        });
    }
    let options = MergeOptions {
        weighting: job.weighting,
        black_level: job.black,
        saturation_level: job.saturation,
        pixel_weights: weights,
    };
    let merged = merge(&codes, &times, &curve, &options).context("merging the exposures")?;

    write_with_preview(&job.output, &merged.image)?;
    ibl_io::write_atomically(&csv, curve.to_csv().as_bytes())?;
    let g = curve.log_exposure();
    let title = format!("camera response ({})", job.response.name());
    let svg = ibl_eval::response_plot::response_svg(g, &title)?;
    ibl_io::write_atomically(&csv.with_extension("svg"), svg.as_bytes())?;
    let chart = csv.with_extension("png");
    let png = ibl_io::ldr::encode_png(&ibl_eval::response_plot::response_png(g, &title)?)
        .map_err(|e| e.with_path(&chart))?;
    ibl_io::write_atomically(&chart, &png)?;

    Ok(MergeSummary {
        images: codes.len(),
        width: w,
        height: h,
        exposure_times_s: times,
        times_from,
        response: job.response.name(),
        shifts,
        saturated_pixels: merged.saturated_pixels,
        black_pixels: merged.black_pixels,
        dynamic_range_stops: dynamic_range_stops(&merged.image),
        seconds: started.elapsed().as_secs_f64(),
        outputs: outputs.iter().map(|p| p.display().to_string()).collect(),
    })
}

/// `log2` of the largest over the smallest positive luminance (0 for a black image).
fn dynamic_range_stops(image: &Image<Rgb>) -> f64 {
    let (lo, hi) = image
        .pixels()
        .iter()
        .map(|p| p.luminance())
        .filter(|&l| l > 0.0)
        .fold((f32::INFINITY, 0.0f32), |(lo, hi), l| {
            (lo.min(l), hi.max(l))
        });
    if lo.is_finite() && hi > lo {
        f64::from(hi / lo).log2()
    } else {
        0.0
    }
}

/// The exposure times and where they came from: given, from a file, or every photo's EXIF.
fn exposure_times(
    job: &MergeJob,
    photos: &[ibl_io::photo::Photo],
) -> Result<(Vec<f64>, &'static str)> {
    let (times, from) = match &job.times {
        ExposureTimes::Given(t) => (t.clone(), "--times"),
        ExposureTimes::File(path, unit) => {
            let text = ibl_io::read_text(path, MAX_TEXT_BYTES)?;
            let (t, _) = parse_times_file(path, &text, &job.images, *unit)?;
            (t, "--times-file")
        }
        ExposureTimes::Exif => {
            let mut t = Vec::new();
            for (p, photo) in job.images.iter().zip(photos) {
                t.push(photo.exposure_time_s.ok_or_else(|| {
                    PipelineError::parameter(format!(
                        "{}: no exposure time in its EXIF: give --times or --times-file",
                        p.display()
                    ))
                })?);
            }
            (t, "EXIF")
        }
    };
    if times.len() != job.images.len() {
        return Err(PipelineError::parameter(format!(
            "{} exposure times for {} images (from {from})",
            times.len(),
            job.images.len()
        )));
    }
    Ok((times, from))
}
