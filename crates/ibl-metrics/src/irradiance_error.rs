//! Irradiance error metrics, CONVENTIONS section 5 (Madsen & Laursen 2006, section 5).
//!
//! For channel c, ground truth `g_kc` and approximation `e_kc` on normals k, and
//! `mu_c = mean_k g_kc`:
//!
//! ```text
//! mean_err% = 100 * mean_c( mean_k |e_kc - g_kc| / mu_c )
//! max_err%  = 100 * mean_c( max_k  |e_kc - g_kc| / mu_c )
//! rel_mean% = 100 * mean_kc |e_kc - g_kc| / max(g_kc, 1e-3 mu_c)
//! rel_max%  = 100 * max_kc  |e_kc - g_kc| / max(g_kc, 1e-3 mu_c)
//! ```
//!
//! The first two scale every error by the channel's mean irradiance (the paper's numbers); the
//! relative pair judges each normal against its own irradiance, floored at 1e-3 mu_c so that
//! normals facing a black hemisphere do not divide by zero. A channel whose mean ground truth is
//! not positive (an all-black channel) has no scale and is left out of every mean; if no channel
//! is left, every metric is 0.

/// The four error metrics of an approximation against the ground truth, in per cent.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IrradianceError {
    /// `100 * mean_c( mean_k |e - g| / mu_c )`.
    pub mean_err_pct: f64,
    /// `100 * mean_c( max_k |e - g| / mu_c )`.
    pub max_err_pct: f64,
    /// `100 * mean_kc |e - g| / max(g, 1e-3 mu_c)`.
    pub rel_mean_err_pct: f64,
    /// `100 * max_kc |e - g| / max(g, 1e-3 mu_c)`.
    pub rel_max_err_pct: f64,
}

impl IrradianceError {
    /// The metrics of `approx` against `truth` (same normals, same order).
    ///
    /// # Panics
    /// If the two slices have different lengths.
    pub fn between(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> Self {
        assert_eq!(
            truth.len(),
            approx.len(),
            "ground truth and approximation must cover the same normals"
        );
        let mu = ibl_core::channel_means(truth);
        let n = truth.len();
        let (mut mean_sum, mut max_sum, mut rel_sum, mut rel_max) = (0.0, 0.0, 0.0, 0.0f64);
        let mut channels = 0usize;
        for c in 0..3 {
            if mu[c].is_nan() || mu[c] <= 0.0 || n == 0 {
                continue;
            }
            channels += 1;
            let floor = 1e-3 * mu[c];
            let (mut abs_sum, mut abs_max) = (0.0f64, 0.0f64);
            for (g, e) in truth.iter().zip(approx) {
                let d = (e[c] - g[c]).abs();
                abs_sum += d;
                abs_max = abs_max.max(d);
                let r = d / g[c].max(floor);
                rel_sum += r;
                rel_max = rel_max.max(r);
            }
            mean_sum += abs_sum / n as f64 / mu[c];
            max_sum += abs_max / mu[c];
        }
        if channels == 0 {
            return IrradianceError::default();
        }
        let k = channels as f64;
        IrradianceError {
            mean_err_pct: 100.0 * mean_sum / k,
            max_err_pct: 100.0 * max_sum / k,
            rel_mean_err_pct: 100.0 * rel_sum / (k * n as f64),
            rel_max_err_pct: 100.0 * rel_max,
        }
    }
}

/// `mean_err%` of `approx` against `truth` (see [`IrradianceError`]).
pub fn mean_err_pct(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> f64 {
    IrradianceError::between(truth, approx).mean_err_pct
}

/// `max_err%` of `approx` against `truth` (see [`IrradianceError`]).
pub fn max_err_pct(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> f64 {
    IrradianceError::between(truth, approx).max_err_pct
}

/// `rel_mean%` of `approx` against `truth` (see [`IrradianceError`]).
pub fn rel_mean_err_pct(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> f64 {
    IrradianceError::between(truth, approx).rel_mean_err_pct
}

/// `rel_max%` of `approx` against `truth` (see [`IrradianceError`]).
pub fn rel_max_err_pct(truth: &[[f64; 3]], approx: &[[f64; 3]]) -> f64 {
    IrradianceError::between(truth, approx).rel_max_err_pct
}
