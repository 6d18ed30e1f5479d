//! Where each light's virtual-object shadow map can hold a caster, and how near the light: a
//! coarse, conservative picture of the virtual atlas for the light culling (`light_tiles.wgsl`).
//!
//! Per light, a [`GRID`] x [`GRID`] grid over its virtual tile (tile coordinates x, y in
//! `[-1, 1]`, `light_space.rs`) holds in each cell the smallest depth, in world units from the
//! tile's near plane, that any caster drawn into the cell can have (`f32::MAX` where none can
//! be), with its min-pyramid above it (cells of 2, 4, ... 32 grid cells; level `k` has
//! `(GRID >> k)^2` cells). The casters are the virtual objects' triangles, bounded in clusters
//! by spheres ([`cluster_spheres`], found once at load): a cluster's sphere, moved with its
//! object, covers every texel its triangles are rasterised into, at depths no nearer than its
//! front. So a cell whose depth is at or beyond a receiver's depth holds no blocker of it.
//!
//! The culling used to test each screen tile's bounding sphere against the objects' bounding
//! sphere alone, which kept a light wherever the widest possible penumbra search around the whole
//! sphere reached: on bunny-sky (16 soft lights, 640 x 480) the real surfaces looped over 1.79 M
//! pixel-lights, and the blocker search found a caster for 0.34 M of them. Against the cells (and
//! the tile's normals: `light_tiles.wgsl`'s `faces`) they loop over 1.25 M (BENCHMARKS.md,
//! "Round 6").
//!
//! Cost: per light and cluster one projection and the cells it covers, then the pyramids, on the
//! CPU each frame the objects move or the lights change (bunny-patches, 32 lights: 1.1 ms a
//! frame), and 5.5 KiB a light uploaded.

use glam::{Affine3A, Vec2, Vec3};

use crate::light_space::{ShadowProjection, bounding_sphere};
use crate::scene_geometry::Vertex;

/// Cells across one light's grid at the finest level (`light_tiles.wgsl`'s `CASTER_GRID`).
pub const GRID: u32 = 32;
/// Levels of the pyramid: `GRID` down to 1 cell across (`CASTER_LEVELS`).
pub const LEVELS: u32 = GRID.trailing_zeros() + 1;
/// Cells per light, all levels (`CASTER_CELLS`): `(4^LEVELS - 1) / 3`.
pub const CELLS_PER_LIGHT: u32 = ((1 << (2 * LEVELS)) - 1) / 3;
/// A cell no caster can cover.
pub const EMPTY: f32 = f32::MAX;
/// Most clusters an object is bounded by: a grid of up to 12 x 12 x 12 cells over its bounds.
const CLUSTERS_PER_AXIS: usize = 12;
/// Triangles a cluster holds on average at least, where an object has few.
const TRIANGLES_PER_CLUSTER: usize = 4;

/// First cell of level `k` within a light's cells: the finer levels' cells before it.
pub fn level_offset(level: u32) -> u32 {
    ((1 << (2 * LEVELS)) - (1 << (2 * (LEVELS - level)))) / 3
}

/// Bounding spheres `(centre, radius)`, load frame, of clusters of an object's triangles
/// (`vertices`, three per triangle): the triangles are grouped by the cell of their centroid in
/// a grid of up to 12 x 12 x 12 cells over the object's bounds (fewer for small meshes, about
/// [`TRIANGLES_PER_CLUSTER`] triangles each), and each non-empty group is bounded by the sphere
/// around its corners' box. Every corner lies in its group's sphere. O(T).
pub fn cluster_spheres(vertices: &[Vertex]) -> Vec<(Vec3, f32)> {
    let triangles = vertices.len() / 3;
    if triangles == 0 {
        return Vec::new();
    }
    let point = |k: usize| Vec3::from(vertices[k].position);
    let (lo, hi) = (0..triangles * 3).fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), k| (lo.min(point(k)), hi.max(point(k))),
    );
    // Cells per axis so that the grid has about one cell per TRIANGLES_PER_CLUSTER triangles.
    let wanted = (triangles / TRIANGLES_PER_CLUSTER).max(1) as f64;
    let n = (wanted.cbrt().ceil() as usize).clamp(1, CLUSTERS_PER_AXIS);
    let size = (hi - lo).max(Vec3::splat(1e-12));
    let cell_of = |p: Vec3| {
        let c = ((p - lo) / size * n as f32).floor();
        let axis = |x: f32| (x.max(0.0) as usize).min(n - 1);
        (axis(c.z) * n + axis(c.y)) * n + axis(c.x)
    };
    let mut boxes = vec![(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); n * n * n];
    for t in 0..triangles {
        let corners = [point(3 * t), point(3 * t + 1), point(3 * t + 2)];
        let b = &mut boxes[cell_of((corners[0] + corners[1] + corners[2]) / 3.0)];
        for c in corners {
            b.0 = b.0.min(c);
            b.1 = b.1.max(c);
        }
    }
    boxes
        .into_iter()
        .filter(|(lo, hi)| lo.x <= hi.x)
        .map(|(lo, hi)| bounding_sphere(lo, hi))
        .collect()
}

/// The largest factor by which `m` stretches a length (the longest column of its linear part, an
/// upper bound for a rotation and scale; for a shear, the Frobenius norm bounds it).
fn stretch(m: &Affine3A) -> f32 {
    let a = m.matrix3;
    let columns = a
        .x_axis
        .length()
        .max(a.y_axis.length())
        .max(a.z_axis.length());
    let frobenius =
        (a.x_axis.length_squared() + a.y_axis.length_squared() + a.z_axis.length_squared()).sqrt();
    // Orthogonal columns (rotation and scale): the longest column is exact; otherwise bound.
    let orthogonal =
        a.x_axis.dot(a.y_axis).abs() + a.y_axis.dot(a.z_axis).abs() + a.z_axis.dot(a.x_axis).abs()
            <= 1e-5 * frobenius * frobenius;
    if orthogonal { columns } else { frobenius }
}

/// The cells of every light (`lights`: each light's virtual tile, its projection), light after
/// light, [`CELLS_PER_LIGHT`] each, from the clusters of each object (`objects`: the object's
/// world-from-load placement and its [`cluster_spheres`]).
pub fn caster_cells(
    lights: &[ShadowProjection],
    objects: &[(Affine3A, &[(Vec3, f32)])],
) -> Vec<f32> {
    let spheres: Vec<(Vec3, f32)> = objects
        .iter()
        .flat_map(|(m, clusters)| {
            let s = stretch(m);
            clusters
                .iter()
                .map(move |&(c, r)| (m.transform_point3(c), r * s))
        })
        .collect();
    let mut cells = vec![EMPTY; lights.len() * CELLS_PER_LIGHT as usize];
    for (light, out) in lights
        .iter()
        .zip(cells.chunks_exact_mut(CELLS_PER_LIGHT as usize))
    {
        let map = light.map_from_world;
        let half_extent = light.half_extent;
        let depth_range = light.depth_range;
        let n = GRID as f32;
        let cell = |x: f32| ((x + 1.0) * 0.5 * n).floor().clamp(0.0, n - 1.0) as usize;
        for &(centre, radius) in &spheres {
            let q = map.project_point3(centre);
            let r = radius / half_extent;
            let xy = Vec2::new(q.x, q.y);
            if (xy.abs() - Vec2::splat(r)).max_element() >= 1.0 {
                // Wholly outside the tile: never drawn into it.
                continue;
            }
            let front = q.z * depth_range - radius;
            let (x0, x1) = (cell(xy.x - r), cell(xy.x + r));
            let (y0, y1) = (cell(xy.y - r), cell(xy.y + r));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let c = &mut out[y * GRID as usize + x];
                    *c = c.min(front);
                }
            }
        }
        // The pyramid: each coarser cell the nearest of its four.
        for level in 1..LEVELS {
            let fine = (
                level_offset(level - 1) as usize,
                (GRID >> (level - 1)) as usize,
            );
            let coarse = (level_offset(level) as usize, (GRID >> level) as usize);
            for y in 0..coarse.1 {
                for x in 0..coarse.1 {
                    let at =
                        |dx: usize, dy: usize| out[fine.0 + (2 * y + dy) * fine.1 + 2 * x + dx];
                    out[coarse.0 + y * coarse.1 + x] =
                        at(0, 0).min(at(1, 0)).min(at(0, 1)).min(at(1, 1));
                }
            }
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(p: Vec3) -> Vertex {
        Vertex {
            position: p.to_array(),
            normal: [0.0, 1.0, 0.0],
            material: 0,
        }
    }

    #[test]
    fn the_levels_tile_a_lights_cells() {
        assert_eq!(LEVELS, 6);
        assert_eq!(CELLS_PER_LIGHT, 1365);
        assert_eq!(level_offset(0), 0);
        assert_eq!(level_offset(1), 1024);
        assert_eq!(level_offset(LEVELS - 1), CELLS_PER_LIGHT - 1);
        let source = include_str!("caster_cells.wgsl");
        assert!(source.contains(&format!("const CASTER_GRID: u32 = {GRID}u;")));
        assert!(source.contains(&format!("const CASTER_LEVELS: u32 = {LEVELS}u;")));
        assert!(source.contains(&format!("const CASTER_CELLS: u32 = {CELLS_PER_LIGHT}u;")));
    }

    #[test]
    fn every_corner_lies_in_its_clusters_sphere() {
        // A bumpy grid of 40 x 40 quads: clusters of about TRIANGLES_PER_CLUSTER triangles.
        let mut v = Vec::new();
        let h =
            |i: usize, j: usize| Vec3::new(i as f32, ((i * 7 + j * 3) % 5) as f32 * 0.1, j as f32);
        for i in 0..40 {
            for j in 0..40 {
                for p in [
                    h(i, j),
                    h(i + 1, j),
                    h(i, j + 1),
                    h(i + 1, j),
                    h(i + 1, j + 1),
                    h(i, j + 1),
                ] {
                    v.push(vertex(p));
                }
            }
        }
        let spheres = cluster_spheres(&v);
        assert!(
            spheres.len() > 20 && spheres.len() <= 512,
            "{}",
            spheres.len()
        );
        for t in v.chunks_exact(3) {
            let corners: Vec<Vec3> = t.iter().map(|x| Vec3::from(x.position)).collect();
            assert!(
                spheres
                    .iter()
                    .any(|&(c, r)| corners.iter().all(|&p| p.distance(c) <= r * (1.0 + 1e-6)))
            );
        }
        assert!(cluster_spheres(&[]).is_empty());
    }

    #[test]
    fn a_cell_holds_the_nearest_caster_that_can_cover_it() {
        // A light from straight above, its tile around the unit sphere at the origin; clusters
        // of radius 0.1 at (0.5, 0.2, 0) and (-0.5, 0.6, 0).
        let w = Vec3::Y;
        let light = ShadowProjection::around_sphere(w, Vec3::ZERO, 1.0, 1.0);
        let clusters = [
            (Vec3::new(0.5, 0.2, 0.0), 0.1),
            (Vec3::new(-0.5, 0.6, 0.0), 0.1),
        ];
        let cells = caster_cells(&[light], &[(Affine3A::IDENTITY, &clusters)]);
        assert_eq!(cells.len(), CELLS_PER_LIGHT as usize);
        // Depth from the tile's near plane (y = 1): 1 - 0.2 - 0.1 and 1 - 0.6 - 0.1.
        let nearest = cells.iter().copied().fold(EMPTY, f32::min);
        assert!((nearest - 0.3).abs() < 1e-5, "{nearest}");
        let top = cells[CELLS_PER_LIGHT as usize - 1];
        assert_eq!(top, nearest);
        let filled = cells[..(GRID * GRID) as usize]
            .iter()
            .filter(|&&c| c < EMPTY)
            .count();
        // Each sphere covers a square 0.2 / 2 of the tile across: 3 to 5 cells a side.
        assert!((2 * 9..=2 * 25).contains(&filled), "{filled}");
        // Every cell a sphere's projection covers is filled with a depth no deeper than its front.
        let p = light.project(Vec3::new(0.5, 0.2, 0.0));
        let cell = |x: f32| ((x + 1.0) * 0.5 * GRID as f32).floor() as usize;
        let c = cells[cell(p.y) * GRID as usize + cell(p.x)];
        assert!((c - 0.7).abs() < 1e-5, "{c}");
        // Moved with its object: scaled twice, the sphere's radius doubles.
        let m = Affine3A::from_scale(Vec3::splat(2.0));
        let moved = caster_cells(&[light], &[(m, &clusters[..1])]);
        let nearest = moved.iter().copied().fold(EMPTY, f32::min);
        assert!((nearest - (1.0 - 0.4 - 0.2)).abs() < 1e-5, "{nearest}");
    }
}
