//! Light extraction (Madsen & Laursen 2006): replacing a lat-long light probe by N directional
//! lights. Each method lives in its own module and returns an [`ibl_light::LightSet`] in the
//! world frame (CONVENTIONS section 4): per light a direction, an RGB radiance, a solid angle and
//! the irradiance `I = L A` it gives a surface facing it, with the method and its parameters as
//! the set's provenance. The light types and the method names live in `ibl-light`.

pub mod adaptive_median_cut;
mod cholesky;
pub mod hemispheres;
pub mod hybrid;
pub mod irradiance_optimization;
mod light_cells;
pub mod lightgen;
mod lune_gram;
pub mod median_cut;
pub mod method;
pub mod model;
pub mod nnls;
mod normal_lanes;
mod region_stats;
pub mod sun;
pub mod variance_minimization;

pub use adaptive_median_cut::adaptive_median_cut;
pub use hemispheres::fit_hemispheres;
pub use hybrid::Hybrid;
pub use irradiance_optimization::{Fit, OptimizationOptions, irradiance_optimization};
pub use lightgen::{LightGenOptions, lightgen};
pub use median_cut::median_cut;
pub use method::{ExtractOptions, FitDomain, extract};
pub use model::{Model, ModelSpec, build_model};
pub use nnls::nnls_gram;
pub use sun::{DominantLight, dominant_light};
pub use variance_minimization::variance_minimization;

/// Why a light set could not be extracted.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ExtractError {
    /// A parameter is out of its range (the message says which and why).
    #[error("{0}")]
    Parameter(String),
    /// The probe is not a usable lat-long map.
    #[error("{0}")]
    Invalid(String),
}

impl ExtractError {
    /// Always true: both causes are the caller's input (a parameter out of range, a probe that is
    /// not a usable lat-long map); extraction has no internal failure mode that returns.
    pub fn is_bad_input(&self) -> bool {
        match self {
            ExtractError::Parameter(_) | ExtractError::Invalid(_) => true,
        }
    }
}
