//! Which surface points the sun reaches: the paper's binary shadow map, by ray casting, and the
//! rule for when to cast again.
//!
//! Jensen, Andersen & Madsen 2006 (section 4.2): `s = 1` where a pixel's surface point is in
//! direct sunlight and 0 where the real scene shades it, "generated anew every time the
//! relighting algorithm detects that the light direction has changed significantly". Here `s` is
//! one shadow ray from the point (moved `1e-4` of the scene's extent off the surface) towards
//! the sun; a point whose normal faces away from the sun is shaded by its own `max(0, n . l) =
//! 0` whatever `s` is.
//!
//! **The sun's disc.** The sun is 0.533 degrees across ([`SUN_ANGULAR_RADIUS`]), so a shadow
//! edge is a penumbra about 1 cm wide per metre from the occluder's edge: 15 cm behind a
//! building 8 m high at 28 degrees of elevation, the size of a probe pixel there. When points
//! come in groups (the sub-pixel footprint of one pixel, [`crate::tracking::PointLighting`]), the
//! `m`-th point of a group of `S` aims its ray at the `m`-th point of a Vogel spiral over the
//! disc (radius `R sqrt((m + 1/2) / S)`, golden-angle turns, the spiral turned by a golden-ratio
//! fraction of a turn from one group to the next), so the group's mean of `s` integrates the
//! visible fraction of the disc over the pixel's footprint at no extra rays. Measured on the
//! synthetic day (probe pixels shaded at 09:30 and sunlit at 17:00, see docs/OUTDOOR.md): aiming
//! at the centre leaves penumbra pixels with `s = 0` that the renderer's disc partly lights, and
//! their albedo comes out several times too high. A group of one aims at the centre, the paper's
//! binary map.
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

/// The sun's mean angular radius, radians (0.2666 degrees: 959.63 arc seconds at 1 AU).
pub const SUN_ANGULAR_RADIUS: f64 = 0.2666 * std::f64::consts::PI / 180.0;

/// The golden angle, radians: `pi (3 - sqrt 5)`.
const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;

/// The direction of the `m`-th of `per_group` shadow rays of group `group` towards the sun's
/// disc around `sun` (unit): see the module doc. `per_group <= 1` gives the centre.
pub fn disc_direction(sun: Vec3, group: usize, m: usize, per_group: usize) -> Vec3 {
    if per_group <= 1 {
        return sun;
    }
    let sun64 = sun.as_dvec3();
    let (t, b) = ibl_scene::primitives::tangents(sun);
    let (t, b) = (t.as_dvec3(), b.as_dvec3());
    let r = SUN_ANGULAR_RADIUS * ((m as f64 + 0.5) / per_group as f64).sqrt();
    let turn = (group as f64 * 0.618_033_988_749_895).fract() * std::f64::consts::TAU;
    let phi = m as f64 * GOLDEN_ANGLE + turn;
    (sun64 * r.cos() + (t * phi.cos() + b * phi.sin()) * r.sin())
        .normalize()
        .as_vec3()
}

/// `s` for every point: 1 when its ray towards the sun leaves the scene, else 0 (and 0 for a
/// `None`, a sub-pixel ray that sees the sky). `points` come in groups of `per_group` (one
/// pixel's footprint) whose rays spread over the sun's disc around `sun` (unit); see the module
/// doc.
pub fn sun_visibility(
    layer: &GeometryLayer,
    points: &[Option<SurfacePoint>],
    sun: Vec3,
    per_group: usize,
) -> Vec<f32> {
    let offset = ray_offset(layer);
    let per_group = per_group.max(1);
    points
        .par_iter()
        .enumerate()
        .map(|(index, p)| {
            let Some(p) = p else { return 0.0 };
            let dir = disc_direction(sun, index / per_group, index % per_group, per_group);
            let side = if p.normal.dot(dir) >= 0.0 { 1.0 } else { -1.0 };
            let ray = Ray::new(p.position + p.normal * (side * offset), dir);
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
    per_group: usize,
    visibility: Vec<f32>,
    casts: u32,
}

impl ShadowState {
    /// No map yet; re-cast when the sun moves more than `threshold_rad`; points come in groups
    /// of `per_group` whose rays spread over the sun's disc ([`sun_visibility`]).
    pub fn new(threshold_rad: f32, per_group: usize) -> ShadowState {
        ShadowState {
            sun: None,
            threshold_rad: threshold_rad.max(0.0),
            per_group: per_group.max(1),
            visibility: Vec::new(),
            casts: 0,
        }
    }

    /// Makes the map current for `sun`: casts again when there is none or the sun moved more
    /// than the threshold since the last cast. Returns whether it cast.
    pub fn update(
        &mut self,
        layer: &GeometryLayer,
        points: &[Option<SurfacePoint>],
        sun: Vec3,
    ) -> bool {
        let fresh = match self.sun {
            Some(last) if self.visibility.len() == points.len() => {
                last.dot(sun).clamp(-1.0, 1.0).acos() <= self.threshold_rad
            }
            _ => false,
        };
        if fresh {
            return false;
        }
        self.visibility = sun_visibility(layer, points, sun, self.per_group);
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
        let at = |z: f32| {
            Some(SurfacePoint {
                position: Vec3::new(0.0, 0.0, z),
                normal: Vec3::Y,
            })
        };
        let points = [at(-1.0), at(-1.9), at(-2.2), at(1.0)];
        let mut state = ShadowState::new(DEFAULT_SHADOW_THRESHOLD_RAD, 1);
        assert!(state.update(&layer, &points, sun));
        assert_eq!(state.visibility(), &[0.0, 0.0, 1.0, 1.0]);
        // 0.1 degrees later: kept; 1 degree later: cast again.
        let turn = |deg: f32| glam::Quat::from_rotation_y(deg.to_radians()) * sun;
        assert!(!state.update(&layer, &points, turn(0.1)));
        assert!(state.update(&layer, &points, turn(1.0)));
        assert_eq!(state.casts(), 2);
    }
}
