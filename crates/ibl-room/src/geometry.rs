//! Planar faces from a room description: every rectangle, box face, filled opening and polygon
//! becomes one [`Face`] with an orthonormal frame, in the world frame (metres).
//!
//! A face has an origin, two unit in-plane axes `u` and `v` and its front normal `n = u x v`
//! (right-handed, so a shape counter-clockwise in `(u, v)` is counter-clockwise seen from the
//! front). Its outline is given in `(u, v)` metres from the origin: a rectangle with rectangular
//! holes, or a simple polygon. Box faces use the world axes of [`BoxFace::in_plane_axes`],
//! swapped where needed so that `u x v` is the face's front (outward for furniture, inward for a
//! room's shell); a filled opening is a rectangle of its own group lying in its hole, with the
//! same front. Keeping faces apart from patches lets the patch size change without re-reading
//! the description, and gives the depth map a face index per pixel (edges between faces are
//! where probe pixels mix two surfaces).

use glam::{Vec2, Vec3};

use crate::RoomError;
use crate::description::{BoxFace, Facing, RoomDescription};

/// A planar face of the room.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Name for reports (`shell.-z`, `shell.-z.opening[0]`, `table`).
    pub name: String,
    /// Index of its material group in the description.
    pub group: u32,
    /// Origin of the face's `(u, v)` coordinates, world frame, metres.
    pub origin: Vec3,
    /// Unit first in-plane axis, world frame.
    pub u_axis: Vec3,
    /// Unit second in-plane axis, world frame, orthogonal to `u_axis`.
    pub v_axis: Vec3,
    /// Unit front normal `u_axis x v_axis`.
    pub normal: Vec3,
    /// The outline in `(u, v)` metres from the origin.
    pub shape: FaceShape,
}

/// A face's outline, in its own `(u, v)` metres.
#[derive(Clone, Debug, PartialEq)]
pub enum FaceShape {
    /// `[0, size[0]] x [0, size[1]]` minus rectangular holes `[u0, v0, u1, v1]`.
    Rectangle {
        /// Side lengths along `u` and `v`, metres.
        size: [f32; 2],
        /// Holes `[u0, v0, u1, v1]`, metres, inside the rectangle, not overlapping.
        holes: Vec<[f32; 4]>,
    },
    /// A simple polygon, counter-clockwise in `(u, v)`.
    Polygon {
        /// Vertices in `(u, v)` metres.
        points: Vec<Vec2>,
    },
}

impl Face {
    /// The world point at face coordinates `(s, t)` metres.
    pub fn point(&self, s: f32, t: f32) -> Vec3 {
        self.origin + self.u_axis * s + self.v_axis * t
    }

    /// Area, m^2 (holes excluded).
    pub fn area_m2(&self) -> f32 {
        match &self.shape {
            FaceShape::Rectangle { size, holes } => {
                size[0] * size[1]
                    - holes
                        .iter()
                        .map(|h| (h[2] - h[0]) * (h[3] - h[1]))
                        .sum::<f32>()
            }
            FaceShape::Polygon { points } => signed_area(points),
        }
    }
}

/// Twice the signed area's half: the signed area of a 2D polygon (positive counter-clockwise).
pub(crate) fn signed_area(points: &[Vec2]) -> f32 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| points[i].perp_dot(points[(i + 1) % n]))
        .sum::<f32>()
}

fn axis_vec(axis: usize) -> Vec3 {
    match axis {
        0 => Vec3::X,
        1 => Vec3::Y,
        _ => Vec3::Z,
    }
}

/// Every face of `description` (validated first), in file order: rectangles, boxes (faces in
/// [`BoxFace::ALL`] order, each followed by its filled openings), polygons.
pub fn faces(description: &RoomDescription) -> Result<Vec<Face>, RoomError> {
    description.validate()?;
    let group = |name: &str| -> u32 { description.group_index(name).unwrap_or(0) as u32 };
    let mut faces = Vec::new();
    for (i, r) in description.rectangles.iter().enumerate() {
        let name = r.name.clone().unwrap_or_else(|| format!("rectangle[{i}]"));
        let eu = Vec3::from(r.edge_u);
        let ev = Vec3::from(r.edge_v);
        let u_axis = eu.normalize();
        // Exactly orthogonal (validation allowed |cos| <= 1e-3).
        let v_axis = (ev - u_axis * ev.dot(u_axis)).normalize();
        let size = [eu.length(), ev.length()];
        let normal = u_axis.cross(v_axis).normalize();
        let holes: Vec<[f32; 4]> = r
            .holes
            .iter()
            .map(|h| [h.min[0], h.min[1], h.max[0], h.max[1]])
            .collect();
        let parent = Face {
            name: name.clone(),
            group: group(&r.group),
            origin: Vec3::from(r.corner),
            u_axis,
            v_axis,
            normal,
            shape: FaceShape::Rectangle {
                size,
                holes: holes.clone(),
            },
        };
        let filled: Vec<Face> = r
            .holes
            .iter()
            .enumerate()
            .filter_map(|(k, h)| {
                h.fill
                    .as_ref()
                    .map(|g| filled_hole(format!("{name}.hole[{k}]"), group(g), &parent, holes[k]))
            })
            .collect();
        faces.push(parent);
        faces.extend(filled);
    }
    for (i, b) in description.boxes.iter().enumerate() {
        let name = b.name.clone().unwrap_or_else(|| format!("box[{i}]"));
        for face in BoxFace::ALL {
            if b.omit.contains(&face) {
                continue;
            }
            let axis = face.axis();
            let (ua, va) = face.in_plane_axes();
            let outward = if face.at_max() {
                axis_vec(axis)
            } else {
                -axis_vec(axis)
            };
            let normal = match b.facing {
                Facing::Outward => outward,
                Facing::Inward => -outward,
            };
            let plane = if face.at_max() {
                b.max[axis]
            } else {
                b.min[axis]
            };
            let mut origin = Vec3::ZERO;
            origin[axis] = plane;
            origin[ua] = b.min[ua];
            origin[va] = b.min[va];
            let mut size = [b.max[ua] - b.min[ua], b.max[va] - b.min[va]];
            let mut holes: Vec<[f32; 4]> = b
                .openings
                .iter()
                .filter(|o| o.face == face)
                .map(|o| {
                    [
                        o.min[0] - b.min[ua],
                        o.min[1] - b.min[va],
                        o.max[0] - b.min[ua],
                        o.max[1] - b.min[va],
                    ]
                })
                .collect();
            let fills: Vec<Option<&String>> = b
                .openings
                .iter()
                .filter(|o| o.face == face)
                .map(|o| o.fill.as_ref())
                .collect();
            let (mut u_axis, mut v_axis) = (axis_vec(ua), axis_vec(va));
            if u_axis.cross(v_axis).dot(normal) < 0.0 {
                std::mem::swap(&mut u_axis, &mut v_axis);
                size.swap(0, 1);
                for h in &mut holes {
                    *h = [h[1], h[0], h[3], h[2]];
                }
            }
            let shell = Face {
                name: format!("{name}.{}", face.name()),
                group: group(b.face_group(face)),
                origin,
                u_axis,
                v_axis,
                normal,
                shape: FaceShape::Rectangle {
                    size,
                    holes: holes.clone(),
                },
            };
            let filled: Vec<Face> = holes
                .iter()
                .zip(&fills)
                .enumerate()
                .filter_map(|(k, (h, fill))| {
                    fill.map(|g| {
                        filled_hole(
                            format!("{name}.{}.opening[{k}]", face.name()),
                            group(g),
                            &shell,
                            *h,
                        )
                    })
                })
                .collect();
            faces.push(shell);
            faces.extend(filled);
        }
    }
    for (i, p) in description.polygons.iter().enumerate() {
        let name = p.name.clone().unwrap_or_else(|| format!("polygon[{i}]"));
        let (origin, u_axis, v_axis, normal, points) =
            polygon_frame(&p.vertices).map_err(|problem| {
                RoomError::invalid(format!("room.polygon[{i}].vertices"), problem)
            })?;
        faces.push(Face {
            name,
            group: group(&p.group),
            origin,
            u_axis,
            v_axis,
            normal,
            shape: FaceShape::Polygon { points },
        });
    }
    Ok(faces)
}

/// The rectangle filling hole `h = [u0, v0, u1, v1]` of `parent`.
fn filled_hole(name: String, group: u32, parent: &Face, h: [f32; 4]) -> Face {
    Face {
        name,
        group,
        origin: parent.point(h[0], h[1]),
        u_axis: parent.u_axis,
        v_axis: parent.v_axis,
        normal: parent.normal,
        shape: FaceShape::Rectangle {
            size: [h[2] - h[0], h[3] - h[1]],
            holes: Vec::new(),
        },
    }
}

/// The frame of a planar polygon: origin (its first vertex), unit axes `u` (along the first
/// edge) and `v`, front normal `u x v` (Newell's normal, so the given winding is
/// counter-clockwise seen from the front), and the vertices in `(u, v)` metres. Refuses
/// polygons out of plane by more than 1 mm plus 1e-4 of their size, with no area, or whose edges
/// cross.
pub(crate) fn polygon_frame(
    vertices: &[[f32; 3]],
) -> Result<(Vec3, Vec3, Vec3, Vec3, Vec<Vec2>), String> {
    let p: Vec<Vec3> = vertices.iter().map(|&v| Vec3::from(v)).collect();
    let n = p.len();
    // Newell's method: robust for any simple planar polygon.
    let mut newell = Vec3::ZERO;
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        newell += Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let extent = p
        .iter()
        .map(|&q| (q - p[0]).length())
        .fold(0.0f32, f32::max);
    if newell.length() < 1e-6 * extent.max(1e-3).powi(2) || extent < 1e-3 {
        return Err("has no area".into());
    }
    let normal = newell.normalize();
    let tolerance = 1e-3 + 1e-4 * extent;
    if let Some(k) = p
        .iter()
        .position(|&q| (q - p[0]).dot(normal).abs() > tolerance)
    {
        return Err(format!(
            "vertex {k} lies {:.4} m off the polygon's plane (tolerance {tolerance:.4} m)",
            (p[k] - p[0]).dot(normal).abs()
        ));
    }
    let first_edge = (1..n)
        .map(|i| p[i] - p[0])
        .find(|e| e.cross(normal).length() > 1e-4)
        .ok_or("has no area")?;
    let u_axis = (first_edge - normal * first_edge.dot(normal)).normalize();
    let v_axis = normal.cross(u_axis);
    let points: Vec<Vec2> = p
        .iter()
        .map(|&q| Vec2::new((q - p[0]).dot(u_axis), (q - p[0]).dot(v_axis)))
        .collect();
    if signed_area(&points) <= 1e-6 {
        return Err("has no area".into());
    }
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if !adjacent
                && segments_cross(
                    points[i],
                    points[(i + 1) % n],
                    points[j],
                    points[(j + 1) % n],
                )
            {
                return Err(format!(
                    "edges {i} and {j} cross (the polygon is not simple)"
                ));
            }
        }
    }
    Ok((p[0], u_axis, v_axis, normal, points))
}

/// Whether segments `ab` and `cd` intersect (touching counts).
fn segments_cross(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let orient = |p: Vec2, q: Vec2, r: Vec2| (q - p).perp_dot(r - p);
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: Vec2, q: Vec2, r: Vec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}
