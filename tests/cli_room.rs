//! End-to-end tests of `ibl room`: `calibrate` on the bundled apartment marks (frame, residuals,
//! scale, the room file it writes matching the committed one), `estimate` and `lights` on a
//! coarse copy of the synthetic room (report, pictures, the area-light file, which `ibl render`
//! then reads), and exit status 2 naming the file and the field for malformed room and marks
//! files, with outputs checked before any work.

mod common;

use std::path::{Path, PathBuf};

use common::{ibl, repo, stderr};
use serde_json::Value;

fn s(p: &Path) -> String {
    p.display().to_string()
}

fn read_json(p: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(p).expect("read")).expect("JSON")
}

fn apartment_marks() -> String {
    s(&repo().join("assets/rooms/apartment/marks.json"))
}

/// The synthetic room of `assets/rooms/synthetic` cut into patches of at most 0.5 m^2 (about
/// 300 instead of 2295) and naming its probe by absolute path, so each run takes well under a
/// second at `--rays-per-patch 64`.
fn coarse_synthetic_room(dir: &Path) -> PathBuf {
    let synthetic = repo().join("assets/rooms/synthetic");
    let text = std::fs::read_to_string(synthetic.join("room.toml")).expect("room file");
    let probe = s(&synthetic.join("probe.exr"));
    let text = text
        .replace("file = \"probe.exr\"", &format!("file = {probe:?}"))
        .replace("patch_area_m2 = 0.05", "patch_area_m2 = 0.5");
    let path = dir.join("room.toml");
    std::fs::write(&path, text).expect("write room");
    path
}

#[test]
fn calibrate_gives_the_frame_residuals_and_scale_of_the_marks() {
    let dir = tempfile::tempdir().expect("tempdir");
    let room = dir.path().join("room.toml");
    let out = ibl(&[
        "room",
        "calibrate",
        &apartment_marks(),
        "-o",
        &s(&room),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let lines = v["lines"].as_u64().expect("lines");
    assert_eq!(lines, 13);
    assert_eq!(
        v["calibration"]["line_residuals_deg"]
            .as_array()
            .expect("residuals")
            .len() as u64,
        lines
    );
    // Measured 0.762 deg RMS and a 1.370 m probe (docs/ROOMS.md, the committed room file's
    // header); the same code runs here, so 1e-3 covers only the JSON's decimal rounding.
    let rms = v["calibration"]["rms_residual_deg"].as_f64().expect("rms");
    assert!((rms - 0.762).abs() < 1e-3, "{rms}");
    let h = v["scale"]["probe_height_m"].as_f64().expect("height");
    assert!((h - 1.370).abs() < 1e-3, "{h}");
    // The room file written is the committed one (same shapes, same frame).
    let made = std::fs::read_to_string(&room).expect("room written");
    let committed =
        std::fs::read_to_string(repo().join("assets/rooms/apartment/room.toml")).expect("room");
    let body = |t: &str| {
        t.lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("file ="))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(body(&made), body(&committed));
    assert!(made.contains("apartment.exr"));
    // Text mode says the same in words.
    let text = ibl(&["room", "calibrate", &apartment_marks()]);
    assert!(text.status.success(), "{}", stderr(&text));
    let text = String::from_utf8_lossy(&text.stdout).into_owned();
    assert!(
        text.contains("13 lines") && text.contains("1.370 m"),
        "{text}"
    );
}

#[test]
fn estimate_writes_the_report_and_pictures() {
    let dir = tempfile::tempdir().expect("tempdir");
    let room = coarse_synthetic_room(dir.path());
    let out_dir = dir.path().join("estimate");
    let out = ibl(&[
        "room",
        "estimate",
        &s(&room),
        "-o",
        &s(&out_dir),
        "--rays-per-patch",
        "64",
        "--important",
        "4",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    assert_eq!(v["format"], "iblkit.room-report/1");
    assert_eq!(v, read_json(&out_dir.join("report.json")));
    for f in [
        "report.md",
        "rho-panorama.png",
        "overlay.png",
        "cutaway.png",
    ] {
        let len = std::fs::metadata(out_dir.join(f)).expect(f).len();
        assert!(len > 100, "{f}: {len} bytes");
    }
    assert!(v["converged"].as_bool().expect("converged"));
    assert_eq!(
        v["important"]["important"]
            .as_array()
            .expect("lights")
            .len(),
        4
    );
    // Seen groups within 0.1 of their albedo: the full-resolution estimate is within 0.015
    // (docs/ROOMS.md); 0.5 m^2 patches and 81 rays each were measured up to 0.075 off here
    // (ceiling, blue), so 0.1 leaves a margin of 0.025.
    for g in v["groups"].as_array().expect("groups") {
        let (Some(rho), Some(real)) = (
            g["reflectance"].as_array(),
            g["measured_reflectance"].as_array(),
        ) else {
            continue;
        };
        if g["seen_area_fraction"].as_f64().expect("seen") < 0.5 {
            continue;
        }
        for k in 0..3 {
            let d = rho[k].as_f64().expect("rho") - real[k].as_f64().expect("real");
            assert!(d.abs() < 0.1, "{}: {d}", g["name"]);
        }
    }
}

#[test]
fn lights_are_an_area_light_file_that_render_reads() {
    let dir = tempfile::tempdir().expect("tempdir");
    let room = coarse_synthetic_room(dir.path());
    let lights = dir.path().join("lights.json");
    let out = ibl(&[
        "room",
        "lights",
        &s(&room),
        "-n",
        "8",
        "-o",
        &s(&lights),
        "--rays-per-patch",
        "64",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary: Value = serde_json::from_slice(&out.stdout).expect("JSON summary");
    assert_eq!(summary["lights"], 8);
    let file = read_json(&lights);
    assert_eq!(file["format"], "iblkit.area-lights/1");
    let records = file["lights"].as_array().expect("lights");
    assert_eq!(records.len(), 8);
    // The window is the room's only source: its patches carry the most flux.
    assert_eq!(records[0]["group"], "window");
    let fraction = file["important_flux_fraction"].as_f64().expect("fraction");
    assert!(fraction > 0.0 && fraction <= 1.0, "{fraction}");
    // `ibl render` reads it as directional lights (a tiny render: 32 pixels, 1 spp).
    let scene = repo().join("assets/scenes/bunny-sky.toml");
    let image = dir.path().join("render.exr");
    let render = ibl(&[
        "render",
        &s(&scene),
        "-o",
        &s(&image),
        "--mode",
        "lights",
        "--lights",
        &s(&lights),
        "--width",
        "32",
        "--spp",
        "1",
        "--json",
    ]);
    assert!(render.status.success(), "{}", stderr(&render));
    assert!(image.exists());
}

#[test]
fn malformed_files_are_exit_2_naming_the_file_and_the_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let room = coarse_synthetic_room(dir.path());
    let text = std::fs::read_to_string(&room).expect("room");
    let bad_room = dir.path().join("bad-room.toml");
    std::fs::write(
        &bad_room,
        text.replace("patch_area_m2 = 0.5", "patch_area_m2 = \"big\""),
    )
    .expect("write");
    let out = ibl(&[
        "room",
        "estimate",
        &s(&bad_room),
        "-o",
        &s(&dir.path().join("o")),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(
        e.contains("bad-room.toml") && e.contains("room.patch_area_m2"),
        "{e}"
    );

    let marks = std::fs::read_to_string(apartment_marks()).expect("marks");
    let bad_marks = dir.path().join("bad-marks.json");
    std::fs::write(&bad_marks, marks.replacen("\"views\"", "\"viewz\"", 1)).expect("write");
    let out = ibl(&["room", "calibrate", &s(&bad_marks)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("bad-marks.json") && e.contains("views"), "{e}");

    let missing = ibl(&[
        "room",
        "lights",
        "nowhere.toml",
        "-o",
        &s(&dir.path().join("l.json")),
    ]);
    assert_eq!(missing.status.code(), Some(2), "{}", stderr(&missing));
    assert!(stderr(&missing).contains("nowhere.toml"));
}

#[test]
fn outputs_are_checked_before_any_work() {
    let dir = tempfile::tempdir().expect("tempdir");
    let room = coarse_synthetic_room(dir.path());
    let before = std::fs::read(&room).expect("room");
    // The room file as the light file: refused, untouched.
    let out = ibl(&["room", "lights", &s(&room), "-o", &s(&room)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(std::fs::read(&room).expect("room"), before);
    // Wrong extensions and counts.
    let out = ibl(&["room", "lights", &s(&room), "-o", "lights.txt"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains(".json"));
    let out = ibl(&["room", "lights", &s(&room), "-n", "0", "-o", "l.json"]);
    assert_eq!(out.status.code(), Some(2));
    let out = ibl(&["room", "calibrate", &apartment_marks(), "-o", "room.txt"]);
    assert_eq!(out.status.code(), Some(2));
    // A file where the estimate's folder should be.
    let out = ibl(&["room", "estimate", &s(&room), "-o", &s(&room)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(std::fs::read(&room).expect("room"), before);
    let out = ibl(&[
        "room",
        "estimate",
        &s(&room),
        "-o",
        "x",
        "--rays-per-patch",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn room_render_writes_before_and_after_and_refuses_bad_edits_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let room = repo().join("assets/rooms/apartment/room.toml");
    let edits = repo().join("assets/rooms/apartment/edits.toml");
    let (after, before) = (dir.path().join("after.exr"), dir.path().join("before.png"));
    let o = ibl(&[
        "room",
        "render",
        &s(&room),
        "--edit",
        &s(&edits),
        "-o",
        &s(&after),
        "--before",
        &s(&before),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(summary["kind"], "panorama");
    assert_eq!(summary["materials"][0]["group"], "floor");
    assert!(after.is_file() && before.is_file());

    // An unknown group names the room's surface groups; exit 2.
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "version = 1\n[[material]]\ngroup = \"sofa\"\nreflectance = [0.5, 0.5, 0.5]\n",
    )
    .unwrap();
    let out = dir.path().join("x.exr");
    let o = ibl(&[
        "room",
        "render",
        &s(&room),
        "--edit",
        &s(&bad),
        "-o",
        &s(&out),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("no surface group `sofa`") && e.contains("floor"),
        "{e}"
    );
    assert!(
        !e.contains("estimated in"),
        "refused before the analysis: {e}"
    );
    assert!(!out.exists());
    // The room's probe is never written over, and that is found before the analysis too.
    let probe = repo().join("assets/probes/apartment.exr");
    let bytes = std::fs::read(&probe).unwrap();
    let o = ibl(&["room", "render", &s(&room), "-o", &s(&probe)]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        !e.contains("estimated in"),
        "refused before the analysis: {e}"
    );
    assert_eq!(std::fs::read(&probe).unwrap(), bytes);
    // A picture that cannot be written is refused before the estimate runs.
    let o = ibl(&[
        "room",
        "render",
        &s(&room),
        "-o",
        &s(&dir.path().join("x.txt")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("x.txt"), "{}", stderr(&o));
    let o = ibl(&[
        "room",
        "render",
        &s(&room),
        "-o",
        &s(&out),
        "--before",
        &s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));

    // A light whose file is missing is named, exit 2, before the analysis; the bundled light
    // edits render and report the light.
    let missing = dir.path().join("missing-light.toml");
    std::fs::write(
        &missing,
        "version = 1\n[[light]]\nfile = \"nowhere.ies\"\nposition = [0, 2, 0]\n",
    )
    .unwrap();
    let o = ibl(&[
        "room",
        "render",
        &s(&room),
        "--edit",
        &s(&missing),
        "-o",
        &s(&out),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("nowhere.ies") && !e.contains("estimated in"),
        "{e}"
    );
    assert!(!out.exists());
    let light = repo().join("assets/rooms/apartment/edits-light.toml");
    let o = ibl(&[
        "room",
        "render",
        &s(&room),
        "--edit",
        &s(&light),
        "-o",
        &s(&out),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        summary["lights"][0]["file"]
            .as_str()
            .unwrap()
            .ends_with("umbrella.ies")
    );
    assert!(summary["lights"][0]["flux_lm"].as_f64().unwrap() > 8000.0);
    assert!(out.is_file());
}
