//! Environment maps on disk: one image file in any mapping, or a cube map as six face files (the
//! cube file sets every front end reads and writes the same way).
//!
//! Six-file cube maps are named by a pattern containing `{face}` (replaced by `px nx py ny pz nz`
//! for +X -X +Y -Y +Z -Z); a path without `{face}` gets `_px` etc. before its extension. Inside,
//! a six-file cube is a horizontal strip, so the mapping code sees one image.

use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};
use ibl_io::{ImageFormat, LoadedImage, SanitizeReport, WriteOptions};
use ibl_mapping::{CUBE_FACE_NAMES, CubeLayout, Mapping};

use crate::error::{Context, PipelineError, Result};
use crate::progress::Progress;

/// How an environment map lies on disk: one image in a mapping, or six cube-face files.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EnvMapping {
    /// A single image in this mapping.
    Single(Mapping),
    /// Six files, one per cube face.
    CubeFaces,
}

impl EnvMapping {
    /// Parses a mapping name (`cube-faces` or any name [`Mapping::parse`] knows); `fov_deg` is
    /// the field of view for the fisheye mappings.
    pub fn parse(name: &str, fov_deg: f32) -> Result<EnvMapping> {
        if matches!(name, "cube-faces" | "faces" | "cube-6") {
            return Ok(EnvMapping::CubeFaces);
        }
        Mapping::parse(name, fov_deg).map(EnvMapping::Single).ok_or_else(|| {
            PipelineError::parameter(format!(
                "unknown mapping `{name}` (expected latlong, angular, mirror-ball, cube-hcross, \
                 cube-vcross, cube-strip, cube-vstrip, cube-faces, fisheye or dual-fisheye)"
            ))
        })
    }

    /// The mapping of the in-memory image.
    pub fn in_memory(self) -> Mapping {
        match self {
            EnvMapping::Single(m) => m,
            EnvMapping::CubeFaces => Mapping::Cube(CubeLayout::HorizontalStrip),
        }
    }

    /// Name for messages and reports.
    pub fn name(self) -> String {
        match self {
            EnvMapping::Single(m) => m.name(),
            EnvMapping::CubeFaces => "cube-faces".to_string(),
        }
    }
}

/// Checks before any work that `path` names an image format iblkit writes and no input.
pub fn check_output(path: &Path, inputs: &[&Path]) -> Result<()> {
    if ImageFormat::from_path(path).is_none() {
        return Err(PipelineError::parameter(format!(
            "{}: unknown output format (use .exr, .hdr, .pfm, .png or .jpg)",
            path.display()
        )));
    }
    crate::output_paths::check_output_path(path, inputs)?;
    Ok(())
}

/// Tells the user, through `progress`, how many invalid values reading clamped, if any.
pub fn note_clamped(env: &LoadedEnv, progress: &dyn Progress) {
    if let Some(first) = env.files.first() {
        note_sanitized(first, &env.report, progress);
    }
}

/// The same for one file read with `ibl_io::read_image`.
pub fn note_sanitized(path: &Path, r: &SanitizeReport, progress: &dyn Progress) {
    if r.negative_values + r.nonfinite_values > 0 {
        progress.note(&format!(
            "note: {}: clamped {} negative and {} NaN/Inf values to 0",
            path.display(),
            r.negative_values,
            r.nonfinite_values
        ));
    }
}

/// An environment map read from disk, with what reading it found.
pub struct LoadedEnv {
    /// Radiance, invalid values clamped to 0.
    pub image: Image<Rgb>,
    /// Mapping of `image`.
    pub mapping: Mapping,
    /// File format of the (first) file.
    pub format: ImageFormat,
    /// Encoding details of the (first) file.
    pub details: String,
    /// Invalid values found, summed over all files read.
    pub report: SanitizeReport,
    /// Every file read.
    pub files: Vec<PathBuf>,
}

/// The six face files for a pattern, in the order +X -X +Y -Y +Z -Z.
pub fn face_paths(pattern: &Path) -> Vec<PathBuf> {
    let text = pattern.to_string_lossy();
    CUBE_FACE_NAMES
        .iter()
        .map(|face| {
            if text.contains("{face}") {
                PathBuf::from(text.replace("{face}", face))
            } else {
                let stem = pattern
                    .file_stem()
                    .map(|s| s.to_string_lossy())
                    .unwrap_or_default();
                let name = match pattern.extension() {
                    Some(ext) => format!("{stem}_{face}.{}", ext.to_string_lossy()),
                    None => format!("{stem}_{face}"),
                };
                pattern.with_file_name(name)
            }
        })
        .collect()
}

/// The error for an image whose shape names no mapping (issue 13: never taken for lat-long).
pub fn undetectable(path: &Path, width: usize, height: usize) -> PipelineError {
    PipelineError::parameter(format!(
        "{}: cannot tell the mapping of a {width} x {height} image from its shape (known shapes: \
         2:1 lat-long, 1:1 angular or mirror ball, 4:3 / 3:4 cube cross, 6:1 / 1:6 cube strip); \
         name it with --mapping (or --from)",
        path.display()
    ))
}

/// Reads an environment map; the mapping is `mapping` or, when `None`, detected from the shape
/// ([`Mapping::detect_from_shape`]; a shape that names no mapping is refused).
pub fn load(path: &Path, mapping: Option<EnvMapping>) -> Result<LoadedEnv> {
    if mapping == Some(EnvMapping::CubeFaces) {
        return load_faces(path);
    }
    bind(path, ibl_io::read_image(path)?, mapping)
}

/// Binds an image read from `path` to `mapping` or, when `None`, to the mapping its shape names
/// (a shape that names none is refused), after checking the shape fits.
pub fn bind(path: &Path, loaded: LoadedImage, mapping: Option<EnvMapping>) -> Result<LoadedEnv> {
    let LoadedImage {
        image,
        format,
        report,
        details,
    } = loaded;
    let mapping = match mapping {
        Some(m) => m.in_memory(),
        None => Mapping::detect_from_shape(image.width(), image.height())
            .ok_or_else(|| undetectable(path, image.width(), image.height()))?,
    };
    mapping
        .check_shape(image.width(), image.height())
        .context(format!(
            "{}: not {} image",
            path.display(),
            ibl_mapping::with_article(&mapping.name())
        ))?;
    Ok(LoadedEnv {
        image,
        mapping,
        format,
        details,
        report,
        files: vec![path.to_path_buf()],
    })
}

fn load_faces(pattern: &Path) -> Result<LoadedEnv> {
    let paths = face_paths(pattern);
    let mut faces = Vec::with_capacity(6);
    let mut report: Option<SanitizeReport> = None;
    let mut first: Option<(ImageFormat, String)> = None;
    for p in &paths {
        let loaded = ibl_io::read_image(p)?;
        report = Some(report.map_or(loaded.report, |r| r.merged(loaded.report)));
        first.get_or_insert((loaded.format, loaded.details));
        faces.push(loaded.image);
    }
    // `face_paths` always names six files, so six were read.
    let (Some(report), Some((format, details)), Ok(faces)) =
        (report, first, <[Image<Rgb>; 6]>::try_from(faces))
    else {
        return Err(PipelineError::parameter(format!(
            "{}: expected six cube faces",
            pattern.display()
        )));
    };
    let image = ibl_mapping::join_cube_faces(&faces, CubeLayout::HorizontalStrip).context(
        format!("{}: cube faces do not fit together", pattern.display()),
    )?;
    Ok(LoadedEnv {
        image,
        mapping: Mapping::Cube(CubeLayout::HorizontalStrip),
        format,
        details,
        report,
        files: paths,
    })
}

/// Writes an environment map (six files for [`EnvMapping::CubeFaces`]), refusing to overwrite
/// any of `inputs`. Returns the files written.
pub fn save(
    path: &Path,
    image: &Image<Rgb>,
    mapping: EnvMapping,
    options: &WriteOptions,
    inputs: &[&Path],
) -> Result<Vec<PathBuf>> {
    let targets: Vec<(PathBuf, Image<Rgb>)> = match mapping {
        EnvMapping::Single(_) => vec![(path.to_path_buf(), image.clone())],
        EnvMapping::CubeFaces => {
            let faces = ibl_mapping::split_cube_faces(image, CubeLayout::HorizontalStrip)?;
            face_paths(path).into_iter().zip(faces).collect()
        }
    };
    for (p, _) in &targets {
        check_output(p, inputs)?;
    }
    for (p, img) in &targets {
        ibl_io::write_image(p, img, options)?;
    }
    Ok(targets.into_iter().map(|(p, _)| p).collect())
}
