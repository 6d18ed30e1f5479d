//! HDR merging and response recovery on a synthetic bracket of five 12-megapixel exposures
//! (4000 x 3000, 8-bit, 2 stops apart): a radiance field spanning about 14 stops (a smooth
//! gradient times a fine texture, plus a bright disc) through a gamma 2.2 response. The bracket is
//! built before timing.
//!
//! Run: `cargo bench -p ibl-capture --bench merge -- --warm-up-time 1 --measurement-time 3`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_capture::merge::{MergeOptions, Weighting, merge};
use ibl_capture::response::{RecoverOptions, ResponseCurve};
use ibl_core::Image;

const WIDTH: usize = 4000;
const HEIGHT: usize = 3000;

fn radiance(x: usize, y: usize, c: usize) -> f64 {
    let (u, v) = (x as f64 / WIDTH as f64, y as f64 / HEIGHT as f64);
    let gradient = 2f64.powf(12.0 * u - 8.0);
    let texture = 1.0 + 0.5 * ((x as f64 * 0.31).sin() * (y as f64 * 0.17 + c as f64).cos());
    let disc = if (u - 0.8).powi(2) + (v - 0.3).powi(2) < 0.002 {
        64.0
    } else {
        0.0
    };
    gradient * texture * (1.0 + 0.2 * v) + disc
}

fn bracket() -> (Vec<Image<[u8; 3]>>, Vec<f64>) {
    let times: Vec<f64> = (0..5).map(|j| 4f64.powi(j - 2)).collect();
    let images = times
        .iter()
        .map(|&t| {
            Image::from_fn_par(WIDTH, HEIGHT, |x, y| {
                std::array::from_fn(|c| {
                    let exposure = (radiance(x, y, c) * t).min(1.0);
                    (255.0 * exposure.powf(1.0 / 2.2)).round() as u8
                })
            })
        })
        .collect();
    (images, times)
}

fn bench(c: &mut Criterion) {
    let (images, times) = bracket();
    let table: Vec<f32> = (0..256)
        .map(|z| (2.2 * ((z as f64).max(0.25) / 255.0).ln()) as f32)
        .collect();
    let curve = ResponseCurve::from_table([table.clone(), table.clone(), table]).expect("curve");
    let mut g = c.benchmark_group("capture");
    g.sample_size(10);
    g.bench_function("merge_hat_5x4000x3000", |b| {
        b.iter(|| merge(black_box(&images), &times, &curve, &MergeOptions::default()))
    });
    let noise_aware = MergeOptions {
        weighting: Weighting::NoiseAware,
        ..MergeOptions::default()
    };
    g.bench_function("merge_noise_aware_5x4000x3000", |b| {
        b.iter(|| merge(black_box(&images), &times, &curve, &noise_aware))
    });
    g.bench_function("recover_curve_5x4000x3000", |b| {
        b.iter(|| ResponseCurve::recover(black_box(&images), &times, &RecoverOptions::default()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
