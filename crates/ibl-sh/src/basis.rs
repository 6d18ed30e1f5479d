//! The real orthonormal spherical-harmonic basis of CONVENTIONS section 6, for any number of bands.
//!
//! Convention: real, orthonormal over the sphere (`integral Y_lm Y_l'm' dOmega = delta`), **no
//! Condon-Shortley phase**, coefficient index `l^2 + l + m`, evaluated on world `(x, y, z)` with `z`
//! as the polar axis, exactly as the Ramamoorthi & Hanrahan / three.js formulas write them:
//!
//! ```text
//! Y_l0   = K_l0 P_l(z)
//! Y_lm   = sqrt(2) K_lm P_l^m(z) cos(m phi)      m > 0
//! Y_l-m  = sqrt(2) K_lm P_l^m(z) sin(m phi)      m > 0
//! K_lm   = sqrt((2l + 1) / (4 pi) (l - m)! / (l + m)!)
//! ```
//!
//! with `x = sin(theta) cos(phi)`, `y = sin(theta) sin(phi)`, `z = cos(theta)` and `P_l^m` the
//! associated Legendre functions without the `(-1)^m` factor. So `Y_1-1, Y_10, Y_11` are positive
//! multiples of `y, z, x`.
//!
//! Evaluation is trigonometry-free and stable to high order: `(1 - z^2)^(m/2) cos(m phi)` and
//! `.. sin(m phi)` are the real and imaginary parts of `(x + i y)^m`, and the remaining factor
//! `K_lm P_l^m(z) / (1 - z^2)^(m/2)` follows the standard normalised three-term recurrence in `l`
//! (no factorials, no overflow). Cost O(bands^2) per direction.

use ibl_core::glam::DVec3;

/// Most bands supported (`l <= 63`); the recurrence is accurate well beyond, this bounds memory.
pub const MAX_BANDS: usize = 64;

/// Number of coefficients of `bands` bands: `bands^2`.
pub const fn coefficient_count(bands: usize) -> usize {
    bands * bands
}

/// Index of `Y_lm` in a coefficient vector: `l^2 + l + m`.
pub const fn sh_index(l: usize, m: isize) -> usize {
    (l * l + l).wrapping_add_signed(m)
}

/// Writes `Y_lm(d)` for every `l < bands` into `out[sh_index(l, m)]` (`out` must hold at least
/// `bands^2` values; `d` should be unit: the functions are evaluated on its components as given).
///
/// # Panics
/// If `out` is shorter than `bands^2` (a caller's bug).
pub fn eval_basis(d: DVec3, bands: usize, out: &mut [f64]) {
    assert!(out.len() >= coefficient_count(bands), "SH buffer too short");
    if bands == 0 {
        return;
    }
    let (x, y, z) = (d.x, d.y, d.z);
    // pmm = K_mm P_m^m / (1 - z^2)^(m/2) for the current m: 1/sqrt(4 pi) times prod sqrt((2k+1)/2k).
    let mut pmm = 0.5 / std::f64::consts::PI.sqrt();
    // (c, s) = real and imaginary parts of (x + i y)^m.
    let (mut c, mut s) = (1.0f64, 0.0f64);
    for m in 0..bands {
        if m > 0 {
            pmm *= ((2 * m + 1) as f64 / (2 * m) as f64).sqrt();
            let (cn, sn) = (c * x - s * y, c * y + s * x);
            c = cn;
            s = sn;
        }
        let (cos_part, sin_part) = if m == 0 {
            (1.0, 0.0)
        } else {
            (std::f64::consts::SQRT_2 * c, std::f64::consts::SQRT_2 * s)
        };
        // l = m, m + 1, ... by the normalised recurrence.
        let mut p_prev = 0.0;
        let mut p = pmm;
        for l in m..bands {
            if l == m + 1 {
                p_prev = p;
                p = ((2 * m + 3) as f64).sqrt() * z * pmm;
            } else if l > m + 1 {
                let (lf, mf) = (l as f64, m as f64);
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let b = (((lf - 1.0) * (lf - 1.0) - mf * mf)
                    / (4.0 * (lf - 1.0) * (lf - 1.0) - 1.0))
                    .sqrt();
                let next = a * (z * p - b * p_prev);
                p_prev = p;
                p = next;
            }
            let mi = m as isize;
            if m == 0 {
                out[sh_index(l, 0)] = p;
            } else {
                out[sh_index(l, mi)] = p * cos_part;
                out[sh_index(l, -mi)] = p * sin_part;
            }
        }
    }
}

/// `Y_lm(d)` for every `l < bands`, as a new vector (see [`eval_basis`]).
pub fn basis(d: DVec3, bands: usize) -> Vec<f64> {
    let mut out = vec![0.0; coefficient_count(bands)];
    eval_basis(d, bands, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::gauss_legendre;

    /// The l <= 2 functions of CONVENTIONS section 6, number for number.
    #[test]
    fn first_three_bands_match_the_conventions() {
        for d in [
            DVec3::new(0.3, -0.5, 0.2).normalize(),
            DVec3::new(-0.9, 0.1, 0.4).normalize(),
            DVec3::Z,
            DVec3::new(0.0, 0.6, -0.8),
        ] {
            let (x, y, z) = (d.x, d.y, d.z);
            let want = [
                0.282095,
                0.488603 * y,
                0.488603 * z,
                0.488603 * x,
                1.092548 * x * y,
                1.092548 * y * z,
                0.315392 * (3.0 * z * z - 1.0),
                1.092548 * x * z,
                0.546274 * (x * x - y * y),
            ];
            let got = basis(d, 3);
            for (k, (g, w)) in got.iter().zip(want).enumerate() {
                assert!((g - w).abs() < 2e-6, "index {k}: {g} vs {w} at {d}");
            }
        }
    }

    /// Orthonormality to 31 bands (l <= 30), with a product rule exact for these functions: 64
    /// equally spaced azimuths (exact for `cos(m phi) cos(m' phi)` up to m + m' < 64) times 32
    /// Gauss-Legendre nodes in z (exact for polynomials of degree < 64).
    #[test]
    fn orthonormal_to_thirty_bands() {
        let bands = 31;
        let n = coefficient_count(bands);
        let mut gram = vec![0.0f64; n * n];
        let mut y = vec![0.0; n];
        for (z, wz) in gauss_legendre(32) {
            for k in 0..64 {
                let phi = 2.0 * std::f64::consts::PI * k as f64 / 64.0;
                let r = (1.0 - z * z).sqrt();
                eval_basis(DVec3::new(r * phi.cos(), r * phi.sin(), z), bands, &mut y);
                let w = wz * 2.0 * std::f64::consts::PI / 64.0;
                for a in 0..n {
                    let wa = w * y[a];
                    for b in a..n {
                        gram[a * n + b] += wa * y[b];
                    }
                }
            }
        }
        let mut worst: f64 = 0.0;
        for a in 0..n {
            for b in a..n {
                let want = if a == b { 1.0 } else { 0.0 };
                worst = worst.max((gram[a * n + b] - want).abs());
            }
        }
        assert!(
            worst < 1e-12,
            "largest deviation from the identity: {worst}"
        );
    }

    #[test]
    fn indices() {
        assert_eq!(sh_index(0, 0), 0);
        assert_eq!(sh_index(1, -1), 1);
        assert_eq!(sh_index(2, 2), 8);
        assert_eq!(coefficient_count(31), 961);
    }
}
