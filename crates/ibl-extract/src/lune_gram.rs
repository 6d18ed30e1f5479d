//! The Gram matrix of the irradiance fit's light features in closed form, for fitting normals
//! spread uniformly over the sphere.
//!
//! The Gauss-Newton matrix of the fit (see `irradiance_optimization`) is built from
//! `Q = Phi^T Phi`, the sums over the fitting normals of products of two lights' features
//! `max(0, n.w)`, `n.t1`, `n.t2` (the last two zero behind the light). For normals spread evenly
//! over the sphere, such a sum is `M / (4 pi)` times an integral over the lune where both lights'
//! hemispheres overlap, and that integral has a closed form ([`lune_moment`]). Computing `Q` this
//! way costs O(N^2) instead of the O(M N^2) of the sum, so the number of fitting normals M can grow
//! (for a more faithful fit) without making the step dearer. The matrix only chooses the step:
//! cost and gradient stay exact sums, so a step is still kept only when it truly lowers the cost.

use glam::{DMat3, DVec3};

/// One light pair's block of the Gram matrix `Phi^T Phi` (see the module doc) for `m` evenly
/// spread normals: entry `[x][y]` is `M / (4 pi)` times `f_x^T T f'_y`, with `T` the second
/// moment of the lune where both hemispheres overlap ([`lune_moment`]) and `f = (wi, ti1, ti2)`,
/// `f' = (wj, tj1, tj2)` the features' vectors. O(1), independent of M.
pub(crate) fn feature_block(
    wi: DVec3,
    ti: (DVec3, DVec3),
    wj: DVec3,
    tj: (DVec3, DVec3),
    m: usize,
) -> [[f64; 3]; 3] {
    let density = m as f64 / (4.0 * std::f64::consts::PI);
    let t = lune_moment(wi, wj);
    let tg = [wj, tj.0, tj.1].map(|g| t * g);
    [wi, ti.0, ti.1].map(|f| tg.map(|v| density * f.dot(v)))
}

/// `sum_k max(0, n_k . wi) max(0, n_k . wj)` over `m` evenly spread normals, in closed form
/// (`M / (4 pi)` times `wi . T wj`, see [`lune_moment`]). O(1).
pub(crate) fn cosine_overlap(wi: DVec3, wj: DVec3, m: usize) -> f64 {
    m as f64 / (4.0 * std::f64::consts::PI) * wi.dot(lune_moment(wi, wj) * wj)
}

/// `T = integral of n n^T over the unit directions n with n.wi > 0 and n.wj > 0` (the lune where
/// two hemispheres overlap), in closed form. With `e` the lune's axis (`wi x wj`, normalised),
/// `m` its bisector (`wi + wj`, normalised), `p = e x m` and `h = (pi - theta) / 2` its half
/// width (`theta` the angle between `wi` and `wj`): in polar angles about `e`,
/// `T = (4/3) h e e^T + (4/3) [(h + sin 2h / 2) m m^T + (h - sin 2h / 2) p p^T]`.
/// Equal directions give the hemisphere's `(2 pi / 3) I`, opposite ones zero.
fn lune_moment(wi: DVec3, wj: DVec3) -> DMat3 {
    let cos = wi.dot(wj);
    let axis = wi.cross(wj);
    let sin = axis.length();
    if sin < 1e-12 {
        return if cos > 0.0 {
            DMat3::from_diagonal(DVec3::splat(2.0 * std::f64::consts::PI / 3.0))
        } else {
            DMat3::ZERO
        };
    }
    let e = axis / sin;
    let Some(mid) = (wi + wj).try_normalize() else {
        return DMat3::ZERO;
    };
    let p = e.cross(mid);
    let h = 0.5 * (std::f64::consts::PI - sin.atan2(cos));
    let s2 = 0.5 * (2.0 * h).sin();
    let outer = |v: DVec3, k: f64| DMat3::from_cols(v * (k * v.x), v * (k * v.y), v * (k * v.z));
    outer(e, 4.0 / 3.0 * h) + outer(mid, 4.0 / 3.0 * (h + s2)) + outer(p, 4.0 / 3.0 * (h - s2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::fibonacci_normals;

    /// The closed form against the sum over many Fibonacci normals, for angles from 0 to pi.
    #[test]
    fn lune_moment_matches_a_dense_sum() {
        let normals = fibonacci_normals(200_000);
        let weight = 4.0 * std::f64::consts::PI / normals.len() as f64;
        let wi = DVec3::new(0.2, 0.7, -0.4).normalize();
        let t = wi.any_orthonormal_vector();
        for angle in [0.0, 1e-9, 0.3, 1.0, 1.57, 2.5, 3.1, std::f64::consts::PI] {
            let wj = (wi * f64::cos(angle) + t * f64::sin(angle)).normalize();
            let mut want = DMat3::ZERO;
            for n in &normals {
                if n.dot(wi) > 0.0 && n.dot(wj) > 0.0 {
                    want += DMat3::from_cols(*n * n.x, *n * n.y, *n * n.z) * weight;
                }
            }
            let got = lune_moment(wi, wj);
            let err = (got - want)
                .to_cols_array()
                .iter()
                .map(|v| v.abs())
                .fold(0.0, f64::max);
            assert!(err < 5e-4, "angle {angle}: error {err}");
            assert!(
                (got - got.transpose())
                    .to_cols_array()
                    .iter()
                    .all(|v| v.abs() < 1e-15)
            );
        }
        // A hemisphere with itself: (2 pi / 3) I, whose trace is the hemisphere's 2 pi sr.
        let same = lune_moment(wi, wi);
        assert!(
            (same.x_axis.x + same.y_axis.y + same.z_axis.z - 2.0 * std::f64::consts::PI).abs()
                < 1e-12
        );
    }

    /// The closed-form blocks against the exact sums over 4096 fitting-like normals.
    #[test]
    fn feature_blocks_match_the_exact_sums() {
        let normals = fibonacci_normals(4096);
        let dirs = [DVec3::Y, DVec3::new(0.5, 0.5, 0.7).normalize(), -DVec3::Z];
        let basis: Vec<(DVec3, DVec3)> = dirs
            .iter()
            .map(|w| {
                let t1 = w.any_orthonormal_vector();
                (t1, w.cross(t1))
            })
            .collect();
        let features = |i: usize, n: DVec3| {
            if n.dot(dirs[i]) > 0.0 {
                [n.dot(dirs[i]), n.dot(basis[i].0), n.dot(basis[i].1)]
            } else {
                [0.0; 3]
            }
        };
        for i in 0..3 {
            for j in 0..3 {
                let block = feature_block(dirs[i], basis[i], dirs[j], basis[j], normals.len());
                for (a, row) in block.iter().enumerate() {
                    for (b, &got) in row.iter().enumerate() {
                        let want: f64 = normals
                            .iter()
                            .map(|&n| features(i, n)[a] * features(j, n)[b])
                            .sum();
                        // Within 0.5 % of the diagonal M / 6: the quadrature error of 4096
                        // normals for functions with a kink (the terminators).
                        assert!(
                            (got - want).abs() < 5e-3 * 4096.0 / 6.0,
                            "{i}{a} {j}{b}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }
}
