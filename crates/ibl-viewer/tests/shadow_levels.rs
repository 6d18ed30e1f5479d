//! The virtual objects' coarser copies in the shadow maps (`shadow_lod.rs`) leave the frame as
//! the full meshes draw it, within what moving a shadow by under a texel can change: each copy
//! lies within half a shadow-map texel of the object by meshoptimizer's estimate (at most 0.75
//! texels in fact), under the look-up's depth bias and normal offset, so the object's shadow on
//! itself is unchanged and its shadow on others moves by less than a texel, along its edges.
//! Checked on the frames with and without the copies: the room's 32 patches (point lights,
//! 256-texel cube faces: the copies are drawn there) and the bunny under the umbrella
//! luminaire, the bunny as loaded and moved, through the image-golden helper's mean FLIP (at
//! most 0.005) and the share of pixels that change by over 2 % (at most 0.1 %): measured, the
//! room's FLIP 2e-4 to 3.5e-4 and 2 pixels in 76,800, the lamp's frames equal.

mod common;

use ibl_core::{Image, Rgb};
use ibl_viewer::headless::HeadlessOptions;
use ibl_viewer::lighting::SceneLighting;
use ibl_viewer::{SceneModel, gpu::GpuContext};

const SIZE: (u32, u32) = (320, 240);

fn frame(
    gpu: &GpuContext,
    model: &SceneModel,
    lighting: &SceneLighting,
    levels: bool,
) -> Image<Rgb> {
    let options = HeadlessOptions {
        size: SIZE,
        shadow_levels: levels,
        ..Default::default()
    };
    common::radiance(gpu, model, lighting, &options)
}

fn same_frame(name: &str, gpu: &GpuContext, model: &SceneModel, lighting: &SceneLighting) {
    let copies = frame(gpu, model, lighting, true);
    let full = frame(gpu, model, lighting, false);
    let changed = copies
        .pixels()
        .iter()
        .zip(full.pixels())
        .filter(|(a, b)| (a.luminance() - b.luminance()).abs() > 0.02 * b.luminance().max(1e-3))
        .count();
    let share = changed as f64 / (SIZE.0 * SIZE.1) as f64;
    let dir = tempfile::tempdir().expect("a temporary folder");
    let golden = dir.path().join("full.exr");
    ibl_io::write_image(&golden, &full, &ibl_io::WriteOptions::default()).expect("writes");
    let goldens = ibl_golden::Goldens {
        mode: ibl_golden::Mode::Compare,
        ..ibl_golden::Goldens::from_env()
    };
    let outcome = goldens.check(
        &format!("shadow-levels-{}", name.replace([' ', ','], "-")),
        &copies,
        &golden,
        ibl_golden::Metric::MeanFlip(0.005),
    );
    eprintln!(
        "{name}: {changed} pixels ({:.3} %) change by over 2 %; {outcome:?}",
        100.0 * share
    );
    if let Err(e) = outcome {
        panic!("{name}: {e}");
    }
    assert!(share <= 0.001, "{name}: {changed} pixels changed");
}

#[test]
fn the_rooms_frame_keeps_its_shadows_with_the_copies() {
    let Some(gpu) = common::gpu_or_skip("the_rooms_frame_keeps_its_shadows_with_the_copies") else {
        return;
    };
    let mut live = common::room_with_bunny();
    let lighting = live.lighting.clone();
    common::as_loaded_and_moved("the room", &mut live.model, |name, model| {
        same_frame(name, &gpu, model, &lighting)
    });
}

#[test]
fn the_lamps_frame_keeps_its_shadows_with_the_copies() {
    let Some(gpu) = common::gpu_or_skip("the_lamps_frame_keeps_its_shadows_with_the_copies") else {
        return;
    };
    let (mut model, lighting) = common::example_scene("lamp/bunny-lamp");
    common::as_loaded_and_moved("bunny-lamp", &mut model, |name, model| {
        same_frame(name, &gpu, model, &lighting)
    });
}
