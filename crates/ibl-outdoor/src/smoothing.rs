//! Optional temporal smoothing of the per-frame estimates: a scalar Kalman filter per parameter
//! and channel (a random-walk state observed with the estimate's own standard error).
//!
//! Jensen, Andersen & Madsen 2006 estimate every frame independently; a video of a real yard
//! flickers with the estimator's noise, so a filter that trusts each frame by its confidence is
//! the natural addition. State `x` (one of `P_d`, `P_a` in one channel), variance `V`:
//!
//! ```text
//! predict:  V <- V + (q x)^2 dt                   q: expected relative change per sqrt(second)
//! update:   K = V / (V + sigma^2),  x <- x + K (z - x),  V <- (1 - K) V
//! ```
//!
//! with `z` the frame's estimate and `sigma` its standard error ([`crate::Estimate`]). A frame
//! whose sun is not observable updates only the sky: the sun keeps its prediction. A cloud
//! covering the sun changes `P_d` by a factor of several within seconds, far more than `q`
//! allows, so an innovation beyond `reset_sigmas` standard deviations restarts that state at
//! the measurement: the filter smooths noise but never lags behind a real change.

use serde::Serialize;

use crate::estimate::Estimate;

/// Settings of [`TemporalFilter`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothingOptions {
    /// Expected relative change of a parameter per square root of a second (random walk).
    pub relative_change_per_sqrt_s: f64,
    /// Innovations beyond this many standard deviations restart the state at the measurement.
    pub reset_sigmas: f64,
}

impl Default for SmoothingOptions {
    fn default() -> Self {
        SmoothingOptions {
            relative_change_per_sqrt_s: 0.01,
            reset_sigmas: 4.0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
struct Scalar {
    x: f64,
    var: f64,
}

impl Scalar {
    fn step(&mut self, dt: f64, z: f64, sigma: f64, options: &SmoothingOptions) {
        let q = options.relative_change_per_sqrt_s * self.x.abs();
        self.var += q * q * dt.max(0.0);
        let r = sigma * sigma;
        let innovation = z - self.x;
        if innovation * innovation > options.reset_sigmas.powi(2) * (self.var + r) {
            *self = Scalar { x: z, var: r };
            return;
        }
        let k = if self.var + r > 0.0 {
            self.var / (self.var + r)
        } else {
            1.0
        };
        self.x += k * innovation;
        self.var *= 1.0 - k;
    }
}

/// Smooths a sequence of estimates (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct TemporalFilter {
    options: SmoothingOptions,
    /// Sun then sky, three channels each; `None` before the first frame.
    state: Option<[Scalar; 6]>,
    last_time_s: f64,
}

impl TemporalFilter {
    /// An empty filter.
    pub fn new(options: SmoothingOptions) -> TemporalFilter {
        TemporalFilter {
            options,
            state: None,
            last_time_s: 0.0,
        }
    }

    /// Feeds the estimate of the frame at `time_s` (seconds on any fixed clock) and returns the
    /// smoothed one (same confidence fields; the values and standard errors are the filter's).
    pub fn update(&mut self, time_s: f64, estimate: &Estimate) -> Estimate {
        let z: Vec<(f64, f64)> = (0..3)
            .map(|c| (f64::from(estimate.sun[c]), f64::from(estimate.sun_std[c])))
            .chain((0..3).map(|c| (f64::from(estimate.sky[c]), f64::from(estimate.sky_std[c]))))
            .collect();
        let state = match self.state.as_mut() {
            None => {
                let init = std::array::from_fn(|k| Scalar {
                    x: z[k].0,
                    var: if z[k].1.is_finite() {
                        z[k].1 * z[k].1
                    } else {
                        0.0
                    },
                });
                self.state = Some(init);
                self.last_time_s = time_s;
                return *estimate;
            }
            Some(s) => s,
        };
        let dt = time_s - self.last_time_s;
        self.last_time_s = time_s;
        for (k, s) in state.iter_mut().enumerate() {
            let (value, sigma) = z[k];
            if sigma.is_finite() {
                s.step(dt, value, sigma, &self.options);
            } else {
                // Not observed this frame: predict only.
                let q = self.options.relative_change_per_sqrt_s * s.x.abs();
                s.var += q * q * dt.max(0.0);
            }
        }
        let mut out = *estimate;
        for c in 0..3 {
            out.sun[c] = state[c].x as f32;
            out.sun_std[c] = state[c].var.sqrt() as f32;
            out.sky[c] = state[3 + c].x as f32;
            out.sky_std[c] = state[3 + c].var.sqrt() as f32;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(sun: f32, sky: f32, std: f32) -> Estimate {
        Estimate {
            sun: [sun; 3],
            sky: [sky; 3],
            sun_std: [std; 3],
            sky_std: [std * 0.2; 3],
            correlation: [0.0; 3],
            condition: 2.0,
            sun_observable: true,
            samples: 500,
            inliers: 500,
            sunlit_inliers: 250,
            residual_spread: [0.05; 2],
            iterations: 10,
        }
    }

    #[test]
    fn noise_is_averaged_and_a_cloud_is_followed_at_once() {
        let mut f = TemporalFilter::new(SmoothingOptions::default());
        // Alternating +-2 % noise around 3.0, one frame a second.
        let mut last = estimate(3.0, 0.5, 0.06);
        for k in 0..20 {
            let z = if k % 2 == 0 { 3.06 } else { 2.94 };
            last = f.update(k as f64, &estimate(z, 0.5, 0.06));
        }
        assert!((last.sun[0] - 3.0).abs() < 0.02, "{}", last.sun[0]);
        assert!(last.sun_std[0] < 0.06);
        // A cloud: the sun drops to 0.6 (40 standard errors): followed in one frame.
        let clouded = f.update(20.0, &estimate(0.6, 0.5, 0.06));
        assert!((clouded.sun[0] - 0.6).abs() < 1e-6);
        // An unobservable sun keeps its value.
        let mut blind = estimate(0.0, 0.5, f32::INFINITY);
        blind.sun_observable = false;
        let kept = f.update(21.0, &blind);
        assert!((kept.sun[0] - 0.6).abs() < 1e-6);
    }
}
