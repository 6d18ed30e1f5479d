//! Exact ground-truth irradiance of a synthetic 512 x 256 lat-long probe (non-zero everywhere:
//! smooth sky, textured ground, a bright sun) on 20000 Fibonacci normals, and the fast
//! 64 x 32-block path on the same normals. The probe is built before timing.
//!
//! Run: `cargo bench -p ibl-eval --bench ground_truth -- --warm-up-time 1 --measurement-time 5`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_core::{SyntheticSky, fibonacci_normals};
use ibl_eval::{FAST_DEFAULT_SIZE, irradiance_brute_force, irradiance_exact, irradiance_fast};

fn bench(c: &mut Criterion) {
    let probe = SyntheticSky::default().render(512, 256);
    let normals = fibonacci_normals(20_000);
    let mut g = c.benchmark_group("ground_truth");
    g.sample_size(10);
    g.bench_function("exact_512x256_20000_normals", |b| {
        b.iter(|| irradiance_exact(black_box(&probe), black_box(&normals)))
    });
    g.bench_function("brute_force_512x256_20000_normals", |b| {
        b.iter(|| irradiance_brute_force(black_box(&probe), black_box(&normals)))
    });
    g.bench_function("fast_64x32_20000_normals", |b| {
        b.iter(|| irradiance_fast(black_box(&probe), black_box(&normals), FAST_DEFAULT_SIZE))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
