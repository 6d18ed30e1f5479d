//! Radiance RGBE pixels and scanlines: the shared-exponent conversion and the three scanline
//! encodings (flat, old-style run-length, new-style per-component run-length).
//!
//! A pixel is four bytes `(r, g, b, e)`: channel `c = (m + 0.5) * 2^(e - 136)`, or 0 when
//! `e == 0` (Radiance's `colr_color`, which centres the truncation interval). Encoding truncates
//! (Radiance's `setcolr`), so a decoded channel is within `2^-8` of the pixel's largest channel.
//!
//! - **New-style RLE** (Radiance 2.x, widths 8..=32767): a scanline starts `2, 2, hi, lo` with
//!   `hi << 8 | lo` the scanline length, then the four components one after the other, each as
//!   codes `n > 128` (a run: the next byte repeated `n - 128` times) or `1 <= n <= 128` (a literal
//!   of the next `n` bytes).
//! - **Old-style RLE**: flat pixels, except that a pixel `(1, 1, 1, n)` repeats the previous pixel
//!   `n << shift` times, `shift` growing by 8 for each consecutive run pixel (reset by a normal
//!   pixel). A run at the start of a scanline repeats the last pixel of the previous scanline.
//! - **Flat**: four bytes per pixel (old-style RLE with no run pixel).
//!
//! Every run and literal is checked against the scanline length and the bytes left, so corrupt
//! data gives an error, never an out-of-bounds write.

use ibl_core::Rgb;

/// Shortest scanline written (and recognised) as new-style RLE.
pub(crate) const MIN_RLE_LEN: usize = 8;
/// Longest scanline written (and recognised) as new-style RLE.
pub(crate) const MAX_RLE_LEN: usize = 0x7fff;
/// Shortest repeat worth a run code when writing.
const MIN_RUN: usize = 4;

/// `2^(e - 136)` for `e` in 1..=255 and 0 for `e == 0`: the scale of one mantissa unit.
const EXP_SCALE: [f32; 256] = {
    let mut t = [0.0f32; 256];
    let mut e = 1;
    while e < 256 {
        // 2^(e - 136) built from its f64 bit pattern (exact; subnormal in f32 for e < 10).
        t[e] = f64::from_bits(((e as u64) + 1023 - 136) << 52) as f32;
        e += 1;
    }
    t
};

/// One RGBE pixel to linear RGB.
#[inline]
pub(crate) fn rgbe_to_rgb(p: [u8; 4]) -> Rgb {
    let f = EXP_SCALE[p[3] as usize];
    Rgb::new(
        (p[0] as f32 + 0.5) * f,
        (p[1] as f32 + 0.5) * f,
        (p[2] as f32 + 0.5) * f,
    )
}

/// Linear RGB to one RGBE pixel (truncating, like Radiance). Negative and NaN channels become 0,
/// values below 1e-32 black, values beyond the RGBE range (about 1.7e38) the largest pixel.
#[inline]
pub(crate) fn rgb_to_rgbe(c: Rgb) -> [u8; 4] {
    let clean = |v: f32| if v > 0.0 { v.min(f32::MAX) } else { 0.0 };
    let (r, g, b) = (clean(c.r), clean(c.g), clean(c.b));
    let m = r.max(g).max(b);
    if m < 1e-32 {
        return [0; 4];
    }
    // m = frac * 2^e with frac in [0.5, 1) (m is a normal float here).
    let e = ((m.to_bits() >> 23) & 0xff) as i32 - 126;
    if e > 127 {
        return [255; 4];
    }
    // d = 2^(8 - e): a power of two, so the products below are exact.
    let d = f32::from_bits(((8 - e + 127) as u32) << 23);
    [(r * d) as u8, (g * d) as u8, (b * d) as u8, (e + 128) as u8]
}

/// How one scanline was stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ScanKind {
    /// New-style run-length encoding.
    Rle,
    /// Old-style run-length encoding (at least one run pixel).
    OldRle,
    /// Four bytes per pixel.
    Flat,
}

/// Reads consecutive scanlines from the pixel data of a Radiance file.
pub(crate) struct ScanlineReader<'a> {
    data: &'a [u8],
    pos: usize,
    planes: Vec<u8>,
    prev: Option<[u8; 4]>,
}

const TRUNCATED: &str = "pixel data ends early (truncated file)";

impl<'a> ScanlineReader<'a> {
    /// A reader over `data` (everything after the resolution line) for scanlines of `len` pixels.
    pub(crate) fn new(data: &'a [u8], len: usize) -> Self {
        let planes = if (MIN_RLE_LEN..=MAX_RLE_LEN).contains(&len) {
            vec![0; 4 * len]
        } else {
            Vec::new()
        };
        ScanlineReader {
            data,
            pos: 0,
            planes,
            prev: None,
        }
    }

    /// Bytes consumed so far.
    pub(crate) fn position(&self) -> usize {
        self.pos
    }

    /// Decodes the next scanline into `out` (whose length is the scanline length).
    pub(crate) fn read(&mut self, out: &mut [[u8; 4]]) -> Result<ScanKind, String> {
        let len = out.len();
        if self.planes.len() == 4 * len
            && let Some(&[2, 2, hi, lo]) = self.data.get(self.pos..self.pos + 4)
            && hi & 0x80 == 0
        {
            let declared = (hi as usize) << 8 | lo as usize;
            if declared != len {
                return Err(format!(
                    "RLE scanline header says {declared} pixels but scanlines have {len}"
                ));
            }
            self.pos += 4;
            self.read_rle(out)?;
            return Ok(ScanKind::Rle);
        }
        self.read_old(out)
    }

    fn read_rle(&mut self, out: &mut [[u8; 4]]) -> Result<(), String> {
        let len = out.len();
        let ScanlineReader {
            data,
            pos,
            planes,
            prev,
        } = self;
        for (c, plane) in planes.chunks_exact_mut(len).enumerate() {
            let mut i = 0;
            while i < len {
                let code = *data.get(*pos).ok_or(TRUNCATED)? as usize;
                *pos += 1;
                let (n, run) = if code > 128 {
                    (code - 128, true)
                } else {
                    (code, false)
                };
                if n == 0 {
                    return Err("zero-length literal in RLE data".to_owned());
                }
                let Some(dst) = plane.get_mut(i..i + n) else {
                    let what = if run { "run" } else { "literal" };
                    return Err(format!(
                        "RLE {what} of {n} bytes overflows the scanline (component {c}, {} left)",
                        len - i
                    ));
                };
                if run {
                    dst.fill(*data.get(*pos).ok_or(TRUNCATED)?);
                    *pos += 1;
                } else {
                    dst.copy_from_slice(data.get(*pos..*pos + n).ok_or(TRUNCATED)?);
                    *pos += n;
                }
                i += n;
            }
        }
        let (r, rest) = planes.split_at(len);
        let (g, rest) = rest.split_at(len);
        let (b, e) = rest.split_at(len);
        for ((((px, &r), &g), &b), &e) in out.iter_mut().zip(r).zip(g).zip(b).zip(e) {
            *px = [r, g, b, e];
        }
        *prev = out.last().copied();
        Ok(())
    }

    fn read_old(&mut self, out: &mut [[u8; 4]]) -> Result<ScanKind, String> {
        let len = out.len();
        let mut kind = ScanKind::Flat;
        let mut x = 0;
        let mut shift = 0u32;
        while x < len {
            let px: [u8; 4] = self
                .data
                .get(self.pos..self.pos + 4)
                .and_then(|s| s.try_into().ok())
                .ok_or(TRUNCATED)?;
            self.pos += 4;
            if px[0] == 1 && px[1] == 1 && px[2] == 1 {
                kind = ScanKind::OldRle;
                if shift > 24 {
                    return Err("old-style RLE run count too large".to_owned());
                }
                let count = (px[3] as usize) << shift;
                let fill = match x.checked_sub(1) {
                    Some(i) => out[i],
                    None => self
                        .prev
                        .ok_or("old-style RLE run before the first pixel")?,
                };
                let Some(dst) = x.checked_add(count).and_then(|end| out.get_mut(x..end)) else {
                    return Err(format!(
                        "old-style RLE run of {count} pixels overflows the scanline ({} left)",
                        len - x
                    ));
                };
                dst.fill(fill);
                x += count;
                shift += 8;
            } else {
                out[x] = px;
                x += 1;
                shift = 0;
            }
        }
        self.prev = out.last().copied().or(self.prev);
        Ok(kind)
    }
}

/// Appends a scanline as flat RGBE (four bytes per pixel).
pub(crate) fn write_flat(row: &[[u8; 4]], out: &mut Vec<u8>) {
    out.reserve(4 * row.len());
    for p in row {
        out.extend_from_slice(p);
    }
}

/// Appends a scanline as new-style RLE, or flat when its length is outside 8..=32767 (which
/// new-style RLE cannot represent). `plane` is scratch space.
pub(crate) fn write_rle(row: &[[u8; 4]], out: &mut Vec<u8>, plane: &mut Vec<u8>) {
    let len = row.len();
    if !(MIN_RLE_LEN..=MAX_RLE_LEN).contains(&len) {
        write_flat(row, out);
        return;
    }
    out.extend_from_slice(&[2, 2, (len >> 8) as u8, (len & 0xff) as u8]);
    for c in 0..4 {
        plane.clear();
        plane.extend(row.iter().map(|p| p[c]));
        encode_plane(plane, out);
    }
}

/// Whether a run of at least [`MIN_RUN`] equal bytes starts at `i`.
fn run_starts(src: &[u8], i: usize) -> bool {
    src.get(i..i + MIN_RUN)
        .is_some_and(|w| w.iter().all(|&b| b == w[0]))
}

/// Run-length encodes one component: runs of 4..=127 equal bytes, literals of 1..=128 bytes.
fn encode_plane(src: &[u8], out: &mut Vec<u8>) {
    let n = src.len();
    let mut i = 0;
    while i < n {
        let v = src[i];
        let run = src[i..].iter().take(127).take_while(|&&b| b == v).count();
        if run >= MIN_RUN {
            out.push(128 + run as u8);
            out.push(v);
            i += run;
            continue;
        }
        let start = i;
        i += 1;
        while i < n && i - start < 128 && !run_starts(src, i) {
            i += 1;
        }
        out.push((i - start) as u8);
        out.extend_from_slice(&src[start..i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_known_values() {
        assert_eq!(rgb_to_rgbe(Rgb::ONE), [128, 128, 128, 129]);
        assert_eq!(rgbe_to_rgb([128, 128, 128, 129]), Rgb::splat(128.5 / 128.0));
        assert_eq!(rgb_to_rgbe(Rgb::new(0.5, 0.25, 0.0)), [128, 64, 0, 128]);
        assert_eq!(rgb_to_rgbe(Rgb::new(-1.0, f32::NAN, 0.0)), [0; 4]);
        assert_eq!(rgb_to_rgbe(Rgb::splat(f32::INFINITY)), [255; 4]);
        assert_eq!(rgbe_to_rgb([0, 0, 0, 0]), Rgb::ZERO);
        assert_eq!(rgbe_to_rgb([200, 7, 9, 0]), Rgb::ZERO);
        // Extremes of the exponent stay finite and positive.
        assert!(rgbe_to_rgb([255, 255, 255, 255]).r.is_finite());
        assert!(rgbe_to_rgb([128, 0, 0, 1]).r > 0.0);
    }

    #[test]
    fn plane_encoding_round_trips() {
        let mut src = vec![7u8; 300];
        src.extend((0..=255).cycle().take(400).map(|v: u32| v as u8));
        src.extend([1, 1, 2, 2, 2, 3, 3, 3, 3, 9]);
        let row: Vec<[u8; 4]> = src.iter().map(|&v| [v, v / 2, 255 - v, 130]).collect();
        let mut bytes = Vec::new();
        write_rle(&row, &mut bytes, &mut Vec::new());
        let mut out = vec![[0u8; 4]; row.len()];
        let mut reader = ScanlineReader::new(&bytes, row.len());
        assert_eq!(reader.read(&mut out), Ok(ScanKind::Rle));
        assert_eq!(reader.position(), bytes.len());
        assert_eq!(out, row);
    }
}
