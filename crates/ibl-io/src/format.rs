//! The file formats iblkit reads and writes, the size limits every decoder enforces before it
//! allocates anything, and the raw (unsanitised) result of a decoder.
//!
//! The format of a file is chosen by its extension (so that `ibl convert a.exr b.hdr` does what
//! it says); the magic bytes are only used to give a helpful hint when the two disagree.

use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use ibl_core::{Image, Rgb};

use crate::error::DecodeError;

/// The KTX 2.0 file identifier, the first 12 bytes of every `.ktx2` file (KTX 2.0
/// specification, section 3.1).
pub const KTX2_IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// An image file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ImageFormat {
    /// Radiance RGBE (`.hdr`, `.pic`).
    Hdr,
    /// OpenEXR (`.exr`).
    Exr,
    /// Portable float map (`.pfm`).
    Pfm,
    /// PNG (`.png`), 8 or 16 bits, sRGB.
    Png,
    /// JPEG (`.jpg`, `.jpeg`), sRGB.
    Jpeg,
    /// KTX 2.0 texture (`.ktx2`): level 0, a cube map as its six faces side by side.
    Ktx2,
    /// DirectDraw Surface texture (`.dds`): level 0, a cube map as its six faces side by side.
    Dds,
}

impl ImageFormat {
    /// Every format, in a fixed order.
    pub const ALL: [ImageFormat; 7] = [
        ImageFormat::Hdr,
        ImageFormat::Exr,
        ImageFormat::Pfm,
        ImageFormat::Png,
        ImageFormat::Jpeg,
        ImageFormat::Ktx2,
        ImageFormat::Dds,
    ];

    /// The format named by the path's extension (case-insensitive): `.hdr`/`.pic`, `.exr`, `.pfm`,
    /// `.png`, `.jpg`/`.jpeg`, `.ktx2`, `.dds`. `None` for any other or no extension.
    pub fn from_path(path: &Path) -> Option<ImageFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "hdr" | "pic" => Some(ImageFormat::Hdr),
            "exr" => Some(ImageFormat::Exr),
            "pfm" => Some(ImageFormat::Pfm),
            "png" => Some(ImageFormat::Png),
            "jpg" | "jpeg" => Some(ImageFormat::Jpeg),
            "ktx2" => Some(ImageFormat::Ktx2),
            "dds" => Some(ImageFormat::Dds),
            _ => None,
        }
    }

    /// Short lower-case name: `"hdr"`, `"exr"`, `"pfm"`, `"png"`, `"jpeg"`, `"ktx2"` or `"dds"`.
    pub fn name(self) -> &'static str {
        match self {
            ImageFormat::Hdr => "hdr",
            ImageFormat::Exr => "exr",
            ImageFormat::Pfm => "pfm",
            ImageFormat::Png => "png",
            ImageFormat::Jpeg => "jpeg",
            ImageFormat::Ktx2 => "ktx2",
            ImageFormat::Dds => "dds",
        }
    }

    /// Whether the format stores linear high-dynamic-range values (`.hdr`, `.exr`, `.pfm`,
    /// `.ktx2`, `.dds`) rather than 8/16-bit display-referred sRGB.
    pub fn is_hdr(self) -> bool {
        !matches!(self, ImageFormat::Png | ImageFormat::Jpeg)
    }

    /// Whether the format is a GPU texture container (KTX2, DDS) that can hold a cube map and
    /// mip levels.
    pub fn is_texture(self) -> bool {
        matches!(self, ImageFormat::Ktx2 | ImageFormat::Dds)
    }

    /// The format the first bytes of a file look like, if any (used for error hints).
    pub fn sniff(bytes: &[u8]) -> Option<ImageFormat> {
        if bytes.starts_with(b"#?") {
            Some(ImageFormat::Hdr)
        } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            Some(ImageFormat::Exr)
        } else if bytes.len() >= 3
            && (bytes.starts_with(b"PF") || bytes.starts_with(b"Pf"))
            && bytes[2].is_ascii_whitespace()
        {
            Some(ImageFormat::Pfm)
        } else if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            Some(ImageFormat::Png)
        } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
            Some(ImageFormat::Jpeg)
        } else if bytes.starts_with(&KTX2_IDENTIFIER) {
            Some(ImageFormat::Ktx2)
        } else if bytes.starts_with(b"DDS ") {
            Some(ImageFormat::Dds)
        } else {
            None
        }
    }
}

/// Builds the "bad magic" error of a decoder, with a hint when the bytes are another format.
pub(crate) fn wrong_magic(expected: &str, bytes: &[u8]) -> DecodeError {
    let hint = match ImageFormat::sniff(bytes) {
        Some(actual) => format!(
            " (the content looks like {}; is the extension wrong?)",
            actual.name()
        ),
        None if bytes.is_empty() => " (the file is empty)".to_owned(),
        None => String::new(),
    };
    DecodeError::invalid(format!("not {expected}: wrong magic bytes{hint}"))
}

/// Size limits checked against a file's header before any pixel memory is allocated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest accepted width in pixels (default 65536).
    pub max_width: usize,
    /// Largest accepted height in pixels (default 65536).
    pub max_height: usize,
    /// Largest accepted `width * height` (default 2^28, i.e. 3 GiB of `Rgb` pixels, or what the
    /// process set: [`set_default_max_pixels`], [`MAX_PIXELS_VARIABLE`]).
    pub max_pixels: usize,
}

/// The built-in pixel limit, 2^28 pixels (3 GiB of `Rgb` pixels).
pub const DEFAULT_MAX_PIXELS: usize = 1 << 28;

/// The largest pixel limit a user may set: every 65536 x 65536 image.
pub const MAX_MAX_PIXELS: usize = 1 << 32;

/// The environment variable that sets the pixel limit of [`Limits::default`] for a process.
pub const MAX_PIXELS_VARIABLE: &str = "IBL_MAX_PIXELS";

/// The pixel limit set by [`set_default_max_pixels`]; 0 when none was set.
static SET_MAX_PIXELS: AtomicUsize = AtomicUsize::new(0);

/// Sets the pixel limit of [`Limits::default`] for the rest of the process (the CLI's
/// `--max-pixels`), over [`MAX_PIXELS_VARIABLE`]. Values outside `1..=MAX_MAX_PIXELS` are
/// refused with a message.
pub fn set_default_max_pixels(max_pixels: usize) -> Result<(), String> {
    check_max_pixels(max_pixels)?;
    SET_MAX_PIXELS.store(max_pixels, Ordering::Relaxed);
    Ok(())
}

/// The pixel limit [`MAX_PIXELS_VARIABLE`] asks for: `Ok(None)` when it is not set, an error
/// naming the variable when it is not a whole number in `1..=MAX_MAX_PIXELS`.
pub fn max_pixels_from_environment() -> Result<Option<usize>, String> {
    let Some(raw) = std::env::var_os(MAX_PIXELS_VARIABLE) else {
        return Ok(None);
    };
    let text = raw.to_string_lossy();
    let value: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("{MAX_PIXELS_VARIABLE}={text:?} is not a whole number of pixels"))?;
    check_max_pixels(value).map_err(|e| format!("{MAX_PIXELS_VARIABLE}: {e}"))?;
    Ok(Some(value))
}

fn check_max_pixels(value: usize) -> Result<(), String> {
    if (1..=MAX_MAX_PIXELS).contains(&value) {
        Ok(())
    } else {
        Err(format!(
            "a pixel limit of {value} is not in 1..={MAX_MAX_PIXELS}"
        ))
    }
}

/// The process's pixel limit: [`set_default_max_pixels`], else a valid [`MAX_PIXELS_VARIABLE`]
/// (an invalid one is ignored here; the CLI refuses it at start), else [`DEFAULT_MAX_PIXELS`].
fn default_max_pixels() -> usize {
    static FROM_ENVIRONMENT: OnceLock<Option<usize>> = OnceLock::new();
    match SET_MAX_PIXELS.load(Ordering::Relaxed) {
        0 => FROM_ENVIRONMENT
            .get_or_init(|| max_pixels_from_environment().ok().flatten())
            .unwrap_or(DEFAULT_MAX_PIXELS),
        set => set,
    }
}

impl Default for Limits {
    /// 65536 pixels a side and [`DEFAULT_MAX_PIXELS`] in all, unless the process set another
    /// pixel limit ([`set_default_max_pixels`], [`MAX_PIXELS_VARIABLE`]).
    fn default() -> Self {
        Limits {
            max_width: 65536,
            max_height: 65536,
            max_pixels: default_max_pixels(),
        }
    }
}

impl Limits {
    /// No limits at all (still overflow-checked); for trusted files only.
    pub const UNLIMITED: Limits = Limits {
        max_width: usize::MAX,
        max_height: usize::MAX,
        max_pixels: usize::MAX,
    };

    /// The largest image file read whole under these limits, bytes: 24 bytes a pixel (an
    /// uncompressed 32-bit RGBA OpenEXR is 16, a cube texture's mip chain adds a third) plus
    /// 16 MiB of headers, tables and metadata. Reads are bounded by it before anything is
    /// decoded, so a device or a sparse file of any size is refused.
    pub fn max_file_bytes(&self) -> u64 {
        (self.max_pixels as u64)
            .saturating_mul(24)
            .saturating_add(16 << 20)
    }

    /// Checks a header's size: zero sizes are invalid, sizes over a limit are a
    /// [`DecodeError::Limits`]. Returns `width * height`.
    pub fn check(&self, width: u64, height: u64) -> Result<usize, DecodeError> {
        if width == 0 || height == 0 {
            return Err(DecodeError::invalid(format!(
                "zero image size {width} x {height}"
            )));
        }
        let over = |what: &str, value: u64, max: usize| {
            DecodeError::Limits(format!(
                "{what} {value} in the header is over the limit of {max} (image {width} x {height})"
            ))
        };
        if width > self.max_width as u64 {
            return Err(over("width", width, self.max_width));
        }
        if height > self.max_height as u64 {
            return Err(over("height", height, self.max_height));
        }
        let pixels = width
            .checked_mul(height)
            .and_then(|p| usize::try_from(p).ok())
            .ok_or_else(|| over("pixel count", u64::MAX, self.max_pixels))?;
        if pixels > self.max_pixels {
            return Err(over("pixel count", pixels as u64, self.max_pixels));
        }
        Ok(pixels)
    }
}

/// What a byte-level decoder returns: the pixels exactly as stored (converted to linear `f32`,
/// row 0 at the top, but **not** sanitised: negative, NaN and infinite values are kept).
#[derive(Clone, Debug, PartialEq)]
pub struct RawImage {
    /// Linear RGB pixels, row 0 at the top.
    pub image: Image<Rgb>,
    /// Human-readable description of the encoding, e.g. `"Radiance RGBE, RLE"`.
    pub details: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_are_case_insensitive() {
        for (name, f) in [
            ("a.HDR", ImageFormat::Hdr),
            ("a.pic", ImageFormat::Hdr),
            ("dir.x/a.Exr", ImageFormat::Exr),
            ("a.pfm", ImageFormat::Pfm),
            ("a.PNG", ImageFormat::Png),
            ("a.jpg", ImageFormat::Jpeg),
            ("a.JPEG", ImageFormat::Jpeg),
            ("a.KTX2", ImageFormat::Ktx2),
            ("a.dds", ImageFormat::Dds),
        ] {
            assert_eq!(ImageFormat::from_path(Path::new(name)), Some(f), "{name}");
        }
        assert_eq!(ImageFormat::from_path(Path::new("a.tiff")), None);
        assert_eq!(ImageFormat::from_path(Path::new("exr")), None);
        let names: Vec<_> = ImageFormat::ALL.iter().map(|f| f.name()).collect();
        assert_eq!(names, ["hdr", "exr", "pfm", "png", "jpeg", "ktx2", "dds"]);
    }

    #[test]
    fn limits_reject_zero_huge_and_overflowing_sizes() {
        let l = Limits::default();
        assert_eq!(l.check(512, 256), Ok(512 * 256));
        assert!(matches!(l.check(0, 5), Err(DecodeError::Invalid(_))));
        assert!(matches!(l.check(1 << 31, 1), Err(DecodeError::Limits(_))));
        assert!(matches!(l.check(65536, 65536), Err(DecodeError::Limits(_))));
        assert!(matches!(
            Limits::UNLIMITED.check(u64::MAX, 3),
            Err(DecodeError::Limits(_))
        ));
    }

    #[test]
    fn sniff_recognises_magic() {
        assert_eq!(ImageFormat::sniff(b"#?RADIANCE\n"), Some(ImageFormat::Hdr));
        assert_eq!(ImageFormat::sniff(b"Pf\n1 1\n-1\n"), Some(ImageFormat::Pfm));
        assert_eq!(ImageFormat::sniff(b"hello"), None);
        assert!(
            wrong_magic("an OpenEXR file", b"#?RGBE")
                .to_string()
                .contains("hdr")
        );
    }
}
