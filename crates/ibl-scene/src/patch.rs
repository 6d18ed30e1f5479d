//! Per-triangle attributes a radiosity solver reads and writes (Grosch 2005, section 3: the room's
//! surfaces cut into patches, each with a diffuse reflectance estimated from the probe and a
//! radiosity `B` solved from `B = E + rho / pi * sum_j F_ij B_j` in radiance form). Every triangle
//! of a [`crate::GeometryLayer`] is one patch until a room subdivides its geometry; the material
//! group a patch belongs to is its [`crate::SurfaceTriangle::material`] index (one material per
//! group), named in [`crate::GeometryLayer::group_names`].
//!
//! Kept apart from the shading data ([`crate::SurfaceTriangle`]) so that the tracer's per-hit
//! reads stay as small as they were, and apart from the BVH so that patches can be split and the
//! accelerator rebuilt.

use ibl_core::Rgb;

/// What radiosity knows about one patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchAttributes {
    /// Diffuse reflectance `rho` per channel, in `[0, 1]` (the material's diffuse albedo until an
    /// estimate replaces it).
    pub reflectance: Rgb,
    /// Outgoing radiance of the (Lambertian) patch, linear RGB, W sr^-1 m^-2 or the probe's unit:
    /// `B / pi` for radiosity `B`. Zero until a solver fills it.
    pub radiance: Rgb,
}

impl PatchAttributes {
    /// A patch of reflectance `reflectance` that sends no light yet.
    pub fn unlit(reflectance: Rgb) -> PatchAttributes {
        PatchAttributes {
            reflectance,
            radiance: Rgb::ZERO,
        }
    }
}
