//! Probe statistics (`ibl info`): what an HDR image holds. Statistics are taken over the pixels
//! inside the mapping's domain (a mirror ball's corners are not part of the sphere); power is
//! `sum L dOmega` per channel with each mapping's exact texel solid angles; the brightest
//! direction is the pixel of largest luminance, as a world vector (or in a preset's axes).

use std::path::Path;

use ibl_core::{FramePreset, Image, Rgb};
use serde::Serialize;

use crate::envmap_files::{self, EnvMapping, LoadedEnv};
use crate::error::Result;

/// Reads `path` (in `mapping`, or guessed from its shape when `None`) and describes it, the
/// brightest direction in `frame`'s axes. Cost O(W H).
pub fn probe_info(path: &Path, mapping: Option<EnvMapping>, frame: FramePreset) -> Result<Info> {
    let env = envmap_files::load(path, mapping)?;
    // A KTX2/DDS cube map says it is one: its mapping is read, not guessed.
    let cube_texture = env.format.is_texture() && env.details.contains("cube");
    Ok(describe(
        &env,
        mapping.is_none() && !cube_texture,
        frame,
        &path.display().to_string(),
    ))
}

/// The brightest pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Brightest {
    /// Unit direction towards it, in the requested frame's axes.
    pub direction: [f32; 3],
    /// Pixel `[x, y]`, row 0 at the top.
    pub pixel: [usize; 2],
    /// Its radiance (linear RGB).
    pub radiance: [f32; 3],
}

/// Luminance range over the pixels in the mapping's domain.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DynamicRange {
    /// Smallest positive luminance.
    pub min_positive_luminance: f32,
    /// Largest luminance.
    pub max_luminance: f32,
    /// `max / min positive`.
    pub ratio: f64,
    /// `log2(ratio)`.
    pub stops: f64,
}

/// Everything `ibl info` reports; the JSON form is this struct.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Info {
    /// The file described.
    pub file: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// File format (`hdr`, `exr`, `pfm`, `png`, `jpeg`).
    pub format: String,
    /// Encoding details.
    pub encoding: String,
    /// Mapping used.
    pub mapping: String,
    /// Whether the mapping was guessed from the shape.
    pub mapping_guessed: bool,
    /// Per-channel minimum after clamping.
    pub min: [f32; 3],
    /// Per-channel maximum.
    pub max: [f32; 3],
    /// Per-channel mean over the pixels in the domain.
    pub mean: [f64; 3],
    /// Per-channel minimum of the raw finite values, before clamping.
    pub raw_min: [f32; 3],
    /// Channel values that were negative (clamped to 0).
    pub negative_values: u64,
    /// Channel values that were NaN or infinite (clamped to 0).
    pub nonfinite_values: u64,
    /// Total power per channel, `sum L dOmega` (radiance unit x sr).
    pub power: [f64; 3],
    /// Luminance dynamic range.
    pub dynamic_range: DynamicRange,
    /// Frame of `brightest.direction`.
    pub frame: String,
    /// The brightest pixel.
    pub brightest: Brightest,
}

/// Computes the statistics of a loaded environment map. Cost O(W H).
pub fn describe(env: &LoadedEnv, guessed: bool, frame: FramePreset, file: &str) -> Info {
    let img = &env.image;
    let (w, h) = (img.width(), img.height());
    let solid = env.mapping.texel_solid_angles(w, h);
    let stats = channel_stats(img, &solid);
    let power = ibl_mapping::power(img, env.mapping);
    let dir = env
        .mapping
        .pixel_dir(
            w,
            h,
            stats.brightest.0 as f64 + 0.5,
            stats.brightest.1 as f64 + 0.5,
        )
        .map(|d| frame.preset_from_world() * d.as_vec3())
        .unwrap_or_default();
    let b = *img.get(stats.brightest.0, stats.brightest.1);
    let ratio = if stats.min_pos_lum > 0.0 && stats.min_pos_lum.is_finite() {
        f64::from(stats.max_lum) / f64::from(stats.min_pos_lum)
    } else {
        1.0
    };
    Info {
        file: file.to_string(),
        width: w,
        height: h,
        format: env.format.name().to_string(),
        encoding: env.details.clone(),
        mapping: env.mapping.name(),
        mapping_guessed: guessed,
        min: stats.min.to_array(),
        max: stats.max.to_array(),
        mean: stats.mean,
        raw_min: env.report.raw_min.to_array(),
        negative_values: env.report.negative_values,
        nonfinite_values: env.report.nonfinite_values,
        power,
        dynamic_range: DynamicRange {
            min_positive_luminance: if stats.min_pos_lum.is_finite() {
                stats.min_pos_lum
            } else {
                0.0
            },
            max_luminance: stats.max_lum,
            ratio,
            stops: ratio.log2(),
        },
        frame: frame.name().to_string(),
        brightest: Brightest {
            direction: dir.to_array(),
            pixel: [stats.brightest.0, stats.brightest.1],
            radiance: b.to_array(),
        },
    }
}

struct ChannelStats {
    min: Rgb,
    max: Rgb,
    mean: [f64; 3],
    min_pos_lum: f32,
    max_lum: f32,
    brightest: (usize, usize),
}

/// Min, max, mean and luminance extremes over the pixels with a positive solid angle.
fn channel_stats(img: &Image<Rgb>, solid: &Image<f64>) -> ChannelStats {
    let mut s = ChannelStats {
        min: Rgb::splat(f32::INFINITY),
        max: Rgb::splat(f32::NEG_INFINITY),
        mean: [0.0; 3],
        min_pos_lum: f32::INFINITY,
        max_lum: f32::NEG_INFINITY,
        brightest: (0, 0),
    };
    let mut count = 0u64;
    for y in 0..img.height() {
        for (x, (p, sa)) in img.row(y).iter().zip(solid.row(y)).enumerate() {
            if *sa <= 0.0 {
                continue;
            }
            count += 1;
            s.min = Rgb::new(s.min.r.min(p.r), s.min.g.min(p.g), s.min.b.min(p.b));
            s.max = Rgb::new(s.max.r.max(p.r), s.max.g.max(p.g), s.max.b.max(p.b));
            for c in 0..3 {
                s.mean[c] += f64::from(p[c]);
            }
            let l = p.luminance();
            if l > s.max_lum {
                s.max_lum = l;
                s.brightest = (x, y);
            }
            if l > 0.0 && l < s.min_pos_lum {
                s.min_pos_lum = l;
            }
        }
    }
    if count == 0 {
        s.min = Rgb::ZERO;
        s.max = Rgb::ZERO;
        s.max_lum = 0.0;
    } else {
        for m in &mut s.mean {
            *m /= count as f64;
        }
    }
    s
}
