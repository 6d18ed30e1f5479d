//! The rendering part of `ibl demo`: the bundled example scenes (`assets/scenes/*.toml`: the
//! bunny in an outdoor probe with a hard sun and in an indoor probe) rendered the ways iblkit
//! offers, and every light approximation scored by its render against the path-traced reference.
//!
//! Per scene, into `renders/<scene>/`, each at the scene's own settings for its mode
//! (`RenderSettings::for_scene`): the reference composite (perspective view, several bounces),
//! the same in the whole panorama, light renders with N = 4, 16 and 64 median-cut lights with soft
//! shadows and 16 with hard shadows, the hybrid (16 lights + SH9 ambient with directional
//! occlusion), the with/without layers of the reference, each light render with its time, its
//! speed-up over the reference and its error against it; then the study of
//! `ibl_eval::render_study` (methods x N = 1..256 with soft shadows, every method's hybrid at
//! N = 16, median cut with hard shadows, against a direct-light reference) with its table in
//! `renders/report.md` and its chart as SVG and PNG.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use ibl_core::{Image, Rgb};
use ibl_eval::{RenderStudy, RenderStudySettings, render_study};
use ibl_extract::{Method, ModelSpec};
use ibl_io::{Display, WriteOptions};
use ibl_render::lighting::LightingPlan;
use ibl_render::{RenderOutput, RenderSettings, render};
use ibl_scene::{Camera, RenderMode, Scene, ShadowKind};
use serde::Serialize;

use crate::progress;

/// Sub-folder of the renders.
pub const RENDER_DIR: &str = "renders";
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

/// The example scenes bundled with iblkit.
pub fn default_scene_dir() -> PathBuf {
    crate::cmd::demo::assets_dir().join("scenes")
}

/// The study's methods: every light extraction method (median cut only at powers of two).
fn study_methods() -> Vec<ModelSpec> {
    Method::ALL.into_iter().map(ModelSpec::from).collect()
}

/// Relative MSE and mean FLIP of `test` against `reference`.
fn against(test: &Image<Rgb>, reference: &Image<Rgb>) -> anyhow::Result<(f64, f64)> {
    let d = ibl_eval::ImageDifference::between(test, reference, None)?;
    let f = ibl_eval::flip(test, reference, &ibl_eval::FlipOptions::default())?;
    Ok((d.relative_mse, f.mean()))
}

/// Renders every scene in `dir` into `out/renders/`.
pub fn demo_renders(dir: &Path, out: &Path) -> anyhow::Result<Vec<SceneResult>> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot list the example scenes", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    let mut results = Vec::new();
    for path in scenes {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        results.push(
            demo_scene(&path, &name, out)
                .with_context(|| format!("demo render of {}", path.display()))?,
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
         light and shadows. The charts are beside this \
         file.\n\n{md}"
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
) -> anyhow::Result<RenderedImage> {
    let exr = dir.join(format!("{stem}.exr"));
    let png = dir.join(format!("{stem}.png"));
    ibl_io::write_image(&exr, image, &WriteOptions::default())?;
    ibl_io::write_image(&png, image, display)?;
    Ok(RenderedImage {
        caption,
        preview: crate::cmd::demo::relative(out, &png),
        exr: crate::cmd::demo::relative(out, &exr),
        seconds,
        speedup: None,
        against_reference: None,
    })
}

fn timed_render(
    scene: &Scene,
    plan: &LightingPlan,
    settings: &RenderSettings,
) -> anyhow::Result<(RenderOutput, f64)> {
    let started = std::time::Instant::now();
    let (lighting, _) = plan.build(scene)?;
    let output = render(scene, &lighting, settings, &|_, _| {})?;
    Ok((output, started.elapsed().as_secs_f64()))
}

fn demo_scene(path: &Path, name: &str, out: &Path) -> anyhow::Result<SceneResult> {
    let loaded = ibl_io::read_scene(path)?;
    let scene = loaded.scene;
    let dir = out.join(RENDER_DIR).join(name);
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let bar = progress::bar(name, (SHOWCASE_COUNTS.len() + 4) as u64);
    // The scene's own settings for each mode (docs/SCENES.md): the reference at `[render] spp`
    // and bounces, the lights and hybrid at `[lighting] spp`, at the showcase width.
    let settings = RenderSettings {
        width: Some(VIEW_WIDTH),
        ..RenderSettings::for_scene(&scene, RenderMode::Reference)
    };
    let lights_settings = RenderSettings {
        width: Some(VIEW_WIDTH),
        ..RenderSettings::for_scene(&scene, RenderMode::Lights)
    };
    let base = LightingPlan::from_scene(&scene);
    let mut images = Vec::new();

    // The reference, its layers, and the exposure every preview of the scene shares.
    let reference_plan = LightingPlan {
        mode: RenderMode::Reference,
        ..base.clone()
    };
    let (reference, reference_seconds) = timed_render(&scene, &reference_plan, &settings)?;
    let display = WriteOptions {
        display: Display {
            exposure_stops: ibl_io::tonemap::auto_exposure_stops(&reference.background),
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
                   scored: bool|
     -> anyhow::Result<()> {
        let mut written = write_render(out, &dir, stem, caption, image, &display, seconds)?;
        if scored {
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
        false,
    )?;
    add(
        "reference-with",
        "local scene with the bunny".into(),
        &reference.with_objects,
        0.0,
        false,
    )?;
    add(
        "reference-without",
        "local scene without it".into(),
        &reference.without_objects,
        0.0,
        false,
    )?;
    add(
        "background",
        "background".into(),
        &reference.background,
        0.0,
        false,
    )?;
    bar.inc(1);

    let spp = lights_settings.spp;
    let light_runs = SHOWCASE_COUNTS
        .iter()
        .map(|&n| (n, ShadowKind::Soft))
        .chain(std::iter::once((SHOWCASE_MODE_LIGHTS, ShadowKind::Hard)));
    for (n, shadows) in light_runs {
        let plan = LightingPlan {
            mode: RenderMode::Lights,
            method: "median-cut".into(),
            lights: n,
            shadows,
            ..base.clone()
        };
        let (output, seconds) = timed_render(&scene, &plan, &lights_settings)?;
        let shadows = shadows.name();
        add(
            &format!("lights-median-cut-{n}-{shadows}"),
            format!("{n} median-cut lights, {shadows} shadows, {spp} spp"),
            &output.composite,
            seconds,
            true,
        )?;
        bar.inc(1);
    }
    let hybrid_plan = LightingPlan {
        mode: RenderMode::Hybrid,
        method: "median-cut".into(),
        lights: SHOWCASE_MODE_LIGHTS,
        shadows: ShadowKind::Soft,
        ..base.clone()
    };
    let (hybrid, seconds) = timed_render(&scene, &hybrid_plan, &lights_settings)?;
    add(
        "hybrid",
        format!(
            "hybrid: {SHOWCASE_MODE_LIGHTS} median-cut lights (soft shadows) + SH{} ambient, \
             {} occlusion rays, {spp} spp",
            hybrid_plan.ambient_bands * hybrid_plan.ambient_bands,
            hybrid_plan.occlusion_rays
        ),
        &hybrid.composite,
        seconds,
        true,
    )?;
    bar.inc(1);

    // The whole panorama, when the background is the probe.
    if matches!(scene.background, ibl_scene::Background::Panorama) {
        let mut panorama = scene.clone();
        panorama.camera = Camera::Panorama {
            position: scene.probe.position,
            world_from_probe: scene.probe.world_from_probe,
        };
        let pano_settings = RenderSettings {
            width: Some(PANORAMA_WIDTH),
            spp: settings.spp / 4,
            ..settings
        };
        let (output, seconds) = timed_render(&panorama, &reference_plan, &pano_settings)?;
        add(
            "panorama",
            format!("the whole panorama, reference, {} spp", pano_settings.spp),
            &output.composite,
            seconds,
            false,
        )?;
    }
    bar.inc(1);
    bar.finish_and_clear();

    // The study: every method at every N against a direct-light reference, soft shadows; the
    // hybrid of every method at the showcase's N; median cut with hard shadows at every N.
    let methods = study_methods();
    let hybrids: Vec<ModelSpec> = methods
        .iter()
        .filter_map(|m| match m {
            ModelSpec::Lights(source) => Some(ModelSpec::Hybrid {
                lights: *source,
                bands: base.ambient_bands,
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
        lights_spp: lights_settings.spp,
        bounces: 1,
        sampler: settings.sampler,
        occlusion_rays: base.occlusion_rays,
        seed: scene.render.seed,
    };
    let runs = study_settings.runs.len() + 2;
    let bar = progress::bar(&format!("{name}: study"), runs as u64);
    let (study, study_images) = render_study(
        &scene,
        name,
        &study_settings,
        &progress::rows_callback(&bar),
    )?;
    bar.finish_and_clear();
    let study_dir = dir.join("study");
    std::fs::create_dir_all(&study_dir)
        .with_context(|| format!("{}: cannot create", study_dir.display()))?;
    ibl_io::write_image(
        &study_dir.join("reference.png"),
        &study_images.reference.with_objects,
        &display,
    )?;
    for (label, n, output) in &study_images.lights {
        let stem = label.replace(" (", "-").replace(')', "");
        ibl_io::write_image(
            &study_dir.join(format!("{stem}-{n}.png")),
            &output.with_objects,
            &display,
        )?;
    }
    let chart = study.chart();
    let svg = ibl_eval::render_svg(&chart, ibl_eval::PLOT_SIZE)?;
    let svg_path = out.join(RENDER_DIR).join(format!("{name}-study.svg"));
    ibl_io::write_atomically(&svg_path, svg.as_bytes())?;
    let png = ibl_io::ldr::encode_png(&ibl_eval::render_png(&chart, ibl_eval::PLOT_SIZE)?)
        .context("encoding the study chart")?;
    let png_path = out.join(RENDER_DIR).join(format!("{name}-study.png"));
    ibl_io::write_atomically(&png_path, &png)?;
    Ok(SceneResult {
        name: name.to_string(),
        images,
        study,
        chart: [
            crate::cmd::demo::relative(out, &svg_path),
            crate::cmd::demo::relative(out, &png_path),
        ],
    })
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
