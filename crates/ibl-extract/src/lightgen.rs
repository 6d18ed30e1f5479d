//! LightGen-style clustering (placeholder being written).

use ibl_core::{Image, Rgb};

use crate::{ExtractError, LightSet};

/// Clustering settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightGenOptions {
    /// Seed of the random initialisations.
    pub seed: u64,
    /// Number of restarts; the best clustering is kept.
    pub restarts: usize,
}

impl Default for LightGenOptions {
    fn default() -> Self {
        LightGenOptions {
            seed: 1,
            restarts: 4,
        }
    }
}

/// LightGen-style clustering into exactly `n` lights.
pub fn lightgen(
    _probe: &Image<Rgb>,
    _n: usize,
    _o: &LightGenOptions,
) -> Result<LightSet, ExtractError> {
    Err(ExtractError::Parameter("lightgen: not written yet".into()))
}
