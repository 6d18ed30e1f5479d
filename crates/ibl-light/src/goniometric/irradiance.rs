//! What a goniometric light delivers to a surface point: Grosch 2005, section 4.2, EQ5,
//! `E = I(theta, phi) cos theta_e / d^2`, with `I` the intensity towards the point (in the
//! light's frame), `theta_e` the angle between the surface normal and the direction to the light
//! and `d` the distance. Unoccluded: shadows are the renderer's.

use glam::Vec3;
use ibl_core::Rgb;

use super::GoniometricLight;

impl GoniometricLight {
    /// The light-frame direction of a world direction (the inverse rotation of
    /// `world_from_light`, which is a rotation, so its transpose).
    pub fn light_from_world(&self, world_dir: Vec3) -> Vec3 {
        self.world_from_light.transpose() * world_dir
    }

    /// The radiant intensity towards world direction `travel` (from the light outwards, any
    /// length), in the scene's unit per sr: the table's interpolant times
    /// `intensity_per_candela`.
    pub fn intensity_towards(&self, travel: Vec3) -> Rgb {
        self.intensity_per_candela * self.table.intensity_towards(self.light_from_world(travel))
    }

    /// EQ5: the irradiance at world `point` on a surface with unit `normal` (lit on its front
    /// only), `I max(0, n . l) / d^2` with `l` the unit direction from the point to the light, in
    /// the scene's unit. Black at the light's own position.
    pub fn irradiance_at(&self, point: Vec3, normal: Vec3) -> Rgb {
        let to_light = self.position - point;
        let d2 = to_light.length_squared();
        if d2 <= 0.0 || !d2.is_finite() {
            return Rgb::ZERO;
        }
        let l = to_light / d2.sqrt();
        let cos = normal.dot(l).max(0.0);
        if cos == 0.0 {
            return Rgb::ZERO;
        }
        self.intensity_towards(-l) * (cos / d2)
    }
}

#[cfg(test)]
mod tests {
    use glam::Mat3;

    use super::*;
    use crate::CandelaTable;

    /// A downlight of 1000 cd straight down, falling linearly to 0 at 90 degrees.
    fn light(world_from_light: Mat3) -> GoniometricLight {
        GoniometricLight {
            position: Vec3::new(0.0, 3.0, 0.0),
            world_from_light,
            table: CandelaTable::new(vec![0.0, 90.0], vec![0.0], vec![1000.0, 0.0]).unwrap(),
            intensity_per_candela: Rgb::new(1.0, 0.5, 0.25),
        }
    }

    #[test]
    fn eq5_on_the_floor_below() {
        let l = light(Mat3::IDENTITY);
        // Straight below at 3 m: 1000 cd, cos 1, E = 1000 / 9 per unit of the scale (1e-3 here and
        // below: f32 rounding of values near 100).
        let e = l.irradiance_at(Vec3::ZERO, Vec3::Y);
        assert!((e.r - 1000.0 / 9.0).abs() < 1e-3 && (e.g - 500.0 / 9.0).abs() < 1e-3);
        // At (3, 0, 0): d^2 = 18, gamma = 45 degrees (500 cd), cos theta_e = 1 / sqrt 2.
        let e = l.irradiance_at(Vec3::new(3.0, 0.0, 0.0), Vec3::Y);
        let expected = 500.0 * std::f32::consts::FRAC_1_SQRT_2 / 18.0;
        assert!((e.r - expected).abs() < 1e-3, "{} vs {expected}", e.r);
        // Facing away, or at the light itself: nothing.
        assert_eq!(l.irradiance_at(Vec3::ZERO, -Vec3::Y), Rgb::ZERO);
        assert_eq!(l.irradiance_at(l.position, Vec3::Y), Rgb::ZERO);
    }

    #[test]
    fn turning_the_light_turns_its_beam() {
        // Turned 90 degrees about +Z: the light frame's -Y (its nadir) points along world +X
        // (1e-2: f32 rounding of the rotation, on values near 1000).
        let l = light(Mat3::from_rotation_z(std::f32::consts::FRAC_PI_2));
        assert!((l.intensity_towards(Vec3::X).r - 1000.0).abs() < 1e-2);
        assert!(l.intensity_towards(-Vec3::Y).r.abs() < 1e-2);
        // A wall at x = 2 facing -X receives the peak at 2 m.
        let e = l.irradiance_at(Vec3::new(2.0, 3.0, 0.0), -Vec3::X);
        assert!((e.r - 250.0).abs() < 1e-2, "{}", e.r);
    }
}
