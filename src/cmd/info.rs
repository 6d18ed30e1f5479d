//! `ibl info`: what an HDR image holds. Statistics are taken over the pixels inside the mapping's
//! domain (a mirror ball's corners are not part of the sphere); power is `sum L dOmega` per
//! channel with each mapping's exact texel solid angles; the brightest direction is the pixel of
//! largest luminance, as a world vector (or in `--frame` axes).

use std::path::PathBuf;

use clap::Args;
use ibl_core::{FramePreset, Image, Rgb};
use serde::Serialize;

use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;

/// Arguments of `ibl info`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl info assets/probes/esplanade.exr
  ibl info probe.hdr --json | jq .brightest
  ibl info ball.exr --mapping mirror-ball
  ibl info env.ktx2                         # a KTX2/DDS cube: format, levels, faces
  ibl info probe.exr --frame blender        # brightest direction in Blender's Z-up axes")]
pub struct InfoArgs {
    /// The image to describe (.hdr, .exr, .pfm, .png, .jpg; .ktx2 and .dds: level 0, a cube map
    /// as its six faces side by side).
    pub file: PathBuf,
    /// Mapping of the image (default: guessed from its shape; 2:1 is lat-long, 1:1 angular).
    #[arg(long, value_name = "MAPPING")]
    pub mapping: Option<String>,
    /// Field of view in degrees for the fisheye mappings.
    #[arg(long, default_value_t = 180.0, value_name = "DEG")]
    pub fov: f32,
    /// Axes in which to print the brightest direction: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET")]
    pub frame: String,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The brightest pixel.
#[derive(Serialize)]
pub struct Brightest {
    /// Unit direction towards it, in the requested frame's axes.
    pub direction: [f32; 3],
    /// Pixel `[x, y]`, row 0 at the top.
    pub pixel: [usize; 2],
    /// Its radiance (linear RGB).
    pub radiance: [f32; 3],
}

/// Luminance range over the pixels in the mapping's domain.
#[derive(Serialize)]
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
#[derive(Serialize)]
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

/// Runs `ibl info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let mapping_arg = args
        .mapping
        .as_deref()
        .map(|m| MappingArg::parse(m, args.fov))
        .transpose()?;
    let frame = FramePreset::from_name(&args.frame).ok_or_else(|| {
        usage(format!(
            "unknown frame `{}` (gltf, paper, threejs, blender)",
            args.frame
        ))
    })?;
    let env = envmap_files::load(&args.file, mapping_arg)?;
    // A KTX2/DDS cube map says it is one: its mapping is read, not guessed.
    let cube_texture = env.format.is_texture() && env.details.contains("cube");
    let info = describe(
        &env,
        mapping_arg.is_none() && !cube_texture,
        frame,
        &args.file.display().to_string(),
    );
    if args.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        print_text(&info);
    }
    Ok(())
}

/// Computes the statistics of a loaded environment map. Cost O(W H).
pub fn describe(
    env: &envmap_files::LoadedEnv,
    guessed: bool,
    frame: FramePreset,
    file: &str,
) -> Info {
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

fn print_text(i: &Info) {
    let guessed = if i.mapping_guessed {
        " (guessed from shape; --mapping to override)"
    } else {
        ""
    };
    println!("file        {}", i.file);
    println!("format      {} ({})", i.format, i.encoding);
    println!("size        {} x {}", i.width, i.height);
    println!("mapping     {}{guessed}", i.mapping);
    println!("             {:>12} {:>12} {:>12}", "R", "G", "B");
    println!(
        "min         {:>12.5e} {:>12.5e} {:>12.5e}",
        i.min[0], i.min[1], i.min[2]
    );
    println!(
        "max         {:>12.5e} {:>12.5e} {:>12.5e}",
        i.max[0], i.max[1], i.max[2]
    );
    println!(
        "mean        {:>12.5e} {:>12.5e} {:>12.5e}",
        i.mean[0], i.mean[1], i.mean[2]
    );
    println!(
        "power       {:>12.5e} {:>12.5e} {:>12.5e}   (sum L dOmega)",
        i.power[0], i.power[1], i.power[2]
    );
    let dr = &i.dynamic_range;
    println!(
        "range       luminance {:.3e} .. {:.3e}: {:.3e}:1 ({:.1} stops)",
        dr.min_positive_luminance, dr.max_luminance, dr.ratio, dr.stops
    );
    println!(
        "invalid     {} negative, {} NaN/Inf values (clamped to 0; raw min {:.4e} {:.4e} {:.4e})",
        i.negative_values, i.nonfinite_values, i.raw_min[0], i.raw_min[1], i.raw_min[2]
    );
    let b = &i.brightest;
    println!(
        "brightest   direction ({:+.4}, {:+.4}, {:+.4}) [{} axes], pixel ({}, {}), radiance ({:.4e}, {:.4e}, {:.4e})",
        b.direction[0],
        b.direction[1],
        b.direction[2],
        i.frame,
        b.pixel[0],
        b.pixel[1],
        b.radiance[0],
        b.radiance[1],
        b.radiance[2]
    );
}
