//! `[camera]`: a pinhole camera (glTF convention: looks along its -Z, +Y up, +X right), given by
//! its position, a point it looks at, an up hint and a vertical field of view or a focal length
//! in pixels (with the principal point), the intrinsics of a photograph or of a panorama view.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, finite3, invalid, positive};

/// `[camera]`: a pinhole camera (glTF convention: looks along its -Z, +Y up, +X right).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDescription {
    /// Eye position, world frame.
    pub position: [f32; 3],
    /// A point the camera looks at, world frame.
    pub look_at: [f32; 3],
    /// Up hint, world frame. Default +Y.
    #[serde(default = "up")]
    pub up: [f32; 3],
    /// Vertical field of view, degrees (give this or `focal_length_px`).
    pub vertical_fov_deg: Option<f32>,
    /// Focal length in pixels of the photograph, `[fx, fy]`.
    pub focal_length_px: Option<[f32; 2]>,
    /// Principal point in pixels of the photograph, `[cx, cy]`. Default the image centre.
    pub principal_point_px: Option<[f32; 2]>,
    /// Image size `[width, height]` in pixels the intrinsics refer to: required for a view of
    /// the panorama; a photo's own size otherwise (and then it must not be given).
    pub image_size_px: Option<[u32; 2]>,
}

fn up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

impl CameraDescription {
    pub(crate) fn validate(&self) -> Result<(), DescriptionError> {
        finite3("camera.position", self.position)?;
        finite3("camera.look_at", self.look_at)?;
        finite3("camera.up", self.up)?;
        let forward = Vec3::from(self.look_at) - Vec3::from(self.position);
        if forward.length() <= 0.0 {
            return Err(invalid("camera.look_at", "equals camera.position"));
        }
        if forward.cross(Vec3::from(self.up)).length() <= 1e-6 * forward.length() {
            return Err(invalid("camera.up", "is parallel to the viewing direction"));
        }
        match (self.vertical_fov_deg, self.focal_length_px) {
            (Some(_), Some(_)) => Err(invalid(
                "camera",
                "give either vertical_fov_deg or focal_length_px, not both",
            )),
            (None, None) => Err(invalid(
                "camera",
                "needs vertical_fov_deg or focal_length_px",
            )),
            (Some(fov), None) => {
                if fov.is_finite() && fov > 0.0 && fov < 179.0 {
                    Ok(())
                } else {
                    Err(invalid(
                        "camera.vertical_fov_deg",
                        format!("{fov} is not in (0, 179)"),
                    ))
                }
            }
            (None, Some(f)) => {
                positive("camera.focal_length_px[0]", f[0])?;
                positive("camera.focal_length_px[1]", f[1])?;
                if let Some(c) = self.principal_point_px {
                    finite3("camera.principal_point_px", [c[0], c[1], 0.0])?;
                }
                Ok(())
            }
        }
    }
}
