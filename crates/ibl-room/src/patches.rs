//! Subdivision of faces into patches by an area threshold (Grosch 2005, section 3.3: "we
//! subdivide the geometry in patches based on an area threshold").
//!
//! - A **rectangle** is cut at its own edges and at every hole's edges; each interval between
//!   two consecutive cuts of length `l` is split into `ceil(l / s)` equal parts, `s =
//!   sqrt(threshold)`, and the cells inside holes are dropped. Every patch is a rectangle of at
//!   most `s x s`, so at most the threshold, and the holes' edges are patch edges.
//! - A **polygon** is triangulated by ear clipping and every triangle is halved through the
//!   midpoint of its longest edge until its area is at most the threshold (longest-edge
//!   bisection keeps the triangles' shapes from degenerating).
//!
//! The number of patches is computed before anything is allocated and bounded by
//! [`MAX_PATCHES`]. A patch is a parallelogram or a triangle, so a uniform point on it is one
//! affine map of the unit square: what form factors by ray casting need.

use glam::{Vec2, Vec3};

use crate::RoomError;
use crate::geometry::{Face, FaceShape};
use ibl_scene::polygon::signed_area;

/// Largest number of patches a room may be cut into.
pub const MAX_PATCHES: usize = 500_000;

/// The shape of a patch, world frame, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PatchShape {
    /// `origin + s edge_u + t edge_v`, `s, t` in [0, 1]; front `edge_u x edge_v`.
    Parallelogram {
        /// One corner.
        origin: Vec3,
        /// First edge.
        edge_u: Vec3,
        /// Second edge.
        edge_v: Vec3,
    },
    /// A triangle, counter-clockwise seen from its front.
    Triangle {
        /// The corners.
        corners: [Vec3; 3],
    },
}

impl PatchShape {
    /// The point for unit-square coordinates `(a, b)`, uniform in area when `(a, b)` is
    /// uniform in the square (triangles by the square-root warp).
    pub fn point(&self, a: f32, b: f32) -> Vec3 {
        match *self {
            PatchShape::Parallelogram {
                origin,
                edge_u,
                edge_v,
            } => origin + edge_u * a + edge_v * b,
            PatchShape::Triangle { corners: [p, q, r] } => {
                let sa = a.sqrt();
                p * (1.0 - sa) + q * (sa * (1.0 - b)) + r * (sa * b)
            }
        }
    }

    /// The triangles covering the patch, counter-clockwise seen from the front (two for a
    /// parallelogram).
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        match *self {
            PatchShape::Parallelogram {
                origin,
                edge_u,
                edge_v,
            } => {
                let (a, b, c, d) = (
                    origin,
                    origin + edge_u,
                    origin + edge_u + edge_v,
                    origin + edge_v,
                );
                vec![[a, b, c], [a, c, d]]
            }
            PatchShape::Triangle { corners } => vec![corners],
        }
    }

    /// The corners in order around the patch.
    pub fn corners(&self) -> Vec<Vec3> {
        match *self {
            PatchShape::Parallelogram {
                origin,
                edge_u,
                edge_v,
            } => vec![
                origin,
                origin + edge_u,
                origin + edge_u + edge_v,
                origin + edge_v,
            ],
            PatchShape::Triangle { corners } => corners.to_vec(),
        }
    }
}

/// A patch: the unit of radiosity (one `B`, `E` and `rho` per channel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// Index of the face it was cut from.
    pub face: u32,
    /// Index of its material group.
    pub group: u32,
    /// Its shape.
    pub shape: PatchShape,
    /// Area, m^2.
    pub area_m2: f32,
    /// Centroid, world frame, metres.
    pub centroid: Vec3,
    /// Unit front normal, world frame.
    pub normal: Vec3,
}

/// The cut positions of one rectangle axis: the ends, the holes' edges, and equal parts of at
/// most `step` between them.
fn cuts(length: f32, edges: impl Iterator<Item = f32>, step: f32) -> Vec<f32> {
    let mut hard: Vec<f32> = std::iter::once(0.0)
        .chain(edges.map(|e| e.clamp(0.0, length)))
        .chain(std::iter::once(length))
        .collect();
    hard.sort_by(f32::total_cmp);
    // Edges within 0.1 mm of each other are one edge.
    hard.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
    if let Some(last) = hard.last_mut() {
        *last = length;
    }
    let mut out = vec![0.0];
    for w in hard.windows(2) {
        let parts = ((w[1] - w[0]) / step).ceil().max(1.0) as usize;
        for k in 1..=parts {
            out.push(w[0] + (w[1] - w[0]) * k as f32 / parts as f32);
        }
    }
    out
}

fn cut_count(length: f32, edges: impl Iterator<Item = f32>, step: f32) -> usize {
    let mut hard: Vec<f32> = std::iter::once(0.0)
        .chain(edges.map(|e| e.clamp(0.0, length)))
        .chain(std::iter::once(length))
        .collect();
    hard.sort_by(f32::total_cmp);
    hard.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
    hard.windows(2)
        .map(|w| ((w[1] - w[0]) / step).ceil().max(1.0) as usize)
        .sum()
}

/// How many patches [`subdivide`] will make of `faces` (an upper bound for rectangles with
/// holes, exact otherwise), without allocating them.
pub fn patch_count(faces: &[Face], max_area_m2: f32) -> Result<usize, RoomError> {
    let step = max_area_m2.sqrt();
    let mut total = 0usize;
    for face in faces {
        let n = match &face.shape {
            FaceShape::Rectangle { size, holes } => {
                let nu = cut_count(size[0], holes.iter().flat_map(|h| [h[0], h[2]]), step);
                let nv = cut_count(size[1], holes.iter().flat_map(|h| [h[1], h[3]]), step);
                nu.saturating_mul(nv)
            }
            FaceShape::Polygon { points } => ear_clip(points)
                .iter()
                .map(|t| {
                    let area = triangle_area2(t);
                    let halvings = (area / max_area_m2).log2().ceil().max(0.0);
                    if halvings > 40.0 {
                        usize::MAX
                    } else {
                        1usize << halvings as u32
                    }
                })
                .fold(0usize, usize::saturating_add),
        };
        total = total.saturating_add(n);
        if total > MAX_PATCHES {
            return Err(RoomError::Limits(format!(
                "the room would have more than {MAX_PATCHES} patches at {max_area_m2} m^2 per \
                 patch (face `{}` alone: {n}); raise room.patch_area_m2",
                face.name
            )));
        }
    }
    Ok(total)
}

/// Cuts every face into patches of at most `max_area_m2` (checked against [`MAX_PATCHES`]
/// first).
pub fn subdivide(faces: &[Face], max_area_m2: f32) -> Result<Vec<Patch>, RoomError> {
    let count = patch_count(faces, max_area_m2)?;
    let step = max_area_m2.sqrt();
    let mut patches = Vec::with_capacity(count);
    for (index, face) in faces.iter().enumerate() {
        let face_index = index as u32;
        match &face.shape {
            FaceShape::Rectangle { size, holes } => {
                let us = cuts(size[0], holes.iter().flat_map(|h| [h[0], h[2]]), step);
                let vs = cuts(size[1], holes.iter().flat_map(|h| [h[1], h[3]]), step);
                for vw in vs.windows(2) {
                    for uw in us.windows(2) {
                        let centre = Vec2::new(0.5 * (uw[0] + uw[1]), 0.5 * (vw[0] + vw[1]));
                        let in_hole = holes.iter().any(|h| {
                            centre.x > h[0] && centre.x < h[2] && centre.y > h[1] && centre.y < h[3]
                        });
                        if in_hole {
                            continue;
                        }
                        let origin = face.point(uw[0], vw[0]);
                        let edge_u = face.u_axis * (uw[1] - uw[0]);
                        let edge_v = face.v_axis * (vw[1] - vw[0]);
                        patches.push(Patch {
                            face: face_index,
                            group: face.group,
                            shape: PatchShape::Parallelogram {
                                origin,
                                edge_u,
                                edge_v,
                            },
                            area_m2: (uw[1] - uw[0]) * (vw[1] - vw[0]),
                            centroid: origin + 0.5 * (edge_u + edge_v),
                            normal: face.normal,
                        });
                    }
                }
            }
            FaceShape::Polygon { points } => {
                let mut stack: Vec<[Vec2; 3]> = ear_clip(points);
                while let Some(t) = stack.pop() {
                    if triangle_area2(&t) > max_area_m2 {
                        stack.extend(bisect(t));
                        continue;
                    }
                    let corners = t.map(|p| face.point(p.x, p.y));
                    patches.push(Patch {
                        face: face_index,
                        group: face.group,
                        shape: PatchShape::Triangle { corners },
                        area_m2: triangle_area2(&t),
                        centroid: (corners[0] + corners[1] + corners[2]) / 3.0,
                        normal: face.normal,
                    });
                }
            }
        }
    }
    Ok(patches)
}

fn triangle_area2(t: &[Vec2; 3]) -> f32 {
    0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs()
}

/// The two halves of a triangle through the midpoint of its longest edge (both keep the
/// counter-clockwise winding).
fn bisect(t: [Vec2; 3]) -> [[Vec2; 3]; 2] {
    let lengths = [
        (t[1] - t[0]).length_squared(),
        (t[2] - t[1]).length_squared(),
        (t[0] - t[2]).length_squared(),
    ];
    let k = (0..3)
        .max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]))
        .unwrap_or(0);
    let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
    let m = 0.5 * (a + b);
    [[a, m, c], [m, b, c]]
}

/// Ear-clipping triangulation of a simple counter-clockwise polygon (Meisters 1975): repeatedly
/// cut off a convex corner whose triangle holds no other vertex. O(n^3) in the worst case for n
/// vertices (at most `MAX_POLYGON_VERTICES`). Collinear corners are skipped once nothing else is
/// left to cut.
pub(crate) fn ear_clip(points: &[Vec2]) -> Vec<[Vec2; 3]> {
    let mut ring: Vec<Vec2> = points.to_vec();
    if signed_area(&ring) < 0.0 {
        ring.reverse();
    }
    let mut out = Vec::with_capacity(ring.len().saturating_sub(2));
    while ring.len() > 3 {
        let n = ring.len();
        let ear = (0..n).find(|&i| {
            let (a, b, c) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
            if (b - a).perp_dot(c - b) <= 0.0 {
                return false;
            }
            !ring.iter().enumerate().any(|(j, &p)| {
                j != i && j != (i + n - 1) % n && j != (i + 1) % n && inside_or_on(p, a, b, c)
            })
        });
        match ear {
            Some(i) => {
                let n = ring.len();
                out.push([ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]]);
                ring.remove(i);
            }
            None => {
                // Only collinear or numerically flat corners remain: drop one (no area lost
                // beyond rounding).
                let n = ring.len();
                let flat = (0..n)
                    .min_by(|&x, &y| {
                        let area = |i: usize| {
                            (ring[i] - ring[(i + n - 1) % n])
                                .perp_dot(ring[(i + 1) % n] - ring[i])
                                .abs()
                        };
                        area(x).total_cmp(&area(y))
                    })
                    .unwrap_or(0);
                ring.remove(flat);
            }
        }
    }
    if ring.len() == 3 && signed_area(&ring) > 0.0 {
        out.push([ring[0], ring[1], ring[2]]);
    }
    out
}

fn inside_or_on(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> bool {
    let d1 = (b - a).perp_dot(p - a);
    let d2 = (c - b).perp_dot(p - b);
    let d3 = (a - c).perp_dot(p - c);
    d1 >= 0.0 && d2 >= 0.0 && d3 >= 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ear_clipping_keeps_the_area_of_a_concave_polygon() {
        // An L shape of area 3.
        let l = [
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        let t = ear_clip(&l);
        assert_eq!(t.len(), 4);
        let area: f32 = t.iter().map(triangle_area2).sum();
        assert!((area - 3.0).abs() < 1e-5, "{area}");
    }

    #[test]
    fn cuts_include_hole_edges_and_respect_the_step() {
        let c = cuts(3.0, [1.2, 1.9].into_iter(), 0.5);
        assert!(c.iter().any(|&x| (x - 1.2).abs() < 1e-6));
        assert!(c.iter().any(|&x| (x - 1.9).abs() < 1e-6));
        assert!(
            c.windows(2)
                .all(|w| w[1] - w[0] <= 0.5 + 1e-6 && w[1] > w[0])
        );
        assert_eq!(c.len() - 1, cut_count(3.0, [1.2, 1.9].into_iter(), 0.5));
    }
}
