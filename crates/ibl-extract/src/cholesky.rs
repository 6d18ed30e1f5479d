//! Blocked Cholesky factorisation `A = L L^T` of a symmetric positive definite matrix, and the
//! solve `A x = b` with it.
//!
//! Why our own: nalgebra's `Cholesky` is a left-looking column loop (one `axpy` per pair of
//! columns), memory-bound at about 1 GFLOP/s, so the 1280 x 1280 Gauss-Newton systems of a
//! 256-light fit took about half a second each. This right-looking blocked variant factors
//! [`BLOCK`]-wide diagonal blocks with nalgebra, inverts each small triangular factor so the panel
//! below is one matrix product, and updates only the lower triangle of the trailing matrix, in
//! column blocks of [`UPDATE_COLUMNS`] that run in parallel, each one matrix product
//! (`matrixmultiply`'s kernels). Almost all of the `n^3 / 3` flops run at matrix-product speed.
//! Deterministic: the column blocks are fixed, so the result does not depend on the thread count.

use nalgebra::{DMatrix, DMatrixViewMut, DVector};
use rayon::prelude::*;

/// Width of the diagonal blocks.
const BLOCK: usize = 64;

/// Columns per parallel block of the trailing update.
const UPDATE_COLUMNS: usize = 128;

/// The lower Cholesky factor `L` of `a` (only its lower triangle is read), or `None` when `a` is
/// not (numerically) positive definite. Cost O(n^3 / 3).
pub fn cholesky_lower(mut a: DMatrix<f64>) -> Option<DMatrix<f64>> {
    cholesky_in_place(&mut a).then_some(a)
}

/// Factors `a` in place into its lower Cholesky factor (only the lower triangle of `a` is read;
/// the upper is zeroed), so a caller can reuse one buffer. False, with `a` overwritten, when it
/// is not (numerically) positive definite or not square. Cost O(n^3 / 3).
pub fn cholesky_in_place(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    if a.ncols() != n {
        return false;
    }
    let mut k0 = 0;
    while k0 < n {
        let kb = BLOCK.min(n - k0);
        let Some(lkk) = a.view((k0, k0), (kb, kb)).clone_owned().cholesky() else {
            return false;
        };
        let lkk = lkk.unpack();
        if !lkk.iter().all(|v| v.is_finite()) {
            return false;
        }
        a.view_mut((k0, k0), (kb, kb)).copy_from(&lkk);
        let rest = n - k0 - kb;
        if rest > 0 {
            // Panel X solves X L_kk^T = A_panel: X = A_panel L_kk^-T.
            let mut inverse = DMatrix::identity(kb, kb);
            if !lkk.solve_lower_triangular_mut(&mut inverse) {
                return false;
            }
            let x = a.view((k0 + kb, k0), (rest, kb)) * inverse.transpose();
            if !x.iter().all(|v| v.is_finite()) {
                return false;
            }
            a.view_mut((k0 + kb, k0), (rest, kb)).copy_from(&x);
            // Trailing lower triangle -= X X^T, by column blocks.
            let first = k0 + kb;
            a.as_mut_slice()[first * n..]
                .par_chunks_mut(UPDATE_COLUMNS * n)
                .enumerate()
                .for_each(|(b, cols)| {
                    let c0 = b * UPDATE_COLUMNS; // first column of the block, within the trailing
                    let width = cols.len() / n;
                    let mut block = DMatrixViewMut::from_slice(cols, n, width);
                    let mut below = block.rows_mut(first + c0, rest - c0);
                    below.gemm(
                        -1.0,
                        &x.rows(c0, rest - c0),
                        &x.rows(c0, width).transpose(),
                        1.0,
                    );
                });
        }
        k0 += kb;
    }
    // Clear the (stale) upper triangle so the factor is a true lower-triangular matrix.
    for c in 1..n {
        for r in 0..c {
            a[(r, c)] = 0.0;
        }
    }
    true
}

/// Solves `L L^T x = b` for a lower factor from [`cholesky_lower`].
pub fn cholesky_solve(l: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let y = l.solve_lower_triangular(b)?;
    l.tr_solve_lower_triangular(&y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_nalgebra_on_a_random_spd_matrix() {
        let mut s = 99u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for n in [1usize, 5, 64, 65, 150, 300] {
            let g = DMatrix::from_fn(n + 7, n, |_, _| rnd());
            let a = g.transpose() * &g + DMatrix::identity(n, n) * 0.1;
            let b = DVector::from_fn(n, |_, _| rnd());
            let l = cholesky_lower(a.clone()).unwrap();
            assert!(
                (&l * l.transpose() - &a).amax() < 1e-10 * a.amax(),
                "n = {n}"
            );
            let x = cholesky_solve(&l, &b).unwrap();
            let want = a.clone().cholesky().unwrap().solve(&b);
            assert!((x - want).amax() < 1e-9, "n = {n}");
        }
    }

    #[test]
    fn reads_only_the_lower_triangle() {
        let n = 150;
        let g = DMatrix::from_fn(n + 3, n, |r, c| ((r * 7 + c * 13) % 11) as f64 - 5.0);
        let a = g.transpose() * &g + DMatrix::identity(n, n);
        let mut garbage = a.clone();
        for c in 1..n {
            for r in 0..c {
                garbage[(r, c)] = 1e30 * (r + c) as f64;
            }
        }
        assert!(cholesky_in_place(&mut garbage));
        assert_eq!(garbage, cholesky_lower(a).unwrap());
    }

    #[test]
    fn rejects_indefinite_and_non_square() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(cholesky_lower(a).is_none());
        assert!(cholesky_lower(DMatrix::zeros(2, 3)).is_none());
        let big = DMatrix::from_fn(100, 100, |r, c| if r == c { -1.0 } else { 0.0 });
        assert!(cholesky_lower(big).is_none());
    }
}
