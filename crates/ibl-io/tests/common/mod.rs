//! Helpers shared by the integration tests: deterministic test images and comparisons.

#![allow(dead_code)]

use ibl_core::{Image, Rgb};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// A `w x h` image of log-uniform values over `[1e-3, 1e4]`, with zero pixels, flat runs (so RLE
/// has something to compress) and a few exact duplicates, from a fixed seed.
pub fn hdr_test_image(w: usize, h: usize, seed: u64) -> Image<Rgb> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut px = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let v = if y % 5 == 1 && x > w / 3 {
                Rgb::new(0.25, 0.5, 1.0) // flat run
            } else if (x + y) % 17 == 0 {
                Rgb::ZERO
            } else {
                let mut c = || 10f32.powf(rng.random_range(-3.0..4.0));
                Rgb::new(c(), c(), c())
            };
            px.push(v);
        }
    }
    Image::from_vec(w, h, px).expect("size")
}

/// Largest error of `b` against `a`, relative to each pixel's largest channel in `a`.
pub fn max_rel_error(a: &Image<Rgb>, b: &Image<Rgb>) -> f32 {
    assert_eq!((a.width(), a.height()), (b.width(), b.height()));
    a.pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| {
            let m = p.max_channel();
            let d = (p.r - q.r)
                .abs()
                .max((p.g - q.g).abs())
                .max((p.b - q.b).abs());
            if m > 0.0 { d / m } else { d }
        })
        .fold(0.0, f32::max)
}

/// The bit patterns of every channel, for bit-exact comparisons (NaN included).
pub fn bits(img: &Image<Rgb>) -> Vec<u32> {
    img.pixels()
        .iter()
        .flat_map(|p| [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()])
        .collect()
}

/// Float values meant to survive bit-exact: signed zeros, subnormals, extremes, NaN, infinities.
pub fn awkward_floats(w: usize, h: usize) -> Image<Rgb> {
    let specials = [
        0.0,
        -0.0,
        f32::MIN_POSITIVE,
        1.0e-45,
        -3.5,
        f32::MAX,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        std::f32::consts::PI,
        1.0 / 3.0,
        65504.0,
        123_456.79,
    ];
    Image::from_fn_par(w, h, |x, y| {
        let i = x + y * w;
        let s = |k: usize| specials[(i * 3 + k) % specials.len()];
        // Every 4th pixel gets ordinary values derived from its index.
        if i % 4 == 3 {
            Rgb::new(i as f32 * 0.37, -(i as f32), 1.0 / (1 + i) as f32)
        } else {
            Rgb::new(s(0), s(1), s(2))
        }
    })
}
