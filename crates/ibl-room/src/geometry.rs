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
use ibl_scene::polygon::{polygon_frame, signed_area};

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
