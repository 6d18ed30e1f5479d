//! Photographs as a camera wrote them, for HDR assembly (`ibl-capture`): the 8-bit codes of a PNG
//! or JPEG (not decoded to linear: the camera's response curve is what the merge recovers), the
//! exposure time from the EXIF `ExposureTime` tag when there is one, and exposure-time lists.
//!
//! 16-bit PNGs keep their top 8 bits (response recovery works on 256 codes). Alpha is dropped.

use std::path::Path;

use ibl_core::Image;

use crate::error::{DecodeError, IoError};
use crate::format::{ImageFormat, Limits, wrong_magic};

/// A photograph's codes and what its metadata says.
#[derive(Clone, Debug, PartialEq)]
pub struct Photo {
    /// 8-bit codes per channel, row 0 at the top, as the file stores them (sRGB-encoded or
    /// whatever the camera's curve made).
    pub codes: Image<[u8; 3]>,
    /// Exposure time from EXIF, seconds.
    pub exposure_time_s: Option<f64>,
    /// Human-readable encoding.
    pub details: String,
}

/// Decodes the 8-bit codes of a PNG or JPEG held in memory.
pub fn decode_codes(bytes: &[u8], limits: &Limits) -> Result<Image<[u8; 3]>, DecodeError> {
    let format = match ImageFormat::sniff(bytes) {
        Some(ImageFormat::Png) => image::ImageFormat::Png,
        Some(ImageFormat::Jpeg) => image::ImageFormat::Jpeg,
        _ => return Err(wrong_magic("a PNG or JPEG photograph", bytes)),
    };
    let decoded = crate::ldr::limited_reader(bytes, format, limits)
        .decode()
        .map_err(|e| DecodeError::invalid(e.to_string().trim()))?;
    let rgb = decoded.to_rgb8();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    limits.check(w as u64, h as u64)?;
    let pixels: Vec<[u8; 3]> = rgb.pixels().map(|p| p.0).collect();
    Image::from_vec(w, h, pixels).map_err(|e| DecodeError::invalid(e.to_string()))
}

/// The EXIF exposure time of a photograph held in memory, seconds; `None` when there is no EXIF
/// or no valid `ExposureTime`.
pub fn exif_exposure_time(bytes: &[u8]) -> Option<f64> {
    let exif = exif::Reader::new()
        .read_from_container(&mut std::io::Cursor::new(bytes))
        .ok()?;
    let field = exif.get_field(exif::Tag::ExposureTime, exif::In::PRIMARY)?;
    match &field.value {
        exif::Value::Rational(v) => v
            .first()
            .map(|r| r.to_f64())
            .filter(|t| t.is_finite() && *t > 0.0),
        _ => None,
    }
}

/// Reads a photograph's codes and EXIF exposure time.
pub fn read_photo(path: &Path) -> Result<Photo, IoError> {
    let limits = Limits::default();
    let bytes = crate::read_bounded(path, limits.max_file_bytes())?;
    let codes = decode_codes(&bytes, &limits).map_err(|e| e.with_path(path))?;
    let exposure_time_s = exif_exposure_time(&bytes);
    let details = match exposure_time_s {
        Some(t) => format!("8-bit codes, EXIF exposure {t} s"),
        None => "8-bit codes, no EXIF exposure time".to_string(),
    };
    Ok(Photo {
        codes,
        exposure_time_s,
        details,
    })
}

/// Parses exposure times: numbers separated by commas, spaces or new lines, each a decimal
/// (`0.004`) or a fraction (`1/250`), in seconds; `#` starts a comment to the end of the line.
pub fn parse_exposure_times(text: &str) -> Result<Vec<f64>, String> {
    let mut times = Vec::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("");
        for token in line.split(|c: char| c == ',' || c.is_whitespace()) {
            if token.is_empty() {
                continue;
            }
            let value = match token.split_once('/') {
                Some((a, b)) => match (a.trim().parse::<f64>(), b.trim().parse::<f64>()) {
                    (Ok(a), Ok(b)) if b != 0.0 => a / b,
                    _ => return Err(format!("'{token}' is not an exposure time")),
                },
                None => token
                    .parse::<f64>()
                    .map_err(|_| format!("'{token}' is not an exposure time"))?,
            };
            if !(value.is_finite() && value > 0.0) {
                return Err(format!("'{token}' is not a positive exposure time"));
            }
            times.push(value);
        }
    }
    Ok(times)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exposure_lists() {
        assert_eq!(
            parse_exposure_times("1/250, 1/60 0.25\n2 # long\n").unwrap(),
            vec![0.004, 1.0 / 60.0, 0.25, 2.0]
        );
        assert!(parse_exposure_times("1/0").is_err());
        assert!(parse_exposure_times("-1").is_err());
        assert!(parse_exposure_times("fast").is_err());
        assert!(parse_exposure_times("").unwrap().is_empty());
    }

    #[test]
    fn codes_round_trip_through_png() {
        let image = Image::from_fn_par(7, 5, |x, y| [(x * 30) as u8, (y * 50) as u8, 200]);
        let png = crate::ldr::encode_png(&image).unwrap();
        assert_eq!(decode_codes(&png, &Limits::default()).unwrap(), image);
        assert_eq!(exif_exposure_time(&png), None);
        assert!(decode_codes(b"not an image", &Limits::default()).is_err());
    }

    /// A JPEG with an EXIF `ExposureTime` of 1/250 s: the APP1 segment (`Exif\0\0` + a TIFF
    /// block made by kamadak-exif's writer) inserted after the JPEG's start-of-image marker.
    fn jpeg_with_exposure(numerator: u32, denominator: u32) -> Vec<u8> {
        let image = Image::from_fn_par(16, 8, |x, y| [(x * 16) as u8, (y * 32) as u8, 128]);
        let jpeg = crate::ldr::encode_jpeg(&image, 90).unwrap();
        let field = exif::Field {
            tag: exif::Tag::ExposureTime,
            ifd_num: exif::In::PRIMARY,
            value: exif::Value::Rational(vec![exif::Rational::from((numerator, denominator))]),
        };
        let mut writer = exif::experimental::Writer::new();
        writer.push_field(&field);
        let mut tiff = std::io::Cursor::new(Vec::new());
        writer.write(&mut tiff, false).unwrap();
        let mut payload = b"Exif\0\0".to_vec();
        payload.extend_from_slice(&tiff.into_inner());
        let length = u16::try_from(payload.len() + 2).unwrap();
        let mut out = jpeg[..2].to_vec();
        out.extend_from_slice(&[0xFF, 0xE1]);
        out.extend_from_slice(&length.to_be_bytes());
        out.extend_from_slice(&payload);
        out.extend_from_slice(&jpeg[2..]);
        out
    }

    #[test]
    fn exif_exposure_time_is_read_from_a_jpeg() {
        let jpeg = jpeg_with_exposure(1, 250);
        assert_eq!(exif_exposure_time(&jpeg), Some(0.004));
        let codes = decode_codes(&jpeg, &Limits::default()).unwrap();
        assert_eq!((codes.width(), codes.height()), (16, 8));
        // A zero exposure time is no exposure time.
        assert_eq!(exif_exposure_time(&jpeg_with_exposure(0, 1)), None);
    }
}
