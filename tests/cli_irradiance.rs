//! End-to-end tests of `ibl irradiance -o`: irradiance environment maps, exact and SH, in
//! lat-long and cube mappings, and their refusals.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use common::{ibl, probe, stderr};
use ibl_core::{Image, Rgb};

fn json(o: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn constant_probe_gives_pi_l_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("white.exr");
    let probe = Image::filled(64, 32, Rgb::new(1.0, 0.5, 0.25));
    ibl_io::write_image(&input, &probe, &ibl_io::WriteOptions::default()).unwrap();
    for method in ["exact", "sh"] {
        let out = dir.path().join(format!("e-{method}.exr"));
        let o = ibl(&[
            "irradiance",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--method",
            method,
            "--width",
            "32",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let map = ibl_io::read_image(&out).unwrap().image;
        assert_eq!((map.width(), map.height()), (32, 16));
        for px in map.pixels() {
            for (v, l) in [(px.r, 1.0), (px.g, 0.5), (px.b, 0.25)] {
                let want = std::f32::consts::PI * l;
                // SH: the constant's l > 0 coefficients are quadrature noise of a 64 x 32 probe.
                assert!((v - want).abs() < 2e-3 * want, "{method}: {v} vs {want}");
            }
        }
    }
}

#[test]
fn sh_maps_state_their_error_and_converge() {
    let dir = tempfile::tempdir().unwrap();
    let mut last = f64::INFINITY;
    for bands in ["3", "9", "21"] {
        let out = dir.path().join(format!("sh{bands}.exr"));
        let o = ibl(&[
            "irradiance",
            &probe("sky.exr"),
            "-o",
            out.to_str().unwrap(),
            "--method",
            "sh",
            "--bands",
            bands,
            "--json",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v = json(&o);
        let mean = v["mean_err_pct"].as_f64().unwrap();
        assert!(mean < last, "{bands} bands: {mean}");
        last = mean;
        assert_eq!(v["bands"], bands.parse::<u64>().unwrap());
    }
    // SH21 irradiance on the sky probe: the 18 shared probes average 0.083 % mean error at 21 bands
    // (ARCHITECTURE.md), the sky's compact sun is the hard case; 0.4 % still fails a broken
    // projection (SH3 is about 3 %).
    assert!(last < 0.4, "21 bands: {last}");
    // The exact method has no error to state.
    let out = dir.path().join("exact.exr");
    let o = ibl(&[
        "irradiance",
        &probe("sky.exr"),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(json(&o)["mean_err_pct"].is_null());
}

#[test]
fn cube_faces_are_six_files() {
    let dir = tempfile::tempdir().unwrap();
    let pattern = dir.path().join("irr_{face}.hdr");
    let o = ibl(&[
        "irradiance",
        &probe("night.exr"),
        "-o",
        pattern.to_str().unwrap(),
        "--to",
        "cube-faces",
        "--width",
        "96",
        "--method",
        "sh",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for face in ["px", "nx", "py", "ny", "pz", "nz"] {
        let img = ibl_io::read_image(&dir.path().join(format!("irr_{face}.hdr")))
            .unwrap()
            .image;
        assert_eq!((img.width(), img.height()), (16, 16));
    }
}

#[test]
fn bad_arguments_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e.exr");
    let o = out.to_str().unwrap();
    let p = probe("night.exr");
    for args in [
        vec!["irradiance", p.as_str()],
        vec![
            "irradiance",
            p.as_str(),
            "-o",
            o,
            "--bands",
            "0",
            "--method",
            "sh",
        ],
        vec![
            "irradiance",
            p.as_str(),
            "-o",
            o,
            "--bands",
            "65",
            "--method",
            "sh",
        ],
        vec!["irradiance", p.as_str(), "-o", o, "--window", "gauss"],
        vec!["irradiance", p.as_str(), "-o", o, "--to", "fisheye"],
        vec!["irradiance", p.as_str(), "-o", o, "--width", "0"],
        vec!["irradiance", p.as_str(), "-o", p.as_str()],
    ] {
        let r = ibl(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {}", stderr(&r));
        assert!(!out.exists(), "{args:?}");
    }
}
