//! The whole per-frame loop of Jensen, Andersen & Madsen 2006 (figures 5 and 6) behind one type:
//! offline maps and sample sites once, then for every frame the sun from place and time, the
//! estimate, the relit map and the refreshed irradiance volume. Front ends (the CLI's `ibl
//! outdoor`, the viewer's sequence mode, the pipeline) are meant to be thin layers on
//! [`OutdoorSystem::new`] and [`OutdoorSystem::process`].
//!
//! Order per frame: sun direction (SPA) -> sky shape and shadows if the sun moved past their
//! thresholds, and then the probe's responses (with interreflections) -> observations at the
//! sample sites (their bounce terms gathered from those responses) -> robust estimate (again
//! with the overcast sky when the sun turns out too weak, or with the clear one when it is back)
//! -> optional temporal smoothing -> relit map (the smoothed estimate) -> volume refresh, (a)
//! from the relit map or (b) from the key-point responses.

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_scene::{Camera, GeometryLayer};
use ibl_sh::{IrradianceVolume, VolumeGrid};
use serde::Serialize;

use crate::OutdoorError;
use crate::composite::FrameLighting;
use crate::estimate::{Estimate, EstimatorOptions, estimate};
use crate::maps::{CaptureSource, MapSettings, ProbeMaps};
use crate::relight::{Relighter, SunLight};
use crate::samples::{SampleSettings, SampleSites};
use crate::shadow::DEFAULT_SHADOW_THRESHOLD_RAD;
use crate::smoothing::{SmoothingOptions, TemporalFilter};
use crate::sun::{DeltaT, Location, Timestamp};
use crate::tracking::{DEFAULT_SKY_THRESHOLD_RAD, SkyCondition, SkyTracker};
use crate::volume_refresh::{KeyPointRelighter, MapGather};

/// How the volume is refreshed each frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeRefresh {
    /// (a) Gather the relit map through the precomputed pixel weights.
    FromMap,
    /// (b) Combine the key points' precomputed responses to `P_a` and `P_d`.
    KeyPoints,
}

/// The irradiance volume to keep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeSettings {
    /// Key points.
    pub grid: VolumeGrid,
    /// Width of each key point's direction map (height half).
    pub directions_width: usize,
    /// How to refresh it.
    pub refresh: VolumeRefresh,
}

/// Everything [`OutdoorSystem`] can be told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SystemSettings {
    /// Offline maps.
    pub maps: MapSettings,
    /// Sample sites.
    pub samples: SampleSettings,
    /// The robust fit.
    pub estimator: EstimatorOptions,
    /// Temporal smoothing (`None`: each frame on its own, as the paper).
    pub smoothing: Option<SmoothingOptions>,
    /// Re-cast shadows when the sun moves more than this, radians.
    pub shadow_threshold_rad: f32,
    /// Re-make the sky shape when the sun moves more than this, radians.
    pub sky_threshold_rad: f32,
    /// The volume, if any.
    pub volume: Option<VolumeSettings>,
    /// `TT - UT` for the sun.
    pub delta_t: DeltaT,
    /// A frame whose estimated sun luminance `Y(P_d)` is below this fraction of the sky's `Y(P_a)`
    /// (or whose sun is not observable) is overcast: it is estimated again, relit and its volume
    /// refreshed with the CIE overcast sky instead of the clear one (`None`: always clear, as
    /// the paper). Clear days give `P_d / P_a` of 5 to 20, a cloud in front of the sun 2 to 5.
    pub overcast_below: Option<f32>,
}

impl Default for SystemSettings {
    fn default() -> Self {
        SystemSettings {
            maps: MapSettings::default(),
            samples: SampleSettings::default(),
            estimator: EstimatorOptions::default(),
            smoothing: None,
            shadow_threshold_rad: DEFAULT_SHADOW_THRESHOLD_RAD,
            sky_threshold_rad: DEFAULT_SKY_THRESHOLD_RAD,
            volume: None,
            delta_t: DeltaT::Estimated,
            overcast_below: Some(1.0),
        }
    }
}

/// The probe and where it was taken.
#[derive(Clone, Debug)]
pub struct ProbeCapture {
    /// Lat-long radiance in the probe's frame.
    pub radiance: Image<Rgb>,
    /// Probe centre, world frame.
    pub position: Vec3,
    /// Rotation from the probe frame to the world.
    pub world_from_probe: Mat3,
    /// When it was taken.
    pub time: Timestamp,
    /// Where its capture lighting comes from.
    pub lighting: CaptureSource,
}

/// The video camera and its marked surfaces.
#[derive(Clone, Debug)]
pub struct CameraSetup {
    /// The calibrated camera.
    pub camera: Camera,
    /// Frame size in pixels.
    pub frame_size: (usize, usize),
    /// Marked diffuse surfaces (frame size).
    pub mask: Image<bool>,
}

/// What one frame gave.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FrameResult {
    /// Seconds since the first frame processed.
    pub time_s: f64,
    /// Unit world direction towards the sun.
    pub sun_direction: [f32; 3],
    /// The frame's own estimate.
    pub raw: Estimate,
    /// The estimate used (smoothed when smoothing is on, else `raw`).
    pub estimate: Estimate,
    /// The sun as a directional light (from `estimate`).
    pub sun: SunLight,
    /// The sky the frame was estimated and relit with.
    pub sky_condition: SkyCondition,
}

/// The offline state and the per-frame loop.
pub struct OutdoorSystem {
    location: Location,
    settings: SystemSettings,
    layer: GeometryLayer,
    maps: ProbeMaps,
    sites: SampleSites,
    sky: SkyTracker,
    relighter: Relighter,
    gather: Option<MapGather>,
    key_points: KeyPointRelighter,
    volume: Option<IrradianceVolume>,
    filter: Option<TemporalFilter>,
    first_time: Option<Timestamp>,
    relit: Image<Rgb>,
}

impl OutdoorSystem {
    /// The offline step: maps from the probe, sample sites in the camera, the volume weights.
    pub fn new(
        layer: GeometryLayer,
        location: Location,
        probe: &ProbeCapture,
        camera: &CameraSetup,
        settings: SystemSettings,
    ) -> Result<OutdoorSystem, OutdoorError> {
        location.validate()?;
        let capture_sun = location.sun_direction(probe.time, settings.delta_t)?;
        let maps = ProbeMaps::build(
            &layer,
            &probe.radiance,
            probe.position,
            probe.world_from_probe,
            capture_sun,
            probe.lighting,
            settings.maps,
        )?;
        let sites = SampleSites::draw(
            &layer,
            &camera.camera,
            camera.frame_size,
            &camera.mask,
            &maps,
            &settings.samples,
            settings.shadow_threshold_rad,
        )?;
        let gather = match settings.volume {
            Some(v) => Some(MapGather::new(&layer, &maps, v.grid, v.directions_width)?),
            None => None,
        };
        let volume = gather.as_ref().map(MapGather::empty_volume);
        Ok(OutdoorSystem {
            location,
            sky: SkyTracker::new(
                settings.maps.sky_model,
                settings.maps.transfer_bands,
                settings.sky_threshold_rad,
            ),
            relighter: Relighter::new(&maps, settings.shadow_threshold_rad),
            filter: settings.smoothing.map(TemporalFilter::new),
            settings,
            layer,
            maps,
            sites,
            gather,
            key_points: KeyPointRelighter::new(),
            volume,
            first_time: None,
            relit: Image::filled(0, 0, Rgb::ZERO),
        })
    }

    /// Processes the frame taken at `time`.
    pub fn process(
        &mut self,
        time: Timestamp,
        frame: &Image<Rgb>,
    ) -> Result<FrameResult, OutdoorError> {
        let sun = self.location.sun_direction(time, self.settings.delta_t)?;
        if sun.y <= 0.0 {
            return Err(OutdoorError::Parameter(format!(
                "the sun is below the horizon at this time (elevation {:.2} degrees): the model is for daylight",
                sun.y.asin().to_degrees()
            )));
        }
        let first = *self.first_time.get_or_insert(time);
        let time_s = time.seconds_since(first);
        self.sky.update(sun)?;
        self.relighter
            .update(&self.layer, &self.maps, &self.sky, sun)?;
        let mut raw = self.estimate_frame(frame, sun)?;
        if let Some(ratio) = self.settings.overcast_below {
            let overcast = !raw.sun_observable
                || raw.sun_rgb().luminance() < ratio * raw.sky_rgb().luminance();
            let condition = if overcast {
                SkyCondition::Overcast
            } else {
                SkyCondition::Clear
            };
            if self.sky.set_condition(condition, sun)? {
                self.relighter
                    .update(&self.layer, &self.maps, &self.sky, sun)?;
                raw = self.estimate_frame(frame, sun)?;
            }
        }
        let estimate = match &mut self.filter {
            Some(f) => f.update(time_s, &raw),
            None => raw,
        };
        let (pa, pd) = (estimate.sky_rgb(), estimate.sun_rgb());
        self.relighter
            .relight_into(&self.maps, sun, pa, pd, &mut self.relit)?;
        if let (Some(v), Some(gather), Some(volume)) = (
            self.settings.volume,
            self.gather.as_mut(),
            self.volume.as_mut(),
        ) {
            match v.refresh {
                VolumeRefresh::FromMap => gather.refresh(&self.relit, &self.sky, pa, volume)?,
                VolumeRefresh::KeyPoints => {
                    self.key_points
                        .update(gather, &self.maps, &self.relighter, &self.sky, sun)?;
                    self.key_points.refresh(pa, pd, volume)?;
                }
            }
        }
        Ok(FrameResult {
            time_s,
            sun_direction: sun.to_array(),
            raw,
            estimate,
            sun: SunLight::new(sun, pd),
            sky_condition: self.sky.condition(),
        })
    }

    fn estimate_frame(&mut self, frame: &Image<Rgb>, sun: Vec3) -> Result<Estimate, OutdoorError> {
        self.sites.update(&self.layer, &self.sky, sun)?;
        let observations = self.sites.observations(frame, sun, &self.relighter)?;
        estimate(&observations, &self.settings.estimator)
    }

    /// The relit map of the last frame (probe frame, lat-long).
    pub fn relit_map(&self) -> &Image<Rgb> {
        &self.relit
    }

    /// The lighting `result` (this system's last frame) gives a composite: its sun, the sky shape
    /// and `P_a` it was estimated with, and the relit map.
    pub fn frame_lighting(&self, result: &FrameResult) -> Result<FrameLighting<'_>, OutdoorError> {
        Ok(FrameLighting {
            sun: result.sun,
            sky_shape: self.sky.shape()?,
            sky: result.estimate.sky_rgb(),
            relit_map: &self.relit,
        })
    }

    /// The volume after the last frame.
    pub fn volume(&self) -> Option<&IrradianceVolume> {
        self.volume.as_ref()
    }

    /// The offline maps.
    pub fn maps(&self) -> &ProbeMaps {
        &self.maps
    }

    /// The sample sites.
    pub fn sites(&self) -> &SampleSites {
        &self.sites
    }

    /// The scene model.
    pub fn layer(&self) -> &GeometryLayer {
        &self.layer
    }

    /// The current sky shape tracker.
    pub fn sky(&self) -> &SkyTracker {
        &self.sky
    }

    /// The relighter (the probe's current responses).
    pub fn relighter(&self) -> &Relighter {
        &self.relighter
    }
}
