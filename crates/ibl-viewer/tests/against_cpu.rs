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

use ibl_render::{RenderSettings, render};
use ibl_scene::{RenderMode, ShadowKind};
use ibl_viewer::SceneModel;
use ibl_viewer::headless::{self, HeadlessOptions};

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

fn compare(name: &str) {
    compare_file(
        name,
        &common::assets().join("scenes").join(format!("{name}.toml")),
    );
}

fn compare_file(name: &str, path: &std::path::Path) {
    let Some(gpu) = common::gpu_or_skip(name) else {
        return;
    };
    let mut model = SceneModel::open(path).expect("the example scene opens");
    model.description.render.mode = RenderMode::Lights;
    model.description.lighting.shadows = ShadowKind::Hard;
    let options = HeadlessOptions {
        size: (WIDTH, HEIGHT),
        ..Default::default()
    };
    let started = std::time::Instant::now();
    let gpu_run = headless::render_scene(&gpu, &model, &options, &|_, _| {}).expect("gpu renders");
    let gpu_seconds = started.elapsed().as_secs_f64();
    let started = std::time::Instant::now();

    let scene = &model.scene;
    let plan = model.lighting_plan();
    let (lighting, _) = plan.build(scene).expect("the same lights");
    let settings = RenderSettings {
        composite: scene.render.composite,
        width: Some(WIDTH),
        spp: 16,
        bounces: 1,
        seed: 1,
        sampler: scene.render.sampler,
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
    compare_file(
        "bunny-patches",
        &common::assets().join("rooms/apartment/bunny-patches.toml"),
    );
}
