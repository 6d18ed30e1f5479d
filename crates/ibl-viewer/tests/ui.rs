//! The window's UI without a display (egui_kittest driving the real eframe application on the
//! viewer's own device): a scene opens, its lights arrive from the worker, the panel's controls
//! change the scene, the frame shows the scene, and a bad file is reported in the window.

mod common;

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use ibl_scene::RenderMode;
use ibl_viewer::view_state::Content;
use ibl_viewer::window::{ViewerApp, WindowOptions};

fn harness(
    gpu: &ibl_viewer::GpuContext,
    input: Option<std::path::PathBuf>,
) -> Harness<'static, ViewerApp> {
    let app = ViewerApp::new(
        gpu.clone(),
        WindowOptions {
            input,
            mapping: None,
            size: (600, 450),
            screenshot: None,
            shadow_tile: 512,
        },
        Default::default(),
    );
    Harness::builder()
        .with_size(eframe::egui::vec2(900.0, 520.0))
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui, None), app)
}

/// Steps the UI until `done` holds or 60 s pass.
fn step_until(h: &mut Harness<'static, ViewerApp>, done: impl Fn(&ViewerApp) -> bool) {
    let start = Instant::now();
    while !done(h.state()) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the UI never got there"
        );
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn lights_drawn(app: &ViewerApp) -> usize {
    match &app.content {
        Content::Scene(s) => s.lighting().map_or(0, |l| l.lights.len()),
        _ => 0,
    }
}

#[test]
fn a_scene_opens_lights_arrive_and_the_panel_edits_it() {
    let Some(gpu) = common::gpu_or_skip("ui") else {
        return;
    };
    let scene = common::assets().join("scenes/bunny-sky.toml");
    let mut h = harness(&gpu, Some(scene));
    step_until(&mut h, |app| lights_drawn(app) == 16);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    h.get_by_label("hybrid (lights + SH ambient)").click();
    h.step();
    match &h.state().content {
        Content::Scene(s) => assert_eq!(s.model.description.render.mode, RenderMode::Hybrid),
        _ => panic!("a scene is open"),
    }
    // The worker recomputes the lights with the ambient; the frames keep coming meanwhile.
    step_until(&mut h, |app| match &app.content {
        Content::Scene(s) => s.lighting().is_some_and(|l| l.ambient.is_some()),
        _ => false,
    });
    // The frame the window shows holds the scene: many distinct colours.
    let frame = match &h.state().content {
        Content::Scene(s) => s.read_frame(&gpu).expect("reads the frame back"),
        _ => panic!("a scene is open"),
    };
    let mut colours = std::collections::BTreeSet::new();
    for p in frame.display.pixels().iter().step_by(37) {
        colours.insert([p[0] / 8, p[1] / 8, p[2] / 8]);
    }
    assert!(
        colours.len() > 40,
        "only {} colours in the frame",
        colours.len()
    );
}

#[test]
fn a_bad_file_is_reported_in_the_window() {
    let Some(gpu) = common::gpu_or_skip("ui bad file") else {
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let bad = dir.path().join("broken.toml");
    std::fs::write(&bad, "version = 1\n[probe]\nfile = 3\n").expect("written");
    let mut h = harness(&gpu, Some(bad));
    h.step();
    let error = h.state().error.clone().expect("an error is shown");
    assert!(error.contains("broken.toml"), "{error}");
    assert!(matches!(h.state().content, Content::Empty));
    h.get_by_label_contains("broken.toml");
}
