//! The light culling keeps the frame: real surfaces that loop over only their screen tile's
//! lights (`light_tiles.rs`, each light kept where its caster cells can shadow the tile) give
//! the frame that testing every light on every real pixel gives. The culling is conservative,
//! and the lights a pixel keeps are summed in the same order either way, so the two frames
//! differ only by what the two compiled shaders round differently; a light wrongly culled from
//! a tile would lose a shadow there, a change of the order of the shadow's contrast (tens of
//! per cent). Soft shadows (PCSS), where the culling reaches furthest (the blocker search's
//! radius), on both example scenes; and the point lights' culling (each light already in the
//! background kept where the cone of the objects' bounding sphere from it can reach the tile,
//! every new light kept where it can shine) on the room's live display, improved and fast,
//! with and without a new downlight, and on the bunny under the umbrella luminaire.

mod common;

use ibl_core::{Image, Rgb};
use ibl_pipeline::progress::Silent;
use ibl_viewer::headless::{self, HeadlessOptions};
use ibl_viewer::lighting::SceneLighting;
use ibl_viewer::room_live::room_live;
use ibl_viewer::{SceneModel, gpu::GpuContext};

fn frame(
    gpu: &GpuContext,
    model: &SceneModel,
    lighting: &SceneLighting,
    light_culling: bool,
) -> Image<Rgb> {
    let options = HeadlessOptions {
        size: (320, 240),
        light_culling,
        ..Default::default()
    };
    common::radiance(gpu, model, lighting, &options)
}

/// An example scene (`assets/scenes/NAME.toml`) with soft shadows.
fn culled_equals_unculled(name: &str) {
    let Some(gpu) = common::gpu_or_skip(name) else {
        return;
    };
    let path = common::assets().join("scenes").join(format!("{name}.toml"));
    let mut model = SceneModel::open(&path).expect("the example scene opens");
    model.description.lighting.shadows = ibl_scene::ShadowKind::Soft;
    let (lighting, _) = headless::lights_now(&model).expect("the scene's lights");
    compare(name, &gpu, &model, &lighting);
}

/// The apartment's live display with the bundled edits file `edits` (display `display`).
fn room_culled_equals_unculled(edits: &str, display: &str) {
    let Some(gpu) = common::gpu_or_skip(edits) else {
        return;
    };
    let assets = common::assets();
    let text = std::fs::read_to_string(assets.join("rooms/apartment").join(edits))
        .expect("the bundled edits file")
        .replace("\"../../", &format!("\"{}/", assets.display()))
        .replace(
            "display = \"improved\"",
            &format!("display = \"{display}\""),
        );
    assert!(
        text.contains(&format!("display = \"{display}\"")),
        "{edits}: no display line"
    );
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join(edits);
    std::fs::write(&path, text).expect("writes the edits file");
    let room = assets.join("rooms/apartment/room.toml");
    let mut live = room_live(&room, &path, &Silent).expect("the live display");
    assert!(
        live.lighting.luminaires.len() >= 32,
        "{edits}: the 32 patches as point lights"
    );
    compare(
        &format!("{edits} ({display})"),
        &gpu,
        &live.model,
        &live.lighting,
    );
    // Turned and moved: the shadow cones follow the objects' sphere.
    live.model.rotate(0, 75.0);
    live.model.translate(0, glam::Vec3::new(0.1, 0.0, -0.05));
    compare(
        &format!("{edits} ({display}), moved"),
        &gpu,
        &live.model,
        &live.lighting,
    );
}

fn compare(name: &str, gpu: &GpuContext, model: &SceneModel, lighting: &SceneLighting) {
    let culled = frame(gpu, model, lighting, true);
    let every = frame(gpu, model, lighting, false);
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

#[test]
fn bunny_lamp_is_the_same_with_and_without_the_culling() {
    culled_equals_unculled("lamp/bunny-lamp");
}

#[test]
fn the_rooms_improved_display_is_the_same_with_and_without_the_culling() {
    room_culled_equals_unculled("edits-object.toml", "improved");
}

#[test]
fn the_rooms_fast_display_is_the_same_with_and_without_the_culling() {
    room_culled_equals_unculled("edits-object.toml", "fast");
}

#[test]
fn the_room_under_a_new_light_is_the_same_with_and_without_the_culling() {
    room_culled_equals_unculled("edits-object-light-view.toml", "improved");
}
