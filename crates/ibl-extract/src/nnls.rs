//! Non-negative least squares in Gram form (Lawson & Hanson 1974, chapter 23):
//!
//! ```text
//! minimise  1/2 x^T Q x - b^T x   subject to  x >= 0
//! ```
//!
//! with `Q = A^T A` (n x n, symmetric positive semi-definite) and `b = A^T y`, which is
//! `min |A x - y|^2, x >= 0`. The fitted-light methods solve for the lights' powers this way: the
//! irradiance is linear in the powers once the directions are fixed, and powers must not go
//! negative. Working on the Gram matrix keeps every solve n x n however many normals `A` has.
//!
//! Active-set method: add the variable with the most positive gradient to the free set, solve the
//! unconstrained problem on the free set by Cholesky, step back to the feasible boundary when a
//! free variable would go negative. Cost O(n^3) per solve and at most `3 n` outer steps. A tiny
//! ridge (`1e-12` of the mean diagonal) keeps the free-set systems positive definite when lights
//! coincide.
//!
//! Warm start: the fits need powers for many lights of which nearly all end up positive, and
//! adding them one at a time would cost n solves, O(n^4). So the free set starts as every
//! variable: solve, drop the variables that come out non-positive, solve again, until all are
//! positive. That point is optimal on its free set and feasible, which is all the active-set
//! loop needs to start from; it then adds back any variable whose gradient asks for it, so the
//! answer is the same NNLS optimum.

use nalgebra::{DMatrix, DVector};

use crate::cholesky::solve_spd;

/// Solves `min 1/2 x^T Q x - b^T x, x >= 0` (see the module doc). `q` is n x n, `b` has n rows.
/// Returns zeros when `b` has no positive entry (the best non-negative answer then) or `Q` is
/// zero or not finite.
pub fn nnls_gram(q: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = b.len();
    let mut x = DVector::zeros(n);
    if n == 0 || q.nrows() != n || q.ncols() != n {
        return x;
    }
    let mean_diag = (0..n).map(|i| q[(i, i)].abs()).sum::<f64>() / n as f64;
    if !(mean_diag.is_finite() && mean_diag > 0.0) {
        return x; // Q = 0: nothing to fit (or not a valid Gram matrix).
    }
    let ridge = 1e-12 * mean_diag;
    let scale = b.amax().max(f64::MIN_POSITIVE);
    let tol = 1e-13 * scale;
    let mut free = warm_start(q, b, ridge, &mut x);
    for _ in 0..3 * n {
        // Gradient of the negative objective: w = b - Q x.
        let w = b - q * &x;
        let Some((j, _)) = (0..n)
            .filter(|&j| !free[j] && w[j] > tol)
            .map(|j| (j, w[j]))
            .max_by(|a, b| a.1.total_cmp(&b.1))
        else {
            break;
        };
        free[j] = true;
        for _ in 0..=n {
            let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
            let Some(z) = solve_subset(q, b, &idx, ridge) else {
                free[j] = false;
                break;
            };
            if z.iter().all(|&v| v > 0.0) {
                for (k, &i) in idx.iter().enumerate() {
                    x[i] = z[k];
                }
                break;
            }
            // Step from x towards z until the first free variable reaches zero (x >= 0 >= z
            // there, so the ratio lies in [0, 1]); those variables leave the free set.
            let alpha = idx
                .iter()
                .zip(&z)
                .filter(|&(_, &zk)| zk <= 0.0)
                .map(|(&i, &zk)| x[i] / (x[i] - zk).max(f64::MIN_POSITIVE))
                .fold(1.0f64, f64::min);
            for (k, &i) in idx.iter().enumerate() {
                let before = x[i];
                x[i] += alpha * (z[k] - before);
                if x[i] <= 1e-12 * before.abs().max(z[k].abs()) {
                    x[i] = 0.0;
                    free[i] = false;
                }
            }
        }
    }
    x.iter_mut()
        .for_each(|v| *v = if v.is_finite() { v.max(0.0) } else { 0.0 });
    x
}

/// The warm start (see the module doc): the largest free set, from all variables down, whose
/// unconstrained solution is positive; `x` gets that solution. Empty (and `x = 0`) if none is
/// found or a system is not positive definite.
fn warm_start(q: &DMatrix<f64>, b: &DVector<f64>, ridge: f64, x: &mut DVector<f64>) -> Vec<bool> {
    let n = b.len();
    let mut free = vec![true; n];
    loop {
        let idx: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
        if idx.is_empty() {
            return free;
        }
        let Some(z) = solve_subset(q, b, &idx, ridge) else {
            return vec![false; n];
        };
        if z.iter().all(|&v| v > 0.0) {
            for (k, &i) in idx.iter().enumerate() {
                x[i] = z[k];
            }
            return free;
        }
        for (k, &i) in idx.iter().enumerate() {
            if z[k] <= 0.0 {
                free[i] = false;
            }
        }
    }
}

/// Solves `Q_SS z = b_S` on the index subset `S` (with a ridge); `None` if not positive definite.
fn solve_subset(q: &DMatrix<f64>, b: &DVector<f64>, idx: &[usize], ridge: f64) -> Option<Vec<f64>> {
    let k = idx.len();
    let sub = DMatrix::from_fn(k, k, |r, c| {
        q[(idx[r], idx[c])] + if r == c { ridge } else { 0.0 }
    });
    let rhs = DVector::from_fn(k, |r, _| b[idx[r]]);
    let z = solve_spd(&sub, &rhs)?;
    Some(z.iter().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gram(a: &DMatrix<f64>, y: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        (a.transpose() * a, a.transpose() * y)
    }

    #[test]
    fn unconstrained_optimum_when_positive() {
        let a = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 2.0, 1.0]);
        let x_true = DVector::from_vec(vec![2.0, 3.0]);
        let y = &a * &x_true;
        let (q, b) = gram(&a, &y);
        let x = nnls_gram(&q, &b);
        assert!((x - x_true).amax() < 1e-10);
    }

    #[test]
    fn clamps_to_zero_where_the_optimum_is_negative() {
        // y wants x1 = -1: the constrained optimum puts x1 = 0 and fits x0 alone.
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 0.0]);
        let y = DVector::from_vec(vec![1.0, -1.0, 1.0]);
        let (q, b) = gram(&a, &y);
        let x = nnls_gram(&q, &b);
        assert!((x[0] - 1.0).abs() < 1e-12 && x[1] == 0.0, "{x}");
    }

    #[test]
    fn kkt_conditions_hold_on_a_random_problem() {
        // Deterministic pseudo-random A and y.
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let a = DMatrix::from_fn(40, 12, |_, _| rnd());
        let y = DVector::from_fn(40, |_, _| rnd());
        let (q, b) = gram(&a, &y);
        let x = nnls_gram(&q, &b);
        let w = &b - &q * &x;
        for i in 0..12 {
            assert!(x[i] >= 0.0);
            if x[i] > 0.0 {
                assert!(w[i].abs() < 1e-9, "free gradient {}", w[i]);
            } else {
                assert!(w[i] < 1e-9, "bound gradient {}", w[i]);
            }
        }
    }

    #[test]
    fn empty_and_degenerate_inputs() {
        assert_eq!(
            nnls_gram(&DMatrix::zeros(0, 0), &DVector::zeros(0)).len(),
            0
        );
        let x = nnls_gram(
            &DMatrix::zeros(3, 3),
            &DVector::from_vec(vec![1.0, 0.0, -1.0]),
        );
        assert!(x.iter().all(|v| v.is_finite() && *v >= 0.0));
    }
}
