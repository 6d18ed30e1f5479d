//! Rays and ray hits in the world frame (`docs/CONVENTIONS.md` section 1: +Y up, -Z forward, metres
//! or any consistent length unit), and the f32 rounding-error constant `gamma_n` the intersection
//! and hit-point error bounds are written in.

use glam::Vec3;

/// A ray `origin + t * direction`, `t` in `[t_min, t_max]`; `direction` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point, world frame.
    pub origin: Vec3,
    /// Unit direction, world frame.
    pub direction: Vec3,
}

impl Ray {
    /// A ray from `origin` along the unit vector `direction`.
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Ray { origin, direction }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }
}

/// The closest intersection of a ray with a triangle set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (distance, since directions are unit length).
    pub t: f32,
    /// Index of the triangle hit, in the order the triangles were given to the accelerator.
    pub triangle: u32,
    /// Barycentric coordinate of the triangle's second vertex.
    pub u: f32,
    /// Barycentric coordinate of the triangle's third vertex (the first has `1 - u - v`).
    pub v: f32,
}

/// `gamma_n = n u / (1 - n u)` with `u = 2^-24` (f32 unit roundoff): a bound on the relative error
/// of `n` successive f32 roundings (Higham 2002, section 3.1; Pharr, Jakob and Humphreys,
/// *Physically Based Rendering*, 4th ed., section 6.8.1).
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * (f32::EPSILON * 0.5);
    nu / (1.0 - nu)
}
