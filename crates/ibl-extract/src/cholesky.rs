//! Solving a symmetric positive definite system `A x = b` by Cholesky factorisation
//! `A = L L^T`, with faer's `llt`.
//!
//! Why faer: the Gauss-Newton systems of irradiance optimisation are `5N x 5N` (1280 x 1280 for
//! 256 lights). nalgebra's `Cholesky` is a left-looking column loop at about 1 GFLOP/s; a
//! right-looking blocked variant of our own (matrix-product updates in parallel) was 2.4x to 3x
//! faster than that, and faer's `llt` is faster again by 1.2x to 1.9x (BENCHMARKS.md, "Cholesky":
//! `cargo bench -p ibl-extract --bench cholesky`), so the blocked code was removed.

use faer::linalg::solvers::Solve;
use nalgebra::{DMatrix, DVector};

/// Solves `a x = b` for a symmetric positive definite `a` (only its lower triangle is read), or
/// `None` when `a` is not square, does not match `b`, or is not (numerically) positive definite.
/// Cost O(n^3 / 3) for the factorisation and O(n^2) for the two triangular solves.
pub fn solve_spd(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let n = a.nrows();
    if a.ncols() != n || b.len() != n {
        return None;
    }
    let fa = faer::MatRef::from_column_major_slice(a.as_slice(), n, n);
    let llt = fa.llt(faer::Side::Lower).ok()?;
    let fb = faer::MatRef::from_column_major_slice(b.as_slice(), n, 1);
    let x = llt.solve(fb);
    let x = DVector::from_fn(n, |i, _| x[(i, 0)]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded random SPD matrix `G^T G + 0.1 I` of size n, and a right-hand side.
    fn system(n: usize, seed: u64) -> (DMatrix<f64>, DVector<f64>) {
        let mut s = seed;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let g = DMatrix::from_fn(n + 7, n, |_, _| rnd());
        let a = g.transpose() * &g + DMatrix::identity(n, n) * 0.1;
        let b = DVector::from_fn(n, |_, _| rnd());
        (a, b)
    }

    #[test]
    fn matches_nalgebra_on_random_spd_matrices() {
        for n in [1usize, 5, 64, 65, 150, 300] {
            let (a, b) = system(n, 99 + n as u64);
            let x = solve_spd(&a, &b).unwrap();
            let want = a.clone().cholesky().unwrap().solve(&b);
            // Both are backward stable: the solutions agree to cond(A) ulps; these systems have
            // cond(A) below 1e4 (smallest eigenvalue >= 0.1, largest below 1e3), so 1e-9.
            assert!((&x - want).amax() < 1e-9, "n = {n}");
            // The residual of a backward-stable solve: n ulps of |A| |x|.
            assert!((&a * &x - &b).amax() < 1e-9, "n = {n}");
        }
    }

    #[test]
    fn reads_only_the_lower_triangle() {
        let (a, b) = system(150, 7);
        let mut garbage = a.clone();
        for c in 1..150 {
            for r in 0..c {
                garbage[(r, c)] = 1e30 * (r + c) as f64;
            }
        }
        assert_eq!(solve_spd(&garbage, &b), solve_spd(&a, &b));
    }

    #[test]
    fn rejects_indefinite_non_square_and_mismatched() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        assert!(solve_spd(&a, &DVector::zeros(2)).is_none());
        assert!(solve_spd(&DMatrix::zeros(2, 3), &DVector::zeros(2)).is_none());
        let big = DMatrix::from_fn(100, 100, |r, c| if r == c { -1.0 } else { 0.0 });
        assert!(solve_spd(&big, &DVector::zeros(100)).is_none());
        let (a, _) = system(4, 3);
        assert!(solve_spd(&a, &DVector::zeros(5)).is_none());
    }
}
