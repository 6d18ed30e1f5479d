//! Surface materials: what a renderer needs to know about a surface's reflectance.
//!
//! Three kinds cover the papers' scenes and the usual test objects:
//! - **diffuse**: Lambertian, `f = albedo / pi` (Grosch's real surfaces, estimated `rho`);
//! - **glossy**: Lambert plus a normalised Phong lobe about the mirror direction,
//!   `f = albedo / pi + specular (e + 2) / (2 pi) cos^e(alpha)`, `alpha` the angle between the
//!   outgoing direction and the mirror of the incoming one (energy-conserving when
//!   `albedo + specular <= 1` per channel);
//! - **mirror**: a perfect specular reflector with reflectance per channel.
//!
//! Reflectances are linear RGB fractions in `[0, 1]`.

use ibl_core::Rgb;

/// A surface material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflector.
    Diffuse {
        /// Diffuse reflectance `rho` per channel, in `[0, 1]`.
        albedo: Rgb,
    },
    /// Lambert plus a normalised Phong lobe.
    Glossy {
        /// Diffuse reflectance per channel, in `[0, 1]`.
        albedo: Rgb,
        /// Specular reflectance per channel, in `[0, 1]`; `albedo + specular <= 1`.
        specular: Rgb,
        /// Phong exponent `e` (1 = very rough, 1000 = nearly a mirror).
        exponent: f32,
    },
    /// Perfect mirror.
    Mirror {
        /// Reflectance per channel, in `[0, 1]`.
        reflectance: Rgb,
    },
}

impl Material {
    /// The diffuse part's albedo (zero for a mirror): what irradiance-based shading multiplies.
    pub fn diffuse_albedo(&self) -> Rgb {
        match *self {
            Material::Diffuse { albedo } | Material::Glossy { albedo, .. } => albedo,
            Material::Mirror { .. } => Rgb::ZERO,
        }
    }
}
