//! Spherical harmonics against closed forms (white furnace, clamped cosine), rotation invariants,
//! convergence with bands, and SH irradiance against the exact ground truth on the bundled probes.
//! Tables print with `cargo test -p ibl-sh --test sh -- --nocapture`.

#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::PI;
use std::path::Path;

use ibl_core::glam::{DMat3, DVec3};
use ibl_core::{Image, LatLong, Rgb, fibonacci_normals, irradiance_exact};
use ibl_metrics::IrradianceError;
use ibl_sh::{RadianceSh, Window, basis, lambert_factor, project_latlong, sh_index};

/// A 512 x 256 lat-long probe with radiance `f(d)` at every pixel centre.
fn synthetic(f: impl Fn(DVec3) -> [f32; 3]) -> Image<Rgb> {
    let (w, h) = (512, 256);
    let ll = LatLong::new(w, h);
    let mut img = Image::filled(w, h, Rgb::ZERO);
    for j in 0..h {
        for i in 0..w {
            let v = f(ll.pixel_dir64(i, j));
            *img.get_mut(i, j) = Rgb::new(v[0], v[1], v[2]);
        }
    }
    img
}

#[test]
fn white_furnace() {
    let probe = synthetic(|_| [1.0, 2.0, 3.0]);
    let sh = project_latlong(&probe, 9).unwrap();
    let c = sh.coefficients();
    for ch in 0..3 {
        let l = (ch + 1) as f64;
        let want = 2.0 * PI.sqrt() * l;
        // A constant probe projects exactly onto Y00 (texel integrals are exact): c00 = 2 sqrt(pi)
        // L to f64 rounding over the sum of the pixels (1e-15 relative); 1e-12.
        assert!(
            (c[0][ch] - want).abs() < 1e-12 * want,
            "{} vs {want}",
            c[0][ch]
        );
        // Every other coefficient vanishes up to the pixel-centre quadrature error.
        let worst = c[1..].iter().map(|v| v[ch].abs()).fold(0.0, f64::max);
        assert!(
            worst < 1e-4 * want,
            "channel {ch}: largest other coefficient {worst}"
        );
    }
    // E = pi L for every normal.
    let e = sh.irradiance(Window::None);
    for n in fibonacci_normals(100) {
        let v = e.irradiance(n);
        for ch in 0..3 {
            let want = PI * (ch + 1) as f64;
            // E = pi L from c00 alone, the other coefficients 0 to rounding: f64 rounding, 1e-12
            // relative.
            assert!((v[ch] - want).abs() < 1e-12 * want, "{v:?} at {n}");
        }
    }
}

#[test]
fn clamped_cosine_projects_onto_the_lambert_factors() {
    // L(d) = max(0, d.a) has c_lm = A_l Y_lm(a) (Funk-Hecke).
    let a = DVec3::new(0.3, 0.8, -0.5).normalize();
    let probe = synthetic(|d| [d.dot(a).max(0.0) as f32; 3]);
    let bands = 11;
    let sh = project_latlong(&probe, bands).unwrap();
    let y = basis(a, bands);
    let mut worst: f64 = 0.0;
    for l in 0..bands {
        let li = l as isize;
        for m in -li..=li {
            let want = lambert_factor(l) * y[sh_index(l, m)];
            worst = worst.max((sh.coefficients()[sh_index(l, m)][0] - want).abs());
        }
    }
    // Relative to c00 = pi / (2 sqrt pi) ~ 0.886: the quadrature error of the terminator's kink.
    assert!(worst < 2e-4, "largest deviation {worst}");
}

/// A smooth environment (no kinks), for tests that should see no quadrature error.
fn smooth(d: DVec3, axis: DVec3) -> [f32; 3] {
    let v = (2.0 * d.dot(axis)).exp() + 0.3 * d.x * d.y;
    [v as f32, (0.5 * v) as f32, (1.0 + d.z * d.z) as f32]
}

#[test]
fn rotation_keeps_band_energy_and_commutes_with_rotating_the_probe() {
    let axis = DVec3::new(0.2, 0.9, 0.4).normalize();
    let r = DMat3::from_axis_angle(DVec3::new(1.0, -0.3, 0.5).normalize(), 0.9);
    let bands = 9;
    let sh = project_latlong(&synthetic(|d| smooth(d, axis)), bands).unwrap();
    let rotated = sh.rotated(r);
    for l in 0..bands {
        let (a, b) = (sh.band_energy(l), rotated.band_energy(l));
        for ch in 0..3 {
            // Rotation is orthogonal per band (Ivanic-Ruedenberg), so each band's energy is kept to
            // f64 rounding of the recursion (1e-14 relative at 9 bands); 1e-12.
            assert!(
                (a[ch] - b[ch]).abs() <= 1e-12 * a[ch].max(1e-30),
                "band {l}"
            );
        }
    }
    // The probe rotated first: L'(d) = L(R^-1 d).
    let rt = r.transpose();
    let direct = project_latlong(&synthetic(|d| smooth(rt * d, axis)), bands).unwrap();
    let norm: f64 = direct
        .coefficients()
        .iter()
        .flatten()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt();
    let diff: f64 = direct
        .coefficients()
        .iter()
        .zip(rotated.coefficients())
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).powi(2)))
        .sum::<f64>()
        .sqrt();
    // Projecting a rotated probe and rotating the projection differ only by the probe's
    // discretisation (piecewise constant over 512 x 256 texels, which does not rotate exactly); for
    // this smooth function that is a small fraction of the norm, bounded here at 1e-4.
    assert!(diff < 1e-4 * norm, "relative difference {}", diff / norm);
}

#[test]
fn reflections_mirror_the_function() {
    // A mirror in x (a change of handedness): L'(d) = L(M^-1 d) with M = diag(-1, 1, 1).
    let axis = DVec3::new(0.6, 0.2, -0.3).normalize();
    let sh = project_latlong(&synthetic(|d| smooth(d, axis)), 9).unwrap();
    let m = DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
    let mirrored = sh.transformed(m);
    for d in fibonacci_normals(50) {
        let (a, b) = (mirrored.radiance(d), sh.radiance(m * d));
        for c in 0..3 {
            // A mirror changes the signs of the odd bands exactly: f64 rounding of the evaluation
            // (1e-15), 1e-9 absolute plus relative.
            assert!((a[c] - b[c]).abs() < 1e-9 * (1.0 + b[c].abs()), "{d}");
        }
    }
}

#[test]
fn reconstruction_converges_as_bands_grow() {
    let axis = DVec3::new(-0.4, 0.5, 0.7).normalize();
    let probe = synthetic(|d| smooth(d, axis));
    let dirs = fibonacci_normals(2000);
    let full = project_latlong(&probe, 9).unwrap();
    let mut last = f64::INFINITY;
    for bands in [1, 2, 4, 8] {
        let sh = full.truncated(bands);
        let got = sh.eval_many(&dirs);
        let rms = (dirs
            .iter()
            .zip(&got)
            .map(|(d, g)| (g[0] - f64::from(smooth(*d, axis)[0])).powi(2))
            .sum::<f64>()
            / dirs.len() as f64)
            .sqrt();
        println!("{bands:2} bands: rms radiance error {rms:.3e}");
        assert!(rms < last, "{bands} bands: {rms} not below {last}");
        last = rms;
    }
    // Beyond about 8 bands the f32 pixels and the pixel-centre quadrature set a floor near 1e-4.
    assert!(last < 1e-3, "8 bands: {last}");
}

fn probes() -> Vec<(String, Image<Rgb>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes");
    let probes = ibl_io::read_images_in(&dir, "exr").expect("the bundled probes load");
    assert!(!probes.is_empty(), "no probes in {}", dir.display());
    probes
}

/// (mean_err%, max_err%) of CONVENTIONS section 5.
fn errors(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> (f64, f64) {
    let e = IrradianceError::between(truth, approx);
    (e.mean_err_pct, e.max_err_pct)
}

/// SH irradiance against the exact ground truth on the bundled probes: 3 bands ("SH9") lands at a
/// few per cent, and the error falls as bands are added, to a few tenths of a per cent or less at
/// 21 bands.
#[test]
fn sh_irradiance_converges_to_the_exact_ground_truth_on_bundled_probes() {
    let normals = fibonacci_normals(20_000);
    let (mut total, mut count) = (0.0, 0.0);
    for (name, probe) in probes() {
        let truth = irradiance_exact(&probe, &normals);
        let full: RadianceSh = project_latlong(&probe, 21).unwrap();
        let mut row = Vec::new();
        let mut last = f64::INFINITY;
        for bands in [3, 5, 9, 15, 21] {
            let e = full.truncated(bands).irradiance(Window::None);
            let (mean, max) = errors(&truth, &e.eval_many(&normals));
            row.push(format!("{bands}: {mean:.3}/{max:.2}"));
            assert!(mean < last, "{name}: {bands} bands {mean} not below {last}");
            last = mean;
            if bands == 3 {
                assert!(mean < 8.0 && max < 30.0, "{name}: SH9 {mean} / {max}");
            }
        }
        println!("{name:10} mean/max % by bands: {}", row.join("  "));
        // Probes with a small bright sun converge slowest (sky: 0.33 %).
        assert!(last < 0.4, "{name}: 21 bands mean {last}");
        total += last;
        count += 1.0;
    }
    // The bundled set is sun-heavy (2 of 5); over the 18 probes of the shared set the average is
    // 0.083 % at 21 bands and 3.0 % / 11 % at 3 bands (issue 4's note).
    assert!(
        total / count < 0.15,
        "21 bands, average mean error {}",
        total / count
    );
}
