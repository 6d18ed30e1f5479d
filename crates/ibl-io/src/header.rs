//! What an image file's header says, without decoding a pixel (`ibl info --header`): the format
//! and the size. A file whose header announces 2^28 pixels takes as long to describe as a tiny
//! one, and nothing is allocated for its pixels.
//!
//! Radiance HDR, OpenEXR, PFM, PNG and JPEG are read from their first [`HEADER_BYTES`] only. A
//! KTX2 or DDS texture is read whole within the [`Limits`] and decoded (its size depends on its
//! levels and faces, which the texture readers check together).

use std::path::Path;

use crate::{DecodeError, ImageFormat, IoError, Limits};

/// The most bytes read for a header: OpenEXR headers with large attributes and JPEG files with
/// large EXIF blocks before their frame header fit.
pub const HEADER_BYTES: u64 = 16 << 20;

/// An image file's format and size, from its header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImageHeader {
    /// The format (from the extension, checked against the magic bytes by each parser).
    pub format: ImageFormat,
    /// Width in pixels (a cube texture: its six faces side by side).
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
}

/// Reads `path`'s header: format and size, no pixel decoded (textures excepted, see the module
/// note). Errors name the file; a header that announces a size over `limits` is not an error
/// here (the header is what was asked for).
pub fn read_header(path: &Path, limits: &Limits) -> Result<ImageHeader, IoError> {
    let format = crate::format_of(path)?;
    let size = match format {
        ImageFormat::Ktx2 | ImageFormat::Dds => {
            let t = crate::read_texture(path, limits)?;
            let (w, h) = t.texture.size();
            Ok((w * t.texture.kind.faces(), h))
        }
        _ => {
            let bytes = crate::read_prefix(path, HEADER_BYTES)?;
            size_of(format, &bytes)
        }
    };
    let (width, height) = size.map_err(|e| e.with_path(path))?;
    Ok(ImageHeader {
        format,
        width,
        height,
    })
}

fn size_of(format: ImageFormat, bytes: &[u8]) -> Result<(usize, usize), DecodeError> {
    match format {
        ImageFormat::Hdr => crate::hdr::header_size(bytes),
        ImageFormat::Exr => crate::exr::header_size(bytes),
        ImageFormat::Pfm => crate::pfm::header_size(bytes),
        ImageFormat::Png | ImageFormat::Jpeg => crate::ldr::header_size(bytes),
        ImageFormat::Ktx2 | ImageFormat::Dds => Err(DecodeError::invalid("a texture")),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use ibl_core::{Image, Rgb};

    #[test]
    fn every_format_reports_the_size_its_decoder_would() {
        let dir = tempfile::tempdir().unwrap();
        let image = Image::from_fn_par(12, 5, |x, y| Rgb::new(x as f32, y as f32, 1.0));
        for ext in ["hdr", "exr", "pfm", "png", "jpg", "ktx2", "dds"] {
            let p = dir.path().join(format!("a.{ext}"));
            crate::write_image(&p, &image, &crate::WriteOptions::default()).unwrap();
            let h = read_header(&p, &Limits::default()).unwrap();
            assert_eq!((h.width, h.height), (12, 5), "{ext}");
            assert_eq!(h.format, crate::format_of(&p).unwrap());
        }
    }

    #[test]
    fn a_header_over_the_limits_is_still_read_and_a_truncated_one_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        // A PFM header announcing 2^30 pixels with no data after it.
        let p = dir.path().join("huge.pfm");
        std::fs::write(&p, b"PF\n32768 32768\n-1.0\n").unwrap();
        let h = read_header(&p, &Limits::default()).unwrap();
        assert_eq!((h.width, h.height), (32768, 32768));
        let t = dir.path().join("cut.hdr");
        std::fs::write(&t, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n").unwrap();
        let e = read_header(&t, &Limits::default()).unwrap_err();
        assert!(e.is_bad_input() && e.to_string().contains("cut.hdr"), "{e}");
    }
}
