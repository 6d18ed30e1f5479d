//! The sample sites of the per-frame estimation: about 500 random pixels of a calibrated camera
//! on the marked diffuse surfaces (Jensen, Andersen & Madsen 2006, section 3.1: "500 randomly
//! selected pixel samples"), each with the model's inputs at its surface point.
//!
//! A camera pixel is a **candidate** when it is marked in the mask, its centre ray meets the
//! model, the probe saw that point ([`crate::view::ProbeProjection::pixel_of`]) and the probe's
//! albedo there is known, and the site is **stable**: the camera pixel's eight neighbours see
//! surfaces of the same normal (no geometric edge), and the probe pixel's 3 x 3 neighbourhood is
//! all surface with one capture shadow and albedos within `albedo_tolerance` (relative, default
//! 30 %: the probe's own noise stays inside it, most texture and shadow edges the two views would
//! sample differently do not), none of them mixed ([`crate::footprint`]). The site's albedo is
//! the mean of those nine, in `[min_albedo, 1]` (a third of the probe's per-pixel noise). Sites
//! are drawn uniformly without replacement among candidates (seeded), once: the same pixels are
//! read every frame, so frame-to-frame changes are changes of light. Each site gets its own sky
//! transfer vector with many rays (default 1024: a standard error of `c` of at most 1.6 %), its
//! own footprint of sub-pixel shadow rays over the sun's disc, cast whenever the sun moves past
//! the threshold, and, when the maps keep interreflections, its own bounce gather onto the
//! probe's surface points ([`crate::interreflection`]; `interreflection_rays` rays). Its
//! observation per frame is the frame's pixel, with the bounce terms gathered from the
//! relighter's current responses.

use glam::Vec3;
use ibl_core::{Image, Rgb};
use ibl_scene::{Camera, GeometryLayer};
use rand::SeedableRng;
use rand::seq::index::sample;
use rand_pcg::Pcg64Mcg;

use crate::OutdoorError;
use crate::estimate::Observation;
use crate::interreflection::{BounceGather, Interreflection};
use crate::maps::ProbeMaps;
use crate::relight::Relighter;
use crate::tracking::{PointLighting, SkyTracker};
use crate::transfer::{AmbientTransfer, SurfacePoint};
use crate::view::{ViewGeometry, pixel_footprint};

/// How sample sites are chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleSettings {
    /// Sites to draw (fewer when there are fewer candidates).
    pub count: usize,
    /// Cosine rays per site for its transfer vector.
    pub transfer_rays: u32,
    /// Smallest albedo in any channel.
    pub min_albedo: f32,
    /// Largest relative difference of the probe's 3 x 3 albedos from their mean.
    pub albedo_tolerance: f32,
    /// Cosine rays per site for its bounce gather (used when the maps keep interreflections).
    pub interreflection_rays: u32,
    /// Seed of the draw and of the rays.
    pub seed: u64,
}

impl Default for SampleSettings {
    fn default() -> Self {
        SampleSettings {
            count: 500,
            transfer_rays: 1024,
            min_albedo: 0.02,
            albedo_tolerance: 0.3,
            interreflection_rays: 256,
            seed: 7,
        }
    }
}

/// The chosen pixels and their model inputs.
#[derive(Clone, Debug)]
pub struct SampleSites {
    frame_size: (usize, usize),
    pixels: Vec<(usize, usize)>,
    points: Vec<SurfacePoint>,
    albedo: Vec<Rgb>,
    transfer: AmbientTransfer,
    lighting: PointLighting,
    bounce: Option<BounceGather>,
    candidates: usize,
}

impl SampleSites {
    /// Draws the sites of `camera`'s `frame_size` images among the pixels marked in `mask`
    /// (same size), with albedo from `maps`.
    pub fn draw(
        layer: &GeometryLayer,
        camera: &Camera,
        frame_size: (usize, usize),
        mask: &Image<bool>,
        maps: &ProbeMaps,
        settings: &SampleSettings,
        shadow_threshold_rad: f32,
    ) -> Result<SampleSites, OutdoorError> {
        let (w, h) = frame_size;
        if mask.width() != w || mask.height() != h || w < 3 || h < 3 {
            return Err(OutdoorError::Parameter(format!(
                "the mask is {} x {} but the frames are {w} x {h} (at least 3 x 3)",
                mask.width(),
                mask.height()
            )));
        }
        let view = ViewGeometry::new(layer, camera, w, h);
        let projection = maps.projection();
        let (pw, ph) = maps.size();
        let albedo = maps.albedo();
        let shadow0 = maps.capture_sun_terms();
        let footprints = maps.footprints();
        let probe_albedo = |i: usize, j: usize| -> Option<(Rgb, f32)> {
            let k = maps.point_of_pixel(j * pw + i)?;
            if footprints.is_mixed(k) {
                return None;
            }
            albedo[k].map(|a| (a, shadow0[k]))
        };
        let mut candidates: Vec<(usize, usize, SurfacePoint, Rgb)> = Vec::new();
        for j in 1..h - 1 {
            for i in 1..w - 1 {
                if !*mask.get(i, j) {
                    continue;
                }
                let Some(hit) = view.hit(i, j) else { continue };
                let flat = (j - 1..=j + 1).all(|b| {
                    (i - 1..=i + 1).all(|a| {
                        view.hit(a, b)
                            .is_some_and(|o| o.normal.dot(hit.normal) > 0.999)
                    })
                });
                if !flat {
                    continue;
                }
                let Some((pi, pj)) = projection.pixel_of(hit.position) else {
                    continue;
                };
                if pj == 0 || pj + 1 >= ph {
                    continue;
                }
                let Some((_, s0)) = probe_albedo(pi, pj) else {
                    continue;
                };
                // The probe's 3 x 3 neighbourhood: all surface, one capture shadow, albedos
                // within the tolerance of their mean (which is the site's albedo: a third of
                // the probe's per-pixel noise).
                let mut block = Vec::with_capacity(9);
                for b in pj - 1..=pj + 1 {
                    for a in [(pi + pw - 1) % pw, pi, (pi + 1) % pw] {
                        match probe_albedo(a, b) {
                            Some((o, os)) if os == s0 => block.push(o),
                            _ => break,
                        }
                    }
                }
                if block.len() != 9 {
                    continue;
                }
                let d = block.iter().fold(Rgb::ZERO, |acc, &o| acc + o) / 9.0;
                if d.to_array()
                    .iter()
                    .any(|&v| !(v >= settings.min_albedo && v <= 1.0))
                {
                    continue;
                }
                let stable = block.iter().all(|o| {
                    (0..3).all(|c| (o[c] - d[c]).abs() <= settings.albedo_tolerance * d[c])
                });
                if stable {
                    candidates.push((
                        i,
                        j,
                        SurfacePoint {
                            position: hit.position,
                            normal: hit.normal,
                        },
                        d,
                    ));
                }
            }
        }
        if candidates.len() < 3 {
            return Err(OutdoorError::Parameter(format!(
                "only {} stable marked pixels see surfaces the probe saw: mark more diffuse surfaces",
                candidates.len()
            )));
        }
        let mut rng = Pcg64Mcg::seed_from_u64(settings.seed);
        let count = settings.count.min(candidates.len());
        let mut chosen: Vec<usize> = sample(&mut rng, candidates.len(), count).into_vec();
        chosen.sort_unstable();
        let picked: Vec<_> = chosen.iter().map(|&k| candidates[k]).collect();
        let points: Vec<SurfacePoint> = picked.iter().map(|c| c.2).collect();
        let side = maps.footprints().side();
        let footprints: Vec<Option<SurfacePoint>> = picked
            .iter()
            .flat_map(|c| {
                pixel_footprint(layer, camera, (w, h), (c.0, c.1), side)
                    .into_iter()
                    .map(|ray| {
                        ray.hit.map(|hit| SurfacePoint {
                            position: hit.position,
                            normal: hit.normal,
                        })
                    })
            })
            .collect();
        let transfer = AmbientTransfer::compute(
            layer,
            &points,
            maps.transfer().bands(),
            settings.transfer_rays,
            settings.seed ^ 0x5A5A,
        )?;
        let bounce = match maps.settings().interreflection {
            Interreflection::Off => None,
            Interreflection::Bounces { .. } => Some(BounceGather::build(
                layer,
                &points,
                settings.interreflection_rays,
                settings.seed ^ 0xB0B0,
                |y| maps.bounce_source(y),
            )?),
        };
        Ok(SampleSites {
            frame_size,
            pixels: picked.iter().map(|c| (c.0, c.1)).collect(),
            albedo: picked.iter().map(|c| c.3).collect(),
            points,
            transfer,
            lighting: PointLighting::new(shadow_threshold_rad, footprints.into(), side * side),
            bounce,
            candidates: candidates.len(),
        })
    }

    /// The sites' camera pixels `(column, row)`.
    pub fn pixels(&self) -> &[(usize, usize)] {
        &self.pixels
    }

    /// The sites' surface points.
    pub fn points(&self) -> &[SurfacePoint] {
        &self.points
    }

    /// How many pixels qualified (the sites were drawn from them).
    pub fn candidates(&self) -> usize {
        self.candidates
    }

    /// The sites' sky and shadow terms.
    pub fn lighting(&self) -> &PointLighting {
        &self.lighting
    }

    /// Brings shadows and sky terms up to date for the sun towards `sun`.
    pub fn update(
        &mut self,
        layer: &GeometryLayer,
        sky: &SkyTracker,
        sun: Vec3,
    ) -> Result<(), OutdoorError> {
        self.lighting
            .update(layer, &self.points, &self.transfer, sky, sun)
    }

    /// The sites' bounce gather (`None` when the maps keep no interreflections).
    pub fn bounce(&self) -> Option<&BounceGather> {
        self.bounce.as_ref()
    }

    /// The observations of `frame` (after [`Self::update`] for the same sun), with the bounce
    /// terms from `relighter`'s responses (updated for the same sun and sky).
    pub fn observations(
        &self,
        frame: &Image<Rgb>,
        sun: Vec3,
        relighter: &Relighter,
    ) -> Result<Vec<Observation>, OutdoorError> {
        if (frame.width(), frame.height()) != self.frame_size {
            return Err(OutdoorError::Parameter(format!(
                "the frame is {} x {}; the sites were drawn for {} x {}",
                frame.width(),
                frame.height(),
                self.frame_size.0,
                self.frame_size.1
            )));
        }
        if self.lighting.sky_terms().len() != self.points.len() {
            return Err(OutdoorError::Parameter(
                "the sample sites were not updated for a sun direction".into(),
            ));
        }
        let sources = relighter.sources();
        if let Some(g) = &self.bounce
            && (sources.sky_previous.is_empty() || sources.sun_previous.is_empty())
        {
            return Err(OutdoorError::Parameter(format!(
                "the relighter has no responses for the {} sites' bounce gather",
                g.len()
            )));
        }
        Ok(self
            .pixels
            .iter()
            .enumerate()
            .map(|(k, &(i, j))| {
                let (indirect_sky, indirect_sun) = match &self.bounce {
                    Some(g) => (
                        g.gather(k, &sources.sky_previous),
                        g.gather(k, &sources.sun_previous),
                    ),
                    None => (Rgb::ZERO, Rgb::ZERO),
                };
                Observation {
                    observed: *frame.get(i, j),
                    albedo: self.albedo[k],
                    sky_term: self.lighting.sky_terms()[k],
                    sun_term: self.lighting.sun_term(k, sun),
                    indirect_sky,
                    indirect_sun,
                }
            })
            .collect())
    }
}
