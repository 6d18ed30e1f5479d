//! `ibl`: the iblkit command line tool.
//!
//! Each subcommand lives in `src/cmd/`: it parses its arguments, fills the options of one
//! `ibl-pipeline` job, runs it with progress bars, and prints the job's summary (text or JSON).
//! Errors are reported as `ibl: <file>: <problem>` on stderr; the exit code is 2 for bad input or
//! arguments and 1 for internal failures (see `failure.rs`).

mod cmd;
mod failure;
mod probe_arg;
mod progress;
mod values;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Image-based lighting for augmented reality: light probes in, lights and renders out.
#[derive(Parser)]
#[command(name = "ibl", version, about, long_about = None, after_help = EXAMPLES)]
struct Cli {
    /// Refuse images of more pixels than this, before decoding or writing them (default 2^28 =
    /// 268435456; also the IBL_MAX_PIXELS environment variable). A file whose header announces
    /// more is refused at once, whatever its size on disk.
    #[arg(long, global = true, value_name = "N")]
    max_pixels: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

const EXAMPLES: &str = "\
Examples:
  ibl demo                                   run the main job on the bundled probes
  ibl info assets/probes/esplanade.exr       statistics, power and brightest direction
  ibl convert probe.hdr cube.exr --to cube-hcross
  ibl preview probe.exr probe.png --tonemap aces
  ibl lights probe.exr -n 16 -o lights.json
  ibl eval assets/probes/*.exr --out eval     compare every extraction method (report.md)
  ibl batch assets/batch/bundled.toml        lights, SH, previews for a folder of probes
  ibl prefilter probe.exr -o env.ktx2        GGX mip chain, irradiance, SH, DFG for engines
  ibl render assets/scenes/bunny-sky.toml -o bunny.exr   the bunny composited into a probe
  ibl compare render.exr reference.exr       RMSE, relative MSE and FLIP of a render
  ibl capture merge IMG_*.jpg -o probe.exr   bracketed exposures to HDR
  ibl outdoor assets/outdoor/courtyard/scene.toml --out day   sun and sky per frame, composites
  ibl view assets/scenes/bunny-sky.toml      real-time viewer: 16 shadowed lights, edit, save

Limits: images over 2^28 pixels are refused before decoding; lower (or raise) it with
--max-pixels N or IBL_MAX_PIXELS=N.

Exit codes: 0 success, 1 internal failure, 2 bad input or arguments.";

#[derive(Subcommand)]
enum Command {
    /// Describe an HDR image: format, size, mapping, statistics, power, brightest direction.
    Info(cmd::info::InfoArgs),
    /// Convert between file formats and environment-map mappings, with rotation.
    Convert(cmd::convert::ConvertArgs),
    /// Irradiance from a lat-long probe: on Fibonacci normals (CSV) or as a map (exact, fast, SH).
    Irradiance(cmd::irradiance::IrradianceArgs),
    /// Approximate a lat-long probe by N directional lights; write JSON, glTF, Mitsuba or pbrt.
    Lights(cmd::lights::LightsArgs),
    /// Spherical-harmonic lighting of a probe, in iblkit's JSON or another tool's convention.
    Sh(cmd::sh::ShArgs),
    /// Engine-ready maps: GGX specular mip chain (KTX2/DDS), irradiance cube, SH, DFG table.
    Prefilter(cmd::prefilter::PrefilterArgs),
    /// Compare the light extraction methods on probes: error vs N, plots, spheres, report.
    Eval(cmd::eval::EvalArgs),
    /// Run per-probe steps (info, lights, SH, maps, previews, eval) over many probes.
    Batch(cmd::batch::BatchArgs),
    /// Error metrics of an image against a reference: RMSE, relative MSE, FLIP; error images.
    Compare(cmd::compare::CompareArgs),
    /// Make a probe with a camera: merge brackets, unwrap mirror balls, stitch fisheyes.
    Capture(cmd::capture::CaptureArgs),
    /// Render virtual objects into the probe panorama or a photo (reference, lights, hybrid).
    Render(cmd::render::RenderArgs),
    /// The reconstructed room (Grosch 2005): calibrate marks, estimate reflectance, light patches.
    Room(cmd::room::RoomArgs),
    /// Outdoor AR (Jensen et al. 2006): sun and sky per video frame, relit maps, composites.
    Outdoor(cmd::outdoor::OutdoorArgs),
    /// Write a tone-mapped 8-bit preview (PNG or JPEG) of an HDR image.
    Preview(cmd::preview::PreviewArgs),
    /// Run the main job on the bundled probes and write everything to a folder.
    Demo(cmd::demo::DemoArgs),
    /// Real-time viewer: a probe, or a scene composited with a shadow per light (or --headless).
    View(cmd::view::ViewArgs),
}

fn main() -> ExitCode {
    ibl_pipeline::interrupts::install();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version go to stdout with status 0; argument errors use status 2.
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() {
                failure::EXIT_BAD_INPUT
            } else {
                0
            });
        }
    };
    let limit = match cli.max_pixels {
        Some(n) => ibl_io::set_default_max_pixels(n).map_err(|e| format!("--max-pixels: {e}")),
        None => ibl_io::max_pixels_from_environment().map(|_| ()),
    };
    if let Err(e) = limit {
        eprintln!("ibl: {e}");
        return ExitCode::from(failure::EXIT_BAD_INPUT);
    }
    let result = match cli.command {
        Command::Info(args) => cmd::info::run(&args),
        Command::Convert(args) => cmd::convert::run(&args),
        Command::Irradiance(args) => cmd::irradiance::run(&args),
        Command::Lights(args) => cmd::lights::run(&args),
        Command::Sh(args) => cmd::sh::run(&args),
        Command::Prefilter(args) => cmd::prefilter::run(&args),
        Command::Eval(args) => cmd::eval::run(&args),
        Command::Batch(args) => cmd::batch::run(&args),
        Command::Compare(args) => cmd::compare::run(&args),
        Command::Render(args) => cmd::render::run(&args),
        Command::Capture(args) => cmd::capture::run(&args),
        Command::Room(args) => cmd::room::run(&args),
        Command::Outdoor(args) => cmd::outdoor::run(&args),
        Command::Preview(args) => cmd::preview::run(&args),
        Command::Demo(args) => cmd::demo::run(&args),
        Command::View(args) => cmd::view::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => failure::report(&err),
    }
}
