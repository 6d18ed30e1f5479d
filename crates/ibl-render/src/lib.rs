//! The iblkit CPU renderer: virtual objects lit by a light probe and composited into real imagery
//! by differential rendering (Debevec 1998; Grosch 2005 section 4.1; Madsen & Laursen 2006 use it
//! to compare light approximations).
//!
//! - [`mod@render`]: the driver and the differential composite (with and without the objects).
//! - [`tracer`]: one light path, in the reference, lights or hybrid mode.
//! - [`lighting`]: what lights each mode (environment, directional lights, lights + SH ambient).
//! - [`adaptive`]: adaptive antialiasing of the lights and hybrid modes.
//! - [`background`]: the background at the output size.
//! - [`environment`]: the probe as an importance-sampled environment light.
//! - [`normal_bins`]: environment sampling by radiance times a cosine bound, per normal bin.
//! - [`footprint`]: the probe's mean over a pinhole pixel's footprint (the background).
//! - [`material`]: BSDFs of the scene's materials (evaluate, sample, density).
//! - [`sample_allocation`]: adaptive sampling of the reference mode (unbiased).
//! - [`sampler`]: the numbers each pixel sample draws (Owen-scrambled Sobol or independent).
//! - [`sampling`]: random number generator, warps and discrete distributions.

pub mod adaptive;
pub mod background;
pub mod environment;
pub mod footprint;
pub mod lighting;
pub mod material;
pub mod normal_bins;
pub mod render;
pub mod sample_allocation;
pub mod sampler;
pub mod sampling;
pub mod tracer;

pub use lighting::{Illumination, Lighting};
pub use render::{RenderOutput, RenderSettings, RenderStats, render};
pub use sampler::SamplerKind;

/// Why a render cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A setting is out of range.
    #[error("{0}")]
    Parameter(String),
    /// The probe cannot be used as an environment light.
    #[error("the probe cannot light the scene: {0}")]
    Environment(#[from] environment::EnvironmentError),
}

impl RenderError {
    /// Whether the scene or the settings the caller gave are at fault: always, since a render
    /// fails only on a setting out of range or a probe that cannot light (black, empty); the
    /// renderer has no internal failure that returns.
    pub fn is_bad_input(&self) -> bool {
        match self {
            RenderError::Parameter(_) | RenderError::Environment(_) => true,
        }
    }
}
