//! Light extraction from a bundled 512 x 256 probe (`assets/probes/sky.exr`, a hard sun in a blue
//! sky), read before timing: median cut and adaptive median cut (whole run, summed-area tables
//! included) for N up to 256, variance minimisation, LightGen-style clustering with its
//! default 4 restarts, and irradiance optimisation (whole run: fitting-normal ground truth,
//! continuation from one light, final fit) at N = 16 and 64.
//!
//! Run: `cargo bench -p ibl-extract --bench extract -- --warm-up-time 1 --measurement-time 3`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use ibl_core::{Image, Rgb};
use ibl_extract::{
    LightGenOptions, OptimizationOptions, adaptive_median_cut, irradiance_optimization, lightgen,
    median_cut, variance_minimization,
};

fn probe() -> Image<Rgb> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes/sky.exr");
    ibl_io::read_image(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .image
}

fn bench(c: &mut Criterion) {
    let probe = probe();
    let mut g = c.benchmark_group("median_cut_512x256");
    for n in [1usize, 16, 64, 256] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| median_cut(black_box(&probe), n.trailing_zeros()))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("adaptive_median_cut_512x256");
    for n in [1usize, 16, 64, 100, 256] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| adaptive_median_cut(black_box(&probe), n))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("variance_minimization_512x256");
    for n in [16usize, 64, 256] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| variance_minimization(black_box(&probe), n))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("lightgen_512x256");
    g.sample_size(10);
    for n in [16usize, 64, 256] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| lightgen(black_box(&probe), n, &LightGenOptions::default()))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("irradiance_optimization_512x256");
    g.sample_size(10);
    for n in [16usize, 64] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| {
                irradiance_optimization(black_box(&probe), n, &OptimizationOptions::default())
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
