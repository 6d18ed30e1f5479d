//! The demo's page: `index.html` (every probe in every mapping, the comparison's tables and
//! plots, the renders) and `summary.json` (the same as data).

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::demo_paths::EVAL_DIR;
use crate::demo_probe::ProbeResult;
use crate::demo_render::SceneResult;
use crate::demo_room::{RoomResult, room_html};
use crate::demo_section::PageSection;
use crate::error::Result;

/// The comparison section of `index.html`: links, the average plot and the lights-needed table.
fn eval_html(report: &ibl_eval::Report) -> String {
    let largest = report.counts.iter().copied().max().unwrap_or(0);
    let counts: Vec<String> = report.counts.iter().map(usize::to_string).collect();
    let f = &report.files;
    let mut html = format!(
        "<h1 id=eval>Light extraction methods compared</h1><p>Every method at N = {}, scored on {} \
         Fibonacci normals against the exact irradiance (Madsen &amp; Laursen 2006, section 5): \
         <a href=\"{EVAL_DIR}/{}\">report.md</a> &middot; <a href=\"{EVAL_DIR}/{}\">report.json</a> \
         &middot; <a href=\"{EVAL_DIR}/{}\">report.csv</a>. Fitted methods: {}.</p>",
        counts.join(", "),
        report.normals,
        f.markdown,
        f.json,
        f.csv,
        report.fit_normals_note
    );
    html.push_str(
        "<table><tr><th>lights needed (average)</th><th>mean_err &le; 1 %</th>\
         <th>mean_err &le; 5 %</th><th>max_err &le; 1 %</th><th>max_err &le; 5 %</th></tr>",
    );
    for x in ibl_eval::LightsNeeded::average(report) {
        let [a, b, c, d] = x.cells(largest).map(|c| c.replace('>', "&gt;"));
        let _ = write!(
            html,
            "<tr><td>{}</td><td>{a}</td><td>{b}</td><td>{c}</td><td>{d}</td></tr>",
            x.method
        );
    }
    html.push_str("</table>");
    for p in &f.plots {
        let _ = write!(
            html,
            "<figure><a href=\"{EVAL_DIR}/{svg}\"><img class=wide src=\"{EVAL_DIR}/{png}\"></a>\
             <figcaption>{}</figcaption></figure>",
            p.probe.as_deref().unwrap_or("average over the probes"),
            svg = p.svg,
            png = p.png
        );
    }
    for x in &f.figures {
        for (what, path) in [("spheres", &x.sphere), ("overlay", &x.overlay)] {
            if let Some(path) = path {
                let _ = write!(
                    html,
                    "<figure><a href=\"{EVAL_DIR}/{path}\"><img src=\"{EVAL_DIR}/{path}\"></a>\
                     <figcaption>{} {} N={} {what}</figcaption></figure>",
                    x.probe, x.method, x.n
                );
            }
        }
    }
    html
}

/// Writes `out/summary.json` (every probe's and scene's results as data) and `out/index.html`
/// (the same to look at, with the comparison's tables and plots).
pub fn write_summary(
    out: &Path,
    results: &[ProbeResult],
    report: &ibl_eval::Report,
    renders: &[SceneResult],
    room: Option<&RoomResult>,
    sections: &[PageSection],
) -> Result<()> {
    #[derive(Serialize)]
    struct Summary<'a> {
        probes: &'a [ProbeResult],
        renders: &'a [SceneResult],
        #[serde(skip_serializing_if = "Option::is_none")]
        room: Option<&'a RoomResult>,
        #[serde(skip_serializing_if = "<[_]>::is_empty")]
        sections: &'a [PageSection],
    }
    // Serialising plain data to a string cannot fail.
    let json = serde_json::to_string_pretty(&Summary {
        probes: results,
        renders,
        room,
        sections,
    })
    .unwrap_or_default();
    ibl_io::write_atomically(&out.join("summary.json"), json.as_bytes())?;
    let mut html = String::from(
        "<!doctype html><meta charset=utf-8><title>iblkit demo</title>\
         <style>body{font-family:sans-serif;background:#222;color:#ddd}img{max-height:220px;margin:4px;border:1px solid #444}\
         figure{display:inline-block;margin:4px}figcaption{font-size:12px}td,th{padding:2px 8px;text-align:right}\
         img.wide{max-height:none;width:640px}a{color:#9cf}</style>\
         <h1>iblkit demo</h1>",
    );
    let _ = write!(
        html,
        "<p>Every probe in every mapping below; then <a href=\"#eval\">the light extraction \
         methods compared</a> (<a href=\"{EVAL_DIR}/{}\">report.md</a>), the renders and \
         <a href=\"#room\">the reconstructed room</a>.</p>",
        report.files.markdown
    );
    for r in results {
        let i = &r.info;
        // The demo's probes are lat-long: both are always known.
        let power = i.power.unwrap_or_default();
        let brightest = i.brightest.direction.unwrap_or_default();
        let _ = write!(
            html,
            "<h2>{}</h2><p>{} x {} {} &middot; power {:.4e} {:.4e} {:.4e} &middot; dynamic range {:.1} stops \
             &middot; brightest ({:+.3}, {:+.3}, {:+.3}) &middot; {} negative / {} NaN-Inf values clamped</p>",
            r.name,
            i.width,
            i.height,
            i.format,
            power[0],
            power[1],
            power[2],
            i.dynamic_range.stops,
            brightest[0],
            brightest[1],
            brightest[2],
            i.negative_values,
            i.nonfinite_values
        );
        let _ = write!(
            html,
            "<figure><img src=\"{}\"><figcaption>latlong</figcaption></figure>",
            r.preview
        );
        let irr = &r.irradiance;
        let _ = write!(
            html,
            "<figure><img src=\"{}\"><figcaption>irradiance, exact</figcaption></figure>\
             <figure><img src=\"{}\"><figcaption>irradiance, SH9 (mean {:.2} %, max {:.1} %; \
             sun confidence {:.2})</figcaption></figure>",
            irr.exact_preview,
            irr.sh9_preview,
            irr.sh9_mean_err_pct,
            irr.sh9_max_err_pct,
            irr.sun_confidence
        );
        for m in &r.mappings {
            let change = m
                .round_trip_power_change_pct
                .map(|c| format!(" (round trip {c:+.3} % power)"))
                .unwrap_or_default();
            let _ = write!(
                html,
                "<figure><img src=\"{}\"><figcaption>{}{change}</figcaption></figure>",
                m.preview, m.mapping
            );
        }
    }
    html.push_str(&eval_html(report));
    html.push_str(&renders_html(renders));
    if let Some(room) = room {
        html.push_str(&room_html(room));
    }
    for s in sections {
        let _ = write!(html, "<h2 id=\"{}\">{}</h2>{}", s.id, s.title, s.html);
    }
    ibl_io::write_atomically(&out.join("index.html"), html.as_bytes())?;
    Ok(())
}

/// The renders section of the demo's `index.html`.
pub fn renders_html(results: &[SceneResult]) -> String {
    let mut html = String::from(
        "<h1 id=renders>Virtual objects in real probes</h1>\
         <p>The example scenes of <code>assets/scenes/</code>, rendered by <code>ibl render</code>: \
         the path-traced reference composited into the probe by differential rendering, light \
         approximations, the hybrid, and the whole panorama. Then every light set scored by its \
         render against the reference (<a href=\"renders/report.md\">renders/report.md</a>).</p>",
    );
    for r in results {
        let _ = write!(html, "<h2>{}</h2>", r.name);
        for image in &r.images {
            let time = if image.seconds > 0.0 {
                format!(" ({:.1} s)", image.seconds)
            } else {
                String::new()
            };
            let error = image
                .against_reference
                .map(|(relative_mse, flip)| {
                    format!(
                        "<br>against the reference: relative MSE {relative_mse:.2e}, FLIP {flip:.3}{}",
                        image
                            .speedup
                            .map_or(String::new(), |x| format!("; {x:.1}x faster"))
                    )
                })
                .unwrap_or_default();
            let _ = write!(
                html,
                "<figure><img src=\"{}\"><figcaption>{}{time}{error}</figcaption></figure>",
                image.preview, image.caption
            );
        }
        let _ = write!(html, "<p><img class=wide src=\"{}\"></p>", r.chart[1]);
    }
    html
}
