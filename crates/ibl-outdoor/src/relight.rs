//! The relit environment map of a frame (Jensen, Andersen & Madsen 2006, section 4.2): every
//! surface pixel of the probe by the per-frame model, the sky filled with the estimate, the sun
//! left out and returned as a directional light.
//!
//! ```text
//! surface pixel:   L = d (c_shape P_a + s max(0, n . l) P_d)
//! sky pixel:       L = P_a shape(w)                       (the paper: L = P_a, a uniform sky)
//! no albedo:       L = L_probe P_a / P_a,0                (it sees neither sky nor sun)
//! sun:             a directional light towards l with irradiance I = pi P_d
//! ```
//!
//! With a [`crate::SkyModel::Preetham`] shape the relit sky keeps the clear sky's structure (bright
//! near the sun and the horizon) at the estimated level; with `Uniform` it is the paper's flat
//! colour. The per-pixel work is a few multiply-adds, in parallel by rows; the sky pixels' shape
//! values and the surface pixels' sky terms are cached until the sky shape changes
//! ([`crate::tracking`]). Cost O(W H) per frame.

use glam::Vec3;
use ibl_core::{Image, Rgb};
use ibl_scene::GeometryLayer;
use rayon::prelude::*;
use serde::Serialize;

use crate::OutdoorError;
use crate::maps::ProbeMaps;
use crate::tracking::{PointLighting, SkyTracker};

/// The sun as a directional light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SunLight {
    /// Unit world direction towards the sun.
    pub direction: [f32; 3],
    /// `I = pi P_d`: irradiance on a surface facing the sun, RGB.
    pub irradiance: [f32; 3],
}

impl SunLight {
    /// The light of `P_d` from `direction`.
    pub fn new(direction: Vec3, sun: Rgb) -> SunLight {
        SunLight {
            direction: direction.to_array(),
            irradiance: (sun * std::f32::consts::PI).to_array(),
        }
    }
}

/// Relights the probe's map frame after frame.
#[derive(Clone, Debug)]
pub struct Relighter {
    lighting: PointLighting,
    /// Per pixel: the sky shape towards a sky pixel, 0 on surface pixels.
    sky_pixels: Vec<Rgb>,
    sky_generation: u64,
}

impl Relighter {
    /// A relighter for `maps` whose shadow map is re-cast when the sun moves more than
    /// `shadow_threshold_rad`.
    pub fn new(maps: &ProbeMaps, shadow_threshold_rad: f32) -> Relighter {
        Relighter {
            lighting: PointLighting::new(
                shadow_threshold_rad,
                maps.footprints().to_vec(),
                maps.footprint_size(),
            ),
            sky_pixels: Vec::new(),
            sky_generation: 0,
        }
    }

    /// Brings the caches up to date for the sun towards `sun` (the tracker must be current).
    pub fn update(
        &mut self,
        layer: &GeometryLayer,
        maps: &ProbeMaps,
        sky: &SkyTracker,
        sun: Vec3,
    ) -> Result<(), OutdoorError> {
        self.lighting
            .update(layer, maps.points(), maps.transfer(), sky, sun)?;
        if self.sky_generation != sky.generation() {
            let (w, h) = maps.size();
            let shape = sky.shape()?;
            let rotation = maps.projection().world_from_probe;
            let grid = ibl_core::LatLong::new(w, h);
            self.sky_pixels = (0..w * h)
                .into_par_iter()
                .map(|p| match maps.point_of_pixel(p) {
                    Some(_) => Rgb::ZERO,
                    None => shape.radiance(rotation * grid.pixel_dir(p % w, p / w)),
                })
                .collect();
            self.sky_generation = sky.generation();
        }
        Ok(())
    }

    /// The sun-dependent terms of the probe's surface points.
    pub fn lighting(&self) -> &PointLighting {
        &self.lighting
    }

    /// The sky shape at each pixel (0 on surface pixels).
    pub fn sky_pixels(&self) -> &[Rgb] {
        &self.sky_pixels
    }

    /// The relit map for `P_a = sky`, `P_d = sun`, the sun towards `sun_direction`, written into
    /// `out` (resized to the probe's size).
    pub fn relight_into(
        &self,
        maps: &ProbeMaps,
        sun_direction: Vec3,
        sky: Rgb,
        sun: Rgb,
        out: &mut Image<Rgb>,
    ) -> Result<(), OutdoorError> {
        let (w, h) = maps.size();
        if self.sky_pixels.len() != w * h || self.lighting.sky_terms().len() != maps.points().len()
        {
            return Err(OutdoorError::Parameter(
                "the relighter was not updated for these maps".into(),
            ));
        }
        if out.width() != w || out.height() != h {
            *out = Image::filled(w, h, Rgb::ZERO);
        }
        let capture_sky = Rgb::from_array(maps.capture().sky);
        let sky_ratio = Rgb::new(
            sky.r / capture_sky.r.max(1e-30),
            sky.g / capture_sky.g.max(1e-30),
            sky.b / capture_sky.b.max(1e-30),
        );
        let albedo = maps.albedo();
        let terms = self.lighting.sky_terms();
        let probe = maps.probe().pixels();
        out.rows_mut()
            .collect::<Vec<_>>()
            .into_par_iter()
            .enumerate()
            .for_each(|(j, row)| {
                for (i, px) in row.iter_mut().enumerate() {
                    let p = j * w + i;
                    *px = match maps.point_of_pixel(p) {
                        None => self.sky_pixels[p] * sky,
                        Some(k) => match albedo[k] {
                            Some(d) => {
                                let k_sun = self.lighting.sun_term(k, sun_direction);
                                d * (terms[k] * sky + sun * k_sun)
                            }
                            None => probe[p] * sky_ratio,
                        },
                    };
                }
            });
        Ok(())
    }

    /// [`Self::relight_into`] into a new image.
    pub fn relight(
        &self,
        maps: &ProbeMaps,
        sun_direction: Vec3,
        sky: Rgb,
        sun: Rgb,
    ) -> Result<Image<Rgb>, OutdoorError> {
        let mut out = Image::filled(0, 0, Rgb::ZERO);
        self.relight_into(maps, sun_direction, sky, sun, &mut out)?;
        Ok(out)
    }
}
