//! Bilinear look-ups as taps: up to eight source pixels with weights summing to 1, so that a
//! caller can both gather radiance (`sum w_k L_k`) and measure how much weight each source pixel
//! receives (energy-conserving resampling). A leaf module: every mapping's look-up builds them.

use ibl_core::Rgb;

/// The four bilinear corners `(column, row, weight)` of continuous texel coordinates `(fx, fy)`
/// (texel centres at integers), clamped to a `width` x `height` grid.
pub(crate) fn bilinear_corners(
    fx: f64,
    fy: f64,
    width: usize,
    height: usize,
) -> [(usize, usize, f64); 4] {
    let fx = fx.clamp(0.0, width.saturating_sub(1) as f64);
    let fy = fy.clamp(0.0, height.saturating_sub(1) as f64);
    let (i0, j0) = (fx.floor() as usize, fy.floor() as usize);
    let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
    let i1 = (i0 + 1).min(width.saturating_sub(1));
    let j1 = (j0 + 1).min(height.saturating_sub(1));
    [
        (i0, j0, (1.0 - tx) * (1.0 - ty)),
        (i1, j0, tx * (1.0 - ty)),
        (i0, j1, (1.0 - tx) * ty),
        (i1, j1, tx * ty),
    ]
}

/// Up to eight (pixel index, weight) pairs: a bilinear look-up, or two blended ones.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Taps {
    idx: [usize; 8],
    w: [f64; 8],
    n: usize,
}

impl Taps {
    /// Adds a tap (ignored beyond eight).
    pub(crate) fn push(&mut self, idx: usize, w: f64) {
        if self.n < 8 {
            self.idx[self.n] = idx;
            self.w[self.n] = w;
            self.n += 1;
        }
    }

    /// Whether there are no taps.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The taps with weights scaled to sum to 1 (unchanged if they sum to 0).
    pub(crate) fn normalised(mut self) -> Self {
        let sum: f64 = self.w[..self.n].iter().sum();
        if sum > 0.0 {
            for w in &mut self.w[..self.n] {
                *w /= sum;
            }
        }
        self
    }

    /// The `(index, weight)` pairs.
    pub fn iter(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.idx[..self.n]
            .iter()
            .copied()
            .zip(self.w[..self.n].iter().copied())
    }
}

impl Taps {
    /// The weighted sum `sum_k w_k L_k` of `pixels` (row-major, as the taps index them); black
    /// for no taps.
    pub fn gather(&self, pixels: &[Rgb]) -> Rgb {
        let mut sum = [0.0f64; 3];
        for (i, w) in self.iter() {
            if let Some(p) = pixels.get(i) {
                for (s, c) in sum.iter_mut().zip(p.to_array()) {
                    *s += w * f64::from(c);
                }
            }
        }
        Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
    }
}
