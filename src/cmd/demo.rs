//! `ibl demo`: the main job on the bundled probes and example scenes, with no arguments needed
//! (`ibl_pipeline::demo`); prints where everything is.

use std::path::{Path, PathBuf};

use clap::Args;
use ibl_core::rgb::Rgb64;
use ibl_pipeline::demo::{DemoOptions, demo};
use ibl_pipeline::demo_paths::{EVAL_DIR, RENDER_DIR};
use ibl_pipeline::demo_probe::ProbeResult;

use crate::cmd::eval::print_lights_needed;
use crate::progress::Bars;

/// Arguments of `ibl demo`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl demo                       writes ./demo-out (open demo-out/index.html)
  ibl demo --out /tmp/ibl-demo
  ibl demo --probes my-probes/   every .exr/.hdr lat-long probe in a folder")]
pub struct DemoArgs {
    /// Folder for all outputs (created if missing).
    #[arg(long, default_value = "demo-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Folder of lat-long probes to use (default: the bundled `assets/probes`).
    #[arg(long, value_name = "DIR")]
    pub probes: Option<PathBuf>,
    /// Folder of scene files to render (default: the bundled `assets/scenes`).
    #[arg(long, value_name = "DIR")]
    pub scenes: Option<PathBuf>,
    /// Room file of the reconstructed-room section (default: the bundled
    /// `assets/rooms/apartment/room.toml`).
    #[arg(long, value_name = "ROOM.toml")]
    pub room: Option<PathBuf>,
}

/// The bundled `assets` folder: beside the binary's source tree, else in the current folder.
pub fn assets_dir() -> PathBuf {
    let built_in = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    if built_in.is_dir() {
        built_in
    } else {
        PathBuf::from("assets")
    }
}

/// Runs `ibl demo`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let options = DemoOptions {
        out: args.out.clone(),
        probes: args
            .probes
            .clone()
            .unwrap_or_else(|| assets_dir().join("probes")),
        scenes: args
            .scenes
            .clone()
            .unwrap_or_else(|| assets_dir().join("scenes")),
        room: Some(
            args.room
                .clone()
                .unwrap_or_else(|| assets_dir().join("rooms/apartment/room.toml")),
        ),
    };
    let made = demo(
        &options,
        &Bars::default(),
        &[&ibl_viewer::demo_frames::ViewerFrames],
    )?;
    print_summary(&args.out, &made.probes);
    println!();
    print_lights_needed(&made.report);
    println!(
        "  {}/{EVAL_DIR}/report.md    the comparison: tables, plots, spheres, overlays",
        args.out.display()
    );
    println!(
        "  {}/{RENDER_DIR}/report.md the example scenes rendered, lights scored against the reference",
        args.out.display()
    );
    if let Some(room) = &made.room {
        println!(
            "  {}/room/report.md        the reconstructed room: {} patches, rho per group, {} important patches",
            args.out.display(),
            room.patches,
            ibl_pipeline::demo_room::DEMO_IMPORTANT_PATCHES
        );
    }
    for s in &made.sections {
        println!("  {}/index.html#{}  {}", args.out.display(), s.id, s.title);
    }
    Ok(())
}

fn print_summary(out: &Path, results: &[ProbeResult]) {
    println!(
        "{:<12} {:>9} {:>8} {:>12}  round-trip power change per mapping (%)",
        "probe", "size", "stops", "luminance"
    );
    for r in results {
        let i = &r.info;
        let [pr, pg, pb] = i.power.unwrap_or_default(); // the demo's probes are lat-long
        let power_lum = Rgb64 {
            r: pr,
            g: pg,
            b: pb,
        }
        .luminance();
        let changes: Vec<String> = r
            .mappings
            .iter()
            .filter_map(|m| {
                m.round_trip_power_change_pct
                    .map(|c| format!("{} {c:+.3}", m.mapping))
            })
            .collect();
        println!(
            "{:<12} {:>9} {:>8.1} {:>12.4e}  {}",
            r.name,
            format!("{}x{}", i.width, i.height),
            i.dynamic_range.stops,
            power_lum,
            changes.join(", ")
        );
    }
    println!();
    println!("outputs in {}/", out.display());
    println!(
        "  {}/index.html     every probe in every mapping, tone-mapped",
        out.display()
    );
    println!("  {}/summary.json   the same as data", out.display());
    println!(
        "  {}/<probe>/       info.json, latlong.png, <mapping>.exr and .png",
        out.display()
    );
}
