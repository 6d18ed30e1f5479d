//! Issue 13, items 6 and 7: the smaller wrong answers (SH formats that hold 3 bands refuse
//! others, `-n 0` asks for N >= 1, "an angular" grammar, a mirror-ball unwrap with nothing
//! reliable fails) and progress lines when stderr is not a terminal.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::Path;
use std::process::Command;

use common::{ibl, ibl_binary, probe, stderr};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn three_band_formats_refuse_other_band_counts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sh.txt");
    for bands in ["5", "2"] {
        let o = ibl(&[
            "sh",
            &probe("sky.exr"),
            "--format",
            "filament",
            "--bands",
            bands,
            "-o",
            s(&out),
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "--bands {bands}: {e}");
        assert!(e.contains("exactly 3 bands") && e.contains(bands), "{e}");
        assert!(!out.exists(), "nothing written");
    }
}

#[test]
fn zero_lights_ask_for_at_least_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("l.json");
    for method in ["median-cut", "lightgen"] {
        let o = ibl(&[
            "lights",
            &probe("sky.exr"),
            "-n",
            "0",
            "--method",
            method,
            "-o",
            s(&out),
        ]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{method}: {e}");
        assert!(
            e.contains("N >= 1") && !e.contains("power of two"),
            "{method}: {e}"
        );
    }
}

#[test]
fn mapping_messages_take_the_right_article() {
    let dir = tempfile::tempdir().unwrap();
    let photo = dir.path().join("photo.pfm");
    let mut bytes = b"PF\n40 60\n-1.0\n".to_vec();
    bytes.extend(std::iter::repeat_n(0u8, 40 * 60 * 12));
    std::fs::write(&photo, bytes).unwrap();
    let o = ibl(&["info", s(&photo), "--mapping", "angular"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("an angular image") && !e.contains("a angular"),
        "{e}"
    );
}

#[test]
fn a_mirror_ball_with_nothing_reliable_fails_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let photo = dir.path().join("ball.pfm");
    let mut bytes = b"PF\n64 64\n-1.0\n".to_vec();
    bytes.extend(std::iter::repeat_n(0x3f80_0000u32.to_le_bytes(), 64 * 64 * 3).flatten());
    std::fs::write(&photo, bytes).unwrap();
    let out = dir.path().join("probe.exr");
    // A 3-pixel ball: every texel samples far less than one photo pixel (before: "0 % of the
    // sphere reliable", exit 0).
    let o = ibl(&[
        "capture",
        "ball",
        s(&photo),
        "--circle",
        "32,32,3",
        "-o",
        s(&out),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("no part of the sphere is reliable"), "{e}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the photo"
    );
}

#[test]
fn long_commands_print_progress_lines_when_stderr_is_not_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cross.exr");
    // The interval is set to 0 so that a short conversion shows its lines; stderr is a pipe.
    let o = Command::new(ibl_binary())
        .args(["convert", &probe("sky.exr"), s(&out), "--to", "cube-hcross"])
        .env("IBL_PROGRESS_SECONDS", "0")
        .output()
        .unwrap();
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    let lines: Vec<&str> = e
        .lines()
        .filter(|l| l.starts_with("resampling: "))
        .collect();
    assert!(lines.len() > 2, "{e}");
    // `stage: done/total, elapsed`, and the end of the stage.
    assert!(
        lines.iter().any(|l| l.contains('/') && l.ends_with(" s")),
        "{e}"
    );
    assert!(e.contains("resampling: done, "), "{e}");
    // With the default interval a job this short prints no progress at all.
    let o = ibl(&["convert", &probe("sky.exr"), s(&out), "--to", "cube-vcross"]);
    assert!(!stderr(&o).contains("resampling:"), "{}", stderr(&o));
}
