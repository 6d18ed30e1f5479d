//! The distant environment light of a lat-long probe: radiance look-up and importance sampling.
//!
//! The probe is a W x H lat-long image of radiance in the probe frame (`docs/CONVENTIONS.md`
//! section 2); `world_from_probe` (an orthogonal matrix) turns probe directions into world
//! directions, and a radiance scale multiplies every texel. Radiance is **piecewise constant**: a
//! direction sees the radiance of the texel it falls in (nearest texel, no filtering), exactly the
//! function the section-4 ground truth integrates with exact texel solid angles
//! `dOmega_j = (2 pi / W) (cos(pi j / H) - cos(pi (j + 1) / H))`.
//!
//! Importance sampling (the 2-D piecewise-constant scheme of Pharr, Jakob and Humphreys,
//! *Physically Based Rendering*, 4th ed., section A.5, with exact texel solid angles in place of
//! `sin theta`): texel `(i, j)` is chosen with probability `p_ij` proportional to
//! `luminance(L_ij) dOmega_j`, the row from the marginal distribution over rows and the column from
//! that row's conditional distribution; the direction is then uniform in solid angle within the
//! texel (`phi` uniform over the column, `cos(theta)` uniform over the row's band), so the density
//! is `p_ij / dOmega_j` per steradian. Luminance weights are all positive, so a texel has zero
//! probability only when its radiance is zero in every channel and the estimator stays unbiased.
//! A map that is black everywhere falls back to uniform sphere sampling (`1 / (4 pi)`).
//! Texel coordinates of a sample are kept `1e-3` of a texel away from its edges so that the
//! f32 direction maps back to the same texel: `pdf(sample.direction) == sample.pdf_sr`.
//!
//! **Half-sphere sampling.** A surface whose geometric normal is the probe's up (or down) axis,
//! exactly (a floor or a ceiling under an upright probe), receives no light from the other half
//! of the sphere, so drawing samples there wastes them: half of them under the apartment probe,
//! whose floor is as bright as its walls. [`EnvironmentLight::region_for`] names the rows such a
//! vertex can see ([`SampleRegion`]), and [`EnvironmentLight::sample_in`] draws only from them:
//! the row from a marginal distribution over those rows alone, the column as before, so the
//! density there is `p_ij / (P_region dOmega_j)` (`P_region` the region's share of the map's
//! weight) and 0 elsewhere; [`EnvironmentLight::radiance_and_pdf_in`] gives the same density for
//! multiple importance sampling. The upper half is rows `0..ceil(H / 2)`, the lower half rows
//! `floor(H / 2)..H` (an odd height's middle row straddles the horizon and belongs to both), so
//! every direction such a vertex can receive light from stays in the region and the estimate
//! stays unbiased. [`EnvironmentLight::half_irradiance`] gives the irradiance such a surface
//! receives from its half with nothing in the way, `sum L_ij kappa_ij`, `kappa_ij = (pi / W)
//! (mu_hi^2 - mu_lo^2)` the texel's cosine-weighted solid angle (`mu = |cos(theta)|` over the
//! part of the row's band on the half's side of the horizon): the tracer's control variate.
//!
//! **Normal bins.** Any other surface draws from its normal's bin ([`crate::normal_bins`]), in
//! proportion to radiance times a bound of its cosine, so its samples land above it and more of
//! them where the cosine is large; [`SampleRegion::Facing`]. Above a real floor that is all the
//! real geometry, from the bin clipped to the upper half ([`EnvironmentLight::within_half`]).
//!
//! Texel look-up uses `theta = atan2(sqrt(x^2 + z^2), y)`, well conditioned at the poles, and
//! `phi = atan2(x, -z)` in f32 (within about `2.4e-7` rad: a thousandth of a texel up to 8192
//! texels across, where the f64 functions cost a twentieth of a reference render). Each texel
//! keeps its radiance and its density side by side (16 bytes), so a look-up reads one place.
//! Cost: O(W H) to build (rows in parallel, sums in f64 per row), O(1) expected per sample (the
//! guided inversion of [`Distribution1D`]), O(1) per radiance or density look-up.

use std::f64::consts::PI;

use glam::{DVec3, Mat3, Vec3};
use ibl_core::rgb::Rgb64;
use ibl_core::{Image, LatLong, Rgb};
use rayon::prelude::*;

use crate::normal_bins::{Half, NormalBins};
use crate::sampling::{Distribution1D, UniformCone, cos_sin_turn};

/// How far (as a fraction of a texel) sampled texel coordinates stay from the texel's edges.
const EDGE_MARGIN: f64 = 1e-3;

/// Largest deviation of `M^T M` from the identity accepted for `world_from_probe`.
const ORTHOGONALITY_TOLERANCE: f32 = 1e-4;

/// Why an environment light could not be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EnvironmentError {
    /// The probe has no pixels.
    #[error("the environment map is empty ({width} x {height})")]
    Empty {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// A texel holds a negative, NaN or infinite value.
    #[error("texel ({x}, {y}) holds an invalid radiance (negative or not finite)")]
    InvalidRadiance {
        /// Column.
        x: usize,
        /// Row (0 at the top).
        y: usize,
    },
    /// `world_from_probe` is not orthogonal (or not finite).
    #[error("world_from_probe is not a rotation: |M^T M - I| = {deviation}")]
    NotOrthogonal {
        /// Largest absolute entry of `M^T M - I`.
        deviation: f32,
    },
    /// The radiance scale is negative or not finite.
    #[error("radiance scale {0} is not a finite non-negative number")]
    InvalidScale(f32),
}

impl EnvironmentError {
    /// Always true: the probe, its rotation and its scale come from the scene.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

/// One direction drawn from [`EnvironmentLight::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvSample {
    /// Unit direction towards the environment, world frame.
    pub direction: Vec3,
    /// Radiance arriving from `direction` (scaled probe units).
    pub radiance: Rgb,
    /// Density of `direction` per steradian, equal to [`EnvironmentLight::pdf`] of it.
    pub pdf_sr: f32,
}

/// A direction drawn by [`EnvironmentLight::direction_in`], with what
/// [`EnvironmentLight::texel_of_draw`] needs to read its radiance and density later.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawnDirection {
    /// Unit direction towards the environment, world frame.
    pub direction: Vec3,
    /// The region it was drawn from.
    region: SampleRegion,
    /// Its texel `(column, row)`; `None` for a black map's uniform draw.
    texel: Option<(usize, usize)>,
}

/// A lat-long probe as a distant light, with a luminance-proportional sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    latlong: LatLong,
    /// Per texel, row-major, row 0 at the top: the scaled radiance and the density (1/sr) of
    /// sampling a direction in it.
    texels: Vec<Texel>,
    world_from_probe: Mat3,
    probe_from_world: Mat3,
    /// Exact solid angle (sr) of a texel in each row.
    row_solid_angle: Vec<f64>,
    /// `cos(pi j / H)` for `j = 0..=H`: the rows' band edges.
    row_edge_cos: Vec<f64>,
    /// Distribution over rows (weights: row sums of luminance x solid angle).
    marginal: Distribution1D,
    /// Per row, the distribution over its columns.
    conditionals: Vec<Distribution1D>,
    /// False when the map is black: sampling is then uniform over the sphere.
    importance: bool,
    /// The upper and lower halves' own row distributions ([`SampleRegion`]).
    halves: [HalfRows; 2],
    /// The distributions of [`SampleRegion::Facing`]; `None` for a light built without them
    /// ([`EnvironmentLight::without_normal_bins`]).
    normal_bins: Option<NormalBins>,
}

/// The directions an environment sample is drawn from (module notes, "Half-sphere sampling").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleRegion {
    /// The whole sphere.
    Sphere,
    /// The probe's upper half, rows `0..ceil(H / 2)`: for a surface facing the probe's +Y.
    Upper,
    /// The probe's lower half, rows `floor(H / 2)..H`: for a surface facing the probe's -Y.
    Lower,
    /// The directions a surface whose normal falls in normal bin `k` can receive light from,
    /// in proportion to radiance times a bound of the cosine ([`crate::normal_bins`]), or the
    /// bin clipped to one half of the probe ([`EnvironmentLight::within_half`]).
    Facing(u16),
}

/// The rows of one half of the map and their own distribution.
#[derive(Clone, Debug)]
struct HalfRows {
    /// The half's first row.
    first_row: usize,
    /// Distribution over the half's rows (the same weights as the whole map's marginal).
    marginal: Distribution1D,
    /// `1 / P_half`: the whole map's weight over the half's (0 when the half is black).
    density_scale: f32,
    /// `sum_ij L_ij kappa_ij` over the half (module notes): the irradiance a surface facing its
    /// pole receives from it, unshadowed (exact for the texel-constant probe).
    irradiance: Rgb,
}

/// One texel's radiance and sampling density, read together.
#[derive(Clone, Copy, Debug)]
struct Texel {
    radiance: Rgb,
    /// Density (1/sr) of [`EnvironmentLight::sample`] within the texel.
    pdf_sr: f32,
}

impl EnvironmentLight {
    /// Builds the light from a lat-long radiance probe (probe frame), the orthogonal matrix
    /// `world_from_probe` and a radiance scale (multiplies every texel), with its normal bins
    /// ([`crate::normal_bins`]) for the reference's environment samples. O(W H + B^2 C).
    pub fn new(
        probe: Image<Rgb>,
        world_from_probe: Mat3,
        radiance_scale: f32,
    ) -> Result<Self, EnvironmentError> {
        Self::build(probe, world_from_probe, radiance_scale, true)
    }

    /// [`EnvironmentLight::new`] without the normal bins, for a light whose surfaces never draw
    /// environment samples (the lights and hybrid modes: the probe is only seen, through the
    /// background, mirrors and escaping rays): the bins are most of the build's time (0.09 of
    /// 0.11 s for a 512 x 256 probe on 2 cores) and 9 MiB. Sampling is unchanged
    /// but for [`EnvironmentLight::region_for`], which then never names a bin, so a surface
    /// that is not a floor or a ceiling draws from the whole sphere. O(W H).
    pub fn without_normal_bins(
        probe: Image<Rgb>,
        world_from_probe: Mat3,
        radiance_scale: f32,
    ) -> Result<Self, EnvironmentError> {
        Self::build(probe, world_from_probe, radiance_scale, false)
    }

    /// [`EnvironmentLight::new`] when `with_normal_bins`, else
    /// [`EnvironmentLight::without_normal_bins`].
    pub(crate) fn build(
        probe: Image<Rgb>,
        world_from_probe: Mat3,
        radiance_scale: f32,
        with_normal_bins: bool,
    ) -> Result<Self, EnvironmentError> {
        let (width, height) = (probe.width(), probe.height());
        if probe.is_empty() {
            return Err(EnvironmentError::Empty { width, height });
        }
        if !(radiance_scale.is_finite() && radiance_scale >= 0.0) {
            return Err(EnvironmentError::InvalidScale(radiance_scale));
        }
        let deviation = (world_from_probe.transpose() * world_from_probe - Mat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0_f32, |m, &e| {
                if e.is_nan() {
                    f32::INFINITY
                } else {
                    m.max(e.abs())
                }
            });
        if deviation > ORTHOGONALITY_TOLERANCE {
            return Err(EnvironmentError::NotOrthogonal { deviation });
        }
        if let Some(k) = probe.pixels().iter().position(|p| !p.is_valid_radiance()) {
            return Err(EnvironmentError::InvalidRadiance {
                x: k % width,
                y: k / width,
            });
        }

        let latlong = LatLong::new(width, height);
        let row_solid_angle = latlong.row_solid_angles();
        let row_edge_cos: Vec<f64> = (0..=height)
            .map(|j| (PI * j as f64 / height as f64).cos())
            .collect();
        let radiance: Vec<Rgb> = probe
            .into_vec()
            .into_iter()
            .map(|l| l * radiance_scale)
            .collect();
        // Each texel's sampling weight, `lum(L) dOmega`: the rows' conditionals and the normal
        // bins share it.
        let weights: Vec<f64> = radiance
            .par_chunks_exact(width)
            .zip(row_solid_angle.par_iter())
            .flat_map_iter(|(row, &d_omega)| {
                row.iter().map(move |l| f64::from(l.luminance()) * d_omega)
            })
            .collect();
        let conditionals: Vec<Distribution1D> = weights
            .par_chunks_exact(width)
            .map(|row| Distribution1D::new(row.iter().copied()))
            .collect();
        let marginal = Distribution1D::new(conditionals.iter().map(Distribution1D::total));
        let importance = marginal.total() > 0.0;
        let normal_bins = with_normal_bins.then(|| NormalBins::new(width, height, &weights));
        let half = |first_row: usize, end_row: usize, sign: f64| {
            let half_marginal = Distribution1D::new(
                conditionals[first_row..end_row]
                    .iter()
                    .map(Distribution1D::total),
            );
            let density_scale = if half_marginal.total() > 0.0 {
                (marginal.total() / half_marginal.total()) as f32
            } else {
                0.0
            };
            // `kappa_j = (pi / W) (mu_hi^2 - mu_lo^2)` over the part of row `j`'s band on the
            // half's side of the horizon.
            let mut irradiance = Rgb64::ZERO;
            for j in first_row..end_row {
                let (a, b) = (sign * row_edge_cos[j], sign * row_edge_cos[j + 1]);
                let (lo, hi) = (a.min(b).max(0.0), a.max(b).max(0.0));
                let kappa = PI / width as f64 * (hi * hi - lo * lo);
                let mut row_sum = Rgb64::ZERO;
                for &l in &radiance[j * width..(j + 1) * width] {
                    row_sum.add_weighted(l, kappa);
                }
                irradiance = irradiance + row_sum;
            }
            HalfRows {
                first_row,
                marginal: half_marginal,
                density_scale,
                irradiance: Rgb::new(
                    irradiance.r as f32,
                    irradiance.g as f32,
                    irradiance.b as f32,
                ),
            }
        };
        let halves = [
            half(0, height.div_ceil(2), 1.0),
            half(height / 2, height, -1.0),
        ];
        // `p_ij / dOmega_j` (module notes), or the uniform sphere's density for a black map.
        let texels = radiance
            .par_chunks_exact(width)
            .zip(conditionals.par_iter())
            .enumerate()
            .flat_map_iter(|(j, (row, conditional))| {
                let marginal = &marginal;
                let row_solid_angle = row_solid_angle[j];
                row.iter().enumerate().map(move |(i, &radiance)| {
                    let pdf_sr = if importance {
                        let p = f64::from(marginal.probability(j))
                            * f64::from(conditional.probability(i));
                        (p / row_solid_angle) as f32
                    } else {
                        UniformCone::SPHERE.pdf()
                    };
                    Texel { radiance, pdf_sr }
                })
            })
            .collect();
        Ok(EnvironmentLight {
            latlong,
            texels,
            world_from_probe,
            probe_from_world: world_from_probe.transpose(),
            row_solid_angle,
            row_edge_cos,
            marginal,
            conditionals,
            importance,
            halves,
            normal_bins,
        })
    }

    /// The probe's lat-long parameterisation (its size).
    pub fn latlong(&self) -> LatLong {
        self.latlong
    }

    /// The matrix turning probe directions into world directions.
    pub fn world_from_probe(&self) -> Mat3 {
        self.world_from_probe
    }

    /// The texel `(column, row)` a world direction falls in (the direction need not be unit).
    pub fn texel_of(&self, dir_world: Vec3) -> (usize, usize) {
        let d = self.probe_from_world * dir_world;
        // The squares of f32 values are exact in f64 and cannot overflow: no need for `hypot`.
        let (x, z) = (f64::from(d.x), f64::from(d.z));
        let theta = ((x * x + z * z).sqrt() as f32).atan2(d.y);
        let phi = d.x.atan2(-d.z);
        let (w, h) = (self.latlong.width, self.latlong.height);
        let mut u = phi * (0.5 * std::f32::consts::FRAC_1_PI) + 0.5;
        if u >= 1.0 {
            u -= 1.0;
        }
        // Float-to-int casts saturate (NaN gives 0), so any input maps to a valid texel.
        let i = ((u * w as f32) as usize).min(w - 1);
        let j = ((theta * std::f32::consts::FRAC_1_PI * h as f32) as usize).min(h - 1);
        (i, j)
    }

    /// Radiance arriving from the world direction `dir_world` (nearest texel, scaled).
    pub fn radiance(&self, dir_world: Vec3) -> Rgb {
        let (i, j) = self.texel_of(dir_world);
        self.texels[j * self.latlong.width + i].radiance
    }

    /// Density (1/sr) with which [`EnvironmentLight::sample`] draws `dir_world`.
    pub fn pdf(&self, dir_world: Vec3) -> f32 {
        self.radiance_and_pdf(dir_world).1
    }

    /// [`EnvironmentLight::radiance`] and [`EnvironmentLight::pdf`] of one direction, finding
    /// its texel once.
    pub fn radiance_and_pdf(&self, dir_world: Vec3) -> (Rgb, f32) {
        self.radiance_and_pdf_in(SampleRegion::Sphere, dir_world)
    }

    /// [`EnvironmentLight::radiance_and_pdf`] with the density of
    /// [`EnvironmentLight::sample_in`] of `region`: 0 outside its rows.
    pub fn radiance_and_pdf_in(&self, region: SampleRegion, dir_world: Vec3) -> (Rgb, f32) {
        let (i, j) = self.texel_of(dir_world);
        let texel = self.texels[j * self.latlong.width + i];
        let pdf = match region {
            SampleRegion::Facing(bin) if self.importance => self.facing_density(bin, i, j),
            _ => texel.pdf_sr * self.region_scale(region, j),
        };
        (texel.radiance, pdf)
    }

    /// The region a surface with the world geometric normal `normal` can receive light from:
    /// a half when the normal is exactly the probe's up or down axis (its other two
    /// components exactly 0), else its normal bin ([`SampleRegion::Facing`]); the whole sphere
    /// for a zero or non-finite normal, a bin no light reaches, a black map, and a light built
    /// without normal bins.
    pub fn region_for(&self, normal: Vec3) -> SampleRegion {
        if !self.importance {
            return SampleRegion::Sphere;
        }
        match self.half_facing(normal) {
            Some(Half::Upper) => SampleRegion::Upper,
            Some(Half::Lower) => SampleRegion::Lower,
            None => self
                .normal_bins
                .as_ref()
                .and_then(|bins| bins.bin_of(self.probe_from_world * normal))
                .map_or(SampleRegion::Sphere, SampleRegion::Facing),
        }
    }

    /// The probe's half that the world direction `normal` points into when it is exactly the
    /// probe's up or down axis (its other two components exactly 0), else `None`.
    pub fn half_facing(&self, normal: Vec3) -> Option<Half> {
        let n = self.probe_from_world * normal;
        match (n.x == 0.0 && n.z == 0.0, n.y) {
            (true, y) if y > 0.0 => Some(Half::Upper),
            (true, y) if y < 0.0 => Some(Half::Lower),
            _ => None,
        }
    }

    /// `region` with its normal bin clipped to the probe's `half` ([`NormalBins::within`]): for
    /// a vertex on that side of a real floor or ceiling that is all the real geometry, whose
    /// other half meets the plane. Unchanged for any other region, and where none of the half's
    /// light reaches the bin's normals.
    pub fn within_half(&self, region: SampleRegion, half: Half) -> SampleRegion {
        match region {
            SampleRegion::Facing(bin) => self
                .normal_bins
                .as_ref()
                .and_then(|bins| bins.within(bin, half))
                .map_or(region, SampleRegion::Facing),
            _ => region,
        }
    }

    /// The irradiance (scaled radiance x sr) a surface facing `region`'s pole receives from its
    /// half with nothing in the way, `sum L_ij kappa_ij` (module notes): the expectation of
    /// `L cos(theta) / pdf` over the samples of any unbiased strategy. `None` for the sphere, a
    /// normal bin and a black map.
    pub fn half_irradiance(&self, region: SampleRegion) -> Option<Rgb> {
        match region {
            _ if !self.importance => None,
            SampleRegion::Upper => Some(self.halves[0].irradiance),
            SampleRegion::Lower => Some(self.halves[1].irradiance),
            SampleRegion::Sphere | SampleRegion::Facing(_) => None,
        }
    }

    /// The density (1/sr) of [`SampleRegion::Facing`]`(bin)` in texel `(i, j)`.
    #[inline]
    fn facing_density(&self, bin: u16, i: usize, j: usize) -> f32 {
        let probability = self
            .normal_bins
            .as_ref()
            .map_or(0.0, |bins| bins.texel_probability(bin, i, j));
        (f64::from(probability) / self.row_solid_angle[j]) as f32
    }

    /// The factor from the whole sphere's density to `region`'s in row `j`.
    #[inline]
    fn region_scale(&self, region: SampleRegion, j: usize) -> f32 {
        let half = match region {
            // A black map is sampled uniformly over the sphere in every region.
            _ if !self.importance => return 1.0,
            SampleRegion::Sphere | SampleRegion::Facing(_) => return 1.0,
            SampleRegion::Upper => &self.halves[0],
            SampleRegion::Lower => &self.halves[1],
        };
        let rows = half.first_row..half.first_row + half.marginal.len();
        if rows.contains(&j) {
            half.density_scale
        } else {
            0.0
        }
    }

    /// A direction drawn with density proportional to luminance (uniform within a texel) from
    /// `u1, u2` in `[0, 1)`: `u1` picks the row, `u2` the column. O(1) expected, O(log W +
    /// log H) at worst.
    pub fn sample(&self, u1: f32, u2: f32) -> EnvSample {
        self.sample_in(SampleRegion::Sphere, u1, u2)
    }

    /// [`EnvironmentLight::sample`] within `region` (module notes, "Half-sphere sampling" and
    /// "Normal bins"): `u1` picks the row among the region's (a bin: the cell, then the band
    /// within the texel), `u2` the column (a bin: the texel within the cell, then the column
    /// range). A black half gives density 0 (no light can come from it).
    pub fn sample_in(&self, region: SampleRegion, u1: f32, u2: f32) -> EnvSample {
        self.texel_of_draw(self.direction_in(region, u1, u2))
    }

    /// The direction [`EnvironmentLight::sample_in`] draws, without reading its texel's radiance
    /// and density ([`EnvironmentLight::texel_of_draw`] reads them): a caller that needs them
    /// only sometimes (a control-variate vertex, whose samples count only where their shadow
    /// ray is blocked) skips that read, a cache miss into the probe, most of the time.
    pub fn direction_in(&self, region: SampleRegion, u1: f32, u2: f32) -> DrawnDirection {
        let (marginal, first_row) = match region {
            SampleRegion::Sphere | SampleRegion::Facing(_) => (&self.marginal, 0),
            SampleRegion::Upper => (&self.halves[0].marginal, self.halves[0].first_row),
            SampleRegion::Lower => (&self.halves[1].marginal, self.halves[1].first_row),
        };
        // The texel, and where in its band of `cos(theta)` and its range of `phi`.
        let chosen = match region {
            _ if !self.importance => None,
            SampleRegion::Facing(bin) => self
                .normal_bins
                .as_ref()
                .and_then(|bins| bins.sample(bin, u1, u2))
                .map(|t| (t.row, t.along_row_band, t.column, t.along_columns)),
            _ => marginal.sample(u1).and_then(|row| {
                let j = first_row + row.index;
                self.conditionals[j]
                    .sample(u2)
                    .map(|column| (j, row.remapped, column.index, column.remapped))
            }),
        };
        let Some((j, along_band, i, along_columns)) = chosen else {
            return DrawnDirection {
                direction: UniformCone::SPHERE.sample(u1, u2),
                region,
                texel: None,
            };
        };
        let inset = |f: f32| EDGE_MARGIN + (1.0 - 2.0 * EDGE_MARGIN) * f64::from(f);
        let w = self.latlong.width;
        // `phi = 2 pi (t - 1/2)`, so `(cos phi, sin phi) = -(cos 2 pi t, sin 2 pi t)`, each
        // within 2e-7 ([`cos_sin_turn`]).
        let t = (i as f64 + inset(along_columns)) / w as f64;
        let (cos_turn, sin_turn) = cos_sin_turn(t as f32);
        let (c0, c1) = (self.row_edge_cos[j], self.row_edge_cos[j + 1]);
        let cos_theta = c0 + inset(along_band) * (c1 - c0);
        let sin_theta = ((1.0 - cos_theta) * (1.0 + cos_theta)).max(0.0).sqrt();
        let (sp, cp) = (-f64::from(sin_turn), -f64::from(cos_turn));
        let probe_dir = DVec3::new(sin_theta * sp, cos_theta, -sin_theta * cp).as_vec3();
        DrawnDirection {
            direction: (self.world_from_probe * probe_dir).normalize_or(Vec3::Y),
            region,
            texel: Some((i, j)),
        }
    }

    /// The sample a [`DrawnDirection`] of this light stands for: its texel's radiance and the
    /// draw's density (uniform over the sphere for a black map).
    pub fn texel_of_draw(&self, drawn: DrawnDirection) -> EnvSample {
        let Some((i, j)) = drawn.texel else {
            return EnvSample {
                direction: drawn.direction,
                radiance: self.radiance(drawn.direction),
                pdf_sr: UniformCone::SPHERE.pdf(),
            };
        };
        let texel = self.texels[j * self.latlong.width + i];
        let pdf_sr = match drawn.region {
            SampleRegion::Facing(bin) => self.facing_density(bin, i, j),
            _ => texel.pdf_sr * self.region_scale(drawn.region, j),
        };
        EnvSample {
            direction: drawn.direction,
            radiance: texel.radiance,
            pdf_sr,
        }
    }

    /// Power per channel, `sum_p L_p dOmega_p` (scaled radiance x sr), accumulated in f64 per row
    /// and then over rows in order (CONVENTIONS section 4).
    pub fn total_power(&self) -> Rgb64 {
        self.texels
            .chunks_exact(self.latlong.width)
            .zip(&self.row_solid_angle)
            .fold(Rgb64::ZERO, |total, (row, &d_omega)| {
                let mut row_sum = Rgb64::ZERO;
                for texel in row {
                    row_sum.add_weighted(texel.radiance, d_omega);
                }
                total + row_sum
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(width: usize, height: usize) -> EnvironmentLight {
        EnvironmentLight::new(Image::filled(width, height, Rgb::ONE), Mat3::IDENTITY, 1.0).unwrap()
    }

    #[test]
    fn a_light_without_normal_bins_draws_from_the_sphere_where_the_other_names_a_bin() {
        // A brighter quadrant, so that the distributions are not uniform.
        let mut probe = Image::filled(64, 32, Rgb::ONE);
        for j in 0..16 {
            for i in 0..32 {
                *probe.get_mut(i, j) = Rgb::splat(5.0);
            }
        }
        let binned = EnvironmentLight::new(probe.clone(), Mat3::IDENTITY, 1.0).unwrap();
        let plain = EnvironmentLight::without_normal_bins(probe, Mat3::IDENTITY, 1.0).unwrap();
        let tilted = Vec3::new(0.3, 0.8, 0.1).normalize();
        assert!(matches!(binned.region_for(tilted), SampleRegion::Facing(_)));
        assert_eq!(plain.region_for(tilted), SampleRegion::Sphere);
        assert_eq!(plain.region_for(Vec3::Y), SampleRegion::Upper);
        assert_eq!(plain.region_for(Vec3::NEG_Y), SampleRegion::Lower);
        // Everything else is the same light, bit for bit.
        for region in [
            SampleRegion::Sphere,
            SampleRegion::Upper,
            SampleRegion::Lower,
        ] {
            for k in 0..256 {
                let (u1, u2) = ((k as f32 + 0.5) / 256.0, (k * 37 % 256) as f32 / 256.0);
                let sample = plain.sample_in(region, u1, u2);
                assert_eq!(sample, binned.sample_in(region, u1, u2));
                assert_eq!(
                    plain.radiance_and_pdf_in(region, sample.direction),
                    binned.radiance_and_pdf_in(region, sample.direction)
                );
            }
        }
        assert_eq!(plain.total_power(), binned.total_power());
    }

    #[test]
    fn pixel_centres_map_to_their_texels() {
        let env = light(64, 32);
        for j in 0..32 {
            for i in 0..64 {
                assert_eq!(env.texel_of(env.latlong().pixel_dir(i, j)), (i, j));
            }
        }
    }

    #[test]
    fn section_two_vectors_land_in_the_right_texels() {
        let env = light(512, 256);
        assert_eq!(env.texel_of(Vec3::X), (384, 128));
        assert_eq!(env.texel_of(Vec3::Z).0, 0);
        assert_eq!(env.texel_of(Vec3::NEG_Z), (256, 128));
        assert_eq!(env.texel_of(Vec3::Y).1, 0);
        assert_eq!(env.texel_of(Vec3::NEG_Y).1, 255);
        assert_eq!(env.texel_of(Vec3::ZERO).1, 0);
        assert_eq!(env.texel_of(Vec3::splat(f32::NAN)), (0, 0));
    }

    #[test]
    fn rejects_bad_inputs() {
        let probe = Image::filled(4, 2, Rgb::ONE);
        assert!(matches!(
            EnvironmentLight::new(probe.clone(), Mat3::from_diagonal(Vec3::splat(2.0)), 1.0),
            Err(EnvironmentError::NotOrthogonal { .. })
        ));
        assert!(matches!(
            EnvironmentLight::new(probe.clone(), Mat3::IDENTITY, -1.0),
            Err(EnvironmentError::InvalidScale(_))
        ));
        let mut bad = probe.clone();
        *bad.get_mut(3, 1) = Rgb::new(0.0, f32::NAN, 0.0);
        assert_eq!(
            EnvironmentLight::new(bad, Mat3::IDENTITY, 1.0).err(),
            Some(EnvironmentError::InvalidRadiance { x: 3, y: 1 })
        );
        let empty = Image::<Rgb>::from_vec(0, 3, Vec::new()).unwrap();
        assert!(matches!(
            EnvironmentLight::new(empty, Mat3::IDENTITY, 1.0),
            Err(EnvironmentError::Empty { .. })
        ));
        let mut nan_matrix = Mat3::IDENTITY;
        nan_matrix.x_axis.x = f32::NAN;
        assert!(EnvironmentLight::new(probe, nan_matrix, 1.0).is_err());
    }

    #[test]
    fn constant_map_power_is_four_pi_l() {
        let env = EnvironmentLight::new(
            Image::filled(64, 32, Rgb::new(1.0, 2.0, 3.0)),
            Mat3::IDENTITY,
            0.5,
        )
        .unwrap();
        let p = env.total_power().to_array();
        for (c, expected) in p.iter().zip([0.5, 1.0, 1.5]) {
            assert!((c - 4.0 * PI * expected).abs() < 1e-9, "{c}");
        }
    }
}
