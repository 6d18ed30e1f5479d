//! Translation-only registration of hand-held exposure brackets with median threshold bitmaps
//! (Ward 2003, "Fast, Robust Image Registration for Compositing High Dynamic Range Photographs
//! from Hand-Held Exposures", journal of graphics tools 8(2)).
//!
//! Each 8-bit photograph becomes a grey image `g = (54 R + 183 G + 19 B) / 256` (codes, not
//! linear). Its median `m` splits it into a *threshold bitmap* (`g > m`) that is nearly the same
//! for every exposure of a static scene whatever the exposure time, because the camera response is
//! monotonic; pixels within `+-4` codes of the split flip with noise, so an *exclusion bitmap*
//! (`|g - m| > 4`) keeps only the reliable ones. The misalignment of two bitmaps at an offset is
//! `popcount((t_ref XOR t_img) AND e_ref AND e_img)`, the image's bitmaps read at the offset and
//! zero (excluded) where the offset reads outside the frame.
//!
//! **Split quantile.** Ward notes that for very dark or bright exposures another percentile than
//! the median works better. Both images of a pair are split at the same quantile `p` (the same
//! scene radiance rank in both, since a monotonic response keeps the order of pixels): the
//! middle of the ranks that neither image clips, `p = (low + high) / 2` with `low` the larger
//! fraction of grey codes `<= CLIPPED_DARK` (8) and `1 - high` the larger fraction of codes
//! `>= CLIPPED_BRIGHT` (247), both measured at full resolution. Without clipping `p = 0.5`,
//! Ward's median; if the unclipped ranges do not overlap, `p = 0.5` as well. Without this a
//! bracket member saturated over half its pixels has median 255 and an empty threshold bitmap.
//!
//! **Search.** The pyramid holds 2 x 2 box averages of the grey image; the `p`-quantile and the
//! bitmaps are recomputed on every level. Levels are added while the next one keeps at least
//! [`MIN_COARSE_SIDE`] pixels on its shorter side and at most `max_levels` halvings are made, so
//! a 256 x 128 image gets 3 halvings (coarsest 32 x 16). On the coarsest level the 9 offsets
//! `{-1, 0, 1}^2` are tried; the best one is doubled for the next finer level and its 9
//! neighbours tried again, down to full resolution. With `L` halvings the recovered offset is at
//! most `2^(L+1) - 1` pixels in each axis. Ties keep the centre offset, so a flat image or two
//! images without reliable pixels align with shift 0.
//!
//! **Only integer translations are recovered**: no rotation, no scale, no sub-pixel offsets
//! (Ward's paper handles rotation separately; hand-held brackets are dominated by translation).
//!
//! Bitmaps are packed 64 pixels to a `u64` word (bit `x % 64` of word `x / 64` is column `x`), so
//! one offset costs `W H / 64` word operations and popcounts. Cost: O(W H) per level to build the
//! grey image, its histogram quantile and the bitmaps, plus 9 offsets x O(W H / 64) per level;
//! O(W H) in all since the levels shrink geometrically. [`align_bracket`] runs the images in
//! parallel.

use ibl_core::Image;
use rayon::prelude::*;

use crate::CaptureError;
use crate::response::check_same_size;

/// Codes within this distance of the split code are excluded from the comparison (Ward's noise
/// tolerance, in 8-bit grey codes).
pub const EXCLUSION_CODES: u8 = 4;

/// Grey codes at or below this count as clipped dark when choosing the split quantile.
pub const CLIPPED_DARK: u8 = 8;

/// Grey codes at or above this count as clipped bright when choosing the split quantile.
pub const CLIPPED_BRIGHT: u8 = 247;

/// The pyramid stops halving before its shorter side would drop below this many pixels.
pub const MIN_COARSE_SIDE: usize = 16;

/// Options of the bitmap alignment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AlignOptions {
    /// Most pyramid halvings; the largest recoverable offset is `2^(max_levels + 1) - 1` pixels,
    /// fewer where the image is too small (see [`MIN_COARSE_SIDE`]). 0 searches only `+-1` pixel.
    pub max_levels: u32,
}

impl Default for AlignOptions {
    /// 6 halvings: offsets up to 127 pixels on images large enough (Ward's setting).
    fn default() -> Self {
        AlignOptions { max_levels: 6 }
    }
}

/// An integer translation in pixels: the displacement of an image's content relative to the
/// reference, `image(x + dx, y + dy) ~ reference(x, y)` (x right, y down, row 0 at the top).
/// A feature at column 10 of the reference appears at column `10 + dx` of the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Shift {
    /// Displacement to the right, pixels.
    pub dx: i32,
    /// Displacement downwards, pixels.
    pub dy: i32,
}

/// Finds the integer translation of `image` relative to `reference` (see [`Shift`] for the sign).
///
/// Errors: [`CaptureError::Invalid`] if the two images differ in size or are empty.
pub fn align_to(
    reference: &Image<[u8; 3]>,
    image: &Image<[u8; 3]>,
    options: &AlignOptions,
) -> Result<Shift, CaptureError> {
    check_same_size([reference, image])?;
    let levels = pyramid_levels(reference.width(), reference.height(), options.max_levels);
    let reference = Pyramid::new(reference, levels);
    let image = Pyramid::new(image, levels);
    Ok(reference.align(&image))
}

/// Aligns every image of a bracket to its middle image (index `len / 2`; pass the bracket sorted
/// by exposure time so this is the middle exposure). Returns one [`Shift`] per image, the
/// reference's being zero.
///
/// Errors: [`CaptureError::Invalid`] if the bracket is empty or the images differ in size.
pub fn align_bracket(
    images: &[Image<[u8; 3]>],
    options: &AlignOptions,
) -> Result<Vec<Shift>, CaptureError> {
    if images.is_empty() {
        return Err(CaptureError::Invalid("no images to align".into()));
    }
    check_same_size(images)?;
    let reference_index = images.len() / 2;
    let levels = pyramid_levels(images[0].width(), images[0].height(), options.max_levels);
    let reference = Pyramid::new(&images[reference_index], levels);
    Ok(images
        .par_iter()
        .enumerate()
        .map(|(i, image)| {
            if i == reference_index {
                Shift::default()
            } else {
                reference.align(&Pyramid::new(image, levels))
            }
        })
        .collect())
}

/// Moves `image`'s content by `-shift` so it lines up with the reference the shift was measured
/// against: `aligned(x, y) = image(x + dx, y + dy)`.
///
/// Pixels whose source lies outside the frame are filled with the nearest edge pixel (coordinates
/// clamped) and marked `false` in the returned validity mask (`true` = real data); a merge should
/// give them zero weight. Cost O(W H).
pub fn apply_shift<T: Copy + Send + Sync>(
    image: &Image<T>,
    shift: Shift,
) -> (Image<T>, Image<bool>) {
    let (w, h) = (image.width(), image.height());
    if w == 0 || h == 0 {
        return (image.clone(), image.map(|_| false));
    }
    let source = |x: usize, y: usize| {
        let sx = x as i64 + i64::from(shift.dx);
        let sy = y as i64 + i64::from(shift.dy);
        let inside = (0..w as i64).contains(&sx) && (0..h as i64).contains(&sy);
        let cx = sx.clamp(0, w as i64 - 1) as usize;
        let cy = sy.clamp(0, h as i64 - 1) as usize;
        (cx, cy, inside)
    };
    let aligned = Image::from_fn_par(w, h, |x, y| {
        let (cx, cy, _) = source(x, y);
        *image.get(cx, cy)
    });
    let valid = Image::from_fn_par(w, h, |x, y| source(x, y).2);
    (aligned, valid)
}

/// Number of halvings for a `w x h` image: while the next level keeps [`MIN_COARSE_SIDE`] pixels
/// on its shorter side, at most `max_levels`.
fn pyramid_levels(w: usize, h: usize, max_levels: u32) -> u32 {
    let mut levels = 0;
    let mut side = w.min(h);
    while levels < max_levels && side / 2 >= MIN_COARSE_SIDE {
        side /= 2;
        levels += 1;
    }
    levels
}

/// Threshold and exclusion bitmaps of one pyramid level, rows packed into `u64` words.
struct Bitmaps {
    height: usize,
    words_per_row: usize,
    /// Bit set where grey > threshold code.
    threshold: Vec<u64>,
    /// Bit set where |grey - threshold code| > [`EXCLUSION_CODES`] (reliable pixels); padding
    /// bits zero.
    exclusion: Vec<u64>,
}

impl Bitmaps {
    /// Bitmaps of `level` split at its `fraction` quantile.
    fn new(level: &GreyLevel, fraction: f64) -> Self {
        let split = level.quantile(fraction);
        let (width, height) = (level.width, level.height);
        let words_per_row = width.div_ceil(64);
        let mut threshold = vec![0u64; words_per_row * height];
        let mut exclusion = vec![0u64; words_per_row * height];
        for y in 0..height {
            let row = &level.grey[y * width..(y + 1) * width];
            for (x, &g) in row.iter().enumerate() {
                let word = y * words_per_row + x / 64;
                let bit = 1u64 << (x % 64);
                if g > split {
                    threshold[word] |= bit;
                }
                if g.abs_diff(split) > EXCLUSION_CODES {
                    exclusion[word] |= bit;
                }
            }
        }
        Bitmaps {
            height,
            words_per_row,
            threshold,
            exclusion,
        }
    }

    /// Misalignment of `other` read at offset `(dx, dy)` against `self`: the number of reliable
    /// pixels (in both) whose threshold bits differ, `other(x + dx, y + dy)` vs `self(x, y)`.
    fn mismatch(&self, other: &Bitmaps, dx: i64, dy: i64) -> u64 {
        let n = self.words_per_row;
        let mut count = 0u64;
        for y in 0..self.height {
            let sy = y as i64 + dy;
            if sy < 0 || sy >= other.height as i64 {
                continue;
            }
            let own = y * n..(y + 1) * n;
            let theirs = sy as usize * n..(sy as usize + 1) * n;
            let (t_ref, e_ref) = (&self.threshold[own.clone()], &self.exclusion[own]);
            let (t_img, e_img) = (&other.threshold[theirs.clone()], &other.exclusion[theirs]);
            for k in 0..n {
                if e_ref[k] == 0 {
                    continue;
                }
                let t = shifted_word(t_img, k, dx);
                let e = shifted_word(e_img, k, dx);
                count += u64::from(((t_ref[k] ^ t) & e_ref[k] & e).count_ones());
            }
        }
        count
    }
}

/// Word `k` of the packed row `row` read `dx` bits further on: bit `b` of the result is bit
/// `64 k + b + dx` of the row, zero outside it.
fn shifted_word(row: &[u64], k: usize, dx: i64) -> u64 {
    let word = |i: i64| -> u64 {
        if i < 0 || i >= row.len() as i64 {
            0
        } else {
            row[i as usize]
        }
    };
    let q = dx.div_euclid(64);
    let r = dx.rem_euclid(64) as u32;
    let base = k as i64 + q;
    if r == 0 {
        word(base)
    } else {
        (word(base) >> r) | (word(base + 1) << (64 - r))
    }
}

/// One pyramid level of the grey image and its histogram.
struct GreyLevel {
    width: usize,
    height: usize,
    grey: Vec<u8>,
    histogram: [usize; 256],
}

impl GreyLevel {
    fn new(grey: Vec<u8>, width: usize, height: usize) -> Self {
        let mut histogram = [0usize; 256];
        for &g in &grey {
            histogram[usize::from(g)] += 1;
        }
        GreyLevel {
            width,
            height,
            grey,
            histogram,
        }
    }

    /// The smallest code with at least `ceil(fraction n)` (at least 1) pixels at or below it;
    /// `fraction = 0.5` gives the (lower) median.
    fn quantile(&self, fraction: f64) -> u8 {
        let n = self.grey.len();
        let rank = ((fraction * n as f64).ceil() as usize).clamp(1, n.max(1));
        let mut seen = 0;
        for (code, &count) in self.histogram.iter().enumerate() {
            seen += count;
            if seen >= rank {
                return code as u8;
            }
        }
        u8::MAX
    }

    /// Fractions of pixels at or below [`CLIPPED_DARK`] and at or above [`CLIPPED_BRIGHT`].
    fn clipped_fractions(&self) -> (f64, f64) {
        let n = self.grey.len().max(1) as f64;
        let dark: usize = self.histogram[..=usize::from(CLIPPED_DARK)].iter().sum();
        let bright: usize = self.histogram[usize::from(CLIPPED_BRIGHT)..].iter().sum();
        (dark as f64 / n, bright as f64 / n)
    }
}

/// Grey images of every pyramid level, finest first.
struct Pyramid {
    levels: Vec<GreyLevel>,
}

impl Pyramid {
    fn new(image: &Image<[u8; 3]>, halvings: u32) -> Self {
        let (mut w, mut h) = (image.width(), image.height());
        let grey: Vec<u8> = image
            .pixels()
            .iter()
            .map(|&[r, g, b]| {
                ((54 * u32::from(r) + 183 * u32::from(g) + 19 * u32::from(b)) >> 8) as u8
            })
            .collect();
        let mut levels = vec![GreyLevel::new(grey, w, h)];
        for _ in 0..halvings {
            let (w2, h2) = (w / 2, h / 2);
            let mut half = Vec::with_capacity(w2 * h2);
            if let Some(finer) = levels.last() {
                let grey = &finer.grey;
                for y in 0..h2 {
                    let top = &grey[2 * y * w..(2 * y + 1) * w];
                    let bottom = &grey[(2 * y + 1) * w..(2 * y + 2) * w];
                    for x in 0..w2 {
                        let sum = u32::from(top[2 * x])
                            + u32::from(top[2 * x + 1])
                            + u32::from(bottom[2 * x])
                            + u32::from(bottom[2 * x + 1]);
                        half.push(((sum + 2) / 4) as u8);
                    }
                }
            }
            (w, h) = (w2, h2);
            levels.push(GreyLevel::new(half, w, h));
        }
        Pyramid { levels }
    }

    /// The quantile both images are split at: the middle of the range of ranks that is clipped
    /// in neither (0.5, Ward's median, when nothing is clipped or the ranges do not overlap).
    fn shared_fraction(&self, image: &Pyramid) -> f64 {
        let (Some(a), Some(b)) = (self.levels.first(), image.levels.first()) else {
            return 0.5;
        };
        let (dark_a, bright_a) = a.clipped_fractions();
        let (dark_b, bright_b) = b.clipped_fractions();
        let low = dark_a.max(dark_b);
        let high = 1.0 - bright_a.max(bright_b);
        if low < high { 0.5 * (low + high) } else { 0.5 }
    }

    /// Coarse-to-fine search of `image`'s offset relative to `self`.
    fn align(&self, image: &Pyramid) -> Shift {
        let fraction = self.shared_fraction(image);
        let (mut dx, mut dy) = (0i64, 0i64);
        for (reference, other) in self.levels.iter().zip(&image.levels).rev() {
            let reference = Bitmaps::new(reference, fraction);
            let other = Bitmaps::new(other, fraction);
            let (cx, cy) = (2 * dx, 2 * dy);
            // The centre first: a neighbour replaces it only if strictly better.
            let mut best = (reference.mismatch(&other, cx, cy), cx, cy);
            for (ox, oy) in NEIGHBOURS {
                let candidate = (
                    reference.mismatch(&other, cx + ox, cy + oy),
                    cx + ox,
                    cy + oy,
                );
                if candidate.0 < best.0 {
                    best = candidate;
                }
            }
            (dx, dy) = (best.1, best.2);
        }
        // Each level at most doubles the offset and adds 1, so |d| < 2^(levels + 1), which is at
        // most max(2, shorter side / 8) (`pyramid_levels`): it fits i32 for any image in memory.
        let to_i32 = |d: i64| d.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        Shift {
            dx: to_i32(dx),
            dy: to_i32(dy),
        }
    }
}

/// The 8 offsets around the centre.
const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];
