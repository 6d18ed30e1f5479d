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
//! Texel look-up uses `theta = atan2(sqrt(x^2 + z^2), y)`, well conditioned at the poles, and
//! `phi = atan2(x, -z)` in f64. Cost: O(W H) to build (rows in parallel, sums in f64 per row),
//! O(1) expected per sample (the guided inversion of [`Distribution1D`]), O(1) per radiance or
//! density look-up.

use std::f64::consts::{PI, TAU};

use glam::{DVec3, Mat3, Vec3};
use ibl_core::rgb::Rgb64;
use ibl_core::{Image, LatLong, Rgb};
use rayon::prelude::*;

use crate::sampling::{Distribution1D, UniformCone};

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

/// A lat-long probe as a distant light, with a luminance-proportional sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    latlong: LatLong,
    /// Scaled radiance, row-major, row 0 at the top.
    radiance: Vec<Rgb>,
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
}

impl EnvironmentLight {
    /// Builds the light from a lat-long radiance probe (probe frame), the orthogonal matrix
    /// `world_from_probe` and a radiance scale (multiplies every texel). O(W H).
    pub fn new(
        probe: Image<Rgb>,
        world_from_probe: Mat3,
        radiance_scale: f32,
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
        let row_edge_cos = (0..=height)
            .map(|j| (PI * j as f64 / height as f64).cos())
            .collect();
        let radiance: Vec<Rgb> = probe
            .into_vec()
            .into_iter()
            .map(|l| l * radiance_scale)
            .collect();
        let conditionals: Vec<Distribution1D> = radiance
            .par_chunks_exact(width)
            .zip(row_solid_angle.par_iter())
            .map(|(row, &d_omega)| {
                Distribution1D::new(row.iter().map(|l| f64::from(l.luminance()) * d_omega))
            })
            .collect();
        let marginal = Distribution1D::new(conditionals.iter().map(Distribution1D::total));
        let importance = marginal.total() > 0.0;
        Ok(EnvironmentLight {
            latlong,
            radiance,
            world_from_probe,
            probe_from_world: world_from_probe.transpose(),
            row_solid_angle,
            row_edge_cos,
            marginal,
            conditionals,
            importance,
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
        let d: DVec3 = (self.probe_from_world * dir_world).as_dvec3();
        // The squares of f32 values are exact in f64 and cannot overflow: no need for `hypot`.
        let theta = (d.x * d.x + d.z * d.z).sqrt().atan2(d.y);
        let phi = d.x.atan2(-d.z);
        let (w, h) = (self.latlong.width, self.latlong.height);
        let mut u = phi / TAU + 0.5;
        if u >= 1.0 {
            u -= 1.0;
        }
        // Float-to-int casts saturate (NaN gives 0), so any input maps to a valid texel.
        let i = ((u * w as f64) as usize).min(w - 1);
        let j = ((theta / PI * h as f64) as usize).min(h - 1);
        (i, j)
    }

    /// Radiance arriving from the world direction `dir_world` (nearest texel, scaled).
    pub fn radiance(&self, dir_world: Vec3) -> Rgb {
        let (i, j) = self.texel_of(dir_world);
        self.radiance[j * self.latlong.width + i]
    }

    /// Density (1/sr) with which [`EnvironmentLight::sample`] draws `dir_world`.
    pub fn pdf(&self, dir_world: Vec3) -> f32 {
        self.radiance_and_pdf(dir_world).1
    }

    /// [`EnvironmentLight::radiance`] and [`EnvironmentLight::pdf`] of one direction, finding
    /// its texel once.
    pub fn radiance_and_pdf(&self, dir_world: Vec3) -> (Rgb, f32) {
        let (i, j) = self.texel_of(dir_world);
        let pdf = if self.importance {
            self.texel_pdf(i, j)
        } else {
            UniformCone::SPHERE.pdf()
        };
        (self.radiance[j * self.latlong.width + i], pdf)
    }

    fn texel_pdf(&self, i: usize, j: usize) -> f32 {
        let p = f64::from(self.marginal.probability(j))
            * f64::from(self.conditionals[j].probability(i));
        (p / self.row_solid_angle[j]) as f32
    }

    /// A direction drawn with density proportional to luminance (uniform within a texel) from
    /// `u1, u2` in `[0, 1)`: `u1` picks the row, `u2` the column. O(1) expected, O(log W +
    /// log H) at worst.
    pub fn sample(&self, u1: f32, u2: f32) -> EnvSample {
        let chosen = if self.importance {
            self.marginal.sample(u1).and_then(|row| {
                self.conditionals[row.index]
                    .sample(u2)
                    .map(|column| (row, column))
            })
        } else {
            None
        };
        let Some((row, column)) = chosen else {
            let direction = UniformCone::SPHERE.sample(u1, u2);
            return EnvSample {
                direction,
                radiance: self.radiance(direction),
                pdf_sr: UniformCone::SPHERE.pdf(),
            };
        };
        let j = row.index;
        let i = column.index;
        let inset = |f: f32| EDGE_MARGIN + (1.0 - 2.0 * EDGE_MARGIN) * f64::from(f);
        let w = self.latlong.width;
        let phi = TAU * ((i as f64 + inset(column.remapped)) / w as f64 - 0.5);
        let (c0, c1) = (self.row_edge_cos[j], self.row_edge_cos[j + 1]);
        let cos_theta = c0 + inset(row.remapped) * (c1 - c0);
        let sin_theta = ((1.0 - cos_theta) * (1.0 + cos_theta)).max(0.0).sqrt();
        let (sp, cp) = phi.sin_cos();
        let probe_dir = DVec3::new(sin_theta * sp, cos_theta, -sin_theta * cp).as_vec3();
        EnvSample {
            direction: (self.world_from_probe * probe_dir).normalize_or(Vec3::Y),
            radiance: self.radiance[j * w + i],
            pdf_sr: self.texel_pdf(i, j),
        }
    }

    /// Power per channel, `sum_p L_p dOmega_p` (scaled radiance x sr), accumulated in f64 per row
    /// and then over rows in order (CONVENTIONS section 4).
    pub fn total_power(&self) -> Rgb64 {
        self.radiance
            .chunks_exact(self.latlong.width)
            .zip(&self.row_solid_angle)
            .fold(Rgb64::ZERO, |total, (row, &d_omega)| {
                let mut row_sum = Rgb64::ZERO;
                for &l in row {
                    row_sum.add_weighted(l, d_omega);
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
