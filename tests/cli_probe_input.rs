//! Issue 13, item 1: every command that takes a probe reads it through one loader. An angular
//! map, a mirror ball and a cube cross (made here from the bundled CC0 `sky.exr`) given to
//! `lights`, `sh`, `irradiance` and `eval` must give what the same probe converted to lat-long
//! first (`ibl convert --to latlong`) gives: the loader's conversion is `convert`'s, so the
//! goldens are the converted probe's own results and the comparison is exact (same code, f32
//! PFM files hold f32 values losslessly). A shape that names no mapping is refused (exit 2,
//! naming the file and its size). Before the fix each of these commands read any image as
//! lat-long and exited 0 with other numbers.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::{Path, PathBuf};

use common::{ibl, probe, stderr};

/// One non-lat-long input: its file, the `--mapping` it needs (None: detected) and the same
/// probe converted to lat-long first.
struct Input {
    name: &'static str,
    file: PathBuf,
    mapping: Option<&'static str>,
    latlong: PathBuf,
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn run_ok(args: &[&str]) -> std::process::Output {
    let o = ibl(args);
    assert!(o.status.success(), "ibl {args:?}: {}", stderr(&o));
    o
}

/// Makes the three inputs (in their own folders, with the same file stem `probe`, so that the
/// eval reports name them alike) and their lat-long conversions.
fn inputs(dir: &Path) -> Vec<Input> {
    let sky = probe("sky.exr");
    [
        ("angular", "angular", None),
        ("mirror-ball", "mirror-ball", Some("mirror-ball")),
        ("cross", "cube-hcross", None),
    ]
    .into_iter()
    .map(|(name, to, mapping)| {
        let folder = dir.join(name);
        std::fs::create_dir_all(folder.join("ll")).unwrap();
        let file = folder.join("probe.pfm");
        run_ok(&["convert", &sky, s(&file), "--to", to, "--width", "96"]);
        let latlong = folder.join("ll/probe.pfm");
        let mut args = vec!["convert", s(&file), s(&latlong), "--to", "latlong"];
        if let Some(m) = mapping {
            args.extend(["--from", m]);
        }
        run_ok(&args);
        Input {
            name,
            file,
            mapping,
            latlong,
        }
    })
    .collect()
}

/// `args` with `--mapping M` appended when the input needs it.
fn with_mapping<'a>(mut args: Vec<&'a str>, input: &'a Input) -> Vec<&'a str> {
    if let Some(m) = input.mapping {
        args.extend(["--mapping", m]);
    }
    args
}

fn json(bytes: &[u8]) -> serde_json::Value {
    serde_json::from_slice(bytes).unwrap()
}

#[test]
fn every_probe_command_converts_angular_ball_and_cross_inputs_like_convert() {
    let dir = tempfile::tempdir().unwrap();
    for input in inputs(dir.path()) {
        let out = dir.path().join(input.name);
        let name = input.name;

        // sh: the coefficients equal the converted probe's.
        let got = run_ok(&with_mapping(vec!["sh", s(&input.file)], &input));
        let want = run_ok(&["sh", s(&input.latlong)]);
        assert_eq!(
            json(&got.stdout)["coefficients"],
            json(&want.stdout)["coefficients"],
            "{name}: sh"
        );
        assert!(
            stderr(&got).contains("converted to a"),
            "{name}: the loader says what it did: {}",
            stderr(&got)
        );

        // lights: the same lights, and --json says what was detected.
        let (lg, lw) = (out.join("got.json"), out.join("want.json"));
        let got = run_ok(&with_mapping(
            vec!["lights", s(&input.file), "-n", "4", "-o", s(&lg), "--json"],
            &input,
        ));
        run_ok(&["lights", s(&input.latlong), "-n", "4", "-o", s(&lw)]);
        let read = |p: &Path| json(&std::fs::read(p).unwrap())["lights"].clone();
        assert_eq!(read(&lg), read(&lw), "{name}: lights");
        let summary = json(&got.stdout);
        let detected = &summary["probe_input"];
        let expected_source = if input.mapping.is_some() {
            "given"
        } else {
            "shape"
        };
        assert_eq!(detected["mapping_source"], expected_source, "{name}");
        assert!(detected["converted_to"].is_array(), "{name}: {summary}");

        // irradiance: the same CSV.
        let (cg, cw) = (out.join("got.csv"), out.join("want.csv"));
        run_ok(&with_mapping(
            vec![
                "irradiance",
                s(&input.file),
                "--normals",
                "300",
                "--csv",
                s(&cg),
            ],
            &input,
        ));
        run_ok(&[
            "irradiance",
            s(&input.latlong),
            "--normals",
            "300",
            "--csv",
            s(&cw),
        ]);
        assert_eq!(
            std::fs::read_to_string(&cg).unwrap(),
            std::fs::read_to_string(&cw).unwrap(),
            "{name}: irradiance"
        );

        // eval: the same errors (the CSV's seconds column aside).
        let (eg, ew) = (out.join("eval-got"), out.join("eval-want"));
        for (file, folder, mapped) in [(&input.file, &eg, true), (&input.latlong, &ew, false)] {
            let mut args = vec![
                "eval",
                s(file),
                "-n",
                "2",
                "--methods",
                "median-cut",
                "--normals",
                "300",
                "--out",
                s(folder),
            ];
            if mapped && let Some(m) = input.mapping {
                args.extend(["--mapping", m]);
            }
            run_ok(&args);
        }
        let errors = |folder: &Path| -> Vec<Vec<String>> {
            std::fs::read_to_string(folder.join("report.csv"))
                .unwrap()
                .lines()
                .map(|l| {
                    let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
                    cells.remove(8); // seconds
                    cells
                })
                .collect()
        };
        assert_eq!(errors(&eg), errors(&ew), "{name}: eval");
    }
}

/// A PFM of `w x h` grey pixels.
fn write_pfm(path: &Path, w: usize, h: usize) {
    let mut bytes = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    for _ in 0..w * h * 3 {
        bytes.extend_from_slice(&0.5f32.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn a_shape_that_names_no_mapping_is_refused_by_every_probe_command() {
    let dir = tempfile::tempdir().unwrap();
    let photo = dir.path().join("photo.pfm");
    write_pfm(&photo, 40, 60);
    let p = s(&photo);
    let out = dir.path().join("o");
    let o_json = format!("{}.json", s(&out));
    let o_csv = format!("{}.csv", s(&out));
    for args in [
        vec!["lights", p, "-n", "4", "-o", &o_json],
        vec!["sh", p],
        vec!["irradiance", p, "--csv", &o_csv],
        vec!["eval", p, "-n", "2", "--out", s(&out)],
    ] {
        let o = ibl(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(p) && e.contains("40 x 60"), "{args:?}: {e}");
        assert!(!out.with_extension("json").exists() && !out.exists());
    }
    // `ibl info` describes any image: it says the mapping is unknown and leaves out what needs
    // one (power, the brightest direction) instead of refusing.
    let o = ibl(&["info", p, "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = json(&o.stdout);
    assert_eq!(v["mapping"], "unknown");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(40), Some(60))
    );
    assert!(
        v["power"].is_null() && v["brightest"]["direction"].is_null(),
        "{v}"
    );
    // Named explicitly, the same image is accepted as lat-long.
    run_ok(&["sh", p, "--mapping", "latlong"]);
}
