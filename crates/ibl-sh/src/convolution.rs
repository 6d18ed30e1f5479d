//! Lambert convolution (Ramamoorthi & Hanrahan 2001) and windows against ringing.
//!
//! By the Funk-Hecke theorem, convolving radiance with the clamped cosine `max(0, n.d)` scales band
//! `l` by `A_l = 2 pi integral_0^1 t P_l(t) dt`:
//!
//! ```text
//! A_0 = pi,   A_1 = 2 pi / 3,   A_l = 0 for odd l > 1,
//! A_l = 2 pi (-1)^(l/2 - 1) / ((l + 2)(l - 1)) * l! / (2^l ((l/2)!)^2)   for even l >= 2
//! ```
//!
//! (`A_2 = pi / 4`). The factorial ratio is built as a running product, so any l is safe.

/// The Lambert factor `A_l` of band `l` (see the module doc).
pub fn lambert_factor(l: usize) -> f64 {
    use std::f64::consts::PI;
    match l {
        0 => PI,
        1 => 2.0 * PI / 3.0,
        _ if l % 2 == 1 => 0.0,
        _ => {
            // l! / (2^l ((l/2)!)^2) = prod_{k=1}^{l/2} (2k - 1) / (2k), the central binomial / 4^(l/2).
            let half = l / 2;
            let ratio: f64 = (1..=half)
                .map(|k| (2 * k - 1) as f64 / (2 * k) as f64)
                .product();
            let sign = if half % 2 == 1 { 1.0 } else { -1.0 }; // (-1)^(l/2 - 1)
            2.0 * PI * sign / ((l + 2) as f64 * (l - 1) as f64) * ratio
        }
    }
}

/// A window applied to the bands of a truncated SH expansion, against ringing (Gibbs
/// oscillations around bright, small sources). `weight(l, bands)` multiplies band `l` of an
/// expansion with `bands` bands; every window keeps band 0 (the average) exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Window {
    /// No windowing: the plain truncated expansion (the best least-squares fit).
    #[default]
    None,
    /// Lanczos sigma factors `sinc(l / bands)`: gentle, the usual choice for irradiance.
    Lanczos,
    /// Hann: `(1 + cos(pi l / bands)) / 2`, stronger smoothing.
    Hann,
}

impl Window {
    /// Weight of band `l` in an expansion of `bands` bands.
    pub fn weight(self, l: usize, bands: usize) -> f64 {
        if l == 0 || bands == 0 {
            return 1.0;
        }
        let x = l as f64 / bands as f64;
        match self {
            Window::None => 1.0,
            Window::Lanczos => {
                let a = std::f64::consts::PI * x;
                a.sin() / a
            }
            Window::Hann => 0.5 * (1.0 + (std::f64::consts::PI * x).cos()),
        }
    }

    /// The window's name as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            Window::None => "none",
            Window::Lanczos => "lanczos",
            Window::Hann => "hann",
        }
    }
}

impl std::str::FromStr for Window {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "none" => Ok(Window::None),
            "lanczos" => Ok(Window::Lanczos),
            "hann" => Ok(Window::Hann),
            other => Err(format!(
                "unknown SH window '{other}' (expected none, lanczos or hann)"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn known_factors() {
        assert_eq!(lambert_factor(0), PI);
        assert!((lambert_factor(1) - 2.0 * PI / 3.0).abs() < 1e-15);
        assert!((lambert_factor(2) - PI / 4.0).abs() < 1e-15);
        assert_eq!(lambert_factor(3), 0.0);
        // A_4 = -pi / 24, A_6 = pi / 64 (Ramamoorthi & Hanrahan 2001).
        assert!((lambert_factor(4) + PI / 24.0).abs() < 1e-15);
        assert!((lambert_factor(6) - PI / 64.0).abs() < 1e-15);
    }

    /// A_l = 2 pi integral_0^1 t P_l(t) dt, by a fine midpoint rule, to l = 30.
    #[test]
    fn factors_match_the_integral() {
        let steps = 200_000;
        for l in 0..=30 {
            let mut integral = 0.0;
            for k in 0..steps {
                let t = (k as f64 + 0.5) / steps as f64;
                let (mut p0, mut p1) = (1.0, t);
                let p = if l == 0 {
                    1.0
                } else {
                    for j in 2..=l {
                        let p2 = ((2 * j - 1) as f64 * t * p1 - (j - 1) as f64 * p0) / j as f64;
                        p0 = p1;
                        p1 = p2;
                    }
                    p1
                };
                integral += t * p / steps as f64;
            }
            let want = 2.0 * PI * integral;
            assert!(
                (lambert_factor(l) - want).abs() < 1e-8,
                "l {l}: {} vs {want}",
                lambert_factor(l)
            );
        }
    }

    #[test]
    fn windows_keep_the_average_and_taper() {
        for w in [Window::None, Window::Lanczos, Window::Hann] {
            assert_eq!(w.weight(0, 3), 1.0);
            assert_eq!(w.name().parse::<Window>(), Ok(w));
        }
        assert!(Window::Hann.weight(2, 3) < Window::Lanczos.weight(2, 3));
        assert!(Window::Lanczos.weight(2, 3) < 1.0);
    }
}
