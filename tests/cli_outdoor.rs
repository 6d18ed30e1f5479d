//! End-to-end tests of `ibl outdoor` on the bundled synthetic courtyard
//! (`assets/outdoor/courtyard`, made with the example `courtyard_sequence`): the estimates against
//! the sequence's `truth.csv`, the files written, and bad input (exit status 2 naming the file).

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::Path;

use common::{ibl, repo, stderr};
use serde_json::Value;

fn courtyard() -> String {
    repo()
        .join("assets/outdoor/courtyard/scene.toml")
        .display()
        .to_string()
}

/// `(P_d, P_a)` per frame of the bundled `truth.csv`.
fn truth() -> Vec<([f64; 3], [f64; 3])> {
    let text = std::fs::read_to_string(repo().join("assets/outdoor/courtyard/truth.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').skip(3).map(|s| s.parse().unwrap()).collect();
            ([v[0], v[1], v[2]], [v[3], v[4], v[5]])
        })
        .collect()
}

#[test]
fn the_courtyard_sequence_is_estimated_and_composited() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("run");
    let out = ibl(&[
        "outdoor",
        &courtyard(),
        "--out",
        out_dir.to_str().unwrap(),
        "--frames",
        "3",
        "--relit",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    let truth = truth();
    for f in frames {
        let k = f["index"].as_u64().unwrap() as usize;
        let e = &f["result"]["estimate"];
        let (pd, pa) = truth[k];
        let rel = |key: &str, c: usize, want: f64| e[key][c].as_f64().unwrap() / want - 1.0;
        // 10:00 clear, 11:00 under a cloud, 12:00 clear; renders with 3 bounces, the bounce
        // transfer on (the default). Measured: P_d within 2.2 % (bound 5 %), P_a within 5.2 %
        // but red at 12:00, -20.4 % (bound 30 %): the sky around midday is the model's weak
        // figure with interreflections (docs/OUTDOOR.md, -25 % in red at worst over the day).
        for c in 0..3 {
            let (sun, sky) = (rel("sun", c, pd[c]), rel("sky", c, pa[c]));
            println!(
                "frame {k} channel {c}: P_d {:+.2} %, P_a {:+.2} %",
                100.0 * sun,
                100.0 * sky
            );
            assert!(sun.abs() < 0.05, "frame {k}: P_d off by {sun}");
            assert!(sky.abs() < 0.30, "frame {k}: P_a off by {sky}");
        }
        let composite = f["composite"].as_str().unwrap();
        assert!(out_dir.join(composite).exists());
        assert!(
            out_dir
                .join(Path::new(composite).with_extension("png"))
                .exists()
        );
        assert!(out_dir.join(f["relit_map"].as_str().unwrap()).exists());
    }
    let csv = std::fs::read_to_string(out_dir.join("estimates.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    let svg = std::fs::read_to_string(out_dir.join("estimates.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.contains("<svg"));
}

#[test]
fn a_scene_without_an_outdoor_table_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo().join("assets/scenes/bunny-sky.toml");
    let out = ibl(&[
        "outdoor",
        scene.to_str().unwrap(),
        "--out",
        dir.path().join("run").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("bunny-sky.toml") && err.contains("[outdoor]"),
        "{err}"
    );
}

/// The bundled scene with `edit` applied, written into `dir` with its paths made absolute.
fn edited_scene(dir: &Path, edit: impl Fn(String) -> String) -> String {
    let src = repo().join("assets/outdoor/courtyard");
    let scene = std::fs::read_to_string(src.join("scene.toml"))
        .unwrap()
        .replace("\"mask.png\"", &format!("{:?}", src.join("mask.png")))
        .replace("\"probe.exr\"", &format!("{:?}", src.join("probe.exr")))
        .replace("\"model.obj\"", &format!("{:?}", src.join("model.obj")))
        .replace(
            "\"frames/1000.exr\"",
            &format!("{:?}", src.join("frames/1000.exr")),
        )
        .replace(
            "source = \"frames\"",
            &format!("source = {:?}", src.join("frames")),
        );
    let path = dir.join("scene.toml");
    std::fs::write(&path, edit(scene)).unwrap();
    path.display().to_string()
}

#[test]
fn a_missing_mask_is_bad_input_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = edited_scene(dir.path(), |s| {
        let mask = format!("{:?}", repo().join("assets/outdoor/courtyard/mask.png"));
        s.replace(&mask, "\"no-such-mask.png\"")
    });
    let run = dir.path().join("run");
    let out = ibl(&["outdoor", &scene, "--out", run.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("no-such-mask.png"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn a_night_only_sequence_is_refused_before_the_offline_step() {
    let dir = tempfile::tempdir().unwrap();
    // 01:00 and 02:00 local time in Aalborg in April: the sun is well below the horizon.
    let scene = edited_scene(dir.path(), |s| {
        s.replace("start = 2024-04-20T10:00:00", "start = 2024-04-20T01:00:00")
    });
    let run = dir.path().join("run");
    let out = ibl(&[
        "outdoor",
        &scene,
        "--out",
        run.to_str().unwrap(),
        "--frames",
        "2",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("below the horizon") && err.contains("skipped"),
        "{err}"
    );
    assert!(err.contains("scene.toml"), "{err}");
}

/// Whether `ffmpeg` and `ffprobe` run here; under CI they must (`.ci/run` installs them).
fn have_ffmpeg(test: &str) -> bool {
    let ok = ["ffmpeg", "ffprobe"].iter().all(|tool| {
        std::process::Command::new(tool)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    });
    assert!(
        ok || !common::in_ci(),
        "{test}: ffmpeg and ffprobe are required under CI"
    );
    if !ok {
        eprintln!("{test}: SKIPPED, no ffmpeg on the PATH");
    }
    ok
}

/// A video of the courtyard: frames 10:00 to 12:00 as sRGB PNGs (exposure 0, clamped: the
/// linear values survive but for 8-bit rounding) encoded losslessly (H.264 at QP 0, 4:4:4).
#[test]
fn a_video_is_decoded_estimated_and_the_composites_encoded() {
    if !have_ffmpeg("video") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let frames = repo().join("assets/outdoor/courtyard/frames");
    for (i, name) in ["1000", "1100", "1200"].iter().enumerate() {
        let png = dir.path().join(format!("{i:02}.png"));
        let exr = frames.join(format!("{name}.exr"));
        let out = ibl(&[
            "preview",
            exr.to_str().unwrap(),
            png.to_str().unwrap(),
            "--exposure",
            "0",
            "--tonemap",
            "clamp",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let video = dir.path().join("day.mkv");
    let encoded = std::process::Command::new("ffmpeg")
        .args(["-v", "error", "-y", "-framerate", "1", "-i"])
        .arg(dir.path().join("%02d.png"))
        .args(["-c:v", "libx264", "-qp", "0", "-pix_fmt", "yuv444p"])
        .arg(&video)
        .status()
        .unwrap();
    assert!(encoded.success());
    let scene = edited_scene(dir.path(), |s| {
        let folder = format!("{:?}", frames);
        s.replace(
            &format!("source = {folder}"),
            &format!("source = {video:?}"),
        )
    });
    let run = dir.path().join("run");
    let composites = run.join("composites.mp4");
    let out = ibl(&[
        "outdoor",
        &scene,
        "--out",
        run.to_str().unwrap(),
        "--video",
        composites.to_str().unwrap(),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let got = v["frames"].as_array().unwrap();
    assert_eq!(got.len(), 3, "every frame of the video");
    let truth = truth();
    for f in got {
        let k = f["index"].as_u64().unwrap() as usize;
        assert_eq!(f["name"], format!("frame_{k:05}"));
        let e = &f["result"]["estimate"];
        for c in 0..3 {
            let sun = e["sun"][c].as_f64().unwrap() / truth[k].0[c] - 1.0;
            // Measured within 2.3 % from the EXR frames and within 1.4 % of those estimates
            // through the 8-bit video; bound 5 % as for the EXR frames.
            assert!(sun.abs() < 0.05, "frame {k}: P_d off by {sun}");
        }
    }
    let probed = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=nb_read_frames,width,height",
            "-of",
            "csv=p=0",
        ])
        .arg(&composites)
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&probed.stdout).trim(), "160,120,3");
    // Not a video: exit 2 naming it.
    let bad = dir.path().join("bad.mp4");
    std::fs::write(&bad, b"not a video at all").unwrap();
    let scene = edited_scene(dir.path(), |s| {
        let folder = format!("{:?}", frames);
        s.replace(&format!("source = {folder}"), &format!("source = {bad:?}"))
    });
    let out = ibl(&["outdoor", &scene, "--out", run.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("bad.mp4"), "{}", stderr(&out));
}
