//! One entry point that runs any extraction method ([`ibl_light::Method`]) for any N; the set it
//! returns records the method and its parameters in its provenance.
//!
//! Median cut makes only powers of two (the paper's algorithm); every other method takes any
//! N >= 1. The fitted method (irradiance optimisation) fits on its own normals, never on the
//! 20000 Fibonacci normals that `ibl-eval` scores on (see the [`crate::irradiance_optimization`](mod@crate::irradiance_optimization) module).

use ibl_core::{Image, Rgb};
use ibl_light::{LightSet, Method};

use crate::ExtractError;

/// Settings shared by the methods (each uses what applies to it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExtractOptions {
    /// Seed of every random choice (clustering restarts); equal seeds give equal lights.
    pub seed: u64,
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions { seed: 1 }
    }
}

/// Runs `method` on a lat-long probe for exactly `n` lights.
pub fn extract(
    probe: &Image<Rgb>,
    method: Method,
    n: usize,
    options: &ExtractOptions,
) -> Result<LightSet, ExtractError> {
    if !method.accepts(n) {
        return Err(ExtractError::Parameter(match method {
            Method::MedianCut => format!("median cut makes a power of two lights; {n} is not one"),
            _ => format!("{method} needs at least one light; got {n}"),
        }));
    }
    Ok(match method {
        Method::MedianCut => crate::median_cut(probe, n.trailing_zeros())?,
        Method::AdaptiveMedianCut => crate::adaptive_median_cut(probe, n)?,
        Method::VarianceMinimization => crate::variance_minimization(probe, n)?,
        Method::LightGen => {
            let o = crate::LightGenOptions {
                seed: options.seed,
                ..Default::default()
            };
            crate::lightgen(probe, n, &o)?
        }
        Method::IrradianceOptimization => {
            crate::irradiance_optimization(probe, n, &crate::OptimizationOptions::default())?.set
        }
    })
}
