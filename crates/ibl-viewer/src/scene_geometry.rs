//! The scene's triangles as the rasteriser draws them, taken from the assembled
//! `ibl_scene::Scene` (so the viewer draws exactly the geometry, normals and materials the CPU
//! renderer traces, placed by the same code): real geometry merged into one vertex list, every
//! virtual object a list of its own so that it can move. Positions and normals are in the world
//! frame of the loaded scene; a moved object is drawn through `world_from_load`, its transform
//! relative to where the file put it.
//!
//! Each object keeps a BVH of its triangles (in the load frame) for picking with the mouse.

use std::collections::HashMap;
use std::ops::Range;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use ibl_scene::{Bvh, GeometryLayer, Material, Scene};

/// One vertex: world position and unit normal at load, and a global material index.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    /// Position, load frame.
    pub position: [f32; 3],
    /// Unit normal (the vertex normal of a smooth mesh, the face normal of a flat one).
    pub normal: [f32; 3],
    /// Index into [`SceneGeometry::materials`].
    pub material: u32,
}

/// The vertex layout of [`Vertex`] for pipelines.
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32];

/// Triangles of one object (three vertices each).
#[derive(Clone, Debug)]
pub struct ObjectGeometry {
    /// Name from the scene file.
    pub name: String,
    /// Three vertices per triangle.
    pub vertices: Vec<Vertex>,
    /// The triangles for picking (load frame).
    pub bvh: Bvh,
    /// Axis-aligned bounds at load, `(min, max)`.
    pub bounds: (Vec3, Vec3),
    /// Global material indices this object uses.
    pub materials: Range<u32>,
}

/// Everything the viewer draws.
#[derive(Clone, Debug)]
pub struct SceneGeometry {
    /// The real (local) geometry, merged.
    pub real: ObjectGeometry,
    /// The virtual objects, in file order.
    pub objects: Vec<ObjectGeometry>,
    /// Real materials, then every virtual object's.
    pub materials: Vec<Material>,
}

fn bounds_of(vertices: &[Vertex]) -> (Vec3, Vec3) {
    vertices.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), v| {
            let p = Vec3::from(v.position);
            (lo.min(p), hi.max(p))
        },
    )
}

/// Per object of `layer`: its vertices (materials offset by `material_base`).
fn layer_objects(layer: &GeometryLayer, material_base: u32) -> Vec<Vec<Vertex>> {
    let corners = layer.bvh.triangles();
    let mut objects = vec![Vec::new(); layer.object_names.len()];
    for (tri, surface) in corners.iter().zip(&layer.surfaces) {
        let out: &mut Vec<Vertex> = &mut objects[surface.object as usize];
        for (corner, normal) in tri.iter().zip(&surface.normals) {
            out.push(Vertex {
                position: corner.to_array(),
                normal: normal.to_array(),
                material: material_base + surface.material,
            });
        }
    }
    objects
}

fn object(name: String, vertices: Vec<Vertex>) -> ObjectGeometry {
    let corners: Vec<[Vec3; 3]> = vertices
        .chunks_exact(3)
        .map(|t| {
            [
                Vec3::from(t[0].position),
                Vec3::from(t[1].position),
                Vec3::from(t[2].position),
            ]
        })
        .collect();
    let (lo, hi) = vertices.iter().fold((u32::MAX, 0u32), |(lo, hi), v| {
        (lo.min(v.material), hi.max(v.material))
    });
    ObjectGeometry {
        name,
        bounds: bounds_of(&vertices),
        bvh: Bvh::new(&corners),
        materials: if vertices.is_empty() {
            0..0
        } else {
            lo..hi + 1
        },
        vertices,
    }
}

/// The triangles of `vertices` (three per triangle) as shared vertices and indices into them:
/// equal vertices (bit for bit: position, normal and material) kept once, in order of first use.
/// A rasteriser transforms a kept vertex once per draw where it can reuse it (lavapipe's vertex
/// cache): a list of three vertices per triangle transforms every corner, about six per vertex
/// of a smooth mesh, in every shadow-map tile it is drawn into. O(n) expected.
pub fn shared_vertices(vertices: &[Vertex]) -> (Vec<Vertex>, Vec<u32>) {
    let mut index_of: HashMap<[u32; 7], u32> = HashMap::with_capacity(vertices.len() / 4);
    let mut kept = Vec::new();
    let indices = vertices
        .iter()
        .map(|v| {
            *index_of.entry(bytemuck::cast(*v)).or_insert_with(|| {
                kept.push(*v);
                kept.len() as u32 - 1
            })
        })
        .collect();
    (kept, indices)
}

impl SceneGeometry {
    /// The geometry of a loaded scene. O(T log T) for T triangles (the picking BVHs).
    pub fn from_scene(scene: &Scene) -> SceneGeometry {
        let real_count = scene.real.materials.len() as u32;
        let real: Vec<Vertex> = layer_objects(&scene.real, 0).concat();
        let objects = layer_objects(&scene.virtual_objects, real_count)
            .into_iter()
            .zip(&scene.virtual_objects.object_names)
            .map(|(vertices, name)| object(name.clone(), vertices))
            .collect();
        let mut materials = scene.real.materials.clone();
        materials.extend(&scene.virtual_objects.materials);
        SceneGeometry {
            real: object("real geometry".into(), real),
            objects,
            materials,
        }
    }

    /// The plane of the real geometry when every real triangle lies in one plane (the ground of
    /// most AR scenes): `(n, d)` with `n . p + d = 0` on it, `n` a unit vector; `None` when the
    /// real geometry is empty or not flat (within 1e-5 of its extent). A flat real layer
    /// cannot shadow a point on the side of the plane that a light shines from: the scene pass
    /// skips its real shadow look-up there (`shadow_lookup.wgsl`).
    pub fn real_plane(&self) -> Option<(Vec3, f32)> {
        let v = &self.real.vertices;
        let (lo, hi) = self.real_bounds()?;
        let tolerance = 1e-5 * (hi - lo).length().max(1e-6);
        let corner = |k: usize| Vec3::from(v[k].position);
        // The normal of the largest triangle (the best conditioned).
        let normal = (0..v.len() / 3)
            .map(|t| (corner(3 * t + 1) - corner(3 * t)).cross(corner(3 * t + 2) - corner(3 * t)))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))?
            .try_normalize()?;
        let d = -normal.dot(corner(0));
        v.iter()
            .all(|x| (normal.dot(Vec3::from(x.position)) + d).abs() <= tolerance)
            .then_some((normal, d))
    }

    /// Bounds of the real geometry at load; `None` when there is none.
    pub fn real_bounds(&self) -> Option<(Vec3, Vec3)> {
        (!self.real.vertices.is_empty()).then_some(self.real.bounds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry(corners: &[[f32; 3]]) -> SceneGeometry {
        let vertices = corners
            .iter()
            .map(|&position| Vertex {
                position,
                normal: [0.0, 1.0, 0.0],
                material: 0,
            })
            .collect();
        SceneGeometry {
            real: object("real".into(), vertices),
            objects: Vec::new(),
            materials: Vec::new(),
        }
    }

    #[test]
    fn shared_vertices_give_back_every_triangle() {
        // Two triangles sharing an edge, a third on the first's corners with another normal and
        // a fourth on them in another material: 12 corners, 10 distinct vertices.
        let (a, b, c, d) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]);
        let (up, tilted) = ([0.0, 1.0, 0.0], [0.0, 0.6, 0.8]);
        let triangles = [
            ([a, b, c], up, 0),
            ([b, d, c], up, 0),
            ([a, b, c], tilted, 0),
            ([a, b, c], up, 1),
        ];
        let corners: Vec<Vertex> = triangles
            .iter()
            .flat_map(|&(positions, normal, material)| {
                positions.map(|position| Vertex {
                    position,
                    normal,
                    material,
                })
            })
            .collect();
        let (kept, indices) = shared_vertices(&corners);
        assert_eq!(kept.len(), 10);
        assert_eq!(indices.len(), corners.len());
        let rebuilt: Vec<Vertex> = indices.iter().map(|&i| kept[i as usize]).collect();
        assert_eq!(rebuilt, corners);
        assert_eq!(shared_vertices(&[]), (Vec::new(), Vec::new()));
    }

    #[test]
    fn a_ground_of_two_triangles_is_flat_and_a_bent_one_is_not() {
        let (a, b, c, d) = (
            [-20.0, -1.0, -20.0],
            [20.0, -1.0, -20.0],
            [20.0, -1.0, 20.0],
            [-20.0, -1.0, 20.0],
        );
        let (n, offset) = geometry(&[a, b, c, a, c, d]).real_plane().unwrap();
        assert!((n.y.abs() - 1.0).abs() < 1e-6 && n.x.abs() < 1e-6 && n.z.abs() < 1e-6);
        // n . p + d = 0 at y = -1.
        assert!((offset - n.y).abs() < 1e-5);
        // One corner lifted by 1 mm over a 57 m diagonal is more than 1e-5 of the extent.
        let lifted = [20.0, -0.999, 20.0];
        assert!(
            geometry(&[a, b, lifted, a, lifted, d])
                .real_plane()
                .is_none()
        );
        assert!(geometry(&[]).real_plane().is_none());
    }
}
