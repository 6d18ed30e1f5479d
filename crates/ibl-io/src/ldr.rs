//! PNG and JPEG (low dynamic range) through the `image` crate: decoding to linear RGB with the
//! sRGB EOTF, and encoding already tone-mapped 8-bit sRGB pixels (see [`ibl_core::tonemap`]).
//!
//! Decoding accepts 8- and 16-bit grey, grey+alpha, RGB and RGBA; alpha is dropped (not
//! premultiplied) and embedded gamma or ICC information is ignored: every file is taken to be
//! sRGB, which is what cameras and the web write. The header's size is checked against
//! [`Limits`] by the decoder (through `image::Limits`) before the pixel buffer is allocated.

use std::io::Cursor;

use ibl_core::{Image, Rgb};
use image::{DynamicImage, ImageDecoder, ImageEncoder};
use rayon::prelude::*;

use crate::error::{DecodeError, EncodeError};
use crate::format::{ImageFormat, Limits, RawImage, wrong_magic};
use ibl_core::tonemap::srgb_to_linear;

/// Default JPEG quality used by [`crate::write_image`].
pub const JPEG_QUALITY: u8 = 92;

fn from_image_error(e: image::ImageError) -> DecodeError {
    match e {
        image::ImageError::Limits(l) => DecodeError::Limits(l.to_string().trim().to_owned()),
        image::ImageError::Unsupported(u) => {
            DecodeError::Unsupported(u.to_string().trim().to_owned())
        }
        image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            DecodeError::invalid("data ends early (truncated file)")
        }
        other => DecodeError::invalid(other.to_string().trim()),
    }
}

/// Converts samples (`channels` per pixel, the first three or one of them colour) to linear RGB.
fn to_linear<T: Copy + Sync>(
    samples: &[T],
    channels: usize,
    eotf: impl Fn(T) -> f32 + Sync,
) -> Vec<Rgb> {
    samples
        .par_chunks_exact(channels)
        .with_min_len(4096)
        .map(|px| {
            if channels >= 3 {
                Rgb::new(eotf(px[0]), eotf(px[1]), eotf(px[2]))
            } else {
                Rgb::splat(eotf(px[0]))
            }
        })
        .collect()
}

/// A reader of `bytes` in `format` that refuses images over `limits` before allocating.
pub(crate) fn limited_reader<'a>(
    bytes: &'a [u8],
    format: image::ImageFormat,
    limits: &Limits,
) -> image::ImageReader<Cursor<&'a [u8]>> {
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
    let mut il = image::Limits::default();
    il.max_image_width = Some(u32::try_from(limits.max_width).unwrap_or(u32::MAX));
    il.max_image_height = Some(u32::try_from(limits.max_height).unwrap_or(u32::MAX));
    // 16-bit RGBA is the largest decoded layout: 8 bytes per pixel.
    il.max_alloc = Some(
        (limits.max_pixels as u64)
            .saturating_mul(8)
            .saturating_add(1 << 20),
    );
    reader.limits(il);
    reader
}

/// The image size (width, height) a PNG or JPEG header announces, from the header alone (no
/// pixel is decoded; `bytes` may be only the start of the file).
pub fn header_size(bytes: &[u8]) -> Result<(usize, usize), DecodeError> {
    let format = match ImageFormat::sniff(bytes) {
        Some(ImageFormat::Png) => image::ImageFormat::Png,
        Some(ImageFormat::Jpeg) => image::ImageFormat::Jpeg,
        _ => return Err(wrong_magic("a PNG or JPEG file", bytes)),
    };
    let reader = limited_reader(bytes, format, &Limits::UNLIMITED);
    let (w, h) = reader.into_dimensions().map_err(from_image_error)?;
    Ok((w as usize, h as usize))
}

/// Decodes a PNG or JPEG file held in memory to linear RGB (row 0 at the top).
pub fn decode(bytes: &[u8], limits: &Limits) -> Result<RawImage, DecodeError> {
    let format = match ImageFormat::sniff(bytes) {
        Some(ImageFormat::Png) => image::ImageFormat::Png,
        Some(ImageFormat::Jpeg) => image::ImageFormat::Jpeg,
        _ => return Err(wrong_magic("a PNG or JPEG file", bytes)),
    };
    let reader = limited_reader(bytes, format, limits);
    let decoder = reader.into_decoder().map_err(from_image_error)?;
    let (w, h) = decoder.dimensions();
    limits.check(u64::from(w), u64::from(h))?;
    let decoded = DynamicImage::from_decoder(decoder).map_err(from_image_error)?;

    let lut8: Vec<f32> = (0..=255u8)
        .map(|v| srgb_to_linear(f32::from(v) / 255.0))
        .collect();
    let eotf8 = |v: u8| lut8[v as usize];
    let eotf16 = |v: u16| srgb_to_linear(f32::from(v) / 65535.0);
    let (pixels, layout) = match &decoded {
        DynamicImage::ImageLuma8(i) => (to_linear(i.as_raw(), 1, eotf8), "8-bit grey"),
        DynamicImage::ImageLumaA8(i) => (to_linear(i.as_raw(), 2, eotf8), "8-bit grey+alpha"),
        DynamicImage::ImageRgb8(i) => (to_linear(i.as_raw(), 3, eotf8), "8-bit RGB"),
        DynamicImage::ImageRgba8(i) => (to_linear(i.as_raw(), 4, eotf8), "8-bit RGBA"),
        DynamicImage::ImageLuma16(i) => (to_linear(i.as_raw(), 1, eotf16), "16-bit grey"),
        DynamicImage::ImageLumaA16(i) => (to_linear(i.as_raw(), 2, eotf16), "16-bit grey+alpha"),
        DynamicImage::ImageRgb16(i) => (to_linear(i.as_raw(), 3, eotf16), "16-bit RGB"),
        DynamicImage::ImageRgba16(i) => (to_linear(i.as_raw(), 4, eotf16), "16-bit RGBA"),
        other => (to_linear(other.to_rgb16().as_raw(), 3, eotf16), "RGB"),
    };
    let image = Image::from_vec(w as usize, h as usize, pixels)
        .map_err(|e| DecodeError::invalid(e.to_string()))?;
    let name = if format == image::ImageFormat::Png {
        "PNG"
    } else {
        "JPEG"
    };
    Ok(RawImage {
        image,
        details: format!("{name}, {layout}, sRGB decoded to linear"),
    })
}

fn checked_size(image: &Image<[u8; 3]>) -> Result<(u32, u32), EncodeError> {
    let w = u32::try_from(image.width());
    let h = u32::try_from(image.height());
    match (w, h) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => Err(EncodeError::new(format!(
            "cannot encode a {} x {} image",
            image.width(),
            image.height()
        ))),
    }
}

/// Encodes 8-bit sRGB pixels as an RGB PNG.
pub fn encode_png(image: &Image<[u8; 3]>) -> Result<Vec<u8>, EncodeError> {
    let (w, h) = checked_size(image)?;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            image.pixels().as_flattened(),
            w,
            h,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| EncodeError::new(format!("PNG encoder: {e}")))?;
    Ok(out)
}

/// Encodes 8-bit sRGB pixels as a baseline JPEG of the given quality (1..=100).
pub fn encode_jpeg(image: &Image<[u8; 3]>, quality: u8) -> Result<Vec<u8>, EncodeError> {
    let (w, h) = checked_size(image)?;
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality.clamp(1, 100))
        .write_image(
            image.pixels().as_flattened(),
            w,
            h,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| EncodeError::new(format!("JPEG encoder: {e}")))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_is_exact_in_srgb() {
        let img = Image::from_fn_par(17, 5, |x, y| [(x * 15) as u8, (y * 60) as u8, 255]);
        let bytes = encode_png(&img).expect("encodes");
        let raw = decode(&bytes, &Limits::default()).expect("decodes");
        assert_eq!(raw.details, "PNG, 8-bit RGB, sRGB decoded to linear");
        let back = ibl_core::tonemap::to_srgb8(
            &raw.image,
            &ibl_core::tonemap::Display {
                exposure_stops: 0.0,
                curve: ibl_core::tonemap::ToneCurve::Clamp,
            },
        );
        assert_eq!(back, img);
    }

    #[test]
    fn jpeg_encodes_and_decodes() {
        let img = Image::from_fn_par(32, 16, |x, _| [(x * 8) as u8, 100, 50]);
        let bytes = encode_jpeg(&img, JPEG_QUALITY).expect("encodes");
        let raw = decode(&bytes, &Limits::default()).expect("decodes");
        assert_eq!((raw.image.width(), raw.image.height()), (32, 16));
        assert!(raw.details.starts_with("JPEG, 8-bit RGB"));
    }

    #[test]
    fn limits_apply_before_decoding() {
        let img = Image::filled(40, 30, [1u8, 2, 3]);
        let bytes = encode_png(&img).expect("encodes");
        let small = Limits {
            max_width: 39,
            ..Limits::default()
        };
        assert!(matches!(
            decode(&bytes, &small),
            Err(DecodeError::Limits(_))
        ));
        let few = Limits {
            max_pixels: 1000,
            ..Limits::default()
        };
        assert!(matches!(decode(&bytes, &few), Err(DecodeError::Limits(_))));
    }
}
