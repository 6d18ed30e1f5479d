//! How much sky each surface point sees: the weighted-ambient value `c` of the paper and its
//! generalisation to a sky that is not uniform, both by ray casting.
//!
//! Jensen, Andersen & Madsen 2006 (section 4.1) weight each pixel's sky light by the "weighted
//! ambient environment map": the cosine-weighted fraction of the sky a surface point sees,
//!
//! ```text
//! c(x) = (1 / pi) integral V(x, w) max(0, n . w) dw        (V = 1 where w reaches the sky)
//! ```
//!
//! so that a uniform sky of radiance `P_a` gives the point the irradiance `pi c P_a`. A sky with
//! structure (a Preetham sky is several times brighter near the sun and the horizon than
//! elsewhere) gives instead `pi P_a c_shape(x)` with `c_shape(x) = (1 / pi) integral V max(0,
//! n.w) shape(w) dw`, which depends on where the sun is. Rather than casting rays again whenever
//! the sun moves, each point keeps its **transfer vector** (Sloan, Kautz & Snyder 2002,
//! precomputed radiance transfer), the SH projection of its cosine-weighted visibility:
//!
//! ```text
//! T_k(x) = (1 / pi) integral V(x, w) max(0, n . w) Y_k(w) dw,     c_shape(x) = sum_k s_k T_k(x)
//! ```
//!
//! (`s_k` the shape's SH coefficients, [`crate::SkyShape::sh`]); the sum is exact when the shape
//! is band-limited to the bands kept, and `c = 2 sqrt(pi) T_0` is the paper's value (the uniform
//! shape has `s_0 = 2 sqrt(pi)` only). Directions below the horizon are never sky.
//!
//! **Estimator.** `N` cosine-distributed rays per point (density `max(0, n.w) / pi`), stratified
//! on a `sqrt(N) x sqrt(N)` grid of the unit square with one jitter per cell, so
//! `T_k = (1/N) sum_{rays reaching the sky} Y_k(w)`. The standard error of `c` is at most that of
//! `N` independent Bernoulli trials, `sqrt(c (1 - c) / N)` (stratification only lowers it); it
//! is reported per point. Each point draws from its own PCG stream `(seed, index)`, so the result
//! does not depend on the thread count. Cost O(N log T) per point.

use glam::{DVec3, Vec3};
use ibl_core::Rgb;
use ibl_scene::{GeometryLayer, Ray, primitives::tangents};
use ibl_sh::{coefficient_count, eval_basis};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

use crate::OutdoorError;
use crate::sky::SkyShape;

/// A surface point: where it is and which way it faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// World position, metres.
    pub position: Vec3,
    /// Unit normal on the side that is seen.
    pub normal: Vec3,
}

/// Per point, the SH transfer vector of its cosine-weighted sky visibility.
#[derive(Clone, Debug, PartialEq)]
pub struct AmbientTransfer {
    bands: usize,
    rays: u32,
    /// `bands^2` values per point.
    coefficients: Vec<f32>,
}

/// How far a ray starts off its surface, as a fraction of the scene's extent.
const RAY_OFFSET: f32 = 1e-4;

/// The offset of secondary rays for `layer` (as the path tracer does: `1e-4` of the extent).
pub fn ray_offset(layer: &GeometryLayer) -> f32 {
    let extent = layer
        .bvh
        .bounds()
        .map_or(1.0, |(lo, hi)| lo.abs().max(hi.abs()).max_element());
    RAY_OFFSET * extent.max(1.0)
}

/// A cosine-distributed direction about `n` from the unit square.
pub fn cosine_direction(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let (t, b) = tangents(n);
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let z = (1.0 - u1).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

impl AmbientTransfer {
    /// Casts `rays` (rounded up to a square) cosine-distributed rays from every point into
    /// `layer`; `bands` SH bands (1 to 8). `seed` picks the jitter.
    pub fn compute(
        layer: &GeometryLayer,
        points: &[SurfacePoint],
        bands: usize,
        rays: u32,
        seed: u64,
    ) -> Result<AmbientTransfer, OutdoorError> {
        if !(1..=8).contains(&bands) {
            return Err(OutdoorError::Parameter(format!(
                "transfer SH bands must be 1 to 8; got {bands}"
            )));
        }
        if rays == 0 || rays > 1 << 20 {
            return Err(OutdoorError::Parameter(format!(
                "rays per point must be 1 to 2^20; got {rays}"
            )));
        }
        let side = (f64::from(rays).sqrt().ceil() as u32).max(1);
        let n = coefficient_count(bands);
        let offset = ray_offset(layer);
        let coefficients = points
            .par_iter()
            .enumerate()
            .flat_map_iter(|(index, p)| {
                let mut rng = Pcg64Mcg::seed_from_u64(
                    seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
                );
                let mut sum = vec![0.0f64; n];
                let mut y = vec![0.0f64; n];
                let origin = p.position + p.normal * offset;
                for a in 0..side {
                    for b in 0..side {
                        let u1 = (a as f32 + rng.random::<f32>()) / side as f32;
                        let u2 = (b as f32 + rng.random::<f32>()) / side as f32;
                        let w = cosine_direction(p.normal, u1.min(1.0), u2);
                        if w.y <= 0.0
                            || layer.bvh.occluded(&Ray::new(origin, w), 0.0, f32::INFINITY)
                        {
                            continue;
                        }
                        eval_basis(w.as_dvec3(), bands, &mut y);
                        for (s, v) in sum.iter_mut().zip(&y) {
                            *s += v;
                        }
                    }
                }
                let count = f64::from(side * side);
                sum.into_iter().map(move |s| (s / count) as f32)
            })
            .collect();
        Ok(AmbientTransfer {
            bands,
            rays: side * side,
            coefficients,
        })
    }

    /// SH bands kept.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// Rays cast per point.
    pub fn rays(&self) -> u32 {
        self.rays
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.coefficients.len() / coefficient_count(self.bands)
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.coefficients.is_empty()
    }

    /// The transfer vector of point `i`.
    pub fn vector(&self, i: usize) -> &[f32] {
        let n = coefficient_count(self.bands);
        &self.coefficients[i * n..(i + 1) * n]
    }

    /// The paper's weighted ambient `c` of point `i`: the cosine-weighted visible sky fraction.
    pub fn weighted_ambient(&self, i: usize) -> f32 {
        (2.0 * std::f64::consts::PI.sqrt() * f64::from(self.vector(i)[0])) as f32
    }

    /// The bound `sqrt(c (1 - c) / N)` on the standard error of [`Self::weighted_ambient`].
    pub fn standard_error(&self, i: usize) -> f32 {
        let c = self.weighted_ambient(i).clamp(0.0, 1.0);
        (c * (1.0 - c) / self.rays as f32).sqrt()
    }

    /// `c_shape` of point `i` per channel: `sum_k s_k T_k` over the bands both have.
    pub fn sky_ambient(&self, i: usize, shape: &SkyShape) -> Rgb {
        let mut out = [0.0f64; 3];
        for (t, s) in self.vector(i).iter().zip(shape.sh()) {
            for c in 0..3 {
                out[c] += f64::from(*t) * s[c];
            }
        }
        Rgb::new(
            out[0].max(0.0) as f32,
            out[1].max(0.0) as f32,
            out[2].max(0.0) as f32,
        )
    }

    /// [`Self::sky_ambient`] of every point, in parallel.
    pub fn sky_ambient_all(&self, shape: &SkyShape) -> Vec<Rgb> {
        (0..self.len())
            .into_par_iter()
            .map(|i| self.sky_ambient(i, shape))
            .collect()
    }
}

/// `c_shape` of one point by direct ray casting with `rays` stratified rays (no SH): the
/// reference [`AmbientTransfer::sky_ambient`] is checked against.
pub fn sky_ambient_direct(
    layer: &GeometryLayer,
    point: SurfacePoint,
    shape: &SkyShape,
    rays: u32,
    seed: u64,
) -> Rgb {
    let side = (f64::from(rays).sqrt().ceil() as u32).max(1);
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let origin = point.position + point.normal * ray_offset(layer);
    let mut sum = DVec3::ZERO;
    for a in 0..side {
        for b in 0..side {
            let u1 = (a as f32 + rng.random::<f32>()) / side as f32;
            let u2 = (b as f32 + rng.random::<f32>()) / side as f32;
            let w = cosine_direction(point.normal, u1.min(1.0), u2);
            if w.y <= 0.0 || layer.bvh.occluded(&Ray::new(origin, w), 0.0, f32::INFINITY) {
                continue;
            }
            let l = shape.radiance(w);
            sum += DVec3::new(f64::from(l.r), f64::from(l.g), f64::from(l.b));
        }
    }
    let v = sum / f64::from(side * side);
    Rgb::new(v.x as f32, v.y as f32, v.z as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::SkyModel;
    use ibl_scene::{Material, PlacedMesh, primitives};

    fn layer(meshes: Vec<ibl_scene::TriangleMesh>) -> GeometryLayer {
        let m = Material::Diffuse {
            albedo: Rgb::splat(0.5),
        };
        GeometryLayer::new(
            meshes
                .into_iter()
                .enumerate()
                .map(|(i, mesh)| PlacedMesh {
                    name: format!("m{i}"),
                    mesh,
                    materials: vec![m],
                })
                .collect(),
        )
    }

    #[test]
    fn open_ground_sees_the_whole_sky_and_a_wall_half() {
        let ground = primitives::plane(Vec3::ZERO, Vec3::Y, [1000.0, 1000.0]);
        let l = layer(vec![ground]);
        let points = [
            SurfacePoint {
                position: Vec3::ZERO,
                normal: Vec3::Y,
            },
            // A vertical surface at 1 m above an infinite-ish ground: it sees the upper quarter
            // sphere, c = 1/2 exactly (the lower half of its hemisphere is ground).
            SurfacePoint {
                position: Vec3::new(0.0, 1.0, 0.0),
                normal: Vec3::X,
            },
        ];
        let t = AmbientTransfer::compute(&l, &points, 3, 4096, 7).unwrap();
        assert_eq!(t.rays(), 4096);
        assert!((t.weighted_ambient(0) - 1.0).abs() < 1e-5);
        assert_eq!(t.standard_error(0), 0.0);
        // Stratified: the error is far below the Bernoulli bound sqrt(1/4 / 4096) = 0.0078; the
        // ground seen below the horizon within atan(1 / 500) is 1e-3 of c.
        assert!(
            (t.weighted_ambient(1) - 0.5).abs() < 0.0078,
            "{}",
            t.weighted_ambient(1)
        );
        // A uniform sky gives c_shape = c.
        let uniform = SkyShape::new(SkyModel::Uniform, Vec3::Y, 3).unwrap();
        let c = t.sky_ambient(1, &uniform);
        assert!((c.g - t.weighted_ambient(1)).abs() < 1e-5);
    }

    #[test]
    fn a_box_overhang_blocks_the_sky_it_covers() {
        // A point on the ground under the middle of a 2 x 2 m roof at height 1 m: the visible
        // sky fraction by the closed form of a square's view factor. Rays start `ray_offset`
        // (1e-4 of the 10 m extent) above the ground, so the roof is 0.999 m above their origin.
        let ground = primitives::plane(Vec3::ZERO, Vec3::Y, [20.0, 20.0]);
        let roof = primitives::plane(Vec3::new(0.0, 1.0, 0.0), Vec3::NEG_Y, [2.0, 2.0]);
        let l = layer(vec![ground, roof]);
        let p = [SurfacePoint {
            position: Vec3::ZERO,
            normal: Vec3::Y,
        }];
        let t = AmbientTransfer::compute(&l, &p, 1, 16384, 3).unwrap();
        // View factor from a point to a parallel rectangle with a corner above it (Howell's
        // catalogue): F = (1 / 2 pi) [X / sqrt(1 + X^2) atan(Y / sqrt(1 + X^2)) + (X <-> Y)];
        // four 1 x 1 quadrants at height 1: F = (4 / pi) x / sqrt(1 + x^2) atan(x / sqrt(1 + x^2)).
        let x: f64 = 1.0 / (1.0 - f64::from(ray_offset(&l)));
        let s = (1.0 + x * x).sqrt();
        let f = 4.0 / std::f64::consts::PI * (x / s) * (x / s).atan();
        let want = (1.0 - f) as f32;
        // Three Bernoulli standard errors (stratification makes the real error smaller).
        assert!(
            (t.weighted_ambient(0) - want).abs() < 3.0 * (want * (1.0 - want) / 16384.0).sqrt(),
            "{} vs {want}",
            t.weighted_ambient(0)
        );
    }
}
