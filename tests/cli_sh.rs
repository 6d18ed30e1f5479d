//! End-to-end tests of `ibl sh`: every export format read back gives the same irradiance at 1000
//! random normals (to 1e-5 relative), iblkit's JSON keeps any band count and irradiance, and bad
//! arguments exit 2. The conventions and the files they were taken from (three.js
//! `src/math/SphericalHarmonics3.js` and `src/lights/LightProbe.js`; Filament
//! `tools/cmgen/src/cmgen.cpp` `outputSh`, `libs/ibl/src/CubemapSH.cpp` and
//! `shaders/src/surface_light_indirect.fs`) are checked formula by formula in
//! `ibl-io::sh_file`'s unit tests.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use common::{ibl, probe, stderr};
use ibl_core::glam::DVec3;
use ibl_sh::{RadianceSh, Window};
use rand::{Rng, SeedableRng};

fn radiance_of(path: &std::path::Path) -> RadianceSh {
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    assert_eq!(v["quantity"], "radiance");
    let coeffs: Vec<[f64; 3]> = serde_json::from_value(v["coefficients"].clone()).unwrap();
    RadianceSh::new(v["bands"].as_u64().unwrap() as usize, coeffs).unwrap()
}

#[test]
fn every_format_round_trips_to_the_same_irradiance() {
    let dir = tempfile::tempdir().unwrap();
    let original = dir.path().join("sky.json");
    let o = ibl(&["sh", &probe("sky.exr"), "-o", original.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let want = radiance_of(&original).irradiance(Window::None);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let normals: Vec<DVec3> = (0..1000)
        .map(|_| {
            DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize()
        })
        .collect();
    let reference = want.eval_many(&normals);
    let scale = reference
        .iter()
        .flatten()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    for format in [
        "json", "threejs", "filament", "unity", "webxr", "arkit", "gltf-ext",
    ] {
        let exported = dir.path().join(format!("export.{format}"));
        let o = ibl(&[
            "sh",
            original.to_str().unwrap(),
            "--from",
            "json",
            "--format",
            format,
            "-o",
            exported.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{format}: {}", stderr(&o));
        let back = dir.path().join(format!("back-{format}.json"));
        let o = ibl(&[
            "sh",
            exported.to_str().unwrap(),
            "--from",
            format,
            "-o",
            back.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{format}: {}", stderr(&o));
        let got = radiance_of(&back)
            .irradiance(Window::None)
            .eval_many(&normals);
        for (g, w) in got.iter().zip(&reference) {
            for c in 0..3 {
                // Tool formats store coefficients as decimal text, some through f32: a round trip
                // loses a few f32 ulps (1e-7 relative); 1e-5, floored at 1e-3 of the scale for
                // near-zero coefficients.
                assert!(
                    (g[c] - w[c]).abs() <= 1e-5 * w[c].abs().max(1e-3 * scale),
                    "{format}: {g:?} vs {w:?}"
                );
            }
        }
    }
}

#[test]
fn json_keeps_bands_and_irradiance() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.json");
    let o = ibl(&[
        "sh",
        &probe("night.exr"),
        "--bands",
        "7",
        "--irradiance",
        "--window",
        "lanczos",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(v["format"], "iblkit.sh/1");
    assert_eq!(v["bands"], 7);
    assert_eq!(v["quantity"], "irradiance");
    assert_eq!(v["window"], "lanczos");
    assert_eq!(v["coefficients"].as_array().unwrap().len(), 49);
    // Band 0 of irradiance is pi times radiance's (no window on band 0).
    let radiance = dir.path().join("l.json");
    let o = ibl(&["sh", &probe("night.exr"), "-o", radiance.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&radiance).unwrap()).unwrap();
    let (e0, c0) = (
        v["coefficients"][0][1].as_f64().unwrap(),
        r["coefficients"][0][1].as_f64().unwrap(),
    );
    // Irradiance band 0 is pi times radiance band 0 (A_0 = pi), one f64 product; 1e-12 relative.
    assert!((e0 - std::f64::consts::PI * c0).abs() < 1e-12 * e0);
}

#[test]
fn bad_arguments_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.txt");
    let o = out.to_str().unwrap();
    let p = probe("night.exr");
    let garbage = dir.path().join("garbage.txt");
    std::fs::write(&garbage, "(1, 2)\n").unwrap();
    let g = garbage.to_str().unwrap();
    for args in [
        vec!["sh", p.as_str(), "--format", "maya", "-o", o],
        vec![
            "sh",
            p.as_str(),
            "--format",
            "filament",
            "--bands",
            "2",
            "-o",
            o,
        ],
        vec![
            "sh",
            p.as_str(),
            "--format",
            "unity",
            "--irradiance",
            "-o",
            o,
        ],
        vec!["sh", p.as_str(), "--bands", "0", "-o", o],
        vec!["sh", p.as_str(), "--window", "box", "-o", o],
        vec!["sh", g, "--from", "filament", "-o", o],
        vec!["sh", g, "--from", "nothing", "-o", o],
        vec!["sh", p.as_str(), "-o", p.as_str()],
    ] {
        let r = ibl(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {}", stderr(&r));
        assert!(!out.exists(), "{args:?}");
    }
    // The garbage file is named in the message.
    let r = ibl(&["sh", g, "--from", "filament"]);
    assert!(stderr(&r).contains("garbage.txt"), "{}", stderr(&r));
}
