//! The viewer part of `ibl demo`: each example scene drawn by the real-time viewer headless
//! (`ibl view --headless`), one still frame and a short benchmark (camera orbit, moving object),
//! with their timings, into `view/`. Without a GPU adapter the section says so and the rest of
//! the demo is unaffected.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use ibl_viewer::headless::{self, HeadlessOptions, Motion};
use ibl_viewer::{GpuContext, SceneModel};
use serde::Serialize;

/// Sub-folder of the viewer frames.
pub const VIEW_DIR: &str = "view";
/// Size of the demo's viewer frames (the example cameras are 4:3).
const SIZE: (u32, u32) = (640, 480);
/// Frames of the demo's benchmark (one orbit).
const BENCH_FRAMES: u32 = 60;

/// One scene's viewer frames.
#[derive(Clone, Debug, Serialize)]
pub struct ViewResult {
    /// Scene name (file stem).
    pub name: String,
    /// The still frame's PNG, relative to the demo folder.
    pub preview: String,
    /// Its EXR.
    pub exr: String,
    /// Lights and shadows drawn.
    pub lighting: String,
    /// Shadow map side per light, texels.
    pub shadow_map_texels: u32,
    /// Wall-clock time of the first frame (uploads, shadow atlases), milliseconds.
    pub first_frame_ms: f64,
    /// The benchmark: median and 95th-percentile frame rates while the camera orbits and the
    /// object moves.
    pub bench: headless::RunStatistics,
}

/// What the demo's viewer section found.
#[derive(Clone, Debug, Serialize)]
pub struct ViewSection {
    /// The adapter the frames were drawn on (`None`: no adapter, nothing drawn).
    pub adapter: Option<String>,
    /// Why nothing was drawn.
    pub skipped: Option<String>,
    /// The frames.
    pub scenes: Vec<ViewResult>,
}

fn scene_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot list the example scenes", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    Ok(scenes)
}

/// Draws every scene in `dir` into `out/view/`.
pub fn demo_views(dir: &Path, out: &Path) -> anyhow::Result<ViewSection> {
    let gpu = match GpuContext::headless() {
        Ok(gpu) => gpu,
        Err(e) => {
            return Ok(ViewSection {
                adapter: None,
                skipped: Some(e.to_string()),
                scenes: Vec::new(),
            });
        }
    };
    let folder = out.join(VIEW_DIR);
    std::fs::create_dir_all(&folder)
        .with_context(|| format!("{}: cannot create", folder.display()))?;
    let mut scenes = Vec::new();
    for path in scene_files(dir)? {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let model = SceneModel::open(&path)?;
        let still = headless::render_scene(
            &gpu,
            &model,
            &HeadlessOptions {
                size: SIZE,
                ..Default::default()
            },
            &|_, _| {},
        )?;
        let bench = headless::render_scene(
            &gpu,
            &model,
            &HeadlessOptions {
                size: SIZE,
                frames: BENCH_FRAMES,
                motion: Motion::Orbit,
                ..Default::default()
            },
            &|_, _| {},
        )?;
        let png = folder.join(format!("{name}.png"));
        let exr = folder.join(format!("{name}.exr"));
        let bytes = ibl_io::ldr::encode_png(&still.images.display).map_err(|e| e.with_path(&png))?;
        ibl_io::write_atomically(&png, &bytes)?;
        ibl_io::write_image(&exr, &still.images.radiance, &ibl_io::WriteOptions::default())?;
        scenes.push(ViewResult {
            name,
            preview: crate::cmd::demo::relative(out, &png),
            exr: crate::cmd::demo::relative(out, &exr),
            lighting: still.lighting.clone(),
            shadow_map_texels: still.shadow_tile,
            first_frame_ms: still.frames.first().map_or(0.0, |f| f.wall_seconds * 1e3),
            bench: bench.statistics,
        });
    }
    Ok(ViewSection {
        adapter: Some(gpu.summary.line()),
        skipped: None,
        scenes,
    })
}

/// The viewer section of the demo's `index.html`.
pub fn views_html(section: &ViewSection) -> String {
    let mut html = String::from(
        "<h1 id=view>The real-time viewer</h1><p>The example scenes drawn by <code>ibl view \
         --headless</code> (every light with its own shadow map, differential compositing, 4x \
         MSAA), and a benchmark of one camera orbit while the bunny moves.</p>",
    );
    match (&section.adapter, &section.skipped) {
        (_, Some(why)) => {
            let _ = write!(html, "<p>Skipped: {why}</p>");
        }
        (Some(adapter), None) => {
            let _ = write!(html, "<p>GPU: {adapter}</p>");
        }
        (None, None) => {}
    }
    for s in &section.scenes {
        let b = &s.bench;
        let _ = write!(
            html,
            "<figure><img src=\"{}\"><figcaption>{}: {}, shadow maps {}&sup2;; first frame {:.0} ms; \
             orbit with the object moving: {:.1} fps median, {:.1} fps at p95 \
             ({:.1} / {:.1} ms)</figcaption></figure>",
            s.preview,
            s.name,
            s.lighting,
            s.shadow_map_texels,
            s.first_frame_ms,
            b.fps_median,
            b.fps_p95,
            b.frame_ms_median,
            b.frame_ms_p95
        );
    }
    html
}
