//! The omnidirectional depth map of the room seen from the probe centre (Grosch 2005, section
//! 3.2 and Fig. 5): per lat-long pixel, the distance to the first surface and which patch and
//! face it is.
//!
//! Pixel `(i, j)` of a `W x H` map looks along `world_from_probe * d(u, v)` with the pixel
//! centre's `(u, v)` (`docs/CONVENTIONS.md` section 2), from `probe_position`, so the map is
//! pixel-aligned with the probe image. One ray per pixel centre on the room's BVH. A pixel whose
//! ray meets a patch's back side (a gap in the model) or nothing (an open model) has no patch.
//! The depth test [`ProbeDepthMap::sees`] tells whether the probe saw a world point: what the
//! hole filling of a moved camera (section 4.4) needs. Cost: one ray per pixel, rows in
//! parallel, identical for any thread count.

use glam::Vec3;
use ibl_core::{Image, LatLong};
use rayon::prelude::*;

use crate::{Room, RoomError};

/// "No patch" in the patch and face maps.
pub const NO_PATCH: u32 = u32::MAX;

/// Largest depth map, pixels.
pub const MAX_DEPTH_PIXELS: usize = 1 << 26;

/// What one depth-map pixel sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthSample {
    /// Distance from the probe centre along the pixel centre's ray, metres (`INFINITY` when the
    /// ray met nothing).
    pub distance_m: f32,
    /// The patch whose front the ray met, or [`NO_PATCH`].
    pub patch: u32,
    /// The face of the surface met (front or back), or [`NO_PATCH`].
    pub face: u32,
}

/// The depth map: one [`DepthSample`] per pixel, row 0 at the top.
#[derive(Clone, Debug)]
pub struct ProbeDepthMap {
    samples: Image<DepthSample>,
    /// Pixels whose ray met a back side.
    pub back_pixels: usize,
    /// Pixels whose ray met nothing.
    pub empty_pixels: usize,
}

impl ProbeDepthMap {
    /// Casts one ray per pixel centre of a `width x height` lat-long map from the probe.
    pub fn new(room: &Room, width: usize, height: usize) -> Result<ProbeDepthMap, RoomError> {
        if width == 0 || height == 0 || width.saturating_mul(height) > MAX_DEPTH_PIXELS {
            return Err(RoomError::Parameter(format!(
                "a {width} x {height} depth map is empty or more than {MAX_DEPTH_PIXELS} pixels"
            )));
        }
        let latlong = LatLong::new(width, height);
        let rows: Vec<Vec<DepthSample>> = (0..height)
            .into_par_iter()
            .map(|j| {
                (0..width)
                    .map(|i| {
                        let d = room.world_from_probe * latlong.pixel_dir(i, j);
                        match room.hit(room.probe_position, d.normalize(), 0.0, f32::INFINITY) {
                            Some(hit) => DepthSample {
                                distance_m: hit.distance_m,
                                patch: if hit.front { hit.patch } else { NO_PATCH },
                                face: room.patches[hit.patch as usize].face,
                            },
                            None => DepthSample {
                                distance_m: f32::INFINITY,
                                patch: NO_PATCH,
                                face: NO_PATCH,
                            },
                        }
                    })
                    .collect()
            })
            .collect();
        let samples = Image::from_vec(width, height, rows.into_iter().flatten().collect())
            .map_err(|e| RoomError::Numerical(e.to_string()))?;
        let back_pixels = samples
            .pixels()
            .iter()
            .filter(|s| s.patch == NO_PATCH && s.face != NO_PATCH)
            .count();
        let empty_pixels = samples
            .pixels()
            .iter()
            .filter(|s| s.face == NO_PATCH)
            .count();
        Ok(ProbeDepthMap {
            samples,
            back_pixels,
            empty_pixels,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.samples.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.samples.height()
    }

    /// The sample of pixel `(i, j)`.
    pub fn sample(&self, i: usize, j: usize) -> DepthSample {
        *self.samples.get(i, j)
    }

    /// All samples, row 0 at the top.
    pub fn samples(&self) -> &Image<DepthSample> {
        &self.samples
    }

    /// Distances as an image, metres (`INFINITY` where nothing was met): Grosch's Fig. 5.
    pub fn distance_image(&self) -> Image<f32> {
        self.samples.map(|s| s.distance_m)
    }

    /// Whether the probe saw the world point `point`: the depth of the pixel it projects to is
    /// not shorter than its own distance by more than `tolerance_m` (shadow-map style, Grosch
    /// section 4.4).
    pub fn sees(&self, room: &Room, point: Vec3, tolerance_m: f32) -> bool {
        let to_point = point - room.probe_position;
        let distance = to_point.length();
        if distance <= 0.0 {
            return true;
        }
        let probe_dir = room.world_from_probe.transpose() * to_point;
        let (i, j) = LatLong::new(self.width(), self.height()).dir_to_pixel(probe_dir.as_dvec3());
        self.sample(i, j).distance_m >= distance - tolerance_m
    }
}
