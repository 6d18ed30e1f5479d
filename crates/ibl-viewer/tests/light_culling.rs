//! The light culling keeps the frame: real surfaces that loop over only their screen tile's
//! lights (`light_tiles.rs`, each light kept where its caster cells can shadow the tile) give
//! the frame that testing every light on every real pixel gives. The culling is conservative,
//! and the lights a pixel keeps are summed in the same order either way, so the two frames
//! differ only by what the two compiled shaders round differently; a light wrongly culled from
//! a tile would lose a shadow there, a change of the order of the shadow's contrast (tens of
//! per cent). Soft shadows (PCSS), where the culling reaches furthest (the blocker search's
//! radius), on both example scenes.

mod common;

use ibl_core::{Image, Rgb};
use ibl_viewer::SceneModel;
use ibl_viewer::headless::{self, HeadlessOptions};

fn frame(gpu: &ibl_viewer::gpu::GpuContext, model: &SceneModel, light_culling: bool) -> Image<Rgb> {
    let options = HeadlessOptions {
        size: (320, 240),
        light_culling,
        ..Default::default()
    };
    headless::render_scene(gpu, model, &options, &|_, _| {})
        .expect("gpu renders")
        .images
        .radiance
}

fn culled_equals_unculled(name: &str) {
    let Some(gpu) = common::gpu_or_skip(name) else {
        return;
    };
    let path = common::assets().join("scenes").join(format!("{name}.toml"));
    let mut model = SceneModel::open(&path).expect("the example scene opens");
    model.description.lighting.shadows = ibl_scene::ShadowKind::Soft;
    let culled = frame(&gpu, &model, true);
    let every = frame(&gpu, &model, false);
    let mut worst = 0.0f32;
    for (a, b) in culled.pixels().iter().zip(every.pixels()) {
        for (x, y) in [(a.r, b.r), (a.g, b.g), (a.b, b.b)] {
            worst = worst.max((x - y).abs() / (1e-3 + y.abs()));
        }
    }
    eprintln!("{name}: largest relative difference {worst:e}");
    // Half-float radiance: 2^-11 relative, with room for the two shaders' rounding.
    assert!(worst <= 4e-3, "{name}: culling changed a pixel by {worst}");
}

#[test]
fn bunny_sky_is_the_same_with_and_without_the_culling() {
    culled_equals_unculled("bunny-sky");
}

#[test]
fn bunny_apartment_is_the_same_with_and_without_the_culling() {
    culled_equals_unculled("bunny-apartment");
}
