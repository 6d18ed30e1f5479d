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
use ibl_core::{EulerDegrees, FramePreset, Image, Rgb};
use ibl_io::{ExrOptions, WriteOptions};
use ibl_mapping::Mapping;

use crate::envmap_files::{self, EnvMapping, LoadedEnv};
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
    /// Output width in pixels (`None`: the mapping's default for the input's size); for
    /// [`EnvMapping::CubeFaces`] the width of each face file.
    pub width: Option<usize>,
    /// Face size in pixels of a cube output (any layout, or six faces); excludes `width`.
    pub face_size: Option<usize>,
    /// `world_from_probe` applied to the environment.
    pub rotation: EulerDegrees,
    /// Layout preset of the output.
    pub frame: FramePreset,
    /// Layout preset of the input.
    pub from_frame: FramePreset,
    /// EXR sample type and compression.
    pub exr: ExrOptions,
}

/// One file a conversion wrote, with its own size.
#[derive(Clone, Debug, PartialEq)]
pub struct WrittenImage {
    /// The file.
    pub path: PathBuf,
    /// Its width in pixels (a face's for cube faces).
    pub width: usize,
    /// Its height in pixels.
    pub height: usize,
}

/// What a conversion wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Converted {
    /// Every file written (six for cube faces), each with its size.
    pub files: Vec<WrittenImage>,
    /// Name of the output mapping.
    pub mapping: String,
}

/// The files `save` wrote, with their sizes: the image's, or a face's for six face files.
fn written(files: Vec<PathBuf>, image: &Image<Rgb>, layout: EnvMapping) -> Vec<WrittenImage> {
    let (width, height) = match layout {
        EnvMapping::CubeFaces => (image.height(), image.height()),
        EnvMapping::Single(_) => (image.width(), image.height()),
    };
    files
        .into_iter()
        .map(|path| WrittenImage {
            path,
            width,
            height,
        })
        .collect()
}

/// The output size: `--face-size` for cube outputs, `--width` (a face file's width for six
/// faces), or the default that keeps the source's angular resolution.
fn output_size(o: &ConvertOptions, to: EnvMapping, source: &LoadedEnv) -> Result<(usize, usize)> {
    let to_mapping = to.in_memory();
    match (o.face_size, o.width, to, to_mapping) {
        (Some(_), Some(_), _, _) => Err(PipelineError::parameter(
            "give --width or --face-size, not both",
        )),
        (Some(s), None, _, Mapping::Cube(layout)) => {
            let (cols, rows) = layout.grid();
            s.checked_mul(cols)
                .zip(s.checked_mul(rows))
                .ok_or_else(|| PipelineError::parameter(format!("--face-size {s} is too large")))
        }
        (Some(_), None, _, m) => Err(PipelineError::parameter(format!(
            "--face-size applies to cube outputs, not to {}",
            m.name()
        ))),
        (None, Some(w), EnvMapping::CubeFaces, _) => w
            .checked_mul(6)
            .map(|strip| (strip, w))
            .ok_or_else(|| PipelineError::parameter(format!("--width {w} is too large"))),
        (None, Some(w), _, m) => Ok(m.size_for_width(w)),
        (None, None, _, m) => {
            Ok(m.default_size_for(source.mapping, source.image.width(), source.image.height()))
        }
    }
}

/// Whether the options ask for a change of format only: no output mapping other than the
/// input's, no width, no rotation, the same frame preset. Then the pixels pass through unchanged
/// whatever the image's shape (issue 13: a photo must not become a 512 x 256 lat-long).
fn is_format_only(o: &ConvertOptions) -> bool {
    (o.to.is_none() || o.to == o.from)
        && o.width.is_none()
        && o.face_size.is_none()
        && o.rotation == EulerDegrees::default()
        && o.frame == o.from_frame
}

/// Writes the input's pixels unchanged in the output's format (six face files stay six).
fn pass_through(o: &ConvertOptions, progress: &dyn Progress) -> Result<Converted> {
    // `save` only tells one file from six face files; the mapping inside `Single` is not used.
    let (image, files, layout) = match o.from {
        Some(from) => {
            let env = envmap_files::load(&o.input, Some(from))?;
            envmap_files::note_clamped(&env, progress);
            (env.image, env.files, from)
        }
        None => {
            let loaded = ibl_io::read_image(&o.input)?;
            envmap_files::note_sanitized(&o.input, &loaded.report, progress);
            let layout = EnvMapping::Single(Mapping::LatLong);
            (loaded.image, vec![o.input.clone()], layout)
        }
    };
    let options = WriteOptions {
        exr: o.exr,
        ..WriteOptions::default()
    };
    let inputs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    let files = envmap_files::save(&o.output, &image, layout, &options, &inputs)?;
    Ok(Converted {
        files: written(files, &image, layout),
        mapping: "unchanged (format only)".to_string(),
    })
}

/// Reads, resamples and writes (see the module doc); a change of format only passes the pixels
/// through.
pub fn convert(o: &ConvertOptions, progress: &dyn Progress) -> Result<Converted> {
    if o.width == Some(0) || o.face_size == Some(0) {
        return Err(PipelineError::parameter(
            "--width and --face-size must be at least 1",
        ));
    }
    // Every output checked before any work (issue 13): the faces' files for cube faces.
    let mut inputs = vec![o.input.clone()];
    if o.from == Some(EnvMapping::CubeFaces) {
        inputs = envmap_files::face_paths(&o.input);
    }
    let input_refs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let to = o.to.or(o.from);
    let outputs = match to {
        Some(EnvMapping::CubeFaces) => envmap_files::face_paths(&o.output),
        _ => vec![o.output.clone()],
    };
    for out in &outputs {
        envmap_files::check_output(out, &input_refs)?;
    }
    if is_format_only(o) {
        return pass_through(o, progress);
    }
    let env = envmap_files::load(&o.input, o.from)?;
    envmap_files::note_clamped(&env, progress);
    let to = o.to.or(o.from).unwrap_or(EnvMapping::Single(env.mapping));
    let to_mapping = to.in_memory();
    let (w, h) = output_size(o, to, &env)?;
    let asked = match (o.face_size, o.width) {
        (Some(s), _) => format!("--face-size {s}"),
        (None, Some(w)) => format!("--width {w}"),
        (None, None) => format!("{} at the input's resolution", to.name()),
    };
    crate::output_paths::check_output_pixels(&asked, w, h)?;
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
        files: written(files, &out, to),
        mapping: to.name(),
    })
}
