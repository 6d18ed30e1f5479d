//! Outdoor augmented reality under changing light (Jensen, Andersen & Madsen 2006, "Real-time
//! image based lighting for outdoor augmented reality under dynamically changing illumination
//! conditions"): from a 3D model of the scene, one HDR probe taken once and the sun's position
//! from place and time, estimate the sun's and the sky's RGB intensity in every video frame from
//! a few hundred pixels on diffuse surfaces, relight the environment map to match and refresh an
//! irradiance volume from it.
//!
//! - [`sun`]: place, time and the NREL SPA sun direction in the world frame.
//! - [`sky`]: Preetham, CIE overcast and uniform skies, normalised to the sky parameter `P_a`.
//! - [`view`]: what the probe and the camera see of the model; the probe's projective mapping.
//! - [`transfer`]: the weighted ambient `c` and the sky transfer vectors behind `c_shape`.
//! - [`footprint`]: what each probe pixel covers; pixels across the skyline or an edge.
//! - [`interreflection`]: the light the model's surfaces reflect onto each other.
//! - [`shadow`]: the binary sun-visibility map and when to re-cast it.
//! - [`tracking`]: sky shape and per-point terms kept current as the sun moves.
//! - [`maps`]: the offline maps in the probe's lat-long (normal, weighted ambient, shadow,
//!   albedo by inverse rendering) and the capture lighting.
//! - [`samples`]: the camera pixels the estimation reads, with their model inputs.
//! - [`mod@estimate`]: the robust per-frame fit of `P_d` and `P_a` with its confidence.
//! - [`smoothing`]: optional temporal smoothing (a Kalman filter per parameter).
//! - [`relight`]: the relit environment map and the sun as a directional light.
//! - [`volume_refresh`]: the irradiance volume from the relit map (a) or from key-point
//!   responses (b).
//! - [`system`]: the whole per-frame loop behind one type.
//! - [`composite`]: each frame's virtual objects, rendered under the estimates and composited
//!   into the frame by differential rendering (shadows both ways).
//! - [`courtyard`] and [`synthetic`]: the validation scene and its path-traced day.
//! - [`plot`]: the estimates over a day as an SVG chart.
//!
//! Units: radiance in the probe's units; `P_d = E_sun / pi` (the radiance of a white Lambertian
//! surface facing the sun), `P_a` the radiance of the uniform sky of the same horizontal
//! irradiance (docs/CONVENTIONS.md, "Sun, sky and time"). This crate does no I/O.

pub mod composite;
pub mod courtyard;
pub mod estimate;
pub mod footprint;
pub mod interreflection;
pub mod maps;
pub mod plot;
pub mod relight;
pub mod samples;
pub mod shadow;
pub mod sky;
pub mod smoothing;
pub mod sun;
pub mod synthetic;
pub mod system;
pub mod tracking;
pub mod transfer;
pub mod view;
pub mod volume_refresh;

pub use composite::{CompositeSettings, FrameCompositor, FrameLighting};
pub use estimate::{Estimate, EstimatorOptions, Observation, estimate};
pub use interreflection::Interreflection;
pub use maps::{CaptureSource, LightingParameters, MapSettings, ProbeMaps};
pub use relight::{Relighter, SunLight};
pub use samples::{SampleSettings, SampleSites};
pub use sky::{PreethamSky, SkyModel, SkyShape};
pub use smoothing::{SmoothingOptions, TemporalFilter};
pub use sun::{Atmosphere, DeltaT, Location, SunPosition, Timestamp};
pub use system::{
    CameraSetup, FrameResult, OutdoorSystem, ProbeCapture, SystemSettings, VolumeRefresh,
    VolumeSettings,
};
pub use tracking::SkyCondition;
pub use volume_refresh::{KeyPointRelighter, MapGather};

/// Why an outdoor operation could not run.
#[derive(Debug, thiserror::Error)]
pub enum OutdoorError {
    /// A parameter or an input is out of range or inconsistent (the caller's input is at fault).
    #[error("{0}")]
    Parameter(String),
    /// The computation failed on valid input (a model with no sky, a singular system).
    #[error("{0}")]
    Numerical(String),
    /// The path tracer refused a render.
    #[error("rendering: {0}")]
    Render(#[from] ibl_render::RenderError),
}

impl OutdoorError {
    /// Whether the caller's input is at fault (exit code 2 at the command line).
    pub fn is_bad_input(&self) -> bool {
        matches!(self, OutdoorError::Parameter(_))
    }
}
