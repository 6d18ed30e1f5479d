//! The background a render is composited into, at the output size.
//!
//! - A panorama background is the probe itself: at the probe's own size it is the probe image,
//!   pixel for pixel (so an empty scene composites to exactly the probe); at another size it is
//!   the probe resampled with `ibl-mapping`'s energy-conserving lat-long resampling.
//! - A perspective view of the panorama (a pinhole `[camera]` with a panorama background) shows
//!   in each pixel the mean probe radiance over a 4 x 4 grid of rays through the pixel (nearest
//!   texel each): exact for a camera at the probe's centre, with parallax error elsewhere.
//! - A photograph at its own size is itself; at a smaller or larger output size it is box-filtered:
//!   each output pixel averages the photo over its footprint, weighting partly covered photo
//!   pixels by the covered area (exact area integral of the piecewise-constant photo). O(W H k^2)
//!   for a reduction factor k.

use glam::Mat3;
use ibl_core::LatLong;
use ibl_core::{Image, Rgb};
use ibl_mapping::{Mapping, resample};
use ibl_scene::{Background, Camera, Scene};

use crate::RenderError;

/// The scene's background at `width x height`.
pub fn background_image(scene: &Scene, width: u32, height: u32) -> Result<Image<Rgb>, RenderError> {
    let (w, h) = (width as usize, height as usize);
    match &scene.background {
        Background::Panorama if matches!(scene.camera, Camera::Pinhole { .. }) => {
            Ok(probe_view(scene, width, height))
        }
        Background::Panorama => {
            let probe = &scene.probe.radiance;
            if probe.width() == w && probe.height() == h {
                Ok(probe.clone())
            } else {
                resample(
                    probe,
                    Mapping::LatLong,
                    Mapping::LatLong,
                    w,
                    h,
                    Mat3::IDENTITY,
                    &|_, _| {},
                )
                .map_err(|e| RenderError::Parameter(format!("resampling the panorama: {e}")))
            }
        }
        Background::Photo(photo) => Ok(if photo.width() == w && photo.height() == h {
            photo.clone()
        } else {
            area_resize(photo, w, h)
        }),
    }
}

/// Sub-pixel rays per axis of [`probe_view`].
const VIEW_SUBSAMPLES: usize = 4;

/// The probe seen through the scene's pinhole camera.
fn probe_view(scene: &Scene, width: u32, height: u32) -> Image<Rgb> {
    let probe = &scene.probe.radiance;
    let grid = LatLong::new(probe.width(), probe.height());
    let probe_from_world = scene.probe.world_from_probe.transpose();
    let n = VIEW_SUBSAMPLES;
    Image::from_fn_par(width as usize, height as usize, |x, y| {
        let mut sum = Rgb::ZERO;
        for sy in 0..n {
            for sx in 0..n {
                let px = x as f32 + (sx as f32 + 0.5) / n as f32;
                let py = y as f32 + (sy as f32 + 0.5) / n as f32;
                let ray = scene.camera.ray(px, py, width, height);
                let (i, j) = grid.dir_to_pixel((probe_from_world * ray.direction).as_dvec3());
                sum += *probe.get(i, j);
            }
        }
        sum / (n * n) as f32
    })
}

/// Area-weighted resize of a piecewise-constant image.
fn area_resize(src: &Image<Rgb>, width: usize, height: usize) -> Image<Rgb> {
    let sx = src.width() as f64 / width as f64;
    let sy = src.height() as f64 / height as f64;
    Image::from_fn_par(width, height, |x, y| {
        let (x0, x1) = (x as f64 * sx, (x + 1) as f64 * sx);
        let (y0, y1) = (y as f64 * sy, (y + 1) as f64 * sy);
        let mut sum = [0.0f64; 3];
        let mut area = 0.0f64;
        for j in (y0.floor() as usize)..(y1.ceil() as usize).min(src.height()) {
            let wy = (y1.min(j as f64 + 1.0) - y0.max(j as f64)).max(0.0);
            for i in (x0.floor() as usize)..(x1.ceil() as usize).min(src.width()) {
                let wx = (x1.min(i as f64 + 1.0) - x0.max(i as f64)).max(0.0);
                let p = src.get(i, j);
                let a = wx * wy;
                sum[0] += f64::from(p.r) * a;
                sum[1] += f64::from(p.g) * a;
                sum[2] += f64::from(p.b) * a;
                area += a;
            }
        }
        if area > 0.0 {
            Rgb::new(
                (sum[0] / area) as f32,
                (sum[1] / area) as f32,
                (sum[2] / area) as f32,
            )
        } else {
            Rgb::ZERO
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_resize_keeps_the_mean() {
        let src = Image::from_fn_par(9, 6, |x, y| Rgb::splat((x * 7 + y * 3) as f32));
        let out = area_resize(&src, 4, 3);
        let mean = |im: &Image<Rgb>| {
            im.pixels().iter().map(|p| f64::from(p.r)).sum::<f64>() / im.len() as f64
        };
        assert!((mean(&src) - mean(&out)).abs() < 1e-4);
    }
}
