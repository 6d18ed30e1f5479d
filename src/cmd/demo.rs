//! `ibl demo`: the main job on the bundled probes and example scenes, with no arguments needed
//! (`ibl_pipeline::demo`); prints where everything is.

use std::path::{Path, PathBuf};

use clap::Args;
use ibl_pipeline::demo::{DemoOptions, demo};
use ibl_pipeline::demo_text::demo_text;

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
        outdoor: Some(assets_dir().join("outdoor/courtyard/scene.toml")),
    };
    let made = demo(
        &options,
        &Bars::default(),
        &[&ibl_viewer::demo_frames::ViewerFrames],
    )?;
    print!("{}", demo_text(&args.out, &made));
    Ok(())
}
