//! SH on a bundled 512 x 256 probe (`assets/probes/sky.exr`, read before timing): projection at 3
//! and 21 bands, Lambert convolution plus evaluation at the 20000 scoring normals, and a rotation
//! of 21 bands.
//!
//! Run: `cargo bench -p ibl-sh --bench sh -- --warm-up-time 1 --measurement-time 3`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use ibl_core::glam::{DMat3, DVec3};
use ibl_core::{Image, Rgb, fibonacci_normals};
use ibl_sh::{Window, project_latlong};

fn probe() -> Image<Rgb> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/probes/sky.exr");
    ibl_io::read_image(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .image
}

fn bench(c: &mut Criterion) {
    let probe = probe();
    let mut g = c.benchmark_group("sh_projection_512x256");
    for bands in [3usize, 21] {
        g.bench_with_input(BenchmarkId::from_parameter(bands), &bands, |b, &bands| {
            b.iter(|| project_latlong(black_box(&probe), bands))
        });
    }
    g.finish();
    let normals = fibonacci_normals(20_000);
    let mut g = c.benchmark_group("sh_irradiance_20000_normals");
    for bands in [3usize, 21] {
        let sh = project_latlong(&probe, bands).unwrap_or_else(|e| panic!("{e}"));
        g.bench_with_input(BenchmarkId::from_parameter(bands), &bands, |b, _| {
            b.iter(|| sh.irradiance(Window::None).eval_many(black_box(&normals)))
        });
    }
    g.finish();
    let sh = project_latlong(&probe, 21).unwrap_or_else(|e| panic!("{e}"));
    let r = DMat3::from_axis_angle(DVec3::new(0.3, 1.0, 0.2).normalize(), 0.8);
    c.bench_function("sh_rotation_21_bands", |b| {
        b.iter(|| black_box(&sh).rotated(r))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
