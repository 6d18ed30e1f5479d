//! Projection of a lat-long probe onto SH with exact solid angles.
//!
//! `c_lm = sum_p L_p Y_lm(d_p) dOmega_p`: the basis at each pixel centre `d_p`, weighted by the
//! pixel's exact solid angle (CONVENTIONS section 4), invalid radiance clamped to 0. This is the
//! same quadrature as the exact irradiance ground truth (`sum_p L_p max(0, n.d_p) dOmega_p`), so the
//! Lambert-convolved expansion converges to that ground truth as bands are added, with no
//! discretisation gap between them.
//!
//! The sum is taken separably. In the frame `d' = (z, x, y)` (a rotation, `P` below) the SH pole is
//! world +Y, the lat-long's own axis, so every pixel row is a circle of constant polar angle:
//! `Y_lm(d') = A_lm(theta) cos(m phi')` (`sin` for negative m), with `A_lm` the basis at `phi' = 0`.
//! Per row that leaves Fourier sums `sum_i L_i cos(m phi'_i)`, `sum_i L_i sin(m phi'_i)` (O(W B))
//! and one basis evaluation (O(B^2)); the coefficients found in that frame are rotated back to the
//! world frame (O(B^3)). Cost O(H (W B + B^2) + B^3) instead of the O(W H B^2) of evaluating every
//! basis function at every pixel; the same sum, to rounding (tested against the direct sum).
//! Rows run in parallel and are summed in row order, so the result is bit-identical whatever the
//! thread count.

use ibl_core::glam::{DMat3, DVec3};
use ibl_core::{Image, LatLong, Rgb, valid_radiance};
use rayon::prelude::*;

use crate::ShError;
use crate::basis::{MAX_BANDS, basis, coefficient_count, sh_index};
use crate::coefficients::RadianceSh;
use crate::rotation::ShRotation;

/// Projects a lat-long probe (world frame) onto `bands` bands (1 to [`MAX_BANDS`]).
pub fn project_latlong(probe: &Image<Rgb>, bands: usize) -> Result<RadianceSh, ShError> {
    let (w, h) = (probe.width(), probe.height());
    if w == 0 || h == 0 {
        return Err(ShError::Invalid("the probe has no pixels".into()));
    }
    if bands == 0 || bands > MAX_BANDS {
        return Err(ShError::Parameter(format!(
            "SH band count must be 1 to {MAX_BANDS}; got {bands}"
        )));
    }
    let ll = LatLong::new(w, h);
    let n = coefficient_count(bands);
    // Column i's azimuth in the primed frame: d = (sin t sin f, cos t, -sin t cos f) gives
    // x' = z = -sin t cos f and y' = x = sin t sin f, so phi' = pi - f.
    let trig: Vec<(f64, f64)> = (0..w)
        .flat_map(|i| {
            let phi = std::f64::consts::TAU * ((i as f64 + 0.5) / w as f64 - 0.5);
            let phi_p = std::f64::consts::PI - phi;
            (0..bands).map(move |m| {
                let a = m as f64 * phi_p;
                (a.cos(), a.sin())
            })
        })
        .collect();
    let rows: Vec<Vec<[f64; 3]>> = (0..h)
        .into_par_iter()
        .map(|j| {
            let omega = ll.row_solid_angle(j);
            let mut fc = vec![[0.0f64; 3]; bands];
            let mut fs = vec![[0.0f64; 3]; bands];
            for (i, px) in probe.row(j).iter().enumerate() {
                let l = [px.r, px.g, px.b].map(|v| valid_radiance(v) * omega);
                if l == [0.0; 3] {
                    continue;
                }
                for (m, &(c, s)) in trig[i * bands..(i + 1) * bands].iter().enumerate() {
                    for ch in 0..3 {
                        fc[m][ch] += l[ch] * c;
                        fs[m][ch] += l[ch] * s;
                    }
                }
            }
            let theta = std::f64::consts::PI * (j as f64 + 0.5) / h as f64;
            let a = basis(DVec3::new(theta.sin(), 0.0, theta.cos()), bands);
            let mut acc = vec![[0.0f64; 3]; n];
            for l in 0..bands {
                for m in 0..=l {
                    let alm = a[sh_index(l, m as isize)];
                    acc[sh_index(l, m as isize)] = fc[m].map(|v| alm * v);
                    if m > 0 {
                        acc[sh_index(l, -(m as isize))] = fs[m].map(|v| alm * v);
                    }
                }
            }
            acc
        })
        .collect();
    let mut primed = vec![[0.0f64; 3]; n];
    for row in rows {
        for (c, r) in primed.iter_mut().zip(row) {
            for ch in 0..3 {
                c[ch] += r[ch];
            }
        }
    }
    // The primed coefficients belong to the probe turned by P (d -> (z, x, y)); turn them back.
    let p = DMat3::from_cols(DVec3::Y, DVec3::Z, DVec3::X);
    let coeffs = ShRotation::new(p.transpose(), bands).apply(&primed);
    RadianceSh::new(bands, coeffs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::eval_basis;

    /// The separable projection is the per-pixel sum `sum_p L_p Y(d_p) dOmega_p`, to rounding.
    #[test]
    fn separable_projection_is_the_direct_sum() {
        let (w, h) = (96, 48);
        let ll = LatLong::new(w, h);
        let mut probe = Image::filled(w, h, Rgb::ZERO);
        for j in 0..h {
            for i in 0..w {
                let d = ll.pixel_dir64(i, j);
                let v = (1.5 + d.x + 0.5 * d.y * d.z).max(0.0)
                    + if (i * 7 + j * 3) % 11 == 0 { 5.0 } else { 0.0 };
                *probe.get_mut(i, j) = Rgb::new(v as f32, (0.5 * v) as f32, (d.z.abs()) as f32);
            }
        }
        let bands = 9;
        let got = project_latlong(&probe, bands).unwrap();
        let mut want = vec![[0.0f64; 3]; coefficient_count(bands)];
        let mut y = vec![0.0; coefficient_count(bands)];
        for j in 0..h {
            for i in 0..w {
                let px = probe.get(i, j);
                eval_basis(ll.pixel_dir64(i, j), bands, &mut y);
                for (c, yk) in want.iter_mut().zip(&y) {
                    for (ch, v) in [px.r, px.g, px.b].into_iter().enumerate() {
                        c[ch] += f64::from(v) * ll.row_solid_angle(j) * yk;
                    }
                }
            }
        }
        let scale = want[0][0].abs();
        for (k, (g, w)) in got.coefficients().iter().zip(&want).enumerate() {
            for ch in 0..3 {
                assert!(
                    (g[ch] - w[ch]).abs() < 1e-12 * scale,
                    "coefficient {k}: {g:?} vs {w:?}"
                );
            }
        }
    }
}
