//! The background a render is composited into, at the output size: in every case the mean, over
//! each output pixel's area, of what the camera sees there (the same quantity the pixel's
//! jittered samples estimate where they meet geometry, so partly covered pixels blend
//! consistently).
//!
//! - A panorama background seen by the panorama camera is the probe itself: at the probe's own
//!   size the probe image, pixel for pixel (so an empty scene composites to exactly the probe); at
//!   another size each output pixel is a rectangle of texel coordinates, and its value the exact
//!   area mean of the piecewise-constant probe over it ([`area_resize`]).
//! - A perspective view of the panorama (a pinhole `[camera]` with a panorama background) shows
//!   in each pixel the mean of the probe over the pixel's footprint on the sphere
//!   ([`crate::footprint`]: exact for the piecewise-constant probe up to the footprint's curvature
//!   within a cell), as seen from the probe's centre (no parallax: the probe is at infinity).
//! - A photograph at its own size is itself; at a smaller or larger output size it is box-filtered
//!   by the same exact area mean. O(W H k^2) for a reduction factor k.

use ibl_core::{Image, Rgb};
use ibl_scene::{Background, Camera, Scene};

use crate::footprint::PixelFootprint;

/// The scene's background at `width x height`.
pub fn background_image(scene: &Scene, width: u32, height: u32) -> Image<Rgb> {
    let (w, h) = (width as usize, height as usize);
    let probe = &scene.probe.radiance;
    match &scene.background {
        Background::Panorama if matches!(scene.camera, Camera::Pinhole { .. }) => {
            PixelFootprint::new(
                probe,
                &scene.camera,
                scene.probe.world_from_probe,
                width,
                height,
            )
            .image()
        }
        Background::Panorama if probe.width() == w && probe.height() == h => probe.clone(),
        Background::Panorama => area_resize(probe, w, h),
        Background::Photo(photo) if photo.width() == w && photo.height() == h => photo.clone(),
        Background::Photo(photo) => area_resize(photo, w, h),
    }
}

/// Area-weighted resize of a piecewise-constant image: each output pixel the exact mean of `src`
/// over its rectangle (fractional pixels weighted by their covered area).
pub fn area_resize(src: &Image<Rgb>, width: usize, height: usize) -> Image<Rgb> {
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
