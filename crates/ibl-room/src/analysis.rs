//! The whole of Grosch 2005 section 3.2 in one call: depth map, probe radiosity, form factors and
//! the reflectance estimate, with progress through a callback. This is what a command or a
//! viewer runs on a room and its probe; the steps stay callable one by one.

use ibl_core::{Image, Rgb};

use crate::depth_map::ProbeDepthMap;
use crate::form_factors::{FormFactorSettings, FormFactors};
use crate::observation::{ObservationSettings, Observations, observe};
use crate::reflectance::{Estimate, EstimationSettings, estimate_reflectance};
use crate::{Room, RoomError};

/// Every setting of the analysis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AnalysisSettings {
    /// How probe pixels are assigned to patches.
    pub observation: ObservationSettings,
    /// How form factors are sampled.
    pub form_factors: FormFactorSettings,
    /// The iteration of steps 1 to 5.
    pub estimation: EstimationSettings,
}

/// A stage of the analysis, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Casting the depth map's rays.
    DepthMap,
    /// Casting the form factors' rays (`done` of `total` patches).
    FormFactors,
    /// Iterating the estimate.
    Estimate,
}

/// Everything the analysis computed.
#[derive(Clone, Debug)]
pub struct RoomAnalysis {
    /// The depth map, at the probe's size.
    pub depth: ProbeDepthMap,
    /// What the probe shows of each patch.
    pub observations: Observations,
    /// Form factors between the patches.
    pub form_factors: FormFactors,
    /// Reflectance and radiosity per patch and group, every iteration.
    pub estimate: Estimate,
}

/// Runs the analysis of `room` seen in `probe` (lat-long radiance, any size).
/// `progress(stage, done, total)` is called from worker threads.
pub fn analyse_room(
    room: &Room,
    probe: &Image<Rgb>,
    settings: &AnalysisSettings,
    progress: &(dyn Fn(Stage, usize, usize) + Sync),
) -> Result<RoomAnalysis, RoomError> {
    progress(Stage::DepthMap, 0, 1);
    let depth = ProbeDepthMap::new(room, probe.width(), probe.height())?;
    progress(Stage::DepthMap, 1, 1);
    let observations = observe(room, &depth, probe, &settings.observation)?;
    let form_factors = FormFactors::compute(room, &settings.form_factors, &|done, total| {
        progress(Stage::FormFactors, done, total)
    })?;
    progress(Stage::Estimate, 0, 1);
    let estimate = estimate_reflectance(room, &observations, &form_factors, &settings.estimation)?;
    progress(Stage::Estimate, 1, 1);
    Ok(RoomAnalysis {
        depth,
        observations,
        form_factors,
        estimate,
    })
}
