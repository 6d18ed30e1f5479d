//! The probe viewer shows a probe the right way round (CONVENTIONS sections 1 and 2): a
//! synthetic probe with coloured marks at known directions, rendered headless, must show forward
//! (-Z) at the centre, +X to the right and +Y up, in the look-around and the lat-long views.

mod common;

use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};
use ibl_viewer::headless::{self, HeadlessOptions};
use ibl_viewer::probe_pass::ProbeProjection;
use ibl_viewer::{ProbeModel, ProbeViewSettings};

/// A dim grey probe with red at forward (-Z), green 30 degrees to the right of it (towards +X)
/// and blue 30 degrees above it (towards +Y), each a disc of 6 degrees.
fn marked_probe() -> Image<Rgb> {
    let (w, h) = (512, 256);
    let grid = LatLong::new(w, h);
    let forward = Vec3::NEG_Z;
    let right = Vec3::new(30f32.to_radians().sin(), 0.0, -30f32.to_radians().cos());
    let up = Vec3::new(0.0, 30f32.to_radians().sin(), -30f32.to_radians().cos());
    let near = |d: Vec3, m: Vec3| d.dot(m) > 6f32.to_radians().cos();
    Image::from_fn_par(w, h, |i, j| {
        let d = grid.pixel_dir(i, j);
        if near(d, forward) {
            Rgb::new(1.0, 0.0, 0.0)
        } else if near(d, right) {
            Rgb::new(0.0, 1.0, 0.0)
        } else if near(d, up) {
            Rgb::new(0.0, 0.0, 1.0)
        } else {
            Rgb::splat(0.05)
        }
    })
}

fn model() -> (tempfile::TempDir, ProbeModel) {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("marked.exr");
    ibl_io::write_image(&path, &marked_probe(), &ibl_io::WriteOptions::default())
        .expect("writes the probe");
    let model = ProbeModel::open(&path, None).expect("reads it back");
    (dir, model)
}

fn dominant(p: &[u8; 3]) -> Option<usize> {
    let max = *p.iter().max()?;
    (max > 100 && p.iter().filter(|&&c| c == max).count() == 1)
        .then(|| p.iter().position(|&c| c == max))
        .flatten()
}

#[test]
fn forward_is_centred_right_is_right_and_up_is_up() {
    let Some(gpu) = common::gpu_or_skip("orientation") else {
        return;
    };
    let (_dir, model) = model();
    let mut settings = ProbeViewSettings::for_probe(&model.latlong);
    settings.overlays.lights = false;
    settings.overlays.dominant = false;
    settings.orbit.vertical_fov = 90f32.to_radians();
    settings.display.exposure_stops = 0.0;
    let options = HeadlessOptions {
        size: (200, 200),
        ..Default::default()
    };
    let run =
        headless::render_probe(&gpu, &model, &settings, &options, &|_, _| {}).expect("renders");
    let picture = &run.images.display;
    // f = 100 px for a 90-degree view of 200 px: 30 degrees off-axis is 100 tan(30) = 57.7 px.
    assert_eq!(
        dominant(picture.get(100, 100)),
        Some(0),
        "forward (-Z) is red at the centre"
    );
    assert_eq!(
        dominant(picture.get(158, 100)),
        Some(1),
        "30 degrees towards +X is right of centre"
    );
    assert_eq!(
        dominant(picture.get(100, 42)),
        Some(2),
        "30 degrees towards +Y is above the centre"
    );
    assert_eq!(
        dominant(picture.get(42, 100)),
        None,
        "nothing is mirrored to the left"
    );

    settings.projection = ProbeProjection::LatLong;
    let options = HeadlessOptions {
        size: (512, 256),
        ..Default::default()
    };
    let run =
        headless::render_probe(&gpu, &model, &settings, &options, &|_, _| {}).expect("renders");
    let picture = &run.images.display;
    // CONVENTIONS section 2: forward at (u, v) = (0.5, 0.5); phi = 30 degrees is u = 0.5833.
    assert_eq!(dominant(picture.get(256, 128)), Some(0));
    assert_eq!(dominant(picture.get(298, 128)), Some(1));
    assert_eq!(dominant(picture.get(256, 85)), Some(2));
}

#[test]
fn the_cursor_reads_the_texel_the_view_shows() {
    let (_dir, model) = model();
    let settings = ProbeViewSettings::for_probe(&model.latlong);
    let d = settings.direction_at(100.0, 100.0, 200, 200);
    // The centre of a look-around view with yaw 0 and pitch 0 looks along -Z.
    assert!((d - Vec3::NEG_Z).length() < 1e-6, "{d}");
    assert_eq!(model.radiance_towards(d), Rgb::new(1.0, 0.0, 0.0));
}
