//! How widely a light's power spreads about its direction, as the solid angle of a uniform cone:
//! what sizes the light's soft shadow ([`crate::Light::spread_sr`]).
//!
//! A light stands for a set of probe pixels `p` with energy `E_p = Y(L_p) dOmega_p` (luminance x
//! sr), direction `d_p` and solid angle `dOmega_p`. Its spread is measured by the **half-energy
//! angle** `t_h` about the light's direction `w`: half of `sum E_p` lies at `1 - d_p . w <= 1 -
//! cos t_h`. A uniform cone has half its power within half its solid angle, so the cone with
//! the same half-energy angle has solid angle `2 x 2 pi (1 - cos t_h) = 4 pi (1 - cos t_h)`.
//! To that comes the pixels' own extent, `Q / P` with `Q = sum E_p dOmega_p` and `P = sum E_p`
//! (the energy-weighted mean pixel solid angle), so one bright pixel spreads over its own solid
//! angle rather than none.
//!
//! Why a median and not a moment: a region (or LightGen cluster) holding a sun and 0.2 sr of dim
//! sky has most of its power in the sun, and its shadow should be the sun's. Its mean cosine
//! (the second moment of the angle) is dominated by the far sky pixels: the equal-variance cone
//! is several times wider than the sun, while the half-energy angle stays inside it. (On the
//! bundled bunny-sky scene at 32 lights, LightGen's relative MSE against the path-traced
//! reference with the cone of its region's solid angle: 3.4e-2; of the equal-variance cone:
//! 3.2e-3; of the half-energy cone: 1.2e-3. BENCHMARKS.md, "Round 4".)
//!
//! **A core and a halo.** One cone cannot be both: the same cluster's shadow is the sun's, but
//! about a tenth of its power is sky that an occluder of the sun does not hide. So the light is
//! also given a two-cone shape, a **core** (the spread above) holding the fraction `f` of the
//! power and a **halo**, the uniform cone of the light's source solid angle `A`, holding
//! `1 - f` ([`SpreadHistogram::core_fraction`]). `f` is the least-squares fit of the two cones'
//! cumulative power to the pixels', over `x = 1 - cos` from 0 to the halo's edge `x_A = A / 2
//! pi` (uniform in solid angle, where a uniform cone's cumulative power is a straight line):
//!
//! ```text
//! G(x) = f min(x / x_c, 1) + (1 - f) x / x_A
//! f    = int (F - b)(a - b) dx / int (a - b)^2 dx,   a = min(x / x_c, 1), b = x / x_A
//! ```
//!
//! clamped to `[0, 1]`, with `F` the histogram's cumulative fraction and `x_c` the core's. A
//! uniform region gives `f = 1` (its core is the whole cone); the bundled sky probe's sun, held
//! by LightGen's brightest cluster of 32 with 0.24 sr of sky, gives 0.958: rendered by hand
//! with `f` from 0.7 to 1 that light's bunny-sky error was least at 0.92 to 0.95 (BENCHMARKS.md,
//! "A core and a halo").
//!
//! Only a core narrow enough beside its source gets a halo: at most half the source's solid
//! angle for a region of the lat-long image ([`WIDEST_CORE_IN_A_REGION`]), nine tenths for a
//! LightGen cluster ([`WIDEST_CORE_IN_A_CLUSTER`]). The halo is a uniform cone about the light.
//! A lat-long rectangle (median cut's, variance minimisation's) is often long and thin, and a
//! cone of its solid angle blurs its shadow the wrong way: with a halo for every core below 0.9
//! of the region, 16 variance-minimisation lights on bunny-apartment scored 13.1x the
//! reference's noise floor against 9.6x without halos (9.9x with the bound of one half; their
//! regions with cores of 0.7 to 0.9 of the source fitted `f` anywhere from 0 to 0.7). A
//! LightGen cluster is the set of pixels nearest a direction, a compact cell of the sphere,
//! which a cone stands for: its 16 lights on bunny-apartment scored 6.9x with the bound of one
//! half and 4.5x with nine tenths (bunny-sky: 5.1x with either). (These were measured while a
//! halo light sent one shadow ray a sample; BENCHMARKS.md, "A core and a halo", has the
//! figures with one ray into each cone.) Above nine tenths the two cones are nearly one shape
//! and `f` loses its meaning (`a - b -> 0`).
//!
//! The half-energy angle is found in a histogram of `1 - cos` over [`BINS`] bins, eight per
//! octave from `2^-32` to 2 (bins read off the f64 bit pattern: no logarithm per pixel), with
//! linear interpolation inside the bin that holds the half: `1 - cos t_h` to within 9 % of
//! itself (`t_h` within 5 %), far finer than a penumbra's visible size. Histograms merge by
//! adding bins, so rows can be summed apart and merged in a fixed order (results do not depend
//! on the thread count).

/// Bins per octave of `1 - cos`.
const PER_OCTAVE: u32 = 8;
/// Octaves below 2 that get bins: keys below `2^-32` (angles under 2e-5 rad) share the first.
const OCTAVES: u32 = 33;
/// Number of bins.
pub const BINS: usize = (PER_OCTAVE * OCTAVES) as usize;
/// Biased exponent of `2^-32`, the first bin's lower bound.
const FIRST_EXPONENT: u64 = 1023 - 32;

/// The widest core, as a fraction of its source's solid angle, that gets a halo when the source
/// is a region of the lat-long image (median cut, adaptive median cut, variance minimisation):
/// wider cores keep all the power (module doc, "A core and a halo").
pub const WIDEST_CORE_IN_A_REGION: f64 = 0.5;

/// The same for a LightGen cluster: the pixels nearest a direction, a compact cell of the sphere
/// that a cone stands for better than for a lat-long rectangle (module doc).
pub const WIDEST_CORE_IN_A_CLUSTER: f64 = 0.9;

/// A histogram of a light's energy over `1 - cos` of the angle to its direction, with the
/// energy and the pixels' extent it needs for [`SpreadHistogram::spread_sr`].
#[derive(Clone, Debug, PartialEq)]
pub struct SpreadHistogram {
    bins: Vec<f64>,
    energy: f64,
    extent: f64,
}

impl Default for SpreadHistogram {
    fn default() -> Self {
        SpreadHistogram::new()
    }
}

/// The bin of key `k = 1 - cos` (`k` in `[0, 2]`): from the exponent and the top three mantissa
/// bits of its f64 pattern, which order positive floats as the numbers themselves.
#[inline(always)]
fn bin_of(k: f64) -> usize {
    // `max` sends NaN and negative keys to 0 (bin 0) without a branch.
    let bits = k.max(0.0).to_bits() >> (52 - 3);
    let first = FIRST_EXPONENT << 3;
    (bits.saturating_sub(first) as usize).min(BINS - 1)
}

/// The lower bound of bin `b` (`0` for the first, which also holds every smaller key).
fn bin_start(b: usize) -> f64 {
    if b == 0 {
        return 0.0;
    }
    f64::from_bits(((FIRST_EXPONENT << 3) + b as u64) << (52 - 3))
}

impl SpreadHistogram {
    /// An empty histogram.
    pub fn new() -> SpreadHistogram {
        SpreadHistogram {
            bins: vec![0.0; BINS],
            energy: 0.0,
            extent: 0.0,
        }
    }

    /// Adds a pixel of energy `energy` (luminance x sr, >= 0), solid angle `pixel_sr` and
    /// `one_minus_cos = 1 - d_p . w` to the light's direction `w`. Non-finite or non-positive
    /// energies add nothing.
    #[inline]
    pub fn add(&mut self, one_minus_cos: f64, energy: f64, pixel_sr: f64) {
        if !(energy > 0.0 && energy.is_finite()) {
            return;
        }
        self.bins[bin_of(one_minus_cos)] += energy;
        self.energy += energy;
        self.extent += energy * pixel_sr;
    }

    /// Adds pixels of one solid angle `pixel_sr` given as `(1 - cos, luminance)` pairs (energy
    /// `luminance x pixel_sr`), as [`SpreadHistogram::add`] of each would but faster: neighbours
    /// mostly fall in one bin, so runs of one bin are summed before they are added (rounding
    /// differs from pixel-by-pixel adds, by the order of additions only). Luminances that are
    /// not positive and finite add nothing.
    pub fn add_pixels(&mut self, pixels: &[(f64, f64)], pixel_sr: f64) {
        let (mut run_bin, mut run) = (0, 0.0);
        let mut sum = 0.0;
        for &(key, y) in pixels {
            // Without a branch: NaN and negative luminances to 0 by `max`, infinite ones to 0.
            let y = if y.is_finite() { y.max(0.0) } else { 0.0 };
            let b = bin_of(key);
            if b != run_bin {
                self.bins[run_bin] += run * pixel_sr;
                (run_bin, run) = (b, 0.0);
            }
            run += y;
            sum += y;
        }
        self.bins[run_bin] += run * pixel_sr;
        self.energy += sum * pixel_sr;
        self.extent += sum * pixel_sr * pixel_sr;
    }

    /// Adds `other`'s pixels.
    pub fn merge(&mut self, other: &SpreadHistogram) {
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            *a += b;
        }
        self.energy += other.energy;
        self.extent += other.extent;
    }

    /// The spread (module doc): `4 pi (1 - cos t_h) + Q / P`, sr, at most `4 pi`; `None` when
    /// no energy was added.
    pub fn spread_sr(&self) -> Option<f64> {
        if !(self.energy > 0.0 && self.energy.is_finite()) {
            return None;
        }
        let half = self.energy / 2.0;
        let mut below = 0.0;
        let mut key = 2.0;
        for (b, &e) in self.bins.iter().enumerate() {
            if below + e >= half && e > 0.0 {
                let (lo, hi) = (bin_start(b), bin_start(b + 1).min(2.0));
                key = lo + (hi - lo) * ((half - below) / e).clamp(0.0, 1.0);
                break;
            }
            below += e;
        }
        let four_pi = 4.0 * std::f64::consts::PI;
        Some((four_pi * key + self.extent / self.energy).min(four_pi))
    }
}

impl SpreadHistogram {
    /// The fraction `f` of the power in the core of `core_sr` (sr) when the rest spreads as a
    /// uniform halo of `source_sr` (sr), fitted to the histogram (module doc), in `[0, 1]`. 1
    /// when the core's `1 - cos` is more than `widest_core` (below 1:
    /// [`WIDEST_CORE_IN_A_REGION`], [`WIDEST_CORE_IN_A_CLUSTER`]) of the halo's, when no energy
    /// was added, or when the inputs are not finite and positive. O([`BINS`]).
    pub fn core_fraction(&self, core_sr: f64, source_sr: f64, widest_core: f64) -> f64 {
        let tau = 2.0 * std::f64::consts::PI;
        let (xc, xa) = (core_sr / tau, (source_sr / tau).min(2.0));
        let narrow = xc > 0.0 && xc <= widest_core.min(0.9) * xa;
        if !(self.energy > 0.0 && self.energy.is_finite() && narrow) {
            return 1.0;
        }
        // The integrals over x in [0, x_A], by the trapezoid rule over the bins' edges (and
        // x_A), the cumulative fraction linear inside a bin.
        let (mut num, mut den) = (0.0, 0.0);
        let (mut below, mut x0, mut r0) = (0.0, 0.0, (0.0, 0.0));
        let term = |x: f64, cdf: f64| {
            let a = (x / xc).min(1.0);
            let b = x / xa;
            ((cdf - b) * (a - b), (a - b) * (a - b))
        };
        for (b, &e) in self.bins.iter().enumerate() {
            let (lo, hi) = (bin_start(b), bin_start(b + 1).min(2.0));
            if lo >= xa {
                break;
            }
            let x1 = hi.min(xa);
            let inside = if hi > lo { (x1 - lo) / (hi - lo) } else { 1.0 };
            let cdf = (below + e * inside) / self.energy;
            // The core's corner at x_c is an edge too, where it falls in this bin.
            let mut edges = [(x1, cdf); 2];
            let mut count = 1;
            if xc > x0 && xc < x1 {
                let at = below + e * ((xc - lo) / (hi - lo)).clamp(0.0, 1.0);
                edges = [(xc, at / self.energy), (x1, cdf)];
                count = 2;
            }
            for &(x, f) in &edges[..count] {
                let r1 = term(x, f);
                num += 0.5 * (r0.0 + r1.0) * (x - x0);
                den += 0.5 * (r0.1 + r1.1) * (x - x0);
                (x0, r0) = (x, r1);
            }
            below += e;
        }
        // `den >= x_A / 300` for a core of at most 0.9 of the halo: never 0.
        if den > 0.0 {
            (num / den).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn bins_are_ordered_and_cover_zero_to_two() {
        assert_eq!(bin_of(0.0), 0);
        assert_eq!(bin_of(1e-30), 0);
        assert_eq!(bin_of(2.0), BINS - 1);
        let mut last = 0;
        for k in 1..2000 {
            let x = 2.0 * (k as f64 / 2000.0).powi(8);
            let b = bin_of(x);
            assert!(b >= last);
            assert!(bin_start(b) <= x && x < bin_start(b + 1), "{x} in bin {b}");
            last = b;
        }
    }

    /// A uniform cone of half-angle `a` sampled finely in `1 - cos` (uniform in solid angle):
    /// its spread is its own solid angle `2 pi (1 - cos a)`, to the bins' resolution.
    #[test]
    fn a_uniform_cone_spreads_over_its_own_solid_angle() {
        for a in [0.003f64, 0.05, 0.3, 1.0, 2.5] {
            let mut h = SpreadHistogram::new();
            let n = 20_000;
            let top = 1.0 - a.cos();
            for k in 0..n {
                h.add(top * (k as f64 + 0.5) / n as f64, 1.0, 0.0);
            }
            let expected = TAU * top;
            let got = h.spread_sr().unwrap();
            // Linear interpolation inside a bin of a uniform density is exact but for the
            // sampling: 1e-3 relative.
            assert!(
                (got - expected).abs() < 1e-3 * expected,
                "{a}: {got} {expected}"
            );
        }
    }

    #[test]
    fn a_sun_in_dim_sky_keeps_the_suns_spread() {
        // 90 % of the energy in a 0.5-degree sun (uniform in 1 - cos), 10 % spread over 15
        // degrees: the half-energy cone is the sun's (the sky moves the median by 1/0.9).
        let sun = 1.0 - 0.25f64.to_radians().cos();
        let sky = 1.0 - 15f64.to_radians().cos();
        let mut h = SpreadHistogram::new();
        for k in 0..9000 {
            h.add(sun * (k as f64 + 0.5) / 9000.0, 1.0, 0.0);
        }
        for k in 0..1000 {
            h.add(sky * (k as f64 + 0.5) / 1000.0, 1.0, 0.0);
        }
        let got = h.spread_sr().unwrap();
        let sun_sr = TAU * sun;
        assert!(got > 0.9 * sun_sr && got < 1.2 * sun_sr, "{got} {sun_sr}");
    }

    /// A sun of 0.5 degrees holding a share `f` of the power, the rest uniform over a cone of
    /// 15 degrees (the halo): the fit gives the share back. A uniform cone is all core.
    #[test]
    fn the_core_fraction_is_the_suns_share_of_the_power() {
        let sun = 1.0 - 0.25f64.to_radians().cos();
        let sky = 1.0 - 15f64.to_radians().cos();
        for share in [0.5, 0.8, 0.9, 0.97] {
            let mut h = SpreadHistogram::new();
            for k in 0..10_000 {
                h.add(sun * (k as f64 + 0.5) / 10_000.0, share / 10_000.0, 0.0);
                h.add(
                    sky * (k as f64 + 0.5) / 10_000.0,
                    (1.0 - share) / 10_000.0,
                    0.0,
                );
            }
            let core = h.spread_sr().unwrap();
            let f = h.core_fraction(core, TAU * sky, WIDEST_CORE_IN_A_REGION);
            // The sky inside the sun's cone counts as core: `share + (1 - share) sun / sky`,
            // within the trapezoid rule's error over the bins (3e-3).
            let expected = share + (1.0 - share) * sun / sky;
            assert!((f - expected).abs() < 3e-3, "{share}: {f} {expected}");
        }
        let mut uniform = SpreadHistogram::new();
        for k in 0..10_000 {
            uniform.add(sky * (k as f64 + 0.5) / 10_000.0, 1.0, 0.0);
        }
        let core = uniform.spread_sr().unwrap();
        for widest in [WIDEST_CORE_IN_A_REGION, WIDEST_CORE_IN_A_CLUSTER] {
            let f = uniform.core_fraction(core, TAU * sky, widest);
            assert!(f > 0.99, "{f}");
            // A core half the cone: the uniform cone is all halo.
            let f = uniform.core_fraction(0.5 * TAU * sky, TAU * sky, widest);
            assert!(f < 0.01, "{f}");
        }
        assert_eq!(uniform.core_fraction(TAU * sky, TAU * sky, 0.9), 1.0);
        assert_eq!(SpreadHistogram::new().core_fraction(0.1, 1.0, 0.5), 1.0);
        assert_eq!(uniform.core_fraction(f64::NAN, 1.0, 0.5), 1.0);
    }

    #[test]
    fn one_pixel_spreads_over_itself_and_black_is_unknown() {
        let mut h = SpreadHistogram::new();
        h.add(0.0, 3.0, 1e-4);
        // Keys below the first bin's top (2^-32 x 9/8) are not told apart: 4 pi x 2.6e-10.
        assert!((h.spread_sr().unwrap() - 1e-4).abs() < 4e-9);
        assert_eq!(SpreadHistogram::new().spread_sr(), None);
        let mut black = SpreadHistogram::new();
        black.add(0.5, 0.0, 1.0);
        black.add(0.5, f64::NAN, 1.0);
        assert_eq!(black.spread_sr(), None);
        // The whole sphere, uniformly: half the energy within the hemisphere, 4 pi.
        let mut all = SpreadHistogram::new();
        for k in 0..10_000 {
            all.add(2.0 * (k as f64 + 0.5) / 10_000.0, 1.0, 0.0);
        }
        assert!((all.spread_sr().unwrap() - 4.0 * PI).abs() < 1e-2);
    }

    #[test]
    fn rows_of_pixels_add_as_single_pixels_do() {
        let pixels: Vec<(f64, f64)> = (0..500)
            .map(|k| {
                (
                    (k as f64 / 500.0).powi(2),
                    if k % 7 == 0 {
                        0.0
                    } else {
                        1.0 + (k % 5) as f64
                    },
                )
            })
            .chain([(0.3, f64::NAN), (0.3, -1.0), (0.4, f64::INFINITY)])
            .collect();
        let (mut rows, mut single) = (SpreadHistogram::new(), SpreadHistogram::new());
        rows.add_pixels(&pixels, 0.01);
        for &(key, y) in &pixels {
            single.add(key, y * 0.01, 0.01);
        }
        let (x, y) = (rows.spread_sr().unwrap(), single.spread_sr().unwrap());
        assert!((x - y).abs() < 1e-12 * y, "{x} {y}");
        assert!((rows.energy - single.energy).abs() < 1e-12 * single.energy);
    }

    #[test]
    fn merged_halves_equal_the_whole() {
        let (mut a, mut b, mut whole) = (
            SpreadHistogram::new(),
            SpreadHistogram::new(),
            SpreadHistogram::new(),
        );
        for k in 0..100 {
            let key = (k as f64 / 100.0).powi(3);
            let e = 1.0 + k as f64;
            if k % 2 == 0 { &mut a } else { &mut b }.add(key, e, 0.001);
            whole.add(key, e, 0.001);
        }
        a.merge(&b);
        let (x, y) = (a.spread_sr().unwrap(), whole.spread_sr().unwrap());
        assert!((x - y).abs() < 1e-12 * y);
    }
}
