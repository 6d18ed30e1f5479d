//! The viewer against the CPU renderer: every example scene and the room's important-patches
//! scene (`assets/rooms/apartment/bunny-patches.toml`), lights mode with hard shadows, the
//! same lights (`LightingPlan::build`, the call both make), the same camera and size. The viewer
//! draws direct light only, so the CPU side renders one bounce (direct light) too.
//!
//! Truth and its noise: the CPU render (16 jittered samples per pixel) is exact in the
//! interior of surfaces (hard shadows and directional lights are deterministic: only where a
//! pixel straddles an edge does the jitter matter), so its noise is confined to edge pixels,
//! where 16 samples estimate coverage to about +-0.12 (binomial standard error at 0.5). The GPU
//! differs by construction in three places: shadow maps instead of shadow rays (edges within
//! about a texel), 4x MSAA instead of 16 jittered samples (edge pixels), half-float radiance
//! (2^-11 relative). Thresholds from the issue: mean FLIP <= 0.05, coverage masks (alpha > 0.5)
//! equal on >= 99.5 % of pixels, FLIP through the image-golden helper (`ibl-golden`; failing
//! images go to target/golden-failures/).

mod common;

use ibl_core::{Image, Rgb};
use ibl_render::{RenderSettings, render};
use ibl_scene::{RenderMode, ShadowKind};
use ibl_viewer::SceneModel;
use ibl_viewer::headless::{self, HeadlessOptions};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

fn compare(name: &str) {
    let _ = compare_file(
        name,
        &common::assets().join("scenes").join(format!("{name}.toml")),
    );
}

/// The scene at `path` as the comparison draws it: lights mode, hard shadows.
fn lights_mode(path: &std::path::Path) -> SceneModel {
    let mut model = SceneModel::open(path).expect("the example scene opens");
    model.description.render.mode = RenderMode::Lights;
    model.description.lighting.shadows = ShadowKind::Hard;
    model
}

/// The viewer's frame of `model` at the comparison's size.
fn gpu_frame(gpu: &ibl_viewer::gpu::GpuContext, model: &SceneModel) -> headless::HeadlessRun {
    let options = HeadlessOptions {
        size: (WIDTH, HEIGHT),
        ..Default::default()
    };
    headless::render_scene(gpu, model, &options, &|_, _| {}).expect("gpu renders")
}

/// Compares the viewer with the CPU on the scene at `path` (asserting the thresholds)
/// and returns both composites, GPU first; `None` when no GPU adapter exists.
fn compare_file(name: &str, path: &std::path::Path) -> Option<(Image<Rgb>, Image<Rgb>)> {
    compare_model(name, lights_mode(path))
}

/// [`compare_file`] for a scene already opened (and changed).
fn compare_model(name: &str, model: SceneModel) -> Option<(Image<Rgb>, Image<Rgb>)> {
    let gpu = common::gpu_or_skip(name)?;
    let started = std::time::Instant::now();
    let gpu_run = gpu_frame(&gpu, &model);
    let gpu_seconds = started.elapsed().as_secs_f64();
    let started = std::time::Instant::now();

    let scene = &model.scene;
    let plan = model.lighting_plan();
    let (lighting, _) = plan
        .build(scene, scene.lighting.spp)
        .expect("the same lights");
    let settings = RenderSettings {
        composite: scene.render.composite,
        width: Some(WIDTH),
        spp: 16,
        bounces: 1,
        seed: 1,
        sampler: scene.render.sampler,
        adaptive: None,
        adaptive_sampling: false,
    };
    let cpu = render(scene, &lighting, &settings, &|_, _| {}).expect("cpu renders");
    let cpu_seconds = started.elapsed().as_secs_f64();
    assert_eq!(
        (cpu.composite.width(), cpu.composite.height()),
        (WIDTH as usize, HEIGHT as usize)
    );

    let (outcome, masks_equal) =
        common::against_cpu(&format!("viewer-{name}"), &gpu_run.images, &cpu, 0.05);
    eprintln!(
        "{name}: {outcome:?}, coverage masks equal on {:.3} % (GPU {gpu_seconds:.1} s, CPU \
         {cpu_seconds:.1} s)",
        100.0 * masks_equal
    );
    // The thresholds (see the module notes for where the differences come from).
    if let Err(e) = outcome {
        panic!("{name}: {e}");
    }
    assert!(masks_equal >= 0.995, "{name}: masks equal on {masks_equal}");
    Some((gpu_run.images.radiance, cpu.composite))
}

/// Mean luminance of an image.
fn mean_luminance(image: &Image<Rgb>) -> f64 {
    image
        .pixels()
        .iter()
        .map(|p| f64::from(p.luminance()))
        .sum::<f64>()
        / image.len() as f64
}

#[test]
fn bunny_sky_matches_the_cpu_lights_mode() {
    compare("bunny-sky");
}

#[test]
fn bunny_apartment_matches_the_cpu_lights_mode() {
    compare("bunny-apartment");
}

#[test]
fn the_room_patches_scene_matches_the_cpu_lights_mode() {
    // The bunny lit by the apartment's 32 important patches (Grosch 2005's improved display's
    // lights, read from an area-light file as directional lights).
    let _ = compare_file(
        "bunny-patches",
        &common::assets().join("rooms/apartment/bunny-patches.toml"),
    );
}

#[test]
fn the_lamp_scene_matches_the_cpu_lights_mode() {
    // bunny-sky with the umbrella downlight (a `[[luminaire]]`): its pool on the ground, its
    // light on the bunny and the bunny's shadow of it, a cube shadow map per layer on the GPU
    // against shadow rays on the CPU.
    let path = common::assets().join("scenes/lamp/bunny-lamp.toml");
    let Some((gpu_with, cpu_with)) = compare_file("bunny-lamp", &path) else {
        return;
    };
    // The comparison sees the lamp: without it the viewer's frame is much darker than the CPU's
    // with it, while with it the two agree closely on the mean.
    let gpu = common::gpu_or_skip("bunny-lamp").expect("an adapter, as above");
    let mut model = lights_mode(&path);
    std::sync::Arc::make_mut(&mut model.scene)
        .luminaires
        .clear();
    let gpu_without = gpu_frame(&gpu, &model).images.radiance;
    let (with, without, cpu) = (
        mean_luminance(&gpu_with),
        mean_luminance(&gpu_without),
        mean_luminance(&cpu_with),
    );
    eprintln!(
        "bunny-lamp: mean luminance GPU {with:.4} (without the lamp {without:.4}), CPU {cpu:.4}"
    );
    // The pool fills much of the lower frame (docs/images/scene-luminaire.png): measured 3.6
    // times the frame's mean without it. The renderers' means: measured 0.02 % apart (half
    // floats, 2^-11, and edge pixels); the bound, 1 %, is a tenth of what a lamp 10 % too
    // bright or too dim would move.
    assert!(
        with > 2.0 * without,
        "the lamp adds {with} against {without}"
    );
    assert!(
        (with - cpu).abs() <= 0.01 * cpu,
        "GPU {with} against CPU {cpu}"
    );
}

#[test]
fn the_lamp_scene_matches_the_cpu_under_the_difference_rule_too() {
    // bunny-lamp composites by the ratio rule; under the difference rule a new light's pool is
    // added to the background as `rho / pi E` of the ground's albedo instead.
    let mut model = lights_mode(&common::assets().join("scenes/lamp/bunny-lamp.toml"));
    model.description.render.composite = ibl_scene::description::CompositeRule::Difference;
    std::sync::Arc::make_mut(&mut model.scene).render.composite =
        ibl_scene::description::CompositeRule::Difference;
    let _ = compare_model("bunny-lamp-difference", model);
}

#[test]
fn the_background_is_each_pixels_area_mean_as_on_the_cpu() {
    // A coarse probe (32 x 16 texels of unrelated colours, 11.25 degrees each) seen magnified
    // about 60 times, once across the map and once across the seam where the columns wrap. The
    // CPU renderer takes each pixel's exact area mean of the nearest-texel probe (ibl-render's
    // footprint.rs), so a pixel straddling a texel edge shows the edge's share of its area. The
    // viewer weighs the 2 x 2 texels under the pixel's linearised footprint: exact where one
    // edge crosses it, the product of the two axes' shares at a texel corner. Measured: mean
    // absolute difference 1.8e-4 and 1.7e-4, largest 0.004 (colours 0.05 to 0.95; half floats
    // alone are 5e-4 of 1). A 4 x 4 grid of nearest-texel rays, what the viewer drew before, is
    // off by up to an eighth of an edge's contrast (measured across the map: mean 1.24e-3,
    // largest 0.090) and fails both bounds: 5e-4 (about three times the measured mean) and 0.02
    // (five times the measured largest, a fifth of the grid's).
    let Some(gpu) = common::gpu_or_skip("background") else {
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let probe = Image::from_fn_par(32, 16, |i, j| {
        let level = |k: usize| 0.05 + 0.9 * ((i * 7 + j * 13 + k * 5) % 11) as f32 / 10.0;
        Rgb::new(level(0), level(1), level(2))
    });
    ibl_io::write_image(
        &dir.path().join("probe.exr"),
        &probe,
        &ibl_io::WriteOptions::default(),
    )
    .expect("writes the probe");
    for (view, look_at) in [
        ("across the map", "[0.6, 0.35, -1.0]"),
        ("across the seam", "[0.1, 0.3, 1.0]"),
    ] {
        let path = dir.path().join("background.toml");
        std::fs::write(
            &path,
            format!(
                "version = 1\n[probe]\nfile = \"probe.exr\"\n[camera]\nposition = [0.0, 0.0, 0.0]\n\
                 look_at = {look_at}\nvertical_fov_deg = 30.0\nimage_size_px = [160, 120]\n"
            ),
        )
        .expect("writes the scene");
        let model = lights_mode(&path);
        let options = HeadlessOptions {
            size: (160, 120),
            ..Default::default()
        };
        let gpu_frame = headless::render_scene(&gpu, &model, &options, &|_, _| {})
            .expect("gpu renders")
            .images
            .radiance;
        let cpu = ibl_render::background::background_image(&model.scene, 160, 120);
        let errors: Vec<f32> = gpu_frame
            .pixels()
            .iter()
            .zip(cpu.pixels())
            .map(|(g, c)| {
                (g.r - c.r)
                    .abs()
                    .max((g.g - c.g).abs())
                    .max((g.b - c.b).abs())
            })
            .collect();
        let mean = errors.iter().map(|&e| f64::from(e)).sum::<f64>() / errors.len() as f64;
        let largest = errors.iter().fold(0.0_f32, |m, &e| m.max(e));
        eprintln!("background {view}: mean absolute difference {mean:.2e}, largest {largest:.3}");
        assert!(mean <= 5e-4, "{view}: mean absolute difference {mean}");
        assert!(largest <= 0.02, "{view}: largest difference {largest}");
    }
}
