//! `ibl capture`: making a light probe with a camera (`ibl-capture`).
//!
//! - `merge`: bracketed 8-bit exposures (PNG/JPEG) into one HDR image (Debevec & Malik 1997):
//!   exposure times from EXIF, `--times` or `--times-file`; the response recovered, linear or
//!   given as CSV; optional alignment (Ward 2003) and ghost suppression; writes the HDR, its
//!   preview, and the response curve (CSV, SVG and PNG chart).
//! - `ball`: one or more mirror-ball photographs (HDR, or 8-bit decoded as sRGB) unwrapped to
//!   lat-long; several views taken from different sides merged by reliability, so the camera and
//!   the photographer disappear.
//! - `fisheye`: two opposite equidistant fisheye images, or one dual-fisheye frame, stitched to
//!   lat-long with a feathered seam.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use clap::{Args, Subcommand, ValueEnum};
use ibl_capture::CaptureError;
use ibl_capture::align::{AlignOptions, align_bracket, apply_shift};
use ibl_capture::ball::{Circle, find_ball, merge_views, unwrap_ball};
use ibl_capture::fisheye::{FisheyeOptions, stitch_fisheye_pair};
use ibl_capture::ghost::{GhostOptions, ghost_weights};
use ibl_capture::merge::{MergeOptions, Weighting, merge};
use ibl_capture::response::{RecoverOptions, ResponseCurve};
use ibl_core::{Image, Rgb};
use ibl_io::{Display, ToneCurve, WriteOptions};
use serde::Serialize;

use crate::cmd::convert::parse_rotation;
use crate::failure::usage;

/// Arguments of `ibl capture`.
#[derive(Args)]
pub struct CaptureArgs {
    /// What to capture.
    #[command(subcommand)]
    pub command: CaptureCommand,
}

/// The capture subcommands.
#[derive(Subcommand)]
pub enum CaptureCommand {
    /// Merge bracketed 8-bit exposures into one HDR image.
    Merge(MergeArgs),
    /// Unwrap mirror-ball photographs to a lat-long probe (several views merged).
    Ball(BallArgs),
    /// Stitch two opposite fisheye images (or one dual-fisheye frame) to lat-long.
    Fisheye(FisheyeArgs),
}

/// How the camera's response is known.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WeightingArg {
    /// Debevec & Malik's triangle.
    Hat,
    /// The triangle times the exposure time (inverse photon-noise variance).
    NoiseAware,
}

/// Arguments of `ibl capture merge`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl capture merge IMG_1*.jpg -o probe.exr                  times from EXIF, response recovered
  ibl capture merge a.png b.png c.png --times 1/250,1/60,1/15 -o hdr.exr --response-out curve.csv
  ibl capture merge *.png --times-file times.txt --response linear -o hdr.exr
  ibl capture merge *.jpg -o hdr.exr --response curve.csv --align --deghost

Writes OUT, OUT's .png preview and (recovered or not) the response curve as
<OUT stem>-response.csv/.svg/.png unless --response-out names the CSV.")]
pub struct MergeArgs {
    /// The exposures (PNG or JPEG, same size), any order.
    #[arg(required = true)]
    pub images: Vec<PathBuf>,
    /// Output HDR image (.exr, .hdr, .pfm).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: PathBuf,
    /// Exposure times in seconds, one per image in order (`1/250,1/60,0.25`); overrides EXIF.
    #[arg(long, value_name = "LIST")]
    pub times: Option<String>,
    /// A file of exposure times (numbers or fractions, separated by commas, spaces or lines).
    #[arg(long, value_name = "FILE")]
    pub times_file: Option<PathBuf>,
    /// The camera response: `recover` (Debevec & Malik), `linear` (RAW-like data) or a CSV file
    /// written by --response-out.
    #[arg(long, default_value = "recover", value_name = "recover|linear|FILE")]
    pub response: String,
    /// Where to write the response curve (CSV; an SVG and a PNG chart go beside it).
    #[arg(long, value_name = "FILE")]
    pub response_out: Option<PathBuf>,
    /// Smoothness weight lambda of the response recovery.
    #[arg(long, default_value_t = 50.0, value_name = "LAMBDA")]
    pub smoothness: f64,
    /// Weighting of the exposures.
    #[arg(long, value_enum, default_value = "hat")]
    pub weighting: WeightingArg,
    /// Codes at or below this carry no information (black level).
    #[arg(long, default_value_t = 2, value_name = "CODE")]
    pub black: u8,
    /// Codes at or above this are saturated.
    #[arg(long, default_value_t = 250, value_name = "CODE")]
    pub saturation: u8,
    /// Align hand-held exposures first (median threshold bitmaps, integer shifts).
    #[arg(long)]
    pub align: bool,
    /// Suppress ghosts (things that moved between exposures).
    #[arg(long)]
    pub deghost: bool,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `ibl capture ball`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl capture ball ball.exr -o probe.exr                        the ball found automatically
  ibl capture ball ball.exr -o probe.exr --circle 812,604,377   the ball given (x, y, radius px)
  ibl capture ball front.exr side.exr --yaw 0,90 -o probe.exr   two views 90 degrees apart merged

Each view is a photo of the ball from the side given by --yaw (degrees about +Y; the first view
defines the probe's frame: its camera is behind the viewer, +Z). The rim and the direction back
to the camera (where the photographer stands) are unreliable; with two or more views the merge
takes each direction from the view that saw it best. Writes OUT, OUT's .png preview and
<OUT stem>-reliability.png for each view.")]
pub struct BallArgs {
    /// Mirror-ball photographs (HDR .exr/.hdr/.pfm, or PNG/JPEG decoded as sRGB).
    #[arg(required = true)]
    pub photos: Vec<PathBuf>,
    /// Output lat-long probe.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: PathBuf,
    /// The ball in each photo as `x,y,r` in pixels (repeat once per photo, in order); default:
    /// found automatically.
    #[arg(long, value_name = "X,Y,R")]
    pub circle: Vec<String>,
    /// Yaw of each view in degrees, comma-separated (default 0 for one view, 0,90 for two, ...).
    #[arg(long, value_name = "LIST")]
    pub yaw: Option<String>,
    /// Width of the lat-long output.
    #[arg(long, default_value_t = 1024, value_name = "W")]
    pub width: usize,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `ibl capture fisheye`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl capture fisheye front.exr back.exr -o probe.exr --fov 195
  ibl capture fisheye gear360.png -o probe.exr --fov 195 --width 2048   one dual-fisheye frame
  ibl capture fisheye f.exr b.exr -o p.exr --fov 200 --back-rotate 0.5,-0.3,0 --blend 8")]
pub struct FisheyeArgs {
    /// The front fisheye (looks -Z), or one dual-fisheye frame (2:1, front circle left).
    pub front: PathBuf,
    /// The back fisheye (looks +Z).
    pub back: Option<PathBuf>,
    /// Output lat-long probe.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: PathBuf,
    /// Field of view of each lens, degrees (more than 180).
    #[arg(long, value_name = "DEG")]
    pub fov: f32,
    /// Small rotation of the back lens from ideal, yaw,pitch,roll degrees.
    #[arg(long, value_name = "Y,P,R")]
    pub back_rotate: Option<String>,
    /// Width of the seam's feather, degrees.
    #[arg(long, default_value_t = 10.0, value_name = "DEG")]
    pub blend: f32,
    /// Width of the lat-long output.
    #[arg(long, default_value_t = 2048, value_name = "W")]
    pub width: usize,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `ibl capture`.
pub fn run(args: &CaptureArgs) -> anyhow::Result<()> {
    match &args.command {
        CaptureCommand::Merge(a) => run_merge(a),
        CaptureCommand::Ball(a) => run_ball(a),
        CaptureCommand::Fisheye(a) => run_fisheye(a),
    }
}

/// A capture error, as bad input (exit 2) or an internal failure, naming what it is about.
fn capture_error(what: &str, e: CaptureError) -> anyhow::Error {
    if e.is_bad_input() {
        usage(format!("{what}: {e}"))
    } else {
        anyhow::anyhow!("{what}: {e}")
    }
}

/// Writes `image` and a tone-mapped PNG preview beside it; returns the preview's path.
fn write_with_preview(path: &Path, image: &Image<Rgb>) -> anyhow::Result<PathBuf> {
    ibl_io::write_image(path, image, &WriteOptions::default())?;
    let preview = path.with_extension("png");
    let display = WriteOptions {
        display: Display {
            exposure_stops: ibl_io::tonemap::auto_exposure_stops(image),
            curve: ToneCurve::Reinhard,
        },
        ..WriteOptions::default()
    };
    ibl_io::write_image(&preview, image, &display)?;
    Ok(preview)
}

/// `<stem><suffix>` beside `path`.
fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or("out".to_string(), |s| s.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}{suffix}"))
}

/// What `capture merge --json` prints.
#[derive(Serialize)]
struct MergeSummary {
    images: usize,
    width: usize,
    height: usize,
    exposure_times_s: Vec<f64>,
    times_from: &'static str,
    response: String,
    shifts: Vec<(i32, i32)>,
    saturated_pixels: usize,
    black_pixels: usize,
    dynamic_range_stops: f64,
    seconds: f64,
    outputs: Vec<String>,
}

fn run_merge(args: &MergeArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let csv = args
        .response_out
        .clone()
        .unwrap_or_else(|| sibling(&args.output, "-response.csv"));
    let outputs = vec![
        args.output.clone(),
        args.output.with_extension("png"),
        csv.clone(),
        csv.with_extension("svg"),
        csv.with_extension("png"),
    ];
    let mut inputs: Vec<&Path> = args.images.iter().map(PathBuf::as_path).collect();
    if let Some(t) = &args.times_file {
        inputs.push(t);
    }
    let given_curve = match args.response.as_str() {
        "recover" | "linear" => None,
        file => Some(PathBuf::from(file)),
    };
    if let Some(c) = &given_curve {
        inputs.push(c);
    }
    for out in &outputs {
        ibl_io::ensure_output_is_not_input(out, &inputs)?;
    }

    let photos = args
        .images
        .iter()
        .map(|p| ibl_io::photo::read_photo(p))
        .collect::<Result<Vec<_>, _>>()?;
    let (w, h) = (photos[0].codes.width(), photos[0].codes.height());
    for (p, photo) in args.images.iter().zip(&photos) {
        if (photo.codes.width(), photo.codes.height()) != (w, h) {
            return Err(usage(format!(
                "{}: {} x {}, but {} is {w} x {h}: a bracket's exposures must have the same size",
                p.display(),
                photo.codes.width(),
                photo.codes.height(),
                args.images[0].display()
            )));
        }
    }
    let (times, times_from) = exposure_times(args, &photos)?;

    let mut codes: Vec<Image<[u8; 3]>> = photos.into_iter().map(|p| p.codes).collect();
    let mut valid: Option<Vec<Image<bool>>> = None;
    let mut shifts = vec![(0, 0); codes.len()];
    if args.align {
        let found = align_bracket(&codes, &AlignOptions::default())
            .map_err(|e| capture_error("aligning the exposures", e))?;
        let mut masks = Vec::new();
        for (image, shift) in codes.iter_mut().zip(&found) {
            let (aligned, mask) = apply_shift(image, *shift);
            *image = aligned;
            masks.push(mask);
        }
        shifts = found.iter().map(|s| (s.dx, s.dy)).collect();
        valid = Some(masks);
    }

    let curve = match (args.response.as_str(), &given_curve) {
        ("recover", _) => ResponseCurve::recover(
            &codes,
            &times,
            &RecoverOptions {
                smoothness: args.smoothness,
                ..RecoverOptions::default()
            },
        )
        .map_err(|e| capture_error("--response recover", e))?,
        ("linear", _) => {
            ResponseCurve::linear(256).map_err(|e| capture_error("the linear response", e))?
        }
        (_, Some(path)) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("{}: cannot read the response curve", path.display()))
                .map_err(|e| usage(format!("{e:#}")))?;
            ResponseCurve::from_csv(&text)
                .map_err(|e| capture_error(&path.display().to_string(), e))?
        }
        _ => return Err(usage("--response: expected recover, linear or a CSV file")),
    };

    let mut weights: Option<Vec<Image<f32>>> = valid.map(|masks| {
        masks
            .iter()
            .map(|m| m.map(|&ok| if ok { 1.0 } else { 0.0 }))
            .collect()
    });
    if args.deghost {
        let times32: Vec<f32> = times.iter().map(|&t| t as f32).collect();
        let exposure = |channel: usize, code: u8| curve.exposure_of(code as usize)[channel];
        let ghosts = ghost_weights(&codes, &times32, &exposure, &GhostOptions::default())
            .map_err(|e| capture_error("suppressing ghosts", e))?;
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
        weighting: match args.weighting {
            WeightingArg::Hat => Weighting::Hat,
            WeightingArg::NoiseAware => Weighting::NoiseAware,
        },
        black_level: args.black,
        saturation_level: args.saturation,
        pixel_weights: weights,
    };
    let merged = merge(&codes, &times, &curve, &options)
        .map_err(|e| capture_error("merging the exposures", e))?;

    write_with_preview(&args.output, &merged.image)?;
    ibl_io::write_atomically(&csv, curve.to_csv().as_bytes())?;
    let g = curve.log_exposure();
    let title = format!("camera response ({})", args.response);
    let svg = ibl_eval::response_plot::response_svg(g, &title)?;
    ibl_io::write_atomically(&csv.with_extension("svg"), svg.as_bytes())?;
    let png = ibl_io::ldr::encode_png(&ibl_eval::response_plot::response_png(g, &title)?)
        .context("encoding the response chart")?;
    ibl_io::write_atomically(&csv.with_extension("png"), &png)?;

    let lum: Vec<f32> = merged
        .image
        .pixels()
        .iter()
        .map(|p| p.luminance())
        .filter(|&l| l > 0.0)
        .collect();
    let (lo, hi) = lum.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &l| {
        (lo.min(l), hi.max(l))
    });
    let stops = if lo.is_finite() && hi > lo {
        f64::from(hi / lo).log2()
    } else {
        0.0
    };
    let summary = MergeSummary {
        images: codes.len(),
        width: w,
        height: h,
        exposure_times_s: times,
        times_from,
        response: args.response.clone(),
        shifts,
        saturated_pixels: merged.saturated_pixels,
        black_pixels: merged.black_pixels,
        dynamic_range_stops: stops,
        seconds: started.elapsed().as_secs_f64(),
        outputs: outputs.iter().map(|p| p.display().to_string()).collect(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "merged {} exposures ({} x {}, times from {}): {:.1} stops, {} saturated and {} black \
             pixels; wrote {}",
            summary.images,
            w,
            h,
            summary.times_from,
            stops,
            summary.saturated_pixels,
            summary.black_pixels,
            summary.outputs.join(", ")
        );
    }
    Ok(())
}

/// The exposure times: `--times`, `--times-file`, or every photo's EXIF.
fn exposure_times(
    args: &MergeArgs,
    photos: &[ibl_io::photo::Photo],
) -> anyhow::Result<(Vec<f64>, &'static str)> {
    let (times, from) = if let Some(list) = &args.times {
        let t = ibl_io::photo::parse_exposure_times(list)
            .map_err(|e| usage(format!("--times: {e}")))?;
        (t, "--times")
    } else if let Some(path) = &args.times_file {
        let text = std::fs::read_to_string(path).map_err(|e| {
            usage(format!(
                "{}: cannot read exposure times: {e}",
                path.display()
            ))
        })?;
        let t = ibl_io::photo::parse_exposure_times(&text)
            .map_err(|e| usage(format!("{}: {e}", path.display())))?;
        (t, "--times-file")
    } else {
        let mut t = Vec::new();
        for (p, photo) in args.images.iter().zip(photos) {
            t.push(photo.exposure_time_s.ok_or_else(|| {
                usage(format!(
                    "{}: no exposure time in its EXIF: give --times or --times-file",
                    p.display()
                ))
            })?);
        }
        (t, "EXIF")
    };
    if times.len() != args.images.len() {
        return Err(usage(format!(
            "{} exposure times for {} images (from {from})",
            times.len(),
            args.images.len()
        )));
    }
    Ok((times, from))
}

/// Parses `x,y,r`.
fn parse_circle(text: &str) -> anyhow::Result<Circle> {
    let v: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage(format!("--circle `{text}`: expected x,y,r in pixels")))?;
    match v.as_slice() {
        &[cx, cy, r] if cx.is_finite() && cy.is_finite() && r.is_finite() && r > 0.0 => {
            Ok(Circle { cx, cy, r })
        }
        _ => Err(usage(format!(
            "--circle `{text}`: expected x,y,r in pixels"
        ))),
    }
}

/// What `capture ball --json` prints.
#[derive(Serialize)]
struct BallSummary {
    views: Vec<BallView>,
    width: usize,
    outputs: Vec<String>,
}

#[derive(Serialize)]
struct BallView {
    photo: String,
    circle: Circle,
    found: bool,
    yaw_deg: f32,
    reliable_fraction: f64,
}

fn run_ball(args: &BallArgs) -> anyhow::Result<()> {
    let n = args.photos.len();
    if !args.circle.is_empty() && args.circle.len() != n {
        return Err(usage(format!(
            "{} --circle values for {n} photos: give one per photo or none",
            args.circle.len()
        )));
    }
    let yaws: Vec<f32> = match &args.yaw {
        Some(list) => list
            .split(',')
            .map(|p| p.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| usage(format!("--yaw `{list}`: expected degrees, e.g. 0,90")))?,
        None => (0..n).map(|k| 90.0 * k as f32).collect(),
    };
    if yaws.len() != n || yaws.iter().any(|y| !y.is_finite()) {
        return Err(usage(format!(
            "--yaw: expected {n} finite angles, one per photo"
        )));
    }
    let mut outputs = vec![args.output.clone(), args.output.with_extension("png")];
    for k in 0..n {
        outputs.push(sibling(&args.output, &format!("-reliability-{k}.png")));
    }
    let inputs: Vec<&Path> = args.photos.iter().map(PathBuf::as_path).collect();
    for out in &outputs {
        ibl_io::ensure_output_is_not_input(out, &inputs)?;
    }
    let mut views = Vec::new();
    let mut summary = Vec::new();
    for (k, path) in args.photos.iter().enumerate() {
        let photo = ibl_io::read_image(path)?.image;
        let (circle, found) = match args.circle.get(k) {
            Some(text) => (parse_circle(text)?, false),
            None => (
                find_ball(&photo).map_err(|e| capture_error(&path.display().to_string(), e))?,
                true,
            ),
        };
        let unwrapped = unwrap_ball(&photo, circle, args.width)
            .map_err(|e| capture_error(&path.display().to_string(), e))?;
        let reliable = unwrapped
            .reliability
            .pixels()
            .iter()
            .filter(|&&r| r > 0.5)
            .count();
        summary.push(BallView {
            photo: path.display().to_string(),
            circle,
            found,
            yaw_deg: yaws[k],
            reliable_fraction: reliable as f64 / unwrapped.reliability.len().max(1) as f64,
        });
        let grey: Image<Rgb> = unwrapped.reliability.map(|&r| Rgb::splat(r));
        ibl_io::write_image(&outputs[2 + k], &grey, &WriteOptions::default())?;
        views.push((unwrapped, yaws[k]));
    }
    let probe = merge_views(&views).map_err(|e| capture_error("merging the views", e))?;
    write_with_preview(&args.output, &probe)?;
    let s = BallSummary {
        views: summary,
        width: args.width,
        outputs: outputs.iter().map(|p| p.display().to_string()).collect(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        for v in &s.views {
            println!(
                "{}: ball at ({:.1}, {:.1}) radius {:.1} px ({}), yaw {} deg, {:.0} % of the sphere reliable",
                v.photo,
                v.circle.cx,
                v.circle.cy,
                v.circle.r,
                if v.found { "found" } else { "given" },
                v.yaw_deg,
                100.0 * v.reliable_fraction
            );
        }
        println!("wrote {}", s.outputs.join(", "));
    }
    Ok(())
}

fn run_fisheye(args: &FisheyeArgs) -> anyhow::Result<()> {
    let mut inputs: Vec<&Path> = vec![&args.front];
    if let Some(b) = &args.back {
        inputs.push(b);
    }
    let outputs = [args.output.clone(), args.output.with_extension("png")];
    for out in &outputs {
        ibl_io::ensure_output_is_not_input(out, &inputs)?;
    }
    let front = ibl_io::read_image(&args.front)?.image;
    let back = match &args.back {
        Some(p) => Some(ibl_io::read_image(p)?.image),
        None => None,
    };
    let options = FisheyeOptions {
        fov_deg: args.fov,
        back_rotation: match &args.back_rotate {
            Some(r) => parse_rotation(r)?,
            None => ibl_core::EulerDegrees::default(),
        },
        width: args.width,
        blend_deg: args.blend,
    };
    let probe = stitch_fisheye_pair(&front, back.as_ref(), options)
        .map_err(|e| capture_error(&args.front.display().to_string(), e))?;
    write_with_preview(&args.output, &probe)?;
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "width": probe.width(),
                "height": probe.height(),
                "fov_deg": args.fov,
                "pair": args.back.is_some(),
                "outputs": outputs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            })
        );
    } else {
        println!(
            "stitched {} to {} x {}; wrote {}, {}",
            if args.back.is_some() {
                "a fisheye pair"
            } else {
                "a dual-fisheye frame"
            },
            probe.width(),
            probe.height(),
            outputs[0].display(),
            outputs[1].display()
        );
    }
    Ok(())
}
