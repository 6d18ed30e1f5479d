//! Perspective views of the panorama from the probe centre (Grosch 2005, section 3.1: "the
//! camera is placed in the center of the sphere with a perspective projection"): where marks are
//! drawn, and the pictures they are drawn on.
//!
//! A view is a pinhole camera at the probe centre in the glTF convention (looks along its -Z, +Y
//! up, +X right), turned by `probe_from_view = Ry(yaw) Rx(pitch) Rz(roll)` (the rotation
//! convention of `docs/CONVENTIONS.md` section 1, in the probe's own frame), with a vertical field
//! of view over `height` pixels: `f = (height / 2) / tan(fov / 2)`, principal point at the image
//! centre. Continuous pixel `(x, y)` (row 0 at the top, pixel `(i, j)` covering `[i, i + 1) x [j,
//! j + 1)`) looks along `probe_from_view ((x - W/2) / f, -(y - H/2) / f, -1)`. Everything is f64:
//! a vanishing point is a direction known to hundredths of a degree.

use glam::{DMat3, DVec3};
use ibl_core::{Image, LatLong, Rgb};
use serde::{Deserialize, Serialize};

/// A perspective view of the panorama.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerspectiveView {
    /// Turn about the probe's +Y, degrees (positive looks left).
    pub yaw_deg: f64,
    /// Tilt about +X, degrees (positive looks up).
    #[serde(default)]
    pub pitch_deg: f64,
    /// Roll about +Z, degrees.
    #[serde(default)]
    pub roll_deg: f64,
    /// Vertical field of view, degrees, in (1, 170).
    pub vertical_fov_deg: f64,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
}

/// Largest view side, pixels.
pub const MAX_VIEW_SIDE: u32 = 16384;

impl PerspectiveView {
    /// Rotation from view directions to probe directions.
    pub fn probe_from_view(&self) -> DMat3 {
        DMat3::from_rotation_y(self.yaw_deg.to_radians())
            * DMat3::from_rotation_x(self.pitch_deg.to_radians())
            * DMat3::from_rotation_z(self.roll_deg.to_radians())
    }

    /// Focal length, pixels.
    pub fn focal_px(&self) -> f64 {
        0.5 * f64::from(self.height) / (0.5 * self.vertical_fov_deg.to_radians()).tan()
    }

    /// Unit probe-frame direction through continuous pixel `(x, y)`.
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        let f = self.focal_px();
        let v = DVec3::new(
            (x - 0.5 * f64::from(self.width)) / f,
            -(y - 0.5 * f64::from(self.height)) / f,
            -1.0,
        );
        (self.probe_from_view() * v).normalize()
    }

    /// Continuous pixel coordinates of a probe-frame direction, if it lies in front of the view
    /// (anywhere on the image plane, inside the picture or not).
    pub fn project(&self, probe_dir: DVec3) -> Option<(f64, f64)> {
        let v = self.probe_from_view().transpose() * probe_dir;
        if v.z >= -1e-12 {
            return None;
        }
        let f = self.focal_px();
        Some((
            0.5 * f64::from(self.width) + f * (v.x / -v.z),
            0.5 * f64::from(self.height) - f * (v.y / -v.z),
        ))
    }

    /// The view of a lat-long `probe` (bilinear look-ups at pixel centres, wrapping across the
    /// seam, clamped at the poles).
    pub fn render(&self, probe: &Image<Rgb>) -> Image<Rgb> {
        Image::from_fn_par(self.width as usize, self.height as usize, |x, y| {
            sample_latlong(probe, self.direction(x as f64 + 0.5, y as f64 + 0.5))
        })
    }
}

/// Bilinear radiance of a lat-long image in probe direction `d`.
pub fn sample_latlong(probe: &Image<Rgb>, d: DVec3) -> Rgb {
    let (w, h) = (probe.width(), probe.height());
    if w == 0 || h == 0 {
        return Rgb::ZERO;
    }
    let (u, v) = LatLong::dir_to_uv(d);
    let fx = u * w as f64 - 0.5;
    let fy = (v * h as f64 - 0.5).clamp(0.0, h as f64 - 1.0);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = ((fx - x0) as f32, (fy - y0) as f32);
    let xi = |x: f64| (x as i64).rem_euclid(w as i64) as usize;
    let (xa, xb) = (xi(x0), xi(x0 + 1.0));
    let ya = y0 as usize;
    let yb = (ya + 1).min(h - 1);
    let top = *probe.get(xa, ya) * (1.0 - tx) + *probe.get(xb, ya) * tx;
    let bottom = *probe.get(xa, yb) * (1.0 - tx) + *probe.get(xb, yb) * tx;
    top * (1.0 - ty) + bottom * ty
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_forward_and_projects_back() {
        let view = PerspectiveView {
            yaw_deg: 0.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            vertical_fov_deg: 90.0,
            width: 800,
            height: 600,
        };
        assert!(
            view.direction(400.0, 300.0)
                .abs_diff_eq(DVec3::NEG_Z, 1e-12)
        );
        // 90 degrees vertical: the top edge's centre is 45 degrees up.
        let up = view.direction(400.0, 0.0);
        assert!((up.y - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        let turned = PerspectiveView {
            yaw_deg: 30.0,
            pitch_deg: -10.0,
            roll_deg: 5.0,
            ..view
        };
        let d = turned.direction(123.25, 456.5);
        let (x, y) = turned.project(d).expect("in front");
        assert!((x - 123.25).abs() < 1e-9 && (y - 456.5).abs() < 1e-9);
        // Yaw +90 looks left (-X), as CONVENTIONS section 1.
        let left = PerspectiveView {
            yaw_deg: 90.0,
            ..view
        };
        assert!(
            left.direction(400.0, 300.0)
                .abs_diff_eq(DVec3::NEG_X, 1e-12)
        );
    }
}
