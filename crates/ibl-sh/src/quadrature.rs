//! Gauss-Legendre quadrature on [-1, 1]: `n` nodes integrate polynomials of degree `2n - 1`
//! exactly. Nodes by Newton's method on the Legendre recurrence from Tricomi's initial guesses
//! (at most 100 steps each; they converge in a handful). Cost O(n^2).

/// `(node, weight)` pairs of the `n`-point rule on [-1, 1].
pub(crate) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut weight = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                weight = 2.0 / ((1.0 - x * x) * dp * dp);
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (x, weight)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        for n in [1usize, 2, 5, 16, 40] {
            let rule = gauss_legendre(n);
            assert!(
                (rule.iter().map(|r| r.1).sum::<f64>() - 2.0).abs() < 1e-13,
                "n {n}"
            );
            // x^(2n-2) integrates to 2 / (2n - 1).
            let k = 2 * n - 2;
            let got: f64 = rule.iter().map(|&(x, w)| w * x.powi(k as i32)).sum();
            assert!((got - 2.0 / (k as f64 + 1.0)).abs() < 1e-12, "n {n}: {got}");
        }
    }
}
