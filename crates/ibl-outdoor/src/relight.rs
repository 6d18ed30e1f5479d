//! The relit environment map of a frame (Jensen, Andersen & Madsen 2006, section 4.2): every
//! surface pixel of the probe by the per-frame model, the sky filled with the estimate, the sun
//! left out and returned as a directional light.
//!
//! ```text
//! pure surface pixel:  L = d (c_shape P_a + k P_d + b_a P_a + b_d P_d)
//! sky pixel:           L = P_a shape(w)                       (the paper: L = P_a, a uniform sky)
//! mixed pixel:         L = (1 / S) sum_j L_j                  (sub-ray j: sky, or its donor's surface)
//! no albedo:           L = L_probe P_a / P_a,0                (it sees neither sky nor sun)
//! sun:                 a directional light towards l with irradiance I = pi P_d
//! ```
//!
//! `k` is the footprint's sun term ([`crate::tracking::PointLighting`]), `b_a`, `b_d` the
//! interreflection terms ([`crate::interreflection`]; zero when off), and a mixed pixel
//! ([`crate::footprint`]) is the mean of its sub-rays: a sky sub-ray by the sky model, a surface
//! sub-ray by its donor's albedo, sky and bounce terms with its own shadow and cosine. Every
//! pixel is linear in the estimates,
//!
//! ```text
//! L = P_a A + P_d (B + D . l)        (per channel; D the albedo-weighted sunlit normal sum)
//! ```
//!
//! so [`Relighter::update`] makes `A`, `B` and `D` per pixel whenever the shadows are re-cast or
//! the sky shape changes ([`crate::tracking`]), and a frame costs a few multiply-adds per pixel:
//! `D . l` keeps the cosines exact as the sun moves between casts (the shadows and the bounce
//! term `B` are those of the last cast). With a [`crate::SkyModel::Preetham`] shape the relit sky
//! keeps the clear sky's structure (bright near the sun and the horizon) at the estimated level;
//! with `Uniform` it is the paper's flat colour. Cost O(W H S) per update, O(W H) per frame.

use glam::Vec3;
use ibl_core::{Image, Rgb};
use ibl_scene::GeometryLayer;
use rayon::prelude::*;
use serde::Serialize;

use crate::OutdoorError;
use crate::interreflection::{Propagated, propagate};
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

/// One pixel's response to the estimates: `L = P_a sky + P_d (sun + sun_linear . l)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelResponse {
    /// Response to unit `P_a`.
    pub sky: Rgb,
    /// Response to unit `P_d` that does not follow the sun's direction (interreflections).
    pub sun: Rgb,
    /// Per channel, the vector whose dot product with the sun direction is the direct part of
    /// the response to unit `P_d`.
    pub sun_linear: [Vec3; 3],
}

impl PixelResponse {
    /// The response to unit `P_d` for the sun towards `l`.
    pub fn sun_response(&self, l: Vec3) -> Rgb {
        self.sun
            + Rgb::new(
                self.sun_linear[0].dot(l),
                self.sun_linear[1].dot(l),
                self.sun_linear[2].dot(l),
            )
    }
}

/// The surface points' radiance responses to unit `P_a` and unit `P_d`, with interreflections.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceResponses {
    /// Response to unit `P_a` per point.
    pub sky: Vec<Rgb>,
    /// Response to unit `P_d` per point (for the sun of the last cast).
    pub sun: Vec<Rgb>,
    /// The same one bounce earlier: what a receiver outside the probe (a sample site) gathers
    /// for the same number of bounces.
    pub sky_previous: Vec<Rgb>,
    /// See [`Self::sky_previous`].
    pub sun_previous: Vec<Rgb>,
}

/// Relights the probe's map frame after frame.
#[derive(Clone, Debug)]
pub struct Relighter {
    lighting: PointLighting,
    sources: SourceResponses,
    pixels: Vec<PixelResponse>,
    /// The (sky generation, shadow casts) the responses were made for.
    made_for: Option<(u64, u32)>,
}

/// `d (x)` per channel for a vector `x`: the per-channel vectors `d_c x`.
fn scaled(d: Rgb, x: Vec3) -> [Vec3; 3] {
    [x * d.r, x * d.g, x * d.b]
}

impl Relighter {
    /// A relighter for `maps` whose shadow map is re-cast when the sun moves more than
    /// `shadow_threshold_rad`.
    pub fn new(maps: &ProbeMaps, shadow_threshold_rad: f32) -> Relighter {
        let f = maps.footprints();
        Relighter {
            lighting: PointLighting::new(shadow_threshold_rad, f.sub_points(), f.per_point()),
            sources: SourceResponses::default(),
            pixels: Vec::new(),
            made_for: None,
        }
    }

    /// Brings the caches up to date for the sun towards `sun` (the tracker must be current):
    /// shadows when the sun moved past the threshold, and then, or when the sky shape changed,
    /// the responses. Returns whether the responses were re-made.
    pub fn update(
        &mut self,
        layer: &GeometryLayer,
        maps: &ProbeMaps,
        sky: &SkyTracker,
        sun: Vec3,
    ) -> Result<bool, OutdoorError> {
        self.lighting
            .update(layer, maps.points(), maps.transfer(), sky, sun)?;
        let state = (sky.generation(), self.lighting.shadow().casts());
        if self.made_for == Some(state) {
            return Ok(false);
        }
        let cast_sun = self.lighting.shadow().sun().unwrap_or(sun);
        let shape = sky.shape()?;
        let probe = maps.probe().pixels();
        let pixels = maps.surface_pixels();
        let capture_sky = Rgb::from_array(maps.capture().sky);
        let terms = self.lighting.sky_terms();
        let n = maps.points().len();
        // Direct responses and albedos; a point without albedo has the fixed response of its
        // captured radiance scaled with the sky, and reflects nothing further.
        let mut albedo = vec![Rgb::ZERO; n];
        let mut direct_sky = vec![Rgb::ZERO; n];
        let mut direct_sun = vec![Rgb::ZERO; n];
        for k in 0..n {
            match maps.albedo()[k] {
                Some(d) => {
                    albedo[k] = d;
                    direct_sky[k] = d * terms[k];
                    direct_sun[k] = d * self.lighting.sun_term(k, cast_sun);
                }
                None => {
                    let p = probe[pixels[k]];
                    direct_sky[k] = Rgb::new(
                        p.r / capture_sky.r.max(1e-30),
                        p.g / capture_sky.g.max(1e-30),
                        p.b / capture_sky.b.max(1e-30),
                    );
                }
            }
        }
        let bounces = maps.settings().interreflection.bounces();
        let (sky_x, sun_x) = match maps.bounce() {
            Some(g) => (
                propagate(g, &albedo, &direct_sky, bounces)?,
                propagate(g, &albedo, &direct_sun, bounces)?,
            ),
            None => {
                let none = |a: Vec<Rgb>| Propagated {
                    previous: a.clone(),
                    bounce: vec![Rgb::ZERO; a.len()],
                    radiance: a,
                };
                (none(direct_sky), none(direct_sun))
            }
        };
        // The sky seen by the mixed pixels' sky sub-rays, per point.
        let footprints = maps.footprints();
        let s = footprints.per_point() as f32;
        let mut mixed_sky = vec![Rgb::ZERO; n];
        for &(k, d) in footprints.sky_rays() {
            mixed_sky[k as usize] += shape.radiance(d) / s;
        }
        let (w, h) = maps.size();
        let rotation = maps.projection().world_from_probe;
        let grid = ibl_core::LatLong::new(w, h);
        let lighting = &self.lighting;
        // The surface response of point `q` seen through a sub-ray with surface point `x` and
        // sun visibility `v`, each weighted 1 / S.
        let sub_ray = |q: usize, x: &crate::transfer::SurfacePoint, v: f32| -> PixelResponse {
            let lit = v > 0.0 && x.normal.dot(cast_sun) > 0.0;
            match maps.albedo()[q] {
                Some(d) => PixelResponse {
                    sky: sky_x.radiance[q] / s,
                    sun: d * sun_x.bounce[q] / s,
                    sun_linear: scaled(d, if lit { x.normal * (v / s) } else { Vec3::ZERO }),
                },
                None => PixelResponse {
                    sky: sky_x.radiance[q] / s,
                    ..PixelResponse::default()
                },
            }
        };
        self.pixels = (0..w * h)
            .into_par_iter()
            .map(|p| {
                let Some(k) = maps.point_of_pixel(p) else {
                    return PixelResponse {
                        sky: shape.radiance(rotation * grid.pixel_dir(p % w, p / w)),
                        ..PixelResponse::default()
                    };
                };
                if !footprints.is_mixed(k) {
                    return match maps.albedo()[k] {
                        Some(d) => PixelResponse {
                            sky: sky_x.radiance[k],
                            sun: d * sun_x.bounce[k],
                            sun_linear: scaled(d, lighting.sunlit_normal(k)),
                        },
                        None => PixelResponse {
                            sky: sky_x.radiance[k],
                            ..PixelResponse::default()
                        },
                    };
                }
                let mut out = PixelResponse {
                    sky: mixed_sky[k],
                    ..PixelResponse::default()
                };
                let subs = lighting.footprint(k).iter().zip(lighting.visibility(k));
                for ((sub, v), donor) in subs.zip(footprints.donors(k)) {
                    let Some(x) = sub else { continue };
                    let r = sub_ray(donor.unwrap_or(k), x, *v);
                    out.sky += r.sky;
                    out.sun += r.sun;
                    for (o, a) in out.sun_linear.iter_mut().zip(r.sun_linear) {
                        *o += a;
                    }
                }
                out
            })
            .collect();
        self.sources = SourceResponses {
            sky: sky_x.radiance,
            sun: sun_x.radiance,
            sky_previous: sky_x.previous,
            sun_previous: sun_x.previous,
        };
        self.made_for = Some(state);
        Ok(true)
    }

    /// The sun-dependent terms of the probe's surface points.
    pub fn lighting(&self) -> &PointLighting {
        &self.lighting
    }

    /// The surface points' responses (after [`Self::update`]).
    pub fn sources(&self) -> &SourceResponses {
        &self.sources
    }

    /// Every pixel's response, row-major (after [`Self::update`]).
    pub fn pixel_responses(&self) -> &[PixelResponse] {
        &self.pixels
    }

    /// The (sky generation, shadow casts) the responses were made for.
    pub fn made_for(&self) -> Option<(u64, u32)> {
        self.made_for
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
        if self.pixels.len() != w * h {
            return Err(OutdoorError::Parameter(
                "the relighter was not updated for these maps".into(),
            ));
        }
        if out.width() != w || out.height() != h {
            *out = Image::filled(w, h, Rgb::ZERO);
        }
        out.rows_mut()
            .collect::<Vec<_>>()
            .into_par_iter()
            .zip(self.pixels.par_chunks(w))
            .for_each(|(row, responses)| {
                for (px, r) in row.iter_mut().zip(responses) {
                    *px = r.sky * sky + r.sun_response(sun_direction) * sun;
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
