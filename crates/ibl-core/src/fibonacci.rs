//! Fibonacci-sphere normals, CONVENTIONS section 5 (Madsen & Laursen 2006 evaluate irradiance on
//! 20000 such normals): for k = 0..M-1,
//!
//! ```text
//! y_k = 1 - (2k + 1) / M,  r_k = sqrt(1 - y_k^2),  a_k = k pi (3 - sqrt 5),
//! n_k = (r_k cos a_k, y_k, r_k sin a_k)
//! ```
//!
//! The points are nearly uniform on the sphere with no clustering at the poles. Computed in f64.

use glam::DVec3;

/// The default number of evaluation normals.
pub const DEFAULT_NORMAL_COUNT: usize = 20_000;

/// The M Fibonacci normals of CONVENTIONS section 5, unit length, in order k = 0..M-1. Cost O(M).
pub fn fibonacci_normals(m: usize) -> Vec<DVec3> {
    let golden_angle = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    let mf = m as f64;
    (0..m)
        .map(|k| {
            let kf = k as f64;
            let y = 1.0 - (2.0 * kf + 1.0) / mf;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let a = kf * golden_angle;
            DVec3::new(r * a.cos(), y, r * a.sin())
        })
        .collect()
}
