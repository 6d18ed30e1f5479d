//! Area patches: the planar pieces a room's surfaces are cut into for radiosity (Grosch 2005,
//! section 3: the room reconstructed from the probe, its walls subdivided into patches whose
//! radiance the probe shows and whose reflectance is estimated). A patch is a small Lambertian
//! emitter: seen from a point at distance `r` and angles `theta` (at the receiver) and `theta'` (at
//! the patch) it gives irradiance `E ~= L A cos(theta) cos(theta') / r^2` (the point-to-patch form
//! factor, valid while `r` is large against the patch).
//!
//! Data only; `ibl-room` makes and solves them. [`AreaPatch::as_distant_light`] is that
//! point-to-patch formula read as a directional light, for renderers that have no local lights.

use glam::{DVec3, Vec3};
use ibl_core::rgb::Rgb64;
use ibl_core::{Rgb, UnitDir};

use crate::Light;

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

    /// The patch as a directional light seen from `point` (world frame, metres): direction
    /// `w = (position - point) / r`, solid angle `Omega = A cos(theta') / r^2` with
    /// `cos(theta') = -normal . w` (the patch's tilt away from the point), radiance `L` and
    /// `I = L Omega`, the far-field form of the module's point-to-patch formula (good while `r`
    /// is large against the patch's size). `None` when the patch faces away from the point or
    /// sits on it.
    pub fn as_distant_light(&self, point: DVec3) -> Option<Light> {
        let offset = self.position.as_dvec3() - point;
        let r2 = offset.length_squared();
        if r2 <= 0.0 || !r2.is_finite() {
            return None;
        }
        let direction = offset / r2.sqrt();
        let cos_patch = -self.normal.dvec3().dot(direction);
        if cos_patch <= 0.0 {
            return None;
        }
        let solid_angle_sr = f64::from(self.area_m2) * cos_patch / r2;
        let mut irradiance = Rgb64::ZERO;
        irradiance.add_weighted(self.radiance, solid_angle_sr);
        Some(Light {
            direction,
            radiance: self.radiance,
            solid_angle_sr,
            irradiance,
            region: None,
            spread_sr: None,
            core_fraction: None,
            side: None,
        })
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

    #[test]
    fn a_distant_patch_is_its_point_to_patch_form_factor() {
        // A 0.01 m^2 patch 2 m above the point, facing down: Omega = A / r^2 = 0.0025 sr; tilted
        // by 60 degrees about x it gives half of that; facing up (away) it gives nothing.
        let p = AreaPatch {
            position: Vec3::new(0.0, 2.0, 0.0),
            normal: UnitDir::new(Vec3::NEG_Y).expect("unit"),
            area_m2: 0.01,
            radiance: Rgb::new(4.0, 2.0, 1.0),
        };
        let l = p.as_distant_light(DVec3::ZERO).expect("faces the point");
        // f32 area (0.01 to 1 ulp) times f64 arithmetic: 1e-9 relative is far above the error.
        assert!((l.solid_angle_sr - 0.0025).abs() < 0.0025 * 1e-6);
        assert!((l.direction - DVec3::Y).length() < 1e-12);
        assert!((l.irradiance.r - 4.0 * 0.0025).abs() < 1e-8);
        let tilted = AreaPatch {
            normal: UnitDir::new(Vec3::new(0.0, -0.5, 0.75f32.sqrt())).expect("unit"),
            ..p
        };
        let t = tilted
            .as_distant_light(DVec3::ZERO)
            .expect("still faces it");
        assert!((t.solid_angle_sr - 0.00125).abs() < 1e-9);
        let away = AreaPatch {
            normal: UnitDir::UP,
            ..p
        };
        assert_eq!(away.as_distant_light(DVec3::ZERO), None);
        assert_eq!(p.as_distant_light(DVec3::new(0.0, 2.0, 0.0)), None);
    }
}
