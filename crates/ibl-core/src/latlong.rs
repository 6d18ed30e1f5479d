//! The lat-long (equirectangular) parameterisation of the sphere, CONVENTIONS section 2.
//!
//! For a W x H map, pixel (i, j) has its centre at `u = (i + 0.5) / W`, `v = (j + 0.5) / H`, and
//!
//! ```text
//! theta = pi v                 polar angle from +Y
//! phi   = 2 pi (u - 0.5)       azimuth, 0 = forward (-Z), +pi/2 = right (+X)
//! d     = (sin theta sin phi, cos theta, -sin theta cos phi)
//! ```
//!
//! The solid angle of every pixel in row j is exact (not the `sin theta dtheta dphi` Riemann
//! approximation): `dOmega_j = (2 pi / W) (cos(pi j / H) - cos(pi (j + 1) / H))`, which sums to
//! exactly 4 pi. All trigonometry is in f64 and rounded once at the end.

use std::f64::consts::{PI, TAU};

use glam::{DVec3, Vec3};

/// The lat-long parameterisation of a W x H map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatLong {
    /// Width in pixels (normally `2 * height`).
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
}

impl LatLong {
    /// The parameterisation of a `width` x `height` map.
    pub fn new(width: usize, height: usize) -> Self {
        LatLong { width, height }
    }

    /// Direction for continuous map coordinates `u, v` in [0, 1] (f64, unit length).
    pub fn uv_to_dir64(u: f64, v: f64) -> DVec3 {
        let theta = PI * v;
        let phi = TAU * (u - 0.5);
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        DVec3::new(st * sp, ct, -st * cp)
    }

    /// Direction for continuous map coordinates `u, v` in [0, 1].
    pub fn uv_to_dir(u: f64, v: f64) -> Vec3 {
        Self::uv_to_dir64(u, v).as_vec3()
    }

    /// Map coordinates `(u, v)` of a direction, `u` in [0, 1), `v` in [0, 1]. The direction
    /// need not be normalised; a zero vector maps to the zenith.
    pub fn dir_to_uv(d: DVec3) -> (f64, f64) {
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return (0.5, 0.0);
        }
        let theta = (d.y / len).clamp(-1.0, 1.0).acos();
        let phi = d.x.atan2(-d.z);
        let mut u = phi / TAU + 0.5;
        if u >= 1.0 {
            u -= 1.0;
        }
        (u, theta / PI)
    }

    /// Direction through the centre of pixel (i, j).
    pub fn pixel_dir64(&self, i: usize, j: usize) -> DVec3 {
        Self::uv_to_dir64(
            (i as f64 + 0.5) / self.width as f64,
            (j as f64 + 0.5) / self.height as f64,
        )
    }

    /// Direction through the centre of pixel (i, j), f32.
    pub fn pixel_dir(&self, i: usize, j: usize) -> Vec3 {
        self.pixel_dir64(i, j).as_vec3()
    }

    /// The pixel containing a direction (column wraps, row clamps).
    pub fn dir_to_pixel(&self, d: DVec3) -> (usize, usize) {
        let (u, v) = Self::dir_to_uv(d);
        let i = ((u * self.width as f64) as usize).min(self.width - 1);
        let j = ((v * self.height as f64) as usize).min(self.height - 1);
        (i, j)
    }

    /// Exact solid angle (sr) of one pixel in row `j`.
    pub fn row_solid_angle(&self, j: usize) -> f64 {
        let h = self.height as f64;
        let t0 = PI * j as f64 / h;
        let t1 = PI * (j as f64 + 1.0) / h;
        (TAU / self.width as f64) * (t0.cos() - t1.cos())
    }

    /// Exact solid angles of every row, top to bottom.
    pub fn row_solid_angles(&self) -> Vec<f64> {
        (0..self.height).map(|j| self.row_solid_angle(j)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trips() {
        let ll = LatLong::new(64, 32);
        for j in 0..32 {
            for i in 0..64 {
                let d = ll.pixel_dir64(i, j);
                assert_eq!(ll.dir_to_pixel(d), (i, j));
            }
        }
    }
}
