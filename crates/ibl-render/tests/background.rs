//! The background of a render is the mean of the probe over each output pixel's area, checked
//! against closed forms:
//!
//! 1. a pinhole camera at the probe's centre looking at the horizon (-Z) sees meridians as
//!    vertical lines (`phi = atan(X)` for image-plane abscissa `X`, whatever the height), so for a
//!    probe whose texels depend on their column only, a pixel's mean is a one-dimensional
//!    integral over its `X` interval: `sum_i L_i |[X0, X1] ∩ [tan phi_i, tan phi_(i+1)]| / (X1 - X0)`;
//! 2. a constant probe gives the constant everywhere, poles included (the weights sum to 1);
//! 3. the panorama camera at half the probe's size averages 2 x 2 texel blocks exactly.

#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::PI;

use ibl_core::{Image, Rgb};
use ibl_render::background::background_image;
use ibl_scene::{Scene, SceneDescription};

fn scene(toml: &str, probe: Image<Rgb>) -> Scene {
    let description = SceneDescription::from_toml(toml).unwrap();
    Scene::assemble(&description, probe, None, Vec::new(), Vec::new()).unwrap()
}

/// Radiance of column `i` of the column-function probe: distinct, irregular steps.
fn column_radiance(i: usize) -> f32 {
    1.0 + ((i * 37) % 11) as f32
}

#[test]
fn a_horizon_view_of_a_column_probe_is_its_exact_area_mean() {
    let (pw, ph) = (256, 128);
    let probe = Image::from_fn_par(pw, ph, |i, _| Rgb::splat(column_radiance(i)));
    let (w, h) = (48u32, 36u32);
    let fov_deg = 40.0f64;
    let toml = format!(
        "version = 1\n[probe]\nfile = \"p.exr\"\n[camera]\nposition = [0.0, 0.0, 0.0]\n\
         look_at = [0.0, 0.0, -1.0]\nvertical_fov_deg = {fov_deg}\nimage_size_px = [{w}, {h}]\n"
    );
    let scene = scene(&toml, probe);
    let background = background_image(&scene, w, h);
    // Image-plane abscissa of output column x: X = (x - cx) / f, f = (h / 2) / tan(fov / 2).
    let f = 0.5 * f64::from(h) / (0.5 * fov_deg.to_radians()).tan();
    let cx = 0.5 * f64::from(w);
    let mut worst = 0.0f64;
    for x in 0..w {
        let (x0, x1) = ((f64::from(x) - cx) / f, (f64::from(x) + 1.0 - cx) / f);
        let mut sum = 0.0;
        for i in 0..pw {
            let phi0 = 2.0 * PI * (i as f64 / pw as f64 - 0.5);
            let phi1 = 2.0 * PI * ((i + 1) as f64 / pw as f64 - 0.5);
            if phi1 <= -0.5 * PI || phi0 >= 0.5 * PI {
                continue;
            }
            let (t0, t1) = (phi0.max(-1.5).tan(), phi1.min(1.5).tan());
            let overlap = (x1.min(t1) - x0.max(t0)).max(0.0);
            sum += f64::from(column_radiance(i)) * overlap;
        }
        let expected = sum / (x1 - x0);
        for y in 0..h {
            let got = f64::from(background.get(x as usize, y as usize).g);
            worst = worst.max((got - expected).abs() / expected);
        }
    }
    // Meridians are clipped exactly in the image plane; what is left is the f32 rounding of the
    // camera's ray directions (about 1e-7 rad, against pixels 0.015 rad wide, a texel 0.025 rad).
    // Measured 3.7e-6 relative at worst; tolerance 2e-5. A 4 x 4 grid of nearest-texel rays
    // per pixel, the former background, is off by up to 1/8 of a jump between columns.
    assert!(worst < 2e-5, "worst relative error {worst}");
}

#[test]
fn a_constant_probe_is_constant_through_every_pixel_including_the_poles() {
    let l = Rgb::new(0.75, 0.5, 0.25);
    let probe = Image::filled(64, 32, l);
    // Looking straight up: the zenith is inside the image.
    let toml = "version = 1\n[probe]\nfile = \"p.exr\"\n[camera]\nposition = [0.0, 0.0, 0.0]\n\
                look_at = [0.0, 1.0, 0.0]\nup = [0.0, 0.0, -1.0]\nvertical_fov_deg = 60.0\n\
                image_size_px = [32, 24]\n";
    let scene = scene(toml, probe);
    let background = background_image(&scene, 32, 24);
    for p in background.pixels() {
        // Area fractions summing to 1 in f64, rounded once to f32: within 1 ulp.
        for k in 0..3 {
            assert!((p[k] - l[k]).abs() <= l[k] * f32::EPSILON, "{p:?}");
        }
    }
}

#[test]
fn the_panorama_at_half_size_averages_texel_blocks() {
    let probe = Image::from_fn_par(64, 32, |x, y| Rgb::splat((x * 3 + y * 7) as f32));
    let scene = scene("version = 1\n[probe]\nfile = \"p.exr\"\n", probe.clone());
    let half = background_image(&scene, 32, 16);
    for y in 0..16 {
        for x in 0..32 {
            let mean = (probe.get(2 * x, 2 * y).g
                + probe.get(2 * x + 1, 2 * y).g
                + probe.get(2 * x, 2 * y + 1).g
                + probe.get(2 * x + 1, 2 * y + 1).g)
                / 4.0;
            // Dyadic weights (1/4 each) of small integers: exact in f64 and in f32.
            assert_eq!(half.get(x, y).g, mean, "({x}, {y})");
        }
    }
}
