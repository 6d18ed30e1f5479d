//! GGX-prefiltered radiance for the split-sum approximation (Karis 2013), by importance sampling
//! with filtered importance sampling (Krivanek & Colbert 2008).
//!
//! For a direction `n` (= view = reflection, the split-sum assumption) and GGX roughness
//! `alpha = r^2`, the prefiltered radiance is the `D (n.l)`-weighted mean of the environment,
//!
//! ```text
//! LD(n) = integral L(l) D(h) (n.l)+ dl / integral D(h) (n.l)+ dl,   h = (n + l) / |n + l|
//! ```
//!
//! the quantity Filament's cmgen and the Khronos glTF-IBL-Sampler store. It is estimated with N
//! GGX samples `h_i` (Hammersley, [`crate::ggx`]), `l_i = 2 (n.h_i) h_i - n` of density
//! `p(l) = D / 4`: `LD ~ sum L(l_i) (n.l_i) / sum (n.l_i)`. Each sample reads the source's mip
//! pyramid ([`CubePyramid`]) at the level whose texel matches the sample's share of the sphere,
//! `lod = 1/2 log2(Omega_s / Omega_p)` with `Omega_s = 1 / (N p(l))` and `Omega_p` the
//! source texel's solid angle (Krivanek & Colbert eq. 13): a few hundred
//! samples then integrate the lobe without the noise of point samples. (Krivanek & Colbert add
//! a bias of 1; we use 0, see `LOD_BIAS`.)
//!
//! **Energy.** The weights are normalised, so a constant environment prefilters to itself at
//! every roughness (exactly, to f32 rounding) and the kernel, a function of `n.l` alone, keeps
//! the map's power (tested).
//!
//! **No seams.** Every output texel is computed from its own centre direction with the same
//! samples in a tangent frame that varies continuously with `n` ("Building an
//! orthonormal basis from a 3D unit vector" (Frisvad 2012), with its one singular point turned
//! to -Y, straight down), and
//! the look-ups are seamless across cube faces, so texels on either side of a cube edge differ
//! only as much as neighbours inside a face.
//!
//! The samples (local direction, weight `n.l`, level) depend only on roughness, so they are
//! tabulated once per level; each output texel then costs N trilinear look-ups. Texels are
//! independent (rows in parallel), so the result does not depend on the thread count.
//!
//! **Samples per level** ([`samples_for_level`]). A level needs no more samples than make the
//! footprint of a sample at the lobe's peak, `Omega_s = 1 / (N p_max) = 4 pi alpha^2 / N`
//! (Krivanek & Colbert eq. 13 with `p_max = D(1) / 4`), as large as one output texel: more
//! samples would read the pyramid finer than the output can hold. A level is given
//! `clamp(4 pi alpha^2 / Omega_out, MIN_SAMPLES, N)`: for a 256-pixel Khronos chain and 256
//! samples that is 41, 164, 207, 164, 100, ... samples at levels 1, 2, 3, 4, 5, so the level of
//! 128-pixel faces, three quarters of the work, costs a sixth as much.
//!
//! **Hot texels exactly** ([`crate::specular_source`]). Where the map has texels far brighter
//! than its mean (a sun), the samples read the map with those texels clamped, and the excess is
//! added by the exact sum `sum_t dL_t D(h_t) (n.l_t)+ dOmega_t / W(alpha)` over the hot texels
//! of the coarsest pyramid level whose texels are at most an eighth of the lobe's width, with
//! `W(alpha) = integral D(h) (n.l)+ dl` ([`lobe_weight`]). That is done when those texels are at
//! most half as many as the level's samples (it then costs at most half again); narrow lobes,
//! which resolve a sun by themselves, keep the plain samples.
//!
//! **Exact convolution for wide lobes** ([`GgxFilter`]). A small, very bright source (a sun)
//! falls on a few samples only, whatever the level bias: measured against the brute force of
//! the tests, a 2-degree sun of 1000 times the sky left up to 10 % error at roughness 0.8 with
//! 512 samples and still 8 % with 4096, alternating in sign (aliasing, not blur). Where the
//! lobe is wide, the sum is taken instead over every texel of the coarsest pyramid level whose
//! texels are at most an eighth of the lobe's width (`1.3 alpha` rad, twice the half-maximum
//! angle of D in `h`), weights `D(h) (n.l)+ dOmega_t` with each texel's exact solid angle: the
//! definition itself, on a map whose every level carries the source's power. That is chosen
//! when the level has at most four times as many texels as there are samples, which in
//! practice means roughness above about 0.6 for 128 to 512 samples.

use glam::Vec3;
use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::cube::face_dir;
use crate::cube_pyramid::CubePyramid;
use crate::ggx::{ggx_cos_theta, ggx_d, radical_inverse};
use crate::specular_source::{SparseTexel, SpecularSource};

/// Level bias added to Krivanek & Colbert's footprint level. They suggest 1 (one level coarser:
/// less noise, more blur); against the brute force of the tests 0 was three times closer on
/// smooth content (0.09 % against 0.25 % mean at roughness 0.35 and 0.7, 512 samples).
const LOD_BIAS: f64 = 0.0;

/// Fewest samples a level is given ([`samples_for_level`]).
pub const MIN_SAMPLES: usize = 32;

/// The samples a level of output texels of `output_texel_solid_angle` sr needs at `roughness`,
/// at most `budget` (see the module note).
pub fn samples_for_level(roughness: f64, budget: usize, output_texel_solid_angle: f64) -> usize {
    let alpha = roughness * roughness;
    let needed = 4.0 * std::f64::consts::PI * alpha * alpha / output_texel_solid_angle;
    let needed = if needed.is_finite() {
        needed.ceil().min(1e9) as usize
    } else {
        budget
    };
    needed.max(MIN_SAMPLES).min(budget.max(1))
}

/// `W(alpha) = integral D(h) (n.l)+ dl` with `n = v` (the normaliser of the prefiltered
/// radiance). With `dl = 4 (n.h) dh` and `n.l = 2 (n.h)^2 - 1` it is `4 E[(2 c^2 - 1)+]` under
/// the density `D(h) (n.h)` of `c = n.h`, whose inverse CDF is [`ggx_cos_theta`]: a smooth
/// integral over `v` in [0, 1), taken with 4096 midpoints (relative error under 1e-6).
pub fn lobe_weight(alpha: f64) -> f64 {
    const STEPS: usize = 4096;
    let sum: f64 = (0..STEPS)
        .map(|k| {
            let c = ggx_cos_theta((k as f64 + 0.5) / STEPS as f64, alpha);
            (2.0 * c * c - 1.0).max(0.0)
        })
        .sum();
    4.0 * sum / STEPS as f64
}

/// The GGX samples of one roughness in the tangent frame of `n = +Z`.
#[derive(Clone, Debug)]
pub struct GgxSamples {
    /// `(l, n.l, level)` for every sample with `n.l > 0`.
    samples: Vec<(Vec3, f32, f32)>,
    /// `1 / sum (n.l)`.
    inv_weight: f32,
}

impl GgxSamples {
    /// Tabulates `count` GGX samples (`alpha = roughness^2`) for a source whose level-0 texels
    /// subtend `texel_solid_angle` sr. `roughness` must be positive.
    pub fn new(roughness: f64, count: usize, texel_solid_angle: f64) -> Self {
        let alpha = roughness * roughness;
        let n = count.max(1);
        let mut samples = Vec::with_capacity(n);
        let mut weight = 0.0f64;
        for i in 0..n {
            let phi = std::f64::consts::TAU * (i as f64 / n as f64);
            let cos_h = ggx_cos_theta(radical_inverse(i as u32), alpha);
            let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
            let (sp, cp) = phi.sin_cos();
            // l = 2 (n.h) h - n with n = +Z.
            let l = glam::DVec3::new(
                2.0 * cos_h * sin_h * cp,
                2.0 * cos_h * sin_h * sp,
                2.0 * cos_h * cos_h - 1.0,
            );
            if l.z <= 0.0 {
                continue;
            }
            let pdf = ggx_d(cos_h, alpha) / 4.0;
            let omega_s = 1.0 / (n as f64 * pdf);
            let lod = (0.5 * (omega_s / texel_solid_angle).log2() + LOD_BIAS).max(0.0);
            samples.push((l.as_vec3(), l.z as f32, lod as f32));
            weight += l.z;
        }
        GgxSamples {
            samples,
            inv_weight: if weight > 0.0 {
                (1.0 / weight) as f32
            } else {
                0.0
            },
        }
    }

    /// Number of samples kept (those with `n.l > 0`).
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether no sample was kept.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The prefiltered radiance `LD(n)` for a unit direction `n`.
    #[inline]
    pub fn prefilter(&self, source: &CubePyramid, n: Vec3) -> Vec3 {
        let (t, b) = tangent_frame(n);
        let mut sum = Vec3::ZERO;
        for &(l, w, lod) in &self.samples {
            let d = t * l.x + b * l.y + n * l.z;
            sum += source.sample(d, lod) * w;
        }
        sum * self.inv_weight
    }
}

/// The prefilter of one roughness: importance samples with filtered look-ups, or the exact sum
/// over one pyramid level (see the module note).
#[derive(Clone, Debug)]
pub enum GgxFilter {
    /// GGX importance samples with filtered importance sampling of the whole map.
    Sampled(GgxSamples),
    /// Importance samples of the map's smooth part, and its hot texels summed exactly.
    Split {
        /// The samples (of [`SpecularSource::smooth`]).
        samples: GgxSamples,
        /// The hot texels' excess radiance at one pyramid level.
        hot: Vec<SparseTexel>,
        /// `alpha^2`.
        a2: f32,
        /// `1 / (pi W(alpha))`: `D` without its `1 / pi`, normalised.
        scale: f32,
    },
    /// Every texel of one pyramid level `(direction, solid angle, radiance)`, and `alpha`.
    Exact {
        /// The texels.
        texels: Vec<(Vec3, f32, Vec3)>,
        /// GGX `alpha = r^2`.
        alpha: f64,
    },
}

impl GgxFilter {
    /// The filter for `roughness` (positive) with a budget of `samples` per texel, for output
    /// texels of `output_texel_solid_angle` sr (which sets the samples a level needs,
    /// [`samples_for_level`]).
    pub fn new(
        source: &SpecularSource,
        roughness: f64,
        samples: usize,
        output_texel_solid_angle: f64,
    ) -> Self {
        let pyramid = &source.full;
        let alpha = roughness * roughness;
        let lobe = 1.3 * alpha; // rad
        // Coarsest level whose texel (90 degrees / face size) is at most lobe / 8.
        let mut level = None;
        for l in (0..pyramid.level_count()).rev() {
            let texel = std::f64::consts::FRAC_PI_2 / pyramid.level_size(l) as f64;
            if texel <= lobe / 8.0 {
                level = Some(l);
                break;
            }
        }
        if let Some(l) = level
            && 6 * pyramid.level_size(l).pow(2) <= 4 * samples.max(1)
        {
            return GgxFilter::Exact {
                texels: pyramid.texels(l),
                alpha,
            };
        }
        let count = samples_for_level(roughness, samples, output_texel_solid_angle);
        let sampled = GgxSamples::new(roughness, count, pyramid.texel_solid_angle());
        match level {
            Some(l) if !source.hot(l).is_empty() && 2 * source.hot(l).len() <= sampled.len() => {
                GgxFilter::Split {
                    samples: sampled,
                    hot: source.hot(l).to_vec(),
                    a2: (alpha * alpha) as f32,
                    scale: (1.0 / (std::f64::consts::PI * lobe_weight(alpha))) as f32,
                }
            }
            _ => GgxFilter::Sampled(sampled),
        }
    }

    /// The prefiltered radiance `LD(n)` for a unit direction `n`.
    pub fn prefilter(&self, source: &SpecularSource, n: Vec3) -> Vec3 {
        match self {
            GgxFilter::Sampled(s) => s.prefilter(&source.full, n),
            GgxFilter::Split {
                samples,
                hot,
                a2,
                scale,
            } => {
                let mut excess = Vec3::ZERO;
                for &(l, omega, radiance) in hot {
                    let n_l = n.dot(l);
                    if n_l <= 0.0 {
                        continue;
                    }
                    // D(h) pi with (n.h)^2 = (1 + n.l) / 2 for h = (n + l) / |n + l|.
                    let f = 0.5 * (1.0 + n_l) * (a2 - 1.0) + 1.0;
                    excess += radiance * (a2 / (f * f) * n_l * omega);
                }
                samples.prefilter(&source.smooth, n) + excess * *scale
            }
            GgxFilter::Exact { texels, alpha } => {
                let a2 = (alpha * alpha) as f32;
                let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
                for &(l, omega, radiance) in texels {
                    let n_l = n.dot(l);
                    if n_l <= 0.0 {
                        continue;
                    }
                    // D(h) with (n.h)^2 = (1 + n.l) / 2 for h = (n + l) / |n + l|; the 1/pi
                    // cancels in the normalised sum.
                    let c2 = 0.5 * (1.0 + n_l);
                    let f = c2 * (a2 - 1.0) + 1.0;
                    let w = a2 / (f * f) * n_l * omega;
                    sum += radiance * w;
                    weight += w;
                }
                if weight > 0.0 {
                    sum / weight
                } else {
                    Vec3::ZERO
                }
            }
        }
    }
}

/// An orthonormal, right-handed tangent frame `(t, b)` around unit `n` (`t x b = n`),
/// continuous everywhere except at `n = -Y` (Frisvad 2012, "Building an orthonormal basis from
/// a 3D unit vector without normalization", with y and z exchanged so that its singular pole
/// z = -1 becomes straight down; Duff et al.'s branchless variant would be discontinuous across
/// a whole great circle).
#[inline]
fn tangent_frame(n: Vec3) -> (Vec3, Vec3) {
    // In axes (x, z, y) the basis of p = (x, y, z) is singular only at p.z = -1. f64: near the
    // pole `1 / (1 + z)` cancels catastrophically in f32 (frames off unit length by 1e-3).
    // Normalised again in f64: an f32 `n` off unit length by 1e-7 would be amplified by
    // `1 / (1 + z)` near the pole.
    let p = glam::DVec3::new(n.x.into(), n.z.into(), n.y.into()).normalize();
    let (x, y, z) = (p.x, p.y, p.z);
    if z < -0.999_999_9 {
        return (Vec3::X, Vec3::Z);
    }
    let a = 1.0 / (1.0 + z);
    let b = -x * y * a;
    let t = glam::DVec3::new(1.0 - x * x * a, b, -x);
    let u = glam::DVec3::new(b, 1.0 - y * y * a, -y);
    // Back to world axes (a reflection, so the pair is swapped to stay right-handed).
    (
        glam::DVec3::new(u.x, u.z, u.y).as_vec3(),
        glam::DVec3::new(t.x, t.z, t.y).as_vec3(),
    )
}

/// Prefilters six faces of `size` (GL orientation) at `roughness`; roughness 0 returns the
/// source's level of that size unchanged. `size` must be a power of two not above the source's.
pub fn prefilter_cube(
    source: &SpecularSource,
    size: usize,
    roughness: f64,
    samples: usize,
) -> [Image<Rgb>; 6] {
    if roughness <= 0.0 {
        let level = (source.size() / size.max(1)).trailing_zeros() as usize;
        return source.full.faces(level);
    }
    let texel = 4.0 * std::f64::consts::PI / (6 * size * size).max(1) as f64;
    let table = GgxFilter::new(source, roughness, samples, texel);
    std::array::from_fn(|face| {
        Image::from_fn_par(size, size, |i, j| {
            let sc = 2.0 * (i as f64 + 0.5) / size as f64 - 1.0;
            let tc = 2.0 * (j as f64 + 0.5) / size as f64 - 1.0;
            let n = face_dir(face, sc, tc).normalize().as_vec3();
            let v = table.prefilter(source, n);
            Rgb::new(v.x, v.y, v.z)
        })
    })
}

/// Prefilters a `width x width/2` lat-long map at `roughness` (every texel at its centre
/// direction, CONVENTIONS section 2).
pub fn prefilter_latlong(
    source: &SpecularSource,
    width: usize,
    roughness: f64,
    samples: usize,
) -> Image<Rgb> {
    let (w, h) = (width.max(2), (width / 2).max(1));
    let ll = ibl_core::LatLong::new(w, h);
    let texel = 4.0 * std::f64::consts::PI / (w * h) as f64;
    let table = GgxFilter::new(source, roughness.max(1e-4), samples, texel);
    let rows: Vec<Vec<Rgb>> = (0..h)
        .into_par_iter()
        .map(|j| {
            (0..w)
                .map(|i| {
                    let v = table.prefilter(source, ll.pixel_dir(i, j));
                    Rgb::new(v.x, v.y, v.z)
                })
                .collect()
        })
        .collect();
    Image::from_vec(w, h, rows.concat()).unwrap_or_else(|_| Image::filled(w, h, Rgb::ZERO))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use super::*;

    #[test]
    fn tangent_frames_are_orthonormal() {
        for n in ibl_core::fibonacci_normals(2000) {
            let n = n.as_vec3();
            let (t, b) = tangent_frame(n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(v).abs() < 1e-5, "{n} {t} {b}");
            }
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
            // Right-handed: t x b = n.
            assert!((t.cross(b) - n).length() < 1e-4, "{n}");
        }
    }

    #[test]
    fn the_lobe_weight_is_the_integral_of_d_times_cosine() {
        // Against a direct sum over l in polar angle (D peaks sharply: 200000 midpoints).
        for alpha in [0.05, 0.2, 0.6, 1.0] {
            let steps = 200_000;
            let dt = std::f64::consts::FRAC_PI_2 / steps as f64;
            let direct: f64 = (0..steps)
                .map(|k| {
                    let t = (k as f64 + 0.5) * dt;
                    let cos_h = (0.5 * t).cos();
                    ggx_d(cos_h, alpha) * t.cos() * std::f64::consts::TAU * t.sin() * dt
                })
                .sum();
            // Midpoint rules of 4096 and 200000 steps: measured under 2e-6 relative.
            assert!(
                (lobe_weight(alpha) / direct - 1.0).abs() < 1e-5,
                "{alpha}: {} {direct}",
                lobe_weight(alpha)
            );
        }
    }

    #[test]
    fn levels_get_the_samples_their_texels_need() {
        let texel = |s: usize| 4.0 * std::f64::consts::PI / (6 * s * s) as f64;
        // 256-pixel Khronos chain, level 1 (r = 1/7, 128-pixel faces): 4 pi alpha^2 / Omega.
        assert_eq!(samples_for_level(1.0 / 7.0, 256, texel(128)), 41);
        assert_eq!(samples_for_level(0.01, 256, texel(128)), MIN_SAMPLES);
        assert_eq!(samples_for_level(0.9, 256, texel(8)), 252); // 4 pi 0.81^2 / (4 pi / 384)
        assert_eq!(samples_for_level(0.9, 16, texel(8)), 16);
    }

    #[test]
    fn samples_concentrate_as_roughness_falls() {
        let mean_cos = |r: f64| {
            let s = GgxSamples::new(r, 256, 1e-4);
            s.samples.iter().map(|(l, _, _)| l.z).sum::<f32>() / s.len() as f32
        };
        assert!(mean_cos(0.1) > 0.99 && mean_cos(0.5) < mean_cos(0.2));
        assert!(mean_cos(1.0) < 0.7);
    }
}
