//! Which surface points the sun reaches: the paper's binary shadow map, by ray casting, and the
//! rule for when to cast again.
//!
//! Jensen, Andersen & Madsen 2006 (section 4.2): `s = 1` where a pixel's surface point is in
//! direct sunlight and 0 where the real scene shades it, "generated anew every time the
//! relighting algorithm detects that the light direction has changed significantly". Here `s` is
//! one shadow ray from the point (moved `1e-4` of the scene's extent off the surface) towards
//! the sun's centre; a point whose normal faces away from the sun is shaded by its own
//! `max(0, n . l) = 0` whatever `s` is. The sun's disc (0.53 degrees) makes real penumbrae a few
//! centimetres wide per metre of occluder distance: those points are the estimator's outliers.
//!
//! [`ShadowState`] keeps the map with the sun direction it was cast for and casts again only
//! when the sun has moved more than a threshold angle (default 0.25 degrees: the sun moves 0.25
//! degrees of hour angle per minute, and a shadow edge 10 m from its occluder moves 4 cm).

use glam::Vec3;
use ibl_scene::{GeometryLayer, Ray};
use rayon::prelude::*;

use crate::transfer::{SurfacePoint, ray_offset};

/// Default re-cast threshold, radians (0.25 degrees).
pub const DEFAULT_SHADOW_THRESHOLD_RAD: f32 = 0.25 * std::f32::consts::PI / 180.0;

/// `s` for every point: 1 when the ray towards `sun` (unit) leaves the scene, else 0.
pub fn sun_visibility(layer: &GeometryLayer, points: &[SurfacePoint], sun: Vec3) -> Vec<f32> {
    let offset = ray_offset(layer);
    points
        .par_iter()
        .map(|p| {
            let side = if p.normal.dot(sun) >= 0.0 { 1.0 } else { -1.0 };
            let ray = Ray::new(p.position + p.normal * (side * offset), sun);
            if layer.bvh.occluded(&ray, 0.0, f32::INFINITY) {
                0.0
            } else {
                1.0
            }
        })
        .collect()
}

/// A shadow map with the sun direction it was cast for.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowState {
    sun: Option<Vec3>,
    threshold_rad: f32,
    visibility: Vec<f32>,
    casts: u32,
}

impl ShadowState {
    /// No map yet; re-cast when the sun moves more than `threshold_rad`.
    pub fn new(threshold_rad: f32) -> ShadowState {
        ShadowState {
            sun: None,
            threshold_rad: threshold_rad.max(0.0),
            visibility: Vec::new(),
            casts: 0,
        }
    }

    /// Makes the map current for `sun`: casts again when there is none or the sun moved more
    /// than the threshold since the last cast. Returns whether it cast.
    pub fn update(&mut self, layer: &GeometryLayer, points: &[SurfacePoint], sun: Vec3) -> bool {
        let fresh = match self.sun {
            Some(last) if self.visibility.len() == points.len() => {
                last.dot(sun).clamp(-1.0, 1.0).acos() <= self.threshold_rad
            }
            _ => false,
        };
        if fresh {
            return false;
        }
        self.visibility = sun_visibility(layer, points, sun);
        self.sun = Some(sun);
        self.casts += 1;
        true
    }

    /// `s` per point (empty before the first update).
    pub fn visibility(&self) -> &[f32] {
        &self.visibility
    }

    /// The sun direction of the current map.
    pub fn sun(&self) -> Option<Vec3> {
        self.sun
    }

    /// How many times the map was cast.
    pub fn casts(&self) -> u32 {
        self.casts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::Rgb;
    use ibl_scene::{Material, PlacedMesh, primitives};

    #[test]
    fn a_wall_shades_the_ground_behind_it_and_recasts_only_on_a_move() {
        let m = Material::Diffuse {
            albedo: Rgb::splat(0.5),
        };
        let layer = GeometryLayer::new(vec![
            PlacedMesh {
                name: "ground".into(),
                mesh: primitives::plane(Vec3::ZERO, Vec3::Y, [100.0, 100.0]),
                materials: vec![m],
            },
            PlacedMesh {
                name: "wall".into(),
                mesh: primitives::cuboid(Vec3::new(-5.0, 0.0, -0.1), Vec3::new(5.0, 2.0, 0.1)),
                materials: vec![m],
            },
        ]);
        // Sun 45 degrees up in the south (+Z): the wall's shadow reaches 2 m north (-Z).
        let sun = Vec3::new(0.0, 1.0, 1.0).normalize();
        let at = |z: f32| SurfacePoint {
            position: Vec3::new(0.0, 0.0, z),
            normal: Vec3::Y,
        };
        let points = [at(-1.0), at(-1.9), at(-2.2), at(1.0)];
        let mut state = ShadowState::new(DEFAULT_SHADOW_THRESHOLD_RAD);
        assert!(state.update(&layer, &points, sun));
        assert_eq!(state.visibility(), &[0.0, 0.0, 1.0, 1.0]);
        // 0.1 degrees later: kept; 1 degree later: cast again.
        let turn = |deg: f32| glam::Quat::from_rotation_y(deg.to_radians()) * sun;
        assert!(!state.update(&layer, &points, turn(0.1)));
        assert!(state.update(&layer, &points, turn(1.0)));
        assert_eq!(state.casts(), 2);
    }
}
