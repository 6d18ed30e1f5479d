//! Environment maps on disk: one image file in any mapping, or a cube map as six face files.
//!
//! Six-file cube maps are named by a pattern containing `{face}` (replaced by `px nx py ny pz nz`
//! for +X -X +Y -Y +Z -Z); a path without `{face}` gets `_px` etc. before its extension. Inside,
//! a six-file cube is a horizontal strip, so the mapping code sees one image.

use std::path::{Path, PathBuf};

use anyhow::Context;
use ibl_core::{Image, Rgb};
use ibl_io::{ImageFormat, LoadedImage, SanitizeReport, WriteOptions};
use ibl_mapping::{CUBE_FACE_NAMES, CubeLayout, Mapping};

use crate::failure::usage;

/// A mapping named on the command line: one image in a mapping, or six cube-face files.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MappingArg {
    /// A single image in this mapping.
    Single(Mapping),
    /// Six files, one per cube face.
    CubeFaces,
}

impl MappingArg {
    /// Parses a mapping name (`cube-faces` or any name [`Mapping::parse`] knows); `fov_deg` is
    /// the field of view for the fisheye mappings.
    pub fn parse(name: &str, fov_deg: f32) -> anyhow::Result<MappingArg> {
        if matches!(name, "cube-faces" | "faces" | "cube-6") {
            return Ok(MappingArg::CubeFaces);
        }
        Mapping::parse(name, fov_deg).map(MappingArg::Single).ok_or_else(|| {
            usage(format!(
                "unknown mapping `{name}` (expected latlong, angular, mirror-ball, cube-hcross, \
                 cube-vcross, cube-strip, cube-faces, fisheye or dual-fisheye)"
            ))
        })
    }

    /// The mapping of the in-memory image.
    pub fn in_memory(self) -> Mapping {
        match self {
            MappingArg::Single(m) => m,
            MappingArg::CubeFaces => Mapping::Cube(CubeLayout::HorizontalStrip),
        }
    }

    /// Name for messages and reports.
    pub fn name(self) -> String {
        match self {
            MappingArg::Single(m) => m.name(),
            MappingArg::CubeFaces => "cube-faces".to_string(),
        }
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

/// Reads an environment map; the mapping is `mapping` or, when `None`, guessed from the shape.
pub fn load(path: &Path, mapping: Option<MappingArg>) -> anyhow::Result<LoadedEnv> {
    if mapping == Some(MappingArg::CubeFaces) {
        return load_faces(path);
    }
    let LoadedImage {
        image,
        format,
        report,
        details,
    } = ibl_io::read_image(path)?;
    let mapping = match mapping {
        Some(m) => m.in_memory(),
        None => Mapping::guess_from_shape(image.width(), image.height()),
    };
    mapping
        .check_shape(image.width(), image.height())
        .with_context(|| format!("{}: not a {} image", path.display(), mapping.name()))?;
    Ok(LoadedEnv {
        image,
        mapping,
        format,
        details,
        report,
        files: vec![path.to_path_buf()],
    })
}

fn load_faces(pattern: &Path) -> anyhow::Result<LoadedEnv> {
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
    let report = report.ok_or_else(|| anyhow::anyhow!("no cube face read"))?;
    let faces: [Image<Rgb>; 6] = faces
        .try_into()
        .map_err(|_| anyhow::anyhow!("expected six cube faces"))?;
    let image = ibl_mapping::join_cube_faces(&faces, CubeLayout::HorizontalStrip)
        .with_context(|| format!("{}: cube faces do not fit together", pattern.display()))?;
    let (format, details) = first.ok_or_else(|| anyhow::anyhow!("no cube face read"))?;
    Ok(LoadedEnv {
        image,
        mapping: Mapping::Cube(CubeLayout::HorizontalStrip),
        format,
        details,
        report,
        files: paths,
    })
}

/// Writes an environment map (six files for [`MappingArg::CubeFaces`]), refusing to overwrite
/// any of `inputs`. Returns the files written.
pub fn save(
    path: &Path,
    image: &Image<Rgb>,
    mapping: MappingArg,
    options: &WriteOptions,
    inputs: &[&Path],
) -> anyhow::Result<Vec<PathBuf>> {
    let targets: Vec<(PathBuf, Image<Rgb>)> = match mapping {
        MappingArg::Single(_) => vec![(path.to_path_buf(), image.clone())],
        MappingArg::CubeFaces => {
            let faces = ibl_mapping::split_cube_faces(image, CubeLayout::HorizontalStrip)?;
            face_paths(path).into_iter().zip(faces).collect()
        }
    };
    for (p, _) in &targets {
        if ImageFormat::from_path(p).is_none() {
            return Err(usage(format!(
                "{}: unknown output format (use .exr, .hdr, .pfm, .png or .jpg)",
                p.display()
            )));
        }
        ibl_io::ensure_output_is_not_input(p, inputs)?;
    }
    for (p, img) in &targets {
        ibl_io::write_image(p, img, options)?;
    }
    Ok(targets.into_iter().map(|(p, _)| p).collect())
}
