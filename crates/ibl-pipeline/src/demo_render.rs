//! The rendering part of `ibl demo`: the bundled example scenes (`assets/scenes/*.toml`: the
//! bunny in an outdoor probe with a hard sun and in an indoor probe) rendered the ways iblkit
//! offers, and every light approximation scored by its render against the path-traced reference.
//!
//! Per scene, into `renders/<scene>/`, each at the scene's own settings for its mode
//! (`RenderSettings::for_scene`): the reference composite (perspective view, several bounces),
//! the same in the whole panorama, light renders with N = 4, 16 and 64 median-cut lights with soft
//! shadows and 16 with hard shadows, the hybrid (16 lights + the scene's SH ambient, 5 bands, with
//! directional occlusion), the with/without layers of the reference, each light render with its time, its
//! speed-up over the reference and its error against it; then the study of
//! `ibl_eval::render_study` (methods x N = 1..256 with soft shadows, every method's hybrid at
//! N = 16, median cut with hard shadows, against a direct-light reference) with its table in
//! `renders/report.md` and its chart as SVG and PNG.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ibl_core::tonemap::{Display, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_eval::{RenderStudy, RenderStudySettings, render_study};
use ibl_extract::ModelSpec;
use ibl_io::WriteOptions;
use ibl_light::Method;
use ibl_render::{RenderOutput, RenderSettings, render};
use ibl_scene::{Camera, RenderMode, Scene, ShadowKind};
use serde::Serialize;

use crate::demo_paths::{RENDER_DIR, relative};
use crate::error::{Context, Result};
use crate::lighting_plan::LightingPlan;
use crate::progress::{Progress, rows};
/// Width of the demo's perspective renders (the scenes' views are 4:3).
const VIEW_WIDTH: u32 = 320;
/// Width of the demo's panorama composites.
const PANORAMA_WIDTH: u32 = 512;
/// Light counts of the showcase light renders.
const SHOWCASE_COUNTS: [usize; 3] = [4, 16, 64];
/// Light count of the showcase's hard-shadow and hybrid renders.
const SHOWCASE_MODE_LIGHTS: usize = 16;
/// Width of the study's renders (small: every method at every N is rendered).
const STUDY_WIDTH: u32 = 128;
/// Light counts of the study.
const STUDY_COUNTS: [usize; 9] = [1, 2, 4, 8, 16, 32, 64, 128, 256];
/// Samples per pixel of the study's path-traced references.
const STUDY_REFERENCE_SPP: u32 = 512;

/// One image the demo wrote, for the index page.
#[derive(Clone, Debug, Serialize)]
pub struct RenderedImage {
    /// What it shows.
    pub caption: String,
    /// The PNG preview, relative to the demo folder.
    pub preview: String,
    /// The EXR, relative to the demo folder.
    pub exr: String,
    /// Seconds it took to render (lighting built and image rendered).
    pub seconds: f64,
    /// How many times faster than the reference it rendered (light and hybrid renders only).
    pub speedup: Option<f64>,
    /// Relative MSE and mean FLIP of the composite against the reference composite (light and
    /// hybrid renders only).
    pub against_reference: Option<(f64, f64)>,
}

/// What the demo rendered for one scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneResult {
    /// Scene name (the file stem).
    pub name: String,
    /// The showcase images.
    pub images: Vec<RenderedImage>,
    /// The study.
    pub study: RenderStudy,
    /// The study's chart (SVG and PNG), relative to the demo folder.
    pub chart: [String; 2],
}

/// Whether a showcase image is scored against the reference (time ratio and error).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scored {
    /// A light or hybrid render.
    AgainstReference,
    /// The reference itself, its layers, the background, the panorama.
    No,
}

/// The study's methods: every light extraction method (median cut only at powers of two).
fn study_methods() -> Vec<ModelSpec> {
    Method::ALL.into_iter().map(ModelSpec::from).collect()
}

/// Relative MSE and mean FLIP of `test` against `reference`.
fn against(test: &Image<Rgb>, reference: &Image<Rgb>) -> Result<(f64, f64)> {
    let d = ibl_metrics::ImageDifference::between(test, reference, None)?;
    let f = ibl_metrics::flip(test, reference, &ibl_metrics::FlipOptions::default())?;
    Ok((d.relative_mse, f.mean()))
}

/// The demo's scene files: every `*.toml` in `dir`, sorted as `ibl_io::list_dir` sorts them.
pub fn list_scenes(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut scenes = ibl_io::list_dir(dir)?;
    scenes.retain(|p| p.extension().is_some_and(|e| e == "toml"));
    Ok(scenes)
}

/// Renders every scene of [`list_scenes`] in `dir` into `out/renders/`.
pub fn demo_renders(dir: &Path, out: &Path, progress: &dyn Progress) -> Result<Vec<SceneResult>> {
    let scenes = list_scenes(dir)?;
    let mut results = Vec::new();
    for path in scenes {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        results.push(
            demo_scene(&path, &name, out, progress)
                .context(format!("demo render of {}", path.display()))?,
        );
    }
    let md = results
        .iter()
        .map(|r| format!("{}\n{}", showcase_markdown(r), r.study.markdown()))
        .collect::<Vec<_>>()
        .join("\n");
    let report = format!(
        "# Renders: light approximations against the path-traced reference\n\n\
         Per scene: the showcase renders (composites at the scene's own settings per mode: the \
         reference's samples and bounces, the lights' antialiasing samples) with their time, \
         speed-up and error against the reference composite; then the study, where every method \
         at every N lights the scene (soft shadows unless marked, hybrids at N = 16) against a \
         path-traced reference of the whole probe (importance sampling and MIS), both with one \
         bounce (direct light), so the numbers show what a light set gets wrong about direct \
         light and shadows. The charts are beside this file.\n\n{md}"
    );
    ibl_io::write_atomically(&out.join(RENDER_DIR).join("report.md"), report.as_bytes())?;
    Ok(results)
}

/// The showcase renders of a scene and their error against its reference, as Markdown.
fn showcase_markdown(r: &SceneResult) -> String {
    let mut md = format!(
        "## {}\n\n| image | seconds | faster than the reference | relative MSE vs reference | FLIP vs reference |\n|---|---:|---:|---:|---:|\n",
        r.name
    );
    for image in &r.images {
        let (relative_mse, flip) = image
            .against_reference
            .map_or(("-".to_string(), "-".to_string()), |(e, f)| {
                (format!("{e:.2e}"), format!("{f:.3}"))
            });
        let speedup = image
            .speedup
            .map_or("-".to_string(), |x| format!("{x:.1}x"));
        let _ = writeln!(
            md,
            "| [{}]({}) | {:.2} | {speedup} | {relative_mse} | {flip} |",
            image.caption,
            image.preview.trim_start_matches("renders/"),
            image.seconds
        );
    }
    md
}

fn write_render(
    out: &Path,
    dir: &Path,
    stem: &str,
    caption: String,
    image: &Image<Rgb>,
    display: &WriteOptions,
    seconds: f64,
) -> Result<RenderedImage> {
    let exr = dir.join(format!("{stem}.exr"));
    let png = dir.join(format!("{stem}.png"));
    ibl_io::write_image(&exr, image, &WriteOptions::default())?;
    ibl_io::write_image(&png, image, display)?;
    Ok(RenderedImage {
        caption,
        preview: relative(out, &png),
        exr: relative(out, &exr),
        seconds,
        speedup: None,
        against_reference: None,
    })
}

fn timed_render(
    scene: &Scene,
    plan: &LightingPlan,
    settings: &RenderSettings,
) -> Result<(RenderOutput, f64)> {
    let started = std::time::Instant::now();
    let (lighting, _) = plan.build(scene, settings.spp)?;
    let output = render(scene, &lighting, settings, &|_, _| {})?;
    Ok((output, started.elapsed().as_secs_f64()))
}

fn demo_scene(path: &Path, name: &str, out: &Path, progress: &dyn Progress) -> Result<SceneResult> {
    let loaded = ibl_io::read_scene(path)?;
    let scene = loaded.scene;
    let dir = out.join(RENDER_DIR).join(name);
    ibl_io::create_dir_all(&dir)?;
    let steps = (SHOWCASE_COUNTS.len() + 4) as u64;
    progress.begin(name, steps);
    let showcase = showcase(&scene, &dir, out, &mut |done| {
        progress.update(done, steps, None);
    });
    progress.end();
    let (images, display) = showcase?;
    study(&scene, name, &dir, out, &display, images, progress)
}

/// The showcase renders of a scene into `dir` (`step(done)` after each group), and the display
/// transform every preview of the scene shares (the reference background's exposure).
fn showcase(
    scene: &Scene,
    dir: &Path,
    out: &Path,
    step: &mut dyn FnMut(u64),
) -> Result<(Vec<RenderedImage>, WriteOptions)> {
    // The scene's own settings for each mode (docs/SCENES.md): the reference at `[render] spp`
    // and bounces, the lights and hybrid at `[lighting] spp`, at the showcase width.
    let settings = RenderSettings {
        width: Some(VIEW_WIDTH),
        ..RenderSettings::for_scene(scene, RenderMode::Reference)
    };
    let lights_settings = RenderSettings {
        width: Some(VIEW_WIDTH),
        ..RenderSettings::for_scene(scene, RenderMode::Lights)
    };
    let base = LightingPlan::from_scene(scene);
    let mut images = Vec::new();

    // The reference, its layers, and the exposure every preview of the scene shares.
    let reference_plan = LightingPlan {
        mode: RenderMode::Reference,
        ..base.clone()
    };
    let (reference, reference_seconds) = timed_render(scene, &reference_plan, &settings)?;
    let display = WriteOptions {
        display: Display {
            exposure_stops: auto_exposure_stops(&reference.background),
            ..Display::default()
        },
        ..WriteOptions::default()
    };
    let reference_composite = reference.composite.clone();
    // Writes an image; light and hybrid renders also get their speed-up and error against the
    // reference.
    let mut add = |stem: &str,
                   caption: String,
                   image: &Image<Rgb>,
                   seconds: f64,
                   scored: Scored|
     -> Result<()> {
        let mut written = write_render(out, dir, stem, caption, image, &display, seconds)?;
        if scored == Scored::AgainstReference {
            written.speedup = Some(reference_seconds / seconds.max(1e-9));
            written.against_reference = Some(against(image, &reference_composite)?);
        }
        images.push(written);
        Ok(())
    };
    add(
        "reference",
        format!(
            "reference: path-traced, {} spp ({}), {} bounces, composited ({})",
            settings.spp,
            settings.sampler.name(),
            settings.bounces,
            settings.composite.name()
        ),
        &reference.composite,
        reference_seconds,
        Scored::No,
    )?;
    add(
        "reference-with",
        "local scene with the bunny".into(),
        &reference.with_objects,
        0.0,
        Scored::No,
    )?;
    add(
        "reference-without",
        "local scene without it".into(),
        &reference.without_objects,
        0.0,
        Scored::No,
    )?;
    add(
        "background",
        "background".into(),
        &reference.background,
        0.0,
        Scored::No,
    )?;
    step(1);

    let spp = lights_settings.spp;
    let light_runs = SHOWCASE_COUNTS
        .iter()
        .map(|&n| (n, ShadowKind::Soft))
        .chain(std::iter::once((SHOWCASE_MODE_LIGHTS, ShadowKind::Hard)));
    for (k, (n, shadows)) in light_runs.enumerate() {
        let plan = LightingPlan {
            shadows,
            ..LightingPlan::median_cut(scene, RenderMode::Lights, n)
        };
        let (output, seconds) = timed_render(scene, &plan, &lights_settings)?;
        let shadows = shadows.name();
        add(
            &format!("lights-median-cut-{n}-{shadows}"),
            format!("{n} median-cut lights, {shadows} shadows, {spp} spp"),
            &output.composite,
            seconds,
            Scored::AgainstReference,
        )?;
        step(2 + k as u64);
    }
    let hybrid_plan = LightingPlan {
        shadows: ShadowKind::Soft,
        ..LightingPlan::median_cut(scene, RenderMode::Hybrid, SHOWCASE_MODE_LIGHTS)
    };
    let (hybrid, seconds) = timed_render(scene, &hybrid_plan, &lights_settings)?;
    add(
        "hybrid",
        format!(
            "hybrid: {SHOWCASE_MODE_LIGHTS} median-cut lights (soft shadows) + SH{} ambient, \
             {} occlusion rays, {spp} spp",
            hybrid_plan.ray_bands(spp).pow(2),
            hybrid_plan.occlusion_rays
        ),
        &hybrid.composite,
        seconds,
        Scored::AgainstReference,
    )?;
    step(3 + SHOWCASE_COUNTS.len() as u64);

    // The whole panorama, when the background is the probe.
    if matches!(scene.background, ibl_scene::Background::Panorama) {
        let mut panorama = scene.clone();
        panorama.camera = Camera::Panorama {
            position: scene.probe.position,
            world_from_probe: scene.probe.world_from_probe,
        };
        let pano_settings = RenderSettings {
            width: Some(PANORAMA_WIDTH),
            spp: (settings.spp / 4).max(1),
            ..settings
        };
        let (output, seconds) = timed_render(&panorama, &reference_plan, &pano_settings)?;
        add(
            "panorama",
            format!("the whole panorama, reference, {} spp", pano_settings.spp),
            &output.composite,
            seconds,
            Scored::No,
        )?;
    }
    step(4 + SHOWCASE_COUNTS.len() as u64);
    Ok((images, display))
}

/// The study of a scene (every method at every N against a direct-light reference) with its
/// images under `dir/study/` and its chart beside `renders/report.md`.
fn study(
    scene: &Scene,
    name: &str,
    dir: &Path,
    out: &Path,
    display: &WriteOptions,
    images: Vec<RenderedImage>,
    progress: &dyn Progress,
) -> Result<SceneResult> {
    // Every method at every N with soft shadows; the hybrid of every method at the showcase's N;
    // median cut with hard shadows at every N.
    let base = LightingPlan::from_scene(scene);
    let lights_defaults = RenderSettings::for_scene(scene, RenderMode::Lights);
    let methods = study_methods();
    let hybrids: Vec<ModelSpec> = methods
        .iter()
        .filter_map(|m| match m {
            ModelSpec::Lights(source) => Some(ModelSpec::Hybrid {
                lights: *source,
                bands: base.ray_bands(lights_defaults.spp),
            }),
            _ => None,
        })
        .collect();
    let mut runs = RenderStudySettings::grid(&methods, &STUDY_COUNTS, ShadowKind::Soft);
    runs.extend(RenderStudySettings::grid(
        &hybrids,
        &[SHOWCASE_MODE_LIGHTS],
        ShadowKind::Soft,
    ));
    runs.extend(RenderStudySettings::grid(
        &[ModelSpec::from(Method::MedianCut)],
        &STUDY_COUNTS,
        ShadowKind::Hard,
    ));
    let study_settings = RenderStudySettings {
        runs,
        width: Some(STUDY_WIDTH),
        reference_spp: STUDY_REFERENCE_SPP,
        lights_spp: lights_defaults.spp,
        lights_adaptive: lights_defaults.adaptive,
        bounces: 1,
        sampler: lights_defaults.sampler,
        occlusion_rays: base.occlusion_rays,
        seed: scene.render.seed,
    };
    let runs = study_settings.runs.len() + 2;
    progress.begin(&format!("{name}: study"), runs as u64);
    let studied = render_study(scene, name, &study_settings, &rows(progress));
    progress.end();
    let (study, study_images) = studied?;
    let study_dir = dir.join("study");
    ibl_io::create_dir_all(&study_dir)?;
    ibl_io::write_image(
        &study_dir.join("reference.png"),
        &study_images.reference.with_objects,
        display,
    )?;
    for (label, n, output) in &study_images.lights {
        let stem = label.replace(" (", "-").replace(')', "");
        ibl_io::write_image(
            &study_dir.join(format!("{stem}-{n}.png")),
            &output.with_objects,
            display,
        )?;
    }
    let chart = study.chart();
    let svg = ibl_eval::render_svg(&chart, ibl_eval::PLOT_SIZE)?;
    let svg_path = out.join(RENDER_DIR).join(format!("{name}-study.svg"));
    ibl_io::write_atomically(&svg_path, svg.as_bytes())?;
    let png_path = out.join(RENDER_DIR).join(format!("{name}-study.png"));
    let png = ibl_io::ldr::encode_png(&ibl_eval::render_png(&chart, ibl_eval::PLOT_SIZE)?)
        .map_err(|e| e.with_path(&png_path))?;
    ibl_io::write_atomically(&png_path, &png)?;
    Ok(SceneResult {
        name: name.to_string(),
        images,
        study,
        chart: [relative(out, &svg_path), relative(out, &png_path)],
    })
}
