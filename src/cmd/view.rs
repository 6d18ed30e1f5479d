//! `ibl view`: the real-time viewer (`ibl-viewer`): a probe, or a scene file with its virtual
//! objects composited into the probe or the photo, every light casting a shadow. In a window by
//! default; `--headless` renders offscreen with the same code and writes the last frame. The
//! arguments and the job are the viewer's (`ibl_viewer::command_line`).

pub use ibl_viewer::command_line::ViewArgs;

use crate::progress::Bars;

/// Runs `ibl view` and prints the headless summary (text, or JSON with `--json`).
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    if let Some(summary) = ibl_viewer::command_line::run(args, &Bars::default())?
        && !super::print_json(args.json, &summary)?
    {
        println!("{}", summary.line());
    }
    Ok(())
}
