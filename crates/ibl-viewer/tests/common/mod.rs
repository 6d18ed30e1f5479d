//! Shared by the viewer's GPU tests: the device, or a clear skip.

#![allow(dead_code)]

use std::path::PathBuf;

use ibl_viewer::GpuContext;

/// Whether this is a CI run (`CI` set, and not to `false` or `0`).
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// The GPU, or `None` (with a message) when no adapter exists outside CI. Under CI a missing
/// adapter fails the test: a skipped GPU suite in CI would hide a broken install.
pub fn gpu_or_skip(test: &str) -> Option<GpuContext> {
    match GpuContext::headless() {
        Ok(gpu) => Some(gpu),
        Err(e) => {
            assert!(
                !in_ci(),
                "{test}: no GPU adapter under CI ({e}); .ci/run must install mesa-vulkan-drivers \
                 and libvulkan1 so that the GPU tests run"
            );
            eprintln!("{test}: SKIPPED, no GPU adapter ({e})");
            None
        }
    }
}

/// The repository's `assets/` folder.
pub fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

/// A folder under `target/` for images a failing test leaves to look at.
pub fn failure_dir(test: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../target/viewer-test-failures")
        .join(test);
    let _ = std::fs::create_dir_all(&dir);
    dir
}

/// The viewer's frame against a CPU render of the same frame, through the image-golden helper
/// (`ibl-golden`; the CPU render is written as a fresh golden, compared, never blessed; failing
/// images go to target/golden-failures/NAME/): the mean-FLIP outcome at `max_flip`, and the
/// fraction of pixels whose coverage masks (alpha > 0.5) agree.
pub fn against_cpu(
    name: &str,
    gpu: &ibl_viewer::frame_targets::FrameImages,
    cpu: &ibl_render::RenderOutput,
    max_flip: f64,
) -> (Result<ibl_golden::Outcome, String>, f64) {
    let masks_equal = gpu
        .coverage
        .pixels()
        .iter()
        .zip(cpu.object_coverage.pixels())
        .filter(|(g, c)| (**g > 0.5) == (**c > 0.5))
        .count() as f64
        / cpu.object_coverage.len() as f64;
    let dir = tempfile::tempdir().expect("a temporary folder");
    let golden = dir.path().join("cpu.exr");
    ibl_io::write_image(&golden, &cpu.composite, &ibl_io::WriteOptions::default())
        .expect("writes the CPU render");
    let goldens = ibl_golden::Goldens {
        mode: ibl_golden::Mode::Compare,
        ..ibl_golden::Goldens::from_env()
    };
    let outcome = goldens
        .check(
            name,
            &gpu.radiance,
            &golden,
            ibl_golden::Metric::MeanFlip(max_flip),
        )
        .map_err(|e| e.to_string());
    (outcome, masks_equal)
}

/// An example scene (`assets/scenes/NAME.toml`) and its lights, as `ibl view` makes them.
pub fn example_scene(name: &str) -> (ibl_viewer::SceneModel, ibl_viewer::lighting::SceneLighting) {
    let path = assets().join("scenes").join(format!("{name}.toml"));
    let model = ibl_viewer::SceneModel::open(&path).expect("the example scene opens");
    let (lighting, _) = ibl_viewer::headless::lights_now(&model).expect("the scene's lights");
    (model, lighting)
}

/// The apartment's live display with the bundled bunny in the sun patch (`edits-object.toml`,
/// improved display): the room as the real layer, its 32 important patches as point lights.
pub fn room_with_bunny() -> ibl_viewer::room_live::RoomLive {
    let room = assets().join("rooms/apartment");
    ibl_viewer::room_live::room_live(
        &room.join("room.toml"),
        &room.join("edits-object.toml"),
        &ibl_pipeline::progress::Silent,
    )
    .expect("the live display")
}

/// Runs `check(name, model)` on the scene as it is, then with its first object turned 75 degrees
/// about the vertical and moved 0.1 m along x and -0.05 m along z (`NAME, moved`).
pub fn as_loaded_and_moved(
    name: &str,
    model: &mut ibl_viewer::SceneModel,
    check: impl Fn(&str, &ibl_viewer::SceneModel),
) {
    check(name, model);
    model.rotate(0, 75.0);
    model.translate(0, glam::Vec3::new(0.1, 0.0, -0.05));
    check(&format!("{name}, moved"), model);
}

/// The radiance of one headless frame of `model` under `lighting`, drawn with `options`.
pub fn radiance(
    gpu: &GpuContext,
    model: &ibl_viewer::SceneModel,
    lighting: &ibl_viewer::lighting::SceneLighting,
    options: &ibl_viewer::headless::HeadlessOptions,
) -> ibl_core::Image<ibl_core::Rgb> {
    ibl_viewer::headless::render_scene_lit(gpu, model, lighting.clone(), 0.0, options, &|_, _| {})
        .expect("gpu renders")
        .images
        .radiance
}
