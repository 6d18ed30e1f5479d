//! Issue 13, item 5: every output path is checked before the work starts. A missing folder, a
//! folder that takes no files (`/proc` refuses even root, where permission bits would not) and an
//! output equal to the input exit 2 with a message naming the path the user gave, never the
//! hidden temporary file of the atomic write; nothing is written. Before the fix a missing folder
//! was an internal failure (exit 1) after the whole extraction, naming `.iblkit-XXXX.tmp`.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use common::{ibl, probe, stderr};

/// Every command with a file output, writing to `out`.
fn commands(out: &str) -> Vec<Vec<String>> {
    let sky = probe("sky.exr");
    [
        vec!["lights", &sky, "-n", "4", "-o", out],
        vec!["sh", &sky, "-o", out],
        vec!["irradiance", &sky, "--normals", "100", "--csv", out],
        vec!["convert", &sky, out],
        vec!["convert", &sky, out, "--to", "cube-hcross"],
        vec!["preview", &sky, out],
    ]
    .into_iter()
    .map(|v| v.into_iter().map(str::to_string).collect())
    .collect()
}

fn refused(args: &[String], path: &str) {
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = ibl(&refs);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(e.contains(path), "{args:?} names {path}: {e}");
    assert!(
        !e.contains(".iblkit-"),
        "{args:?} names a temporary file: {e}"
    );
}

#[test]
fn a_missing_output_folder_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["out.json", "out.exr", "out.png", "out.csv"] {
        let out = dir.path().join("missing").join(ext);
        let out = out.to_str().unwrap();
        for args in commands(out) {
            // Only the commands whose output format this extension is.
            let fits = match args[0].as_str() {
                "lights" | "sh" => ext.ends_with(".json"),
                "irradiance" => ext.ends_with(".csv"),
                "convert" => ext.ends_with(".exr"),
                "preview" => ext.ends_with(".png"),
                _ => false,
            };
            if fits {
                refused(&args, out);
            }
        }
    }
    // A missing report folder is created, but one under /proc cannot be.
    let o = ibl(&[
        "eval",
        &probe("sky.exr"),
        "-n",
        "2",
        "--out",
        "/proc/ibl-eval",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("/proc/ibl-eval"), "{}", stderr(&o));
}

#[test]
fn a_folder_that_takes_no_files_is_refused_before_any_work() {
    for (ext, args) in [
        ("json", commands("/proc/ibl-out.json")[0].clone()),
        ("json", commands("/proc/ibl-out.json")[1].clone()),
        ("csv", commands("/proc/ibl-out.csv")[2].clone()),
        ("exr", commands("/proc/ibl-out.exr")[3].clone()),
        ("png", commands("/proc/ibl-out.png")[5].clone()),
    ] {
        refused(&args, &format!("/proc/ibl-out.{ext}"));
    }
}

#[test]
fn an_output_equal_to_the_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("sky.exr");
    std::fs::copy(probe("sky.exr"), &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    let c = copy.to_str().unwrap();
    for args in [
        vec!["convert", c, c],
        vec!["convert", c, c, "--to", "cube-hcross"],
        vec!["preview", c, c],
    ] {
        let o = ibl(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(c), "{args:?}: {}", stderr(&o));
    }
    assert_eq!(
        std::fs::read(&copy).unwrap(),
        before,
        "the input is untouched"
    );
}
