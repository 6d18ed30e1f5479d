//! Irradiance optimisation (placeholder being written).

use std::collections::BTreeMap;

use ibl_core::{Image, Rgb};

use crate::{ExtractError, LightSet};

/// Optimisation settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OptimizationOptions {
    /// Seed of the starting clustering.
    pub seed: u64,
}

impl Default for OptimizationOptions {
    fn default() -> Self {
        OptimizationOptions { seed: 1 }
    }
}

/// How a fit went.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FitReport {
    /// Iterations run.
    pub iterations: usize,
}

impl FitReport {
    /// The report as named numbers.
    pub fn parameters(&self) -> BTreeMap<String, f64> {
        BTreeMap::from([("iterations".to_string(), self.iterations as f64)])
    }
}

/// A fitted light set and its report.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The lights.
    pub set: LightSet,
    /// How the fit went.
    pub report: FitReport,
}

/// Irradiance optimisation into exactly `n` lights.
pub fn irradiance_optimization(
    _probe: &Image<Rgb>,
    _n: usize,
    _o: &OptimizationOptions,
) -> Result<Fit, ExtractError> {
    Err(ExtractError::Parameter(
        "irradiance optimisation: not written yet".into(),
    ))
}

/// What the fit is scored against, in words for reports: the fit never sees the scoring normals.
pub const FIT_NORMALS_NOTE: &str = "fitted on 4096 Fibonacci normals turned by 0.5 rad about the axis (1,1,1); scored on the 20000 Fibonacci normals of CONVENTIONS section 5";
