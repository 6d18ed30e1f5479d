//! The demo's room (Grosch 2005 section 3, `docs/ROOMS.md`): the worked example's room file
//! (`assets/rooms/apartment`, reconstructed from marks on the bundled apartment probe) estimated
//! by [`crate::room_estimate`] into `room/`: the Table-1 report, reflectance per group, the
//! important patches as an area-light file, and the three pictures; and the section of the
//! demo's page that shows them.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::demo_paths::ROOM_DIR;
use crate::error::{Context, Result};
use crate::progress::Progress;
use crate::room_estimate::{SamplingOptions, estimate_room, report, write_pictures};
use crate::room_lights::write_lights;
use crate::room_render::{RoomEdits, render_edits};

/// Important patches the demo lists and exports.
pub const DEMO_IMPORTANT_PATCHES: usize = 16;

/// One group's row of the demo's room table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RoomGroupRow {
    /// Group name.
    pub name: String,
    /// Estimated reflectance (surfaces), linear RGB.
    pub reflectance: Option<[f32; 3]>,
    /// Whether it comes from the group's own seen patches (else the mean of the others).
    pub estimated: bool,
    /// Fraction of the group's area the probe sees.
    pub seen_area_fraction: f32,
}

/// What the demo's room made.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RoomResult {
    /// The room file.
    pub room: String,
    /// Patches.
    pub patches: usize,
    /// Iterations of steps 1 to 5 and whether they converged.
    pub iterations: usize,
    /// Whether the last iteration changed every reflectance by less than the tolerance.
    pub converged: bool,
    /// Seconds of the analysis.
    pub seconds: f64,
    /// Per group.
    pub groups: Vec<RoomGroupRow>,
    /// Share of the room's luminous flux in the important patches.
    pub important_flux_fraction: f64,
    /// Paths relative to the demo folder: report.md, report.json, lights.json, rho-panorama.png,
    /// overlay.png, cutaway.png, and each manipulation's pictures.
    pub files: Vec<String>,
    /// Grosch 2005 section 4's manipulations of the room, before and after.
    pub manipulations: Vec<RoomManipulation>,
}

/// One manipulation of the demo's room (an edits file beside the room file, `ibl room render`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RoomManipulation {
    /// The edits file.
    pub edits: String,
    /// What it does, for the page.
    pub caption: String,
    /// The picture before, relative to the demo folder.
    pub before: String,
    /// The picture after.
    pub after: String,
}

/// The edits files the demo applies, beside the room file: file, picture prefix, caption.
const DEMO_EDITS: [(&str, &str, &str); 4] = [
    (
        "edits.toml",
        "material",
        "the floor's reflectance changed (Grosch 2005 section 4.3): its radiance scaled by \
         rho'/rho, one bounce of colour bleeding onto the rest of the room",
    ),
    (
        "edits-light.toml",
        "light",
        "a new light (section 4.2): a real IES downlight hung by the +x wall, its direct light \
         EQ5 at every pixel with shadow rays, one bounce of its light by delta radiosity",
    ),
    (
        "edits-object.toml",
        "object",
        "a virtual object (section 4.1): the bunny in the sunlit patch, Grosch's improved display \
         (the irradiance volume's unimportant light, 32 important patches recomputed with \
         shadows), its shadows subtracted from the probe",
    ),
    (
        "edits-view.toml",
        "view",
        "the same change seen from a camera moved 0.6 m (section 4.4): the probe projected on \
         the model, the estimate rho E / pi where the probe did not see",
    ),
];

/// Renders each of [`DEMO_EDITS`] found beside `room` into `dir` (before and after PNGs at one
/// exposure).
fn manipulations(
    estimated: &crate::room_estimate::EstimatedRoom,
    room: &Path,
    dir: &Path,
) -> Result<Vec<RoomManipulation>> {
    let mut out = Vec::new();
    for (file, prefix, caption) in DEMO_EDITS {
        let path = room.with_file_name(file);
        if !path.is_file() {
            continue;
        }
        let edits = RoomEdits::read(&path)?;
        let assets = edits.load()?;
        let pictures =
            render_edits(estimated, &edits, &assets, room).context(path.display().to_string())?;
        let (before, after) = (
            format!("{prefix}-before.png"),
            format!("{prefix}-after.png"),
        );
        pictures.write(&dir.join(&after), Some(&dir.join(&before)))?;
        out.push(RoomManipulation {
            edits: path.display().to_string(),
            caption: caption.to_string(),
            before: format!("{ROOM_DIR}/{before}"),
            after: format!("{ROOM_DIR}/{after}"),
        });
    }
    Ok(out)
}

/// Estimates the room file `room` into `out/room/`.
pub fn demo_room(room: &Path, out: &Path, progress: &dyn Progress) -> Result<RoomResult> {
    let dir = out.join(ROOM_DIR);
    ibl_io::create_dir_all(&dir)?;
    let name = room.display().to_string();
    let sampling = SamplingOptions::default();
    let estimated = estimate_room(room, &sampling, progress).context(name.clone())?;
    let (report, lights) = report(&estimated, DEMO_IMPORTANT_PATCHES);
    ibl_io::write_atomically(&dir.join("report.json"), report.to_json()?.as_bytes())?;
    ibl_io::write_atomically(&dir.join("report.md"), report.to_markdown().as_bytes())?;
    write_pictures(
        &dir,
        &estimated.input.room,
        &estimated.probe,
        &estimated.analysis,
    )?;
    // The light file as `ibl room lights` writes it.
    write_lights(
        &estimated,
        room,
        &dir.join("lights.json"),
        DEMO_IMPORTANT_PATCHES,
        progress,
    )?;
    let manipulations = manipulations(&estimated, room, &dir)?;
    let estimate = &estimated.analysis.estimate;
    let mut files: Vec<String> = [
        "report.md",
        "report.json",
        "lights.json",
        "rho-panorama.png",
        "overlay.png",
        "cutaway.png",
    ]
    .iter()
    .map(|f| format!("{ROOM_DIR}/{f}"))
    .collect();
    for m in &manipulations {
        files.extend([m.before.clone(), m.after.clone()]);
    }
    Ok(RoomResult {
        room: name,
        patches: estimated.input.room.patches.len(),
        iterations: estimate.iterations.len(),
        converged: estimate.converged,
        seconds: estimated.seconds,
        groups: estimate
            .groups
            .iter()
            .map(|g| RoomGroupRow {
                name: g.name.clone(),
                reflectance: g.reflectance,
                estimated: g.estimated,
                seen_area_fraction: g.seen_area_fraction,
            })
            .collect(),
        important_flux_fraction: lights.important_flux_fraction,
        files,
        manipulations,
    })
}

/// The room section of the demo's `index.html`.
pub fn room_html(r: &RoomResult) -> String {
    let mut html = format!(
        "<h1 id=room>The reconstructed room</h1><p>Grosch 2005, section 3, on the bundled \
         apartment probe (<code>{}</code>, made from marked lines by <code>ibl room calibrate</code>; \
         the method and its validation are in the repository's <code>docs/ROOMS.md</code>): {} patches, reflectance \
         <code>rho = B / E</code> by radiosity in {} iterations ({}), {:.1} s. The {} important \
         patches carry {:.1} % of the room's luminous flux (<a href=\"{ROOM_DIR}/lights.json\">\
         lights.json</a>, for <code>ibl render --lights</code>). \
         <a href=\"{ROOM_DIR}/report.md\">report.md</a> &middot; \
         <a href=\"{ROOM_DIR}/report.json\">report.json</a></p>",
        r.room,
        r.patches,
        r.iterations,
        if r.converged {
            "converged"
        } else {
            "not converged"
        },
        r.seconds,
        DEMO_IMPORTANT_PATCHES,
        100.0 * r.important_flux_fraction
    );
    html.push_str("<table><tr><th>group</th><th>rho (R, G, B)</th><th>seen</th><th>from</th></tr>");
    for g in &r.groups {
        let rho = g
            .reflectance
            .map(|[a, b, c]| format!("{a:.3}, {b:.3}, {c:.3}"))
            .unwrap_or_else(|| "light".into());
        let _ = write!(
            html,
            "<tr><td>{}</td><td>{rho}</td><td>{:.0} %</td><td>{}</td></tr>",
            g.name,
            100.0 * g.seen_area_fraction,
            if g.estimated {
                "its patches"
            } else {
                "the others' mean"
            }
        );
    }
    html.push_str("</table>");
    for (file, caption) in [
        (
            "rho-panorama.png",
            "patches coloured by reflectance, hidden ones hatched",
        ),
        ("overlay.png", "the model's edges over the probe"),
        (
            "cutaway.png",
            "the room from above, coloured by reflectance",
        ),
    ] {
        let _ = write!(
            html,
            "<figure><img class=wide src=\"{ROOM_DIR}/{file}\"><figcaption>{caption}</figcaption></figure>"
        );
    }
    if !r.manipulations.is_empty() {
        html.push_str(
            "<h2>Manipulations</h2><p>Each an edits file beside the room file, rendered by \
             <code>ibl room render ROOM --edit EDITS -o after.png --before before.png</code>; \
             before and after at the same exposure.</p>",
        );
    }
    for m in &r.manipulations {
        let _ = write!(
            html,
            "<figure><img src=\"{}\"> <img src=\"{}\"><figcaption>before, after: {} \
             (<code>{}</code>)</figcaption></figure>",
            m.before, m.after, m.caption, m.edits
        );
    }
    html
}
