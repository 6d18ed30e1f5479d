//! End-to-end tests of `ibl eval`: the report folder (JSON, CSV, markdown, plots, spheres,
//! overlays), `--json` on stdout, and exit code 2 with the file named for bad input.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::Path;
use std::process::Output;

use common::{ibl, probe, stderr};

fn eval_sky(out: &Path, extra: &[&str]) -> Output {
    let sky = probe("sky.exr");
    let mut args = vec![
        "eval",
        &sky,
        "--methods",
        "median-cut",
        "--n",
        "1,2,4,16",
        "--normals",
        "2000",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ibl(&args)
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path).is_ok_and(|b| b.starts_with(b"\x89PNG\r\n\x1a\n"))
}

#[test]
fn eval_writes_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let o = eval_sky(&out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains(&format!("{}/report.md", out.display())),
        "eval must say where the report is: {stdout}"
    );
    assert!(stdout.contains("median-cut"), "{stdout}");

    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(v["format"], "iblkit.eval/1");
    assert_eq!(v["normals"], 2000);
    assert!(v["fit_normals_note"].is_string());
    let p = &v["probes"][0];
    assert_eq!(p["name"], "sky");
    assert_eq!(p["sha256"].as_str().unwrap().len(), 64);
    assert!(p["ground_truth_seconds"].as_f64().unwrap() >= 0.0);
    let rows = p["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for r in rows {
        assert_eq!(r["status"], "ok", "{r}");
        for k in [
            "mean_err_pct",
            "max_err_pct",
            "rel_mean_err_pct",
            "rel_max_err_pct",
            "seconds",
        ] {
            assert!(r[k].as_f64().unwrap() >= 0.0, "{k}: {r}");
        }
    }
    assert_eq!(v["averages"].as_array().unwrap().len(), 4);

    let csv = std::fs::read_to_string(out.join("report.csv")).unwrap();
    assert!(csv.starts_with("probe,method,n,lights,mean_err_pct,max_err_pct,"));
    assert_eq!(csv.lines().count(), 1 + 4);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("median-cut") && md.contains("1 %") && md.contains("5 %"));

    for plot in ["average", "sky"] {
        let svg = std::fs::read_to_string(out.join(format!("plots/{plot}.svg"))).unwrap();
        assert!(svg.starts_with("<svg"), "{plot}");
        assert!(is_png(&out.join(format!("plots/{plot}.png"))), "{plot}");
    }
    assert!(is_png(&out.join("spheres/sky-median-cut-16.png")));
    assert!(is_png(&out.join("overlays/sky-median-cut-16.png")));
    // Every file the report lists exists.
    let files = &v["files"];
    for p in files["plots"].as_array().unwrap() {
        assert!(out.join(p["svg"].as_str().unwrap()).exists());
        assert!(out.join(p["png"].as_str().unwrap()).exists());
    }
    for f in files["figures"].as_array().unwrap() {
        assert!(out.join(f["sphere"].as_str().unwrap()).exists());
        assert!(out.join(f["overlay"].as_str().unwrap()).exists());
    }
}

#[test]
fn eval_json_prints_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let o = eval_sky(dir.path(), &["--json", "--overlay-n", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "iblkit.eval/1");
    assert_eq!(v["probes"][0]["rows"].as_array().unwrap().len(), 4);
    assert_eq!(v["files"]["json"], "report.json");
    assert_eq!(v["files"]["figures"][0]["n"], 4);
    assert!(dir.path().join("spheres/sky-median-cut-4.png").exists());
}

#[test]
fn median_cut_skips_counts_that_are_not_powers_of_two() {
    let dir = tempfile::tempdir().unwrap();
    let sky = probe("sky.exr");
    let o = ibl(&[
        "eval",
        &sky,
        "--methods",
        "median-cut",
        "--n",
        "2,3",
        "--normals",
        "500",
        "--out",
        dir.path().to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["probes"][0]["rows"].as_array().unwrap();
    assert_eq!(rows[1]["n"], 3);
    assert_eq!(rows[1]["status"], "skipped");
    assert!(rows[1]["reason"].as_str().unwrap().contains("power of two"));
}

#[test]
fn bad_input_exits_2_and_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let out = out.to_str().unwrap();
    let missing = dir.path().join("no-such-probe.exr");
    let o = ibl(&["eval", missing.to_str().unwrap(), "--out", out]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no-such-probe.exr"), "{}", stderr(&o));

    let garbage = dir.path().join("garbage.hdr");
    std::fs::write(&garbage, b"not an image").unwrap();
    let o = ibl(&["eval", garbage.to_str().unwrap(), "--out", out]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("garbage.hdr"), "{}", stderr(&o));

    let sky = probe("sky.exr");
    for bad in [
        vec!["--methods", "no-such-method"],
        vec!["--n", "0"],
        vec!["--n", "1,2", "--overlay-n", "8"],
        vec!["--normals", "0"],
    ] {
        let mut args = vec!["eval", sky.as_str(), "--out", out];
        args.extend(bad.iter());
        let o = ibl(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{bad:?}");
    }
    let o = ibl(&["eval", "--out", out]);
    assert_eq!(o.status.code(), Some(2), "a probe is required");
}

#[test]
fn eval_never_writes_over_an_input() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("plots")).unwrap();
    // A probe that sits exactly where its own plot would go: plots/sky.png.
    let input = dir.path().join("plots/sky.png");
    let o = ibl(&["preview", &probe("sky.exr"), input.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(&input).unwrap();
    let o = ibl(&[
        "eval",
        input.to_str().unwrap(),
        "--methods",
        "median-cut",
        "--n",
        "1",
        "--normals",
        "200",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("sky.png"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

#[test]
fn eval_help_has_examples() {
    let o = ibl(&["eval", "--help"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("Examples:") && text.contains("--methods"),
        "{text}"
    );
}

#[test]
fn hybrid_and_sh_models_are_scored_beside_light_sets() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hybrid");
    let sky = probe("sky.exr");
    let o = ibl(&[
        "eval",
        &sky,
        "--methods",
        "sun+sh3,sh3,lightgen,lightgen+sh3",
        "--n",
        "1,4",
        "--normals",
        "2000",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = report["probes"][0]["rows"].as_array().unwrap();
    let row = |m: &str, n: u64| {
        rows.iter()
            .find(|r| r["method"] == m && r["n"] == n)
            .unwrap()
            .clone()
    };
    let err = |m: &str, n: u64| row(m, n)["mean_err_pct"].as_f64().unwrap();
    // The sky has a hard sun: 1 sun + SH9 is far better than SH9 alone, and beats 4 lights.
    assert!(err("sun+sh3", 1) < 0.2 * err("sh3", 1));
    assert!(err("sun+sh3", 1) < err("lightgen", 4));
    assert_eq!(row("sun+sh3", 1)["parameters"]["sun_used"], 1.0);
    assert_eq!(row("sun+sh3", 4)["status"], "skipped");
    // SH alone has no lights and the same error at every N; the ambient helps the lights.
    assert_eq!(row("sh3", 4)["lights"], 0);
    assert_eq!(err("sh3", 1), err("sh3", 4));
    assert!(err("lightgen+sh3", 4) < err("lightgen", 4));
    // Power is conserved by every model (SH9 and the hybrids exactly).
    for r in rows.iter().filter(|r| r["status"] == "ok") {
        assert!(r["power_change_pct"].as_f64().unwrap().abs() < 1e-6, "{r}");
    }
    // Figures are drawn for light sets only.
    assert!(out.join("overlays/sky-lightgen-4.png").exists());
    assert!(!out.join("overlays/sky-sh3-4.png").exists());
    assert!(!out.join("overlays/sky-lightgen+sh3-4.png").exists());
}
