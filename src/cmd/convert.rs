//! `ibl convert`: any mapping to any mapping, any format to any format, with rotation and frame
//! presets (`ibl_pipeline::convert`).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use ibl_core::{EulerDegrees, FramePreset};
use ibl_io::{ExrCompression, ExrOptions, ExrPrecision};
use ibl_pipeline::EnvMapping;
use ibl_pipeline::convert::{ConvertOptions, convert};

use crate::progress::Bars;
use crate::values;

/// EXR sample types on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PrecisionArg {
    /// 32-bit float.
    Float,
    /// 16-bit half.
    Half,
}

/// EXR compressions on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CompressionArg {
    /// Uncompressed.
    None,
    /// Run-length.
    Rle,
    /// Zlib, one scanline per block.
    Zips,
    /// Zlib, 16 scanlines per block.
    Zip,
    /// Wavelet (PIZ).
    Piz,
}

/// Arguments of `ibl convert`.
#[derive(Args)]
#[command(after_help = "\
Mappings: latlong, angular, mirror-ball, cube-hcross, cube-vcross, cube-strip (6:1), cube-vstrip
          (1:6), cube-faces (six files: OUT may contain {face}, else _px.._nz is added), fisheye,
          dual-fisheye. Without --from the input's mapping is detected from its shape (2:1, 1:1,
          4:3, 3:4, 6:1, 1:6); other shapes need --from. Without --to (and no --width, --rotate
          or --frame) only the file format changes: the pixels pass through unchanged.

Examples:
  ibl convert probe.hdr probe.exr                         format only
  ibl convert probe.exr cross.exr --to cube-hcross        lat-long to a cube cross
  ibl convert probe.exr 'sky_{face}.hdr' --to cube-faces --face-size 256   six 256 x 256 files
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
    /// Output width in pixels (height follows from the mapping); with `--to cube-faces` the
    /// width of each face file.
    #[arg(long, value_name = "W")]
    pub width: Option<usize>,
    /// Face size in pixels of a cube output (cube-hcross, cube-vcross, cube-strip, cube-vstrip,
    /// cube-faces), instead of --width.
    #[arg(long, value_name = "S")]
    pub face_size: Option<usize>,
    /// Rotate the environment: yaw,pitch,roll in degrees (about +Y, +X, +Z; roll first).
    #[arg(long, value_name = "Y,P,R", allow_hyphen_values = true, value_parser = values::rotation)]
    pub rotate: Option<EulerDegrees>,
    /// Write the output in this tool's layout: gltf (ours), paper, threejs, blender.
    #[arg(long, default_value = "gltf", value_name = "PRESET", value_parser = values::frame)]
    pub frame: FramePreset,
    /// The input's layout preset.
    #[arg(long, default_value = "gltf", value_name = "PRESET", value_parser = values::frame)]
    pub from_frame: FramePreset,
    /// Field of view in degrees for fisheye mappings (input and output).
    #[arg(long, default_value_t = 180.0, value_name = "DEG")]
    pub fov: f32,
    /// Field of view of the input when it differs from the output's.
    #[arg(long, value_name = "DEG")]
    pub from_fov: Option<f32>,
    /// EXR sample type.
    #[arg(long, value_enum, default_value = "float")]
    pub exr_precision: PrecisionArg,
    /// EXR compression.
    #[arg(long, value_enum, default_value = "zip")]
    pub exr_compression: CompressionArg,
}

/// EXR options from the command line.
fn exr_options(precision: PrecisionArg, compression: CompressionArg) -> ExrOptions {
    ExrOptions {
        precision: match precision {
            PrecisionArg::Float => ExrPrecision::Float,
            PrecisionArg::Half => ExrPrecision::Half,
        },
        compression: match compression {
            CompressionArg::None => ExrCompression::None,
            CompressionArg::Rle => ExrCompression::Rle,
            CompressionArg::Zips => ExrCompression::Zips,
            CompressionArg::Zip => ExrCompression::Zip,
            CompressionArg::Piz => ExrCompression::Piz,
        },
    }
}

/// Runs `ibl convert`.
pub fn run(args: &ConvertArgs) -> anyhow::Result<()> {
    let parse = |name: &Option<String>, fov: f32| {
        name.as_deref()
            .map(|m| EnvMapping::parse(m, fov))
            .transpose()
    };
    let options = ConvertOptions {
        input: args.input.clone(),
        output: args.output.clone(),
        from: parse(&args.from, args.from_fov.unwrap_or(args.fov))?,
        to: parse(&args.to, args.fov)?,
        width: args.width,
        face_size: args.face_size,
        rotation: args.rotate.unwrap_or_default(),
        frame: args.frame,
        from_frame: args.from_frame,
        exr: exr_options(args.exr_precision, args.exr_compression),
    };
    let converted = convert(&options, &Bars::default())?;
    for f in &converted.files {
        eprintln!(
            "wrote {} ({} x {}, {})",
            f.path.display(),
            f.width,
            f.height,
            converted.mapping
        );
    }
    Ok(())
}
