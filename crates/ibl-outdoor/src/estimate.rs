//! Per-frame estimation of the sun's and the sky's RGB intensity from samples on diffuse
//! surfaces (Jensen, Andersen & Madsen 2006, section 3.1 and the equation of section 4.2).
//!
//! Each sample `i` is a pixel of the frame on a marked diffuse surface, with its observed
//! radiance `P_i`, the albedo `d_i` the offline inverse rendering found there, its sky term
//! `c_i` (the weighted ambient, or `c_shape` for a sky with structure: [`crate::transfer`]) and
//! its sun term `k_i = s_i max(0, n_i . l)` (shadow times cosine), and, when the model keeps
//! interreflections ([`crate::interreflection`]), the light other surfaces reflect onto it per
//! unit `P_a` and `P_d`, `b_a,i` and `b_d,i`. Per channel the model is
//!
//! ```text
//! P_i = d_i (c_i P_a + k_i P_d + b_a,i P_a + b_d,i P_d)   =>   y_i = P_i / d_i = u_i P_a + v_i P_d
//! ```
//!
//! (`u = c + b_a`, `v = k + b_d`), linear in the two unknowns, solved by weighted least squares with `P_a, P_d >= 0` (the
//! two-variable active set: the unconstrained solution, else the better of the two one-variable
//! fits). Pixel noise (photon, compression, path-tracing) grows with the signal, so each
//! residual is taken relative to its prediction: weights `1 / max(y_hat_i, f)^2`, `f` 5 % of the
//! median prediction.
//!
//! **Robustness** (people, glints, penumbrae, albedo errors at texture edges): iteratively
//! reweighted least squares (Holland & Welsch 1977). The three channels share one weight per
//! sample, from the root-mean-square of its relative residuals `e_i`, scaled by the robust
//! spread `sigma = median(e) / 0.888` (the median of `sqrt(chi^2_3 / 3)`: `sigma` is then the
//! per-channel relative noise for Gaussian residuals), taken separately for sunlit and shaded
//! samples: a shaded pixel gets a fraction of the light and so a larger relative noise, and one
//! scale for both would reject the shade, which is what pins `P_a`. Each sample's least-squares
//! weight is `1 / (sigma_class y_hat)^2` times its robust weight. The first iterations use Huber's loss
//! (`k = 1.345`, convex, so the start cannot fall into a bad local minimum), the rest Tukey's
//! biweight (`c = 4.685`, which gives gross outliers zero weight); both are the 95 %-efficiency
//! constants of the Gaussian case.
//!
//! **Confidence.** Per channel the covariance `sigma_r^2 (X^T W X)^-1` of the final weighted fit
//! (`sigma_r^2` the weighted residual variance over `n - 2` degrees of freedom) gives standard
//! errors and the sun-sky correlation; the conditioning is that of `X^T W X` with unit diagonal,
//! `(1 + |rho|) / (1 - |rho|)`. The sun is **observable** only when enough inliers are sunlit
//! and the conditioning is bounded: samples that are all in shadow (or all with the same ratio
//! of sun to sky term) cannot separate `P_d` from `P_a`. Then the sky is fitted alone, `P_d` is
//! reported as 0 with an infinite standard error, and the caller keeps its previous sun.
//! Under a heavy overcast the sunlit and shaded samples look alike and the fit returns `P_d`
//! near 0, as the paper reports.

use ibl_core::Rgb;
use serde::Serialize;

use crate::OutdoorError;

/// One sample of the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    /// Observed radiance `P` (the frame's pixel).
    pub observed: Rgb,
    /// Diffuse albedo `d` there.
    pub albedo: Rgb,
    /// Sky term `c` (weighted ambient, or `c_shape`), per channel.
    pub sky_term: Rgb,
    /// Sun term `s max(0, n . l)` (direct sunlight only: it decides whether the sample is
    /// sunlit).
    pub sun_term: f32,
    /// Light reflected onto the sample by other surfaces per unit `P_a`, `b_a` (0 without
    /// interreflections).
    pub indirect_sky: Rgb,
    /// The same per unit `P_d`, `b_d`.
    pub indirect_sun: Rgb,
}

/// Options of the robust fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorOptions {
    /// IRLS iterations at most (the first [`Self::huber_iterations`] with Huber's loss).
    pub max_iterations: u32,
    /// Iterations with Huber's loss before Tukey's biweight takes over (0: Tukey from the start).
    pub huber_iterations: u32,
    /// Samples whose albedo is below this in a channel are not used (their `P / d` is noise).
    pub min_albedo: f32,
    /// Sunlit inliers needed for the sun to count as observable.
    pub min_sunlit: usize,
    /// Largest conditioning of the two-column system for the sun to count as observable.
    pub max_condition: f64,
}

impl Default for EstimatorOptions {
    fn default() -> Self {
        EstimatorOptions {
            max_iterations: 40,
            huber_iterations: 6,
            min_albedo: 0.02,
            min_sunlit: 20,
            max_condition: 1.0e4,
        }
    }
}

/// The estimate for one frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// `P_d`, the sun's parameter (`E_sun / pi`: radiance of a white surface facing the sun).
    pub sun: [f32; 3],
    /// `P_a`, the sky's parameter (the radiance of a uniform sky of the same horizontal
    /// irradiance).
    pub sky: [f32; 3],
    /// Standard error of `P_d` per channel (infinite when the sun is not observable).
    pub sun_std: [f32; 3],
    /// Standard error of `P_a` per channel.
    pub sky_std: [f32; 3],
    /// Correlation of the `P_d` and `P_a` errors per channel.
    pub correlation: [f32; 3],
    /// Conditioning of the weighted two-column system (green channel), 1 = orthogonal columns.
    pub condition: f64,
    /// Whether the samples could separate the sun from the sky.
    pub sun_observable: bool,
    /// Samples used (after the albedo test).
    pub samples: usize,
    /// Samples with a non-zero final weight.
    pub inliers: usize,
    /// Inliers in direct sunlight (`k > 0`).
    pub sunlit_inliers: usize,
    /// Robust relative spread of the residuals (per channel, Gaussian-equivalent) of the sunlit
    /// and of the shaded samples.
    pub residual_spread: [f32; 2],
    /// IRLS iterations run.
    pub iterations: u32,
}

impl Estimate {
    /// `P_d` as RGB.
    pub fn sun_rgb(&self) -> Rgb {
        Rgb::from_array(self.sun)
    }

    /// `P_a` as RGB.
    pub fn sky_rgb(&self) -> Rgb {
        Rgb::from_array(self.sky)
    }
}

/// Normal-equation sums of one channel.
#[derive(Clone, Copy, Default)]
struct Sums {
    uu: f64,
    uv: f64,
    vv: f64,
    uy: f64,
    vy: f64,
    yy: f64,
}

impl Sums {
    fn add(&mut self, w: f64, u: f64, v: f64, y: f64) {
        self.uu += w * u * u;
        self.uv += w * u * v;
        self.vv += w * v * v;
        self.uy += w * u * y;
        self.vy += w * v * y;
        self.yy += w * y * y;
    }

    fn objective(&self, a: f64, b: f64) -> f64 {
        self.yy - 2.0 * (a * self.uy + b * self.vy)
            + a * a * self.uu
            + 2.0 * a * b * self.uv
            + b * b * self.vv
    }

    /// `argmin (a, b) >= 0`; `sun` false fits `a` alone with `b = 0`.
    fn solve(&self, sun: bool) -> (f64, f64) {
        let sky_only = (
            if self.uu > 0.0 {
                (self.uy / self.uu).max(0.0)
            } else {
                0.0
            },
            0.0,
        );
        if !sun {
            return sky_only;
        }
        let det = self.uu * self.vv - self.uv * self.uv;
        if det > 1e-12 * self.uu * self.vv {
            let a = (self.uy * self.vv - self.vy * self.uv) / det;
            let b = (self.vy * self.uu - self.uy * self.uv) / det;
            if a >= 0.0 && b >= 0.0 {
                return (a, b);
            }
        }
        let sun_only = (
            0.0,
            if self.vv > 0.0 {
                (self.vy / self.vv).max(0.0)
            } else {
                0.0
            },
        );
        if self.objective(sun_only.0, sun_only.1) < self.objective(sky_only.0, sky_only.1) {
            sun_only
        } else {
            sky_only
        }
    }
}

/// A sample ready for the fit: `y = P / d` and the two columns per channel, and whether it is
/// in direct sunlight.
struct Row {
    y: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    sunlit: bool,
}

fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mid = values.len() / 2;
    let (_, m, _) = values.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    *m
}

/// Huber's and Tukey's 95 %-efficiency constants.
const HUBER_K: f64 = 1.345;
const TUKEY_C: f64 = 4.685;
/// Median of `sqrt(chi^2_3 / 3)`: turns the median RMS residual into a per-channel sigma.
const RMS3_MEDIAN: f64 = 0.8880;

/// Estimates `P_d` and `P_a` from `observations` (see the module doc).
pub fn estimate(
    observations: &[Observation],
    options: &EstimatorOptions,
) -> Result<Estimate, OutdoorError> {
    let rows: Vec<Row> = observations
        .iter()
        .filter(|o| {
            o.albedo
                .to_array()
                .iter()
                .all(|&a| a >= options.min_albedo && a.is_finite())
                && o.observed.is_valid_radiance()
                && o.sky_term.is_valid_radiance()
                && o.sun_term.is_finite()
                && o.sun_term >= 0.0
                && o.indirect_sky.is_valid_radiance()
                && o.indirect_sun.is_valid_radiance()
        })
        .map(|o| {
            let (p, d, c) = (
                o.observed.to_array(),
                o.albedo.to_array(),
                o.sky_term.to_array(),
            );
            let (ba, bd) = (o.indirect_sky.to_array(), o.indirect_sun.to_array());
            Row {
                y: [0, 1, 2].map(|k| f64::from(p[k]) / f64::from(d[k])),
                u: [0, 1, 2].map(|k| f64::from(c[k]) + f64::from(ba[k])),
                v: [0, 1, 2].map(|k| f64::from(o.sun_term) + f64::from(bd[k])),
                sunlit: o.sun_term > 0.0,
            }
        })
        .collect();
    if rows.len() < 3 {
        return Err(OutdoorError::Parameter(format!(
            "{} usable samples (of {}): at least 3 are needed (albedo at least {} in every channel)",
            rows.len(),
            observations.len(),
            options.min_albedo
        )));
    }
    let n = rows.len();
    let sunlit_total = rows.iter().filter(|r| r.sunlit).count();
    let mut sun_allowed = sunlit_total >= options.min_sunlit;
    let mut robust = vec![1.0f64; n];
    let mut params = [(0.0f64, 0.0f64); 3];
    let mut sigma = [0.0f64; 2];
    let mut iterations = 0;
    // Relative weights: none in the first, ordinary least-squares fit.
    let mut relative: Vec<[f64; 3]> = vec![[1.0; 3]; n];
    for it in 0..options.max_iterations.max(1) {
        iterations = it + 1;
        let mut next = [(0.0, 0.0); 3];
        for (c, p) in next.iter_mut().enumerate() {
            let mut s = Sums::default();
            for ((r, w), h) in rows.iter().zip(&robust).zip(&relative) {
                s.add(w * h[c], r.u[c], r.v[c], r.y[c]);
            }
            *p = s.solve(sun_allowed);
        }
        // Predictions, relative residuals, robust scale.
        let predictions: Vec<[f64; 3]> = rows
            .iter()
            .map(|r| [0, 1, 2].map(|c| next[c].0 * r.u[c] + next[c].1 * r.v[c]))
            .collect();
        let floors: [f64; 3] = [0, 1, 2].map(|c| {
            let mut p: Vec<f64> = predictions.iter().map(|p| p[c]).collect();
            (0.05 * median(&mut p)).max(1e-12)
        });
        let rms: Vec<f64> = rows
            .iter()
            .zip(&predictions)
            .map(|(r, p)| {
                let sq: f64 = (0..3)
                    .map(|c| ((r.y[c] - p[c]) / p[c].max(floors[c])).powi(2))
                    .sum();
                (sq / 3.0).sqrt()
            })
            .collect();
        // One robust scale per noise class: sunlit samples (k > 0) and shaded ones, whose
        // relative noise is larger (less light); a class of fewer than 5 borrows the other's.
        let class_sigma = |lit: bool| -> Option<f64> {
            let mut e: Vec<f64> = rows
                .iter()
                .zip(&rms)
                .filter(|(r, _)| r.sunlit == lit)
                .map(|(_, e)| *e)
                .collect();
            (e.len() >= 5).then(|| (median(&mut e) / RMS3_MEDIAN).max(1e-9))
        };
        let (lit_sigma, shade_sigma) = (class_sigma(true), class_sigma(false));
        sigma = [
            lit_sigma.or(shade_sigma).unwrap_or(1e-9),
            shade_sigma.or(lit_sigma).unwrap_or(1e-9),
        ];
        for ((w, e), r) in robust.iter_mut().zip(&rms).zip(&rows) {
            let u = e / sigma[usize::from(!r.sunlit)];
            *w = if it < options.huber_iterations {
                if u <= HUBER_K { 1.0 } else { HUBER_K / u }
            } else if u < TUKEY_C {
                (1.0 - (u / TUKEY_C).powi(2)).powi(2)
            } else {
                0.0
            };
        }
        for ((h, p), r) in relative.iter_mut().zip(&predictions).zip(&rows) {
            let class = sigma[usize::from(!r.sunlit)];
            *h = [0, 1, 2].map(|c| 1.0 / (class * p[c].max(floors[c])).powi(2));
        }
        let change = (0..3)
            .map(|c| {
                let scale = next[c].0.abs() + next[c].1.abs() + 1e-30;
                ((next[c].0 - params[c].0).abs() + (next[c].1 - params[c].1).abs()) / scale
            })
            .fold(0.0f64, f64::max);
        params = next;
        if it >= options.huber_iterations + 2 && change < 1e-7 {
            break;
        }
    }
    // Observability and the final covariance, with the final weights.
    let inliers = robust.iter().filter(|&&w| w > 0.0).count();
    let sunlit_inliers = rows
        .iter()
        .zip(&robust)
        .filter(|(r, w)| r.sunlit && **w > 0.0)
        .count();
    let mut condition = f64::INFINITY;
    let mut sun_std = [f32::INFINITY; 3];
    let mut sky_std = [f32::INFINITY; 3];
    let mut correlation = [0.0f32; 3];
    for c in [1, 0, 2] {
        let mut s = Sums::default();
        let mut wsum = 0.0;
        let mut rss = 0.0;
        for ((r, w), h) in rows.iter().zip(&robust).zip(&relative) {
            let weight = w * h[c];
            s.add(weight, r.u[c], r.v[c], r.y[c]);
            let res = r.y[c] - params[c].0 * r.u[c] - params[c].1 * r.v[c];
            rss += weight * res * res;
            wsum += w;
        }
        let dof = (wsum - 2.0).max(1.0);
        let var = rss / dof;
        let det = s.uu * s.vv - s.uv * s.uv;
        if c == 1 {
            let rho = if s.uu > 0.0 && s.vv > 0.0 {
                s.uv / (s.uu * s.vv).sqrt()
            } else {
                1.0
            };
            condition = if rho.abs() < 1.0 {
                (1.0 + rho.abs()) / (1.0 - rho.abs())
            } else {
                f64::INFINITY
            };
            if sun_allowed
                && (sunlit_inliers < options.min_sunlit
                    || condition.is_nan()
                    || condition > options.max_condition)
            {
                sun_allowed = false;
            }
        }
        if sun_allowed && det > 0.0 {
            let (ia, ib, iab) = (s.vv / det, s.uu / det, -s.uv / det);
            sky_std[c] = (var * ia).sqrt() as f32;
            sun_std[c] = (var * ib).sqrt() as f32;
            correlation[c] = (iab / (ia * ib).sqrt()) as f32;
        } else if s.uu > 0.0 {
            sky_std[c] = (var / s.uu).sqrt() as f32;
        }
    }
    if !sun_allowed {
        // Refit the sky alone with the final weights.
        for (c, p) in params.iter_mut().enumerate() {
            let mut s = Sums::default();
            for ((r, w), h) in rows.iter().zip(&robust).zip(&relative) {
                s.add(w * h[c], r.u[c], r.v[c], r.y[c]);
            }
            *p = s.solve(false);
        }
    }
    Ok(Estimate {
        sun: params.map(|p| p.1 as f32),
        sky: params.map(|p| p.0 as f32),
        sun_std,
        sky_std,
        correlation,
        condition,
        sun_observable: sun_allowed,
        samples: n,
        inliers,
        sunlit_inliers,
        residual_spread: [sigma[0] as f32, sigma[1] as f32],
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// Samples of a known sun and sky, relative Gaussian noise `noise`, a fraction `outliers`
    /// replaced by gross errors (x0.2 to x5: people, glints).
    fn synthetic(
        sun: Rgb,
        sky: Rgb,
        n: usize,
        noise: f32,
        outliers: f32,
        sunlit_fraction: f32,
        seed: u64,
    ) -> Vec<Observation> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let albedo = Rgb::new(
                    rng.random_range(0.1..0.7),
                    rng.random_range(0.1..0.7),
                    rng.random_range(0.1..0.7),
                );
                let c: f32 = rng.random_range(0.3..1.0);
                let sky_term = Rgb::new(c, c * 0.98, c * 1.03);
                let lit = rng.random::<f32>() < sunlit_fraction;
                let sun_term = if lit { rng.random_range(0.2..1.0) } else { 0.0 };
                let clean = albedo * (sky_term * sky + sun * sun_term);
                // Light from other surfaces, per unit P_a and P_d: none here (see
                // `with_interreflections`).
                let (indirect_sky, indirect_sun) = (Rgb::ZERO, Rgb::ZERO);
                // Box-Muller.
                let mut g = || {
                    let (a, b): (f32, f32) = (rng.random::<f32>().max(1e-9), rng.random());
                    (-2.0 * a.ln()).sqrt() * (std::f32::consts::TAU * b).cos()
                };
                let mut observed =
                    clean * Rgb::new(1.0 + noise * g(), 1.0 + noise * g(), 1.0 + noise * g());
                if rng.random::<f32>() < outliers {
                    let f: f32 = if rng.random::<bool>() {
                        rng.random_range(0.2..0.5)
                    } else {
                        rng.random_range(2.0..5.0)
                    };
                    observed *= f;
                }
                Observation {
                    observed: observed.map(|v| v.max(0.0)),
                    albedo,
                    sky_term,
                    sun_term,
                    indirect_sky,
                    indirect_sun,
                }
            })
            .collect()
    }

    #[test]
    fn exact_samples_give_the_exact_answer() {
        let (sun, sky) = (Rgb::new(3.0, 2.8, 2.5), Rgb::new(0.4, 0.5, 0.7));
        let obs = synthetic(sun, sky, 500, 0.0, 0.0, 0.5, 1);
        let e = estimate(&obs, &EstimatorOptions::default()).unwrap();
        for c in 0..3 {
            // f32 inputs: 1e-5 relative.
            assert!((e.sun[c] - sun.to_array()[c]).abs() < 1e-5 * sun.to_array()[c]);
            assert!((e.sky[c] - sky.to_array()[c]).abs() < 1e-5 * sky.to_array()[c]);
        }
        assert!(e.sun_observable);
        assert_eq!(e.inliers, 500);
    }

    #[test]
    fn noise_is_within_its_standard_error_and_outliers_are_rejected() {
        let (sun, sky) = (Rgb::new(3.0, 2.8, 2.5), Rgb::new(0.4, 0.5, 0.7));
        let clean = synthetic(sun, sky, 500, 0.05, 0.0, 0.5, 2);
        let e = estimate(&clean, &EstimatorOptions::default()).unwrap();
        for c in 0..3 {
            // Four standard errors (a false alarm rate of 6e-5 per number).
            assert!((e.sun[c] - sun.to_array()[c]).abs() < 4.0 * e.sun_std[c]);
            assert!((e.sky[c] - sky.to_array()[c]).abs() < 4.0 * e.sky_std[c]);
            // 5 % noise over ~250 samples per column: about 0.5 % standard error.
            assert!(e.sun_std[c] < 0.01 * sun.to_array()[c]);
        }
        for spread in e.residual_spread {
            assert!((spread - 0.05).abs() < 0.01, "{spread}");
        }
        // 20 % gross outliers: the same answer within 2 %, most outliers at zero weight.
        let dirty = synthetic(sun, sky, 500, 0.05, 0.2, 0.5, 3);
        let robust = estimate(&dirty, &EstimatorOptions::default()).unwrap();
        for c in 0..3 {
            assert!(
                (robust.sun[c] / sun.to_array()[c] - 1.0).abs() < 0.02,
                "{robust:?}"
            );
            assert!(
                (robust.sky[c] / sky.to_array()[c] - 1.0).abs() < 0.02,
                "{robust:?}"
            );
        }
        assert!(
            robust.inliers < 440 && robust.inliers > 360,
            "{}",
            robust.inliers
        );
    }

    #[test]
    fn overcast_gives_no_sun_and_shade_only_cannot_see_it() {
        let sky = Rgb::new(0.8, 0.8, 0.85);
        let overcast = synthetic(Rgb::ZERO, sky, 500, 0.03, 0.0, 0.5, 4);
        let e = estimate(&overcast, &EstimatorOptions::default()).unwrap();
        assert!(e.sun_observable);
        for c in 0..3 {
            // P_d >= 0 by construction; within 4 standard errors of 0.
            assert!(e.sun[c] <= 4.0 * e.sun_std[c], "{e:?}");
        }
        let shade = synthetic(Rgb::new(3.0, 3.0, 3.0), sky, 300, 0.03, 0.0, 0.0, 5);
        let e = estimate(&shade, &EstimatorOptions::default()).unwrap();
        assert!(!e.sun_observable);
        assert_eq!(e.sun, [0.0; 3]);
        assert!(e.sun_std[0].is_infinite());
        assert!((e.sky[0] / 0.8 - 1.0).abs() < 0.01);
        assert!(estimate(&shade[..2], &EstimatorOptions::default()).is_err());
    }

    /// Adds light reflected by other surfaces to `observations`: per sample `b_a = 0.3 c` and
    /// `b_d = 0.25 (0.9, 0.7, 0.5)` (a warm sunlit wall nearby), observed by the pixels; with
    /// `modelled` the observations also carry the terms.
    fn with_interreflections(
        observations: &[Observation],
        sun: Rgb,
        sky: Rgb,
        modelled: bool,
    ) -> Vec<Observation> {
        observations
            .iter()
            .map(|o| {
                let ba = o.sky_term * 0.3;
                let bd = Rgb::new(0.9, 0.7, 0.5) * 0.25;
                let extra = o.albedo * (ba * sky + bd * sun);
                let expected = o.albedo * (o.sky_term * sky + sun * o.sun_term);
                // Keep the sample's relative noise: scale the extra light by observed / clean.
                let noise = Rgb::new(
                    o.observed.r / expected.r,
                    o.observed.g / expected.g,
                    o.observed.b / expected.b,
                );
                Observation {
                    observed: o.observed + extra * noise,
                    indirect_sky: if modelled { ba } else { Rgb::ZERO },
                    indirect_sun: if modelled { bd } else { Rgb::ZERO },
                    ..*o
                }
            })
            .collect()
    }

    #[test]
    fn interreflections_bias_the_paper_model_and_the_bounce_terms_remove_it() {
        let (sun, sky) = (Rgb::new(3.0, 2.8, 2.5), Rgb::new(0.4, 0.5, 0.7));
        let base = synthetic(sun, sky, 500, 0.03, 0.0, 0.5, 6);
        let modelled = with_interreflections(&base, sun, sky, true);
        let e = estimate(&modelled, &EstimatorOptions::default()).unwrap();
        for c in 0..3 {
            // Four standard errors, as above.
            assert!(
                (e.sun[c] - sun.to_array()[c]).abs() < 4.0 * e.sun_std[c],
                "{e:?}"
            );
            assert!(
                (e.sky[c] - sky.to_array()[c]).abs() < 4.0 * e.sky_std[c],
                "{e:?}"
            );
        }
        // Ignored, the shaded samples' bounce light reads as sky: P_a comes out far too high
        // (the shade's bounce light is 0.25 P_d / (c P_a) ~ 2 to 4 times its sky light).
        let ignored = with_interreflections(&base, sun, sky, false);
        let e = estimate(&ignored, &EstimatorOptions::default()).unwrap();
        assert!(e.sky[1] > 1.5 * sky.g, "{e:?}");
    }
}
