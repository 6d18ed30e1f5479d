//! Lat-long -> cube map (horizontal cross) -> lat-long at 1024 x 512, on a synthetic environment
//! (smooth sky, textured ground, a 0.5-degree sun) built before timing: no file I/O is measured.
//!
//! Run: `cargo bench -p ibl-mapping --bench mapping -- --warm-up-time 1 --measurement-time 5`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_core::glam::Mat3;
use ibl_core::{Image, Rgb, SyntheticSky};
use ibl_mapping::{CubeLayout, Mapping, power, resample};

fn environment(w: usize, h: usize) -> Image<Rgb> {
    SyntheticSky {
        sun_radius_deg: 0.5,
        sun_radiance: 50_000.0,
        ..SyntheticSky::default()
    }
    .render(w, h)
}

fn bench(c: &mut Criterion) {
    let (w, h) = (1024, 512);
    let src = environment(w, h);
    let cube = Mapping::Cube(CubeLayout::HorizontalCross);
    let (cw, ch) = cube.default_size_for(Mapping::LatLong, w, h); // 1024 x 768, faces of 256
    let none = |_: usize, _: usize| {};
    let mut group = c.benchmark_group("resample");
    group.sample_size(10);
    group.bench_function("latlong 1024x512 -> cube hcross 1024x768", |b| {
        b.iter(|| {
            resample(
                black_box(&src),
                Mapping::LatLong,
                cube,
                cw,
                ch,
                Mat3::IDENTITY,
                &none,
            )
        })
    });
    let mid =
        resample(&src, Mapping::LatLong, cube, cw, ch, Mat3::IDENTITY, &none).expect("valid sizes");
    group.bench_function("cube hcross 1024x768 -> latlong 1024x512", |b| {
        b.iter(|| {
            resample(
                black_box(&mid),
                cube,
                Mapping::LatLong,
                w,
                h,
                Mat3::IDENTITY,
                &none,
            )
        })
    });
    group.bench_function("latlong 1024x512 -> cube -> latlong (round trip)", |b| {
        b.iter(|| {
            let mid = resample(
                black_box(&src),
                Mapping::LatLong,
                cube,
                cw,
                ch,
                Mat3::IDENTITY,
                &none,
            )
            .expect("valid sizes");
            resample(&mid, cube, Mapping::LatLong, w, h, Mat3::IDENTITY, &none)
        })
    });
    group.bench_function("power of a 1024x512 lat-long", |b| {
        b.iter(|| power(black_box(&src), Mapping::LatLong))
    });
    group.bench_function("power of a 1024x768 cube cross", |b| {
        b.iter(|| power(black_box(&mid), cube))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
