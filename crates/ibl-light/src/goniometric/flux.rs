//! Luminous flux of a candela table: the exact integral over the sphere of its bilinear
//! interpolant ([`super::interpolate`]), `Phi = int_0^2pi int_0^pi I(gamma, C) sin gamma dgamma dC`
//! (lm from cd, solid angle `dOmega = sin gamma dgamma dC`).
//!
//! In a cell the interpolant is linear in `C` for fixed `gamma`, so integrating over
//! `[C_j, C_j+1]` gives `(C_j+1 - C_j) (I_j(gamma) + I_j+1(gamma)) / 2`, where `I_j(gamma)` is
//! column `j` interpolated linearly in `gamma`. For a linear `f` on `[p, q]` with `f(p) = a`,
//! `f(q) = b`, `h = q - p`:
//!
//! `int_p^q f(gamma) sin gamma dgamma = a S0 + (b - a) S1 / h`, with
//! `S0 = cos p - cos q` and `S1 = int_p^q (gamma - p) sin gamma dgamma = sin q - sin p - h cos q`.
//!
//! Nothing is sampled, so the result is the interpolant's flux to rounding whatever the grid.
//! A plain sum of the samples times solid angles is not: on a coarse file its weights near the
//! nadir (where `sin gamma` vanishes) and at the edges of the measured range are badly off.

use super::CandelaTable;

/// `int_p^q f(gamma) sin gamma dgamma` for the linear `f` with `f(p) = a`, `f(q) = b` (radians).
fn linear_times_sine(p: f64, q: f64, a: f64, b: f64) -> f64 {
    let h = q - p;
    if h <= 0.0 {
        return 0.0;
    }
    let s0 = p.cos() - q.cos();
    let s1 = q.sin() - p.sin() - h * q.cos();
    a * s0 + (b - a) * s1 / h
}

impl CandelaTable {
    /// The luminous flux, lm: the exact integral of the interpolated intensity over the sphere.
    pub fn flux(&self) -> f64 {
        self.flux_between_deg(0.0, 180.0)
    }

    /// The flux, lm, into the zone of vertical angles `from_deg..to_deg` (degrees from the
    /// nadir; `0..90` is the downward flux). 0 for an empty or reversed zone.
    pub fn flux_between_deg(&self, from_deg: f64, to_deg: f64) -> f64 {
        let v = self.vertical_deg();
        // Per column, `int I_h(gamma) sin gamma dgamma` over the zone.
        let column_integral = |h: usize| -> f64 {
            let value = |k: usize| f64::from(self.values()[h * v.len() + k]);
            (0..v.len() - 1)
                .map(|i| {
                    let (g0, g1) = (f64::from(v[i]), f64::from(v[i + 1]));
                    let (p, q) = (g0.max(from_deg), g1.min(to_deg));
                    if p >= q {
                        return 0.0;
                    }
                    let at = |g: f64| value(i) + (value(i + 1) - value(i)) * (g - g0) / (g1 - g0);
                    linear_times_sine(p.to_radians(), q.to_radians(), at(p), at(q))
                })
                .sum()
        };
        if self.is_rotationally_symmetric() {
            return std::f64::consts::TAU * column_integral(0);
        }
        let h = self.horizontal_deg();
        let columns: Vec<f64> = (0..h.len()).map(column_integral).collect();
        (0..h.len() - 1)
            .map(|j| f64::from(h[j + 1] - h[j]).to_radians() * (columns[j] + columns[j + 1]) / 2.0)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    #[test]
    fn an_isotropic_point_has_four_pi_lumens_per_candela() {
        // Linear interpolation of a constant is exact, so only rounding remains (1e-9 relative).
        let t = CandelaTable::new(vec![0.0, 37.0, 90.0, 180.0], vec![0.0], vec![3.0; 4]).unwrap();
        assert!((t.flux() / (4.0 * PI * 3.0) - 1.0).abs() < 1e-9);
        assert!((t.flux_between_deg(0.0, 90.0) / (2.0 * PI * 3.0) - 1.0).abs() < 1e-9);
        let h = vec![0.0, 10.0, 200.0, 360.0];
        let full = CandelaTable::new(vec![0.0, 180.0], h, vec![3.0; 8]).unwrap();
        assert!((full.flux() / (4.0 * PI * 3.0) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_lambertian_downlight_has_pi_i0() {
        // I = I0 cos gamma sampled every `step` degrees over 0..90. Linear interpolation of cos
        // errs by at most h^2/8 max|cos''| = h^2 I0 / 8, so the flux, 2 pi int I sin over 0..pi/2,
        // errs by at most 2 pi h^2 I0 / 8: relative to pi I0 that is h^2 / 4.
        let step = 5.0_f32;
        let v: Vec<f32> = (0..=18).map(|i| i as f32 * step).collect();
        // (cos 90 degrees is -4e-8 in f32: clamped, a table holds no negative candela.)
        let cd: Vec<f32> = v
            .iter()
            .map(|g| (1000.0 * g.to_radians().cos()).max(0.0))
            .collect();
        let t = CandelaTable::new(v, vec![0.0], cd).unwrap();
        let h = f64::from(step).to_radians();
        let error = t.flux() / (PI * 1000.0) - 1.0;
        assert!(error.abs() <= h * h / 4.0, "{error}");
        assert!(error < 0.0, "the chords of a concave cos lie below it");
    }

    #[test]
    fn zones_add_up() {
        let t = CandelaTable::new(
            vec![0.0, 30.0, 95.0, 180.0],
            vec![0.0, 120.0, 360.0],
            vec![1.0, 5.0, 2.0, 0.0, 4.0, 1.0, 1.0, 3.0, 1.0, 5.0, 2.0, 0.0],
        )
        .unwrap();
        let parts = t.flux_between_deg(0.0, 17.0)
            + t.flux_between_deg(17.0, 90.0)
            + t.flux_between_deg(90.0, 180.0);
        assert!((parts / t.flux() - 1.0).abs() < 1e-12);
        assert_eq!(t.flux_between_deg(50.0, 40.0), 0.0);
    }
}
