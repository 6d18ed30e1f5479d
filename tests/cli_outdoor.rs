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
