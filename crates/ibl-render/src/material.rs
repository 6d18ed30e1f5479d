//! The BSDF of an [`ibl_scene::Material`] at a shading point: evaluation, importance sampling and
//! density, for a path tracer and for multiple importance sampling with light sampling.
//!
//! Directions are unit world vectors pointing **away** from the surface: `wo` towards the viewer
//! (or the previous path vertex), `wi` towards the incoming light. `n_s` is the shading normal and
//! `n_g` the geometric normal, both on the side of `wo`. `f(wo, wi)` (1/sr) is zero unless `wo` and
//! `wi` are above the geometric surface and `wi` above the shading surface; cosines `cos(theta_i)`
//! are taken to `n_s`. With `r = 2 (wo . n_s) n_s - wo` the mirror direction of `wo`:
//!
//! - **diffuse**: `f = albedo / pi`; sampled by cosine (`pdf = cos(theta_i) / pi`), so the sample
//!   weight `f cos / pdf` is exactly `albedo`.
//! - **glossy** (Lambert plus the normalised Phong lobe of Lafortune and Willems 1994):
//!   `f = albedo / pi + specular (e + 2) / (2 pi) cos^e(alpha)` with `cos(alpha) = max(0, wi . r)`.
//!   A lobe is chosen with probability proportional to the luminance of `albedo` and `specular`
//!   (`P_s` for the specular one); the Phong lobe is sampled about `r` with
//!   `pdf = (e + 1) / (2 pi) cos^e(alpha)` over the hemisphere about `r`, its samples below the
//!   surface give no sample (`None`: that part of the density is never drawn, and `f = 0` there,
//!   so the estimate of the reflected radiance stays unbiased). The reported density is the mixture `(1 - P_s) cos(theta_i) / pi + P_s (e + 1) / (2 pi)
//!   cos^e(alpha)` whichever lobe drew `wi`, and the weight is `f cos(theta_i) / pdf` with the full
//!   `f` (one-sample MIS over the two lobes, balance heuristic). At normal incidence the
//!   directional albedo is exactly `albedo + specular`; it falls towards grazing angles.
//! - **mirror**: a delta lobe, `wi = r` with weight `reflectance`, `pdf_sr = 0` and
//!   `is_delta = true`; `eval` and `pdf` are 0 for every pair of directions (a light sample can
//!   never hit a delta).
//!
//! Cost: O(1) per call (one `powf` for the Phong lobe).

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::Vec3;
use ibl_core::Rgb;
use ibl_scene::Material;

use crate::sampling::{OrthonormalBasis, cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// One direction drawn from a [`Bsdf`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit incoming direction (away from the surface), world frame.
    pub wi: Vec3,
    /// `f cos(theta_i) / pdf` per channel (for a delta lobe: the reflectance).
    pub weight: Rgb,
    /// Density of `wi` per steradian; 0 for a delta lobe.
    pub pdf_sr: f32,
    /// Whether `wi` comes from a delta (mirror) lobe.
    pub is_delta: bool,
}

/// The lobes of a material, with what sampling needs precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Lobes {
    Diffuse {
        albedo: Rgb,
    },
    Glossy {
        albedo: Rgb,
        specular: Rgb,
        exponent: f32,
        /// Probability of sampling the Phong lobe.
        specular_probability: f32,
    },
    Mirror {
        reflectance: Rgb,
    },
}

/// A material's BSDF at one shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    lobes: Lobes,
    /// Basis about the shading normal (its `normal` is `n_s`).
    shading: OrthonormalBasis,
    geometric_normal: Vec3,
}

impl Bsdf {
    /// The BSDF of `material` at a point with unit shading normal `shading_normal` and unit
    /// geometric normal `geometric_normal`, both on the side of the outgoing direction. A zero or
    /// non-finite shading normal falls back to the geometric one; a negative or NaN Phong exponent
    /// counts as 0.
    pub fn new(material: &Material, shading_normal: Vec3, geometric_normal: Vec3) -> Self {
        let geometric_normal = geometric_normal.normalize_or_zero();
        let shading_normal = shading_normal.normalize_or(geometric_normal);
        let lobes = match *material {
            Material::Diffuse { albedo } => Lobes::Diffuse { albedo },
            Material::Glossy {
                albedo,
                specular,
                exponent,
            } => {
                let (d, s) = (albedo.luminance().max(0.0), specular.luminance().max(0.0));
                let specular_probability = if d + s > 0.0 { s / (d + s) } else { 0.0 };
                Lobes::Glossy {
                    albedo,
                    specular,
                    exponent: exponent.max(0.0),
                    specular_probability,
                }
            }
            Material::Mirror { reflectance } => Lobes::Mirror { reflectance },
        };
        Bsdf {
            lobes,
            shading: OrthonormalBasis::from_normal(shading_normal),
            geometric_normal,
        }
    }

    /// Whether the BSDF is a pure delta (a mirror): `eval` and `pdf` are then always 0.
    pub fn is_delta(&self) -> bool {
        matches!(self.lobes, Lobes::Mirror { .. })
    }

    /// Whether [`Bsdf::sample`] reads its first number (the choice between a glossy BSDF's two
    /// lobes); a diffuse or mirror BSDF ignores it, so a caller may skip drawing it.
    pub fn chooses_lobe(&self) -> bool {
        matches!(self.lobes, Lobes::Glossy { .. })
    }

    /// `f = albedo / pi` when the BSDF is purely diffuse and `wo` is on the surface's side: then
    /// `eval(wo, wi)` is that value for every `wi` above both the shading and the geometric
    /// surface (and 0 below), so a caller lighting one point from many directions can read it
    /// once. `None` for other lobes, or `wo` below the geometric surface.
    pub fn lambertian(&self, wo: Vec3) -> Option<Rgb> {
        match self.lobes {
            Lobes::Diffuse { albedo } if wo.dot(self.geometric_normal) > 0.0 => {
                Some(albedo * FRAC_1_PI)
            }
            _ => None,
        }
    }

    /// The mirror direction of `wo` about the shading normal.
    fn mirror(&self, wo: Vec3) -> Vec3 {
        let n = self.shading.normal;
        2.0 * wo.dot(n) * n - wo
    }

    /// `cos(theta_i)` to the shading normal when both directions are on the valid side, else
    /// `None`.
    fn cos_incoming(&self, wo: Vec3, wi: Vec3) -> Option<f32> {
        let cos_i = wi.dot(self.shading.normal);
        (wo.dot(self.geometric_normal) > 0.0 && wi.dot(self.geometric_normal) > 0.0 && cos_i > 0.0)
            .then_some(cos_i)
    }

    /// `(e + 1) / (2 pi) cos^e(alpha)`, the Phong lobe's sampling density about `r` (0 for
    /// `alpha > pi / 2`).
    fn phong_pdf(exponent: f32, cos_alpha: f32) -> f32 {
        if cos_alpha <= 0.0 {
            return 0.0;
        }
        (exponent + 1.0) / TAU * cos_alpha.powf(exponent)
    }

    /// The BSDF value `f(wo, wi)` per channel, in 1/sr (no cosine); 0 for a mirror.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if self.cos_incoming(wo, wi).is_none() {
            return Rgb::ZERO;
        }
        match self.lobes {
            Lobes::Diffuse { albedo } => albedo * FRAC_1_PI,
            Lobes::Glossy {
                albedo,
                specular,
                exponent,
                ..
            } => {
                let cos_alpha = wi.dot(self.mirror(wo));
                let lobe = if cos_alpha > 0.0 {
                    (exponent + 2.0) / TAU * cos_alpha.powf(exponent)
                } else {
                    0.0
                };
                albedo * FRAC_1_PI + specular * lobe
            }
            Lobes::Mirror { .. } => Rgb::ZERO,
        }
    }

    /// Density (1/sr) with which [`Bsdf::sample`] draws `wi` given `wo`; 0 for a mirror and for
    /// directions it never returns (below the surface).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(cos_i) = self.cos_incoming(wo, wi) else {
            return 0.0;
        };
        match self.lobes {
            Lobes::Diffuse { .. } => cosine_hemisphere_pdf(cos_i),
            Lobes::Glossy {
                exponent,
                specular_probability,
                ..
            } => {
                (1.0 - specular_probability) * cosine_hemisphere_pdf(cos_i)
                    + specular_probability * Self::phong_pdf(exponent, wi.dot(self.mirror(wo)))
            }
            Lobes::Mirror { .. } => 0.0,
        }
    }

    /// Draws an incoming direction for `wo` from `u` (three uniform numbers in `[0, 1)`; `u[0]`
    /// chooses the lobe of a glossy material). `None` when the sampled direction is below the
    /// surface, `wo` is, or the material reflects nothing.
    pub fn sample(&self, wo: Vec3, u: [f32; 3]) -> Option<BsdfSample> {
        match self.lobes {
            Lobes::Diffuse { albedo } => {
                let wi = self
                    .shading
                    .to_world(sample_cosine_hemisphere(u[1], u[2]))
                    .normalize();
                let cos_i = self.cos_incoming(wo, wi)?;
                Some(BsdfSample {
                    wi,
                    weight: albedo,
                    pdf_sr: cosine_hemisphere_pdf(cos_i),
                    is_delta: false,
                })
            }
            Lobes::Glossy {
                albedo,
                specular,
                exponent,
                specular_probability,
            } => {
                if albedo.max_channel() <= 0.0 && specular.max_channel() <= 0.0 {
                    return None;
                }
                let wi = if u[0] < specular_probability {
                    let cos_alpha = u[1].powf(1.0 / (exponent + 1.0));
                    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
                    let (sp, cp) = (TAU * u[2]).sin_cos();
                    OrthonormalBasis::from_normal(self.mirror(wo).normalize_or_zero())
                        .to_world(Vec3::new(sin_alpha * cp, sin_alpha * sp, cos_alpha))
                } else {
                    self.shading.to_world(sample_cosine_hemisphere(u[1], u[2]))
                }
                .normalize_or_zero();
                let cos_i = self.cos_incoming(wo, wi)?;
                let pdf_sr = self.pdf(wo, wi);
                if !(pdf_sr > 0.0 && pdf_sr.is_finite()) {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: self.eval(wo, wi) * (cos_i / pdf_sr),
                    pdf_sr,
                    is_delta: false,
                })
            }
            Lobes::Mirror { reflectance } => {
                let wi = self.mirror(wo).normalize_or_zero();
                self.cos_incoming(wo, wi)?;
                Some(BsdfSample {
                    wi,
                    weight: reflectance,
                    pdf_sr: 0.0,
                    is_delta: true,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_reflects_about_the_shading_normal() {
        let bsdf = Bsdf::new(
            &Material::Mirror {
                reflectance: Rgb::new(0.9, 0.8, 0.7),
            },
            Vec3::Y,
            Vec3::Y,
        );
        let wo = Vec3::new(1.0, 1.0, 0.0).normalize();
        let s = bsdf.sample(wo, [0.3, 0.3, 0.3]).unwrap();
        assert!((s.wi - Vec3::new(-1.0, 1.0, 0.0).normalize()).length() < 1e-6);
        assert_eq!(s.weight, Rgb::new(0.9, 0.8, 0.7));
        assert!(s.is_delta && s.pdf_sr == 0.0);
        assert_eq!(bsdf.eval(wo, s.wi), Rgb::ZERO);
        assert_eq!(bsdf.pdf(wo, s.wi), 0.0);
        assert!(bsdf.is_delta());
    }

    #[test]
    fn the_lambertian_value_is_eval_above_the_surface() {
        let n_g = Vec3::Y;
        let n_s = Vec3::new(0.3, 1.0, 0.0).normalize();
        let albedo = Rgb::new(0.5, 0.6, 0.7);
        let bsdf = Bsdf::new(&Material::Diffuse { albedo }, n_s, n_g);
        let wo = Vec3::new(0.2, 1.0, 0.1).normalize();
        let f = bsdf.lambertian(wo).expect("diffuse");
        for wi in [Vec3::Y, Vec3::new(1.0, 0.2, 0.0), Vec3::new(-0.3, 0.5, 0.8)] {
            assert_eq!(bsdf.eval(wo, wi.normalize()), f);
        }
        assert!(bsdf.lambertian(-wo).is_none());
        let mirror = Bsdf::new(
            &Material::Mirror {
                reflectance: albedo,
            },
            n_s,
            n_g,
        );
        assert!(mirror.lambertian(wo).is_none());
    }

    #[test]
    fn below_geometric_surface_is_black() {
        let n_g = Vec3::Y;
        let n_s = Vec3::new(0.5, 1.0, 0.0).normalize();
        let bsdf = Bsdf::new(&Material::Diffuse { albedo: Rgb::ONE }, n_s, n_g);
        let wo = Vec3::Y;
        // Above the shading surface, below the geometric one.
        let wi = Vec3::new(1.0, -0.1, 0.0).normalize();
        assert!(wi.dot(n_s) > 0.0);
        assert_eq!(bsdf.eval(wo, wi), Rgb::ZERO);
        assert_eq!(bsdf.pdf(wo, wi), 0.0);
        // Incoming from below the geometric surface.
        assert_eq!(bsdf.eval(-wo, Vec3::Y), Rgb::ZERO);
        assert!(bsdf.sample(-wo, [0.5, 0.5, 0.5]).is_none());
    }

    #[test]
    fn black_glossy_draws_nothing() {
        let bsdf = Bsdf::new(
            &Material::Glossy {
                albedo: Rgb::ZERO,
                specular: Rgb::ZERO,
                exponent: 10.0,
            },
            Vec3::Y,
            Vec3::Y,
        );
        assert!(bsdf.sample(Vec3::Y, [0.5, 0.5, 0.5]).is_none());
    }
}
