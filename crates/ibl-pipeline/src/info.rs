//! Probe statistics (`ibl info`): what an HDR image holds. Statistics are taken over the pixels
//! inside the mapping's domain (a mirror ball's corners are not part of the sphere); power is
//! `sum L dOmega` per channel with each mapping's exact texel solid angles; the brightest
//! direction is the pixel of largest luminance, as a world vector (or in a preset's axes).

use std::path::Path;

use ibl_core::{FramePreset, Image, Rgb};
use serde::Serialize;

use ibl_io::{ImageFormat, LoadedImage, SanitizeReport};
use ibl_mapping::Mapping;

use crate::envmap_files::{self, EnvMapping, LoadedEnv};
use crate::error::Result;

/// Reads `path` (in `mapping`, or guessed from its shape when `None`) and describes it, the
/// brightest direction in `frame`'s axes. Cost O(W H).
pub fn probe_info(path: &Path, mapping: Option<EnvMapping>, frame: FramePreset) -> Result<Info> {
    if mapping == Some(EnvMapping::CubeFaces) {
        let env = envmap_files::load(path, mapping)?;
        return Ok(describe(&env, false, frame, &path.display().to_string()));
    }
    let loaded = ibl_io::read_image(path)?;
    let (w, h) = (loaded.image.width(), loaded.image.height());
    if mapping.is_none() && Mapping::detect_from_shape(w, h).is_none() {
        // Not a probe by its shape (a photo, a strip of samples): still an image worth
        // describing, without the quantities that need a mapping.
        return Ok(describe_unmapped(
            &loaded,
            frame,
            &path.display().to_string(),
        ));
    }
    // A KTX2/DDS cube map says it is one: its mapping is read, not guessed.
    let cube_texture = loaded.format.is_texture() && loaded.details.contains("cube");
    let env = envmap_files::bind(path, loaded, mapping)?;
    Ok(describe(
        &env,
        mapping.is_none() && !cube_texture,
        frame,
        &path.display().to_string(),
    ))
}

/// What `ibl info --header` reports: the header's facts, no pixel decoded.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeaderInfo {
    /// The file described.
    pub file: String,
    /// File format (`hdr`, `exr`, `pfm`, `png`, `jpeg`, `ktx2`, `dds`).
    pub format: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width * height`.
    pub pixels: u64,
    /// Whether [`ibl_io::Limits::default`] would decode it (2^28 pixels unless `--max-pixels`
    /// or `IBL_MAX_PIXELS` set another limit).
    pub within_limits: bool,
    /// The mapping given, or guessed from the shape ([`UNKNOWN_MAPPING`] when it names none).
    pub mapping: String,
    /// Whether the mapping was guessed from the shape.
    pub mapping_guessed: bool,
}

/// Reads only `path`'s header (`ibl_io::read_header`): instant whatever the image's size, and
/// nothing allocated for its pixels.
pub fn header_info(path: &Path, mapping: Option<EnvMapping>) -> Result<HeaderInfo> {
    let limits = ibl_io::Limits::default();
    let h = ibl_io::read_header(path, &limits)?;
    let guessed = Mapping::detect_from_shape(h.width, h.height);
    let (mapping, mapping_guessed) = match (mapping, guessed) {
        (Some(m), _) => (m.name(), false),
        (None, Some(g)) => (g.name(), true),
        (None, None) => (UNKNOWN_MAPPING.to_string(), false),
    };
    Ok(HeaderInfo {
        file: path.display().to_string(),
        format: h.format.name().to_string(),
        width: h.width,
        height: h.height,
        pixels: h.width as u64 * h.height as u64,
        within_limits: limits.check(h.width as u64, h.height as u64).is_ok(),
        mapping,
        mapping_guessed,
    })
}

/// Describes an image whose shape names no mapping: statistics over every pixel, no power and
/// no direction (those need a mapping: `--mapping` gives one).
fn describe_unmapped(loaded: &LoadedImage, frame: FramePreset, file: &str) -> Info {
    let img = &loaded.image;
    let ones = Image::filled(img.width(), img.height(), 1.0);
    let stats = channel_stats(img, &ones);
    let facts = FileFacts {
        format: loaded.format,
        details: &loaded.details,
        report: loaded.report,
    };
    info_of(img, &stats, &facts, None, frame, file)
}

/// The mapping name `ibl info` reports for an image whose shape names none.
pub const UNKNOWN_MAPPING: &str = "unknown";

/// The brightest pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Brightest {
    /// Unit direction towards it, in the requested frame's axes (`None` when the image's
    /// mapping is unknown).
    pub direction: Option<[f32; 3]>,
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
    /// Mapping used (`unknown` when the shape names none and none was given).
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
    /// Total power per channel, `sum L dOmega` (radiance unit x sr); `None` when the mapping
    /// is unknown.
    pub power: Option<[f64; 3]>,
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
    let solid = env.mapping.texel_solid_angles(img.width(), img.height());
    let stats = channel_stats(img, &solid);
    let facts = FileFacts {
        format: env.format,
        details: &env.details,
        report: env.report,
    };
    // The solid angles serve the statistics and the power: computed once (they are most of
    // the time on a large disc image).
    let power = match env.mapping {
        Mapping::LatLong => ibl_mapping::power(img, env.mapping),
        _ => ibl_mapping::power_with_solid_angles(img, &solid),
    };
    let bound = BoundMapping {
        mapping: env.mapping,
        guessed,
        power,
    };
    info_of(img, &stats, &facts, Some(bound), frame, file)
}

/// The mapping an image is described in, and whether it was guessed from the shape.
#[derive(Clone, Copy)]
struct BoundMapping {
    mapping: Mapping,
    guessed: bool,
    /// `sum L dOmega` per channel.
    power: [f64; 3],
}

/// What the file said about itself, beside its pixels.
struct FileFacts<'a> {
    format: ImageFormat,
    details: &'a str,
    report: SanitizeReport,
}

/// The description; without a mapping there is no power and no direction to the brightest pixel.
fn info_of(
    img: &Image<Rgb>,
    stats: &ChannelStats,
    loaded: &FileFacts<'_>,
    bound: Option<BoundMapping>,
    frame: FramePreset,
    file: &str,
) -> Info {
    let (w, h) = (img.width(), img.height());
    let direction = bound.map(|b| {
        b.mapping
            .pixel_dir(
                w,
                h,
                stats.brightest.0 as f64 + 0.5,
                stats.brightest.1 as f64 + 0.5,
            )
            .map(|d| frame.preset_from_world() * d.as_vec3())
            .unwrap_or_default()
            .to_array()
    });
    let b = if w > 0 && h > 0 {
        *img.get(stats.brightest.0, stats.brightest.1)
    } else {
        Rgb::ZERO
    };
    let ratio = if stats.min_pos_lum > 0.0 && stats.min_pos_lum.is_finite() {
        f64::from(stats.max_lum) / f64::from(stats.min_pos_lum)
    } else {
        1.0
    };
    Info {
        file: file.to_string(),
        width: w,
        height: h,
        format: loaded.format.name().to_string(),
        encoding: loaded.details.to_string(),
        mapping: bound.map_or(UNKNOWN_MAPPING.to_string(), |b| b.mapping.name()),
        mapping_guessed: bound.is_some_and(|b| b.guessed),
        min: stats.min.to_array(),
        max: stats.max.to_array(),
        mean: stats.mean,
        raw_min: loaded.report.raw_min.to_array(),
        negative_values: loaded.report.negative_values,
        nonfinite_values: loaded.report.nonfinite_values,
        power: bound.map(|b| b.power),
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
            direction,
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

/// The text `ibl info` prints.
impl std::fmt::Display for Info {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let i = self;
        let guessed = if i.mapping_guessed {
            " (guessed from shape; --mapping to override)"
        } else if i.mapping == UNKNOWN_MAPPING {
            " (its shape names none: not read as a probe; --mapping to name one)"
        } else {
            ""
        };
        writeln!(f, "file        {}", i.file)?;
        writeln!(f, "format      {} ({})", i.format, i.encoding)?;
        writeln!(f, "size        {} x {}", i.width, i.height)?;
        writeln!(f, "mapping     {}{guessed}", i.mapping)?;
        writeln!(f, "             {:>12} {:>12} {:>12}", "R", "G", "B")?;
        for (name, v) in [("min", i.min), ("max", i.max)] {
            writeln!(
                f,
                "{name:<12}{:>12.5e} {:>12.5e} {:>12.5e}",
                v[0], v[1], v[2]
            )?;
        }
        let m = i.mean;
        writeln!(
            f,
            "mean        {:>12.5e} {:>12.5e} {:>12.5e}",
            m[0], m[1], m[2]
        )?;
        match i.power {
            Some(p) => writeln!(
                f,
                "power       {:>12.5e} {:>12.5e} {:>12.5e}   (sum L dOmega)",
                p[0], p[1], p[2]
            )?,
            None => writeln!(f, "power       needs a mapping: name one with --mapping")?,
        }
        let dr = &i.dynamic_range;
        writeln!(
            f,
            "range       luminance {:.3e} .. {:.3e}: {:.3e}:1 ({:.1} stops)",
            dr.min_positive_luminance, dr.max_luminance, dr.ratio, dr.stops
        )?;
        writeln!(
            f,
            "invalid     {} negative, {} NaN/Inf values (clamped to 0; raw min {:.4e} {:.4e} {:.4e})",
            i.negative_values, i.nonfinite_values, i.raw_min[0], i.raw_min[1], i.raw_min[2]
        )?;
        let b = &i.brightest;
        let direction = match b.direction {
            Some(d) => format!(
                "direction ({:+.4}, {:+.4}, {:+.4}) [{} axes], ",
                d[0], d[1], d[2], i.frame
            ),
            None => String::new(),
        };
        writeln!(
            f,
            "brightest   {direction}pixel ({}, {}), radiance ({:.4e}, {:.4e}, {:.4e})",
            b.pixel[0], b.pixel[1], b.radiance[0], b.radiance[1], b.radiance[2]
        )
    }
}

/// The text `ibl info --header` prints.
impl std::fmt::Display for HeaderInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let guessed = if self.mapping_guessed {
            " (guessed from shape)"
        } else {
            ""
        };
        let limits = if self.within_limits {
            "within the limits"
        } else {
            "over the pixel limit: refused unless --max-pixels allows it"
        };
        writeln!(f, "file        {}", self.file)?;
        writeln!(f, "format      {}", self.format)?;
        writeln!(
            f,
            "size        {} x {} ({} pixels, {limits})",
            self.width, self.height, self.pixels
        )?;
        writeln!(f, "mapping     {}{guessed}", self.mapping)
    }
}
