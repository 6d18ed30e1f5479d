//! Named coordinate-frame presets and probe rotations.
//!
//! iblkit's world frame is the glTF one: right-handed, +Y up, -Z forward, +X right
//! (CONVENTIONS section 1). Other tools differ in two independent ways, both captured here as
//! fixed orthogonal matrices applied only at import/export edges:
//!
//! * **vector axes** ([`FramePreset::world_from_preset`]): how the tool writes a direction vector
//!   (a light's direction, the brightest direction). `paper` (Madsen & Laursen 2006 read
//!   literally) is Z-up and mirrored, `ours = (-y_p, z_p, x_p)` (det = -1); `blender` is Z-up,
//!   `ours = (x_b, z_b, -y_b)` (as the glTF importer maps axes); `threejs` uses our axes.
//! * **lat-long image layout** ([`FramePreset::world_from_latlong_image`]): which world direction
//!   a pixel of the tool's equirectangular image shows. Reading the tool's image with *our*
//!   formula gives `d_img`; the world direction it shows is `M d_img`. For `paper` this is the
//!   identity (its mirrored axes and left-edge azimuth origin cancel: its images are pixel-for-pixel
//!   ours). `threejs` (`u = atan2(z, x) / 2 pi + 0.5`) and `blender`
//!   (`u = -atan2(y, x) / 2 pi + 0.5`) both centre their image on world +X, a quarter turn from ours.
//!
//! Rotations of a probe are [`EulerDegrees`] at the command line and [`glam::Mat3`] inside.

use glam::{Mat3, Vec3};

/// A named frame convention of another tool or paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FramePreset {
    /// Ours: glTF 2.0, +Y up, -Z forward, +X right.
    Gltf,
    /// Madsen & Laursen 2006: `w = [sin t cos p, sin t sin p, cos t]`, Z up, mirrored.
    Paper,
    /// three.js: our axes; equirect image centred on +X.
    Threejs,
    /// Blender: Z up, -Y forward; equirect image centred on +X.
    Blender,
}

impl FramePreset {
    /// Every preset, in a stable order.
    pub const ALL: [FramePreset; 4] = [
        FramePreset::Gltf,
        FramePreset::Paper,
        FramePreset::Threejs,
        FramePreset::Blender,
    ];

    /// The preset's name as used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            FramePreset::Gltf => "gltf",
            FramePreset::Paper => "paper",
            FramePreset::Threejs => "threejs",
            FramePreset::Blender => "blender",
        }
    }

    /// Looks a preset up by name (case-insensitive).
    pub fn from_name(name: &str) -> Option<FramePreset> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name))
    }

    /// Matrix taking a vector written in the preset's axes to our world frame.
    pub fn world_from_preset(self) -> Mat3 {
        match self {
            FramePreset::Gltf | FramePreset::Threejs => Mat3::IDENTITY,
            // ours = (-y_p, z_p, x_p); columns are the images of the preset's basis vectors.
            FramePreset::Paper => Mat3::from_cols(Vec3::Z, Vec3::NEG_X, Vec3::Y),
            // ours = (x_b, z_b, -y_b).
            FramePreset::Blender => Mat3::from_cols(Vec3::X, Vec3::NEG_Z, Vec3::Y),
        }
    }

    /// Matrix taking a vector in our world frame to the preset's axes (the transpose).
    pub fn preset_from_world(self) -> Mat3 {
        self.world_from_preset().transpose()
    }

    /// Rotation taking the direction that *our* lat-long formula assigns to a pixel of the preset's
    /// equirectangular image to the world direction that pixel shows.
    pub fn world_from_latlong_image(self) -> Mat3 {
        match self {
            FramePreset::Gltf | FramePreset::Paper => Mat3::IDENTITY,
            // (x, y, z) -> (-z, y, x): image centre (-Z) shows +X, u = 0.75 (+X) shows +Z.
            FramePreset::Threejs | FramePreset::Blender => {
                Mat3::from_cols(Vec3::Z, Vec3::Y, Vec3::NEG_X)
            }
        }
    }
}

/// A probe rotation given as yaw, pitch and roll in degrees (the command line's `--rotate Y,P,R`).
///
/// The rotation is `R = Ry(yaw) Rx(pitch) Rz(roll)` (right-hand rule about +Y, +X and +Z, applied
/// roll first), taking probe directions to world directions (`world_from_probe`). A positive yaw of
/// 90 degrees moves what was straight ahead (-Z) to the left (-X); a positive pitch tilts what was
/// ahead upwards.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EulerDegrees {
    /// Rotation about +Y (up), degrees.
    pub yaw_deg: f32,
    /// Rotation about +X (right), degrees.
    pub pitch_deg: f32,
    /// Rotation about +Z (backwards), degrees.
    pub roll_deg: f32,
}

impl EulerDegrees {
    /// The rotation matrix `world_from_probe`.
    pub fn world_from_probe(self) -> Mat3 {
        Mat3::from_rotation_y(self.yaw_deg.to_radians())
            * Mat3::from_rotation_x(self.pitch_deg.to_radians())
            * Mat3::from_rotation_z(self.roll_deg.to_radians())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_axes_match_conventions() {
        // ours = (-y_p, z_p, x_p)
        let p = Vec3::new(0.3, -0.5, 0.8);
        let ours = FramePreset::Paper.world_from_preset() * p;
        assert!(ours.abs_diff_eq(Vec3::new(0.5, 0.8, 0.3), 1e-6));
        assert!((FramePreset::Paper.world_from_preset().determinant() + 1.0).abs() < 1e-6);
    }

    #[test]
    fn presets_are_orthogonal() {
        for p in FramePreset::ALL {
            for m in [p.world_from_preset(), p.world_from_latlong_image()] {
                assert!(
                    (m * m.transpose()).abs_diff_eq(Mat3::IDENTITY, 1e-6),
                    "{p:?}"
                );
            }
            assert_eq!(FramePreset::from_name(p.name()), Some(p));
        }
    }

    #[test]
    fn yaw_moves_forward_to_the_left() {
        let r = EulerDegrees {
            yaw_deg: 90.0,
            ..Default::default()
        }
        .world_from_probe();
        assert!((r * Vec3::NEG_Z).abs_diff_eq(Vec3::NEG_X, 1e-6));
        let r = EulerDegrees {
            pitch_deg: 90.0,
            ..Default::default()
        }
        .world_from_probe();
        assert!((r * Vec3::NEG_Z).abs_diff_eq(Vec3::Y, 1e-6));
    }
}
