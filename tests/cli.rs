//! End-to-end tests of the `ibl` binary: JSON output, conversions, previews, the demo, exit codes,
//! and the hostile-input corpus in `tests/hostile/` (every case must end in a clear error naming
//! the file and exit code 2, or load with its invalid values counted; never a panic).

mod common;

use std::path::{Path, PathBuf};

use common::{ibl, in_ci, probe, repo, stderr};

#[test]
fn info_json_has_every_field_on_every_bundled_probe() {
    for name in ["apartment", "esplanade", "night", "sky", "sunset"] {
        for ext in ["exr", "hdr"] {
            let path = probe(&format!("{name}.{ext}"));
            let out = ibl(&["info", &path, "--json"]);
            assert!(out.status.success(), "{path}: {}", stderr(&out));
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
            assert_eq!(v["width"], 512);
            assert_eq!(v["height"], 256);
            assert_eq!(v["format"], ext);
            assert_eq!(v["mapping"], "latlong");
            for key in ["min", "max", "mean", "power"] {
                assert_eq!(v[key].as_array().map(Vec::len), Some(3), "{key}");
            }
            assert!(v["negative_values"].is_u64() && v["nonfinite_values"].is_u64());
            let d: Vec<f64> = v["brightest"]["direction"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            // The JSON direction is an f32 unit vector printed in full: unit to f32 rounding
            // (1e-7); 1e-4.
            assert!(
                (len - 1.0).abs() < 1e-4,
                "{path}: brightest direction not unit: {d:?}"
            );
            assert_eq!(v["brightest"]["pixel"].as_array().map(Vec::len), Some(2));
            assert_eq!(v["brightest"]["radiance"].as_array().map(Vec::len), Some(3));
            let power: Vec<f64> = v["power"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            assert!(power.iter().all(|p| *p > 0.0), "{path}: power {power:?}");
        }
    }
}

#[test]
fn sky_sun_is_the_brightest_direction_and_above_the_horizon() {
    let out = ibl(&["info", &probe("sky.exr"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let y = v["brightest"]["direction"][1].as_f64().unwrap();
    let peak = v["brightest"]["radiance"][0].as_f64().unwrap();
    // The sun in `sky` is about 48 degrees above the horizon, ahead and to the right.
    assert!(y > 0.7 && y < 0.8, "sun elevation: {y}");
    assert!(peak > 1000.0, "sun radiance {peak}");
    // The .exr keeps DWAB's negative ringing; the tool must count it.
    assert!(v["negative_values"].as_u64().unwrap() > 0);
}

#[test]
fn info_text_names_the_mapping_guess() {
    let out = ibl(&["info", &probe("night.hdr")]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("latlong") && text.contains("guessed"),
        "{text}"
    );
    assert!(text.contains("brightest"));
}

#[test]
fn convert_between_formats_and_cube_faces_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    let out = ibl(&["convert", &probe("sunset.hdr"), &d("a.pfm")]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = ibl(&[
        "convert",
        &d("a.pfm"),
        &d("faces.exr"),
        "--to",
        "cube-faces",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    for face in ["px", "nx", "py", "ny", "pz", "nz"] {
        assert!(
            dir.path().join(format!("faces_{face}.exr")).exists(),
            "{face}"
        );
    }
    let pattern = d("faces_{face}.exr");
    let out = ibl(&[
        "convert",
        &pattern,
        &d("back.exr"),
        "--from",
        "cube-faces",
        "--to",
        "latlong",
        "--width",
        "512",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let power = |p: &str| -> Vec<f64> {
        let o = ibl(&["info", p, "--json"]);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["power"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (a, b) = (power(&probe("sunset.hdr")), power(&d("back.exr")));
    for c in 0..3 {
        // A cube round trip resamples twice with area averaging that conserves energy to the
        // sub-sample quadrature (the demo's round trips print their power change; a few hundredths
        // of a per cent); 0.5 %.
        assert!(
            (a[c] - b[c]).abs() / a[c] < 0.005,
            "channel {c}: {} vs {}",
            a[c],
            b[c]
        );
    }
}

#[test]
fn rotate_and_frame_are_accepted_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("r.hdr").display().to_string();
    let ok = ibl(&[
        "convert",
        &probe("night.hdr"),
        &out_path,
        "--rotate",
        "-90,10,0",
        "--frame",
        "threejs",
    ]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    let bad = ibl(&[
        "convert",
        &probe("night.hdr"),
        &out_path,
        "--rotate",
        "90,0",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let bad = ibl(&["convert", &probe("night.hdr"), &out_path, "--frame", "maya"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("maya"));
    let bad = ibl(&[
        "convert",
        &probe("night.hdr"),
        &out_path,
        "--to",
        "octahedral",
    ]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn preview_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("p.png");
    let out = ibl(&[
        "preview",
        &probe("apartment.exr"),
        png.to_str().unwrap(),
        "--tonemap",
        "aces",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let out = ibl(&[
        "preview",
        &probe("apartment.exr"),
        png.to_str().unwrap(),
        "--exposure",
        "-3",
    ]);
    assert!(out.status.success());
}

#[test]
fn never_writes_over_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("probe.hdr");
    std::fs::copy(probe("night.hdr"), &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    let c = copy.to_str().unwrap();
    let out = ibl(&["convert", c, c]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("probe.hdr"));
    assert_eq!(std::fs::read(&copy).unwrap(), before, "input changed");
}

#[test]
fn missing_files_and_bad_arguments_exit_2() {
    let out = ibl(&["info", "/nonexistent/probe.exr"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("/nonexistent/probe.exr"));
    let out = ibl(&["info"]);
    assert_eq!(out.status.code(), Some(2));
    let out = ibl(&["frobnicate"]);
    assert_eq!(out.status.code(), Some(2));
    let out = ibl(&["--help"]);
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn every_help_has_examples() {
    for cmd in [
        "info",
        "convert",
        "preview",
        "demo",
        "lights",
        "irradiance",
        "eval",
        "sh",
    ] {
        let out = ibl(&[cmd, "--help"]);
        assert!(out.status.success());
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("Examples:"),
            "{cmd}"
        );
    }
}

/// Parses `tests/hostile/README.md`: lines `name | error|loads | what`.
fn hostile_cases() -> Vec<(PathBuf, bool)> {
    let dir = repo().join("tests/hostile");
    let readme = std::fs::read_to_string(dir.join("README.md")).expect("tests/hostile/README.md");
    let cases: Vec<(PathBuf, bool)> = readme
        .lines()
        .filter_map(|line| {
            let cols: Vec<&str> = line
                .split('|')
                .map(|c| c.trim().trim_matches('`'))
                .collect();
            if cols.len() < 3 || !matches!(cols[1], "error" | "loads") {
                return None;
            }
            Some((dir.join(cols[0]), cols[1] == "error"))
        })
        .collect();
    assert!(
        cases.len() >= 15,
        "hostile corpus too small: {}",
        cases.len()
    );
    cases
}

#[test]
fn hostile_corpus_gives_clear_errors_and_exit_2() {
    for (path, must_fail) in hostile_cases() {
        assert!(path.exists(), "{} listed but missing", path.display());
        let p = path.display().to_string();
        let out = ibl(&["info", &p]);
        let err = stderr(&out);
        assert!(!err.contains("panicked"), "{p}: panic: {err}");
        if must_fail {
            assert_eq!(
                out.status.code(),
                Some(2),
                "{p}: expected exit 2, stderr: {err}"
            );
            let name = path.file_name().unwrap().to_string_lossy();
            assert!(
                err.contains(name.as_ref()),
                "{p}: message does not name the file: {err}"
            );
        } else {
            assert_eq!(out.status.code(), Some(0), "{p}: expected to load: {err}");
        }
    }
}

/// The whole demo on the bundled data: the slow tier (about 3.5 minutes of CI's 2 cores, most of
/// the test step's; `IBL_SLOW=1 bash .ci/run`). The main tier runs the same demo and the same
/// checks on one probe and one scene ([`demo_on_one_probe_and_one_scene_writes_every_section`]).
#[test]
#[ignore = "slow tier: the whole demo on the bundled data; IBL_SLOW=1 bash .ci/run"]
fn demo_writes_every_mapping_and_an_index() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("demo");
    let out = ibl(&["demo", "--out", out_dir.to_str().unwrap()]);
    check_demo(
        &out,
        &out_dir,
        &["apartment", "esplanade", "night", "sky", "sunset"],
        2,
    );
}

/// The demo with every section (mappings, comparison, renders and their study, room, outdoor
/// sequence, viewer frames) on the sky probe and the bunny-sky scene, copied with what they
/// name into a folder laid out as `assets/` is.
#[test]
fn demo_on_one_probe_and_one_scene_writes_every_section() {
    let dir = tempfile::tempdir().unwrap();
    let assets = repo().join("assets");
    for (from, to) in [
        ("probes/sky.exr", "probes/sky.exr"),
        ("models/bunny.glb", "models/bunny.glb"),
        ("scenes/bunny-sky.toml", "scenes/bunny-sky.toml"),
    ] {
        let to = dir.path().join(to);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(assets.join(from), to).unwrap();
    }
    let out_dir = dir.path().join("demo");
    let out = ibl(&[
        "demo",
        "--out",
        out_dir.to_str().unwrap(),
        "--probes",
        dir.path().join("probes").to_str().unwrap(),
        "--scenes",
        dir.path().join("scenes").to_str().unwrap(),
    ]);
    check_demo(&out, &out_dir, &["sky"], 1);
}

/// Checks a demo run on `probe_names` and `scene_count` scenes.
#[allow(clippy::unwrap_used)] // a test's helper: a failure is the test's
fn check_demo(
    out: &std::process::Output,
    out_dir: &Path,
    probe_names: &[&str],
    scene_count: usize,
) {
    assert!(out.status.success(), "{}", stderr(out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(out_dir.to_str().unwrap()),
        "demo must say where its outputs are"
    );
    assert!(out_dir.join("index.html").exists());
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap();
    let probes = summary["probes"].as_array().unwrap();
    let names: Vec<&str> = probes.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, probe_names);
    let sections = summary["sections"].as_array().unwrap();
    // The outdoor sequence (issue 18): every bundled frame estimated and composited.
    let outdoor = sections.iter().find(|s| s["id"] == "outdoor").unwrap();
    let frames = outdoor["data"]["summary"]["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 8);
    for f in frames {
        let png = std::path::Path::new("outdoor")
            .join(f["composite"].as_str().unwrap())
            .with_extension("png");
        assert!(out_dir.join(&png).exists(), "{}", png.display());
    }
    assert!(out_dir.join("outdoor/estimates.svg").exists());
    // The viewer's section (issue 15): a headless frame of each example scene with its timings,
    // and the outdoor sequence played (issue 18); the bundled data adds the lamp scene and the
    // room's live display (issue 17). Without a GPU adapter a frame says so, which only a
    // machine outside CI may lack.
    let viewer = sections.iter().find(|s| s["id"] == "viewer").unwrap();
    let frames = viewer["data"].as_array().unwrap();
    let shown: Vec<&str> = frames.iter().filter_map(|f| f["scene"].as_str()).collect();
    let rendered = summary["renders"].as_array().unwrap();
    assert_eq!(rendered.len(), scene_count);
    for r in rendered {
        let name = r["name"].as_str().unwrap();
        assert!(
            shown.contains(&name),
            "no viewer frame of {name}: {shown:?}"
        );
    }
    assert_eq!(shown.len(), frames.len(), "every frame names its scene");
    let sequence = frames
        .iter()
        .find(|f| f["scene"] == "outdoor-courtyard")
        .unwrap_or_else(|| panic!("no viewer frame of the outdoor sequence: {shown:?}"));
    if let Some(played) = sequence["summary"]["sequence"]["frames"].as_array() {
        assert_eq!(played.len(), 3, "the demo plays three sequence frames");
    }
    for f in frames {
        if let Some(png) = f["frame"].as_str() {
            assert!(out_dir.join(png).exists(), "{png}");
            assert!(f["summary"]["statistics"]["fps_median"].as_f64().unwrap() > 0.0);
        } else {
            let error = f["error"].as_str().unwrap();
            assert!(
                !in_ci() && error.contains("no usable GPU adapter"),
                "{}: {error}",
                f["scene"]
            );
        }
    }
    for p in probes {
        for m in p["mappings"].as_array().unwrap() {
            assert!(out_dir.join(m["preview"].as_str().unwrap()).exists());
            if let Some(change) = m["round_trip_power_change_pct"].as_f64() {
                // Round trips through every mapping keep the power to the resampler's quadrature
                // (the demo prints them); 0.5 %, while a lost face or hemisphere would change it by
                // 15 % or more.
                assert!(
                    change.abs() < 0.5,
                    "{} {}: {change} %",
                    p["name"],
                    m["mapping"]
                );
            }
        }
    }
    assert!(
        out_dir
            .join(probe_names[0])
            .join("cube-faces_px.exr")
            .exists()
    );
    // Irradiance maps: exact and SH9, with SH9's error (a few per cent) and the sun's confidence.
    for p in probes {
        let irr = &p["irradiance"];
        assert!(
            out_dir
                .join(irr["exact_preview"].as_str().unwrap())
                .exists()
        );
        assert!(out_dir.join(irr["sh9_preview"].as_str().unwrap()).exists());
        let err = irr["sh9_mean_err_pct"].as_f64().unwrap();
        assert!(err > 0.1 && err < 10.0, "{}: {err}", p["name"]);
    }
    let sky = probes.iter().find(|p| p["name"] == "sky").unwrap();
    assert!(sky["irradiance"]["sun_confidence"].as_f64().unwrap() > 0.5);

    // The example scenes: every image written, light and hybrid renders scored, and in the study
    // every method's light renders closer to the reference at N = 256 than at N = 1 (falling to
    // within a few times the reference's own noise).
    assert!(out_dir.join("renders/report.md").exists());
    let renders = summary["renders"].as_array().unwrap();
    assert_eq!(renders.len(), scene_count);
    for r in renders {
        for image in r["images"].as_array().unwrap() {
            assert!(out_dir.join(image["preview"].as_str().unwrap()).exists());
            assert!(out_dir.join(image["exr"].as_str().unwrap()).exists());
        }
        let scored = r["images"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|i| !i["against_reference"].is_null())
            .count();
        assert_eq!(
            scored, 5,
            "{}: 3 soft-shadow light renders, one hard, and the hybrid",
            r["name"]
        );
        for chart in r["chart"].as_array().unwrap() {
            assert!(out_dir.join(chart.as_str().unwrap()).exists());
        }
        let study = &r["study"];
        let floor = study["noise_floor_relative_mse"].as_f64().unwrap();
        let rows = study["rows"].as_array().unwrap();
        let error = |method: &str, n: u64| {
            rows.iter()
                .find(|row| row["method"] == method && row["n"] == n && row["shadows"] == "soft")
                .and_then(|row| row["relative_mse"].as_f64())
                .unwrap()
        };
        for method in [
            "median-cut",
            "adaptive-median-cut",
            "lightgen",
            "variance-minimization",
            "irradiance-optimization",
        ] {
            let (first, last) = (error(method, 1), error(method, 256));
            // Every method's soft-shadow renders converge towards the reference with N:
            // measured at N = 256, in multiples of the reference's noise floor (bunny-apartment /
            // bunny-sky): median cut 6.3x / 12.8x, adaptive median cut 6.1x / 13.6x, LightGen
            // 5.9x / 15.1x, variance minimisation 6.2x / 14.5x, irradiance optimisation 5.8x /
            // 15.3x; bound 20x. (The reference's noise floor fell twice, raising these multiples
            // by as much, the lights' own errors unchanged: the floor's environment samples from
            // the upper half alone, by 18 % / 13 %, and its control variate with the objects'
            // normal bins, by 23 % / 34 %; docs/RENDERING.md.) Every method gains at least 10x
            // from N = 1 (measured 29x to 510x).
            let floor_bound = 20.0;
            assert!(
                last < first / 10.0 && last < floor_bound * floor,
                "{} {method}: relative MSE {first} at N = 1, {last} at N = 256 (floor {floor})",
                r["name"]
            );
            // The hybrid (the same 16 lights plus the SH ambient through its occlusion rays)
            // is no worse than its lights alone at the scenes' settings. Measured (relative MSE,
            // hybrid over lights): 0.56 to 0.99 for every method on both scenes but irradiance
            // optimisation on bunny-sky, 1.010 (its lights already carry the probe's
            // irradiance, so the rays' 3 bands leave them almost nothing to gain, and they add
            // their noise); bound 1.02. The renders are deterministic (seeded, any thread
            // count), so the figures are these on every machine.
            let hybrid = rows
                .iter()
                .find(|row| {
                    row["mode"] == "hybrid"
                        && row["n"] == 16
                        && row["method"]
                            .as_str()
                            .is_some_and(|m| m.split('+').next() == Some(method))
                })
                .and_then(|row| row["relative_mse"].as_f64())
                .unwrap();
            let lights = error(method, 16);
            assert!(
                hybrid <= 1.02 * lights,
                "{} {method}: the hybrid's relative MSE {hybrid} against its lights' {lights}",
                r["name"]
            );
        }
    }

    // The worked example's room: every file written, converged in at most 5 iterations (issue
    // 16), every surface group with a reflectance in (0, 1), the important patches exported.
    let room = &summary["room"];
    for f in room["files"].as_array().unwrap() {
        assert!(out_dir.join(f.as_str().unwrap()).exists(), "{f}");
    }
    assert!(room["converged"].as_bool().unwrap());
    assert!(room["iterations"].as_u64().unwrap() <= 5);
    for g in room["groups"].as_array().unwrap() {
        if let Some(rho) = g["reflectance"].as_array() {
            for c in rho {
                let c = c.as_f64().unwrap();
                assert!(c > 0.0 && c < 1.0, "{}: {c}", g["name"]);
            }
        }
    }
    let html = std::fs::read_to_string(out_dir.join("index.html")).unwrap();
    assert!(html.contains("id=room") && html.contains("room/rho-panorama.png"));
}

#[test]
fn lights_writes_the_json_light_set_and_conserves_power() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sky.json");
    let o = ibl(&[
        "lights",
        &probe("sky.exr"),
        "-n",
        "16",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(v["format"], "iblkit.lights/1");
    assert_eq!(v["frame"], "gltf");
    assert_eq!(v["method"]["name"], "median-cut");
    assert_eq!(v["probe"]["width"], 512);
    assert_eq!(v["probe"]["sha256"].as_str().unwrap().len(), 64);
    let lights = v["lights"].as_array().unwrap();
    assert_eq!(lights.len(), 16);
    let info = ibl(&["info", &probe("sky.exr"), "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    for c in 0..3 {
        let sum: f64 = lights
            .iter()
            .map(|l| l["irradiance"][c].as_f64().unwrap())
            .sum();
        let power = info["power"][c].as_f64().unwrap();
        // Median cut's lights carry the probe's power per region in f64; the file and `info` print
        // shortest round-trip decimals, so the sums agree to f64 rounding (1e-15); 1e-6 relative.
        assert!(
            (sum - power).abs() / power < 1e-6,
            "channel {c}: {sum} vs {power}"
        );
    }
    // The same set in Blender's axes: ours = (x, z, -y), so blender = (x, -z, y).
    let out_b = dir.path().join("sky-blender.json");
    let o = ibl(&[
        "lights",
        &probe("sky.exr"),
        "-n",
        "16",
        "-o",
        out_b.to_str().unwrap(),
        "--frame",
        "blender",
    ]);
    assert!(o.status.success());
    let b: serde_json::Value = serde_json::from_slice(&std::fs::read(&out_b).unwrap()).unwrap();
    let (d, db) = (&lights[3]["direction"], &b["lights"][3]["direction"]);
    let f = |x: &serde_json::Value| x.as_f64().unwrap();
    // Blender's axes are a signed permutation of ours, exact in f64: the JSON round trip keeps the
    // digits; 1e-12.
    assert!((f(&db[0]) - f(&d[0])).abs() < 1e-12);
    assert!((f(&db[1]) + f(&d[2])).abs() < 1e-12);
    assert!((f(&db[2]) - f(&d[1])).abs() < 1e-12);
}

#[test]
fn lights_rejects_counts_median_cut_cannot_make() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.json");
    let o = ibl(&[
        "lights",
        &probe("sky.exr"),
        "-n",
        "10",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("power of two"));
    let o = ibl(&[
        "lights",
        &probe("sky.exr"),
        "-n",
        "8",
        "-o",
        dir.path().join("x.txt").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
}

#[test]
fn irradiance_csv_is_the_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("e.csv");
    let o = ibl(&[
        "irradiance",
        &probe("night.exr"),
        "--normals",
        "500",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("nx,ny,nz,r,g,b"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 500);
    // Row k holds Fibonacci normal k of CONVENTIONS section 5.
    let k = 123.0f64;
    let y = 1.0 - (2.0 * k + 1.0) / 500.0;
    let a = k * std::f64::consts::PI * (3.0 - 5.0f64.sqrt());
    let r = (1.0 - y * y).sqrt();
    let row = &rows[123];
    // CONVENTIONS section 5's Fibonacci formula in f64, printed with shortest round-trip digits:
    // equal to a few ulps; 1e-12.
    assert!((row[0] - r * a.cos()).abs() < 1e-12 && (row[1] - y).abs() < 1e-12);
    assert!((row[2] - r * a.sin()).abs() < 1e-12);
    assert!(
        rows.iter()
            .all(|r| r[3..].iter().all(|e| e.is_finite() && *e >= 0.0))
    );
    let o = ibl(&[
        "irradiance",
        &probe("night.exr"),
        "--normals",
        "0",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}
