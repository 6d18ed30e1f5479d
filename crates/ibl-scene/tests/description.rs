//! The scene file format (`docs/SCENES.md`): the bundled examples parse and validate, every
//! validation rule names its field by path (`object[1].scale`, `camera.up`, ...) with a readable
//! message, the transform is `T R S` with `R = Ry Rx Rz`, and mutated files never panic.

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::PathBuf;

use glam::Vec3;
use ibl_scene::description::{
    CompositeRule, GroupKind, MaterialKind, RectangleDescription, ShapeKind,
};
use ibl_scene::{DescriptionError, RenderMode, SceneDescription};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn example(name: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/scenes")
        .join(name);
    std::fs::read_to_string(&path).unwrap()
}

/// The smallest valid scene: a probe, two virtual spheres.
const BASE: &str = r#"version = 1

[probe]
file = "p.exr"

[[object]]
shape = "sphere"
radius = 0.5

[[object]]
shape = "sphere"
radius = 0.25
translate = [1.0, 0.0, -2.0]
"#;

/// A `[camera]` viewing the panorama, before any field of the case at hand.
const CAMERA: &str = r#"
[camera]
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, -1.0]
"#;

/// The error `text` gives; fails when it parses.
fn error_of(text: &str) -> DescriptionError {
    match SceneDescription::from_toml(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

/// `text` is refused with the error at `field`, a message containing `phrase`, and a readable
/// `field: problem` line (one line, no Rust debug syntax, not too long).
fn refused(text: &str, field: &str, phrase: &str) {
    let e = error_of(text);
    assert_eq!(e.field, field, "{e}\nin:\n{text}");
    assert!(
        e.problem.contains(phrase),
        "{field}: {:?} lacks {phrase:?}",
        e.problem
    );
    let line = e.to_string();
    assert!(line.starts_with(&format!("{field}: ")), "{line}");
    assert!(!line.contains('\n') && line.len() < 400, "{line}");
    assert!(!line.contains("Some(") && !line.contains("None"), "{line}");
}

#[test]
fn bundled_examples_parse_and_validate() {
    for name in ["bunny-sky.toml", "bunny-apartment.toml"] {
        let d = SceneDescription::from_toml(&example(name)).unwrap();
        d.validate().unwrap();
        assert_eq!(d.version, 1, "{name}");
        assert_eq!(d.render.mode, RenderMode::Reference, "{name}");
        assert_eq!((d.local.len(), d.object.len()), (1, 1), "{name}");
        assert_eq!(d.local[0].shape, ShapeKind::Plane, "{name}");
        assert_eq!(d.object[0].shape, ShapeKind::Mesh, "{name}");
        let m = d.object[0].material.as_ref().unwrap();
        assert_eq!(m.kind, MaterialKind::Diffuse, "{name}");
        assert_eq!(d.camera.as_ref().unwrap().image_size_px, Some([640, 480]));
    }
    let sky = SceneDescription::from_toml(&example("bunny-sky.toml")).unwrap();
    assert_eq!(sky.render.composite, CompositeRule::Ratio);
}

#[test]
fn the_example_in_the_user_documentation_parses() {
    let doc = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/SCENES.md"),
    )
    .unwrap();
    let start = doc.find("```toml\n").unwrap() + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let d = SceneDescription::from_toml(&doc[start..end]).unwrap();
    // It is the bundled example, shortened: the same values.
    let bundled = SceneDescription::from_toml(&example("bunny-sky.toml")).unwrap();
    assert_eq!(d, bundled);
}

#[test]
fn defaults_fill_what_is_left_out() {
    let d = SceneDescription::from_toml(BASE).unwrap();
    assert_eq!(d.probe.radiance_scale, 1.0);
    assert_eq!(d.probe.rotation_deg, [0.0; 3]);
    assert_eq!(d.probe.position, [0.0; 3]);
    assert!(d.camera.is_none() && d.local.is_empty());
    assert_eq!(d.render.mode, RenderMode::Reference);
    assert_eq!((d.render.spp, d.render.bounces, d.render.seed), (64, 4, 1));
    assert_eq!(d.render.width, None);
    assert_eq!(d.render.composite, CompositeRule::Difference);
    let l = &d.lighting;
    assert_eq!((l.method.name(), l.lights), ("median-cut", 16));
    assert_eq!(
        (l.ambient_bands, l.ao_samples, l.spp),
        (ibl_scene::AmbientBands::Auto, 4, 4)
    );
    assert_eq!(l.shadows, ibl_scene::ShadowKind::Soft);
    assert_eq!(d.render.sampler, ibl_scene::SamplerKind::Sobol);
    assert!(l.lights_file.is_none());
}

#[test]
fn ambient_bands_are_auto_or_a_count() {
    use ibl_scene::AmbientBands;
    let bands = |value: &str| {
        SceneDescription::from_toml(&format!("{BASE}[lighting]\nambient_bands = {value}\n"))
            .unwrap()
            .lighting
            .ambient_bands
    };
    assert_eq!(bands("\"auto\""), AmbientBands::Auto);
    assert_eq!(bands("\"AUTO\""), AmbientBands::Auto);
    assert_eq!(bands("5"), AmbientBands::Fixed(5));
    // Auto: one band more each time a pixel's rays (samples x occlusion rays) double, from 3
    // at 16 rays (the scenes' 4 samples of 4 rays) to 7 at 256 and beyond.
    for (spp, rays, expected) in [
        (1, 1, 3),
        (4, 4, 3),
        (8, 4, 4),
        (16, 4, 5),
        (32, 4, 6),
        (64, 4, 7),
        (4, 64, 7),
        (1024, 4, 7),
        (u32::MAX, u32::MAX, 7),
        (0, 0, 3),
    ] {
        assert_eq!(
            AmbientBands::Auto.resolve(spp, rays),
            expected,
            "{spp} spp x {rays} rays"
        );
    }
    assert_eq!(AmbientBands::Fixed(9).resolve(4, 4), 9);
    assert_eq!("auto".parse(), Ok(AmbientBands::Auto));
    assert_eq!(" 12 ".parse(), Ok(AmbientBands::Fixed(12)));
    assert!("0".parse::<AmbientBands>().is_err() && "17".parse::<AmbientBands>().is_err());
    assert_eq!(
        (AmbientBands::Auto.name(), AmbientBands::Fixed(3).name()),
        ("auto".into(), "3".into())
    );
}

#[test]
fn transform_is_scale_then_yaw_pitch_roll_then_translate() {
    // CONVENTIONS section 1: yaw +90 takes -Z to -X, pitch +90 takes -Z to +Y.
    let text = format!("{BASE}scale = 2.0\nrotate_deg = [90.0, 0.0, 0.0]\n");
    let d =
        SceneDescription::from_toml(&text.replace("translate = [1.0, 0.0, -2.0]\n", "")).unwrap();
    let m = d.object[1].world_from_model();
    let p = m.transform_point3(Vec3::new(0.0, 0.0, -1.0));
    // Scale 2 then yaw 90 degrees in f32: sin/cos of pi/2 round to 1e-8, times 2; 1e-5.
    assert!(p.distance(Vec3::new(-2.0, 0.0, 0.0)) < 1e-5, "{p}");

    let text = format!("{BASE}scale = [1.0, 3.0, 1.0]\nrotate_deg = [0.0, 90.0, 0.0]\n");
    let d = SceneDescription::from_toml(&text).unwrap();
    let m = d.object[1].world_from_model();
    // (0, 1, -1) -> scale (0, 3, -1) -> pitch +90 about +X (y, z) -> (-z, y): (0, 1, 3)
    // -> translate (1, 0, -2): (1, 1, 1).
    let p = m.transform_point3(Vec3::new(0.0, 1.0, -1.0));
    assert!(p.distance(Vec3::new(1.0, 1.0, 1.0)) < 1e-5, "{p}");

    // Yaw, then pitch, then roll applied right to left: Ry(90) Rx(90) Rz(90) on +X.
    // Rz(90): +X -> +Y; Rx(90): +Y -> +Z; Ry(90): +Z -> +X.
    let text = format!("{BASE}rotate_deg = [90.0, 90.0, 90.0]\n");
    let d =
        SceneDescription::from_toml(&text.replace("translate = [1.0, 0.0, -2.0]\n", "")).unwrap();
    let p = d.object[1].world_from_model().transform_vector3(Vec3::X);
    // Pitch then roll in f32 (quaternions of degrees): a few f32 roundings of unit vectors (1e-7);
    // 1e-5.
    assert!(p.distance(Vec3::X) < 1e-5, "{p}");
}

#[test]
fn unknown_fields_are_named_where_they_are() {
    refused(
        &format!("colour = 1\n{BASE}"),
        "colour",
        "unknown field `colour`",
    );
    // Appended to BASE, a key lands in the second `[[object]]`.
    refused(
        &format!("{BASE}colour = 1\n"),
        "object[1].colour",
        "unknown field",
    );
    refused(
        &format!("{BASE}[object.material]\nkind = \"diffuse\"\nshine = 3\n"),
        "object[1].material.shine",
        "unknown field `shine`",
    );
    let first_inline = BASE.replacen(
        "radius = 0.5\n",
        "radius = 0.5\nmaterial = { kind = \"glossy\", shine = 3.0 }\n",
        1,
    );
    refused(
        &first_inline,
        "object[0].material.shine",
        "unknown field `shine`",
    );
    refused(
        &format!("{BASE}[render]\nspp = 4\nsamples = 4\n"),
        "render.samples",
        "expected one of",
    );
    refused(
        &format!("{BASE}{CAMERA}fov = 40\n"),
        "camera.fov",
        "unknown field",
    );
    refused(
        "version = 1\n[probe]\nfile = \"p.exr\"\nrotation = [0, 0, 0]\n",
        "probe.rotation",
        "rotation_deg",
    );
}

#[test]
fn missing_and_mistyped_fields_are_named() {
    refused("version = 1\n", "probe", "missing field `probe`");
    refused(
        &format!("{BASE}[[object]]\nradius = 1.0\n"),
        "object[2].shape",
        "missing",
    );
    refused(
        &format!("{BASE}material = {{ albedo = [0.5, 0.5, 0.5] }}\n"),
        "object[1].material.kind",
        "missing field `kind`",
    );
    refused(
        &format!("{BASE}scale = \"big\"\n"),
        "object[1].scale",
        "Scale",
    );
    refused(
        &format!("{BASE}rotate_deg = [1.0, 2.0]\n"),
        "object[1].rotate_deg",
        "length",
    );
    refused(&format!("{BASE}[render]\nspp = -1\n"), "render.spp", "-1");
    refused(
        &format!("{BASE}[render]\nmode = \"fast\"\n"),
        "render.mode",
        "`fast`",
    );
    refused(
        &format!("{BASE}[[object]]\nshape = \"cone\"\n"),
        "object[2].shape",
        "`cone`",
    );
    // A document that is not TOML at all.
    refused("version = 1\n[probe\n", "toml", "line 2");
    refused("version = = 1", "toml", "line 1");
}

#[test]
fn every_validation_rule_names_its_field() {
    refused(
        &BASE.replace("version = 1", "version = 2"),
        "version",
        "version 2",
    );
    refused(
        &format!("{BASE}rotate_deg = [0.0, nan, 0.0]\n"),
        "object[1].rotate_deg",
        "not finite",
    );
    refused(
        &BASE.replace("[1.0, 0.0, -2.0]", "[nan, 0.0, -2.0]"),
        "object[1].translate",
        "not finite",
    );
    refused(
        &format!("{BASE}scale = 0.0\n"),
        "object[1].scale",
        "non-zero",
    );
    refused(
        &format!("{BASE}scale = [1.0, 0.0, 1.0]\n"),
        "object[1].scale[1]",
        "non-zero",
    );
    refused(
        &format!("{BASE}[[local]]\nshape = \"plane\"\nalbedo = [0.5, 0.5, 0.5]\n"),
        "local[0].size",
        "shape \"plane\" needs it",
    );
    refused(
        &format!("{BASE}[[local]]\nshape = \"plane\"\nsize = [1.0, 0.0]\n"),
        "local[0].size[1]",
        "positive",
    );
    refused(
        &format!("{BASE}file = \"ball.glb\"\n"),
        "object[1].file",
        "does not apply",
    );
    refused(
        &format!("{BASE}[[object]]\nshape = \"mesh\"\n"),
        "object[2].file",
        "needs it",
    );
    refused(
        &format!("{BASE}[[object]]\nshape = \"sphere\"\nradius = -1.0\n"),
        "object[2].radius",
        "positive",
    );
    refused(
        &format!("{BASE}[[local]]\nshape = \"box\"\nmin = [0, 0, 0]\nmax = [1, 0, 1]\n"),
        "local[0].max",
        "exceed min",
    );
    refused(
        &format!("{BASE}[[local]]\nshape = \"plane\"\nsize = [1, 1]\nalbedo = [0.5, 1.2, 0.5]\n"),
        "local[0].albedo",
        "[0, 1]",
    );
    refused(
        &format!("{BASE}material = {{ kind = \"diffuse\", albedo = [1.5, 0.5, 0.5] }}\n"),
        "object[1].material.albedo",
        "[0, 1]",
    );
    refused(
        &format!(
            "{BASE}material = {{ kind = \"glossy\", albedo = [0.8, 0.5, 0.5], specular = [0.3, 0.3, 0.3] }}\n"
        ),
        "object[1].material",
        "albedo + specular exceeds 1",
    );
    refused(
        &format!("{BASE}material = {{ kind = \"glossy\", exponent = 0.5 }}\n"),
        "object[1].material.exponent",
        "[1, 100000]",
    );
    refused(
        &format!("{BASE}material = {{ kind = \"mirror\", albedo = [0.5, 0.5, 0.5] }}\n"),
        "object[1].material",
        "mirror",
    );
    refused(
        &format!(
            "{BASE}[[local]]\nshape = \"plane\"\nsize = [1, 1]\nmaterial = {{ kind = \"diffuse\" }}\n"
        ),
        "local[0].material",
        "real geometry is diffuse",
    );
    refused(
        &format!("{BASE}albedo_by_group = {{ fur = [0.5, 0.5, 0.5] }}\n"),
        "object[1].albedo_by_group",
        "real geometry",
    );
    // Backgrounds and cameras.
    refused(
        &format!("{BASE}[background]\nkind = \"photo\"\nfile = \"photo.png\"\n"),
        "camera",
        "needs a [camera]",
    );
    refused(
        &format!("{BASE}[background]\nkind = \"photo\"\n"),
        "background.file",
        "needs a file",
    );
    refused(
        &format!("{BASE}[background]\nfile = \"photo.png\"\n"),
        "background.file",
        "kind = \"photo\"",
    );
    refused(
        &format!("{BASE}{CAMERA}vertical_fov_deg = 40.0\n"),
        "camera.image_size_px",
        "needs its image size",
    );
    refused(
        &format!(
            "{BASE}{CAMERA}vertical_fov_deg = 40.0\nfocal_length_px = [500.0, 500.0]\nimage_size_px = [64, 48]\n"
        ),
        "camera",
        "not both",
    );
    refused(
        &format!("{BASE}{CAMERA}image_size_px = [64, 48]\n"),
        "camera",
        "needs vertical_fov_deg or focal_length_px",
    );
    refused(
        &format!(
            "{BASE}{}vertical_fov_deg = 40.0\nimage_size_px = [64, 48]\n",
            CAMERA.replace("[0.0, 0.0, -1.0]", "[0.0, 0.0, 0.0]")
        ),
        "camera.look_at",
        "equals camera.position",
    );
    refused(
        &format!(
            "{BASE}{}up = [0.0, 0.0, 2.0]\nvertical_fov_deg = 40.0\nimage_size_px = [64, 48]\n",
            CAMERA
        ),
        "camera.up",
        "parallel",
    );
    refused(
        &format!("{BASE}{CAMERA}vertical_fov_deg = 180.0\nimage_size_px = [64, 48]\n"),
        "camera.vertical_fov_deg",
        "(0, 179)",
    );
    refused(
        &format!(
            "{BASE}[background]\nkind = \"photo\"\nfile = \"p.png\"\n{CAMERA}vertical_fov_deg = 40.0\nimage_size_px = [64, 48]\n"
        ),
        "camera.image_size_px",
        "photograph's own size",
    );
    // Renderer and lighting settings.
    refused(
        &format!("{BASE}[render]\nspp = 0\n"),
        "render.spp",
        "1..=65536",
    );
    refused(
        &format!("{BASE}[render]\nbounces = 0\n"),
        "render.bounces",
        "1..=64",
    );
    refused(
        &format!("{BASE}[render]\nwidth = 1\n"),
        "render.width",
        "2..=16384",
    );
    refused(
        &format!("{BASE}[lighting]\nao_samples = 0\n"),
        "lighting.ao_samples",
        "1..=1024",
    );
    refused(
        &format!("{BASE}[lighting]\nlights = 0\n"),
        "lighting.lights",
        "1..=4096",
    );
    refused(
        &format!("{BASE}[lighting]\nambient_bands = 17\n"),
        "lighting.ambient_bands",
        "1..=16",
    );
    refused(
        &format!("{BASE}[lighting]\nambient_bands = -3\n"),
        "lighting.ambient_bands",
        "1..=16",
    );
    refused(
        &format!("{BASE}[lighting]\nambient_bands = \"seven\"\n"),
        "lighting.ambient_bands",
        "\"auto\" or a band count",
    );
    refused(
        "version = 1\n[probe]\nfile = \"p.exr\"\nradiance_scale = 0.0\n",
        "probe.radiance_scale",
        "positive",
    );
}

#[test]
fn validate_names_the_field_of_a_description_built_in_code() {
    let mut d = SceneDescription::from_toml(BASE).unwrap();
    d.object[1].translate = Some([f32::NAN, 0.0, 0.0]);
    assert_eq!(d.validate().unwrap_err().field, "object[1].translate");
    let mut d = SceneDescription::from_toml(BASE).unwrap();
    d.render.spp = 0;
    assert_eq!(d.validate().unwrap_err().field, "render.spp");
}

/// The characters that change a TOML document's structure, and a few that break tokens.
const SPICE: &[u8] = b"[]{}=\"',.#\n\\ 0123456789-+eEinfa_xyz\t\x7f";

#[test]
fn mutated_scenes_never_panic() {
    let valid = example("bunny-sky.toml");
    let bytes = valid.as_bytes();
    let mut outcomes = [0usize; 2];
    let mut check = |text: &str| {
        // Either a scene that validates, or an error that names some field.
        match SceneDescription::from_toml(text) {
            Ok(d) => {
                d.validate().unwrap();
                outcomes[0] += 1;
            }
            Err(e) => {
                assert!(!e.field.is_empty() && !e.problem.is_empty(), "{e:?}");
                outcomes[1] += 1;
            }
        }
    };
    // Every 7th prefix (the file is ASCII, so every prefix is text).
    for end in (0..=bytes.len()).step_by(7) {
        check(std::str::from_utf8(&bytes[..end]).unwrap());
    }
    // A few bytes replaced, deterministically.
    let mut rng = Pcg64::seed_from_u64(7);
    for _ in 0..600 {
        let mut mutated = bytes.to_vec();
        for _ in 0..rng.random_range(1..=4) {
            let at = rng.random_range(0..mutated.len());
            mutated[at] = if rng.random_bool(0.7) {
                SPICE[rng.random_range(0..SPICE.len())]
            } else {
                rng.random_range(0..0x80)
            };
        }
        check(std::str::from_utf8(&mutated).unwrap());
    }
    // Pure noise.
    for _ in 0..200 {
        let len = rng.random_range(0..200);
        let noise: String = (0..len)
            .map(|_| char::from(SPICE[rng.random_range(0..SPICE.len())]))
            .collect();
        check(&noise);
    }
    // Most mutations break the file, some (inside comments) do not.
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
}

/// An outdoor scene (`[outdoor]`, Jensen, Andersen & Madsen 2006): the probe taken once, the
/// model of the courtyard, the video camera, a representative frame and the whole table.
const OUTDOOR: &str = r#"version = 1

[probe]
file = "probe.exr"
position = [0.0, 1.5, 0.0]

[background]
kind = "photo"
file = "frames/0000.png"

[camera]
position = [0.0, 1.6, 4.0]
look_at = [0.0, 0.5, 0.0]
vertical_fov_deg = 50.0

[[local]]
name = "ground"
shape = "plane"
size = [40.0, 40.0]

[[object]]
shape = "sphere"
radius = 0.5

[outdoor]
latitude_deg = 57.048
longitude_deg = 9.921
elevation_m = 5.0
utc_offset_hours = 2.0
north = [1.0, 0.0, -1.0]
pressure_mbar = 1000.0
temperature_c = 9.5
probe_time = 2024-04-20T09:30:00
mask = "mask.png"
samples = 800
smoothing = true
volume_spacing_m = 2.0

[outdoor.frames]
source = "frames"
start = 2024-04-20T11:00:00.5
interval_s = 1800.0
"#;

#[test]
fn a_full_outdoor_table_parses() {
    let d = SceneDescription::from_toml(OUTDOOR).unwrap();
    let o = d.outdoor.as_ref().unwrap();
    assert_eq!((o.latitude_deg, o.longitude_deg), (57.048, 9.921));
    assert_eq!((o.elevation_m, o.utc_offset_hours), (5.0, 2.0));
    assert_eq!((o.pressure_mbar, o.temperature_c), (1000.0, 9.5));
    assert_eq!(o.north, [1.0, 0.0, -1.0]);
    let n = o.north_unit();
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert!((n - Vec3::new(h, 0.0, -h)).length() < 1e-6, "{n}");
    assert_eq!(o.probe_local_time().unwrap(), (2024, 4, 20, 9, 30, 0.0));
    assert_eq!(o.mask, PathBuf::from("mask.png"));
    assert_eq!(
        (o.samples, o.smoothing, o.volume_spacing_m),
        (800, true, Some(2.0))
    );
    assert_eq!(o.frames.source, PathBuf::from("frames"));
    assert_eq!(
        o.frames.start_local_time().unwrap(),
        (2024, 4, 20, 11, 0, 0.5)
    );
    assert_eq!(o.frames.interval_s, 1800.0);
    // The rest is an ordinary scene.
    assert_eq!(d.local.len(), 1);
    assert!(d.camera.is_some());
    // A scene without the table has none.
    assert!(SceneDescription::from_toml(BASE).unwrap().outdoor.is_none());
}

#[test]
fn outdoor_defaults_fill_what_is_left_out() {
    let mut text = OUTDOOR.to_string();
    for line in [
        "elevation_m = 5.0\n",
        "north = [1.0, 0.0, -1.0]\n",
        "pressure_mbar = 1000.0\n",
        "temperature_c = 9.5\n",
        "samples = 800\n",
        "smoothing = true\n",
        "volume_spacing_m = 2.0\n",
    ] {
        text = text.replace(line, "");
    }
    let d = SceneDescription::from_toml(&text).unwrap();
    let o = d.outdoor.unwrap();
    assert_eq!(o.elevation_m, 0.0);
    assert_eq!(o.north, ibl_scene::description::DEFAULT_NORTH);
    assert_eq!(o.north_unit(), Vec3::NEG_Z);
    assert_eq!((o.pressure_mbar, o.temperature_c), (1013.25, 12.0));
    assert_eq!(
        (o.samples, o.smoothing, o.volume_spacing_m),
        (500, false, None)
    );
}

#[test]
fn every_outdoor_rule_names_its_field() {
    let bad = |from: &str, to: &str, field: &str, phrase: &str| {
        assert!(OUTDOOR.contains(from), "{from}");
        refused(&OUTDOOR.replacen(from, to, 1), field, phrase);
    };
    bad(
        "latitude_deg = 57.048",
        "latitude_deg = 91.0",
        "outdoor.latitude_deg",
        "[-90, 90]",
    );
    bad(
        "longitude_deg = 9.921",
        "longitude_deg = -180.5",
        "outdoor.longitude_deg",
        "[-180, 180]",
    );
    bad(
        "elevation_m = 5.0",
        "elevation_m = nan",
        "outdoor.elevation_m",
        "not in",
    );
    bad(
        "utc_offset_hours = 2.0",
        "utc_offset_hours = 15.0",
        "outdoor.utc_offset_hours",
        "[-14, 14]",
    );
    for north in ["[0.0, 0.0, 0.0]", "[0.0, 1.0, -1.0]", "[inf, 0.0, -1.0]"] {
        bad(
            "north = [1.0, 0.0, -1.0]",
            &format!("north = {north}"),
            "outdoor.north",
            "",
        );
    }
    bad(
        "north = [1.0, 0.0, -1.0]",
        "north = [0.0, 0.1, -1.0]",
        "outdoor.north",
        "off the horizontal",
    );
    bad(
        "north = [1.0, 0.0, -1.0]",
        "north = [0.0, 0.0, 0.0]",
        "outdoor.north",
        "zero",
    );
    bad(
        "pressure_mbar = 1000.0",
        "pressure_mbar = 0.0",
        "outdoor.pressure_mbar",
        "(0, 2000]",
    );
    bad(
        "temperature_c = 9.5",
        "temperature_c = 61.0",
        "outdoor.temperature_c",
        "[-90, 60]",
    );
    bad(
        "probe_time = 2024-04-20T09:30:00",
        "probe_time = 2024-04-20T09:30:00+02:00",
        "outdoor.probe_time",
        "UTC offset",
    );
    bad(
        "probe_time = 2024-04-20T09:30:00",
        "probe_time = 2024-04-20",
        "outdoor.probe_time",
        "not a date and a time",
    );
    bad(
        "probe_time = 2024-04-20T09:30:00",
        "probe_time = \"2024-04-20T09:30:00\"",
        "outdoor.probe_time",
        "datetime",
    );
    bad(
        "mask = \"mask.png\"",
        "mask = \"\"",
        "outdoor.mask",
        "empty",
    );
    bad(
        "samples = 800",
        "samples = 0",
        "outdoor.samples",
        "1..=100000",
    );
    bad(
        "samples = 800",
        "samples = 100001",
        "outdoor.samples",
        "1..=100000",
    );
    bad(
        "volume_spacing_m = 2.0",
        "volume_spacing_m = -1.0",
        "outdoor.volume_spacing_m",
        "positive",
    );
    bad(
        "start = 2024-04-20T11:00:00.5",
        "start = 2024-04-20T11:00:00Z",
        "outdoor.frames.start",
        "UTC offset",
    );
    bad(
        "interval_s = 1800.0",
        "interval_s = 0.0",
        "outdoor.frames.interval_s",
        "positive",
    );
    bad(
        "interval_s = 1800.0",
        "interval_s = inf",
        "outdoor.frames.interval_s",
        "positive",
    );
    bad(
        "source = \"frames\"",
        "source = \"\"",
        "outdoor.frames.source",
        "empty",
    );
    // Unknown and missing fields, in either table.
    bad(
        "samples = 800",
        "samples = 800\nfoo = 1",
        "outdoor.foo",
        "unknown field `foo`",
    );
    refused(
        &format!("{OUTDOOR}fps = 25\n"),
        "outdoor.frames.fps",
        "unknown field `fps`",
    );
    bad(
        "latitude_deg = 57.048\n",
        "",
        "outdoor.latitude_deg",
        "missing field",
    );
    bad(
        "interval_s = 1800.0\n",
        "",
        "outdoor.frames.interval_s",
        "missing field",
    );
}

#[test]
fn an_outdoor_scene_needs_a_camera_and_a_photo_background() {
    let start = OUTDOOR.find("[camera]").unwrap();
    let end = OUTDOOR.find("[[local]]").unwrap();
    let no_camera = format!("{}{}", &OUTDOOR[..start], &OUTDOOR[end..]);
    refused(&no_camera, "camera", "[outdoor]");
    // A panorama background (no file) with the camera: refused at the background's kind.
    let panorama = OUTDOOR
        .replace("kind = \"photo\"\n", "")
        .replace("file = \"frames/0000.png\"\n", "");
    refused(&panorama, "background.kind", "photo");
    // Built in code: the same checks, and the table's own.
    let mut d = SceneDescription::from_toml(OUTDOOR).unwrap();
    d.camera = None;
    assert_eq!(d.validate().unwrap_err().field, "camera");
    let mut d = SceneDescription::from_toml(OUTDOOR).unwrap();
    d.outdoor.as_mut().unwrap().frames.interval_s = 0.0;
    assert_eq!(d.validate().unwrap_err().field, "outdoor.frames.interval_s");
}

#[test]
fn the_outdoor_example_in_the_user_documentation_parses() {
    let doc = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/SCENES.md"),
    )
    .unwrap();
    let section = doc.find("## `[outdoor]`").unwrap();
    let start = section + doc[section..].find("```toml\n").unwrap() + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let d = SceneDescription::from_toml(&doc[start..end]).unwrap();
    let o = d.outdoor.unwrap();
    assert_eq!(
        o.frames.start_local_time().unwrap(),
        (2024, 4, 20, 11, 0, 0.0)
    );
}

fn room_file(name: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/rooms")
        .join(name)
        .join("room.toml");
    std::fs::read_to_string(&path).unwrap()
}

#[test]
fn the_bundled_room_files_are_scenes_with_a_room() {
    for name in ["apartment", "synthetic"] {
        let d = SceneDescription::from_toml(&room_file(name)).unwrap();
        let room = d.room.as_ref().unwrap_or_else(|| panic!("{name}: no room"));
        assert!(!room.groups.is_empty() && !room.boxes.is_empty(), "{name}");
        // A room file has no objects: rendered, it is the probe.
        assert!(d.object.is_empty() && d.local.is_empty(), "{name}");
    }
    // The synthetic room's first surface group, as the file gives it.
    let d = SceneDescription::from_toml(&room_file("synthetic")).unwrap();
    let room = d.room.unwrap();
    assert_eq!(room.groups[0].name, "wall");
    assert_eq!(room.groups[0].kind, GroupKind::Surface);
    assert!(room.groups.iter().any(|g| g.kind == GroupKind::Light));
    // Without a `[room]`, a scene has none.
    assert!(SceneDescription::from_toml(BASE).unwrap().room.is_none());
}

#[test]
fn a_bad_room_field_is_refused_naming_it() {
    let text = room_file("synthetic");
    assert!(text.contains("patch_area_m2 = 0.05"));
    refused(
        &text.replace("patch_area_m2 = 0.05", "patch_area_m2 = 0.0"),
        "room.patch_area_m2",
        "is not in",
    );
    refused(
        &text.replace("patch_area_m2 = 0.05", "patch_area_m2 = \"big\""),
        "room.patch_area_m2",
        "invalid type",
    );
    refused(
        &text.replacen("name = \"wall\"", "name = \"floor\"", 1),
        "room.group[1].name",
        "defined twice",
    );
    refused(
        &format!("{BASE}\n[room]\n[[room.group]]\nname = \"wall\"\n"),
        "room",
        "at least one rectangle, box or polygon",
    );
    refused(
        &format!(
            "{BASE}\n[room]\n[[room.group]]\nname = \"wall\"\n[[room.box]]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\ngroup = \"wall\"\nopenings = [{{ face = \"-z\", min = [0.2, 0.2], max = [0.4, 1.5] }}]\n"
        ),
        "room.box[0].openings[0].max",
        "outside the surface",
    );
    // Built in code: the same checks through `SceneDescription::validate`.
    let mut d = SceneDescription::from_toml(&text).unwrap();
    d.room
        .as_mut()
        .unwrap()
        .rectangles
        .push(RectangleDescription {
            name: None,
            group: "walls".into(),
            corner: [0.0; 3],
            edge_u: [1.0, 0.0, 0.0],
            edge_v: [0.0, 1.0, 0.0],
            holes: Vec::new(),
        });
    let e = d.validate().unwrap_err();
    assert_eq!(e.field, "room.rectangle[0].group", "{e}");
    assert!(
        e.problem.contains("no [[room.group]] is named `walls`"),
        "{e}"
    );
}
