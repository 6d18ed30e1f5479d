//! What the command line prints after `ibl eval` and `ibl demo`, as text the front end shows
//! (a terminal, a log widget, a Python string): the table of lights needed per method, and the
//! demo's probe table with where every output is.

use std::fmt::Write as _;
use std::path::Path;

use ibl_core::rgb::Rgb64;
use ibl_eval::Report;
use ibl_eval::report::LightsNeeded;

use crate::demo::Demo;
use crate::demo_paths::{EVAL_DIR, RENDER_DIR, ROOM_DIR};
use crate::demo_room::DEMO_IMPORTANT_PATCHES;

/// The smallest N each method needs for 1 % and 5 % mean and maximum error, averaged over the
/// report's probes (one line per method, a heading, and a note of skipped runs).
pub fn lights_needed_text(report: &Report) -> String {
    let largest = report.counts.iter().copied().max().unwrap_or(0);
    let k = report.probes.len();
    let mut text = format!(
        "lights needed (smallest N swept), average over {k} probe{}:\n  {:<24} {:>9} {:>9} {:>9} {:>9}\n",
        if k == 1 { "" } else { "s" },
        "method",
        "mean<=1%",
        "mean<=5%",
        "max<=1%",
        "max<=5%"
    );
    for x in LightsNeeded::average(report) {
        let [a, b, c, d] = x.cells(largest);
        let _ = writeln!(text, "  {:<24} {a:>9} {b:>9} {c:>9} {d:>9}", x.method);
    }
    let not_ok = report
        .probes
        .iter()
        .flat_map(|p| &p.rows)
        .filter(|r| r.status != ibl_eval::Status::Ok)
        .count();
    if not_ok > 0 {
        let _ = writeln!(text, "  ({not_ok} runs skipped or failed; see the report)");
    }
    text
}

/// The demo's summary: a line per probe (size, dynamic range, luminance of its power, the power
/// change of every mapping's round trip), the lights needed, and where each output is under
/// `out`.
pub fn demo_text(out: &Path, made: &Demo) -> String {
    let o = out.display();
    let mut text = format!(
        "{:<12} {:>9} {:>8} {:>12}  round-trip power change per mapping (%)\n",
        "probe", "size", "stops", "luminance"
    );
    for r in &made.probes {
        let i = &r.info;
        let [r_, g, b] = i.power.unwrap_or_default(); // the demo's probes are lat-long
        let luminance = Rgb64 { r: r_, g, b }.luminance();
        let changes: Vec<String> = r
            .mappings
            .iter()
            .filter_map(|m| {
                m.round_trip_power_change_pct
                    .map(|c| format!("{} {c:+.3}", m.mapping))
            })
            .collect();
        let _ = writeln!(
            text,
            "{:<12} {:>9} {:>8.1} {:>12.4e}  {}",
            r.name,
            format!("{}x{}", i.width, i.height),
            i.dynamic_range.stops,
            luminance,
            changes.join(", ")
        );
    }
    let _ = write!(
        text,
        "\noutputs in {o}/\n  {o}/index.html     every probe in every mapping, tone-mapped\n  \
         {o}/summary.json   the same as data\n  \
         {o}/<probe>/       info.json, latlong.png, <mapping>.exr and .png\n\n{}",
        lights_needed_text(&made.report)
    );
    let _ = writeln!(
        text,
        "  {o}/{EVAL_DIR}/report.md    the comparison: tables, plots, spheres, overlays\n  \
         {o}/{RENDER_DIR}/report.md the example scenes rendered, lights scored against the reference"
    );
    if let Some(room) = &made.room {
        let _ = writeln!(
            text,
            "  {o}/{ROOM_DIR}/report.md        the reconstructed room: {} patches, rho per group, {DEMO_IMPORTANT_PATCHES} important patches",
            room.patches
        );
    }
    for s in &made.sections {
        let _ = writeln!(text, "  {o}/index.html#{}  {}", s.id, s.title);
    }
    text
}
