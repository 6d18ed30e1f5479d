//! Camera movement (Grosch 2005, section 4.4): the room seen from a viewpoint other than the
//! probe's. The probe is projected onto the reconstructed geometry: a surface point the probe saw
//! shows the probe's radiance in its direction; a point the omnidirectional depth map says it
//! did not see ("if the z-value in the texture is smaller than the real z-value ... we use the
//! radiance estimate", the shadow-map test) shows the radiance estimate of section 3.2, `rho E /
//! pi` of its patch. Both come from [`RoomRadiance`] (its module doc states the depth test's
//! tolerance, `d tan(80 deg) pi / (2 H)` plus 1 mm). Beyond the paper the fill can be modulated
//! by the texture of the part of the same face the probe saw ([`HoleFill::Textured`],
//! [`crate::fill_texture`]).
//!
//! The camera is `ibl-scene`'s ([`Camera`]: a pinhole, or a panorama from a new centre), in the
//! room's world frame (metres). Each output pixel `(i, j)`, covering `[i, i + 1) x [j, j + 1)`,
//! averages `n x n` rays through the centres of an `n x n` grid of sub-pixels (deterministic,
//! so the image is the same for any thread count), and records which fraction of them was
//! filled (met a surface the probe did not see) and which met no front side (a back side or
//! nothing: black). Radiance in the probe's units. Cost: `n^2` rays per pixel and a depth test
//! per hit, rows in parallel.

use ibl_core::{Image, Rgb};
use ibl_scene::Camera;
use rayon::prelude::*;

use crate::RoomError;
use crate::depth_map::NO_PATCH;
use crate::fill_texture::FillTexture;
use crate::room_radiance::RoomRadiance;

/// Largest novel view, pixels (a 4096 x 4096 image).
pub const MAX_VIEW_PIXELS: usize = 1 << 24;

/// Most sub-pixel rays per axis.
pub const MAX_SAMPLES_PER_AXIS: u32 = 16;

/// What fills the surfaces the probe did not see.
#[derive(Clone, Copy, Debug)]
pub enum HoleFill<'a> {
    /// The patch's radiance estimate `rho E / pi` (Grosch 2005, section 4.4).
    Estimate,
    /// The estimate times the reflectance texture of the seen part of the face (beyond the
    /// paper, its section 5).
    Textured(&'a FillTexture),
}

/// Settings of a novel view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NovelViewSettings {
    /// Rays per pixel along each axis (`n`, so `n^2` per pixel), 1 to [`MAX_SAMPLES_PER_AXIS`].
    pub samples_per_axis: u32,
}

impl Default for NovelViewSettings {
    /// 2 x 2 rays: edges antialiased at a quarter pixel, as a path tracer's jittered samples
    /// average them.
    fn default() -> Self {
        NovelViewSettings {
            samples_per_axis: 2,
        }
    }
}

/// A view of the room from a new viewpoint, every image `width x height`, row 0 at the top.
#[derive(Clone, Debug)]
pub struct NovelView {
    /// Radiance, probe units.
    pub image: Image<Rgb>,
    /// Per pixel, the fraction of its rays that met a surface the probe did not see (filled).
    pub filled: Image<f32>,
    /// Per pixel, the fraction of its rays that met no front side (left black).
    pub missed: Image<f32>,
    /// The patch the ray through the pixel's centre meets the front of, or [`NO_PATCH`].
    pub patch: Image<u32>,
}

impl NovelView {
    /// Pixels every ray of which shows the probe's radiance.
    pub fn seen_mask(&self) -> Image<bool> {
        Image::from_fn_par(self.image.width(), self.image.height(), |i, j| {
            *self.filled.get(i, j) == 0.0 && *self.missed.get(i, j) == 0.0
        })
    }

    /// Pixels every ray of which was filled.
    pub fn filled_mask(&self) -> Image<bool> {
        self.filled.map(|&f| f == 1.0)
    }
}

/// One pixel's result.
#[derive(Clone, Copy)]
struct PixelValue {
    radiance: Rgb,
    filled: f32,
    missed: f32,
    patch: u32,
}

/// Renders the room of `radiance` through `camera` at `width x height` pixels, the surfaces the
/// probe did not see filled by `fill`.
pub fn render_novel_view(
    radiance: &RoomRadiance,
    camera: &Camera,
    width: u32,
    height: u32,
    fill: HoleFill,
    settings: &NovelViewSettings,
) -> Result<NovelView, RoomError> {
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 || w.saturating_mul(h) > MAX_VIEW_PIXELS {
        return Err(RoomError::Parameter(format!(
            "a {width} x {height} view is empty or more than {MAX_VIEW_PIXELS} pixels"
        )));
    }
    let n = settings.samples_per_axis;
    if !(1..=MAX_SAMPLES_PER_AXIS).contains(&n) {
        return Err(RoomError::Parameter(format!(
            "{n} samples per axis: 1 to {MAX_SAMPLES_PER_AXIS}"
        )));
    }
    let room = radiance.room();
    let trace = |x: f32, y: f32| {
        let ray = camera.ray(x, y, width, height);
        let hit = radiance.along(ray.origin, ray.direction, 0.0)?;
        let radiance = match (hit.seen, fill) {
            (false, HoleFill::Textured(texture)) => {
                let point = ray.origin + ray.direction * hit.distance_m;
                let face = room.patches[hit.patch as usize].face as usize;
                hit.radiance * texture.modulation(face, point)
            }
            _ => hit.radiance,
        };
        Some((hit, radiance))
    };
    let rows: Vec<Vec<PixelValue>> = (0..h)
        .into_par_iter()
        .map(|j| {
            (0..w)
                .map(|i| {
                    let mut value = PixelValue {
                        radiance: Rgb::ZERO,
                        filled: 0.0,
                        missed: 0.0,
                        patch: NO_PATCH,
                    };
                    for b in 0..n {
                        for a in 0..n {
                            let x = i as f32 + (a as f32 + 0.5) / n as f32;
                            let y = j as f32 + (b as f32 + 0.5) / n as f32;
                            match trace(x, y) {
                                Some((hit, l)) => {
                                    value.radiance += l;
                                    if !hit.seen {
                                        value.filled += 1.0;
                                    }
                                }
                                None => value.missed += 1.0,
                            }
                        }
                    }
                    let rays = (n * n) as f32;
                    value.radiance = value.radiance / rays;
                    value.filled /= rays;
                    value.missed /= rays;
                    let centre = camera.ray(i as f32 + 0.5, j as f32 + 0.5, width, height);
                    if let Some(hit) = room.hit(centre.origin, centre.direction, 0.0, f32::INFINITY)
                        && hit.front
                    {
                        value.patch = hit.patch;
                    }
                    value
                })
                .collect()
        })
        .collect();
    let values: Vec<PixelValue> = rows.into_iter().flatten().collect();
    let image = |f: &dyn Fn(&PixelValue) -> f32| {
        Image::from_vec(w, h, values.iter().map(f).collect())
            .map_err(|e| RoomError::Numerical(e.to_string()))
    };
    Ok(NovelView {
        image: Image::from_vec(w, h, values.iter().map(|v| v.radiance).collect())
            .map_err(|e| RoomError::Numerical(e.to_string()))?,
        filled: image(&|v| v.filled)?,
        missed: image(&|v| v.missed)?,
        patch: Image::from_vec(w, h, values.iter().map(|v| v.patch).collect())
            .map_err(|e| RoomError::Numerical(e.to_string()))?,
    })
}
