//! Golden numbers: every extraction method on every bundled probe at N = 1, 4, 16, 64, scored on
//! 20000 Fibonacci normals, against `tests/golden/extraction.json`.
//!
//! Tolerances (relative to the golden value, per metric):
//! * region methods (median cut, adaptive median cut, variance minimisation): 1e-6. They are
//!   deterministic sums; only the f64 summation order of another CPU could move them.
//! * LightGen clustering: 2 %. Deterministic for a seed and any thread count, but a k-means
//!   assignment can flip on another CPU's rounding.
//! * irradiance optimisation: 15 %. Deterministic on one machine, but its path runs through
//!   matrix-product kernels that `matrixmultiply` picks per CPU (AVX2, AVX-512), so another CPU can
//!   land in a nearby local minimum; the test also fails if any fit did not converge.
//!
//! A missing golden file fails. To write it after a deliberate change:
//! `IBL_BLESS=1 cargo test -p ibl-eval --test golden` (then review the diff). On failure the
//! measured numbers are written to `target/golden-actual/extraction.json` for comparison.

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_eval::{ProbeInput, Status, SweepOptions, sweep};
use ibl_extract::{ExtractOptions, ModelSpec};
use ibl_light::Method;
use serde::{Deserialize, Serialize};

const GOLDEN_FORMAT: &str = "iblkit.golden.extraction/1";

#[derive(Debug, Serialize, Deserialize, PartialEq)]
struct GoldenRow {
    probe: String,
    method: String,
    n: usize,
    mean_err_pct: f64,
    max_err_pct: f64,
}

#[derive(Debug, Serialize, Deserialize)]
struct Golden {
    format: String,
    normals: usize,
    rows: Vec<GoldenRow>,
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tolerance(method: &str) -> f64 {
    match method {
        "lightgen" => 0.02,
        "irradiance-optimization" => 0.15,
        _ => 1e-6,
    }
}

#[test]
fn every_method_on_every_bundled_probe_matches_its_golden_numbers() {
    let dir = repo().join("assets/probes");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "exr"))
        .collect();
    paths.sort();
    let probes: Vec<(String, Image<Rgb>)> = paths
        .iter()
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, ibl_io::read_image(p).unwrap().image)
        })
        .collect();
    let inputs: Vec<ProbeInput<'_>> = probes
        .iter()
        .map(|(name, image)| ProbeInput {
            name,
            sha256: "",
            image,
        })
        .collect();
    let options = SweepOptions {
        methods: Method::ALL.map(ModelSpec::from).to_vec(),
        counts: vec![1, 4, 16, 64],
        normals: 20_000,
        extract: ExtractOptions::default(),
        keep_sets_at: None,
    };
    let result = sweep(&inputs, &options, &|_| {}).unwrap();
    let mut rows = Vec::new();
    for p in &result.report.probes {
        for r in &p.rows {
            assert_eq!(
                r.status,
                Status::Ok,
                "{} {} N={}: {:?}",
                p.name,
                r.method,
                r.n,
                r.reason
            );
            if r.method == "irradiance-optimization" {
                assert_eq!(
                    r.parameters.get("converged").and_then(|v| v.as_f64()),
                    Some(1.0),
                    "{} N={} did not converge",
                    p.name,
                    r.n
                );
            }
            rows.push(GoldenRow {
                probe: p.name.clone(),
                method: r.method.clone(),
                n: r.n,
                mean_err_pct: r.mean_err_pct.unwrap(),
                max_err_pct: r.max_err_pct.unwrap(),
            });
        }
    }
    let actual = Golden {
        format: GOLDEN_FORMAT.into(),
        normals: options.normals,
        rows,
    };
    let path = repo().join("tests/golden/extraction.json");
    if std::env::var_os("IBL_BLESS").is_some() {
        std::fs::write(&path, serde_json::to_string_pretty(&actual).unwrap() + "\n").unwrap();
        println!("blessed {}", path.display());
        return;
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; write it with `IBL_BLESS=1 cargo test -p ibl-eval --test golden`",
            path.display()
        )
    });
    let golden: Golden = serde_json::from_str(&text).unwrap();
    assert_eq!(golden.format, GOLDEN_FORMAT);
    assert_eq!(golden.normals, actual.normals);
    let mut failures = Vec::new();
    for want in &golden.rows {
        let Some(got) = actual
            .rows
            .iter()
            .find(|r| r.probe == want.probe && r.method == want.method && r.n == want.n)
        else {
            failures.push(format!(
                "{} {} N={}: no result",
                want.probe, want.method, want.n
            ));
            continue;
        };
        let tol = tolerance(&want.method);
        for (name, a, b) in [
            ("mean_err_pct", got.mean_err_pct, want.mean_err_pct),
            ("max_err_pct", got.max_err_pct, want.max_err_pct),
        ] {
            if (a - b).abs() > tol * b.abs() + 1e-12 {
                failures.push(format!(
                    "{} {} N={} {name}: {a:.6} vs golden {b:.6} (tolerance {:.0e} relative)",
                    want.probe, want.method, want.n, tol
                ));
            }
        }
    }
    if actual.rows.len() != golden.rows.len() {
        failures.push(format!(
            "{} results against {} golden rows",
            actual.rows.len(),
            golden.rows.len()
        ));
    }
    if !failures.is_empty() {
        let out = repo().join("target/golden-actual");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(
            out.join("extraction.json"),
            serde_json::to_string_pretty(&actual).unwrap(),
        )
        .unwrap();
        panic!(
            "{} golden mismatches (measured numbers in target/golden-actual/extraction.json):\n{}",
            failures.len(),
            failures.join("\n")
        );
    }
}
