//! Unit direction vectors in the world frame (+Y up, -Z forward, +X right).
//!
//! A direction points *from the scene towards where the light comes from*. The type guarantees
//! unit length so that dot products are cosines without a hidden normalisation.

use glam::{DVec3, Vec3};

/// A unit-length direction in the world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitDir(Vec3);

impl UnitDir {
    /// +X, right.
    pub const RIGHT: UnitDir = UnitDir(Vec3::X);
    /// +Y, up (the zenith).
    pub const UP: UnitDir = UnitDir(Vec3::Y);
    /// -Z, forward (the centre of a lat-long map).
    pub const FORWARD: UnitDir = UnitDir(Vec3::NEG_Z);
    /// +Z, behind (the seam of a lat-long map).
    pub const BACK: UnitDir = UnitDir(Vec3::Z);

    /// Normalises `v`; `None` when it is zero-length or not finite.
    pub fn new(v: Vec3) -> Option<UnitDir> {
        let n = v.try_normalize()?;
        Some(UnitDir(n))
    }

    /// Normalises an f64 vector; `None` when it is zero-length or not finite.
    pub fn from_dvec3(v: DVec3) -> Option<UnitDir> {
        let n = v.try_normalize()?;
        Some(UnitDir(n.as_vec3()))
    }

    /// The direction as a plain vector (unit length).
    pub fn vec3(self) -> Vec3 {
        self.0
    }

    /// The direction in f64.
    pub fn dvec3(self) -> DVec3 {
        self.0.as_dvec3()
    }

    /// Cosine of the angle to another direction.
    pub fn cos_to(self, other: UnitDir) -> f32 {
        self.0.dot(other.0).clamp(-1.0, 1.0)
    }
}

impl From<UnitDir> for Vec3 {
    fn from(d: UnitDir) -> Vec3 {
        d.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalises_and_rejects_degenerate() {
        let d = UnitDir::new(Vec3::new(3.0, 0.0, 4.0)).unwrap();
        assert!((d.vec3().length() - 1.0).abs() < 1e-6);
        assert!(UnitDir::new(Vec3::ZERO).is_none());
        assert!(UnitDir::new(Vec3::new(f32::NAN, 0.0, 1.0)).is_none());
    }
}
