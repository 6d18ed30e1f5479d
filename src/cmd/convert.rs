//! `ibl convert`: any mapping to any mapping, any format to any format, with rotation and frame
//! presets.
//!
//! The output pixel whose direction (by our formulas) is `d` shows world direction
//! `M_out d` (`M_out` = the `--frame` preset's lat-long layout matrix), which the probe saw from
//! direction `R^T M_out d` (`R` = `--rotate`, world_from_probe), which the input image stores at
//! `M_in^T R^T M_out d` (`M_in` = `--from-frame`). Resampling is energy-conserving (see
//! `ibl-mapping`).

use std::path::PathBuf;

use clap::Args;
use ibl_core::glam::Mat3;
use ibl_core::{EulerDegrees, FramePreset};
use ibl_io::{ExrCompression, ExrOptions, ExrPrecision, WriteOptions};

use crate::envmap_files::{self, MappingArg};
use crate::failure::usage;
use crate::progress;

/// Arguments of `ibl convert`.
#[derive(Args)]
#[command(after_help = "\
Mappings: latlong, angular, mirror-ball, cube-hcross, cube-vcross, cube-strip, cube-faces
          (six files: OUT may contain {face}, else _px.._nz is added), fisheye, dual-fisheye.

Examples:
  ibl convert probe.hdr probe.exr                         format only
  ibl convert probe.exr cross.exr --to cube-hcross        lat-long to a cube cross
  ibl convert probe.exr 'sky_{face}.hdr' --to cube-faces  six face files
  ibl convert ball.png probe.exr --from mirror-ball --to latlong --width 1024
  ibl convert probe.exr turned.exr --rotate 90,0,0        yaw 90 deg: what was ahead is now left
  ibl convert probe.exr three.hdr --frame threejs         layout for three.js's equirect loader
  ibl convert gear360.jpg pano.exr --from dual-fisheye --fov 195")]
pub struct ConvertArgs {
    /// Input image (.hdr .exr .pfm .png .jpg), or a `{face}` pattern with `--from cube-faces`.
    pub input: PathBuf,
    /// Output image; format from the extension.
    pub output: PathBuf,
    /// Mapping of the input (default: guessed from its shape).
    #[arg(long, value_name = "MAPPING")]
    pub from: Option<String>,
    /// Mapping of the output (default: the input's).
    #[arg(long, value_name = "MAPPING")]
    pub to: Option<String>,
    /// Output width in pixels (height follows from the mapping).
    #[arg(long, value_name = "W")]
    pub width: Option<usize>,
    /// Rotate the environment: yaw,pitch,roll in degrees (about +Y, +X, +Z; roll first).
    #[arg(long, value_name = "Y,P,R", allow_hyphen_values = true)]
    pub rotate: Option<String>,
    /// Write the output in this tool's layout: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET")]
    pub frame: String,
    /// The input's layout preset.
    #[arg(long, default_value = "gltf", value_name = "PRESET")]
    pub from_frame: String,
    /// Field of view in degrees for fisheye mappings (input and output).
    #[arg(long, default_value_t = 180.0, value_name = "DEG")]
    pub fov: f32,
    /// Field of view of the input when it differs from the output's.
    #[arg(long, value_name = "DEG")]
    pub from_fov: Option<f32>,
    /// EXR sample type.
    #[arg(long, default_value = "float", value_parser = ["float", "half"])]
    pub exr_precision: String,
    /// EXR compression.
    #[arg(long, default_value = "zip", value_parser = ["none", "rle", "zips", "zip", "piz"])]
    pub exr_compression: String,
}

/// Parses `Y,P,R` degrees.
pub fn parse_rotation(text: &str) -> anyhow::Result<EulerDegrees> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let bad = || {
        usage(format!(
            "--rotate `{text}`: expected three angles in degrees, e.g. 90,0,0"
        ))
    };
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut v = [0.0f32; 3];
    for (slot, p) in v.iter_mut().zip(&parts) {
        *slot = p.parse().map_err(|_| bad())?;
        if !slot.is_finite() {
            return Err(bad());
        }
    }
    Ok(EulerDegrees {
        yaw_deg: v[0],
        pitch_deg: v[1],
        roll_deg: v[2],
    })
}

/// Looks up a frame preset by name, as a usage error when unknown.
pub fn parse_frame(name: &str) -> anyhow::Result<FramePreset> {
    FramePreset::from_name(name).ok_or_else(|| {
        usage(format!(
            "unknown frame `{name}` (gltf, paper, threejs, blender)"
        ))
    })
}

/// EXR options from the command line.
pub fn exr_options(precision: &str, compression: &str) -> ExrOptions {
    ExrOptions {
        precision: if precision == "half" {
            ExrPrecision::Half
        } else {
            ExrPrecision::Float
        },
        compression: match compression {
            "none" => ExrCompression::None,
            "rle" => ExrCompression::Rle,
            "zips" => ExrCompression::Zips,
            "piz" => ExrCompression::Piz,
            _ => ExrCompression::Zip,
        },
    }
}

/// Runs `ibl convert`.
pub fn run(args: &ConvertArgs) -> anyhow::Result<()> {
    let from = args
        .from
        .as_deref()
        .map(|m| MappingArg::parse(m, args.from_fov.unwrap_or(args.fov)))
        .transpose()?;
    let rotation = args
        .rotate
        .as_deref()
        .map(parse_rotation)
        .transpose()?
        .unwrap_or_default();
    let out_frame = parse_frame(&args.frame)?;
    let in_frame = parse_frame(&args.from_frame)?;
    if args.width == Some(0) {
        return Err(usage("--width must be at least 1"));
    }
    let env = envmap_files::load(&args.input, from)?;
    report_clamped(&env);
    let to = match args.to.as_deref() {
        Some(m) => MappingArg::parse(m, args.fov)?,
        None => from.unwrap_or(MappingArg::Single(env.mapping)),
    };
    let to_mapping = to.in_memory();
    let (w, h) = match args.width {
        Some(w) => to_mapping.size_for_width(w),
        None => to_mapping.default_size_for(env.mapping, env.image.width(), env.image.height()),
    };
    let world_rotation: Mat3 = out_frame.world_from_latlong_image().transpose()
        * rotation.world_from_probe()
        * in_frame.world_from_latlong_image();
    let bar = progress::bar("resampling", h as u64);
    let out = ibl_mapping::resample(
        &env.image,
        env.mapping,
        to_mapping,
        w,
        h,
        world_rotation,
        &progress::rows_callback(&bar),
    )?;
    bar.finish_and_clear();
    let options = WriteOptions {
        exr: exr_options(&args.exr_precision, &args.exr_compression),
        ..WriteOptions::default()
    };
    let inputs: Vec<&std::path::Path> = env.files.iter().map(PathBuf::as_path).collect();
    let written = envmap_files::save(&args.output, &out, to, &options, &inputs)?;
    for p in written {
        eprintln!(
            "wrote {} ({} x {}, {})",
            p.display(),
            out.width(),
            out.height(),
            to.name()
        );
    }
    Ok(())
}

/// Tells the user how many invalid values reading clamped, if any.
pub fn report_clamped(env: &envmap_files::LoadedEnv) {
    let r = &env.report;
    if r.negative_values + r.nonfinite_values > 0 {
        eprintln!(
            "note: {}: clamped {} negative and {} NaN/Inf values to 0",
            env.files
                .first()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
            r.negative_values,
            r.nonfinite_values
        );
    }
}
