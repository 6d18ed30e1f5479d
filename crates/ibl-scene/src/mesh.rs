//! Indexed triangle meshes with per-vertex normals and per-triangle material slots, in the frame
//! of whoever holds them (a model's own frame when loaded, the world frame once placed).
//!
//! A mesh is plain data: the loaders (`ibl-io::mesh_file`) fill it, [`TriangleMesh::transformed`]
//! places it in the world, [`TriangleMesh::validate`] refuses what would break rendering (indices
//! out of range, non-finite positions, no usable triangle), and the accelerator takes its triangles.

use glam::{Affine3A, Vec3};

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, one per position, or empty for flat (geometric) normals.
    pub normals: Vec<Vec3>,
    /// Vertex indices, three per triangle, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, an index into [`TriangleMesh::material_names`].
    pub material_slots: Vec<u32>,
    /// Names of the material groups (glTF material or OBJ `usemtl` names; `"default"` when the file
    /// has none).
    pub material_names: Vec<String>,
}

/// Why a mesh cannot be rendered.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// The mesh has no triangle of non-zero area.
    #[error("the mesh has no triangle of non-zero area ({triangles} triangles, all degenerate)")]
    NoArea {
        /// How many triangles there were.
        triangles: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are {vertices} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The bad index.
        index: u32,
        /// How many vertices there are.
        vertices: usize,
    },
    /// A position or normal is NaN or infinite.
    #[error("vertex {vertex} has a non-finite {what}")]
    NonFinite {
        /// The vertex.
        vertex: usize,
        /// `"position"` or `"normal"`.
        what: &'static str,
    },
    /// Array lengths disagree.
    #[error("{what}")]
    Inconsistent {
        /// What disagrees.
        what: String,
    },
}

impl MeshError {
    /// Always true: the mesh comes from a file or a caller.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

impl TriangleMesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner positions of triangle `i`.
    pub fn corners(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[i];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Checks indices, finiteness and array lengths, then drops zero-area triangles (which a
    /// renderer can never hit) and reports how many were dropped. Fails if nothing is left.
    pub fn validate(&mut self) -> Result<usize, MeshError> {
        let vertices = self.positions.len();
        if !self.normals.is_empty() && self.normals.len() != vertices {
            return Err(MeshError::Inconsistent {
                what: format!("{} normals for {} positions", self.normals.len(), vertices),
            });
        }
        if self.material_slots.len() != self.triangles.len() {
            return Err(MeshError::Inconsistent {
                what: format!(
                    "{} material slots for {} triangles",
                    self.material_slots.len(),
                    self.triangles.len()
                ),
            });
        }
        if let Some(&slot) = self
            .material_slots
            .iter()
            .find(|&&s| s as usize >= self.material_names.len())
        {
            return Err(MeshError::Inconsistent {
                what: format!(
                    "material slot {slot} but only {} material names",
                    self.material_names.len()
                ),
            });
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite {
                vertex: v,
                what: "position",
            });
        }
        if let Some(v) = self.normals.iter().position(|n| !n.is_finite()) {
            return Err(MeshError::NonFinite {
                vertex: v,
                what: "normal",
            });
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertices) {
                return Err(MeshError::IndexOutOfRange {
                    triangle: t,
                    index,
                    vertices,
                });
            }
        }
        let before = self.triangles.len();
        let keep: Vec<bool> = (0..before)
            .map(|i| triangle_area(self.corners(i)) > 0.0)
            .collect();
        let mut k = keep.iter();
        self.triangles.retain(|_| *k.next().unwrap_or(&false));
        let mut k = keep.iter();
        self.material_slots.retain(|_| *k.next().unwrap_or(&false));
        if self.triangles.is_empty() {
            return Err(MeshError::NoArea { triangles: before });
        }
        Ok(before - self.triangles.len())
    }

    /// The mesh with every position mapped by `world_from_model` and every normal by its inverse
    /// transpose (renormalised), so non-uniform scales keep normals perpendicular. A transform with
    /// a negative determinant (a mirror) also reverses the winding, so fronts stay fronts.
    pub fn transformed(&self, world_from_model: Affine3A) -> TriangleMesh {
        let normal_matrix = world_from_model.matrix3.inverse().transpose();
        let mirrored = world_from_model.matrix3.determinant() < 0.0;
        TriangleMesh {
            positions: self
                .positions
                .iter()
                .map(|&p| world_from_model.transform_point3(p))
                .collect(),
            normals: self
                .normals
                .iter()
                .map(|&n| Vec3::from(normal_matrix * glam::Vec3A::from(n)).normalize_or_zero())
                .collect(),
            triangles: if mirrored {
                self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect()
            } else {
                self.triangles.clone()
            },
            material_slots: self.material_slots.clone(),
            material_names: self.material_names.clone(),
        }
    }

    /// Axis-aligned bounds `(min, max)` of the positions; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }
}

/// Area of a triangle, in squared length units.
pub fn triangle_area([a, b, c]: [Vec3; 3]) -> f32 {
    0.5 * (b - a).cross(c - a).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriangleMesh {
        TriangleMesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, -1.0),
            ],
            normals: vec![Vec3::Y; 4],
            triangles: vec![[0, 1, 2], [0, 2, 3], [0, 0, 1]],
            material_slots: vec![0, 0, 0],
            material_names: vec!["default".into()],
        }
    }

    #[test]
    fn validate_drops_degenerate_triangles() {
        let mut m = quad();
        assert_eq!(m.validate(), Ok(1));
        assert_eq!(m.triangle_count(), 2);
        assert_eq!(m.material_slots.len(), 2);
    }

    #[test]
    fn validate_refuses_bad_meshes() {
        let mut m = quad();
        m.triangles[0] = [0, 1, 9];
        assert!(matches!(
            m.validate(),
            Err(MeshError::IndexOutOfRange { index: 9, .. })
        ));
        let mut m = quad();
        m.positions[2].x = f32::NAN;
        assert!(matches!(
            m.validate(),
            Err(MeshError::NonFinite { vertex: 2, .. })
        ));
        let mut m = quad();
        m.triangles = vec![[0, 0, 1]];
        m.material_slots = vec![0];
        assert!(matches!(
            m.validate(),
            Err(MeshError::NoArea { triangles: 1 })
        ));
    }

    #[test]
    fn mirror_transform_keeps_fronts() {
        let m = quad();
        let t = m.transformed(Affine3A::from_scale(Vec3::new(1.0, -2.0, 1.0)));
        assert_eq!(t.triangles[0], [0, 2, 1]);
        assert!((t.normals[0] - Vec3::NEG_Y).length() < 1e-6);
        assert!((t.positions[2] - Vec3::new(1.0, 0.0, -1.0)).length() < 1e-6);
    }
}
