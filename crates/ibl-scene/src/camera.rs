//! Cameras: how an output pixel becomes a primary ray (world frame).
//!
//! - **Panorama**: the probe seen from its centre. Output pixel `(x, y)` of a `W x W/2` image has
//!   the lat-long coordinates `u = x / W`, `v = y / H` of CONVENTIONS section 2 in the probe's own
//!   frame, so the panorama is pixel-aligned with the probe image: the direction is
//!   `world_from_probe * d(u, v)`, from the probe's world position.
//! - **Pinhole**: a photograph's camera (glTF convention: looks along its -Z, +Y up, +X right),
//!   intrinsics in pixels of the photograph (`fx, fy, cx, cy`, row 0 at the top), scaled to the
//!   output size: direction `world_from_camera * ((x - cx) / fx, -(y - cy) / fy, -1)`, normalised.
//!
//! Pixel coordinates are continuous: pixel `(i, j)` covers `[i, i + 1) x [j, j + 1)`, its centre is
//! `(i + 0.5, j + 0.5)`.

use glam::{Mat3, Vec2, Vec3};
use ibl_core::LatLong;

use crate::Ray;

/// A camera producing primary rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Camera {
    /// The lat-long panorama seen from the probe's centre.
    Panorama {
        /// The probe centre, world frame.
        position: Vec3,
        /// Rotation from the probe frame to the world.
        world_from_probe: Mat3,
    },
    /// A pinhole camera.
    Pinhole {
        /// Eye, world frame.
        position: Vec3,
        /// Rotation from the camera frame (-Z forward) to the world.
        world_from_camera: Mat3,
        /// Focal lengths `(fx, fy)` in pixels of the reference image.
        focal_px: Vec2,
        /// Principal point `(cx, cy)` in pixels of the reference image.
        principal_px: Vec2,
        /// Size `(width, height)` of the reference image (the photograph), pixels.
        reference_size: (u32, u32),
    },
}

impl Camera {
    /// A pinhole camera at `position` looking at `look_at`, `up` the up hint.
    pub fn look_at(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        focal_px: Vec2,
        principal_px: Vec2,
        reference_size: (u32, u32),
    ) -> Camera {
        let back = (position - look_at).normalize();
        let right = up.cross(back).normalize();
        let true_up = back.cross(right);
        Camera::Pinhole {
            position,
            world_from_camera: Mat3::from_cols(right, true_up, back),
            focal_px,
            principal_px,
            reference_size,
        }
    }

    /// Focal length in pixels for a vertical field of view over `height` pixels.
    pub fn focal_from_vertical_fov(vertical_fov_deg: f32, height: u32) -> f32 {
        0.5 * height as f32 / (0.5 * vertical_fov_deg.to_radians()).tan()
    }

    /// Output size for a requested width: a panorama is `W x W/2`; a pinhole image keeps its
    /// reference aspect ratio (height rounded, at least 1). `None` takes the reference width
    /// (`default_width` for a panorama).
    pub fn output_size(&self, width: Option<u32>, default_width: u32) -> (u32, u32) {
        match *self {
            Camera::Panorama { .. } => {
                let w = width.unwrap_or(default_width).max(2) & !1;
                (w, w / 2)
            }
            Camera::Pinhole {
                reference_size: (rw, rh),
                ..
            } => {
                let w = width.unwrap_or(rw).max(1);
                let h = ((w as f64 * rh as f64 / rw as f64).round() as u32).max(1);
                (w, h)
            }
        }
    }

    /// The primary ray through continuous output pixel coordinates `(x, y)` of a
    /// `width x height` output image.
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Ray {
        match *self {
            Camera::Panorama {
                position,
                world_from_probe,
            } => {
                let d = LatLong::uv_to_dir(x as f64 / width as f64, y as f64 / height as f64);
                Ray::new(position, (world_from_probe * d).normalize())
            }
            Camera::Pinhole {
                position,
                world_from_camera,
                focal_px,
                principal_px,
                reference_size,
            } => {
                let sx = reference_size.0 as f32 / width as f32;
                let sy = reference_size.1 as f32 / height as f32;
                let (px, py) = (x * sx, y * sy);
                let d = Vec3::new(
                    (px - principal_px.x) / focal_px.x,
                    -(py - principal_px.y) / focal_px.y,
                    -1.0,
                );
                Ray::new(position, (world_from_camera * d).normalize())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panorama_pixels_follow_the_probe_layout() {
        let cam = Camera::Panorama {
            position: Vec3::ZERO,
            world_from_probe: Mat3::IDENTITY,
        };
        // (u, v) = (0.5, 0.5) is forward, (0.75, 0.5) is +X.
        let r = cam.ray(64.0, 32.0, 128, 64);
        assert!((r.direction - Vec3::NEG_Z).length() < 1e-6);
        let r = cam.ray(96.0, 32.0, 128, 64);
        assert!((r.direction - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn pinhole_centre_looks_at_the_target() {
        let cam = Camera::look_at(
            Vec3::new(0.0, 1.0, 5.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            Vec2::splat(100.0),
            Vec2::new(50.0, 40.0),
            (100, 80),
        );
        let r = cam.ray(100.0, 80.0, 200, 160);
        assert!((r.direction - Vec3::NEG_Z).length() < 1e-6);
        // The top of the image looks up.
        let top = cam.ray(100.0, 0.0, 200, 160);
        assert!(top.direction.y > 0.0);
        let right = cam.ray(200.0, 80.0, 200, 160);
        assert!(right.direction.x > 0.0);
        assert_eq!(cam.output_size(Some(50), 0), (50, 40));
    }

    #[test]
    fn focal_from_fov() {
        let f = Camera::focal_from_vertical_fov(90.0, 200);
        assert!((f - 100.0).abs() < 1e-3);
    }
}
