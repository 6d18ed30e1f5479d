//! The demo's outdoor sequence (Jensen, Andersen & Madsen 2006, `docs/OUTDOOR.md`): the bundled
//! synthetic courtyard (`assets/outdoor/courtyard`) run through [`crate::outdoor`] into
//! `outdoor/`: per-frame estimates of the sun and the sky, their chart, and the statue
//! composited into every frame; and the section of the demo's page that shows them, with each
//! estimate's error against the sequence's `truth.csv` when the folder has one.

use std::fmt::Write as _;
use std::path::Path;

use crate::demo_paths::OUTDOOR_DIR;
use crate::demo_section::PageSection;
use crate::error::{Context, Result};
use crate::outdoor::{OutdoorJob, OutdoorSummary, chart_svg, run_outdoor};
use crate::progress::Progress;

/// The chart with the truth, in the outdoor folder.
const TRUTH_CHART: &str = "estimates_truth.svg";

/// Largest `truth.csv` read, bytes.
const MAX_TRUTH_BYTES: u64 = 1 << 20;

/// Runs the sequence of `scene` into `out/outdoor/` and makes its page section.
pub fn demo_outdoor(scene: &Path, out: &Path, progress: &dyn Progress) -> Result<PageSection> {
    let dir = out.join(OUTDOOR_DIR);
    let summary = run_outdoor(&OutdoorJob::new(scene.to_path_buf(), dir), progress)
        .context(format!("demo outdoor sequence {}", scene.display()))?;
    let truth_path = scene.with_file_name("truth.csv");
    let truth = if truth_path.exists() {
        parse_truth(&ibl_io::read_text(&truth_path, MAX_TRUTH_BYTES)?)
    } else {
        Vec::new()
    };
    if truth.len() == summary.frames.len() {
        // The chart with the true values as dots.
        let svg = chart_svg(&summary, Some(&truth), "estimates (lines) and truth (dots)")?;
        ibl_io::write_atomically(&out.join(OUTDOOR_DIR).join(TRUTH_CHART), svg.as_bytes())?;
    }
    Ok(PageSection {
        id: "outdoor".into(),
        title: "Outdoor AR under changing light".into(),
        html: section_html(&summary, &truth),
        data: serde_json::json!({ "summary": summary, "truth": truth }),
    })
}

/// `(P_d, P_a)` per row of a `truth.csv` (columns 3 to 8); rows that do not parse are skipped.
fn parse_truth(text: &str) -> Vec<([f32; 3], [f32; 3])> {
    text.lines()
        .skip(1)
        .filter_map(|line| {
            let v: Vec<f32> = line
                .split(',')
                .skip(3)
                .map(|s| s.trim().parse().ok())
                .collect::<Option<_>>()?;
            (v.len() == 6).then(|| ([v[0], v[1], v[2]], [v[3], v[4], v[5]]))
        })
        .collect()
}

/// The chart, a table of the estimates (with their error against the truth) and the composites.
fn section_html(summary: &OutdoorSummary, truth: &[([f32; 3], [f32; 3])]) -> String {
    let mut html = format!(
        "<p>The bundled synthetic courtyard (<code>{}</code>, made by the project's path tracer \
         with 3 bounces): one probe at 09:30, then a fixed camera's frames. Per frame, \
         <code>ibl outdoor</code> estimates the sun's and the sky's RGB (P_d, P_a) from {} \
         pixels of the model's surfaces, relights the probe and composites the virtual statue \
         with its shadows. Offline maps and sample sites: {:.1} s.</p>\n\
         <p><img src=\"{OUTDOOR_DIR}/{chart}\" alt=\"P_d and P_a over the day\" \
         width=\"720\"></p>\n<table>\n<tr><th>time</th><th>sky</th><th>P_d (G)</th>\
         <th>P_a (G)</th><th>P_d error</th><th>P_a error</th><th>estimate</th>\
         <th>composite</th></tr>\n",
        summary.scene.display(),
        summary.sample_sites,
        summary.setup_seconds,
        chart = if truth.len() == summary.frames.len() {
            TRUTH_CHART
        } else {
            "estimates.svg"
        },
    );
    let pct = |got: f32, want: f32| {
        if want > 0.0 {
            format!("{:+.1} %", 100.0 * (got / want - 1.0))
        } else {
            format!("{got:.4} (none true)")
        }
    };
    for f in &summary.frames {
        let e = &f.result.estimate;
        let (sun_err, sky_err) = match truth.get(f.index) {
            Some((pd, pa)) => (pct(e.sun[1], pd[1]), pct(e.sky[1], pa[1])),
            None => ("-".into(), "-".into()),
        };
        let picture = f.composite.as_ref().map_or(String::new(), |p| {
            format!(
                "<img src=\"{OUTDOOR_DIR}/{}\" width=\"240\">",
                p.with_extension("png").display()
            )
        });
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{:?}</td><td>{:.4}</td><td>{:.4}</td><td>{sun_err}</td>\
             <td>{sky_err}</td><td>{:.1} ms</td><td>{picture}</td></tr>",
            f.local_time.get(11..16).unwrap_or(&f.local_time),
            f.result.sky_condition,
            e.sun[1],
            e.sky[1],
            1000.0 * f.estimate_seconds
        );
    }
    html.push_str(
        "</table>\n<p>Errors are of the green channel against the renders' true light; the \
         sequence has interreflections, which the bounce transfer models \
         (docs/OUTDOOR.md).</p>\n",
    );
    html
}
