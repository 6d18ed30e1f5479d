//! Adaptive median cut (placeholder being written).

use ibl_core::{Image, Rgb};

use crate::{ExtractError, LightSet};

/// Adaptive median cut into exactly `n` lights.
pub fn adaptive_median_cut(_probe: &Image<Rgb>, _n: usize) -> Result<LightSet, ExtractError> {
    Err(ExtractError::Parameter(
        "adaptive median cut: not written yet".into(),
    ))
}
