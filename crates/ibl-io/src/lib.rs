//! File formats for iblkit: Radiance RGBE (`.hdr`), OpenEXR, PFM, PNG and JPEG in; the same out
//! (PNG/JPEG through the tone-mapping display transform of `ibl_core::tonemap`); all presented as linear radiance
//! `Image<Rgb>` with row 0 at the top (`docs/CONVENTIONS.md`, sections 2, 4 and 7).
//!
//! - [`read_image`] picks the decoder by extension, checks header sizes against [`Limits`] (and
//!   against what the file can hold) before allocating, decodes, then clamps negative, NaN and
//!   infinite values to 0 and counts them in a [`SanitizeReport`].
//! - [`write_image`] encodes by extension and writes atomically (temporary file + rename);
//!   [`ensure_output_is_not_input`] refuses to overwrite an input.
//! - The per-format modules ([`hdr`], [`exr`], [`pfm`], [`ldr`]) are pure byte-level codecs
//!   (`decode(bytes, limits) -> RawImage`, `encode(image) -> bytes`), for fuzzing and benches.
//!
//! - [`photometry`] reads luminaires' intensity distributions (IES LM-63 and EULUMDAT files)
//!   into the candela tables of `ibl_light::goniometric`, each symmetry expanded.
//!
//! Errors name the file and say whether the input was at fault ([`IoError::is_bad_input`]).
//! The library never prints and never panics on file content.
//!
//! Writes go to a temporary file in the output's own directory which is then renamed over the
//! destination, so a reader never sees a half-written file and a failed write leaves any previous
//! file untouched (`docs/CONVENTIONS.md`, section 7).

pub mod area_light_file;
mod bounded_read;
pub mod dds;
mod error;
pub mod exr;
mod format;
pub mod hdr;
pub mod header;
pub mod ktx2;
pub mod ldr;
pub mod light_export;
pub mod light_file;
pub mod luminaire_file;
pub mod mesh_file;
pub mod pfm;
pub mod photo;
pub mod photometry;
pub mod sanitize;
pub mod scene_file;
pub mod scene_write;
pub mod sh_file;
pub mod temp_files;
pub mod texture;

use std::io::Write;
use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb};

pub use bounded_read::{check_regular, read_bounded, read_prefix, read_text};
pub use error::{DecodeError, EncodeError, IoError, is_destination_fault};
pub use exr::{ExrCompression, ExrOptions, ExrPrecision};
pub use format::{
    DEFAULT_MAX_PIXELS, ImageFormat, Limits, MAX_MAX_PIXELS, MAX_PIXELS_VARIABLE, RawImage,
    max_pixels_from_environment, set_default_max_pixels,
};
pub use header::{ImageHeader, read_header};
use ibl_core::tonemap::{Display, to_srgb8};
pub use light_export::{ExportError, ExportOptions, LightFormat, write_light_file};
pub use mesh_file::{LoadedMesh, MeshLimits, read_mesh};
pub use photometry::{
    PhotometricFile, PhotometryLimits, StatedFlux, read_photometry, read_photometry_with_limits,
};
pub use sanitize::{SanitizeReport, sanitize};
pub use scene_file::{LoadedScene, read_meshes, read_scene};
pub use sh_file::{ShFile, ShFileFormat, ShQuantity, read_sh_file, write_sh_file};
pub use texture::{DecodedTexture, TexelFormat, Texture, TextureKind, TextureLevel};

/// An image read from a file, with what reading did to it.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedImage {
    /// Linear radiance, row 0 at the top; negative, NaN and infinite values clamped to 0.
    pub image: Image<Rgb>,
    /// The file's format (from its extension).
    pub format: ImageFormat,
    /// How many values were clamped.
    pub report: SanitizeReport,
    /// Human-readable encoding, e.g. `"OpenEXR, ZIP, half"` or `"Radiance RGBE, RLE"`.
    pub details: String,
}

/// How [`write_image`] encodes each format.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WriteOptions {
    /// Precision and compression of `.exr` output.
    pub exr: ExrOptions,
    /// Exposure and tone curve of `.png`/`.jpg` output.
    pub display: Display,
    /// Texel format of `.ktx2`/`.dds` output (half floats by default).
    pub texture: TexelFormat,
}

fn format_of(path: &Path) -> Result<ImageFormat, IoError> {
    ImageFormat::from_path(path).ok_or_else(|| IoError::Unsupported {
        path: path.to_path_buf(),
        what: "file extension (expected .hdr, .pic, .exr, .pfm, .png, .jpg, .jpeg, .ktx2 or .dds)"
            .into(),
    })
}

/// Decodes bytes of a known format (no sanitising).
fn decode(format: ImageFormat, bytes: &[u8], limits: &Limits) -> Result<RawImage, DecodeError> {
    match format {
        ImageFormat::Hdr => hdr::decode(bytes, limits),
        ImageFormat::Exr => exr::decode(bytes, limits),
        ImageFormat::Pfm => pfm::decode(bytes, limits),
        ImageFormat::Png | ImageFormat::Jpeg => ldr::decode(bytes, limits),
        ImageFormat::Ktx2 => ktx2::decode(bytes, limits).map(texture_level0),
        ImageFormat::Dds => dds::decode(bytes, limits).map(texture_level0),
    }
}

/// Level 0 of a texture as an RGB image: a 2D texture as it is (a two-channel table with blue
/// 0), a cube map as its six faces side by side, `+X -X +Y -Y +Z -Z` (the cube-strip layout).
fn texture_level0(decoded: DecodedTexture) -> RawImage {
    let DecodedTexture {
        texture, details, ..
    } = decoded;
    let channels = texture.channels;
    let faces = texture.kind.faces();
    let level = texture.levels.into_iter().next();
    let (w, h, data) = match level {
        Some(l) => (l.width, l.height, l.faces),
        None => (0, 0, Vec::new()),
    };
    let image = Image::from_fn_par(w * faces, h, |x, y| {
        let (face, i) = (x / w.max(1), x % w.max(1));
        let t = &data[face][(y * w + i) * channels..];
        Rgb::new(t[0], t[1], if channels > 2 { t[2] } else { 0.0 })
    });
    RawImage { image, details }
}

/// Reads a KTX2 or DDS texture with every level and face (the format from the extension).
pub fn read_texture(path: &Path, limits: &Limits) -> Result<DecodedTexture, IoError> {
    let format = format_of(path)?;
    let bytes = read_bounded(path, limits.max_file_bytes())?;
    let decoded = match format {
        ImageFormat::Ktx2 => ktx2::decode(&bytes, limits),
        ImageFormat::Dds => dds::decode(&bytes, limits),
        _ => {
            return Err(IoError::Unsupported {
                path: path.to_path_buf(),
                what: format!(
                    "{} is not a texture container (use .ktx2 or .dds)",
                    format.name()
                ),
            });
        }
    };
    decoded.map_err(|e| e.with_path(path))
}

/// Encodes a texture for `.ktx2` or `.dds` in `texel` format.
pub fn encode_texture(
    format: ImageFormat,
    texture: &Texture,
    texel: TexelFormat,
) -> Result<Vec<u8>, EncodeError> {
    match format {
        ImageFormat::Ktx2 => ktx2::encode(texture, texel).map_err(EncodeError::new),
        ImageFormat::Dds => dds::encode(texture, texel).map_err(EncodeError::new),
        other => Err(EncodeError::new(format!(
            "{} cannot hold a texture with mip levels (use .ktx2 or .dds)",
            other.name()
        ))),
    }
}

/// Writes a texture (mip levels, cube faces) as `.ktx2` or `.dds` (by extension), atomically.
pub fn write_texture(path: &Path, texture: &Texture, texel: TexelFormat) -> Result<(), IoError> {
    let format = format_of(path)?;
    if !format.is_texture() {
        return Err(IoError::Unsupported {
            path: path.to_path_buf(),
            what: "a texture with mip levels needs a .ktx2 or .dds file".into(),
        });
    }
    let bytes = encode_texture(format, texture, texel).map_err(|e| e.with_path(path))?;
    write_atomically(path, &bytes)
}

/// A one-level texture of an RGB image (`Flat`), or of the six faces of a cube strip (`Cube`:
/// the image must be `6 S x S`).
pub fn texture_of_image(image: &Image<Rgb>, kind: TextureKind) -> Result<Texture, EncodeError> {
    let faces = kind.faces();
    let (w, h) = (image.width() / faces, image.height());
    if w == 0 || h == 0 || w * faces != image.width() || (kind == TextureKind::Cube && w != h) {
        return Err(EncodeError::new(format!(
            "a {} x {} image is not a {}",
            image.width(),
            image.height(),
            if kind == TextureKind::Cube {
                "6:1 strip of square cube faces"
            } else {
                "texture"
            }
        )));
    }
    let faces = (0..faces)
        .map(|f| {
            (0..h)
                .flat_map(|y| image.row(y)[f * w..(f + 1) * w].iter())
                .flat_map(|p| [p.r, p.g, p.b])
                .collect()
        })
        .collect();
    Ok(Texture {
        kind,
        channels: 3,
        levels: vec![TextureLevel {
            width: w,
            height: h,
            faces,
        }],
    })
}

/// Reads every image in `dir` whose extension is `extension` (case-insensitive), in file-name
/// order, with the default [`Limits`]: `(file stem, image)` pairs. An error names the first file
/// that cannot be read.
pub fn read_images_in(dir: &Path, extension: &str) -> Result<Vec<(String, Image<Rgb>)>, IoError> {
    let mut paths = list_dir(dir)?;
    paths.retain(|p| {
        p.extension()
            .is_some_and(|x| x.eq_ignore_ascii_case(extension))
    });
    paths
        .into_iter()
        .map(|p| {
            let name = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            read_image(&p).map(|loaded| (name, loaded.image))
        })
        .collect()
}

/// The entries of a folder, sorted by path. An unreadable or missing folder is
/// [`IoError::Io`] (bad input when it does not exist).
pub fn list_dir(dir: &Path) -> Result<Vec<PathBuf>, IoError> {
    let entries = std::fs::read_dir(dir).map_err(|e| IoError::read(dir, e))?;
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    Ok(paths)
}

/// Creates a folder and its parents for outputs (nothing to do when it exists).
pub fn create_dir_all(dir: &Path) -> Result<(), IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::write(dir, e))
}

/// Reads an image file with the default [`Limits`].
pub fn read_image(path: &Path) -> Result<LoadedImage, IoError> {
    read_image_with_limits(path, &Limits::default())
}

/// Reads an image file: the format comes from the extension; sizes are checked against `limits`
/// before allocating; negative, NaN and infinite values are clamped to 0 and counted.
pub fn read_image_with_limits(path: &Path, limits: &Limits) -> Result<LoadedImage, IoError> {
    let format = format_of(path)?;
    let bytes = read_bounded(path, limits.max_file_bytes())?;
    let raw = decode(format, &bytes, limits).map_err(|e| e.with_path(path))?;
    drop(bytes);
    let mut image = raw.image;
    let report = sanitize(&mut image);
    Ok(LoadedImage {
        image,
        format,
        report,
        details: raw.details,
    })
}

/// Encodes an image for a format: `.hdr` RLE, `.exr` per `options.exr`, `.pfm` little-endian,
/// `.png`/`.jpg` tone-mapped with `options.display` (JPEG quality 92), `.ktx2`/`.dds` as one 2D
/// level in `options.texture` (use [`write_texture`] for cube maps and mip chains).
pub fn encode_image(
    format: ImageFormat,
    image: &Image<Rgb>,
    options: &WriteOptions,
) -> Result<Vec<u8>, EncodeError> {
    if image.is_empty() {
        return Err(EncodeError::new("cannot write an empty image"));
    }
    match format {
        ImageFormat::Hdr => Ok(hdr::encode(image)),
        ImageFormat::Exr => exr::encode(image, &options.exr),
        ImageFormat::Pfm => Ok(pfm::encode(image, pfm::ByteOrder::LittleEndian)),
        ImageFormat::Png => ldr::encode_png(&to_srgb8(image, &options.display)),
        ImageFormat::Jpeg => {
            ldr::encode_jpeg(&to_srgb8(image, &options.display), ldr::JPEG_QUALITY)
        }
        ImageFormat::Ktx2 | ImageFormat::Dds => {
            let texture = texture_of_image(image, TextureKind::Flat)?;
            encode_texture(format, &texture, options.texture)
        }
    }
}

/// Writes an image, choosing the format by extension, atomically: the bytes go to a temporary
/// file in the same directory which is synced and then renamed over `path` (mode 0644 on Unix).
pub fn write_image(path: &Path, image: &Image<Rgb>, options: &WriteOptions) -> Result<(), IoError> {
    let format = format_of(path)?;
    let bytes = encode_image(format, image, options).map_err(|e| e.with_path(path))?;
    write_atomically(path, &bytes)
}

/// Writes `bytes` to `path` through a temporary file in the same directory, synced, then renamed
/// over `path` (mode 0644 on Unix); also useful for non-image outputs such as JSON. The temporary
/// file is named and listed as [`temp_files`] says, so an interrupt removes it and a later run
/// cleans what a `kill -9` left.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let err = |e| IoError::write(path, e);
    temp_files::clean_stale_in(dir);
    let mut tmp = tempfile::Builder::new()
        .prefix(&temp_files::temp_prefix())
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(err)?;
    let _listed = temp_files::TempRegistration::new(tmp.path());
    tmp.write_all(bytes).map_err(err)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(err)?;
    }
    tmp.as_file().sync_all().map_err(err)?;
    tmp.persist(path).map_err(|e| err(e.error))?;
    Ok(())
}

/// `path` made absolute with symlinks resolved; for a file that does not exist yet, its parent
/// is resolved and the file name appended. `None` when even the parent cannot be resolved.
fn resolve(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let name = path.file_name()?;
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Some(parent.canonicalize().ok()?.join(name))
}

#[cfg(unix)]
fn same_inode(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_inode(_: &Path, _: &Path) -> bool {
    false
}

/// Fails with [`IoError::SameAsInput`] if `output` names the same file as any of `inputs`
/// (same canonical path, through symlinks and `..`, or the same inode through a hard link).
/// Inputs that do not exist are ignored.
pub fn ensure_output_is_not_input(output: &Path, inputs: &[&Path]) -> Result<(), IoError> {
    let out = resolve(output);
    for input in inputs {
        let same_path = match (&out, input.canonicalize()) {
            (Some(o), Ok(i)) => *o == i,
            _ => false,
        };
        if same_path || same_inode(output, input) {
            return Err(IoError::SameAsInput {
                path: output.to_path_buf(),
            });
        }
    }
    Ok(())
}
