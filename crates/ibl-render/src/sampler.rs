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
//! **Evaluation.** The pair is computed here from `sobol_burley`'s own building blocks
//! (`parts`: the index shuffle, the hash and the Owen scramble), bit for bit what
//! `sobol_burley::sample_4d(index, 0, seed)` returns in its first two lanes (a test checks it),
//! but with the Sobol matrix product done by two table look-ups per dimension instead of the
//! crate's loop over the shuffled index's set bits: the Sobol point is linear over GF(2) in the
//! index's bits, so `sobol(i) = T_hi[i >> 8] ^ T_lo[i & 255]` with two 256-entry tables per
//! dimension (4 KiB in all, built once). The crate's loop takes a data-dependent branch per set
//! bit of a random 16-bit index; in the lights mode, which draws one pair per light per sample,
//! it was a fifth of the render time.
//!
//! A pair's three scramble keys (the index shuffle's and the two coordinates') are hashes of
//! its seed, which depends on `(seed, pixel, pair)` and not on the sample: a pixel's samples
//! are drawn through one stream, restarted at each ([`SampleStream::restart`]), which keeps the
//! keys of the pixel's first 32 pairs as it makes them, so each is hashed once per pixel and
//! not once per sample.
//!
//! Cost: Sobol about 5 ns per pair (a seed's mix and three hashes for its keys, three scrambles,
//! four look-ups; the keys in a pixel's first sample only: cachegrind counts 3.5 % fewer
//! instructions in a reference render with them kept), PCG32 about 1 ns per number; both small
//! next to a ray.

use std::sync::LazyLock;

pub use ibl_scene::SamplerKind;
use sobol_burley::parts::{hash, owen_scramble_rev, sobol_rev, u32_to_f32_norm};

use crate::sampling::{PixelRng, splitmix64};

/// Largest sample index a Sobol stream supports (exclusive): `2^16`.
pub const SOBOL_MAX_SAMPLES: u32 = 1 << 16;

/// Pairs whose keys a stream keeps for its pixel's later samples ([`PairKeys`]).
const KEPT_PAIRS: usize = 32;

/// The Sobol stream of one pixel sample (see the module notes).
#[derive(Clone, Debug)]
pub struct SobolStream {
    /// Sample index within the pixel, `< 2^16`, bits reversed.
    index_rev: u32,
    /// Hash of `(seed, pixel)`.
    pixel_key: u64,
    /// Pairs drawn so far.
    pair: u64,
    /// The Sobol tables, looked up once per stream (not once per pair).
    tables: &'static SobolTables,
    /// The keys of the pixel's first pairs, as far as they have been drawn, when the stream
    /// keeps them ([`SampleStream::keeping_keys`]).
    kept: Option<Box<KeptKeys>>,
}

/// The keys of a pixel's first [`KEPT_PAIRS`] pairs, each made when first drawn: bit `k` of
/// `made` says whether `keys[k]` is pair `k`'s.
#[derive(Clone, Debug)]
struct KeptKeys {
    made: u32,
    keys: [PairKeys; KEPT_PAIRS],
}

/// What scrambles one pair, hashed from its seed: the key of the index shuffle and those of
/// the two coordinates' digit scrambles. They depend on `(seed, pixel, pair)` and not on the
/// sample, so a pixel's samples share them: a stream that keeps them
/// ([`SampleStream::keeping_keys`]), moved on to the pixel's next sample
/// ([`SampleStream::restart`]), spares three of a pair's four hashes in every sample after the
/// first (a tenth of a reference render's instructions were the pairs').
#[derive(Clone, Copy, Debug, Default)]
struct PairKeys {
    shuffle: u32,
    dimensions: [u32; 2],
}

impl PairKeys {
    /// The keys `sobol_burley` hashes from `seed` for dimension set 0.
    #[inline]
    fn of(seed: u32) -> PairKeys {
        let base = seed.wrapping_mul(SEED_MULTIPLIER);
        PairKeys {
            shuffle: hash(seed ^ SHUFFLE_KEY),
            dimensions: [
                hash(base ^ DIMENSION_KEYS[0]),
                hash(base ^ DIMENSION_KEYS[1]),
            ],
        }
    }
}

impl SobolStream {
    /// The stream of sample `sample` (below `2^16`; larger indices wrap) of pixel `pixel` in a
    /// render seeded with `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u32) -> Self {
        SobolStream {
            index_rev: (sample % SOBOL_MAX_SAMPLES).reverse_bits(),
            pixel_key: splitmix64(seed ^ splitmix64(pixel ^ 0x243f_6a88_85a3_08d3)),
            pair: 0,
            tables: LazyLock::force(&TABLES),
            kept: None,
        }
    }

    /// [`SobolStream::new`], keeping the pixel's pair keys as it makes them.
    fn keeping_keys(seed: u64, pixel: u64, sample: u32) -> Self {
        SobolStream {
            kept: Some(Box::new(KeptKeys {
                made: 0,
                keys: [PairKeys::default(); KEPT_PAIRS],
            })),
            ..SobolStream::new(seed, pixel, sample)
        }
    }

    /// The same pixel's stream of sample `sample`, from its first pair.
    fn restart(&mut self, sample: u32) {
        self.index_rev = (sample % SOBOL_MAX_SAMPLES).reverse_bits();
        self.pair = 0;
    }

    /// The keys of the next pair: those of its seed, a hash of `(seed, pixel, pair)`, kept or
    /// made.
    #[inline(always)]
    fn next_keys(&mut self) -> PairKeys {
        let pair = self.pair;
        self.pair += 1;
        if let Some(kept) = &self.kept
            && pair < KEPT_PAIRS as u64
            && kept.made & (1 << pair) != 0
        {
            return kept.keys[pair as usize];
        }
        self.make_keys(pair)
    }

    /// The keys of pair `pair`, hashed (and kept where the stream keeps them).
    #[inline]
    fn make_keys(&mut self, pair: u64) -> PairKeys {
        let seed = splitmix64(self.pixel_key ^ pair.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let keys = PairKeys::of(seed as u32);
        if let Some(kept) = &mut self.kept
            && pair < KEPT_PAIRS as u64
        {
            kept.keys[pair as usize] = keys;
            kept.made |= 1 << pair;
        }
        keys
    }

    /// The next pair: point `index` of the pair's scrambled (0,2)-sequence (dimensions 0 and 1).
    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        let keys = self.next_keys();
        self.tables.point(self.index_rev, keys)
    }

    /// Passes over the next pair without computing it: the pairs after it are those a
    /// [`SobolStream::next_2d`] here would have left.
    #[inline]
    pub fn skip_2d(&mut self) {
        self.pair += 1;
    }

    /// `count` pairs stratified together (see [`SampleStream::pairs`]): points `sample * count`
    /// to `sample * count + count - 1` of one fresh pair's scrambled (0,2)-sequence, or `count`
    /// fresh pairs where those indices would pass [`SOBOL_MAX_SAMPLES`].
    fn pairs(&mut self, count: u32) -> Option<JointPairs> {
        let sample = u64::from(self.index_rev.reverse_bits());
        if (sample + 1) * u64::from(count) > u64::from(SOBOL_MAX_SAMPLES) {
            return None;
        }
        let keys = self.next_keys();
        let first = sample as u32 * count;
        Some(JointPairs {
            tables: self.tables,
            keys,
            next: first,
            end: first + count,
        })
    }

    /// The next number: the first coordinate of a fresh pair.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        let keys = self.next_keys();
        // Inlined, the unused second coordinate is never computed.
        self.tables.point(self.index_rev, keys)[0]
    }
}

/// Consecutive points of one scrambled (0,2)-sequence: [`SampleStream::pairs`] of a Sobol stream.
#[derive(Clone, Debug)]
struct JointPairs {
    tables: &'static SobolTables,
    /// The pair's keys: its index shuffle and digit scramble.
    keys: PairKeys,
    /// The next point's index in the sequence, and the end of the run.
    next: u32,
    end: u32,
}

impl Iterator for JointPairs {
    type Item = [f32; 2];

    #[inline]
    fn next(&mut self) -> Option<[f32; 2]> {
        if self.next >= self.end {
            return None;
        }
        let point = self.tables.point(self.next.reverse_bits(), self.keys);
        self.next += 1;
        Some(point)
    }
}

/// `sobol_burley`'s constants for dimension set 0 (its `sample` and `sample_4d`): the key of
/// the index shuffle, the multiplier of the seed and the per-dimension keys of the scramble.
const SHUFFLE_KEY: u32 = 0x79c6_8e4a;
const SEED_MULTIPLIER: u32 = 0x9c8f_2d3b;
const DIMENSION_KEYS: [u32; 2] = [0x912f_69ba, 0x174f_18ab];

/// Two reversed-bit Sobol coordinates Owen-scrambled by `keys` ([`PairKeys::dimensions`]), as
/// numbers in `[0, 1)`. Both are turned back by one 64-bit reversal (`reverse(a : b) =
/// reverse(b) : reverse(a)`): the same bits as two 32-bit ones at half the shifts and masks
/// (the x86-64 baseline has no bit-reversal instruction), which the pairs of every path draw
/// several times.
#[inline]
fn scrambled(sobol_rev: [u32; 2], keys: [u32; 2]) -> [f32; 2] {
    let a = owen_scramble_rev(sobol_rev[0], keys[0]);
    let b = owen_scramble_rev(sobol_rev[1], keys[1]);
    let both = ((u64::from(a) << 32) | u64::from(b)).reverse_bits();
    [
        u32_to_f32_norm(both as u32),
        u32_to_f32_norm((both >> 32) as u32),
    ]
}

/// Dimensions 0 and 1 of the Sobol sequence by look-up: entry `[d][0][b]` is the reversed-bit
/// coordinate of dimension `d` for the reversed index `b << 24`, entry `[d][1][b]` for `b << 16`
/// (the crate uses the top 16 reversed bits only). Linear over GF(2), so any index is the XOR of
/// one entry of each.
struct SobolTables([[[u32; 256]; 2]; 2]);

impl std::fmt::Debug for SobolTables {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SobolTables (dimensions 0 and 1)")
    }
}

impl SobolTables {
    fn new() -> Self {
        let mut t = [[[0u32; 256]; 2]; 2];
        for (d, dim) in t.iter_mut().enumerate() {
            for b in 0..256u32 {
                dim[0][b as usize] = sobol_rev(b << 24, d as u32);
                dim[1][b as usize] = sobol_rev(b << 16, d as u32);
            }
        }
        SobolTables(t)
    }

    /// `sobol_burley::parts::sobol_rev(index_rev, dimension)` for `dimension` 0 or 1.
    #[inline]
    fn get(&self, dimension: usize, index_rev: u32) -> u32 {
        let t = &self.0[dimension];
        t[0][(index_rev >> 24) as usize] ^ t[1][((index_rev >> 16) & 0xff) as usize]
    }

    /// Point `index` (given with its bits reversed) of the (0,2)-sequence of dimensions 0 and 1
    /// with its index shuffled and its digits Owen-scrambled by `keys` (those of a seed,
    /// [`PairKeys::of`]): bit for bit the first two lanes of `sobol_burley::sample_4d(index, 0,
    /// seed)`.
    #[inline]
    fn point(&self, index_rev: u32, keys: PairKeys) -> [f32; 2] {
        // The index shuffled (Burley's nested uniform scramble of the index), still reversed.
        let rev = owen_scramble_rev(index_rev, keys.shuffle);
        scrambled([self.get(0, rev), self.get(1, rev)], keys.dimensions)
    }
}

static TABLES: LazyLock<SobolTables> = LazyLock::new(SobolTables::new);

/// The random numbers of one pixel sample.
#[derive(Clone, Debug)]
pub enum SampleStream {
    /// Owen-scrambled Sobol pairs.
    Sobol(SobolStream),
    /// Independent PCG32 numbers.
    Independent(IndependentStream),
}

/// An independent stream and what made it.
#[derive(Clone, Debug)]
pub struct IndependentStream {
    rng: PixelRng,
    seed: u64,
    pixel: u64,
}

impl SampleStream {
    /// The stream of sample `sample` of pixel `pixel` (any linear pixel index) in a render seeded
    /// with `seed`. Equal arguments give equal streams on every machine and thread count.
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, sample: u32) -> Self {
        match kind {
            SamplerKind::Sobol => SampleStream::Sobol(SobolStream::new(seed, pixel, sample)),
            SamplerKind::Independent => SampleStream::Independent(IndependentStream {
                rng: PixelRng::new(seed, pixel, sample),
                seed,
                pixel,
            }),
        }
    }

    /// [`SampleStream::new`], for drawing several samples of the pixel through
    /// [`SampleStream::restart`]: a Sobol stream then keeps the pixel's pair keys it makes
    /// ([`PairKeys`]), so that each pair's are hashed once per pixel, not once per sample (at
    /// the cost of a 0.4 KiB table per stream, which one sample would not repay).
    pub fn keeping_keys(kind: SamplerKind, seed: u64, pixel: u64, sample: u32) -> Self {
        match kind {
            SamplerKind::Sobol => {
                SampleStream::Sobol(SobolStream::keeping_keys(seed, pixel, sample))
            }
            SamplerKind::Independent => SampleStream::new(kind, seed, pixel, sample),
        }
    }

    /// Makes this the stream of sample `sample` of the same pixel, from its first number:
    /// equal to a new one ([`SampleStream::new`]), with the pair keys it kept.
    pub fn restart(&mut self, sample: u32) {
        match self {
            SampleStream::Sobol(s) => s.restart(sample),
            SampleStream::Independent(s) => s.rng = PixelRng::new(s.seed, s.pixel, sample),
        }
    }

    /// Two numbers in `[0, 1)`, stratified together across a pixel's samples (Sobol).
    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        match self {
            SampleStream::Sobol(s) => s.next_2d(),
            SampleStream::Independent(s) => [s.rng.next_f32(), s.rng.next_f32()],
        }
    }

    /// Passes over the next number without computing it: the later draws are those after a
    /// [`SampleStream::next_1d`] (a Sobol pair's hashes and scrambles, or one PCG step).
    #[inline]
    pub fn skip_1d(&mut self) {
        match self {
            SampleStream::Sobol(s) => s.skip_2d(),
            SampleStream::Independent(s) => {
                s.rng.next_f32();
            }
        }
    }

    /// Passes over the next pair (two numbers of the independent stream) without using it:
    /// the later draws are those after a [`SampleStream::next_2d`].
    #[inline]
    pub fn skip_2d(&mut self) {
        match self {
            SampleStream::Sobol(s) => s.skip_2d(),
            SampleStream::Independent(s) => {
                s.rng.next_f32();
                s.rng.next_f32();
            }
        }
    }

    /// `count` pairs for `count` draws of one estimate within the sample (a vertex's ambient
    /// occlusion rays), stratified together: with Sobol they are points `sample * count` to
    /// `sample * count + count - 1` of one fresh pair's scrambled (0,2)-sequence, so the
    /// `count` pairs of one sample already spread over the square (a (0,2,2)-net for 4), and a
    /// pixel's `2^m` samples give the estimate a `(0, m + log2 count, 2)`-net of `2^m count`
    /// points, where `count` separate pairs would give `count` independent nets of `2^m` each
    /// (Owen 1997: the variance of a scrambled net falls as `n^-1.5` with edges, so one net of
    /// `4n` points has half the variance of four of `n`). Each pair is still uniform on
    /// `[0, 1)^2`. Where `(sample + 1) count` passes [`SOBOL_MAX_SAMPLES`], and with the
    /// independent sampler, they are `count` separate pairs ([`SampleStream::next_2d`]).
    /// The stratification across samples needs the same `count` at the same draw in every
    /// sample of the pixel (with another it stays unbiased, only less stratified).
    pub fn pairs(&mut self, count: u32) -> impl Iterator<Item = [f32; 2]> + '_ {
        let joint = match self {
            SampleStream::Sobol(s) => s.pairs(count),
            SampleStream::Independent(_) => None,
        };
        let separate = if joint.is_none() { count } else { 0 };
        joint
            .into_iter()
            .flatten()
            .chain((0..separate).map(move |_| self.next_2d()))
    }

    /// One number in `[0, 1)`.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        match self {
            SampleStream::Sobol(s) => s.next_1d(),
            SampleStream::Independent(s) => s.rng.next_f32(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_bit_for_bit_those_of_sobol_burley() {
        let seeds = [0u32, 1, 2, 0xdead_beef, u32::MAX, 0x1234_5678];
        for &seed in &seeds {
            for index in (0..SOBOL_MAX_SAMPLES)
                .step_by(7)
                .chain([SOBOL_MAX_SAMPLES - 1])
            {
                let pair = TABLES.point(index.reverse_bits(), PairKeys::of(seed));
                let [a, b, _, _] = sobol_burley::sample_4d(index, 0, seed);
                assert_eq!(pair, [a, b], "index {index}, seed {seed:#x}");
                assert_eq!(pair[0], sobol_burley::sample(index, 0, seed));
            }
        }
    }

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

    #[test]
    fn a_restarted_stream_draws_what_a_new_one_draws() {
        // Every kind of draw, past the kept pairs, in samples taken out of order through one
        // restarted stream (its kept keys made by earlier samples, some pairs skipped there).
        let draws = |s: &mut SampleStream, skip: bool| {
            let mut out = Vec::new();
            for k in 0..(KEPT_PAIRS as u32 + 6) {
                match k % 4 {
                    0 => out.extend(s.next_2d()),
                    1 if skip => s.skip_1d(),
                    1 => out.push(s.next_1d()),
                    2 => out.extend(s.pairs(4).flatten()),
                    _ => s.skip_2d(),
                }
            }
            out
        };
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            let mut kept = SampleStream::keeping_keys(kind, 3, 17, 5);
            for (sample, skip) in [(5, true), (0, false), (7, false), (5, false), (2, true)] {
                kept.restart(sample);
                let fresh = draws(&mut SampleStream::new(kind, 3, 17, sample), skip);
                assert_eq!(draws(&mut kept, skip), fresh, "{kind:?}, sample {sample}");
            }
        }
    }

    #[test]
    fn a_skipped_pair_or_number_leaves_the_later_draws_unchanged() {
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            let mut drawn = SampleStream::new(kind, 7, 11, 3);
            let mut skipped = drawn.clone();
            drawn.next_2d();
            skipped.skip_2d();
            assert_eq!(drawn.next_2d(), skipped.next_2d());
            assert_eq!(drawn.next_1d(), skipped.next_1d());
            // A skipped number likewise (one PCG step, not two).
            drawn.next_1d();
            skipped.skip_1d();
            assert_eq!(drawn.next_2d(), skipped.next_2d());
            assert_eq!(drawn.next_1d(), skipped.next_1d());
        }
    }

    /// Asserts that `points` (`2^m` of them) form a (0,m,2)-net: every elementary interval of
    /// area `2^-m` (`2^-k` by `2^-(m-k)`) holds exactly one.
    fn assert_net(points: &[[f32; 2]], m: u32, what: &str) {
        let n = 1usize << m;
        assert_eq!(points.len(), n, "{what}");
        for k in 0..=m {
            let (columns, rows) = (1usize << k, 1usize << (m - k));
            let mut seen = vec![false; n];
            for p in points {
                // Powers of two: exact in f32.
                let cell = (p[0] * columns as f32) as usize * rows + (p[1] * rows as f32) as usize;
                assert!(
                    !seen[cell],
                    "{what}: two points in cell {cell} of {columns} x {rows}"
                );
                seen[cell] = true;
            }
        }
    }

    #[test]
    fn joint_pairs_are_a_net_in_one_sample_and_across_the_pixel() {
        for pixel in 0..32 {
            let stream = |sample| SampleStream::new(SamplerKind::Sobol, 5, pixel, sample);
            // One sample's 4 occlusion rays: a (0,2,2)-net.
            let one: Vec<[f32; 2]> = stream(0).pairs(4).collect();
            assert_net(&one, 2, "one sample");
            // 16 samples of 4: a (0,6,2)-net of 64 points, not four nets of 16.
            let pixel_points: Vec<[f32; 2]> = (0..16)
                .flat_map(|sample| stream(sample).pairs(4).collect::<Vec<_>>())
                .collect();
            assert_net(&pixel_points, 6, "16 samples of 4");
        }
    }

    #[test]
    fn joint_pairs_take_one_pair_of_the_stream() {
        let mut joint = SampleStream::new(SamplerKind::Sobol, 9, 4, 3);
        let mut skipped = joint.clone();
        assert_eq!(joint.pairs(8).count(), 8);
        skipped.skip_2d();
        assert_eq!(joint.next_2d(), skipped.next_2d());
    }

    #[test]
    fn pairs_are_separate_where_they_cannot_be_joint() {
        // The independent sampler, and Sobol indices past 2^16: `count` ordinary pairs.
        for (kind, sample) in [
            (SamplerKind::Independent, 3),
            (SamplerKind::Sobol, SOBOL_MAX_SAMPLES - 1),
        ] {
            let mut pairs = SampleStream::new(kind, 2, 7, sample);
            let mut single = pairs.clone();
            let drawn: Vec<[f32; 2]> = pairs.pairs(4).collect();
            let expected: Vec<[f32; 2]> = (0..4).map(|_| single.next_2d()).collect();
            assert_eq!(drawn, expected, "{kind:?}");
            assert_eq!(pairs.next_1d(), single.next_1d());
        }
        // The last sample whose run still fits is joint.
        let last = SOBOL_MAX_SAMPLES / 4 - 1;
        let mut joint = SampleStream::new(SamplerKind::Sobol, 2, 7, last);
        let mut single = joint.clone();
        assert_ne!(joint.pairs(4).next(), Some(single.next_2d()));
    }
}
