//! `ibl capture`: making a light probe with a camera: `merge` (bracketed 8-bit exposures to HDR,
//! `ibl_pipeline::capture`), `ball` (mirror-ball photographs unwrapped and merged) and `fisheye`
//! (two opposite fisheyes or one dual-fisheye frame stitched; `ibl_pipeline::capture_views`).

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use ibl_capture::ball::Circle;
use ibl_capture::merge::Weighting;
use ibl_core::EulerDegrees;
use ibl_pipeline::PipelineError;
use ibl_pipeline::capture::{ExposureTimes, MergeJob, Response, merge_bracket};
use ibl_pipeline::capture_views::{
    BallJob, BallView, FisheyeJob, default_yaws, stitch_fisheyes, unwrap_balls,
};
use ibl_pipeline::exposure_list::TimeUnit;

use crate::values::{self, AngleList, ExposureList, ResponseArg};

/// What the numbers of a `--times-file` are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TimeUnitArg {
    /// Seconds (`1/250` is 4 ms).
    Seconds,
    /// 1 / seconds, as OpenCV's list.txt holds them (`250` is 4 ms).
    InverseSeconds,
}

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
  ibl capture merge memorial*.png --times-file list.txt -o hdr.exr   OpenCV's list (1/seconds)
  ibl capture merge *.jpg -o hdr.exr --response curve.csv --align --deghost

--times-file takes numbers or fractions in image order, or `name value` lines matched to the
images by file name: OpenCV's list.txt (values 1/seconds, as its HDR tutorial reads them) and
`name seconds` lists such as exposure_times_seconds.txt. A two-column file's unit comes from
--times-unit, else from its name (list.txt: inverse-seconds; a name with `seconds`: seconds).

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
    #[arg(long, value_name = "LIST", value_parser = values::exposure_times)]
    pub times: Option<ExposureList>,
    /// A file of exposure times: numbers or fractions in image order, or `name value` lines
    /// (OpenCV's list.txt, `name seconds` lists), matched by file name.
    #[arg(long, value_name = "FILE")]
    pub times_file: Option<PathBuf>,
    /// The unit of the --times-file values (default: seconds, or what a two-column file's name
    /// says: list.txt is OpenCV's inverse seconds).
    #[arg(long, value_enum, value_name = "UNIT")]
    pub times_unit: Option<TimeUnitArg>,
    /// The camera response: `recover` (Debevec & Malik), `linear` (RAW-like data) or a CSV file
    /// written by --response-out.
    #[arg(
        long,
        default_value = "recover",
        value_name = "recover|linear|FILE",
        value_parser = values::response
    )]
    pub response: ResponseArg,
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
    #[arg(long, value_name = "X,Y,R", value_parser = values::circle)]
    pub circle: Vec<Circle>,
    /// Yaw of each view in degrees, comma-separated (default 0 for one view, 0,90 for two, ...).
    #[arg(long, value_name = "LIST", value_parser = values::angles)]
    pub yaw: Option<AngleList>,
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
    #[arg(long, value_name = "Y,P,R", allow_hyphen_values = true, value_parser = values::rotation)]
    pub back_rotate: Option<EulerDegrees>,
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

fn run_merge(args: &MergeArgs) -> anyhow::Result<()> {
    let job = MergeJob {
        images: args.images.clone(),
        output: args.output.clone(),
        times: match (&args.times, &args.times_file) {
            (Some(list), _) => ExposureTimes::Given(list.0.clone()),
            (None, Some(file)) => ExposureTimes::File(
                file.clone(),
                args.times_unit.map(|u| match u {
                    TimeUnitArg::Seconds => TimeUnit::Seconds,
                    TimeUnitArg::InverseSeconds => TimeUnit::InverseSeconds,
                }),
            ),
            (None, None) => ExposureTimes::Exif,
        },
        response: match &args.response {
            ResponseArg::Recover => Response::Recover {
                smoothness: args.smoothness,
            },
            ResponseArg::Linear => Response::Linear,
            ResponseArg::File(path) => Response::Given(path.clone()),
        },
        response_out: args.response_out.clone(),
        weighting: match args.weighting {
            WeightingArg::Hat => Weighting::Hat,
            WeightingArg::NoiseAware => Weighting::NoiseAware,
        },
        black: args.black,
        saturation: args.saturation,
        align: args.align,
        deghost: args.deghost,
    };
    let summary = merge_bracket(&job)?;
    if !super::print_json(args.json, &summary)? {
        println!(
            "merged {} exposures ({} x {}, times from {}): {:.1} stops, {} saturated and {} black \
             pixels; wrote {}",
            summary.images,
            summary.width,
            summary.height,
            summary.times_from,
            summary.dynamic_range_stops,
            summary.saturated_pixels,
            summary.black_pixels,
            summary.outputs.join(", ")
        );
    }
    Ok(())
}

fn run_ball(args: &BallArgs) -> anyhow::Result<()> {
    let n = args.photos.len();
    if !args.circle.is_empty() && args.circle.len() != n {
        return Err(PipelineError::parameter(format!(
            "{} --circle values for {n} photos: give one per photo or none",
            args.circle.len()
        ))
        .into());
    }
    let yaws = args
        .yaw
        .as_ref()
        .map_or_else(|| default_yaws(n), |y| y.0.clone());
    if yaws.len() != n {
        return Err(PipelineError::parameter(format!(
            "--yaw: expected {n} finite angles, one per photo"
        ))
        .into());
    }
    let job = BallJob {
        views: args
            .photos
            .iter()
            .zip(yaws)
            .enumerate()
            .map(|(k, (photo, yaw_deg))| BallView {
                photo: photo.clone(),
                circle: args.circle.get(k).copied(),
                yaw_deg,
            })
            .collect(),
        output: args.output.clone(),
        width: args.width,
    };
    let s = unwrap_balls(&job)?;
    match args.json {
        true => println!("{}", serde_json::to_string_pretty(&s)?),
        false => print!("{}", s.text()),
    }
    Ok(())
}

fn run_fisheye(args: &FisheyeArgs) -> anyhow::Result<()> {
    let job = FisheyeJob {
        front: args.front.clone(),
        back: args.back.clone(),
        output: args.output.clone(),
        fov_deg: args.fov,
        back_rotation: args.back_rotate.unwrap_or_default(),
        blend_deg: args.blend,
        width: args.width,
    };
    let probe = stitch_fisheyes(&job)?;
    let outputs = &probe.outputs;
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "width": probe.width,
                "height": probe.height,
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
            probe.width,
            probe.height,
            outputs[0].display(),
            outputs[1].display()
        );
    }
    Ok(())
}
