//! Cholesky solves of the symmetric positive definite systems irradiance optimisation solves,
//! `5N x 5N` for N lights (N = 64, 128, 256: n = 320, 640, 1280): nalgebra's `Cholesky` against
//! faer's `llt`, the one `ibl-extract` uses. Run with
//! `cargo bench -p ibl-extract --bench cholesky`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::linalg::solvers::Solve;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// A random SPD matrix `X^T X + n I` of size n, seeded.
fn spd(n: usize) -> DMatrix<f64> {
    let mut rng = Pcg64::seed_from_u64(n as u64);
    let x = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    x.transpose() * &x + DMatrix::identity(n, n) * n as f64
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("cholesky");
    group.sample_size(10);
    for n in [320usize, 640, 1280] {
        let a = spd(n);
        let b = DVector::from_fn(n, |i, _| (i as f64).sin());
        let fa = faer::Mat::<f64>::from_fn(n, n, |i, j| a[(i, j)]);
        let fb = faer::Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        group.bench_with_input(BenchmarkId::new("nalgebra/solve", n), &a, |bench, a| {
            bench.iter(|| black_box(a.clone().cholesky().map(|l| l.solve(&b))));
        });
        group.bench_with_input(BenchmarkId::new("faer/solve", n), &fa, |bench, fa| {
            bench.iter(|| black_box(fa.llt(faer::Side::Lower).map(|llt| llt.solve(&fb))));
        });
        // Both solve the same system: report the agreement once per size.
        let ours = a.clone().cholesky().expect("SPD").solve(&b);
        let theirs = fa.llt(faer::Side::Lower).expect("SPD").solve(&fb);
        let diff = (0..n)
            .map(|i| (ours[i] - theirs[(i, 0)]).abs())
            .fold(0.0f64, f64::max);
        println!("n = {n}: largest |x_nalgebra - x_faer| = {diff:.2e}");
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
