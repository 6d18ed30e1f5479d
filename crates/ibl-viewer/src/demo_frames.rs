//! The viewer's section of `ibl demo`'s page (issue 15): one headless frame of every example
//! scene, with its timings, made by the same [`ViewJob`] as `ibl view SCENE --headless`. Without
//! a GPU adapter the section says so and the demo goes on.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ibl_core::tonemap::ToneCurve;
use ibl_pipeline::Progress;
use ibl_pipeline::demo_render::list_scenes;
use ibl_pipeline::demo_section::{DemoSection, PageSection};

use crate::headless::{HeadlessOptions, Motion};
use crate::probe_model::Overlays;
use crate::view_job::{ProbeExtras, ProbeViewOptions, ViewJob, ViewSummary};

/// Folder of the frames inside the demo's output folder.
pub const VIEWER_DIR: &str = "viewer";

/// Frames per scene: the first compiles the shaders and draws both shadow atlases; the median of
/// the other two is the steady frame time.
pub const DEMO_FRAMES: u32 = 3;

/// The viewer's demo section.
#[derive(Clone, Copy, Debug, Default)]
pub struct ViewerFrames;

fn job(scene: &Path, output: PathBuf) -> ViewJob {
    ViewJob {
        input: scene.to_path_buf(),
        mapping: None,
        output: Some(output),
        frames: HeadlessOptions {
            frames: DEMO_FRAMES,
            motion: Motion::Still,
            ..HeadlessOptions::default()
        },
        exposure_stops: None,
        curve: ToneCurve::Reinhard,
        method: None,
        lights: None,
        bands: None,
        probe: ProbeViewOptions {
            projection: Default::default(),
            layer: Default::default(),
            sharpen: 0.0,
            overlays: Overlays {
                lights: false,
                regions: false,
                dominant: false,
            },
        },
    }
}

fn caption(name: &str, s: &ViewSummary) -> String {
    let stats = &s.statistics;
    let passes = s
        .per_frame
        .last()
        .and_then(|f| f.passes_ms.as_ref())
        .map(|p| {
            p.iter()
                .map(|(pass, ms)| format!("{pass} {ms:.1} ms"))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_else(|| "no GPU timestamps".into());
    let played = s
        .sequence
        .as_ref()
        .and_then(|q| q.frames.last())
        .map(|f| {
            let e = &f.result.estimate;
            format!(
                "; sequence frame {} at {}: sun P_d {:.3?}, sky P_a {:.3?}",
                f.name, f.local_time, e.sun, e.sky
            )
        })
        .unwrap_or_default();
    format!(
        "{name}: {} at {} x {}, {:.2} fps median ({:.1} ms a frame; last frame: {passes}) on {} ({}){played}",
        s.lighting,
        s.width,
        s.height,
        stats.fps_median,
        stats.frame_ms_median,
        s.adapter.name,
        s.adapter.backend
    )
}

impl DemoSection for ViewerFrames {
    fn section(
        &self,
        scenes: &Path,
        outdoor: Option<&Path>,
        out: &Path,
        progress: &dyn Progress,
    ) -> PageSection {
        let mut html = String::from(
            "<p>Each example scene as the real-time viewer draws it: one headless frame of \
             <code>ibl view SCENE --headless</code> (the same code as the window), its lights \
             each with a shadow map, composited into the probe on the GPU; and the outdoor \
             sequence played by the viewer (its third frame: each frame's sun and sky \
             estimated as <code>ibl outdoor</code> does, the sun with its shadow); the scene \
             with an IES luminaire; and the worked example room's bunny drawn live in the \
             reconstructed room (<code>ibl view PROBE --room ROOM --edit EDITS --live</code>: \
             Grosch's improved display, the 32 important patches as shadowed point \
             lights).</p>",
        );
        let mut data = Vec::new();
        // The scenes the demo rendered, so the two sections show the same ones.
        let mut files = match list_scenes(scenes) {
            Ok(f) => f,
            Err(e) => {
                let _ = write!(html, "<p>No frames: {e}</p>");
                Vec::new()
            }
        };
        let dir = out.join(VIEWER_DIR);
        if let Err(e) = ibl_io::create_dir_all(&dir) {
            let _ = write!(html, "<p>No frames: {e}</p>");
            files.clear();
        }
        let stem = |p: &Path| {
            p.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        let mut named: Vec<(String, PathBuf)> =
            files.iter().map(|p| (stem(p), p.clone())).collect();
        // The scene with a luminaire (a point light with its cube shadow map).
        let lamp = scenes.join("lamp/bunny-lamp.toml");
        if lamp.is_file() {
            named.push(("bunny-lamp".into(), lamp));
        }
        // The sequence is named after its folder (its file is `scene.toml`).
        if let Some(o) = outdoor {
            let folder = o.parent().map_or_else(|| stem(o), stem);
            named.push((format!("outdoor-{folder}"), o.to_path_buf()));
        }
        // The room's live display (docs/ROOMS.md section 14): the bunny of the worked example's
        // edits file in the reconstructed room, Grosch's improved display on the GPU.
        let assets = scenes.parent().unwrap_or(scenes);
        let apartment = assets.join("rooms/apartment");
        let live = ProbeExtras {
            room: Some(apartment.join("room.toml")),
            edit: Some(apartment.join("edits-object.toml")),
            live: true,
            ..ProbeExtras::default()
        };
        let probe = assets.join("probes/apartment.exr");
        let mut jobs: Vec<(String, PathBuf, ProbeExtras)> = named
            .into_iter()
            .map(|(name, scene)| (name, scene, ProbeExtras::default()))
            .collect();
        if probe.is_file() && live.inputs().iter().all(|p| p.is_file()) {
            jobs.push(("room-live-improved".into(), probe, live));
        }
        for (name, scene, extras) in &jobs {
            let png = format!("{VIEWER_DIR}/{name}.png");
            match job(scene, out.join(&png)).run_with(extras, progress) {
                Ok(summary) => {
                    let _ = write!(
                        html,
                        "<figure><a href=\"{png}\"><img class=wide src=\"{png}\"></a>\
                         <figcaption>{}</figcaption></figure>",
                        caption(name, &summary)
                    );
                    data.push(
                        serde_json::json!({ "scene": name, "frame": png, "summary": summary }),
                    );
                }
                Err(e) => {
                    let _ = write!(html, "<p>{name}: no viewer frame: {e}</p>");
                    data.push(serde_json::json!({ "scene": name, "error": e.to_string() }));
                }
            }
        }
        PageSection {
            id: "viewer".into(),
            title: "The real-time viewer".into(),
            html,
            data: serde_json::Value::Array(data),
        }
    }
}
