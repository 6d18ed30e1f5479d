//! Area patches: the planar pieces a room's surfaces are cut into for radiosity (Grosch 2005,
//! section 3: the room reconstructed from the probe, its walls subdivided into patches whose
//! radiance the probe shows and whose reflectance is estimated). A patch is a small Lambertian
//! emitter: seen from a point at distance `r` and angles `theta` (at the receiver) and `theta'` (at
//! the patch) it gives irradiance `E ~= L A cos(theta) cos(theta') / r^2` (the point-to-patch form
//! factor, valid while `r` is large against the patch).
//!
//! Data only; `ibl-room` makes and solves them.

use glam::Vec3;
use ibl_core::{Rgb, UnitDir};

/// One planar, Lambertian patch of a room's surface, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaPatch {
    /// Centre of the patch, metres, world frame.
    pub position: Vec3,
    /// Unit normal on the side that emits and receives, world frame.
    pub normal: UnitDir,
    /// Area, m^2.
    pub area_m2: f32,
    /// Outgoing radiance (emitted plus reflected, uniform over the hemisphere), linear RGB,
    /// W sr^-1 m^-2 (or the probe's relative unit).
    pub radiance: Rgb,
}

impl AreaPatch {
    /// The power the patch sends into its hemisphere, `Phi = pi L A` per channel (W, or the
    /// probe's unit x sr x m^2).
    pub fn power(&self) -> Rgb {
        self.radiance * (std::f32::consts::PI * self.area_m2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_is_pi_l_a() {
        let p = AreaPatch {
            position: Vec3::ZERO,
            normal: UnitDir::UP,
            area_m2: 2.0,
            radiance: Rgb::new(1.0, 0.5, 0.0),
        };
        // pi * 2 in f32: exact to one ulp of 2 pi.
        let e = p.power();
        assert!((e.r - 2.0 * std::f32::consts::PI).abs() <= f32::EPSILON * 8.0);
        assert!((e.g - std::f32::consts::PI).abs() <= f32::EPSILON * 4.0);
        assert_eq!(e.b, 0.0);
    }
}
