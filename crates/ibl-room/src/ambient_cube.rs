//! The ambient cube (McTaggart 2004, Valve's Source engine): irradiance stored as six RGB values,
//! one per world axis direction `+x, -x, +y, -y, +z, -z`, each the irradiance of a surface facing
//! that way; between them `E(n) = n_x^2 C[x, sign n_x] + n_y^2 C[y, sign n_y] + n_z^2 C[z, sign
//! n_z]`, exact on the six axes and for uniform light (the weights sum to 1).
//!
//! It is the alternative to SH L2 the irradiance volume of [`crate::irradiance_volume`] was
//! measured against (18 floats per key point against 27, three squares against nine basis
//! functions); the measurement and the choice are in that module's doc. World frame, radiance and
//! irradiance in the probe's units.

use glam::Vec3;
use ibl_core::Rgb;
use ibl_sh::KeyPointIrradiance;

use crate::irradiance_volume::GatheredIrradiance;

/// Irradiance on the six axis-facing surfaces, `faces[2 a + s]` for axis `a` (x, y, z) and `s =
/// 0` facing `+a`, `s = 1` facing `-a`; per channel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AmbientCube {
    /// Per face, RGB irradiance.
    pub faces: [[f32; 3]; 6],
}

impl KeyPointIrradiance for AmbientCube {
    const ZERO: AmbientCube = AmbientCube {
        faces: [[0.0; 3]; 6],
    };

    fn add_scaled(&mut self, other: &AmbientCube, weight: f32) {
        for (a, b) in self.faces.iter_mut().zip(&other.faces) {
            for ch in 0..3 {
                a[ch] += weight * b[ch];
            }
        }
    }

    fn irradiance(&self, n: Vec3) -> [f32; 3] {
        let mut out = [0.0f32; 3];
        for (a, c) in n.to_array().into_iter().enumerate() {
            let face = &self.faces[2 * a + usize::from(c < 0.0)];
            for ch in 0..3 {
                out[ch] += c * c * face[ch];
            }
        }
        out
    }
}

impl GatheredIrradiance for AmbientCube {
    /// Light from `w` reaches the three faces turned towards it, each by `max(0, +-w_a)`.
    fn add_light(&mut self, w: Vec3, radiance: Rgb, d_omega: f32) {
        for (a, c) in w.to_array().into_iter().enumerate() {
            let face = &mut self.faces[2 * a + usize::from(c < 0.0)];
            let weight = c.abs() * d_omega;
            for ch in 0..3 {
                face[ch] += weight * radiance[ch];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_light_and_axis_normals_are_exact() {
        let mut cube = AmbientCube::ZERO;
        // A uniform sky of radiance 1 over the whole sphere, 20000 Fibonacci directions: every
        // face gathers pi.
        let dirs = ibl_core::fibonacci::fibonacci_normals(20_000);
        let d_omega = (4.0 * std::f64::consts::PI / dirs.len() as f64) as f32;
        for d in &dirs {
            cube.add_light(d.as_vec3(), Rgb::ONE, d_omega);
        }
        for n in [
            Vec3::X,
            Vec3::NEG_Y,
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::ONE.normalize(),
        ] {
            let e = cube.irradiance(n)[1];
            // Quadrature of a cosine lobe on 20000 points: measured 2e-5 relative; 1e-3 margin.
            assert!((e / std::f32::consts::PI - 1.0).abs() < 1e-3, "{n}: {e}");
        }
        // A single direction straight down lights only the -y face.
        let mut down = AmbientCube::ZERO;
        down.add_light(Vec3::NEG_Y, Rgb::new(2.0, 0.0, 0.0), 0.5);
        assert_eq!(down.irradiance(Vec3::NEG_Y), [1.0, 0.0, 0.0]);
        assert_eq!(down.irradiance(Vec3::Y), [0.0, 0.0, 0.0]);
        assert_eq!(down.irradiance(Vec3::X), [0.0, 0.0, 0.0]);
    }
}
