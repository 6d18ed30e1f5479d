//! `ibl room`: the reconstructed room of Grosch 2005 section 3 (`docs/ROOMS.md`): `calibrate`
//! (marks to frame and scale), `estimate` (room and probe to reflectance and the report),
//! `lights` (the important patches as an area-light file), `render` (the room after material
//! changes, with new lights or from a moved camera). The jobs are `ibl_pipeline::room_calibrate`,
//! `room_estimate`, `room_lights` and `room_render`.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use ibl_pipeline::room_calibrate::{CalibrateOptions, room_calibrate};
use ibl_pipeline::room_estimate::{EstimateOptions, SamplingOptions, room_estimate};
use ibl_pipeline::room_lights::{RoomLightsOptions, room_lights};
use ibl_pipeline::room_render::{RoomRenderOptions, room_render};

use crate::progress::Bars;

/// Arguments of `ibl room`.
#[derive(Args)]
pub struct RoomArgs {
    #[command(subcommand)]
    command: RoomCommand,
}

#[derive(Subcommand)]
enum RoomCommand {
    /// Marks file to the probe's frame (vanishing points, residuals) and scale; the room file.
    Calibrate(CalibrateArgs),
    /// Room file and probe to per-patch radiosity and reflectance: report and pictures.
    Estimate(EstimateArgs),
    /// The room's N important light patches as an area-light file for `ibl render --lights`.
    Lights(LightsArgs),
    /// The room re-rendered after material changes (with colour bleeding), with new IES/LDT
    /// lights and virtual objects, or from a moved camera.
    Render(RenderArgs),
}

/// Arguments of `ibl room render`.
#[derive(Args)]
#[command(after_help = "\
The edits file (docs/ROOMS.md sections 11 to 13): [[material]] changes with colour bleeding,
[[light]] IES/EULUMDAT lights with shadows and bounced light, [[object]] virtual objects (display =
\"improved\" or \"fast\"), and a [view] from a moved camera (else the edited probe is the output).

Examples:
  ibl room render assets/rooms/apartment/room.toml --edit assets/rooms/apartment/edits.toml -o a.png --before b.png
  ibl room render assets/rooms/apartment/room.toml --edit assets/rooms/apartment/edits-light.toml -o lit.png
  ibl room render assets/rooms/apartment/room.toml --edit assets/rooms/apartment/edits-object.toml -o bunny.png --json")]
struct RenderArgs {
    /// Room file (.toml).
    room: PathBuf,
    /// Edits file (.toml); none: the room as estimated.
    #[arg(long, value_name = "EDITS.toml")]
    edit: Option<PathBuf>,
    /// The picture after the edits (.exr, .hdr, .pfm, .png, .jpg).
    #[arg(short = 'o', long, value_name = "FILE")]
    output: PathBuf,
    /// Also the picture before the edits.
    #[arg(long, value_name = "FILE")]
    before: Option<PathBuf>,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Arguments of `ibl room calibrate`.
#[derive(Args)]
#[command(after_help = "\
The marks file (iblkit.room-marks/1, docs/ROOMS.md) holds line segments marked in perspective
views of the probe, each assigned to an axis, scale marks (points at a known height) and shapes
placed by constraints. The residuals say how well each line fits its axis: a line far above the
others is probably assigned to the wrong axis.

Examples:
  ibl room calibrate assets/rooms/apartment/marks.json
  ibl room calibrate assets/rooms/apartment/marks.json -o room.toml --propose
  ibl room calibrate marks.json --json > calibration.json")]
struct CalibrateArgs {
    /// Marks file (.json).
    marks: PathBuf,
    /// Write the room file the marked shapes make (.toml; the probe named relative to it).
    #[arg(short = 'o', long, value_name = "ROOM.toml")]
    output: Option<PathBuf>,
    /// Also propose the frame automatically from segments detected in the probe, and compare.
    #[arg(long)]
    propose: bool,
    /// Print the calibration, scale and proposal as JSON on stdout instead of text.
    #[arg(long)]
    json: bool,
}

/// Form-factor sampling, shared by `estimate` and `lights`.
#[derive(Args)]
struct SamplingArgs {
    /// Form-factor rays per patch (rounded to a^2 b^2 strata of position and direction).
    #[arg(long, default_value_t = SamplingOptions::default().rays_per_patch, value_name = "K")]
    rays_per_patch: u32,
    /// Seed of the rays' jitter (the same seed gives the same estimate on any thread count).
    #[arg(long, default_value_t = SamplingOptions::default().seed, value_name = "SEED")]
    seed: u64,
}

impl SamplingArgs {
    fn options(&self) -> SamplingOptions {
        SamplingOptions {
            rays_per_patch: self.rays_per_patch,
            seed: self.seed,
        }
    }
}

/// Arguments of `ibl room estimate`.
#[derive(Args)]
#[command(after_help = "\
Writes into the folder: report.json and report.md (reflectance per group and iteration, like
Grosch's Table 1, and the important patches), rho-panorama.png (patches coloured by reflectance,
hidden ones hatched), overlay.png (the model's edges on the probe), cutaway.png (the room from
above). The room file names its probe relative to itself.

Examples:
  ibl room estimate assets/rooms/apartment/room.toml -o apartment-room
  ibl room estimate assets/rooms/synthetic/room.toml -o synthetic --important 16 --json")]
struct EstimateArgs {
    /// Room file (.toml with `[probe]` and `[room]`).
    room: PathBuf,
    /// Output folder (created if missing).
    #[arg(short = 'o', long, value_name = "DIR")]
    output: PathBuf,
    /// Important patches listed in the report.
    #[arg(long, default_value_t = 16, value_name = "N")]
    important: usize,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Print the report as JSON on stdout instead of its Markdown.
    #[arg(long)]
    json: bool,
}

/// Arguments of `ibl room lights`.
#[derive(Args)]
#[command(after_help = "\
The area-light file (iblkit.area-lights/1, CONVENTIONS section 7) holds per patch its position,
normal, area, radiance L = B / pi (the probe file's units) and corners, in the room's frame.
`ibl render --lights FILE` reads it as directional lights seen from the probe's centre.

Examples:
  ibl room lights assets/rooms/apartment/room.toml -n 32 -o apartment-lights.json
  ibl render assets/scenes/bunny-sky.toml -o b.exr --mode lights --lights apartment-lights.json")]
struct LightsArgs {
    /// Room file (.toml with `[probe]` and `[room]`).
    room: PathBuf,
    /// Area-light file to write (.json).
    #[arg(short = 'o', long, value_name = "FILE.json")]
    output: PathBuf,
    /// Number of important patches (highest luminous flux B A first).
    #[arg(short = 'n', long, default_value_t = 32, value_name = "N")]
    count: usize,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Print a JSON summary on stdout instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs `ibl room ...`.
pub fn run(args: &RoomArgs) -> anyhow::Result<()> {
    match &args.command {
        RoomCommand::Calibrate(a) => calibrate(a),
        RoomCommand::Estimate(a) => estimate(a),
        RoomCommand::Lights(a) => lights(a),
        RoomCommand::Render(a) => render(a),
    }
}

fn render(a: &RenderArgs) -> anyhow::Result<()> {
    let options = RoomRenderOptions {
        room: a.room.clone(),
        edits: a.edit.clone(),
        output: a.output.clone(),
        before: a.before.clone(),
        sampling: a.sampling.options(),
    };
    let result = room_render(&options, &Bars::default())?;
    match a.json {
        true => println!("{:#}", serde_json::to_value(&result)?),
        false => print!("{}", result.text()),
    }
    Ok(())
}

fn calibrate(a: &CalibrateArgs) -> anyhow::Result<()> {
    let result = room_calibrate(
        &CalibrateOptions {
            marks: a.marks.clone(),
            room_output: a.output.clone(),
            propose: a.propose,
        },
        &Bars::default(),
    )?;
    match a.json {
        true => println!("{}", serde_json::to_string_pretty(&result)?),
        false => print!("{}", result.text()),
    }
    Ok(())
}

fn estimate(a: &EstimateArgs) -> anyhow::Result<()> {
    let result = room_estimate(
        &EstimateOptions {
            room: a.room.clone(),
            out_dir: a.output.clone(),
            important: a.important,
            sampling: a.sampling.options(),
        },
        &Bars::default(),
    )?;
    if a.json {
        println!("{}", result.report.to_json()?);
    } else {
        println!("{}", result.report.to_markdown());
        println!(
            "{} patches in {:.2} s; wrote {}",
            result.report.patches,
            result.seconds,
            a.output.display()
        );
    }
    Ok(())
}

fn lights(a: &LightsArgs) -> anyhow::Result<()> {
    let result = room_lights(
        &RoomLightsOptions {
            room: a.room.clone(),
            output: a.output.clone(),
            count: a.count,
            sampling: a.sampling.options(),
        },
        &Bars::default(),
    )?;
    match a.json {
        true => println!("{:#}", result.summary_json(&a.room, &a.output)),
        false => print!("{}", result.text(&a.output)),
    }
    Ok(())
}
