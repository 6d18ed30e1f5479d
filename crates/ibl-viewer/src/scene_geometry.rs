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
    /// Its distinct vertex positions at load (the point lights' shadow cones hold them all:
    /// `point_lights::shadow_cone`).
    pub points: Vec<Vec3>,
    /// Global material indices this object uses.
    pub materials: Range<u32>,
}

/// How an object's triangles bound a volume.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Closure {
    /// Not closed (or not known to be): some edge is not shared by exactly two triangles that
    /// run along it in opposite directions, or parts wind opposite ways.
    Open,
    /// Closed, each triangle counter-clockwise seen from outside (its right-hand normal points
    /// out: every connected part has a positive signed volume).
    Outward,
    /// Closed, each triangle clockwise seen from outside (every part's volume negative).
    Inward,
}

impl Closure {
    /// +1 for [`Closure::Outward`], -1 for [`Closure::Inward`], `None` when open.
    pub fn sign(self) -> Option<f32> {
        match self {
            Closure::Open => None,
            Closure::Outward => Some(1.0),
            Closure::Inward => Some(-1.0),
        }
    }

    /// The closure of `vertices` (three per triangle), their corners joined where positions are
    /// equal bit for bit. Closed when every directed edge of a triangle (corner order) meets
    /// its reverse in exactly one other triangle and no edge twice: then a ray from outside the
    /// volume enters it first through a triangle whose front (right-hand) side faces the ray's
    /// origin, when every connected part winds the same way (each part's signed volume, the sum
    /// of `a . (b x c) / 6` over its triangles, has the same sign and is not zero). Triangles
    /// with two equal corners are left out (they cover nothing). O(n) expected.
    pub fn of(vertices: &[Vertex]) -> Closure {
        let mut id_of: HashMap<[u32; 3], u32> = HashMap::with_capacity(vertices.len() / 4);
        let mut ids = Vec::with_capacity(vertices.len());
        for v in vertices {
            let next = id_of.len() as u32;
            ids.push(*id_of.entry(bytemuck::cast(v.position)).or_insert(next));
        }
        let triangles: Vec<[u32; 3]> = ids
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
            .collect();
        if triangles.is_empty() {
            return Closure::Open;
        }
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
        for t in &triangles {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        let closed = edges
            .iter()
            .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1));
        if !closed {
            return Closure::Open;
        }
        // Connected parts (union-find over the corners), and each part's signed volume.
        let mut parent: Vec<u32> = (0..id_of.len() as u32).collect();
        fn root(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let up = parent[parent[i as usize] as usize];
                parent[i as usize] = up;
                i = up;
            }
            i
        }
        for t in &triangles {
            let a = root(&mut parent, t[0]);
            for &c in &t[1..] {
                let b = root(&mut parent, c);
                parent[b as usize] = a;
            }
        }
        let mut position = vec![Vec3::ZERO; id_of.len()];
        for (v, &id) in vertices.iter().zip(&ids) {
            position[id as usize] = Vec3::from(v.position);
        }
        let mut volume: HashMap<u32, f64> = HashMap::new();
        for t in &triangles {
            let [a, b, c] = t.map(|i| position[i as usize].as_dvec3());
            *volume.entry(root(&mut parent, t[0])).or_insert(0.0) += a.dot(b.cross(c)) / 6.0;
        }
        if volume.values().all(|&v| v > 0.0) {
            Closure::Outward
        } else if volume.values().all(|&v| v < 0.0) {
            Closure::Inward
        } else {
            Closure::Open
        }
    }
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

/// The box of `vertices`' positions, `(min, max)` (infinite and empty for no vertices).
pub(crate) fn bounds_of(vertices: &[Vertex]) -> (Vec3, Vec3) {
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
    let mut seen = std::collections::HashSet::with_capacity(vertices.len() / 4);
    let points = vertices
        .iter()
        .filter(|v| seen.insert(bytemuck::cast::<[f32; 3], [u32; 3]>(v.position)))
        .map(|v| Vec3::from(v.position))
        .collect();
    ObjectGeometry {
        name,
        bounds: bounds_of(&vertices),
        points,
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

    /// The unit cube about `centre` as triangles wound counter-clockwise seen from outside
    /// (normals and materials vary per face, as a mesh's split vertices do), less the faces
    /// in `missing` (0 to 5).
    fn cube(centre: Vec3, missing: &[usize]) -> Vec<Vertex> {
        let mut out = Vec::new();
        for face in 0..6 {
            if missing.contains(&face) {
                continue;
            }
            let axis = face / 2;
            let sign = if face % 2 == 0 { 1.0 } else { -1.0 };
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let (mut u, mut v) = (Vec3::ZERO, Vec3::ZERO);
            u[(axis + 1) % 3] = 0.5;
            v[(axis + 2) % 3] = 0.5;
            let c = centre + 0.5 * n;
            let mut quad = [c - u - v, c + u - v, c + u + v, c - u + v];
            if (quad[1] - quad[0]).cross(quad[2] - quad[0]).dot(n) < 0.0 {
                quad.reverse();
            }
            for k in [0, 1, 2, 0, 2, 3] {
                out.push(Vertex {
                    position: quad[k].to_array(),
                    normal: n.to_array(),
                    material: face as u32,
                });
            }
        }
        out
    }

    fn reversed(vertices: &[Vertex]) -> Vec<Vertex> {
        vertices
            .chunks_exact(3)
            .flat_map(|t| [t[0], t[2], t[1]])
            .collect()
    }

    #[test]
    fn a_closed_mesh_is_told_from_an_open_one_and_its_winding_found() {
        let outward = cube(Vec3::new(3.0, -2.0, 7.0), &[]);
        assert_eq!(Closure::of(&outward), Closure::Outward);
        assert_eq!(Closure::of(&reversed(&outward)), Closure::Inward);
        assert_eq!(
            Closure::of(&cube(Vec3::ZERO, &[4])),
            Closure::Open,
            "a face missing"
        );
        // One triangle flipped: its edges run the same way as their neighbours'.
        let mut flipped = outward.clone();
        flipped.swap(1, 2);
        assert_eq!(Closure::of(&flipped), Closure::Open);
        // A face doubled: its edges are shared by three triangles.
        let mut doubled = outward.clone();
        doubled.extend_from_slice(&outward[..6]);
        assert_eq!(Closure::of(&doubled), Closure::Open);
        // Two closed parts that wind the same way, and two that do not.
        let mut two = outward.clone();
        two.extend(cube(Vec3::new(-5.0, 0.0, 0.0), &[]));
        assert_eq!(Closure::of(&two), Closure::Outward);
        let mut mixed = outward.clone();
        mixed.extend(reversed(&cube(Vec3::new(-5.0, 0.0, 0.0), &[])));
        assert_eq!(Closure::of(&mixed), Closure::Open);
        // A degenerate triangle (two equal corners) covers nothing and changes nothing.
        let mut sliver = outward.clone();
        sliver.extend([outward[0], outward[0], outward[1]]);
        assert_eq!(Closure::of(&sliver), Closure::Outward);
        assert_eq!(Closure::of(&[]), Closure::Open);
        assert_eq!(Closure::Outward.sign(), Some(1.0));
        assert_eq!(Closure::Open.sign(), None);
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
