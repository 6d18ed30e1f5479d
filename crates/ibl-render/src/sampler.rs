//! The numbers a pixel sample draws: an Owen-scrambled Sobol stream (the default) or an
//! independent PCG32 stream, both a pure function of `(seed, pixel, sample)` and of how many
//! numbers the sample has drawn before, so an image never depends on the thread count.
//!
//! **Sobol** (low discrepancy; Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4), via
//! the `sobol_burley` crate): a sample draws its numbers in pairs. Pair `k` of sample `i` of a
//! pixel is point `i` of dimensions 0 and 1 of the Sobol sequence, with its index shuffled and its
//! digits Owen-scrambled by a seed hashed from `(seed, pixel, k)`. Dimensions 0 and 1 form a
//! (0,2)-sequence, and the shuffle and scramble keep its nets, so for `2^m` samples per pixel the
//! pixel's points of every pair are a (0,m,2)-net: each of the `2^m` elementary intervals of area
//! `2^-m` (any aspect) holds exactly one point. Different pairs (and different pixels) get
//! independent shuffles, which decorrelates them ("padding", pbrt-v4's `PaddedSobolSampler`):
//! the pixel jitter, each light's cone sample, each BSDF direction is well stratified across
//! the pixel's samples, and one dimension never aligns with another. A one-number draw takes the
//! first coordinate of a fresh pair (its 1-D projection is a (0,1)-sequence). Owen scrambling
//! makes every point uniform on `[0, 1)^2`, so estimators stay unbiased; the variance falls faster
//! than `1/n` on smooth integrands (Owen 1997: `O(n^-3)` for smooth, `O(n^-1.5)` with edges).
//! Limits: `2^16` samples per pixel (the crate's, and `MAX_SPP`).
//!
//! **Independent**: [`PixelRng`], one PCG32 stream per pixel sample; `1/n` variance, kept for
//! comparison and for estimators that need no stratification.
//!
//! Cost: Sobol about 10 ns per pair (one hash, a 16-step XOR of direction numbers and a
//! scramble), PCG32 about 1 ns per number; both negligible next to a ray.

pub use ibl_scene::SamplerKind;

use crate::sampling::{PixelRng, splitmix64};

/// Largest sample index a Sobol stream supports (exclusive): `2^16`.
pub const SOBOL_MAX_SAMPLES: u32 = 1 << 16;

/// The Sobol stream of one pixel sample (see the module notes).
#[derive(Clone, Debug)]
pub struct SobolStream {
    /// Sample index within the pixel, `< 2^16`.
    index: u32,
    /// Hash of `(seed, pixel)`.
    pixel_key: u64,
    /// Pairs drawn so far.
    pair: u64,
}

impl SobolStream {
    /// The stream of sample `sample` (below `2^16`; larger indices wrap) of pixel `pixel` in a
    /// render seeded with `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u32) -> Self {
        SobolStream {
            index: sample % SOBOL_MAX_SAMPLES,
            pixel_key: splitmix64(seed ^ splitmix64(pixel ^ 0x243f_6a88_85a3_08d3)),
            pair: 0,
        }
    }

    /// The seed of the next pair.
    fn next_seed(&mut self) -> u32 {
        let seed = splitmix64(self.pixel_key ^ self.pair.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.pair += 1;
        seed as u32
    }

    /// The next pair: point `index` of the pair's scrambled (0,2)-sequence. (Dimensions 0 to 3
    /// come from one SIMD evaluation, as fast as one scalar dimension; 2 and 3 are unused: their
    /// 2-D projection is not a (0,2)-sequence.)
    pub fn next_2d(&mut self) -> [f32; 2] {
        let [a, b, _, _] = sobol_burley::sample_4d(self.index, 0, self.next_seed());
        [a, b]
    }

    /// The next number: the first coordinate of a fresh pair.
    pub fn next_1d(&mut self) -> f32 {
        sobol_burley::sample(self.index, 0, self.next_seed())
    }
}

/// The random numbers of one pixel sample.
#[derive(Clone, Debug)]
pub enum SampleStream {
    /// Owen-scrambled Sobol pairs.
    Sobol(SobolStream),
    /// Independent PCG32 numbers.
    Independent(PixelRng),
}

impl SampleStream {
    /// The stream of sample `sample` of pixel `pixel` (any linear pixel index) in a render seeded
    /// with `seed`. Equal arguments give equal streams on every machine and thread count.
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, sample: u32) -> Self {
        match kind {
            SamplerKind::Sobol => SampleStream::Sobol(SobolStream::new(seed, pixel, sample)),
            SamplerKind::Independent => {
                SampleStream::Independent(PixelRng::new(seed, pixel, sample))
            }
        }
    }

    /// Two numbers in `[0, 1)`, stratified together across a pixel's samples (Sobol).
    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        match self {
            SampleStream::Sobol(s) => s.next_2d(),
            SampleStream::Independent(r) => [r.next_f32(), r.next_f32()],
        }
    }

    /// One number in `[0, 1)`.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        match self {
            SampleStream::Sobol(s) => s.next_1d(),
            SampleStream::Independent(r) => r.next_f32(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_pure_functions_of_their_key() {
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            let draw = |seed, pixel, sample| {
                let mut s = SampleStream::new(kind, seed, pixel, sample);
                [s.next_2d()[0], s.next_2d()[1], s.next_1d()]
            };
            assert_eq!(draw(1, 2, 3), draw(1, 2, 3));
            assert_ne!(draw(1, 2, 3), draw(2, 2, 3));
            assert_ne!(draw(1, 2, 3), draw(1, 3, 3));
            assert_ne!(draw(1, 2, 3), draw(1, 2, 4));
        }
    }
}
