//! End-to-end tests of `ibl render` (`docs/SCENES.md`): a small scene (the bunny on a plane under
//! a copy of `assets/probes/sky.exr`, 48 pixels wide, 2 samples per pixel) in the reference,
//! lights and hybrid modes, the layers, the whole panorama and a light file from `ibl lights`;
//! then bad scene files and options, which must exit with status 2 and a message naming the scene
//! file and the field at fault, never panic, and never write over an input.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{ibl, repo, stderr};
use ibl_core::{Image, Rgb};
use serde_json::Value;

/// The good scene: a 64 x 48 view (40 degrees vertical) of the bunny on a grey plane.
const SCENE: &str = r#"version = 1

[probe]
file = "sky.exr"

[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, -0.75, -1.2]
vertical_fov_deg = 40.0
image_size_px = [64, 48]

[[local]]
name = "ground"
shape = "plane"
center = [0.0, -1.0, 0.0]
size = [10.0, 10.0]
albedo = [0.3, 0.3, 0.3]

[[object]]
name = "bunny"
shape = "mesh"
file = "bunny.glb"
scale = 0.25
translate = [0.0, -0.777, -1.2]
material = { kind = "diffuse", albedo = [0.75, 0.75, 0.75] }

[render]
spp = 2
bounces = 2

[lighting]
spp = 2
"#;

/// A temporary folder holding the probe, the bunny and the scene file.
struct Fixture {
    dir: tempfile::TempDir,
}

impl Fixture {
    fn new() -> Fixture {
        let dir = tempfile::tempdir().unwrap();
        let root = repo();
        std::fs::copy(
            root.join("assets/probes/sky.exr"),
            dir.path().join("sky.exr"),
        )
        .unwrap();
        std::fs::copy(
            root.join("assets/models/bunny.glb"),
            dir.path().join("bunny.glb"),
        )
        .unwrap();
        let fixture = Fixture { dir };
        fixture.write("scene.toml", SCENE.as_bytes());
        fixture
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.path(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    /// `ibl render SCENE -o OUT --width 48 --spp 2 EXTRA...` in this folder.
    fn render(&self, scene: &str, out: &str, extra: &[&str]) -> Output {
        let scene = s(&self.path(scene));
        let out = s(&self.path(out));
        let mut args = vec!["render", &scene, "-o", &out, "--width", "48", "--spp", "2"];
        args.extend_from_slice(extra);
        let o = ibl(&args);
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
        o
    }
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

fn json(o: &Output) -> Value {
    serde_json::from_slice(&o.stdout).unwrap()
}

fn image(path: &Path) -> Image<Rgb> {
    ibl_io::read_image(path).unwrap().image
}

/// The render succeeded; its summary, with the common checks done.
fn summary(o: &Output, mode: &str, size: (u64, u64)) -> Value {
    assert!(o.status.success(), "{}", stderr(o));
    let v = json(o);
    assert_eq!(v["mode"], mode);
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(size.0), Some(size.1))
    );
    // `[render] spp` for the reference, `[lighting] spp` for the lights and hybrid modes: both 2.
    assert_eq!(v["spp"], 2);
    assert!(v["rays"].as_u64().unwrap() > 0, "{v}");
    for out in v["outputs"].as_array().unwrap() {
        assert!(Path::new(out.as_str().unwrap()).is_file(), "{out}");
    }
    v
}

#[test]
fn reference_render_writes_exr_png_and_summary() {
    let f = Fixture::new();
    let o = f.render("scene.toml", "ref.exr", &["--json"]);
    let v = summary(&o, "reference", (48, 36));
    assert!(v["lights"].is_null());
    assert_eq!(v["outputs"].as_array().unwrap().len(), 2);
    // The bunny covers about a tenth of this view.
    let coverage = v["object_coverage"].as_f64().unwrap();
    assert!(coverage > 0.01 && coverage < 0.5, "{coverage}");
    assert!(v["virtual_triangles"].as_u64().unwrap() > 1000);
    assert_eq!(v["real_triangles"], 2);
    let exr = image(&f.path("ref.exr"));
    assert_eq!((exr.width(), exr.height()), (48, 36));
    assert!(
        exr.pixels()
            .iter()
            .all(|p| [p.r, p.g, p.b].iter().all(|c| c.is_finite() && *c >= 0.0))
    );
    let png = image(&f.path("ref.png"));
    assert_eq!((png.width(), png.height()), (48, 36));
    // A PNG output is its own preview: written and listed once.
    let o = f.render("scene.toml", "only.png", &["--json"]);
    let v = summary(&o, "reference", (48, 36));
    assert_eq!(v["outputs"].as_array().unwrap().len(), 1, "{v}");
}

#[test]
fn lights_and_hybrid_modes_render_with_layers() {
    let f = Fixture::new();
    let lights = ["-n", "4", "--method", "median-cut", "--json"];
    let o = f.render(
        "scene.toml",
        "lights.exr",
        &[&["--mode", "lights"][..], &lights].concat(),
    );
    let v = summary(&o, "lights", (48, 36));
    assert_eq!(v["lights"]["count"], 4);
    // Soft shadows are the default (docs/SCENES.md); no ambient in the lights mode.
    assert_eq!(v["lights"]["shadows"], "soft");
    assert!(v["lights"]["ambient"].is_null(), "{v}");

    let o = f.render(
        "scene.toml",
        "hybrid.exr",
        &[&["--mode", "hybrid", "--layers"][..], &lights].concat(),
    );
    let v = summary(&o, "hybrid", (48, 36));
    assert_eq!(v["outputs"].as_array().unwrap().len(), 7);
    // The ambient's bands as the summary reports them: given, read, and the rays per sample.
    let ambient = |v: &Value| {
        let a = &v["lights"]["ambient"];
        (
            a["ambient_bands"].clone(),
            a["ray_bands"].clone(),
            a["occlusion_rays"].clone(),
        )
    };
    // `auto` by default, 3 for these 2 samples of 4 rays (the fewest auto reads); given on the
    // command line, the count and rays given.
    assert_eq!(ambient(&v), ("auto".into(), 3.into(), 4.into()));
    let o = f.render(
        "scene.toml",
        "hybrid9.exr",
        &[
            &["--mode", "hybrid", "--ambient-bands", "9", "--ao-rays", "8"][..],
            &lights,
        ]
        .concat(),
    );
    let v = summary(&o, "hybrid", (48, 36));
    assert_eq!(ambient(&v), ("9".into(), 9.into(), 8.into()));

    for layer in [
        "hybrid-with.exr",
        "hybrid-with.png",
        "hybrid-without.exr",
        "hybrid-without.png",
        "hybrid-alpha.png",
    ] {
        let img = image(&f.path(layer));
        assert_eq!((img.width(), img.height()), (48, 36), "{layer}");
    }
}

#[test]
fn panorama_is_w_by_w_over_2() {
    let f = Fixture::new();
    let o = f.render("scene.toml", "pano.exr", &["--panorama", "--json"]);
    summary(&o, "reference", (48, 24));
    let img = image(&f.path("pano.exr"));
    assert_eq!((img.width(), img.height()), (48, 24));
}

#[test]
fn light_file_from_ibl_lights_is_used() {
    let f = Fixture::new();
    let lights = f.path("lights.json");
    let o = ibl(&[
        "lights",
        &s(&f.path("sky.exr")),
        "-n",
        "4",
        "-o",
        &s(&lights),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = f.render(
        "scene.toml",
        "from-file.exr",
        &["--mode", "lights", "--lights", &s(&lights), "--json"],
    );
    let v = summary(&o, "lights", (48, 36));
    assert_eq!(v["lights"]["count"], 4);
    assert!(
        v["lights"]["source"]
            .as_str()
            .unwrap()
            .ends_with("lights.json"),
        "{v}"
    );
}

/// The scene file `name` holding `bytes` is refused: status 2, a message naming the file and
/// every one of `needles`, and no output written.
fn refused(f: &Fixture, name: &str, bytes: &[u8], needles: &[&str]) {
    f.write(name, bytes);
    let o = f.render(name, "bad.exr", &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    assert!(err.contains(name), "{name}: {err}");
    for needle in needles {
        assert!(err.contains(needle), "{name}: {needle:?} not in {err}");
    }
    assert!(
        !f.path("bad.exr").exists() && !f.path("bad.png").exists(),
        "{name}"
    );
}

#[test]
fn bad_scene_files_exit_2_naming_the_file_and_the_field() {
    let f = Fixture::new();
    let edit = |from: &str, to: &str| {
        assert!(SCENE.contains(from), "{from}");
        SCENE.replacen(from, to, 1).into_bytes()
    };
    refused(
        &f,
        "missing-model.toml",
        &edit("\"bunny.glb\"", "\"no-such.glb\""),
        &["object[0].file", "no-such.glb"],
    );
    refused(
        &f,
        "unknown-field.toml",
        &edit("scale = 0.25", "scale = 0.25\ncolour = 1"),
        &["object[0].colour", "unknown field"],
    );
    refused(
        &f,
        "inline-unknown.toml",
        &edit(
            "kind = \"diffuse\",",
            "kind = \"diffuse\", roughness = 0.5,",
        ),
        &["object[0].material.roughness"],
    );
    // Every triangle has zero area: collinear corners and a repeated corner.
    f.write("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n");
    refused(
        &f,
        "flat.toml",
        &edit("\"bunny.glb\"", "\"flat.obj\""),
        &["object[0]", "flat.obj"],
    );
    refused(
        &f,
        "nan.toml",
        &edit("[0.0, -0.777, -1.2]", "[0.0, nan, -1.2]"),
        &["object[0].translate", "not finite"],
    );
    refused(
        &f,
        "missing-probe.toml",
        &edit("\"sky.exr\"", "\"no-such.exr\""),
        &["probe.file", "no-such.exr"],
    );
    let square = Image::filled(32, 32, Rgb::new(1.0, 1.0, 1.0));
    ibl_io::write_image(
        &f.path("square.exr"),
        &square,
        &ibl_io::WriteOptions::default(),
    )
    .unwrap();
    refused(
        &f,
        "square-probe.toml",
        &edit("\"sky.exr\"", "\"square.exr\""),
        &["probe.file", "2:1"],
    );
    let bunny = std::fs::read(f.path("bunny.glb")).unwrap();
    f.write("truncated.glb", &bunny[..bunny.len() / 3]);
    refused(
        &f,
        "truncated-glb.toml",
        &edit("\"bunny.glb\"", "\"truncated.glb\""),
        &["object[0].file", "truncated.glb"],
    );
    refused(&f, "spp.toml", &edit("spp = 2", "spp = 0"), &["render.spp"]);
    // Bytes that are not text, and text that is not TOML.
    let noise: Vec<u8> = (0..3000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    refused(&f, "noise.toml", &noise, &["UTF-8"]);
    refused(
        &f,
        "not-toml.toml",
        b"version = 1\n[probe\nfile = 3\n",
        &["toml", "line 2"],
    );
    refused(&f, "empty.toml", b"", &["missing field"]);
}

#[test]
fn bad_options_exit_2() {
    let f = Fixture::new();
    for (extra, needle) in [
        (
            &["--mode", "lights", "--method", "no-such-method"][..],
            "no-such-method",
        ),
        (
            &["--mode", "lights", "-n", "3", "--method", "median-cut"][..],
            "3 lights",
        ),
        (&["--mode", "hybrid", "-n", "0"][..], "0 lights"),
        (&["--bounces", "0"][..], "--bounces"),
        (&["--panorama", "--mode", "bogus"][..], "bogus"),
        (
            &["--mode", "hybrid", "--ambient-bands", "17"][..],
            "--ambient-bands",
        ),
        (&["--mode", "hybrid", "--ambient-bands", "most"][..], "auto"),
        (&["--mode", "hybrid", "--ao-rays", "0"][..], "--ao-rays 0"),
    ] {
        let o = f.render("scene.toml", "bad.exr", extra);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!f.path("bad.exr").exists(), "{extra:?}");
    }
}

#[test]
fn an_unwritable_output_format_is_refused_before_rendering() {
    let f = Fixture::new();
    // 512 x 384 at 128 spp takes about a minute and a half on two cores (16 spp: 12 s); the
    // refusal must come at once.
    let started = std::time::Instant::now();
    let o = ibl(&[
        "render",
        &s(&f.path("scene.toml")),
        "-o",
        &s(&f.path("out.xyz")),
        "--width",
        "512",
        "--spp",
        "128",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("out.xyz") && err.contains("format"), "{err}");
    assert!(
        started.elapsed().as_secs_f64() < 10.0,
        "{:?}",
        started.elapsed()
    );
    assert!(!f.path("out.png").exists());
}

#[test]
fn a_missing_light_file_named_by_the_scene_names_the_field() {
    let f = Fixture::new();
    let text = format!("{SCENE}lights_file = \"no-such-lights.json\"\n");
    f.write("lights-file.toml", text.as_bytes());
    let o = f.render("lights-file.toml", "l.exr", &["--mode", "lights"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for needle in [
        "lights-file.toml",
        "lighting.lights_file",
        "no-such-lights.json",
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
}

#[test]
fn outputs_never_overwrite_an_input() {
    let f = Fixture::new();
    let probe_before = std::fs::read(f.path("sky.exr")).unwrap();
    let scene_before = std::fs::read(f.path("scene.toml")).unwrap();
    // The output itself, its PNG preview (a probe `x.png` under `-o x.exr`), or a layer.
    std::fs::copy(f.path("sky.exr"), f.path("view-with.exr")).unwrap();
    let png = Image::filled(64, 32, Rgb::new(0.5, 0.5, 0.5));
    ibl_io::write_image(&f.path("ldr.png"), &png, &ibl_io::WriteOptions::default()).unwrap();
    let png_before = std::fs::read(f.path("ldr.png")).unwrap();
    f.write(
        "ldr.toml",
        SCENE.replacen("\"sky.exr\"", "\"ldr.png\"", 1).as_bytes(),
    );
    f.write(
        "layer.toml",
        SCENE
            .replacen("\"sky.exr\"", "\"view-with.exr\"", 1)
            .as_bytes(),
    );
    for (scene, out, extra, needle) in [
        ("scene.toml", "sky.exr", &[][..], "input"),
        // Not an image format, so refused before it could be compared with the inputs.
        ("scene.toml", "scene.toml", &[][..], "format"),
        ("ldr.toml", "ldr.exr", &[][..], "input"),
        ("layer.toml", "view.exr", &["--layers"][..], "input"),
    ] {
        let o = f.render(scene, out, extra);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{out}: {err}");
        assert!(err.contains(needle), "{out}: {err}");
    }
    // The same file under another spelling of its path.
    let sub = f.path("sub");
    std::fs::create_dir(&sub).unwrap();
    let o = ibl(&[
        "render",
        &s(&f.path("scene.toml")),
        "-o",
        &s(&sub.join("../sky.exr")),
        "--width",
        "48",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read(f.path("sky.exr")).unwrap(), probe_before);
    assert_eq!(std::fs::read(f.path("scene.toml")).unwrap(), scene_before);
    assert_eq!(std::fs::read(f.path("ldr.png")).unwrap(), png_before);
    assert!(!f.path("ldr.exr").exists() && !f.path("view.exr").exists());
}

/// A photograph background: the scene of the other tests seen through a pinhole camera whose
/// intrinsics are in pixels of a 48 x 36 photo (an EXR written here).
const PHOTO_SCENE: &str = r#"version = 1

[probe]
file = "sky.exr"

[background]
kind = "photo"
file = "photo.exr"

[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, -0.75, -1.2]
focal_length_px = [66.0, 66.0]
principal_point_px = [24.0, 18.0]

[[local]]
shape = "plane"
center = [0.0, -1.0, 0.0]
size = [10.0, 10.0]
albedo = [0.3, 0.3, 0.3]

OBJECTS

[render]
spp = 2
bounces = 2
"#;

#[test]
fn a_photo_background_composites_back_to_the_photo_when_empty() {
    let f = Fixture::new();
    // A photo with a distinct value in every pixel and channel.
    let photo = Image::from_fn_par(48, 36, |x, y| {
        Rgb::new(
            0.1 + x as f32 / 97.0,
            0.2 + y as f32 / 53.0,
            0.05 + (x * y) as f32 / 3001.0,
        )
    });
    ibl_io::write_image(&f.path("photo.exr"), &photo, &Default::default()).unwrap();
    f.write("empty.toml", PHOTO_SCENE.replace("OBJECTS", "").as_bytes());
    let o = ibl(&[
        "render",
        &s(&f.path("empty.toml")),
        "-o",
        &s(&f.path("empty.exr")),
        "--spp",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = image(&f.path("empty.exr"));
    assert_eq!((out.width(), out.height()), (48, 36));
    for (a, b) in out.pixels().iter().zip(photo.pixels()) {
        for c in 0..3 {
            assert_eq!(
                a[c].to_bits(),
                b[c].to_bits(),
                "empty scene must return the photo"
            );
        }
    }
    // With the bunny: its pixels change, the photo's corners (far from it and its shadow) do not.
    let bunny = "[[object]]\nshape = \"mesh\"\nfile = \"bunny.glb\"\nscale = 0.25\n\
                 translate = [0.0, -0.777, -1.2]\n";
    f.write(
        "bunny.toml",
        PHOTO_SCENE.replace("OBJECTS", bunny).as_bytes(),
    );
    let o = ibl(&[
        "render",
        &s(&f.path("bunny.toml")),
        "-o",
        &s(&f.path("bunny.exr")),
        "--mode",
        "lights",
        "-n",
        "4",
        "--spp",
        "2",
        "--json",
    ]);
    let v = summary(&o, "lights", (48, 36));
    assert!(v["object_coverage"].as_f64().unwrap() > 0.01);
    let out = image(&f.path("bunny.exr"));
    let changed = out
        .pixels()
        .iter()
        .zip(photo.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(changed > 20, "{changed} pixels changed");
    assert_eq!(out.get(0, 0), photo.get(0, 0));
    assert_eq!(out.get(47, 0), photo.get(47, 0));
}

/// Mean luminance of an image.
fn mean_luminance(img: &Image<Rgb>) -> f64 {
    let n = (img.width() * img.height()) as f64;
    img.pixels()
        .iter()
        .map(|p| f64::from(p.luminance()))
        .sum::<f64>()
        / n
}

/// The umbrella IES downlight (the bundled photometry) hung 0.4 m over the ground beside the
/// bunny, aimed down, its peak 20 probe units per sr.
const LUMINAIRE: &str = r#"
[[luminaire]]
file = "umbrella.ies"
position = [0.35, -0.6, -1.2]
peak_intensity = 20.0
"#;

#[test]
fn a_scene_luminaire_lights_the_view_in_every_mode() {
    let f = Fixture::new();
    std::fs::copy(
        repo().join("assets/photometry/ies/umbrella.ies"),
        f.path("umbrella.ies"),
    )
    .unwrap();
    f.write("lamp.toml", format!("{SCENE}{LUMINAIRE}").as_bytes());
    for mode in ["reference", "lights", "hybrid"] {
        let extra = ["--mode", mode, "-n", "4", "--json"];
        let without = format!("{mode}-without-lamp.exr");
        let with = format!("{mode}-with-lamp.exr");
        summary(&f.render("scene.toml", &without, &extra), mode, (48, 36));
        summary(&f.render("lamp.toml", &with, &extra), mode, (48, 36));
        let (dark, lit) = (
            mean_luminance(&image(&f.path(&without))),
            mean_luminance(&image(&f.path(&with))),
        );
        // The lamp's pool on the ground and the bunny's lit side: far brighter than the sky
        // alone gives (about 1.4x over the whole frame in each mode; the sky is unchanged).
        assert!(
            lit > 1.15 * dark,
            "{mode}: {lit} with the lamp, {dark} without"
        );
    }
}

#[test]
fn a_bad_luminaire_is_refused_with_status_2_naming_the_field() {
    let f = Fixture::new();
    let cases = [
        ("missing.toml", LUMINAIRE.to_string(), "luminaire[0].file"),
        (
            "both.toml",
            LUMINAIRE.replace(
                "peak_intensity = 20.0",
                "peak_intensity = 20.0\nnits_per_unit = 1.0",
            ),
            "luminaire[0]",
        ),
        (
            "black.toml",
            LUMINAIRE.replace(
                "peak_intensity = 20.0",
                "peak_intensity = 20.0\ncolour = [0, 0, 0]",
            ),
            "luminaire[0].colour",
        ),
        (
            "unknown.toml",
            LUMINAIRE.replace("peak_intensity = 20.0", "brightness = 20.0"),
            "brightness",
        ),
    ];
    for (name, table, needle) in cases {
        f.write(name, format!("{SCENE}{table}").as_bytes());
        let o = f.render(name, "out.exr", &["--mode", "lights"]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(
            err.contains(name) && err.contains(needle),
            "{needle:?} not in {err}"
        );
        assert!(!f.path("out.exr").exists(), "{name}: nothing is written");
    }
}
