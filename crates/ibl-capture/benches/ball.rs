//! Mirror balls: unwrapping a 2048 x 2048 ball to a 2048 x 1024 lat-long map (crop, resample,
//! reliability), and finding the same ball in a 2400 x 2200 photo. The photo is built before
//! timing from a synthetic environment (smooth sky, checkered ground, a bright sun) rendered to a
//! mirror ball with `ibl_mapping::resample` and pasted into a dark frame.
//!
//! Run: `cargo bench -p ibl-capture --bench ball -- --warm-up-time 1 --measurement-time 5`.

#![allow(missing_docs)] // `criterion_group!` generates an undocumented function

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use ibl_capture::ball::{Circle, find_ball, unwrap_ball};
use ibl_core::glam::Mat3;
use ibl_core::{Image, Rgb, SyntheticSky};
use ibl_mapping::{Mapping, resample};

const BALL: usize = 2048;
const OFFSET: (usize, usize) = (200, 90);

fn environment(w: usize, h: usize) -> Image<Rgb> {
    SyntheticSky {
        checker_texels: 16,
        ..SyntheticSky::default()
    }
    .render(w, h)
}

fn photo() -> Image<Rgb> {
    let ball = resample(
        &environment(2048, 1024),
        Mapping::LatLong,
        Mapping::MirrorBall,
        BALL,
        BALL,
        Mat3::IDENTITY,
        &|_, _| {},
    )
    .unwrap_or_else(|e| panic!("rendering the ball: {e}"));
    let half = BALL as f64 / 2.0;
    Image::from_fn_par(2400, 2200, |x, y| {
        let (i, j) = (x.wrapping_sub(OFFSET.0), y.wrapping_sub(OFFSET.1));
        let inside = i < BALL && j < BALL && {
            let (a, b) = (i as f64 + 0.5 - half, j as f64 + 0.5 - half);
            a * a + b * b <= half * half
        };
        if inside {
            *ball.get(i, j)
        } else {
            Rgb::splat(0.003)
        }
    })
}

fn bench(c: &mut Criterion) {
    let img = photo();
    let circle = Circle {
        cx: OFFSET.0 as f64 + BALL as f64 / 2.0,
        cy: OFFSET.1 as f64 + BALL as f64 / 2.0,
        r: BALL as f64 / 2.0,
    };
    let mut g = c.benchmark_group("ball");
    g.sample_size(10);
    g.bench_function("unwrap_2048_ball_to_2048x1024", |b| {
        b.iter(|| unwrap_ball(black_box(&img), circle, 2048))
    });
    g.bench_function("find_2048_ball_in_2400x2200", |b| {
        b.iter(|| find_ball(black_box(&img)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
