//! The extraction methods by name, and one entry point that runs any of them for any N.
//!
//! Median cut makes only powers of two (the paper's algorithm); every other method takes any
//! N >= 1. The fitted method (irradiance optimisation) fits on its own normals, never on the
//! 20000 Fibonacci normals that `ibl-eval` scores on (see the [`crate::irradiance_optimization`](mod@crate::irradiance_optimization) module).

use std::collections::BTreeMap;
use std::fmt;
use std::str::FromStr;

use ibl_core::{Image, Rgb};

use crate::{ExtractError, LightSet};

/// A light-extraction method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    /// Median cut (Debevec 2005), 2^K lights: [`crate::median_cut()`].
    MedianCut,
    /// Median cut with any N: [`crate::adaptive_median_cut()`].
    AdaptiveMedianCut,
    /// LightGen-style clustering (Cohen & Debevec 2001): [`crate::lightgen()`].
    LightGen,
    /// Variance minimisation (Viriyothai & Debevec 2009): [`crate::variance_minimization()`].
    VarianceMinimization,
    /// Irradiance optimisation (Madsen et al. 2003): [`crate::irradiance_optimization()`].
    IrradianceOptimization,
}

impl Method {
    /// Every method, in the order reports list them.
    pub const ALL: [Method; 5] = [
        Method::MedianCut,
        Method::AdaptiveMedianCut,
        Method::LightGen,
        Method::VarianceMinimization,
        Method::IrradianceOptimization,
    ];

    /// The method's name on the command line and in files (`median-cut`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Method::MedianCut => "median-cut",
            Method::AdaptiveMedianCut => "adaptive-median-cut",
            Method::LightGen => "lightgen",
            Method::VarianceMinimization => "variance-minimization",
            Method::IrradianceOptimization => "irradiance-optimization",
        }
    }

    /// True when the method can make exactly `n` lights (median cut: powers of two only).
    pub fn accepts(self, n: usize) -> bool {
        match self {
            Method::MedianCut => {
                n.is_power_of_two() && n.trailing_zeros() <= crate::median_cut::MAX_SPLITS
            }
            _ => n >= 1,
        }
    }

    /// True for methods whose lights stand for probe regions (their power sums to the probe's).
    pub fn is_region_based(self) -> bool {
        matches!(
            self,
            Method::MedianCut | Method::AdaptiveMedianCut | Method::VarianceMinimization
        )
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = ExtractError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                ExtractError::Parameter(format!(
                    "unknown method '{s}' (expected one of: {})",
                    names.join(", ")
                ))
            })
    }
}

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

/// A light set with the parameters the method ran with (recorded in light files and reports).
#[derive(Clone, Debug, PartialEq)]
pub struct Extraction {
    /// The lights.
    pub set: LightSet,
    /// Named numeric parameters and diagnostics (e.g. `splits`, `iterations`, `converged`).
    pub parameters: BTreeMap<String, f64>,
}

/// Runs `method` on a lat-long probe for exactly `n` lights.
pub fn extract(
    probe: &Image<Rgb>,
    method: Method,
    n: usize,
    options: &ExtractOptions,
) -> Result<Extraction, ExtractError> {
    if !method.accepts(n) {
        return Err(ExtractError::Parameter(match method {
            Method::MedianCut => format!("median cut makes a power of two lights; {n} is not one"),
            _ => format!("{method} needs at least one light; got {n}"),
        }));
    }
    let mut parameters = BTreeMap::new();
    let set = match method {
        Method::MedianCut => {
            let splits = n.trailing_zeros();
            parameters.insert("splits".into(), f64::from(splits));
            crate::median_cut(probe, splits)?
        }
        Method::AdaptiveMedianCut => crate::adaptive_median_cut(probe, n)?,
        Method::VarianceMinimization => crate::variance_minimization(probe, n)?,
        Method::LightGen => {
            let o = crate::LightGenOptions {
                seed: options.seed,
                ..Default::default()
            };
            parameters.insert("restarts".into(), o.restarts as f64);
            parameters.insert("seed".into(), options.seed as f64);
            crate::lightgen(probe, n, &o)?
        }
        Method::IrradianceOptimization => {
            let fit =
                crate::irradiance_optimization(probe, n, &crate::OptimizationOptions::default())?;
            parameters.extend(fit.report.parameters());
            fit.set
        }
    };
    Ok(Extraction { set, parameters })
}
