//! The window's UI without a display (egui_kittest driving the real eframe application on the
//! viewer's own device): a scene opens, its lights arrive from the worker, the panel's controls
//! change the scene, the frame shows the scene, a bad file is reported in the window, and the
//! room tools mark, remove and calibrate lines over a probe.

mod common;

use std::time::{Duration, Instant};

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use ibl_scene::RenderMode;
use ibl_viewer::ProbeExtras;
use ibl_viewer::view_state::{Content, ProbeState};
use ibl_viewer::window::{ViewerApp, WindowOptions};

fn harness(
    gpu: &ibl_viewer::GpuContext,
    input: Option<std::path::PathBuf>,
) -> Harness<'static, ViewerApp> {
    harness_with(gpu, input, ProbeExtras::default(), 520.0)
}

fn harness_with(
    gpu: &ibl_viewer::GpuContext,
    input: Option<std::path::PathBuf>,
    probe: ProbeExtras,
    height: f32,
) -> Harness<'static, ViewerApp> {
    let app = ViewerApp::new(
        gpu.clone(),
        WindowOptions {
            input,
            mapping: None,
            size: (600, 450),
            screenshot: None,
            shadow_tile: 512,
            probe,
        },
        Default::default(),
    );
    Harness::builder()
        .with_size(eframe::egui::vec2(900.0, height))
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
    // The ambient's bands: the scene's `auto` (3 at its 4 samples of 4 rays) until the box is
    // cleared, then the count the slider showed.
    // (By accessibility action: the row may lie below the panel's visible part.)
    h.get_by_label("auto bands").click_accesskit();
    h.step();
    match &h.state().content {
        Content::Scene(s) => assert_eq!(
            s.model.description.lighting.ambient_bands,
            ibl_scene::AmbientBands::Fixed(3)
        ),
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

/// The apartment probe with its room file (and `extras`), in a window tall enough for the side
/// panel's Room section to show without scrolling.
fn apartment_harness(
    gpu: &ibl_viewer::GpuContext,
    extras: ProbeExtras,
) -> Harness<'static, ViewerApp> {
    let room = common::assets().join("rooms/apartment/room.toml");
    harness_with(
        gpu,
        Some(common::assets().join("probes/apartment.exr")),
        ProbeExtras {
            room: Some(room),
            ..extras
        },
        1400.0,
    )
}

fn probe(app: &ViewerApp) -> &ProbeState {
    match &app.content {
        Content::Probe(p) => p,
        _ => panic!("a probe is open: {:?}", app.error),
    }
}

#[test]
fn the_room_tools_mark_a_line_remove_it_and_calibrate() {
    let Some(gpu) = common::gpu_or_skip("ui room") else {
        return;
    };
    let apartment = common::assets().join("rooms/apartment");
    let mut h = apartment_harness(
        &gpu,
        ProbeExtras {
            yaw_deg: Some(20.0),
            marks: Some(apartment.join("marks.json")),
            ..ProbeExtras::default()
        },
    );
    h.step();
    assert_eq!(probe(h.state()).room.line_count(), 13);
    assert_eq!(probe(h.state()).room.room_edges(), 28);
    // M switches marking on; Y picks the axis; a left-drag in the view draws a line.
    h.key_press(egui::Key::M);
    h.key_press(egui::Key::Y);
    h.step();
    assert!(probe(h.state()).marking_lines());
    let (from, to) = (egui::pos2(200.0, 150.0), egui::pos2(230.0, 320.0));
    h.hover_at(from);
    h.step();
    h.drag_at(from);
    h.step();
    for k in 1..=6 {
        h.hover_at(from + (to - from) * (k as f32 / 6.0));
        h.step();
    }
    h.drop_at(to);
    h.step();
    h.step();
    let p = probe(h.state());
    assert_eq!(p.room.line_count(), 14, "{:?}", p.room.refused);
    let view = p.room.marks.views.last().expect("a view of the camera");
    assert_eq!(view.lines[0].axis, ibl_room::Axis::Y);
    // The view is the camera that showed the line, at the frame's pixel size.
    assert!(
        (view.camera.yaw_deg - 20.0).abs() < 1e-4,
        "{:?}",
        view.camera
    );
    assert!((view.camera.vertical_fov_deg - 75.0).abs() < 1e-4);
    let size = p.frame_size();
    assert_eq!((view.camera.width, view.camera.height), size);
    assert!(
        view.name.starts_with("yaw 20.0 pitch 0.0 fov 75.0"),
        "{}",
        view.name
    );
    // Points map to frame pixels one to one (1 pixel per point): the segment is the drag, from
    // the press; the frame starts where the harness's root panel's margin leaves it (8 points).
    let line = view.lines[0];
    let (dx, dy) = (line.to[0] - line.from[0], line.to[1] - line.from[1]);
    assert!(
        (dx - 30.0).abs() < 0.5 && (dy - 170.0).abs() < 0.5,
        "{line:?}"
    );
    let offset = (200.0 - line.from[0], 150.0 - line.from[1]);
    assert!(
        (0.0..=10.0).contains(&offset.0) && (0.0..=10.0).contains(&offset.1),
        "{line:?}"
    );
    // Calibrate: 14 lines, each with its residual shown.
    h.get_by_label("calibrate").click();
    h.step();
    let c = probe(h.state())
        .room
        .calibration
        .clone()
        .expect("ran")
        .expect("calibrates");
    assert_eq!(c.lines.len(), 14);
    h.get_by_label_contains("14 lines: rotation");
    // Backspace removes the new line (and its view).
    h.key_press(egui::Key::Backspace);
    h.step();
    assert_eq!(probe(h.state()).room.line_count(), 13);
    assert!(probe(h.state()).room.calibration.is_none());
}

fn sequence_frames(app: &ViewerApp) -> usize {
    match &app.content {
        Content::Scene(s) => s.sequence.as_ref().map_or(0, |q| q.history.len()),
        _ => 0,
    }
}

#[test]
fn an_outdoor_scene_plays_its_sequence_with_the_estimates_in_the_panel() {
    let Some(gpu) = common::gpu_or_skip("ui sequence") else {
        return;
    };
    let scene = common::assets().join("outdoor/courtyard/scene.toml");
    let mut h = harness_with(&gpu, Some(scene), ProbeExtras::default(), 900.0);
    // The first frame is played at once; the sun is the one light.
    step_until(&mut h, |app| sequence_frames(app) >= 1);
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    assert_eq!(lights_drawn(h.state()), 1);
    h.get_by_label("pause").click();
    h.step();
    let before = sequence_frames(h.state());
    h.get_by_label("next frame").click();
    step_until(&mut h, |app| sequence_frames(app) == before + 1);
    match &h.state().content {
        Content::Scene(s) => {
            let q = s.sequence.as_ref().expect("a sequence");
            assert!(!q.playing);
            let f = q.current().expect("a frame");
            assert_eq!(f.index, before);
        }
        _ => panic!("a scene is open"),
    }
    // The estimates and the relit map are in the panel.
    h.get_by_label_contains("sun P_d");
    h.get_by_label_contains("sky P_a");
    h.get_by_label("relit environment map (the sun left out)");
}

/// The apartment looking straight down at the floor, with the room's editing switched on and
/// its estimate made.
fn editing_the_floor(gpu: &ibl_viewer::GpuContext) -> Harness<'static, ViewerApp> {
    let mut h = apartment_harness(
        gpu,
        ProbeExtras {
            pitch_deg: Some(-89.0),
            ..ProbeExtras::default()
        },
    );
    h.step();
    h.get_by_label("edit the room's materials").click();
    step_until(&mut h, |app| {
        probe(app).edit.as_ref().is_some_and(|e| e.table.is_some())
    });
    h
}

/// A click (press and release in place) at the middle of the view.
fn click_the_middle(h: &mut Harness<'static, ViewerApp>) {
    click_at(h, egui::pos2(305.0, 690.0));
}

/// A click (press and release in place) at `at`.
fn click_at(h: &mut Harness<'static, ViewerApp>, at: egui::Pos2) {
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    h.drop_at(at);
}

/// The edits over the probe, to change them as the panel's drag values do.
fn edit_mut<'a>(
    h: &'a mut Harness<'static, ViewerApp>,
) -> &'a mut ibl_viewer::room_edit::RoomEditSession {
    match &mut h.state_mut().content {
        Content::Probe(p) => p.edit.as_mut().expect("editing"),
        _ => panic!("a probe is open"),
    }
}

#[test]
fn a_click_picks_the_floor_and_its_new_reflectance_edits_the_panorama() {
    let Some(gpu) = common::gpu_or_skip("ui room materials") else {
        return;
    };
    let mut h = editing_the_floor(&gpu);
    h.get_by_label("click picks a surface").click();
    h.step();
    // A click at the middle of the view picks the floor.
    click_the_middle(&mut h);
    h.step();
    let (floor, before) = {
        let e = probe(h.state()).edit.as_ref().expect("editing");
        let g = e.picked.expect("a group picked");
        let table = e.table.as_ref().expect("the table");
        assert_eq!(table.groups[g].name, "floor");
        (g, table.groups[g].estimated.expect("the floor's estimate"))
    };
    // The floor's new reflectance, as edits.toml sets it (docs/ROOMS.md section 11).
    let after = ibl_core::Rgb::new(0.60, 0.12, 0.08);
    edit_mut(&mut h).set_reflectance(floor, after);
    step_until(&mut h, |app| {
        probe(app)
            .edit
            .as_ref()
            .is_some_and(|e| e.materials.len() == 1 && e.shows_current_edits())
    });
    // At one bounce the floor's own pixels scale by rho' / rho exactly (its irradiance changes
    // only at the second bounce): the pixel that was clicked.
    let p = probe(h.state());
    let d = p
        .edit
        .as_ref()
        .and_then(|e| e.picked_towards)
        .expect("picked along");
    let (i, j) =
        ibl_core::LatLong::new(p.original.width(), p.original.height()).dir_to_pixel(d.as_dvec3());
    let (was, now) = (*p.original.get(i, j), *p.model.latlong.get(i, j));
    for (c, (n, o)) in [(now.r, was.r), (now.g, was.g), (now.b, was.b)]
        .iter()
        .enumerate()
    {
        let ratio = [after.r / before.r, after.g / before.g, after.b / before.b][c];
        assert!(
            (n / o - ratio).abs() <= 1e-3 * ratio,
            "channel {c}: {n} / {o} against rho'/rho {ratio}"
        );
    }
    h.get_by_label_contains("bounce of colour bleeding");
    // Switching the edits off shows the probe as read.
    h.get_by_label("show the edits").click();
    step_until(&mut h, |app| {
        std::sync::Arc::ptr_eq(&probe(app).model.latlong, &probe(app).original)
    });
}

#[test]
fn a_click_places_a_light_and_its_pool_brightens_the_floor() {
    let Some(gpu) = common::gpu_or_skip("ui room light") else {
        return;
    };
    let mut h = editing_the_floor(&gpu);
    h.get_by_label("click places a light").click();
    h.step();
    click_the_middle(&mut h);
    step_until(&mut h, |app| {
        probe(app)
            .edit
            .as_ref()
            .is_some_and(|e| e.lights.len() == 1 && e.shows_current_edits())
    });
    let p = probe(h.state());
    let e = p.edit.as_ref().expect("editing");
    assert!(e.light_file.ends_with("umbrella.ies"), "{}", e.light_file);
    // The light hangs 0.3 m above the clicked floor point, aimed down: the floor there is lit
    // far more than by the room alone.
    let d = e.lights[0].towards;
    let (i, j) =
        ibl_core::LatLong::new(p.original.width(), p.original.height()).dir_to_pixel(d.as_dvec3());
    let (was, now) = (*p.original.get(i, j), *p.model.latlong.get(i, j));
    assert!(now.g > 2.0 * was.g, "the pool: {now:?} against {was:?}");
    h.get_by_label_contains("1 light added");

    // "move light 1", then a click elsewhere on the floor: the pool follows the light.
    let latlong = ibl_core::LatLong::new(p.original.width(), p.original.height());
    let pixel = |d: glam::Vec3| latlong.dir_to_pixel(d.as_dvec3());
    let first = d;
    h.get_by_label("move light 1").click();
    h.step();
    click_at(&mut h, egui::pos2(305.0 - 150.0, 690.0));
    step_until(&mut h, |app| {
        probe(app)
            .edit
            .as_ref()
            .is_some_and(|e| e.lights[0].towards != first && e.shows_current_edits())
    });
    let p = probe(h.state());
    let e = p.edit.as_ref().expect("editing");
    assert_eq!(e.lights.len(), 1, "moved, not added");
    assert_eq!(e.moving, None, "the move ends with its click");
    let (k, l) = pixel(e.lights[0].towards);
    let (was_there, now_there) = (*p.original.get(k, l), *p.model.latlong.get(k, l));
    assert!(
        now_there.g > 2.0 * was_there.g,
        "the moved pool: {now_there:?} against {was_there:?}"
    );
    let left = p.model.latlong.get(i, j).g;
    assert!(
        left < 0.5 * now.g,
        "where the pool was: {left} against {}",
        now.g
    );

    // Turning the light 90 degrees (pitch) aims it along the floor: its pool below dims.
    assert!(h.query_by_label_contains("turn light 1").is_some());
    edit_mut(&mut h).lights[0].rotation_deg = [0.0, 90.0, 0.0];
    step_until(&mut h, |app| {
        probe(app)
            .edit
            .as_ref()
            .is_some_and(|e| e.lights[0].rotation_deg[1] == 90.0 && e.shows_current_edits())
    });
    let turned = probe(h.state()).model.latlong.get(k, l).g;
    assert!(
        turned < 0.5 * now_there.g,
        "the turned light's pool: {turned} against {}",
        now_there.g
    );

    eprintln!(
        "the pool (green): {:.3} over {:.3} where placed, {left:.3} after the move; {:.3} over \
         {:.3} where moved, {turned:.3} turned 90 degrees",
        now.g, was.g, now_there.g, was_there.g
    );
    // "remove light 1" leaves no light.
    h.get_by_label("remove light 1").click();
    step_until(&mut h, |app| {
        probe(app)
            .edit
            .as_ref()
            .is_some_and(|e| e.lights.is_empty())
    });
}

#[test]
fn the_live_room_display_redraws_the_bunny_where_it_is_moved() {
    // `--live` (docs/ROOMS.md section 14): the edits' bunny drawn by the GPU in the room, its
    // lights the room's 32 important patches. Moving it redraws it (and its shadows) at once.
    let Some(gpu) = common::gpu_or_skip("ui live") else {
        return;
    };
    let apartment = common::assets().join("rooms/apartment");
    let extras = ProbeExtras {
        room: Some(apartment.join("room.toml")),
        edit: Some(apartment.join("edits-object.toml")),
        live: true,
        ..ProbeExtras::default()
    };
    let mut h = harness_with(
        &gpu,
        Some(common::assets().join("probes/apartment.exr")),
        extras,
        520.0,
    );
    h.step();
    assert!(h.state().error.is_none(), "{:?}", h.state().error);
    let summary = match &h.state().content {
        Content::Scene(s) => s
            .lighting()
            .map(|l| (l.summary.clone(), l.luminaires.len())),
        _ => panic!("the live display is a scene"),
    };
    let (summary, points) = summary.expect("the room's lights are given at once");
    assert!(summary.contains("improved display"), "{summary}");
    assert_eq!(points, 32, "the 32 important patches");
    let frame = |h: &mut Harness<'static, ViewerApp>| {
        h.step();
        match &h.state().content {
            Content::Scene(s) => s.read_frame(&gpu).expect("reads the frame back").display,
            _ => panic!("a scene is open"),
        }
    };
    let before = frame(&mut h);
    match &mut h.state_mut().content {
        Content::Scene(s) => s.model.translate(0, glam::Vec3::new(-0.3, 0.0, 0.2)),
        _ => panic!("a scene is open"),
    }
    let after = frame(&mut h);
    let changed = before
        .pixels()
        .iter()
        .zip(after.pixels())
        .filter(|(a, b)| a != b)
        .count();
    // The bunny covers about 4 % of the view; moved by 0.36 m it leaves its old place and
    // takes a new one, and its shadows go with it.
    assert!(
        changed > before.len() / 50,
        "only {changed} of {} pixels changed",
        before.len()
    );
}
