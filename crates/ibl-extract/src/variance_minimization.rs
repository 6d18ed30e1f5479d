//! Variance minimisation (placeholder being written).

use ibl_core::{Image, Rgb};

use crate::{ExtractError, LightSet};

/// Variance minimisation into exactly `n` lights.
pub fn variance_minimization(_probe: &Image<Rgb>, _n: usize) -> Result<LightSet, ExtractError> {
    Err(ExtractError::Parameter(
        "variance minimisation: not written yet".into(),
    ))
}
