//! Encode and decode speed of a 2048 x 1024 lat-long image held in memory: Radiance RGBE (RLE),
//! OpenEXR float ZIP and half ZIP, PFM, plus the 8-bit display transform. Pure byte-level work,
//! no file system.
//!
//! Run: `cargo bench -p ibl-io --bench io -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{Criterion, Throughput};
use ibl_core::tonemap::{Display, to_srgb8};
use ibl_core::{Image, Rgb};
use ibl_io::exr::{ExrCompression, ExrOptions, ExrPrecision};
use ibl_io::{Limits, exr, hdr, pfm};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const W: usize = 2048;
const H: usize = 1024;

/// A synthetic sky: smooth gradient, a bright sun, darker ground, and 1 % sensor noise, so that
/// compressors see something like a real probe rather than constant or random data.
fn probe_like() -> Image<Rgb> {
    let mut rng = Pcg64::seed_from_u64(42);
    let noise: Vec<f32> = (0..W * H)
        .map(|_| 1.0 + 0.01 * rng.random_range(-1.0f32..1.0))
        .collect();
    Image::from_fn_par(W, H, |x, y| {
        let v = (y as f32 + 0.5) / H as f32;
        let u = (x as f32 + 0.5) / W as f32;
        let base = if v < 0.5 {
            Rgb::new(0.4 + 0.6 * v, 0.6 + 0.5 * v, 1.2 - 0.4 * v)
        } else {
            Rgb::new(0.25, 0.2, 0.15) * (1.2 - v)
        };
        let d2 = (u - 0.3).powi(2) * 4.0 + (v - 0.2).powi(2);
        let sun = if d2 < 1e-4 { 3.0e4 } else { 0.0 };
        (base + Rgb::splat(sun)) * noise[y * W + x]
    })
}

fn benches(c: &mut Criterion) {
    let image = probe_like();
    let limits = Limits::default();
    let mut group = c.benchmark_group("io_2048x1024");
    group.throughput(Throughput::Elements((W * H) as u64));
    group.sample_size(10);

    let hdr_bytes = hdr::encode(&image);
    group.bench_function("hdr_rle_encode", |b| {
        b.iter(|| hdr::encode(black_box(&image)))
    });
    group.bench_function("hdr_rle_decode", |b| {
        b.iter(|| hdr::decode(black_box(&hdr_bytes), &limits).map(|r| r.image.len()))
    });
    // Baseline: the `image` crate's Radiance codec on the same pixels and bytes.
    let pixels: Vec<image::Rgb<f32>> = image
        .pixels()
        .iter()
        .map(|p| image::Rgb([p.r, p.g, p.b]))
        .collect();
    group.bench_function("baseline_image_crate_hdr_encode", |b| {
        b.iter(|| {
            let mut out = Vec::new();
            image::codecs::hdr::HdrEncoder::new(&mut out)
                .encode(black_box(&pixels), W, H)
                .map(|()| out.len())
        })
    });
    group.bench_function("baseline_image_crate_hdr_decode", |b| {
        b.iter(|| {
            image::load_from_memory_with_format(black_box(&hdr_bytes), image::ImageFormat::Hdr)
                .map(|i| i.width())
        })
    });

    for (name, precision) in [("float", ExrPrecision::Float), ("half", ExrPrecision::Half)] {
        let options = ExrOptions {
            precision,
            compression: ExrCompression::Zip,
        };
        let Ok(bytes) = exr::encode(&image, &options) else {
            panic!("exr {name} encoding failed");
        };
        group.bench_function(format!("exr_{name}_zip_encode"), |b| {
            b.iter(|| exr::encode(black_box(&image), &options).map(|v| v.len()))
        });
        group.bench_function(format!("exr_{name}_zip_decode"), |b| {
            b.iter(|| exr::decode(black_box(&bytes), &limits).map(|r| r.image.len()))
        });
        // Baseline: the `exr` crate's own RGBA reader (its default, multi-threaded).
        group.bench_function(format!("baseline_exr_crate_{name}_zip_decode"), |b| {
            b.iter(|| stock_exr::read_first_rgba_layer_from_file_bytes(black_box(&bytes)))
        });
        println!("exr {name} zip: {} bytes", bytes.len());
    }

    let pfm_bytes = pfm::encode(&image, pfm::ByteOrder::LittleEndian);
    group.bench_function("pfm_encode", |b| {
        b.iter(|| pfm::encode(black_box(&image), pfm::ByteOrder::LittleEndian))
    });
    group.bench_function("pfm_decode", |b| {
        b.iter(|| pfm::decode(black_box(&pfm_bytes), &limits).map(|r| r.image.len()))
    });
    group.bench_function("to_srgb8_reinhard", |b| {
        b.iter(|| to_srgb8(black_box(&image), &Display::default()))
    });
    group.finish();
    println!(
        "hdr rle: {} bytes, pfm: {} bytes",
        hdr_bytes.len(),
        pfm_bytes.len()
    );
}

/// The `exr` crate's stock reader over bytes in memory: RGBA as f32, all cores.
mod stock_exr {
    use ::exr::prelude::*;

    /// Decodes the first RGBA layer; returns its pixel count.
    pub fn read_first_rgba_layer_from_file_bytes(bytes: &[u8]) -> usize {
        read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |size, _| vec![[0.0f32; 3]; size.0 * size.1],
                |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                    let w = 2048;
                    px[pos.1 * w + pos.0] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes))
            .map(|img| img.layer_data.channel_data.pixels.len())
            .unwrap_or(0)
    }
}

fn main() {
    // What `criterion_group!`/`criterion_main!` expand to, without their undocumented `pub fn`.
    let mut c = Criterion::default().configure_from_args();
    benches(&mut c);
    c.final_summary();
}
