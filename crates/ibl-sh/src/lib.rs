//! Spherical harmonics for iblkit (CONVENTIONS section 6): the real orthonormal basis of any
//! order, projection of lat-long probes with exact solid angles, rotation of every band, Lambert
//! convolution to irradiance (Ramamoorthi & Hanrahan 2001) with optional windowing, and the
//! radiance and irradiance coefficient sets as distinct types, and irradiance volumes (grids of
//! irradiance key points, L2 by default, shared by the indoor and outdoor pipelines).

pub mod basis;
pub mod coefficients;
pub mod convolution;
pub mod projection;
mod quadrature;
pub mod rotation;
pub mod volume;

pub use basis::{MAX_BANDS, basis, coefficient_count, eval_basis, sh_index};
pub use coefficients::{IrradianceSh, RadianceSh};
pub use convolution::{Window, lambert_factor};
pub use projection::{project_latlong, subtract_point_sources};
pub use rotation::ShRotation;
pub use volume::{
    IrradianceL2, IrradianceVolume, KeyPointIrradiance, KeyPointVolume, LeakControl, VolumeGrid,
    VolumeLayer, VolumeLayers,
};

/// Why an SH operation could not run.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ShError {
    /// A parameter is out of range (band count).
    #[error("{0}")]
    Parameter(String),
    /// The data is not usable (wrong coefficient count, non-finite values, empty probe).
    #[error("{0}")]
    Invalid(String),
}

impl ShError {
    /// Always true: a band count out of range or unusable coefficients or probe are the
    /// caller's input.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}
