//! `material = { kind = ..., ... }` of a virtual object: diffuse, glossy (Lambert plus a
//! normalised Phong lobe) or mirror, with the defaults a description may leave out. The materials
//! themselves are [`crate::Material`].

use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, invalid, reflectance};

/// `material = { kind = ..., ... }` of a virtual object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDescription {
    /// `diffuse`, `glossy` or `mirror`.
    pub kind: MaterialKind,
    /// Diffuse albedo, linear RGB in `[0, 1]` (diffuse, glossy). Default 0.5 grey.
    pub albedo: Option<[f32; 3]>,
    /// Specular reflectance (glossy) or mirror reflectance (mirror), linear RGB in `[0, 1]`.
    pub specular: Option<[f32; 3]>,
    /// Phong exponent of a glossy lobe, >= 1. Default 50.
    pub exponent: Option<f32>,
}

/// Material kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    /// Lambertian.
    Diffuse,
    /// Lambert plus a normalised Phong lobe.
    Glossy,
    /// Perfect mirror.
    Mirror,
}

impl MaterialDescription {
    pub(crate) fn validate(&self, path: &str) -> Result<(), DescriptionError> {
        if let Some(a) = self.albedo {
            reflectance(&format!("{path}.albedo"), a)?;
        }
        if let Some(s) = self.specular {
            reflectance(&format!("{path}.specular"), s)?;
        }
        match self.kind {
            MaterialKind::Diffuse => {
                if self.specular.is_some() || self.exponent.is_some() {
                    return Err(invalid(path, "a diffuse material takes only `albedo`"));
                }
            }
            MaterialKind::Glossy => {
                if let Some(e) = self.exponent
                    && !(e.is_finite() && (1.0..=1.0e5).contains(&e))
                {
                    return Err(invalid(
                        format!("{path}.exponent"),
                        format!("{e} is not in [1, 100000]"),
                    ));
                }
                let a = self.albedo.unwrap_or([DEFAULT_ALBEDO; 3]);
                let s = self.specular.unwrap_or([DEFAULT_SPECULAR; 3]);
                if (0..3).any(|k| a[k] + s[k] > 1.0 + 1e-6) {
                    return Err(invalid(
                        path,
                        "albedo + specular exceeds 1 in a channel (the surface would create light)",
                    ));
                }
            }
            MaterialKind::Mirror => {
                if self.albedo.is_some() || self.exponent.is_some() {
                    return Err(invalid(
                        path,
                        "a mirror takes only `specular` (its reflectance)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// The material this description stands for (defaults filled in).
    pub fn material(&self) -> crate::Material {
        use ibl_core::Rgb;
        let rgb = |v: [f32; 3]| Rgb::new(v[0], v[1], v[2]);
        match self.kind {
            MaterialKind::Diffuse => crate::Material::Diffuse {
                albedo: rgb(self.albedo.unwrap_or([DEFAULT_ALBEDO; 3])),
            },
            MaterialKind::Glossy => crate::Material::Glossy {
                albedo: rgb(self.albedo.unwrap_or([DEFAULT_ALBEDO; 3])),
                specular: rgb(self.specular.unwrap_or([DEFAULT_SPECULAR; 3])),
                exponent: self.exponent.unwrap_or(DEFAULT_EXPONENT),
            },
            MaterialKind::Mirror => crate::Material::Mirror {
                reflectance: rgb(self.specular.unwrap_or([DEFAULT_MIRROR; 3])),
            },
        }
    }
}

/// Default diffuse albedo of a material description that gives none (glossy: the diffuse part).
pub const DEFAULT_ALBEDO: f32 = 0.5;
/// Default specular reflectance of a glossy material.
pub const DEFAULT_SPECULAR: f32 = 0.3;
/// Default Phong exponent of a glossy material.
pub const DEFAULT_EXPONENT: f32 = 50.0;
/// Default reflectance of a mirror.
pub const DEFAULT_MIRROR: f32 = 0.9;
