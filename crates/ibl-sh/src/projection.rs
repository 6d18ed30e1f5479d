//! Projection of a lat-long probe onto SH, exactly.
//!
//! A probe pixel holds the radiance of its whole texel (CONVENTIONS section 4), so the projection
//! of the image is `c_lm = sum_p L_p integral_{texel p} Y_lm dOmega`, each basis function integrated
//! over each texel's exact area, invalid radiance clamped to 0. Nothing is sampled at pixel
//! centres: a constant probe projects to `2 sqrt(pi) L` in `c_00` and zero (to rounding) in every
//! other coefficient, and the texel weights sum to the exact solid angles.
//!
//! How, separably. In the frame `d' = (z, x, y)` (a rotation, `P` below) the SH pole is world +Y,
//! the lat-long's own axis, so a texel is a band of `z' = cos(theta)` times an interval of azimuth
//! `phi'`, and `Y_lm = A_lm(z') cos(m phi')` (`sin` for negative m), with `A_lm` the basis at
//! `phi' = 0`. The azimuth integral is closed-form, `2 sin(m D / 2) / m` times the cosine (sine) at
//! the texel's centre (`D` the texel width), and the `z'` integral over a row is a Gauss-Legendre
//! sum of `bands / 2 + 2` nodes: exact for even m, whose `A_lm` are polynomials in `z'` of degree
//! below `bands`, and for odd m (a polynomial times `sqrt(1 - z'^2)`) far more accurate than the
//! radiance itself over a row a fraction of a degree tall (checked against a 24 x 24 sub-texel sum). Per row that is Fourier sums over the columns (O(W B)) and the basis
//! at the row's nodes (O(B^2) each); the coefficients found in the turned frame are rotated back to
//! the world frame (O(B^3)). Cost O(H (W B + B^2) + B^3). Rows run in parallel and are summed in
//! row order, so the result is bit-identical whatever the thread count.

use ibl_core::glam::{DMat3, DVec3};
use ibl_core::{Image, Rgb, valid_radiance};
use rayon::prelude::*;

use crate::ShError;
use crate::basis::{MAX_BANDS, basis, coefficient_count, eval_basis, sh_index};
use crate::coefficients::RadianceSh;
use crate::quadrature::gauss_legendre;
use crate::rotation::ShRotation;

/// Takes point sources off the radiance coefficients `coefficients` of `bands` bands (in the
/// order of [`sh_index`]): a source of unit direction `d` and power `I` (per channel, radiance x
/// sr) projects to `I Y_lm(d)`, which is subtracted. What is left of a probe once its lights
/// are taken out as points (the hybrid's ambient). O(K bands^2) for K sources.
pub fn subtract_point_sources(
    coefficients: &mut [[f64; 3]],
    bands: usize,
    sources: impl IntoIterator<Item = (DVec3, [f64; 3])>,
) {
    for (direction, power) in sources {
        let y = basis(direction, bands);
        for (c, yk) in coefficients.iter_mut().zip(&y) {
            for (v, p) in c.iter_mut().zip(power) {
                *v -= p * yk;
            }
        }
    }
}

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
    let n = coefficient_count(bands);
    // Column i's azimuth in the primed frame: d = (sin t sin f, cos t, -sin t cos f) gives
    // x' = z = -sin t cos f and y' = x = sin t sin f, so phi' = pi - f. Entry (i, m): the integral
    // of cos(m phi') and sin(m phi') over the column's width D.
    let width = std::f64::consts::TAU / w as f64;
    let trig: Vec<(f64, f64)> = (0..w)
        .flat_map(|i| {
            let phi = std::f64::consts::TAU * ((i as f64 + 0.5) / w as f64 - 0.5);
            let phi_p = std::f64::consts::PI - phi;
            (0..bands).map(move |m| {
                let span = if m == 0 {
                    width
                } else {
                    2.0 * (0.5 * m as f64 * width).sin() / m as f64
                };
                let a = m as f64 * phi_p;
                (span * a.cos(), span * a.sin())
            })
        })
        .collect();
    let rule = gauss_legendre(bands / 2 + 2);
    let rows: Vec<Vec<[f64; 3]>> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut fc = vec![[0.0f64; 3]; bands];
            let mut fs = vec![[0.0f64; 3]; bands];
            for (i, px) in probe.row(j).iter().enumerate() {
                let l = [px.r, px.g, px.b].map(valid_radiance);
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
            // The integral of A_lm(z') over the row's band of z' = cos(theta).
            let z_top = (std::f64::consts::PI * j as f64 / h as f64).cos();
            let z_bottom = (std::f64::consts::PI * (j + 1) as f64 / h as f64).cos();
            let (mid, half) = (0.5 * (z_top + z_bottom), 0.5 * (z_top - z_bottom));
            let mut a = vec![0.0f64; n];
            let mut y = vec![0.0f64; n];
            for &(x, weight) in &rule {
                let z = mid + half * x;
                eval_basis(
                    DVec3::new((1.0 - z * z).max(0.0).sqrt(), 0.0, z),
                    bands,
                    &mut y,
                );
                for (ak, yk) in a.iter_mut().zip(&y) {
                    *ak += half * weight * yk;
                }
            }
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
    use ibl_core::LatLong;

    /// The separable projection is the per-texel integral `sum_p L_p integral Y dOmega`, here
    /// by brute force: 24 x 24 sub-texels per pixel, each weighted by its exact solid angle.
    #[test]
    fn separable_projection_is_the_texel_integral() {
        let (w, h) = (48, 24);
        let ll = LatLong::new(w, h);
        let mut probe = Image::filled(w, h, Rgb::ZERO);
        for j in 0..h {
            for i in 0..w {
                let d = ll.pixel_dir64(i, j);
                let v = (1.5 + d.x + 0.5 * d.y * d.z).max(0.0)
                    + if (i * 7 + j * 3) % 11 == 0 { 5.0 } else { 0.0 };
                *probe.get_mut(i, j) = Rgb::new(v as f32, (0.5 * v) as f32, d.z.abs() as f32);
            }
        }
        let bands = 9;
        let got = project_latlong(&probe, bands).unwrap();
        let sub = 24;
        let fine = LatLong::new(w * sub, h * sub);
        let mut want = vec![[0.0f64; 3]; coefficient_count(bands)];
        let mut y = vec![0.0; coefficient_count(bands)];
        for jj in 0..h * sub {
            let omega = fine.row_solid_angle(jj);
            for ii in 0..w * sub {
                let px = probe.get(ii / sub, jj / sub);
                eval_basis(fine.pixel_dir64(ii, jj), bands, &mut y);
                for (c, yk) in want.iter_mut().zip(&y) {
                    for (ch, v) in [px.r, px.g, px.b].into_iter().enumerate() {
                        c[ch] += f64::from(v) * omega * yk;
                    }
                }
            }
        }
        let scale = want[0][0].abs();
        for (k, (g, w)) in got.coefficients().iter().zip(&want).enumerate() {
            for ch in 0..3 {
                // The brute force's own midpoint error is O(1 / (24^2 H^2)).
                assert!(
                    (g[ch] - w[ch]).abs() < 2e-5 * scale,
                    "coefficient {k}: {g:?} vs {w:?}"
                );
            }
        }
    }
}
