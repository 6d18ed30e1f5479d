//! Monte Carlo sampling building blocks: a per-pixel random number generator, an orthonormal basis
//! from a normal, cosine-weighted hemisphere and uniform cone sampling with their densities, a
//! piecewise-constant 1-D distribution and the power heuristic for multiple importance sampling.
//!
//! - [`PixelRng`]: PCG32 (O'Neill 2014, the `XSH RR` output on a 64-bit LCG) whose state and stream
//!   are a `splitmix64` hash (Steele et al. 2014) of `(seed, pixel, sample)`. Every pixel sample
//!   owns its own generator, so an image does not depend on the thread count or on the order in
//!   which pixels are rendered. `next_f32` returns the top 24 bits, a multiple of `2^-24` in
//!   `[0, 1)`. O(1) per number.
//! - [`OrthonormalBasis`]: the branchless construction of Duff et al. 2017 ("Building an orthonormal
//!   basis, revisited", JCGT 6(1)); `to_world` and `to_local` convert between the world frame and
//!   the local frame whose `+z` is the normal.
//! - [`sample_cosine_hemisphere`]: Malley's method on the concentric disc map of Shirley and Chiu
//!   1997, `pdf = cos(theta) / pi` per steradian (local `+z` up).
//! - [`UniformCone`]: directions uniform in solid angle within `theta <= a` about local `+z`. A light
//!   of solid angle `A` (sr) is the cone with `A = 2 pi (1 - cos a)`; the cone keeps `1 - cos a`
//!   itself so that cones of a sun's size (`A ~ 6e-5 sr`) lose no precision; `pdf = 1 / A`.
//!   With `A = 4 pi` it is the uniform sphere.
//! - [`Distribution1D`]: discrete sampling proportional to non-negative weights by binary search on
//!   an f32 CDF, O(n) to build (sums in f64), O(log n) to sample. The probability it reports for a
//!   cell is the width of that cell in the stored CDF, which is exactly the probability that a
//!   uniform `u` selects it, so densities and samples never disagree.
//! - [`power_heuristic`]: Veach 1997 (section 9.2.4), exponent 2, one sample per technique.
//! - [`cos_sin_turn`]: `(cos 2 pi u, sin 2 pi u)` without a libm call: the angle is reduced to
//!   a quadrant exactly (`4u` splits into integer and fraction without rounding) and the
//!   remaining `|alpha| <= pi / 4` goes through the Taylor polynomials of degree 8 (cos) and
//!   9 (sin), whose truncation at `pi / 4` (the next terms, `alpha^10 / 10!` = 2.5e-8 and
//!   `alpha^11 / 11!` = 1.8e-9) is below the f32 rounding of the result. The warps call it once
//!   per sample (a soft shadow's cone point per light); `sincosf` was 6 % of a lights render.
//!
//! Directions are unit `Vec3` in whatever frame the caller works in (the world frame of
//! `docs/CONVENTIONS.md` section 1 for the renderer); densities are per steradian.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI, TAU};

use glam::Vec3;

/// `splitmix64` finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mixer.
pub(crate) fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// PCG32 LCG multiplier (O'Neill 2014).
const PCG_MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// A small, fast random number generator owned by one sample of one pixel (PCG32).
#[derive(Clone, Debug)]
pub struct PixelRng {
    state: u64,
    increment: u64,
}

impl PixelRng {
    /// The generator of sample `sample` of pixel `pixel` (any linear pixel index) for a render
    /// seeded with `seed`. Equal arguments give equal sequences on every machine and thread count.
    pub fn new(seed: u64, pixel: u64, sample: u32) -> Self {
        let key = splitmix64(seed ^ splitmix64(pixel.wrapping_add(splitmix64(u64::from(sample)))));
        let mut rng = PixelRng {
            state: 0,
            increment: (splitmix64(key ^ 0x5851_f42d_4c95_7f2d) << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(key);
        rng.next_u32();
        rng
    }

    /// The next 32 uniformly distributed bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(PCG_MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// A uniform number in `[0, 1)`: a multiple of `2^-24`, so `1.0` is never returned.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// A right-handed orthonormal basis `(tangent, bitangent, normal)`: local `(x, y, z)` axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrthonormalBasis {
    /// Local `+x`, unit, perpendicular to `normal`.
    pub tangent: Vec3,
    /// Local `+y`, `normal x tangent`.
    pub bitangent: Vec3,
    /// Local `+z`, the unit normal the basis was built from.
    pub normal: Vec3,
}

impl OrthonormalBasis {
    /// The basis about a unit normal (Duff et al. 2017, Listing 3, branchless: no singularity at
    /// `n.z = -1`). `n` must be unit length; the result is orthonormal to f32 rounding.
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0_f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        OrthonormalBasis {
            tangent: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            bitangent: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            normal: n,
        }
    }

    /// World vector of local coordinates `v` (`v.z` along the normal).
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }

    /// Local coordinates of world vector `v`.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(
            v.dot(self.tangent),
            v.dot(self.bitangent),
            v.dot(self.normal),
        )
    }
}

/// `(cos alpha, sin alpha)` for `|alpha| <= pi / 4` (Taylor polynomials, module notes).
#[inline]
fn cos_sin_octant(alpha: f32) -> (f32, f32) {
    let a2 = alpha * alpha;
    let cos =
        1.0 + a2 * (-1.0 / 2.0 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0))));
    let sin = alpha
        * (1.0
            + a2 * (-1.0 / 6.0
                + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362_880.0)))));
    (cos, sin)
}

/// `u.floor()` without a call to the C library's `floorf` (what `f32::floor` compiles to on the
/// x86-64 baseline, which has no SSE4.1 `roundss`; it was 4 % of a lights-mode render): through
/// a truncating conversion where `|u| < 2^23`, `u` itself beyond (every such float is an
/// integer) and for NaN. Bit for bit `u.floor()` for every input.
#[inline]
fn floor(u: f32) -> f32 {
    if u.abs() < 8_388_608.0 {
        let t = u as i32 as f32;
        // The sign keeps -0.0 (whose truncation is +0.0) as it is.
        if t > u { t - 1.0 } else { t.copysign(u) }
    } else {
        u
    }
}

/// `(cos 2 pi u, sin 2 pi u)` for `u` in `[0, 1)` (other values are wrapped into it), each
/// within 2e-7 of the exact value (module notes).
#[inline]
pub fn cos_sin_turn(u: f32) -> (f32, f32) {
    // A sampler's `u` is in `[0, 1)`, where `u - floor(u)` is `u` itself: the floor is taken
    // only for other values. `four` is then in `[0, 4]` (or NaN), where truncation is the floor
    // (bit for bit, -0.0 and NaN included: both paths give the same angle).
    let fraction = if (0.0..1.0).contains(&u) {
        u
    } else {
        u - floor(u)
    };
    let four = 4.0 * fraction;
    let q = four as u32;
    let quadrant = q as f32;
    // 2 pi u = quadrant pi / 2 + pi / 4 + alpha, |alpha| <= pi / 4.
    let alpha = (four - quadrant - 0.5) * (2.0 * FRAC_PI_4);
    let (c, s) = cos_sin_octant(alpha);
    let (c, s) = (
        (c - s) * std::f32::consts::FRAC_1_SQRT_2,
        (c + s) * std::f32::consts::FRAC_1_SQRT_2,
    );
    // The quadrant's turn as two selects, not a four-way branch (random `u` mispredicts it).
    let (x, y) = if q & 1 == 0 { (c, s) } else { (-s, c) };
    if q & 2 == 0 { (x, y) } else { (-x, -y) }
}

/// Maps `[0, 1)^2` onto the unit disc preserving relative area (Shirley and Chiu 1997).
fn concentric_disc(u1: f32, u2: f32) -> (f32, f32) {
    let a = 2.0 * u1 - 1.0;
    let b = 2.0 * u2 - 1.0;
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    if a.abs() > b.abs() {
        // phi = pi / 4 (b / a), within pi / 4 of zero.
        let (c, s) = cos_sin_octant(FRAC_PI_4 * (b / a));
        (a * c, a * s)
    } else {
        // phi = pi / 2 - beta with beta = pi / 4 (a / b): cos phi = sin beta, sin phi = cos beta.
        let (c, s) = cos_sin_octant(FRAC_PI_4 * (a / b));
        (b * s, b * c)
    }
}

/// A cosine-distributed direction about local `+z` from `u1, u2` in `[0, 1)` (Malley's method):
/// density `cos(theta) / pi` per steradian, see [`cosine_hemisphere_pdf`]. The result has
/// `z >= 0` and unit length.
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let (x, y) = concentric_disc(u1, u2);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    Vec3::new(x, y, z)
}

/// Density (1/sr) of [`sample_cosine_hemisphere`] for a direction with `cos(theta) = cos_theta`
/// to the axis: `max(0, cos_theta) / pi`.
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Directions uniform in solid angle within a cone of half-angle `a` about local `+z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniformCone {
    /// `1 - cos(a)`, in `(0, 2]`.
    one_minus_cos: f32,
}

impl UniformCone {
    /// The whole sphere (`a = pi`, solid angle `4 pi`).
    pub const SPHERE: UniformCone = UniformCone { one_minus_cos: 2.0 };

    /// The cone of solid angle `solid_angle_sr` (sr), `cos(a) = 1 - A / (2 pi)`; solid angles
    /// above `4 pi` give the sphere. `None` when the solid angle is not finite and positive.
    pub fn from_solid_angle(solid_angle_sr: f32) -> Option<Self> {
        (solid_angle_sr.is_finite() && solid_angle_sr > 0.0).then(|| UniformCone {
            one_minus_cos: (solid_angle_sr / TAU).min(2.0),
        })
    }

    /// The cone of half-angle `half_angle` (radians, `(0, pi]`; larger angles give the sphere).
    /// `None` when the angle is not finite and positive.
    pub fn from_half_angle(half_angle: f32) -> Option<Self> {
        (half_angle.is_finite() && half_angle > 0.0).then(|| {
            let s = (0.5 * half_angle.min(PI)).sin();
            UniformCone {
                one_minus_cos: 2.0 * s * s,
            }
        })
    }

    /// Solid angle (sr): `2 pi (1 - cos a)`.
    pub fn solid_angle(&self) -> f32 {
        TAU * self.one_minus_cos
    }

    /// Cosine of the half-angle.
    pub fn cos_half_angle(&self) -> f32 {
        1.0 - self.one_minus_cos
    }

    /// Density (1/sr) of a direction inside the cone: `1 / solid_angle`.
    pub fn pdf(&self) -> f32 {
        1.0 / self.solid_angle()
    }

    /// The mean over the cone (uniform in solid angle) of the clamped cosine `max(0, n . w)` to a
    /// unit normal `n` at angle `beta` from the axis, `cos_beta = n . axis`: the irradiance a
    /// surface of normal `n` receives from the cone at uniform radiance `L` is `L A` times this
    /// (`A` the cone's solid angle). With `s = sin a`:
    ///
    /// - cone wholly above the horizon (`cos_beta >= s`): `cos_beta (1 + cos a) / 2`, from
    ///   `int max(0, n . w) dw = pi s^2 cos_beta` (the mean direction of a uniform cap is the axis
    ///   times `(1 + cos a) / 2`);
    /// - wholly below (`cos_beta <= -s`): 0;
    /// - cut by the horizon: Snyder's closed form for a spherical source partly below the
    ///   horizon (J. Snyder, "Area light sources for real-time graphics", Microsoft Research
    ///   MSR-TR-96-11, 1996), with `x = cot a` and `y = -x cot(beta)`:
    ///   `int = s^2 (cos_beta acos(y) - x sin_beta sqrt(1 - y^2)) + atan(sin_beta sqrt(1 - y^2)
    ///   / x)`;
    /// - a cone wider than a hemisphere (`a > pi / 2`): `pi` (the whole sphere's integral) minus
    ///   the integral over the complementary cone about `-axis`.
    ///
    /// Evaluated in f64; the cases meet continuously (tests check them against quadrature).
    pub fn mean_clamped_cosine(&self, cos_beta: f32) -> f32 {
        let omc = f64::from(self.one_minus_cos);
        let integral = clamped_cosine_integral(omc, f64::from(cos_beta).clamp(-1.0, 1.0));
        (integral / (std::f64::consts::TAU * omc)) as f32
    }

    /// A direction about local `+z` from `u1, u2` in `[0, 1)`: `1 - cos(theta) = u1 (1 - cos a)`,
    /// `phi = 2 pi u2`; unit length, and `sin(theta)` comes from `1 - cos(theta)` so tiny cones
    /// stay accurate. Inlined: a lights-mode render draws one per light per sample, and the call
    /// (its result returned through memory) was an eighth of the render's time.
    #[inline]
    pub fn sample(&self, u1: f32, u2: f32) -> Vec3 {
        let one_minus_cos = u1 * self.one_minus_cos;
        let cos_theta = 1.0 - one_minus_cos;
        let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
        let (cp, sp) = cos_sin_turn(u2);
        Vec3::new(sin_theta * cp, sin_theta * sp, cos_theta)
    }
}

/// A cone's [`UniformCone::mean_clamped_cosine`] for repeated use: exact where the cone is
/// wholly above the horizon (`cos_beta (1 + cos a) / 2`) or below it (0), and read from a table
/// of [`ConeShading::STEPS`] intervals, linearly interpolated, across the band where the
/// horizon cuts it (`|cos_beta| < sin a`; every `cos_beta` for a cone wider than a hemisphere),
/// which spares the closed form's `acos` and `atan2` per call. Inside the band the function is
/// smooth but for its ends, where it leaves 0 and meets the line with a singular second
/// derivative; the interpolation error stays under 1e-4 of the cone's light, and under 3e-6
/// for cones up to 70 degrees (a test checks 1e-4 on cones from 0.004 to 3.1 radians, 20 001
/// normals each; the worst, 3.6e-5, is a cone of 86 degrees, nearly a hemisphere).
#[derive(Clone, Debug, PartialEq)]
pub struct ConeShading {
    /// `cos_beta` at the band's ends.
    lo: f32,
    hi: f32,
    /// `(1 + cos a) / 2`: the slope above the band.
    slope: f32,
    /// `STEPS + 1` values across the band.
    table: Vec<f32>,
    /// Wider than a hemisphere: the band is every `cos_beta`.
    wide: bool,
}

impl ConeShading {
    /// Intervals of the table across the band.
    pub const STEPS: usize = 512;

    /// The table of `cone`.
    pub fn new(cone: UniformCone) -> ConeShading {
        let omc = f64::from(cone.one_minus_cos);
        let cos_a = 1.0 - omc;
        let (lo, hi) = if cos_a > 0.0 {
            let sin_a = (omc * (2.0 - omc)).sqrt();
            (-sin_a, sin_a)
        } else {
            (-1.0, 1.0)
        };
        let table = (0..=Self::STEPS)
            .map(|k| {
                let c = lo + (hi - lo) * k as f64 / Self::STEPS as f64;
                cone.mean_clamped_cosine(c as f32)
            })
            .collect();
        ConeShading {
            lo: lo as f32,
            hi: hi as f32,
            slope: (1.0 - 0.5 * omc) as f32,
            table,
            wide: cos_a <= 0.0,
        }
    }

    /// The cone's mean clamped cosine to a normal at `cos_beta` from its axis.
    #[inline]
    pub fn mean_clamped_cosine(&self, cos_beta: f32) -> f32 {
        if !self.wide {
            if cos_beta >= self.hi {
                return self.slope * cos_beta.min(1.0);
            }
            if cos_beta <= self.lo || cos_beta.is_nan() {
                return 0.0;
            }
        }
        let c = cos_beta.clamp(self.lo, self.hi);
        let x = (c - self.lo) / (self.hi - self.lo) * Self::STEPS as f32;
        // NaN turns to 0 here.
        let k = (x as usize).min(Self::STEPS - 1);
        let t = x - k as f32;
        self.table[k] + (self.table[k + 1] - self.table[k]) * t
    }
}

/// A light's cones ([`crate::lighting::DirectionalLight`]: its core, and its halo with its
/// share `s` of the light) as [`ConeShading`] tables: the mean clamped cosine `(1 - s)
/// mean_core + s mean_halo`, each table within its own bound (1e-4 of its cone's light). Each
/// cone keeps its own table, so a narrow core is not read at a wide halo's step.
#[derive(Clone, Debug, PartialEq)]
pub struct LightShading {
    core: ConeShading,
    halo: Option<(ConeShading, f32)>,
}

impl LightShading {
    /// The tables of `core` and of the halo `(cone, share)`, if any.
    pub fn new(core: UniformCone, halo: Option<(UniformCone, f32)>) -> LightShading {
        LightShading {
            core: ConeShading::new(core),
            halo: halo.map(|(cone, share)| (ConeShading::new(cone), share)),
        }
    }

    /// The light's mean clamped cosine to a normal at `cos_beta` from its axis.
    #[inline]
    pub fn mean_clamped_cosine(&self, cos_beta: f32) -> f32 {
        let core = self.core.mean_clamped_cosine(cos_beta);
        match &self.halo {
            Some((halo, share)) => {
                (1.0 - share) * core + share * halo.mean_clamped_cosine(cos_beta)
            }
            None => core,
        }
    }
}

/// `int_cone max(0, n . w) dw` for a cone of `1 - cos a = omc` about an axis at `cos_beta` to
/// `n` ([`UniformCone::mean_clamped_cosine`]).
fn clamped_cosine_integral(omc: f64, cos_beta: f64) -> f64 {
    use std::f64::consts::PI;
    let cos_a = 1.0 - omc;
    if cos_a < 0.0 {
        // Wider than a hemisphere: the sphere's pi less the complementary cone's share.
        return PI - clamped_cosine_integral(2.0 - omc, -cos_beta);
    }
    let sin_a2 = omc * (2.0 - omc);
    let sin_a = sin_a2.sqrt();
    if cos_beta >= sin_a {
        return PI * sin_a2 * cos_beta;
    }
    if cos_beta <= -sin_a {
        return 0.0;
    }
    // Cut by the horizon (Snyder 1996); here sin_beta > cos_a >= 0.
    let sin_beta = (1.0 - cos_beta * cos_beta).max(0.0).sqrt();
    let x = cos_a / sin_a;
    let y = (-x * cos_beta / sin_beta).clamp(-1.0, 1.0);
    let root = sin_beta * (1.0 - y * y).sqrt();
    (sin_a2 * (cos_beta * y.acos() - x * root) + root.atan2(x)).max(0.0)
}

/// A discrete distribution over `n` cells proportional to non-negative weights, sampled by
/// inverting its cumulative distribution.
///
/// The inversion is a binary search narrowed by a guide table (the cutpoint method, Chen & Asau
/// 1974; Devroye, *Non-Uniform Random Variate Generation*, section III.2.4): for `G` (the
/// largest power of two not above `n`) equal steps of `u`, the table holds the cell where each
/// step starts, so a draw searches only the cells its step spans, usually one or two. The answer
/// is the plain binary search's, bit for bit, and the map from `u` to the cell stays monotone, so
/// low-discrepancy points keep their stratification (an alias table would not). The table holds
/// 16-bit cell indices when there are at most `2^16` cells (every probe row, normal bin and cell
/// of the renderer's tables): a draw is memory-bound (its first read, the table, usually misses
/// the cache), and the narrower table halves the lines the tables take.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// `n + 1` non-decreasing values, `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f32>,
    /// `G + 1` entries: entry `k` is the last cell `i < n` with `cdf[i] <= k / G` (exact in
    /// f64, `G` a power of two). Empty when `n = 0`.
    guide: GuideTable,
    /// Sum of the weights (f64).
    total: f64,
}

/// A [`Distribution1D`]'s guide table, its cell indices as narrow as they fit.
#[derive(Clone, Debug, PartialEq)]
enum GuideTable {
    /// At most `2^16` cells.
    Narrow(Vec<u16>),
    /// More.
    Wide(Vec<u32>),
}

impl GuideTable {
    /// Number of entries (`G + 1`, or 0).
    fn len(&self) -> usize {
        match self {
            GuideTable::Narrow(t) => t.len(),
            GuideTable::Wide(t) => t.len(),
        }
    }

    /// The first and last cells that step `k` spans (`k < G`).
    #[inline]
    fn step(&self, k: usize) -> (usize, usize) {
        match self {
            GuideTable::Narrow(t) => (usize::from(t[k]), usize::from(t[k + 1])),
            GuideTable::Wide(t) => (t[k] as usize, t[k + 1] as usize),
        }
    }
}

/// One draw from a [`Distribution1D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteSample {
    /// The chosen cell.
    pub index: usize,
    /// Its probability (the width of its CDF step), in `(0, 1]`.
    pub probability: f32,
    /// Where `u` fell inside the cell's step, rescaled to `[0, 1)`: a fresh uniform number.
    pub remapped: f32,
}

impl Distribution1D {
    /// The distribution proportional to `weights`. Weights that are negative or not finite count
    /// as 0. When every weight is 0 (or there are none) the cells are equally likely and
    /// [`Distribution1D::total`] reports 0. O(n).
    pub fn new(weights: impl IntoIterator<Item = f64>) -> Self {
        let mut prefix = vec![0.0_f64];
        let mut sum = 0.0_f64;
        for w in weights {
            if w.is_finite() && w > 0.0 {
                sum += w;
            }
            prefix.push(sum);
        }
        let n = prefix.len() - 1;
        let cdf: Vec<f32> = if sum > 0.0 {
            prefix.iter().map(|&p| (p / sum) as f32).collect()
        } else {
            (0..=n)
                .map(|k| (k as f64 / n.max(1) as f64) as f32)
                .collect()
        };
        let mut cdf = cdf;
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let guide = guide_table(&cdf);
        Distribution1D {
            cdf,
            guide,
            total: sum,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sum of the (valid, positive) weights, f64.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Probability of cell `index` (0 outside the range).
    pub fn probability(&self, index: usize) -> f32 {
        match (self.cdf.get(index), self.cdf.get(index + 1)) {
            (Some(&lo), Some(&hi)) => hi - lo,
            _ => 0.0,
        }
    }

    /// The cell selected by `u` in `[0, 1)` (values outside are clamped): the last cell whose
    /// CDF start is `<= u`, which always has a positive probability. `None` only when the
    /// distribution has no cells. O(log n).
    pub fn sample(&self, u: f32) -> Option<DiscreteSample> {
        let n = self.len();
        if n == 0 {
            return None;
        }
        let u = if u.is_nan() {
            0.0
        } else {
            u.clamp(0.0, 1.0 - f32::EPSILON / 2.0)
        };
        // The step of the guide table that `u` falls in (exact: `u` has 24 bits, `G` is a
        // power of two below 2^32), and the cells that step spans.
        let steps = self.guide.len() - 1;
        let k = ((f64::from(u) * steps as f64) as usize).min(steps - 1);
        let (first, last) = self.guide.step(k);
        let index = first + self.cdf[first + 1..=last].partition_point(|&c| c <= u);
        let lo = self.cdf[index];
        let probability = self.cdf[index + 1] - lo;
        let remapped = ((u - lo) / probability).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        Some(DiscreteSample {
            index,
            probability,
            remapped,
        })
    }
}

/// The guide table of a CDF of `n + 1` entries (`cdf[0] = 0`, `cdf[n] = 1`, non-decreasing):
/// `G + 1` entries for `G` the largest power of two `<= n`, entry `k` the last cell `i < n` with
/// `cdf[i] <= k / G`. Empty for `n = 0`. O(n).
fn guide_table(cdf: &[f32]) -> GuideTable {
    let n = cdf.len().saturating_sub(1);
    if n == 0 {
        return GuideTable::Narrow(Vec::new());
    }
    let steps = 1usize << n.ilog2();
    let mut cell = 0usize;
    let starts = (0..=steps).map(move |k| {
        let threshold = k as f64 / steps as f64;
        while cell + 1 < n && f64::from(cdf[cell + 1]) <= threshold {
            cell += 1;
        }
        cell
    });
    if n <= 1 << 16 {
        // Cells below `2^16`.
        GuideTable::Narrow(starts.map(|c| c as u16).collect())
    } else {
        // Cells are fewer than 2^32: the image limits bound `n` by 2^28.
        GuideTable::Wide(
            starts
                .map(|c| u32::try_from(c).unwrap_or(u32::MAX))
                .collect(),
        )
    }
}

/// Veach's power heuristic (exponent 2) for one sample from each of two techniques: the weight of
/// a sample drawn from the technique with density `pdf_this` when the other would have drawn it
/// with density `pdf_other`, `pdf_this^2 / (pdf_this^2 + pdf_other^2)`. 0 when `pdf_this` is 0;
/// 1 when `pdf_this` is infinite (a delta) and `pdf_other` finite. Computed as a ratio, so huge
/// densities do not overflow.
pub fn power_heuristic(pdf_this: f32, pdf_other: f32) -> f32 {
    if pdf_this.is_nan() || pdf_this <= 0.0 {
        return 0.0;
    }
    if pdf_this.is_infinite() {
        return if pdf_other.is_infinite() { 0.5 } else { 1.0 };
    }
    let ratio = pdf_other.max(0.0) / pdf_this;
    1.0 / (1.0 + ratio * ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distribution_skips_zero_cells_and_reports_step_widths() {
        let dist = Distribution1D::new([0.0, 1.0, 0.0, 0.0, 3.0, 0.0]);
        assert_eq!(dist.len(), 6);
        assert_eq!(dist.total(), 4.0);
        assert_eq!(dist.probability(1), 0.25);
        assert_eq!(dist.probability(4), 0.75);
        assert_eq!(dist.probability(0), 0.0);
        assert_eq!(dist.probability(9), 0.0);
        for k in 0..1000 {
            let u = k as f32 / 1000.0;
            let s = dist.sample(u).unwrap();
            assert!(s.index == 1 || s.index == 4, "u {u} chose {}", s.index);
            assert_eq!(s.probability, dist.probability(s.index));
            assert!((0.0..1.0).contains(&s.remapped));
        }
        assert_eq!(dist.sample(0.0).unwrap().index, 1);
        assert_eq!(dist.sample(0.25).unwrap().index, 4);
        assert_eq!(dist.sample(0.999_999_9).unwrap().index, 4);
    }

    #[test]
    fn guided_search_equals_the_plain_binary_search() {
        // Weights with runs of zeros, one dominant cell and tiny ones, at sizes around powers of
        // two (65536 and 65537: the last narrow table and the first wide one); `u` on a fine
        // grid, at every CDF value and just either side of it.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in [
            1usize,
            2,
            3,
            7,
            8,
            9,
            63,
            64,
            65,
            500,
            1024,
            1 << 16,
            (1 << 16) + 1,
        ] {
            let weights: Vec<f64> = (0..n)
                .map(|i| match i % 7 {
                    0 | 3 => 0.0,
                    5 => 1e-9 * next(),
                    _ if i == n / 2 => 1e4,
                    _ => next(),
                })
                .collect();
            let dist = Distribution1D::new(weights);
            let plain = |u: f32| (dist.cdf.partition_point(|&c| c <= u) - 1).min(n - 1);
            let mut us: Vec<f32> = (0..4096).map(|k| k as f32 / 4096.0).collect();
            for &c in &dist.cdf {
                us.extend([c, c.next_down(), c.next_up()]);
            }
            for u in us.into_iter().filter(|u| (0.0..1.0).contains(u)) {
                let s = dist.sample(u).unwrap();
                assert_eq!(s.index, plain(u), "n {n}, u {u}");
                assert!(s.probability > 0.0 || dist.total() == 0.0, "n {n}, u {u}");
            }
        }
    }

    #[test]
    fn all_zero_distribution_is_uniform() {
        let dist = Distribution1D::new([0.0; 4]);
        assert_eq!(dist.total(), 0.0);
        for k in 0..4 {
            assert_eq!(dist.probability(k), 0.25);
        }
        assert_eq!(dist.sample(0.6).unwrap().index, 2);
        assert!(
            Distribution1D::new(std::iter::empty())
                .sample(0.5)
                .is_none()
        );
    }

    #[test]
    fn remapped_u_is_uniform_within_cell() {
        let dist = Distribution1D::new([1.0, 3.0]);
        let s = dist.sample(0.25 + 0.75 * 0.5).unwrap();
        assert_eq!(s.index, 1);
        assert!((s.remapped - 0.5).abs() < 1e-6);
    }

    #[test]
    fn turn_and_octant_trigonometry_match_f64() {
        // 2e-7: the polynomials' truncation (2.5e-8) plus a few f32 roundings of values below 1
        // (6e-8 each); measured 1.2e-7.
        let mut worst = 0.0f64;
        for k in 0..=100_000u32 {
            let u = k as f32 / 100_000.0;
            let (c, s) = cos_sin_turn(u);
            let phi = std::f64::consts::TAU * f64::from(u);
            worst = worst
                .max((f64::from(c) - phi.cos()).abs())
                .max((f64::from(s) - phi.sin()).abs());
            let a = (u - 0.5) * (2.0 * FRAC_PI_4);
            let (c, s) = cos_sin_octant(a);
            let a = f64::from(a);
            worst = worst
                .max((f64::from(c) - a.cos()).abs())
                .max((f64::from(s) - a.sin()).abs());
        }
        assert!(worst < 2e-7, "worst error {worst:e}");
        // The quadrant boundaries are exact in the reduction: 1 and 0 to the polynomials'
        // accuracy there.
        let (c, s) = cos_sin_turn(0.25);
        assert!(c.abs() < 1e-7 && (s - 1.0).abs() < 1e-7, "{c} {s}");
        assert_eq!(cos_sin_turn(1.25), cos_sin_turn(0.25));
    }

    #[test]
    fn the_unit_interval_skips_the_floors_bit_for_bit() {
        // The reduction as it was before `[0, 1)` skipped the floors: `four = 4 (u - floor(u))`,
        // `quadrant = floor(four)`.
        let general = |u: f32| {
            let four = 4.0 * (u - floor(u));
            let quadrant = floor(four);
            let alpha = (four - quadrant - 0.5) * (2.0 * FRAC_PI_4);
            let (c, s) = cos_sin_octant(alpha);
            let (c, s) = (
                (c - s) * std::f32::consts::FRAC_1_SQRT_2,
                (c + s) * std::f32::consts::FRAC_1_SQRT_2,
            );
            let q = quadrant as u32;
            let (x, y) = if q & 1 == 0 { (c, s) } else { (-s, c) };
            if q & 2 == 0 { (x, y) } else { (-x, -y) }
        };
        let bits = |(c, s): (f32, f32)| (c.to_bits(), s.to_bits());
        let mut rng = PixelRng::new(3, 5, 7);
        let edges = [0.0, -0.0, 0.25, 0.5, 0.75, 1.0 - f32::EPSILON / 2.0, 1e-30];
        for u in edges
            .into_iter()
            .chain((0..200_000).map(|_| rng.next_f32()))
        {
            assert_eq!(bits(cos_sin_turn(u)), bits(general(u)), "u = {u:e}");
        }
        for u in [-0.3, 1.7, 12345.678, -1e-9] {
            assert_eq!(bits(cos_sin_turn(u)), bits(general(u)), "u = {u:e}");
        }
    }

    #[test]
    fn cone_from_half_angle_matches_solid_angle() {
        let a = 0.3_f32;
        let cone = UniformCone::from_half_angle(a).unwrap();
        let expected = TAU * (1.0 - a.cos());
        assert!((cone.solid_angle() - expected).abs() < 1e-6 * expected);
        assert!(UniformCone::from_half_angle(-1.0).is_none());
        assert!(UniformCone::from_solid_angle(0.0).is_none());
        assert!(UniformCone::from_solid_angle(f32::NAN).is_none());
        assert_eq!(
            UniformCone::from_solid_angle(100.0),
            Some(UniformCone::SPHERE)
        );
    }

    #[test]
    fn floor_is_bit_for_bit_the_library_floor() {
        let specials = [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            0.999_999_94,
            -0.999_999_94,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            1e30,
            -1e30,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
        ];
        let mut rng = PixelRng::new(3, 4, 5);
        let random = (0..100_000).map(|_| (rng.next_f32() - 0.5) * 2e7);
        for u in specials.into_iter().chain(random) {
            assert_eq!(floor(u).to_bits(), u.floor().to_bits(), "floor({u})");
        }
        assert!(floor(f32::NAN).is_nan());
    }

    /// `int_cone max(0, n . w) dw` by a midpoint rule in the cone's own coordinates (theta
    /// from the axis, phi about it), `n` in the axis's x-z plane.
    fn clamped_cosine_quadrature(half_angle: f64, beta: f64) -> f64 {
        let (steps_t, steps_p) = (800, 800);
        let mut sum = 0.0;
        let n = (beta.sin(), beta.cos());
        for i in 0..steps_t {
            let t = (i as f64 + 0.5) / steps_t as f64 * half_angle;
            for j in 0..steps_p {
                let p = (j as f64 + 0.5) / steps_p as f64 * std::f64::consts::TAU;
                let w = (t.sin() * p.cos(), t.cos());
                sum += (n.0 * w.0 + n.1 * w.1).max(0.0) * t.sin();
            }
        }
        sum * (half_angle / steps_t as f64) * (std::f64::consts::TAU / steps_p as f64)
    }

    #[test]
    fn mean_clamped_cosine_matches_quadrature_on_every_case() {
        // Half-angles from a sun-sized cone to wider than a hemisphere; betas with the cone
        // above, cut by and below the horizon. The midpoint rule's error at 800 x 800 steps is
        // below 1e-5 of pi (the kink along the horizon dominates); the f32 result adds 1e-7.
        for half_angle in [0.05f64, 0.3, 0.7, 1.2, 1.5, 1.7, 2.5, 3.0] {
            let cone = UniformCone::from_half_angle(half_angle as f32).unwrap();
            for beta in [0.0f64, 0.4, 0.9, 1.3, 1.5, 1.6, 1.8, 2.2, 2.8, 3.1] {
                let expected = clamped_cosine_quadrature(half_angle, beta)
                    / (std::f64::consts::TAU * (1.0 - half_angle.cos()));
                let got = f64::from(cone.mean_clamped_cosine(beta.cos() as f32));
                assert!(
                    (got - expected).abs() < 3e-5,
                    "half-angle {half_angle}, beta {beta}: {got} against {expected}"
                );
            }
        }
        // The whole sphere: pi / (4 pi) whatever the normal.
        let sphere = UniformCone::SPHERE.mean_clamped_cosine(0.3);
        assert!((sphere - 0.25).abs() < 1e-6, "{sphere}");
    }

    #[test]
    fn mean_clamped_cosine_is_the_mean_of_cone_samples() {
        // The estimator it replaces: the mean of max(0, n . w) over the cone's own samples.
        let cone = UniformCone::from_half_angle(0.8).unwrap();
        let n = Vec3::new(0.9f32.sin(), 0.0, 0.9f32.cos());
        let k = 512;
        let mut sum = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let w = cone.sample((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                sum += f64::from(n.dot(w).max(0.0));
            }
        }
        let mean = sum / (k * k) as f64;
        let got = f64::from(cone.mean_clamped_cosine(0.9f32.cos()));
        assert!((got - mean).abs() < 1e-4, "{got} against {mean}");
    }

    #[test]
    fn a_mixtures_table_is_the_weighted_closed_form() {
        let core = UniformCone::from_half_angle(0.01).unwrap();
        for (halo_angle, share) in [(0.3f32, 0.1f32), (0.8, 0.4), (1.9, 0.05)] {
            let halo = UniformCone::from_half_angle(halo_angle).unwrap();
            let table = LightShading::new(core, Some((halo, share)));
            for k in 0..=20_000 {
                let c = -1.0 + 2.0 * k as f32 / 20_000.0;
                let exact = (1.0 - share) * core.mean_clamped_cosine(c)
                    + share * halo.mean_clamped_cosine(c);
                let err = (table.mean_clamped_cosine(c) - exact).abs();
                assert!(err < 1e-4, "{halo_angle} {share} at {c}: {err}");
            }
        }
    }

    #[test]
    fn the_cone_shading_table_is_the_closed_form() {
        for half_angle in [0.004f32, 0.05, 0.3, 0.7, 1.2, 1.5, 1.7, 2.5, 3.1] {
            let cone = UniformCone::from_half_angle(half_angle).unwrap();
            let table = ConeShading::new(cone);
            let mut worst = 0.0f32;
            for k in 0..=20_000 {
                let c = -1.0 + 2.0 * k as f32 / 20_000.0;
                let err = (table.mean_clamped_cosine(c) - cone.mean_clamped_cosine(c)).abs();
                worst = worst.max(err);
            }
            assert!(worst < 1e-4, "half-angle {half_angle}: {worst}");
        }
    }
}
