//! `ibl outdoor`: outdoor AR under changing light (Jensen, Andersen & Madsen 2006,
//! `docs/OUTDOOR.md`): a scene with an `[outdoor]` table and its frames to per-frame sun and sky
//! estimates (CSV, JSON, chart), relit maps and composites. The job is
//! `ibl_pipeline::outdoor::run_outdoor`.

use std::path::PathBuf;

use clap::Args;
use ibl_pipeline::outdoor::{OutdoorJob, run_outdoor};

use crate::progress::Bars;

/// Arguments of `ibl outdoor`.
#[derive(Args)]
#[command(after_help = "\
Per frame: the sun's and the sky's RGB (P_d, P_a) from about 500 pixels of the marked diffuse
surfaces, the environment map relit to match, and the scene's [[object]]s composited into the
frame with the sun's shadows both ways. Outputs: estimates.csv, estimates.json, estimates.svg,
composites/NAME.exr and .png (one exposure for the whole sequence), relit/NAME.exr (--relit),
a video of the composites (--video, through ffmpeg). The frames are a folder of images or a
video file (decoded by ffmpeg; its sRGB values are made linear).

Examples:
  ibl outdoor assets/outdoor/courtyard/scene.toml --out courtyard
  ibl outdoor scene.toml --out run --frames 10 --spp 64 --relit
  ibl outdoor scene.toml --out run --video run/composites.mp4 --video-fps 2
  ibl outdoor scene.toml --out run --no-composites --json > run.json")]
pub struct OutdoorArgs {
    /// Scene file with an `[outdoor]` table (docs/SCENES.md).
    scene: PathBuf,
    /// Output folder (created when missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Process only the first N frames.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    frames: Option<u32>,
    /// Samples per pixel of the composites.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    spp: u32,
    /// Estimate only: do not composite the objects.
    #[arg(long)]
    no_composites: bool,
    /// Also write each frame's relit environment map.
    #[arg(long)]
    relit: bool,
    /// Also write the composites as a video (through ffmpeg; .mp4, .mkv, ...).
    #[arg(long, value_name = "FILE")]
    video: Option<PathBuf>,
    /// Frame rate of --video.
    #[arg(long, value_name = "FPS", default_value_t = ibl_pipeline::outdoor::DEFAULT_VIDEO_FPS)]
    video_fps: f64,
    /// Print the whole summary as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs `ibl outdoor` and prints a line per frame (or the JSON summary).
pub fn run(args: &OutdoorArgs) -> anyhow::Result<()> {
    let mut job = OutdoorJob::new(args.scene.clone(), args.out.clone());
    job.composites = !args.no_composites;
    job.relit_maps = args.relit;
    job.composite.spp = args.spp;
    job.max_frames = args.frames.map(|n| n as usize);
    job.video = args.video.clone();
    job.video_fps = args.video_fps;
    let summary = run_outdoor(&job, &Bars::default())?;
    if super::print_json(args.json, &summary)? {
        return Ok(());
    }
    println!("time                 sky       P_d (sun) R G B            P_a (sky) R G B");
    for f in &summary.frames {
        let e = &f.result.estimate;
        println!(
            "{}  {:8}  {:7.4} {:7.4} {:7.4}   {:7.4} {:7.4} {:7.4}",
            f.local_time,
            format!("{:?}", f.result.sky_condition).to_lowercase(),
            e.sun[0],
            e.sun[1],
            e.sun[2],
            e.sky[0],
            e.sky[1],
            e.sky[2]
        );
    }
    let out = args.out.display();
    println!("wrote {out}/estimates.csv, estimates.json, estimates.svg");
    Ok(())
}
