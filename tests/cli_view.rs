//! End-to-end tests of `ibl view`: the headless path (frames written, JSON with per-frame CPU and
//! GPU times, the benchmark), bad input (exit status 2 naming the file, never a panic, never a
//! write over an input), and the window under Xvfb (its screenshot shows the scene and the UI).
//!
//! These need a GPU adapter (Mesa's lavapipe on CI). Without one a test says so and passes,
//! except under CI (`CI` set), where a missing adapter fails it.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{ibl, in_ci, repo, stderr};
use serde_json::Value;

/// Whether `out` failed for want of a GPU adapter (then the test is skipped, or fails in CI).
fn no_adapter(out: &Output, test: &str) -> bool {
    let missing = out.status.code() == Some(1) && stderr(out).contains("no usable GPU adapter");
    assert!(
        !(missing && in_ci()),
        "{test}: no GPU adapter under CI: {}",
        stderr(out)
    );
    if missing {
        eprintln!("{test}: SKIPPED, no GPU adapter");
    }
    missing
}

fn scene(name: &str) -> String {
    repo()
        .join("assets/scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn headless_frames_are_written_with_their_timings() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("frame.png");
    let out = ibl(&[
        "view",
        &scene("bunny-sky.toml"),
        "--headless",
        "--size",
        "160x120",
        "--frames",
        "3",
        "-o",
        png.to_str().unwrap(),
        "--json",
    ]);
    if no_adapter(&out, "headless frames") {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["kind"], "scene");
    assert_eq!(v["frames"], 3);
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(160), Some(120))
    );
    assert_eq!(v["lights"], 16, "the scene's 16 median-cut lights");
    assert!(v["adapter"]["name"].as_str().is_some());
    let frames = v["per_frame"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    for f in frames {
        assert!(f["cpu_ms"].as_f64().unwrap() > 0.0);
        assert!(f["wall_ms"].as_f64().unwrap() >= f["cpu_ms"].as_f64().unwrap());
    }
    // The first frame draws both shadow atlases; still frames after it reuse them.
    assert_eq!(frames[0]["virtual_shadows_drawn"], true);
    assert_eq!(frames[1]["virtual_shadows_drawn"], false);
    assert_eq!(frames[2]["real_shadows_drawn"], false);
    assert!(v["statistics"]["fps_median"].as_f64().unwrap() > 0.0);
    assert!(png.exists() && dir.path().join("frame.exr").exists());
    let frame = ibl_io::read_image(&dir.path().join("frame.exr"))
        .unwrap()
        .image;
    assert_eq!((frame.width(), frame.height()), (160, 120));
}

#[test]
fn the_benchmark_moves_the_object_every_frame() {
    let out = ibl(&[
        "view",
        &scene("bunny-apartment.toml"),
        "--headless",
        "--bench",
        "--frames",
        "4",
        "--size",
        "128x96",
        "--json",
    ]);
    if no_adapter(&out, "bench") {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["motion"], "orbit");
    for f in v["per_frame"].as_array().unwrap() {
        assert_eq!(
            f["virtual_shadows_drawn"], true,
            "the object moved: its shadows are redrawn"
        );
    }
    let s = &v["statistics"];
    assert!(s["fps_p95"].as_f64().unwrap() <= s["fps_median"].as_f64().unwrap());
}

#[test]
fn a_probe_is_drawn_flat_with_its_lights() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("probe.png");
    let out = ibl(&[
        "view",
        &common::probe("sky.exr"),
        "--headless",
        "--flat",
        "--size",
        "256x128",
        "--method",
        "lightgen",
        "-n",
        "8",
        "--overlay",
        "lights,dominant,regions",
        "-o",
        png.to_str().unwrap(),
    ]);
    if no_adapter(&out, "probe") {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("8 lightgen lights"));
    let picture = ibl_io::read_image(&png).unwrap().image;
    assert_eq!((picture.width(), picture.height()), (256, 128));
}

/// Runs `ibl view` with `args` and checks it fails with status 2 and a message holding `needle`.
fn refuses(args: &[&str], needle: &str) {
    let out = ibl(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn bad_input_is_refused_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    refuses(
        &["view", missing.to_str().unwrap(), "--headless"],
        "missing.toml",
    );
    refuses(
        &[
            "view",
            &scene("bunny-sky.toml"),
            "--headless",
            "--size",
            "0x10",
        ],
        "--size",
    );
    refuses(
        &[
            "view",
            &scene("bunny-sky.toml"),
            "--headless",
            "--size",
            "wide",
        ],
        "--size",
    );
    let txt = dir.path().join("frame.txt");
    refuses(
        &[
            "view",
            &scene("bunny-sky.toml"),
            "--headless",
            "-o",
            txt.to_str().unwrap(),
        ],
        "frame.txt",
    );
    refuses(
        &["view", &scene("bunny-sky.toml"), "-o", "x.png"],
        "--headless",
    );
    let broken = dir.path().join("broken.toml");
    std::fs::write(
        &broken,
        "version = 1\n[probe]\nfile = \"p.exr\"\n[render]\nspp = 0\n",
    )
    .unwrap();
    refuses(
        &["view", broken.to_str().unwrap(), "--headless"],
        "render.spp",
    );
    // The frame would overwrite the probe it shows: refused before any work.
    let probe = dir.path().join("probe.exr");
    std::fs::copy(repo().join("assets/probes/night.exr"), &probe).unwrap();
    let before = std::fs::read(&probe).unwrap();
    refuses(
        &[
            "view",
            probe.to_str().unwrap(),
            "--headless",
            "-o",
            probe.to_str().unwrap(),
        ],
        "overwrite",
    );
    assert_eq!(std::fs::read(&probe).unwrap(), before);
}

/// The command that runs `ibl` with a display: directly when `DISPLAY` is set, else through
/// `xvfb-run -a` (None when neither exists).
fn with_display() -> Option<Command> {
    if std::env::var_os("DISPLAY").is_some() {
        return Some(Command::new(env!("CARGO_BIN_EXE_ibl")));
    }
    let xvfb = Command::new("xvfb-run").arg("--help").output().is_ok();
    xvfb.then(|| {
        let mut c = Command::new("xvfb-run");
        c.args([
            "-a",
            "-s",
            "-screen 0 1280x800x24",
            env!("CARGO_BIN_EXE_ibl"),
        ]);
        c
    })
}

fn distinct_colours(
    image: &ibl_core::Image<ibl_core::Rgb>,
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
) -> usize {
    let mut colours = std::collections::BTreeSet::new();
    for y in (y0..y1).step_by(3) {
        for x in (x0..x1).step_by(3) {
            let p = image.get(x, y);
            colours.insert([(p.r * 32.0) as u8, (p.g * 32.0) as u8, (p.b * 32.0) as u8]);
        }
    }
    colours.len()
}

#[test]
fn the_window_opens_under_xvfb_and_its_screenshot_shows_the_scene_and_the_ui() {
    let Some(mut command) = with_display() else {
        assert!(
            !in_ci(),
            "CI must install xvfb and xauth for the window test"
        );
        eprintln!("window: SKIPPED, no display and no xvfb-run");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let shot: PathBuf = dir.path().join("window.png");
    let out = command
        .args([
            "view",
            &scene("bunny-sky.toml"),
            "--size",
            "400x300",
            "--screenshot",
        ])
        .arg(&shot)
        .output()
        .unwrap();
    if no_adapter(&out, "window") {
        return;
    }
    assert!(out.status.success(), "{}", stderr(&out));
    let image = ibl_io::read_image(Path::new(&shot)).unwrap().image;
    let (w, h) = (image.width(), image.height());
    assert!(w >= 600 && h >= 300, "{w} x {h}");
    // The view (left) shows the composited scene: sky, sea, the bunny and its shadow.
    let view = distinct_colours(&image, 10, w - 320, 10, h - 40);
    assert!(view > 60, "the view shows {view} colours");
    // The side panel (right) shows the UI: text on a flat background, a few distinct colours.
    let panel = distinct_colours(&image, w - 280, w - 10, 10, h - 40);
    assert!(panel > 2 && panel < view, "the panel shows {panel} colours");
}
