//! Portable float map (`.pfm`) reading and writing; the `image` crate has no PFM support.
//!
//! Layout: `PF` (RGB) or `Pf` (grey), whitespace, width, whitespace, height, whitespace, scale,
//! exactly one whitespace byte (normally `\n`), then `width * height * channels` 32-bit floats,
//! rows stored **bottom to top**, each left to right. A negative scale means little-endian floats,
//! a positive one big-endian. The magnitude of the scale is a free-form "scale factor" whose
//! meaning writers disagree on: it is **ignored** (values are returned exactly as stored, so a
//! round trip is bit-exact) and mentioned in the details when it is not 1. Grey images come back
//! with `r = g = b`.
//!
//! The byte count implied by the header is checked (overflow-safe) against [`Limits`] and against
//! the bytes present before anything is allocated; extra trailing bytes are ignored and reported.

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::error::DecodeError;
use crate::format::{Limits, RawImage, wrong_magic};

/// The byte order of the floats in a PFM file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ByteOrder {
    /// Least significant byte first (written with a negative scale, `-1.0`); the common choice.
    #[default]
    LittleEndian,
    /// Most significant byte first (written with a positive scale, `1.0`).
    BigEndian,
}

/// Longest header token accepted (bytes).
const MAX_TOKEN: usize = 64;

/// Reads one whitespace-delimited token starting at `*pos` (after skipping whitespace).
fn token<'a>(bytes: &'a [u8], pos: &mut usize, what: &str) -> Result<&'a str, DecodeError> {
    while bytes.get(*pos).is_some_and(u8::is_ascii_whitespace) {
        *pos += 1;
    }
    let start = *pos;
    while bytes.get(*pos).is_some_and(|b| !b.is_ascii_whitespace()) {
        *pos += 1;
        if *pos - start > MAX_TOKEN {
            return Err(DecodeError::invalid(format!("header {what} is too long")));
        }
    }
    if start == *pos {
        return Err(DecodeError::invalid(format!(
            "header ends before the {what}"
        )));
    }
    std::str::from_utf8(&bytes[start..*pos])
        .map_err(|_| DecodeError::invalid(format!("header {what} is not text")))
}

/// The image size (width, height) a PFM header announces, from the header alone (`bytes` may be
/// only the start of the file).
pub fn header_size(bytes: &[u8]) -> Result<(usize, usize), DecodeError> {
    if !matches!(bytes.get(..2), Some(b"PF" | b"Pf"))
        || !bytes.get(2).is_some_and(u8::is_ascii_whitespace)
    {
        return Err(wrong_magic("a PFM file (\"PF\" or \"Pf\")", bytes));
    }
    let mut pos = 2;
    let mut size = |what: &str| {
        let t = token(bytes, &mut pos, what)?;
        t.parse::<usize>()
            .map_err(|_| DecodeError::invalid(format!("bad {what} {t:?}")))
    };
    let width = size("width")?;
    Ok((width, size("height")?))
}

/// Decodes a PFM file held in memory (values exactly as stored, not sanitised).
pub fn decode(bytes: &[u8], limits: &Limits) -> Result<RawImage, DecodeError> {
    let channels = match bytes.get(..2) {
        Some(b"PF") => 3,
        Some(b"Pf") => 1,
        _ => return Err(wrong_magic("a PFM file (\"PF\" or \"Pf\")", bytes)),
    };
    if !bytes.get(2).is_some_and(u8::is_ascii_whitespace) {
        return Err(wrong_magic("a PFM file (\"PF\" or \"Pf\")", bytes));
    }
    let mut pos = 2;
    let size = |t: &str, what: &str| {
        t.parse::<u64>()
            .map_err(|_| DecodeError::invalid(format!("bad {what} {t:?}")))
    };
    let width = size(token(bytes, &mut pos, "width")?, "width")?;
    let height = size(token(bytes, &mut pos, "height")?, "height")?;
    let scale_text = token(bytes, &mut pos, "scale")?;
    let scale: f32 = scale_text
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite() && *s != 0.0)
        .ok_or_else(|| DecodeError::invalid(format!("bad scale {scale_text:?}")))?;
    // Exactly one whitespace byte separates the header from the data.
    if !bytes.get(pos).is_some_and(u8::is_ascii_whitespace) {
        return Err(DecodeError::invalid("header ends early (truncated file)"));
    }
    pos += 1;
    let little = scale < 0.0;

    let total = limits.check(width, height)?;
    let (w, h) = (width as usize, height as usize);
    let data = &bytes[pos..];
    let row_bytes = w.checked_mul(channels * 4);
    let needed = row_bytes
        .and_then(|r| r.checked_mul(h))
        .filter(|&n| n <= data.len());
    let (Some(row_bytes), Some(needed)) = (row_bytes, needed) else {
        return Err(DecodeError::Limits(format!(
            "header says {w} x {h} x {channels} floats ({} bytes) but only {} bytes follow \
             (truncated file?)",
            u128::from(width) * u128::from(height) * (channels as u128) * 4,
            data.len()
        )));
    };

    let float = |b: &[u8]| {
        let a = [b[0], b[1], b[2], b[3]];
        if little {
            f32::from_le_bytes(a)
        } else {
            f32::from_be_bytes(a)
        }
    };
    let mut pixels = vec![Rgb::ZERO; total];
    pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        // Row 0 (top) is the last row in the file.
        let src = &data[(h - 1 - y) * row_bytes..(h - y) * row_bytes];
        if channels == 3 {
            for (px, b) in row.iter_mut().zip(src.chunks_exact(12)) {
                *px = Rgb::new(float(&b[0..4]), float(&b[4..8]), float(&b[8..12]));
            }
        } else {
            for (px, b) in row.iter_mut().zip(src.chunks_exact(4)) {
                *px = Rgb::splat(float(b));
            }
        }
    });
    let image = Image::from_vec(w, h, pixels).map_err(|e| DecodeError::invalid(e.to_string()))?;

    let mut details = format!(
        "PFM, {}, {}-endian",
        if channels == 3 { "RGB" } else { "grey" },
        if little { "little" } else { "big" }
    );
    if scale.abs() != 1.0 {
        details.push_str(&format!(", scale factor {} ignored", scale.abs()));
    }
    if data.len() > needed {
        details.push_str(&format!(", {} trailing bytes ignored", data.len() - needed));
    }
    Ok(RawImage { image, details })
}

/// Header plus rows of `channels` floats each, bottom row first.
fn encode_rows<T: Sync>(
    image: &Image<T>,
    order: ByteOrder,
    magic: &str,
    channels: usize,
    put: impl Fn(&T, &mut Vec<u8>, fn(f32) -> [u8; 4]) + Sync,
) -> Vec<u8> {
    let (w, h) = (image.width(), image.height());
    let (scale, to_bytes): (&str, fn(f32) -> [u8; 4]) = match order {
        ByteOrder::LittleEndian => ("-1.0", f32::to_le_bytes),
        ByteOrder::BigEndian => ("1.0", f32::to_be_bytes),
    };
    let header = format!("{magic}\n{w} {h}\n{scale}\n");
    let mut out = Vec::with_capacity(header.len() + w * h * channels * 4);
    out.extend_from_slice(header.as_bytes());
    let rows: Vec<Vec<u8>> = (0..h)
        .into_par_iter()
        .rev()
        .map(|y| {
            let mut bytes = Vec::with_capacity(w * channels * 4);
            for px in image.row(y) {
                put(px, &mut bytes, to_bytes);
            }
            bytes
        })
        .collect();
    for r in rows {
        out.extend_from_slice(&r);
    }
    out
}

/// Encodes an RGB image as `PF` with the given byte order; values are written bit for bit
/// (NaN, Inf and negatives included).
pub fn encode(image: &Image<Rgb>, order: ByteOrder) -> Vec<u8> {
    encode_rows(image, order, "PF", 3, |p, out, to_bytes| {
        out.extend_from_slice(&to_bytes(p.r));
        out.extend_from_slice(&to_bytes(p.g));
        out.extend_from_slice(&to_bytes(p.b));
    })
}

/// Encodes a single-channel image as `Pf` (grey) with the given byte order, bit for bit.
pub fn encode_grey(image: &Image<f32>, order: ByteOrder) -> Vec<u8> {
    encode_rows(image, order, "Pf", 1, |&v, out, to_bytes| {
        out.extend_from_slice(&to_bytes(v))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_forms() {
        // Tabs, several spaces and "\r" are all whitespace; big-endian with scale 4.
        let mut bytes = b"Pf\t2  1\r\n4.0\n".to_vec();
        bytes.extend_from_slice(&1.5f32.to_be_bytes());
        bytes.extend_from_slice(&(-2.0f32).to_be_bytes());
        let raw = decode(&bytes, &Limits::default()).expect("decodes");
        assert_eq!(raw.image.pixels(), &[Rgb::splat(1.5), Rgb::splat(-2.0)]);
        assert!(raw.details.contains("big-endian") && raw.details.contains("scale factor 4"));
    }

    #[test]
    fn rejects_bad_headers() {
        let l = Limits::default();
        for bad in [
            &b""[..],
            b"P6\n1 1\n255\n",
            b"PF",
            b"PF\n1 1\n",
            b"PF\n1 1\n0\n",
            b"PF\n1 1\nnan\n",
            b"PF\n-1 1\n-1\n",
            b"PF\n1 1\n-1\n123",
            b"PF\n4294967296 4294967296\n-1\n",
        ] {
            assert!(
                decode(bad, &l).is_err(),
                "{:?}",
                String::from_utf8_lossy(bad)
            );
        }
    }
}
