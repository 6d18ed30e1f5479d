//! Coarser copies of a virtual object for the shadow maps (levels of detail). A shadow map
//! holds one depth per texel, and a point light's 256-texel cube face sees a 0.5 m object 2 m
//! away across about 30 texels: the bunny's 5,648 triangles, a few texels' worth each, cost
//! lavapipe their vertices and set-up in every face and tile they are drawn into (BENCHMARKS.md,
//! "Viewer", round 7). So each object keeps copies simplified by meshoptimizer's quadric
//! simplifier (Garland and Heckbert 1997, through the `meshopt` crate) to a few deviations,
//! and each shadow draw takes the coarsest copy whose deviation is at most [`LOD_TEXELS`] (half)
//! of that map's texel at the object. The deviation is meshoptimizer's estimate, not a bound:
//! on a finely tessellated sphere the copies' faces stray up to 1.5 times it (the unit test
//! checks 2 times), so a copy stays within three quarters of a texel, under the look-up's
//! smallest depth bias and normal offset (1 and 1.5 texels, `shadow_lookup.wgsl`): the
//! object's shadow on itself does not change, and its shadow on others moves by less than a
//! texel. The copies share the
//! object's vertex buffer (index lists only); the full mesh is level 0.

use crate::scene_geometry::{Closure, Vertex, bounds_of};

/// How far a copy's surface may lie from the object's by meshoptimizer's estimate, in texels of
/// the shadow map it is drawn into at the object: at most 0.75 texels in fact (module notes).
pub const LOD_TEXELS: f32 = 0.5;

/// The deviations asked of the copies, as fractions of the object's bounding-box diagonal
/// (a 0.5 m object: 1, 2.5, 5, 10 and 25 mm). A copy is kept only when it has at most two
/// thirds of the previous level's triangles.
const LEVEL_DEVIATIONS: [f32; 5] = [0.002, 0.005, 0.01, 0.02, 0.05];

/// One level of an object's triangles for the shadow passes.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowLod {
    /// Three indices per triangle into the object's shared vertices
    /// (`scene_geometry::shared_vertices`).
    pub indices: Vec<u32>,
    /// meshoptimizer's bound on how far the copy's surface lies from the object's, load-frame
    /// units (0 for the full mesh).
    pub deviation: f32,
    /// Whether the copy closes a volume (it is drawn with its away-facing triangles culled only
    /// then: `shadow_atlas.rs`).
    pub closure: Closure,
}

/// The levels of a mesh of shared `vertices` and `indices` (three per triangle), finest first:
/// the mesh itself, then its simplified copies. Positions only: vertices that differ only by
/// normal or material are joined first (meshoptimizer's shadow index buffer), so seams do not
/// hold the simplifier back. O(n log n).
pub fn shadow_lods(vertices: &[Vertex], indices: &[u32]) -> Vec<ShadowLod> {
    let corners = |indices: &[u32]| -> Vec<Vertex> {
        indices.iter().map(|&i| vertices[i as usize]).collect()
    };
    let mut levels = vec![ShadowLod {
        indices: indices.to_vec(),
        deviation: 0.0,
        closure: Closure::of(&corners(indices)),
    }];
    if indices.is_empty() {
        return levels;
    }
    let bytes: &[u8] = bytemuck::cast_slice(vertices);
    let Ok(adapter) = meshopt::VertexDataAdapter::new(bytes, std::mem::size_of::<Vertex>(), 0)
    else {
        return levels;
    };
    let positions = meshopt::generate_shadow_indices(indices, &adapter);
    let (lo, hi) = bounds_of(vertices);
    let diagonal = (hi - lo).length();
    for fraction in LEVEL_DEVIATIONS {
        let mut deviation = 0.0f32;
        let simplified = meshopt::simplify(
            &positions,
            &adapter,
            0,
            fraction * diagonal,
            meshopt::SimplifyOptions::ErrorAbsolute,
            Some(&mut deviation),
        );
        let previous = levels.last().map_or(0, |l| l.indices.len());
        if simplified.is_empty() || 3 * simplified.len() > 2 * previous {
            continue;
        }
        levels.push(ShadowLod {
            closure: Closure::of(&corners(&simplified)),
            indices: simplified,
            deviation,
        });
    }
    levels
}

/// The coarsest of levels with `deviations` (load-frame units, finest first) to draw into a
/// shadow map whose texels are `texel` world units wide at the object, placed with its largest
/// stretch `scale`: the last whose deviation is at most [`LOD_TEXELS`] texels.
pub fn level_for(deviations: impl IntoIterator<Item = f32>, texel: f32, scale: f32) -> usize {
    let allowed = LOD_TEXELS * texel;
    deviations
        .into_iter()
        .enumerate()
        .filter(|&(_, d)| d * scale <= allowed)
        .map(|(k, _)| k)
        .last()
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene_geometry::shared_vertices;
    use glam::Vec3;

    /// A unit sphere of `n` x 2n quads (closed, wound outwards), as triangles.
    fn sphere(n: usize) -> Vec<Vertex> {
        let point = |i: usize, j: usize| {
            let theta = std::f32::consts::PI * i as f32 / n as f32;
            let phi = std::f32::consts::TAU * (j % (2 * n)) as f32 / (2 * n) as f32;
            if i == 0 {
                return Vec3::Y;
            }
            if i == n {
                return -Vec3::Y;
            }
            Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            )
        };
        let mut out = Vec::new();
        let mut push = |a: Vec3, b: Vec3, c: Vec3| {
            if a == b || b == c || c == a {
                return;
            }
            let (a, c) = if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
                (c, a)
            } else {
                (a, c)
            };
            for p in [a, b, c] {
                out.push(Vertex {
                    position: p.to_array(),
                    normal: p.to_array(),
                    material: 0,
                });
            }
        };
        for i in 0..n {
            for j in 0..2 * n {
                let (a, b) = (point(i, j), point(i, j + 1));
                let (c, d) = (point(i + 1, j + 1), point(i + 1, j));
                push(a, b, c);
                push(a, c, d);
            }
        }
        out
    }

    #[test]
    fn each_level_is_coarser_and_stays_within_its_deviation() {
        let triangles = sphere(48);
        assert_eq!(Closure::of(&triangles), Closure::Outward);
        let (kept, indices) = shared_vertices(&triangles);
        let levels = shadow_lods(&kept, &indices);
        assert!(levels.len() >= 3, "{} levels", levels.len());
        assert_eq!(levels[0].indices, indices);
        assert_eq!(levels[0].deviation, 0.0);
        for pair in levels.windows(2) {
            assert!(3 * pair[1].indices.len() <= 2 * pair[0].indices.len());
            assert!(pair[1].deviation > pair[0].deviation);
        }
        // Every corner of a copy is a vertex of the sphere, and the copy's faces stay within
        // twice its estimated deviation of the sphere: a face's centre lies at most that far
        // further inside it than the full mesh's facets do (module notes).
        let corner = |i: u32| Vec3::from(kept[i as usize].position);
        let deepest = |level: &ShadowLod| {
            level
                .indices
                .chunks_exact(3)
                .map(|t| 1.0 - ((corner(t[0]) + corner(t[1]) + corner(t[2])) / 3.0).length())
                .fold(0.0f32, f32::max)
        };
        let sag = deepest(&levels[0]);
        for level in &levels {
            let inside = deepest(level);
            eprintln!(
                "{} triangles, deviation {:.4}, deepest face centre {inside:.4}",
                level.indices.len() / 3,
                level.deviation
            );
            assert!(
                inside <= 2.0 * level.deviation + sag,
                "{inside} > 2 x {}",
                level.deviation
            );
            assert_eq!(
                level.closure,
                Closure::Outward,
                "a sphere simplifies to a closed mesh"
            );
        }
    }

    #[test]
    fn the_coarsest_level_within_half_a_texel_is_drawn() {
        let deviations = [0.0, 0.001, 0.004, 0.01];
        assert_eq!(
            level_for(deviations, 1e-4, 1.0),
            0,
            "fine texels: the full mesh"
        );
        assert_eq!(level_for(deviations, 0.002, 1.0), 1);
        assert_eq!(level_for(deviations, 0.008, 1.0), 2);
        assert_eq!(level_for(deviations, 1.0, 1.0), 3);
        assert_eq!(
            level_for(deviations, 0.008, 4.0),
            1,
            "a larger object strays further"
        );
        assert_eq!(level_for([0.0], 1.0, 1.0), 0);
    }

    #[test]
    fn an_empty_mesh_has_its_one_empty_level() {
        let levels = shadow_lods(&[], &[]);
        assert_eq!(levels.len(), 1);
        assert!(levels[0].indices.is_empty());
    }
}
