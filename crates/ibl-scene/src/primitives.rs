//! Analytic shapes as triangle meshes, in their model frame: rectangles, boxes and spheres.
//!
//! Planes and boxes are exact (2 and 12 triangles). Spheres are subdivided icosahedra with the
//! vertices on the sphere and smooth normals `(p - c) / r`; `subdivisions = 5` gives 20480
//! triangles, whose flat facets deviate from the sphere by `r (1 - cos(a/2))`, about `1.5e-4 r`
//! for the edge angle `a` of 0.035 rad: below a pixel for any render where the sphere is under
//! about 5000 pixels across.

use glam::Vec3;
use std::collections::HashMap;

use crate::TriangleMesh;

/// An orthonormal pair of tangents for a unit normal (branchless, Duff et al. 2017).
pub fn tangents(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

fn single_material(
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
) -> TriangleMesh {
    let material_slots = vec![0; triangles.len()];
    TriangleMesh {
        positions,
        normals,
        triangles,
        material_slots,
        material_names: vec!["default".into()],
    }
}

/// A `size[0] x size[1]` rectangle centred on `center`, front side facing `normal`.
pub fn plane(center: Vec3, normal: Vec3, size: [f32; 2]) -> TriangleMesh {
    let n = normal.normalize();
    let (t, b) = tangents(n);
    let (ht, hb) = (t * 0.5 * size[0], b * 0.5 * size[1]);
    let positions = vec![
        center - ht - hb,
        center + ht - hb,
        center + ht + hb,
        center - ht + hb,
    ];
    // Counter-clockwise seen from the normal's side.
    let ccw = (positions[1] - positions[0])
        .cross(positions[2] - positions[0])
        .dot(n)
        > 0.0;
    let triangles = if ccw {
        vec![[0, 1, 2], [0, 2, 3]]
    } else {
        vec![[0, 2, 1], [0, 3, 2]]
    };
    single_material(positions, vec![n; 4], triangles)
}

/// An axis-aligned box from `min` to `max`, faces pointing out, flat normals (24 vertices).
pub fn cuboid(min: Vec3, max: Vec3) -> TriangleMesh {
    let centre = 0.5 * (min + max);
    let half = 0.5 * (max - min);
    let mut positions = Vec::with_capacity(24);
    let mut normals = Vec::with_capacity(24);
    let mut triangles = Vec::with_capacity(12);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = positions.len() as u32;
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut p = centre + n * half[axis];
                p[u] += su * half[u];
                p[v] += sv * half[v];
                positions.push(p);
                normals.push(n);
            }
            // (u, v, axis) is a right-handed cyclic triple, so u x v = +axis.
            if sign > 0.0 {
                triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
            } else {
                triangles.extend([[base, base + 2, base + 1], [base, base + 3, base + 2]]);
            }
        }
    }
    single_material(positions, normals, triangles)
}

/// A sphere of `radius` about `center`: an icosahedron subdivided `subdivisions` times
/// (`20 * 4^s` triangles), smooth normals.
pub fn sphere(center: Vec3, radius: f32, subdivisions: u32) -> TriangleMesh {
    let g = (1.0 + 5f32.sqrt()) / 2.0;
    let mut dirs: Vec<Vec3> = [
        (-1.0, g, 0.0),
        (1.0, g, 0.0),
        (-1.0, -g, 0.0),
        (1.0, -g, 0.0),
        (0.0, -1.0, g),
        (0.0, 1.0, g),
        (0.0, -1.0, -g),
        (0.0, 1.0, -g),
        (g, 0.0, -1.0),
        (g, 0.0, 1.0),
        (-g, 0.0, -1.0),
        (-g, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, dirs: &mut Vec<Vec3>| -> u32 {
            let key = (a.min(b), a.max(b));
            *midpoints.entry(key).or_insert_with(|| {
                dirs.push((dirs[a as usize] + dirs[b as usize]).normalize());
                dirs.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut dirs);
            let bc = midpoint(b, c, &mut dirs);
            let ca = midpoint(c, a, &mut dirs);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    let positions = dirs.iter().map(|&d| center + d * radius).collect();
    single_material(positions, dirs, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::triangle_area;

    fn outward(mesh: &TriangleMesh, centre: Vec3) -> bool {
        (0..mesh.triangle_count()).all(|i| {
            let [a, b, c] = mesh.corners(i);
            (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > 0.0
        })
    }

    #[test]
    fn plane_faces_its_normal_and_has_its_area() {
        for n in [
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::new(0.3, 0.4, -0.8).normalize(),
            Vec3::Z,
            Vec3::NEG_Z,
        ] {
            let m = plane(Vec3::new(1.0, 2.0, 3.0), n, [2.0, 3.0]);
            let area: f32 = (0..2).map(|i| triangle_area(m.corners(i))).sum();
            assert!((area - 6.0).abs() < 1e-4);
            let [a, b, c] = m.corners(0);
            assert!((b - a).cross(c - a).dot(n) > 0.0);
        }
    }

    #[test]
    fn box_and_sphere_face_out() {
        let b = cuboid(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(1.0, 3.0, 2.0));
        assert_eq!(b.triangle_count(), 12);
        assert!(outward(&b, Vec3::new(0.0, 1.5, 0.0)));
        let area: f32 = (0..12).map(|i| triangle_area(b.corners(i))).sum();
        assert!((area - 2.0 * (2.0 * 3.0 + 2.0 * 4.0 + 3.0 * 4.0)).abs() < 1e-3);
        let s = sphere(Vec3::ONE, 2.0, 3);
        assert_eq!(s.triangle_count(), 20 * 64);
        assert!(outward(&s, Vec3::ONE));
        let area: f32 = (0..s.triangle_count())
            .map(|i| triangle_area(s.corners(i)))
            .sum();
        let exact = 4.0 * std::f32::consts::PI * 4.0;
        assert!(area < exact && area > 0.99 * exact);
    }
}
