//! Evaluation of lighting approximations against the exact irradiance of a probe (CONVENTIONS
//! sections 4 and 5, after Madsen & Laursen 2006, section 5).
//!
//! * [`ground_truth`]: the exact irradiance `E(n) = sum_p L_p max(0, n . d_p) dOmega_p` of a
//!   lat-long probe on a set of normals (normally 20000 Fibonacci normals), plus a fast,
//!   energy-conserving approximation of it for interactive use;
//! * [`metrics`]: the error of an approximation against that ground truth (`mean_err%`,
//!   `max_err%`, and the per-normal relative `rel_mean%`, `rel_max%`).
//!
//! Everything is f64 and deterministic: results are bit-identical whatever the rayon thread count.

pub mod ground_truth;
pub mod metrics;
pub mod overlay;
pub mod plot;
pub mod report;
pub mod sphere_image;
pub mod sweep;

pub use ground_truth::{
    Emitters, FAST_DEFAULT_SIZE, GroundTruth, irradiance_brute_force, irradiance_fast,
};
pub use ibl_core::{RowIrradiance, channel_means, irradiance_exact};
pub use metrics::{IrradianceError, max_err_pct, mean_err_pct, rel_max_err_pct, rel_mean_err_pct};
