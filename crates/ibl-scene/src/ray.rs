//! Rays and ray hits in the world frame (`docs/CONVENTIONS.md` section 1: +Y up, -Z forward, metres
//! or any consistent length unit).

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
