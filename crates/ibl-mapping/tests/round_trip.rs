//! Round trips lat-long -> X -> lat-long on every bundled probe (`assets/probes/*.exr`, 512 x 256,
//! loaded with `ibl_io::read_image`): total power must stay within 0.5 % (CONVENTIONS section 3);
//! the per-pixel error is printed (`cargo test -p ibl-mapping --test round_trip -- --nocapture`).
//!
//! Intermediate sizes (from `Mapping::default_size_for`, which keeps the source's angular
//! resolution): angular 512 x 512, mirror ball 1024 x 1024 (its rim is undersampled, so twice the
//! pixels), cube faces 128 (horizontal cross 512 x 384, vertical cross 384 x 512, strip 768 x 128),
//! a 360-degree equidistant fisheye 512 x 512 (it covers the whole sphere), a 200-degree dual
//! fisheye 568 x 284.
//!
//! Per-pixel metrics, on luminance Y, over the 512 x 256 lat-long pixels (a round trip resamples
//! twice, so it blurs by about a texel; next to a sun that blur is most of the error):
//! * `med`: median relative error `|Y' - Y| / Y` (the typical pixel);
//! * `mre`: mean of `|Y' - Y| / max(Y, mean Y)` (relative where brighter than average, relative
//!   to the mean radiance where darker, so a dark pixel beside a sun does not count 1000x);
//! * `rmse`: root-mean-square error divided by the mean radiance.

#![allow(clippy::unwrap_used)] // tests may panic

use std::path::Path;

use ibl_core::glam::Mat3;
use ibl_core::{Image, Rgb};
use ibl_mapping::{CubeLayout, Mapping, power, resample};

fn probes() -> Vec<(String, Image<Rgb>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes");
    let probes = ibl_io::read_images_in(&dir, "exr").expect("the bundled probes load");
    assert!(!probes.is_empty(), "no probes in {}", dir.display());
    probes
}

fn intermediates() -> Vec<Mapping> {
    vec![
        Mapping::Angular,
        Mapping::MirrorBall,
        Mapping::Cube(CubeLayout::HorizontalCross),
        Mapping::Cube(CubeLayout::VerticalCross),
        Mapping::Cube(CubeLayout::HorizontalStrip),
        Mapping::Cube(CubeLayout::VerticalStrip),
        Mapping::Fisheye { fov_deg: 360.0 },
        Mapping::DualFisheye { fov_deg: 200.0 },
    ]
}

/// Largest relative power error over the three channels, in per cent.
fn power_error(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3)
        .map(|c| 100.0 * (b[c] / a[c] - 1.0))
        .fold(0.0, |m: f64, e| if e.abs() > m.abs() { e } else { m })
}

/// `(med %, mre %, rmse / mean %)` of `b` against `a` on luminance (see the module note).
fn pixel_errors(a: &Image<Rgb>, b: &Image<Rgb>) -> (f64, f64, f64) {
    let ya: Vec<f64> = a
        .pixels()
        .iter()
        .map(|c| f64::from(c.luminance()))
        .collect();
    let yb: Vec<f64> = b
        .pixels()
        .iter()
        .map(|c| f64::from(c.luminance()))
        .collect();
    let n = ya.len() as f64;
    let mean = ya.iter().sum::<f64>() / n;
    let mut rel: Vec<f64> = (0..ya.len())
        .filter(|&k| ya[k] > 0.0)
        .map(|k| (yb[k] - ya[k]).abs() / ya[k])
        .collect();
    rel.sort_by(f64::total_cmp);
    let median = rel.get(rel.len() / 2).copied().unwrap_or(0.0);
    let mre = (0..ya.len())
        .map(|k| (yb[k] - ya[k]).abs() / ya[k].max(mean))
        .sum::<f64>()
        / n;
    let rmse = ((0..ya.len()).map(|k| (yb[k] - ya[k]).powi(2)).sum::<f64>() / n).sqrt() / mean;
    (100.0 * median, 100.0 * mre, 100.0 * rmse)
}

#[test]
fn latlong_round_trips_keep_power_on_every_probe() {
    let none = |_: usize, _: usize| {};
    let mut worst: f64 = 0.0;
    let mut failures = Vec::new();
    println!(
        "\n{:<10} {:<18} {:>10} {:>9} {:>9} {:>8} {:>8} {:>8}",
        "probe", "via", "size", "power%", "mid%", "med%", "mre%", "rmse%"
    );
    for (name, src) in probes() {
        let (w, h) = (src.width(), src.height());
        let p0 = power(&src, Mapping::LatLong);
        for m in intermediates() {
            let (mw, mh) = m.default_size_for(Mapping::LatLong, w, h);
            let mid =
                resample(&src, Mapping::LatLong, m, mw, mh, Mat3::IDENTITY, &none).expect("to");
            let back =
                resample(&mid, m, Mapping::LatLong, w, h, Mat3::IDENTITY, &none).expect("back");
            let e_mid = power_error(p0, power(&mid, m));
            let e = power_error(p0, power(&back, Mapping::LatLong));
            let (med, mre, rmse) = pixel_errors(&src, &back);
            let (via, size) = (m.name(), format!("{mw}x{mh}"));
            print!("{name:<10} {via:<18} {size:>10} {e:>+9.4} {e_mid:>+9.4}");
            println!(" {med:>8.3} {mre:>8.3} {rmse:>8.3}");
            worst = worst.max(e.abs()).max(e_mid.abs());
            if e.abs() > 0.5 || e_mid.abs() > 0.5 {
                failures.push(format!(
                    "{name} via {}: {e:+.3} % (intermediate {e_mid:+.3} %)",
                    m.name()
                ));
            }
        }
    }
    println!("worst power error {worst:.4} %");
    assert!(
        failures.is_empty(),
        "power not kept within 0.5 %: {failures:#?}"
    );
}
