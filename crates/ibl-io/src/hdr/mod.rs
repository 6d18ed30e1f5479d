//! Radiance RGBE (`.hdr`, `.pic`) reading and writing, written here rather than taken from the
//! `image` crate because its decoder ignores `EXPOSURE=` (so pixel values are not radiance) and
//! only accepts the standard `-Y H +X W` orientation.
//!
//! Reading handles flat, old-style RLE and new-style RLE scanlines (see the `scanline` submodule for the
//! byte layouts), `FORMAT=32-bit_rle_rgbe` (XYZE is rejected as unsupported: converting it
//! needs the file's primaries and white point), `EXPOSURE=` and `COLORCORR=` lines (pixel values
//! are divided by the product of all of them, giving the radiance before exposure), and all
//! eight resolution strings (`-Y H +X W` standard, `+Y` bottom-up, `-X` right-to-left, and the
//! transposed `+X W -Y H` forms where each stored scanline is a column), always presented with
//! row 0 at the top, left to right.
//!
//! Hostile headers: the width and height are checked against [`Limits`] and against the bytes
//! that follow (every scanline takes at least 4 bytes in any encoding) before anything is
//! allocated. The pixel buffer then starts at the size the remaining bytes could hold as new-style
//! RLE (at least `4 + 8 * ceil(W / 127)` bytes per scanline) or flat data (`4 W`) and only grows
//! past that when old-style runs really decode to more pixels, so memory stays proportional to
//! the file unless its content genuinely expands.
//!
//! Writing produces `#?RADIANCE`, `FORMAT=32-bit_rle_rgbe` and `-Y H +X W` scanlines, new-style
//! RLE by default ([`encode`]) or flat ([`encode_flat`]); scanlines are encoded in parallel.

pub(crate) mod scanline;

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::error::DecodeError;
use crate::format::{Limits, RawImage, wrong_magic};
use scanline::{MAX_RLE_LEN, MIN_RLE_LEN, ScanKind, ScanlineReader, rgb_to_rgbe, rgbe_to_rgb};

/// Longest header line accepted (bytes).
const MAX_LINE: usize = 16 * 1024;
/// Longest header accepted (bytes).
const MAX_HEADER: usize = 1024 * 1024;

/// The pieces of a Radiance header that matter for decoding.
struct Header {
    /// Per-channel divisor: product of all `EXPOSURE` and `COLORCORR` values.
    divisor: [f64; 3],
    /// Whether any `EXPOSURE`/`COLORCORR` line was seen.
    has_exposure: bool,
    layout: Layout,
    /// Offset of the first pixel byte.
    data_start: usize,
}

/// The resolution string: image size and how stored scanlines map to rows and columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Layout {
    width: usize,
    height: usize,
    /// Scanlines are columns (`±X W ±Y H`).
    transposed: bool,
    /// `-Y`: stored from the top row down (else bottom-up).
    y_down: bool,
    /// `+X`: stored left to right (else right to left).
    x_right: bool,
}

impl Layout {
    /// `(number of scanlines, pixels per scanline)`.
    fn scanlines(&self) -> (usize, usize) {
        if self.transposed {
            (self.width, self.height)
        } else {
            (self.height, self.width)
        }
    }

    fn is_standard(&self) -> bool {
        !self.transposed && self.y_down && self.x_right
    }

    fn describe(&self) -> String {
        let y = format!("{}Y {}", if self.y_down { '-' } else { '+' }, self.height);
        let x = format!("{}X {}", if self.x_right { '+' } else { '-' }, self.width);
        if self.transposed {
            format!("{x} {y}")
        } else {
            format!("{y} {x}")
        }
    }
}

/// Splits off one `\n`-terminated line (without `\r\n`/`\n`) starting at `*pos`.
fn next_line<'a>(bytes: &'a [u8], pos: &mut usize) -> Result<&'a [u8], DecodeError> {
    let rest = &bytes[*pos..];
    let window = &rest[..rest.len().min(MAX_LINE + 1)];
    match window.iter().position(|&b| b == b'\n') {
        Some(n) => {
            *pos += n + 1;
            let line = &rest[..n];
            Ok(line.strip_suffix(b"\r").unwrap_or(line))
        }
        None if rest.len() > MAX_LINE => Err(DecodeError::invalid(format!(
            "header line longer than {MAX_LINE} bytes (no newline)"
        ))),
        None => Err(DecodeError::invalid("header ends early (truncated file)")),
    }
}

/// Parses a positive finite number list such as `EXPOSURE=` or `COLORCORR=` values.
fn parse_factors(value: &str, n: usize, what: &str) -> Result<Vec<f64>, DecodeError> {
    let v: Vec<f64> = value
        .split_ascii_whitespace()
        .filter_map(|t| t.parse().ok())
        .collect();
    if v.len() != n || !v.iter().all(|x| x.is_finite() && *x > 0.0) {
        return Err(DecodeError::invalid(format!("bad {what} value {value:?}")));
    }
    Ok(v)
}

fn parse_layout(line: &[u8]) -> Result<Layout, DecodeError> {
    let bad = || {
        DecodeError::invalid(format!(
            "bad resolution line {:?} (expected e.g. \"-Y 512 +X 1024\")",
            String::from_utf8_lossy(&line[..line.len().min(80)])
        ))
    };
    let text = std::str::from_utf8(line).map_err(|_| bad())?;
    let t: Vec<&str> = text.split_ascii_whitespace().collect();
    let [a1, n1, a2, n2] = t[..] else {
        return Err(bad());
    };
    let n1: u64 = n1.parse().map_err(|_| bad())?;
    let n2: u64 = n2.parse().map_err(|_| bad())?;
    let (transposed, y, ny, x, nx) = match (a1.get(1..), a2.get(1..)) {
        (Some("Y"), Some("X")) => (false, a1, n1, a2, n2),
        (Some("X"), Some("Y")) => (true, a2, n2, a1, n1),
        _ => return Err(bad()),
    };
    let sign = |s: &str| match s.as_bytes().first() {
        Some(b'+') => Ok(true),
        Some(b'-') => Ok(false),
        _ => Err(bad()),
    };
    let y_down = !sign(y)?;
    let x_right = sign(x)?;
    // Sizes are range-checked against the limits by the caller; here only against usize.
    let width = usize::try_from(nx).map_err(|_| bad())?;
    let height = usize::try_from(ny).map_err(|_| bad())?;
    Ok(Layout {
        width,
        height,
        transposed,
        y_down,
        x_right,
    })
}

/// The image size (width, height) a Radiance header announces, from the header alone (no pixel
/// is decoded; `bytes` may be only the start of the file).
pub fn header_size(bytes: &[u8]) -> Result<(usize, usize), DecodeError> {
    let layout = parse_header(bytes)?.layout;
    Ok((layout.width, layout.height))
}

fn parse_header(bytes: &[u8]) -> Result<Header, DecodeError> {
    if !bytes.starts_with(b"#?") {
        return Err(wrong_magic("a Radiance HDR file (\"#?RADIANCE\")", bytes));
    }
    let mut pos = 0;
    let mut divisor = [1.0f64; 3];
    let mut has_exposure = false;
    loop {
        if pos > MAX_HEADER {
            return Err(DecodeError::invalid(format!(
                "header longer than {MAX_HEADER} bytes"
            )));
        }
        let line = next_line(bytes, &mut pos)?;
        if line.is_empty() {
            break;
        }
        let text = String::from_utf8_lossy(line);
        let text = text.trim_start();
        if let Some(v) = text.strip_prefix("FORMAT=") {
            match v.trim() {
                "32-bit_rle_rgbe" => {}
                "32-bit_rle_xyze" => {
                    return Err(DecodeError::Unsupported(
                        "Radiance XYZE pixels (FORMAT=32-bit_rle_xyze); convert to RGBE".into(),
                    ));
                }
                other => {
                    return Err(DecodeError::Unsupported(format!(
                        "Radiance pixel format {other:?} (only 32-bit_rle_rgbe)"
                    )));
                }
            }
        } else if let Some(v) = text.strip_prefix("EXPOSURE=") {
            let e = parse_factors(v, 1, "EXPOSURE")?;
            divisor.iter_mut().for_each(|d| *d *= e[0]);
            has_exposure = true;
        } else if let Some(v) = text.strip_prefix("COLORCORR=") {
            let c = parse_factors(v, 3, "COLORCORR")?;
            divisor.iter_mut().zip(&c).for_each(|(d, c)| *d *= c);
            has_exposure = true;
        }
    }
    let layout = parse_layout(next_line(bytes, &mut pos)?)?;
    Ok(Header {
        divisor,
        has_exposure,
        layout,
        data_start: pos,
    })
}

/// Decodes a Radiance RGBE file held in memory. Values are divided by the header's `EXPOSURE`
/// and `COLORCORR` factors; they are not sanitised (RGBE cannot hold negatives or NaN anyway).
pub fn decode(bytes: &[u8], limits: &Limits) -> Result<RawImage, DecodeError> {
    let header = parse_header(bytes)?;
    let layout = header.layout;
    let total = limits.check(layout.width as u64, layout.height as u64)?;
    let (count, len) = layout.scanlines();
    let data = &bytes[header.data_start..];

    // Any encoding needs at least one 4-byte group per scanline.
    if data.len() / 4 < count {
        return Err(DecodeError::Limits(format!(
            "header says {} x {} but only {} bytes of pixel data follow \
             (at least {} needed; truncated file?)",
            layout.width,
            layout.height,
            data.len(),
            count.saturating_mul(4)
        )));
    }
    // The most pixels the bytes could hold as new-style RLE or flat data.
    let typical_min = if (MIN_RLE_LEN..=MAX_RLE_LEN).contains(&len) {
        4 + 8 * len.div_ceil(127)
    } else {
        4 * len
    };
    let capacity = total.min((data.len() / typical_min + 1).saturating_mul(len));
    let mut stored: Vec<[u8; 4]> = Vec::with_capacity(capacity);
    let mut line = vec![[0u8; 4]; len];
    let mut reader = ScanlineReader::new(data, len);
    let (mut rle, mut old, mut flat) = (0usize, 0usize, 0usize);
    for s in 0..count {
        let kind = reader
            .read(&mut line)
            .map_err(|e| DecodeError::invalid(format!("scanline {s} of {count}: {e}")))?;
        match kind {
            ScanKind::Rle => rle += 1,
            ScanKind::OldRle => old += 1,
            ScanKind::Flat => flat += 1,
        }
        stored.extend_from_slice(&line);
    }

    let scale = header.divisor.map(|d| (1.0 / d) as f32);
    let convert = |p: [u8; 4]| {
        let c = rgbe_to_rgb(p);
        if header.has_exposure {
            Rgb::new(c.r * scale[0], c.g * scale[1], c.b * scale[2])
        } else {
            c
        }
    };
    let image = if layout.is_standard() {
        let pixels: Vec<Rgb> = stored
            .par_iter()
            .with_min_len(4096)
            .map(|&p| convert(p))
            .collect();
        Image::from_vec(layout.width, layout.height, pixels)
            .map_err(|e| DecodeError::invalid(e.to_string()))?
    } else {
        let (w, h) = (layout.width, layout.height);
        Image::from_fn_par(w, h, |x, y| {
            let sx = if layout.x_right { x } else { w - 1 - x };
            let sy = if layout.y_down { y } else { h - 1 - y };
            let i = if layout.transposed {
                sx * h + sy
            } else {
                sy * w + sx
            };
            convert(stored[i])
        })
    };

    let encoding = match (rle, old, flat) {
        (_, 0, 0) => "RLE",
        (0, _, _) if old > 0 => "old-style RLE",
        (0, 0, _) => "flat",
        _ => "mixed RLE/flat",
    };
    let mut details = format!("Radiance RGBE, {encoding}");
    if !layout.is_standard() {
        details.push_str(&format!(", orientation {}", layout.describe()));
    }
    if header.has_exposure {
        let d = header.divisor;
        if d[0] == d[1] && d[1] == d[2] {
            details.push_str(&format!(", divided by EXPOSURE {}", d[0]));
        } else {
            details.push_str(&format!(", divided by EXPOSURE*COLORCORR {d:?}"));
        }
    }
    let trailing = data.len() - reader.position();
    if trailing > 0 {
        details.push_str(&format!(", {trailing} trailing bytes ignored"));
    }
    Ok(RawImage { image, details })
}

fn encode_with(image: &Image<Rgb>, rle: bool) -> Vec<u8> {
    let header = format!(
        "#?RADIANCE\nSOFTWARE=iblkit\nFORMAT=32-bit_rle_rgbe\n\n-Y {} +X {}\n",
        image.height(),
        image.width()
    );
    let width = image.width().max(1);
    let rows: Vec<Vec<u8>> = image
        .pixels()
        .par_chunks(width)
        .map_init(
            || (Vec::new(), Vec::new()),
            |(rgbe, plane), row| {
                rgbe.clear();
                rgbe.extend(row.iter().map(|&c| rgb_to_rgbe(c)));
                let mut out = Vec::with_capacity(4 * row.len());
                if rle {
                    scanline::write_rle(rgbe, &mut out, plane);
                } else {
                    scanline::write_flat(rgbe, &mut out);
                }
                out
            },
        )
        .collect();
    let mut out = Vec::with_capacity(header.len() + rows.iter().map(Vec::len).sum::<usize>());
    out.extend_from_slice(header.as_bytes());
    for r in rows {
        out.extend_from_slice(&r);
    }
    out
}

/// Encodes an image as Radiance RGBE with new-style RLE scanlines (flat when the width is outside
/// 8..=32767, which RLE cannot represent). Negative and NaN values are written as 0.
pub fn encode(image: &Image<Rgb>) -> Vec<u8> {
    encode_with(image, true)
}

/// Encodes an image as flat (uncompressed) Radiance RGBE, four bytes per pixel.
pub fn encode_flat(image: &Image<Rgb>) -> Vec<u8> {
    encode_with(image, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_eight_resolution_strings_parse() {
        for (s, transposed, y_down, x_right) in [
            ("-Y 3 +X 5", false, true, true),
            ("-Y 3 -X 5", false, true, false),
            ("+Y 3 +X 5", false, false, true),
            ("+Y 3 -X 5", false, false, false),
            ("+X 5 -Y 3", true, true, true),
            ("-X 5 -Y 3", true, true, false),
            ("+X 5 +Y 3", true, false, true),
            ("-X 5 +Y 3", true, false, false),
        ] {
            let l = parse_layout(s.as_bytes()).expect(s);
            assert_eq!((l.width, l.height), (5, 3), "{s}");
            assert_eq!(
                (l.transposed, l.y_down, l.x_right),
                (transposed, y_down, x_right),
                "{s}"
            );
            assert_eq!(l.describe(), s);
        }
        for bad in [
            "",
            "-Y 3",
            "-Y 3 +Y 5",
            "Y 3 +X 5",
            "-Y -3 +X 5",
            "-Y 3 +X 5 7",
            "*Y 3 +X 5",
        ] {
            assert!(parse_layout(bad.as_bytes()).is_err(), "{bad}");
        }
    }

    #[test]
    fn header_lines_and_limits() {
        let h = parse_header(b"#?RGBE\n\tEXPOSURE=2\nEXPOSURE=1.5\nGAMMA=1\n\n-Y 1 +X 1\n")
            .expect("valid header");
        assert_eq!(h.divisor, [3.0; 3]);
        assert!(parse_header(b"#?RADIANCE\nEXPOSURE=0\n\n-Y 1 +X 1\n").is_err());
        assert!(parse_header(b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n").is_err());
        let mut long = b"#?RADIANCE\n".to_vec();
        long.resize(MAX_LINE + 100, b'x');
        let err = parse_header(&long)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(err.contains("longer than"), "{err}");
    }

    #[test]
    fn transposed_mapping_is_column_major() {
        // "+X 2 -Y 3": two stored scanlines (columns), top to bottom.
        let mut bytes = b"#?RADIANCE\n\n+X 2 -Y 3\n".to_vec();
        for v in [1u8, 2, 3, 4, 5, 6] {
            bytes.extend_from_slice(&[128, 128 + v, 128, 129]);
        }
        let img = decode(&bytes, &Limits::default()).expect("decodes").image;
        let g = |x, y| ((img.get(x, y).g * 128.0 - 0.5) as u32) - 128;
        assert_eq!(
            [g(0, 0), g(0, 1), g(0, 2), g(1, 0), g(1, 1), g(1, 2)],
            [1, 2, 3, 4, 5, 6]
        );
    }
}
