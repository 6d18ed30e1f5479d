//! Projection of a lat-long probe onto SH with exact solid angles.
//!
//! `c_lm = sum_p L_p Y_lm(d_p) dOmega_p`: the basis at each pixel centre `d_p`, weighted by the
//! pixel's exact solid angle (CONVENTIONS section 4), invalid radiance clamped to 0. This is the
//! same quadrature as the exact irradiance ground truth (`sum_p L_p max(0, n.d_p) dOmega_p`), so the
//! Lambert-convolved expansion converges to that ground truth as bands are added, with no
//! discretisation gap between them. Rows run in parallel and are summed in row order, so the
//! result is bit-identical whatever the thread count. Cost O(W H bands^2).

use ibl_core::{Image, LatLong, Rgb, valid_radiance};
use rayon::prelude::*;

use crate::ShError;
use crate::basis::{MAX_BANDS, coefficient_count, eval_basis};
use crate::coefficients::RadianceSh;

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
    let rows: Vec<Vec<[f64; 3]>> = (0..h)
        .into_par_iter()
        .map(|j| {
            let omega = ll.row_solid_angle(j);
            let mut acc = vec![[0.0f64; 3]; n];
            let mut y = vec![0.0f64; n];
            for (i, px) in probe.row(j).iter().enumerate() {
                let l = [px.r, px.g, px.b].map(|v| valid_radiance(v) * omega);
                if l == [0.0; 3] {
                    continue;
                }
                eval_basis(ll.pixel_dir64(i, j), bands, &mut y);
                for (a, yk) in acc.iter_mut().zip(&y) {
                    for c in 0..3 {
                        a[c] += yk * l[c];
                    }
                }
            }
            acc
        })
        .collect();
    let mut coeffs = vec![[0.0f64; 3]; n];
    for row in rows {
        for (c, r) in coeffs.iter_mut().zip(row) {
            for ch in 0..3 {
                c[ch] += r[ch];
            }
        }
    }
    RadianceSh::new(bands, coeffs)
}
