//! End-to-end tests of `ibl prefilter`: the files it writes load back (KTX2 and DDS, cube and
//! 2D), a constant probe gives constant maps, each target's roughness schedule reaches the
//! summary, a KTX2 cube is accepted as a probe, and bad arguments exit 2 before any work.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use common::{ibl, probe, stderr};
use ibl_core::{Image, Rgb};
use ibl_io::{Limits, TextureKind, read_texture};

fn json(o: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn every_output_loads_and_a_constant_probe_stays_constant() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("grey.exr");
    let l = Rgb::new(0.5, 1.0, 2.0);
    ibl_io::write_image(
        &input,
        &Image::filled(64, 32, l),
        &ibl_io::WriteOptions::default(),
    )
    .unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let o = ibl(&[
        "prefilter",
        input.to_str().unwrap(),
        "-o",
        &p("spec.ktx2"),
        "--size",
        "16",
        "--samples",
        "32",
        "--format",
        "rgba32f",
        "--latlong",
        &p("spec-ll.dds"),
        "--irradiance",
        &p("irr.dds"),
        "--irradiance-size",
        "4",
        "--sh",
        &p("sh.json"),
        "--dfg",
        &p("dfg.ktx2"),
        "--dfg-size",
        "8",
        "--preview",
        &p("chain.png"),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = json(&o);
    assert_eq!(summary["target"], "khronos");
    let roughness: Vec<f64> = summary["roughness"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(roughness, vec![0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]); // log2(16) = 4 levels
    let spec = read_texture(p("spec.ktx2").as_ref(), &Limits::default()).unwrap();
    assert_eq!(spec.texture.kind, TextureKind::Cube);
    assert_eq!(spec.texture.levels.len(), 4);
    for level in &spec.texture.levels {
        for face in &level.faces {
            for t in face.chunks(3) {
                for (v, want) in t.iter().zip([l.r, l.g, l.b]) {
                    // f32 storage of a normalised f32 sum: measured under 1e-6 relative.
                    assert!((v / want - 1.0).abs() < 1e-5, "{v} vs {want}");
                }
            }
        }
    }
    let ll = read_texture(p("spec-ll.dds").as_ref(), &Limits::default()).unwrap();
    assert_eq!(
        (ll.texture.kind, ll.texture.size()),
        (TextureKind::Flat, (64, 32))
    );
    let irr = read_texture(p("irr.dds").as_ref(), &Limits::default()).unwrap();
    assert_eq!(
        (irr.texture.kind, irr.texture.size()),
        (TextureKind::Cube, (4, 4))
    );
    for v in irr.texture.levels[0].faces[0].chunks(3) {
        // E / pi of a constant L is L; the pixel-centre cosine of a 64 x 32 probe is off by
        // about 2e-4 (midpoint rule, `ibl-core`'s constant-environment test).
        assert!((v[1] - l.g).abs() < 1e-3 * l.g, "{v:?}");
    }
    let dfg = read_texture(p("dfg.ktx2").as_ref(), &Limits::default()).unwrap();
    assert_eq!((dfg.texture.channels, dfg.texture.size()), (2, (8, 8)));
    let sh = ibl_io::read_sh_file(p("sh.json").as_ref(), ibl_io::ShFileFormat::Json).unwrap();
    assert_eq!(sh.bands, 3);
    assert!(std::fs::metadata(p("chain.png")).unwrap().len() > 100);
}

#[test]
fn targets_set_the_levels_and_a_ktx2_cube_is_a_probe() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("sky.ktx2");
    let o = ibl(&[
        "prefilter",
        &probe("sky.exr"),
        "-o",
        cube.to_str().unwrap(),
        "--size",
        "64",
        "--samples",
        "16",
        "--target",
        "filament",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let levels = json(&o)["roughness"].as_array().unwrap().len();
    assert_eq!(levels, 3); // 64, 32, 16: cmgen's smallest level is 16 px
    // The KTX2 cube, read back as the probe, gives a Unity chain (7 levels need 64 px faces).
    let unity = dir.path().join("unity.dds");
    let o = ibl(&[
        "prefilter",
        cube.to_str().unwrap(),
        "-o",
        unity.to_str().unwrap(),
        "--size",
        "64",
        "--samples",
        "16",
        "--target",
        "unity",
        "--format",
        "rgb9e5",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r = json(&o)["roughness"].clone();
    assert_eq!(r.as_array().unwrap().len(), 7);
    let info = ibl(&["info", unity.to_str().unwrap(), "--json"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let info = json(&info);
    assert_eq!(info["format"], "dds");
    assert_eq!(info["mapping"], "cube-strip");
    assert_eq!(info["mapping_guessed"], false);
    assert!(
        info["encoding"]
            .as_str()
            .unwrap()
            .contains("7 levels, rgb9e5")
    );
}

#[test]
fn bad_arguments_exit_2_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.ktx2");
    let sky = probe("sky.exr");
    for (args, says) in [
        (vec!["prefilter", &sky], "say what to write"),
        (
            vec!["prefilter", &sky, "-o", "/no/such/dir/x.ktx2"],
            "does not exist",
        ),
        (
            vec!["prefilter", &sky, "-o", "x.exr"],
            "unsupported output format",
        ),
        (
            vec![
                "prefilter",
                &sky,
                "-o",
                out.to_str().unwrap(),
                "--target",
                "quake",
            ],
            "unknown --target",
        ),
        (
            vec![
                "prefilter",
                &sky,
                "-o",
                out.to_str().unwrap(),
                "--size",
                "100",
            ],
            "power of two",
        ),
        (
            vec![
                "prefilter",
                &sky,
                "-o",
                out.to_str().unwrap(),
                "--format",
                "rg16f",
            ],
            "unknown --format",
        ),
        (
            vec!["prefilter", &sky, "-o", &sky],
            "unsupported output format",
        ),
        (
            vec!["prefilter", "-o", out.to_str().unwrap()],
            "need a probe",
        ),
    ] {
        let o = ibl(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
    // The DFG table alone needs no probe.
    let dfg = dir.path().join("dfg.exr");
    let o = ibl(&[
        "prefilter",
        "--dfg",
        dfg.to_str().unwrap(),
        "--dfg-size",
        "4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(ibl_io::read_image(&dfg).unwrap().image.width(), 4);
}
