//! Error metrics, below every crate that renders or approximates, so that the renderer's, the
//! capture's and the viewer's tests and the evaluation reports all measure with one definition:
//!
//! * [`irradiance_error`]: the error of an irradiance approximation against the ground truth on a
//!   set of normals (`mean_err%`, `max_err%`, and the per-normal relative `rel_mean%`,
//!   `rel_max%`; CONVENTIONS section 5, Madsen & Laursen 2006 section 5);
//! * [`image_difference`]: RMSE, relative MSE, absolute errors, PSNR and per-pixel error maps
//!   between two images, with percentiles of any map;
//! * [`probe_difference`]: the relative MAE of luminance between two lat-long probes, weighted by
//!   solid angle (capture's tests);
//! * [`mod@flip`]: the FLIP perceptual difference map (Andersson et al. 2020, HDR-FLIP 2021),
//!   checked against NVIDIA's reference implementation (`tests/flip_reference.rs`);
//! * [`comparison`]: the size and mask checks they share, and their error.
//!
//! No I/O, no drawing (false-colour pictures of the maps are `ibl-eval`'s). Sums are f64 with
//! fixed partitions: results are bit-identical whatever the rayon thread count.

pub mod comparison;
pub mod flip;
pub mod image_difference;
pub mod irradiance_error;
pub mod probe_difference;

pub use comparison::DifferenceError;
pub use flip::{DEFAULT_PIXELS_PER_DEGREE, Flip, FlipOptions, FlipRange, flip};
pub use image_difference::{
    ImageDifference, MapStatistics, RELATIVE_MSE_EPSILON, absolute_error_map,
    relative_squared_error_map,
};
pub use irradiance_error::{
    IrradianceError, max_err_pct, mean_err_pct, rel_max_err_pct, rel_mean_err_pct,
};
pub use probe_difference::relative_luminance_mae;
