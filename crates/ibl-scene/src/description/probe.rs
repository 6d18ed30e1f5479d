//! `[probe]`: the HDR light probe lighting the scene (docs/SCENES.md): its lat-long file, its
//! rotation `world_from_probe` (yaw, pitch, roll degrees, CONVENTIONS section 1), a radiance
//! scale and the world position of its centre.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, finite3, positive};

/// `[probe]`: the HDR light probe lighting the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeDescription {
    /// Lat-long image file, relative to the scene file.
    pub file: PathBuf,
    /// `world_from_probe` as yaw, pitch, roll in degrees (CONVENTIONS section 1). Default none.
    #[serde(default)]
    pub rotation_deg: [f32; 3],
    /// Factor applied to every probe radiance (exposure calibration). Default 1.
    #[serde(default = "one")]
    pub radiance_scale: f32,
    /// World position of the probe's centre: where the panorama is seen from. Default origin.
    #[serde(default)]
    pub position: [f32; 3],
}

fn one() -> f32 {
    1.0
}

impl ProbeDescription {
    /// Checks the rotation, position and scale.
    pub(crate) fn validate(&self) -> Result<(), DescriptionError> {
        finite3("probe.rotation_deg", self.rotation_deg)?;
        finite3("probe.position", self.position)?;
        positive("probe.radiance_scale", self.radiance_scale)
    }
}
