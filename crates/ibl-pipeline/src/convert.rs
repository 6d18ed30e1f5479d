//! Conversion between file formats and environment-map mappings (`ibl convert`), with rotation
//! and frame presets.
//!
//! The output pixel whose direction (by our formulas) is `d` shows world direction
//! `M_out d` (`M_out` = the output preset's lat-long layout matrix), which the probe saw from
//! direction `R^T M_out d` (`R` = the rotation, world_from_probe), which the input image stores at
//! `M_in^T R^T M_out d` (`M_in` = the input preset's). Resampling is energy-conserving (see
//! `ibl-mapping`).

use std::path::{Path, PathBuf};

use ibl_core::glam::Mat3;
use ibl_core::{EulerDegrees, FramePreset};
use ibl_io::{ExrOptions, WriteOptions};

use crate::envmap_files::{self, EnvMapping};
use crate::error::{PipelineError, Result};
use crate::progress::{Progress, rows};

/// What to convert.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvertOptions {
    /// Input image, or a `{face}` pattern with [`EnvMapping::CubeFaces`].
    pub input: PathBuf,
    /// Output image; format from the extension.
    pub output: PathBuf,
    /// Mapping of the input (`None`: guessed from its shape).
    pub from: Option<EnvMapping>,
    /// Mapping of the output (`None`: the input's).
    pub to: Option<EnvMapping>,
    /// Output width in pixels (`None`: the mapping's default for the input's size).
    pub width: Option<usize>,
    /// `world_from_probe` applied to the environment.
    pub rotation: EulerDegrees,
    /// Layout preset of the output.
    pub frame: FramePreset,
    /// Layout preset of the input.
    pub from_frame: FramePreset,
    /// EXR sample type and compression.
    pub exr: ExrOptions,
}

/// What a conversion wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Converted {
    /// Every file written (six for cube faces).
    pub files: Vec<PathBuf>,
    /// Size of the output image (of the whole strip for cube faces).
    pub width: usize,
    /// Height of the output image.
    pub height: usize,
    /// Name of the output mapping.
    pub mapping: String,
}

/// Reads, resamples and writes (see the module doc).
pub fn convert(o: &ConvertOptions, progress: &dyn Progress) -> Result<Converted> {
    if o.width == Some(0) {
        return Err(PipelineError::parameter("--width must be at least 1"));
    }
    let env = envmap_files::load(&o.input, o.from)?;
    envmap_files::note_clamped(&env, progress);
    let to = o.to.or(o.from).unwrap_or(EnvMapping::Single(env.mapping));
    let to_mapping = to.in_memory();
    let (w, h) = match o.width {
        Some(w) => to_mapping.size_for_width(w),
        None => to_mapping.default_size_for(env.mapping, env.image.width(), env.image.height()),
    };
    let world_rotation: Mat3 = o.frame.world_from_latlong_image().transpose()
        * o.rotation.world_from_probe()
        * o.from_frame.world_from_latlong_image();
    progress.begin("resampling", h as u64);
    let out = ibl_mapping::resample(
        &env.image,
        env.mapping,
        to_mapping,
        w,
        h,
        world_rotation,
        &rows(progress),
    );
    progress.end();
    let out = out?;
    let options = WriteOptions {
        exr: o.exr,
        ..WriteOptions::default()
    };
    let inputs: Vec<&Path> = env.files.iter().map(PathBuf::as_path).collect();
    let files = envmap_files::save(&o.output, &out, to, &options, &inputs)?;
    Ok(Converted {
        files,
        width: out.width(),
        height: out.height(),
        mapping: to.name(),
    })
}
