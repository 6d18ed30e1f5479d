//! What each of the probe's surface pixels covers: its `S = side^2` sub-pixel rays
//! ([`crate::view::pixel_footprint`]), whether they all meet the plane its centre sees (a
//! **pure** pixel) or not (a **mixed** pixel, across a geometric edge or the skyline), and, for
//! each surface sub-ray of a mixed pixel, the pure pixel nearby on the same plane that stands for
//! it (its **donor**).
//!
//! Why: a probe pixel is the mean radiance over its footprint. Where it straddles a shaded wall
//! and the bright sky above it (or a sunlit roof), inverting the per-pixel model for one albedo
//! puts the sky's light into the wall's albedo, and when the sun later reaches the wall the
//! relit pixel comes out several times too bright. Measured on the synthetic day (direct light,
//! the true lighting): the 5 % of the probe's surface pixels next to the sky or another surface
//! carry most of the relit map's error with the sun low in the west: 6.4 % at 17:00, 2.5 % with
//! those pixels taken from the truth. A mixed pixel is therefore relit sub-ray by sub-ray
//! ([`crate::relight`]): its sky sub-rays by the sky model, each surface sub-ray by its donor's
//! albedo and sky term with its own shadow and cosine; only pure pixels are inverted for an
//! albedo. A sub-ray with no pure pixel of its plane within [`MAX_DONOR_RADIUS`] pixels keeps
//! the mixed pixel's own inversion.
//!
//! Two points are on one plane when their normals agree to within 2.6 degrees (`n . n' >
//! 0.999`) and each lies within `1 cm + 1e-3 r` of the other's plane (`r` the distance from the
//! probe). Pixels seeing one plane across a texture edge (two paving tiles) are pure: the
//! albedo they get is the mean of the two, which relights correctly wherever the light is the
//! same on both sides.

use std::sync::Arc;

use glam::Vec3;
use ibl_scene::{Camera, GeometryLayer};
use rayon::prelude::*;

use crate::transfer::SurfacePoint;
use crate::view::{ProbeProjection, pixel_footprint};

/// Farthest donor, in pixels (Chebyshev distance on the lat-long).
pub const MAX_DONOR_RADIUS: usize = 6;
/// Largest angle between the normals of one plane: `n . n' > 0.999`.
const PLANE_COS: f32 = 0.999;
/// Plane distance tolerance: `1 cm + 1e-3` of the distance from the probe.
const PLANE_ABS: f32 = 0.01;
const PLANE_REL: f32 = 1e-3;

/// The footprints of the probe's surface pixels.
#[derive(Clone, Debug)]
pub struct ProbeFootprints {
    side: usize,
    /// `S` per point: what each sub-ray meets (`None`: the sky).
    sub_points: Arc<[Option<SurfacePoint>]>,
    /// The sky sub-rays of mixed points: `(point, world direction)`.
    sky_rays: Vec<(u32, Vec3)>,
    /// Per point: its index among the mixed points (`u32::MAX`: pure).
    mixed_index: Vec<u32>,
    /// `S` per mixed point: the donor point of each sub-ray (`u32::MAX`: sky or none).
    donors: Vec<u32>,
    /// Per point: itself when pure, else the donor of its centre's plane (itself when none).
    centre_donor: Vec<u32>,
}

fn same_plane(a: &SurfacePoint, b: &SurfacePoint, distance: f32) -> bool {
    a.normal.dot(b.normal) > PLANE_COS
        && a.normal.dot(b.position - a.position).abs() <= PLANE_ABS + PLANE_REL * distance
}

impl ProbeFootprints {
    /// Casts the `side x side` sub-rays of every surface pixel `pixels[k]` (row-major; point `k`
    /// has centre `points[k]`) of `projection`'s lat-long, classifies the pixels and finds the
    /// donors. Cost: `S` rays per point, and a search of at most `(2 R + 1)^2` pixels per
    /// surface sub-ray of a mixed pixel.
    pub fn build(
        layer: &GeometryLayer,
        projection: &ProbeProjection,
        pixels: &[usize],
        points: &[SurfacePoint],
        side: usize,
    ) -> ProbeFootprints {
        let side = side.max(1);
        let s = side * side;
        let (w, h) = (projection.view.width(), projection.view.height());
        let camera = Camera::Panorama {
            position: projection.position,
            world_from_probe: projection.world_from_probe,
        };
        let distance = |p: &SurfacePoint| (p.position - projection.position).length();
        let per_point: Vec<(Vec<Option<SurfacePoint>>, Vec<Vec3>, bool)> = pixels
            .par_iter()
            .zip(points)
            .map(|(&p, centre)| {
                let rays = pixel_footprint(layer, &camera, (w, h), (p % w, p / w), side);
                let subs: Vec<Option<SurfacePoint>> = rays
                    .iter()
                    .map(|r| {
                        r.hit.map(|hit| SurfacePoint {
                            position: hit.position,
                            normal: hit.normal,
                        })
                    })
                    .collect();
                let r = distance(centre);
                let mixed = subs
                    .iter()
                    .any(|q| q.is_none_or(|q| !same_plane(centre, &q, r)));
                let sky = if mixed {
                    rays.iter()
                        .filter(|r| r.hit.is_none())
                        .map(|r| r.direction)
                        .collect()
                } else {
                    Vec::new()
                };
                (subs, sky, mixed)
            })
            .collect();
        let mut point_of_pixel = vec![u32::MAX; w * h];
        for (k, &p) in pixels.iter().enumerate() {
            point_of_pixel[p] = k as u32;
        }
        let pure = |q: u32| q != u32::MAX && !per_point[q as usize].2;
        // The nearest pure point on the plane of `x`, searched ring by ring around `(i, j)`.
        let donor_of = |i: usize, j: usize, x: &SurfacePoint| -> Option<u32> {
            let r = distance(x);
            for radius in 1..=MAX_DONOR_RADIUS as i64 {
                let mut best: Option<(f32, u32)> = None;
                for dj in -radius..=radius {
                    let jj = j as i64 + dj;
                    if jj < 0 || jj >= h as i64 {
                        continue;
                    }
                    for di in -radius..=radius {
                        if di.abs() != radius && dj.abs() != radius {
                            continue;
                        }
                        let ii = (i as i64 + di).rem_euclid(w as i64) as usize;
                        let q = point_of_pixel[jj as usize * w + ii];
                        if !pure(q) || !same_plane(x, &points[q as usize], r) {
                            continue;
                        }
                        let d = (points[q as usize].position - x.position).length();
                        if best.is_none_or(|(b, _)| d < b) {
                            best = Some((d, q));
                        }
                    }
                }
                if let Some((_, q)) = best {
                    return Some(q);
                }
            }
            None
        };
        let mixed_points: Vec<usize> = (0..points.len()).filter(|&k| per_point[k].2).collect();
        let found: Vec<(Vec<u32>, u32)> = mixed_points
            .par_iter()
            .map(|&k| {
                let (i, j) = (pixels[k] % w, pixels[k] / w);
                let donors = per_point[k]
                    .0
                    .iter()
                    .map(|sub| sub.and_then(|x| donor_of(i, j, &x)).unwrap_or(u32::MAX))
                    .collect();
                let centre = donor_of(i, j, &points[k]).unwrap_or(k as u32);
                (donors, centre)
            })
            .collect();
        let mut mixed_index = vec![u32::MAX; points.len()];
        let mut centre_donor: Vec<u32> = (0..points.len() as u32).collect();
        let mut donors = Vec::with_capacity(mixed_points.len() * s);
        for (m, (&k, (d, c))) in mixed_points.iter().zip(found).enumerate() {
            mixed_index[k] = m as u32;
            centre_donor[k] = c;
            donors.extend(d);
        }
        let mut sky_rays = Vec::new();
        let mut sub_points = Vec::with_capacity(points.len() * s);
        for (k, (subs, sky, _)) in per_point.into_iter().enumerate() {
            sub_points.extend(subs);
            sky_rays.extend(sky.into_iter().map(|d| (k as u32, d)));
        }
        ProbeFootprints {
            side,
            sub_points: sub_points.into(),
            sky_rays,
            mixed_index,
            donors,
            centre_donor,
        }
    }

    /// Sub-rays per side.
    pub fn side(&self) -> usize {
        self.side
    }

    /// Sub-rays per pixel, `S`.
    pub fn per_point(&self) -> usize {
        self.side * self.side
    }

    /// `S` per point: what each sub-ray meets (`None`: the sky), shared.
    pub fn sub_points(&self) -> Arc<[Option<SurfacePoint>]> {
        Arc::clone(&self.sub_points)
    }

    /// Whether point `k`'s footprint leaves its centre's plane.
    pub fn is_mixed(&self, k: usize) -> bool {
        self.mixed_index[k] != u32::MAX
    }

    /// Mixed points.
    pub fn mixed_count(&self) -> usize {
        self.donors.len() / self.per_point()
    }

    /// The donor point of each sub-ray of mixed point `k` (`None`: a sky sub-ray or none found);
    /// empty for a pure point.
    pub fn donors(&self, k: usize) -> impl Iterator<Item = Option<usize>> + '_ {
        let s = self.per_point();
        let range = match self.mixed_index[k] {
            u32::MAX => 0..0,
            m => m as usize * s..(m as usize + 1) * s,
        };
        self.donors[range]
            .iter()
            .map(|&d| (d != u32::MAX).then_some(d as usize))
    }

    /// The point that stands for point `k`'s surface: itself when pure, else the donor of its
    /// centre's plane (itself when there is none).
    pub fn centre_donor(&self, k: usize) -> usize {
        self.centre_donor[k] as usize
    }

    /// The sky sub-rays of the mixed points: `(point, unit world direction)`.
    pub fn sky_rays(&self) -> &[(u32, Vec3)] {
        &self.sky_rays
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat3;
    use ibl_core::Rgb;
    use ibl_scene::{Material, PlacedMesh, primitives};

    #[test]
    fn pixels_across_the_skyline_are_mixed_and_borrow_from_below() {
        let m = Material::Diffuse {
            albedo: Rgb::splat(0.5),
        };
        // A wall 2.365 m high, 4 m in front of the probe (at 1 m height): its top edge, the
        // skyline straight ahead, is at elevation atan(1.365 / 4) = 18.84 degrees, row 25.3 of
        // 64: the centre of row 25 (18.28 degrees) sees the wall, its top sub-rows the sky.
        let layer = GeometryLayer::new(vec![
            PlacedMesh {
                name: "ground".into(),
                mesh: primitives::plane(Vec3::ZERO, Vec3::Y, [200.0, 200.0]),
                materials: vec![m],
            },
            PlacedMesh {
                name: "wall".into(),
                mesh: primitives::cuboid(Vec3::new(-50.0, 0.0, -4.2), Vec3::new(50.0, 2.365, -4.0)),
                materials: vec![m],
            },
        ]);
        let projection =
            ProbeProjection::new(&layer, Vec3::new(0.0, 1.0, 0.0), Mat3::IDENTITY, 128);
        let pixels = projection.view.surface_pixels();
        let points: Vec<SurfacePoint> = pixels
            .iter()
            .map(|&p| {
                let hit = projection.view.hits()[p].unwrap();
                SurfacePoint {
                    position: hit.position,
                    normal: hit.normal,
                }
            })
            .collect();
        let f = ProbeFootprints::build(&layer, &projection, &pixels, &points, 4);
        assert_eq!(f.per_point(), 16);
        assert!(f.mixed_count() > 0);
        // Straight ahead (-Z, column 64) the top wall row is mixed, the one below pure; the
        // mixed pixel's surface sub-rays take wall pixels below as donors, the others are sky.
        let col = 64;
        let rows: Vec<usize> = (0..64)
            .filter(|&j| {
                projection
                    .view
                    .hit(col, j)
                    .is_some_and(|h| h.normal.z > 0.9)
            })
            .collect();
        let top = *rows.first().unwrap();
        assert_eq!(top, 25);
        let k = pixels.iter().position(|&p| p == top * 128 + col).unwrap();
        let below = pixels
            .iter()
            .position(|&p| p == (top + 1) * 128 + col)
            .unwrap();
        assert!(f.is_mixed(k), "the skyline pixel");
        assert!(!f.is_mixed(below), "the wall under it");
        let donors: Vec<Option<usize>> = f.donors(k).collect();
        let sky = donors.iter().filter(|d| d.is_none()).count();
        assert!(sky > 0 && sky < 16, "{donors:?}");
        for d in donors.into_iter().flatten() {
            assert!(!f.is_mixed(d));
            assert!(points[d].normal.z > 0.9, "a wall donor");
        }
        assert!(
            f.sky_rays()
                .iter()
                .any(|&(p, d)| p as usize == k && d.y > 0.0)
        );
        assert_ne!(f.centre_donor(k), k);
        assert!(f.donors(below).next().is_none());
    }
}
