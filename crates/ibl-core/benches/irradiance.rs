//! Exact irradiance of a synthetic lat-long probe (smooth sky, textured ground, a bright sun) on
//! 20000 Fibonacci normals, at 512 to 4096 pixels wide: the rows streamed through the cache
//! (`irradiance_exact`) and, at 512 and 1024, the stored-rows path (`RowIrradiance`) it
//! replaced for batches. Probes are built before timing.
//!
//! Run: `cargo bench -p ibl-core --bench irradiance -- --warm-up-time 1 --measurement-time 5`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_core::{RowIrradiance, SyntheticSky, fibonacci_normals, irradiance_exact};

fn bench(c: &mut Criterion) {
    let normals = fibonacci_normals(20_000);
    let mut g = c.benchmark_group("irradiance_exact");
    g.sample_size(10);
    for width in [512, 1024, 2048, 4096] {
        let probe = SyntheticSky::default().render(width, width / 2);
        g.bench_function(format!("streamed_{width}_20000_normals"), |b| {
            b.iter(|| irradiance_exact(black_box(&probe), black_box(&normals)))
        });
        if width <= 1024 {
            g.bench_function(format!("stored_rows_{width}_20000_normals"), |b| {
                b.iter(|| RowIrradiance::new(black_box(&probe)).irradiance(black_box(&normals)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
