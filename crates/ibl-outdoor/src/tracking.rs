//! What changes with the sun, and when to recompute it: the sky shape (re-made when the sun has
//! moved more than a threshold, default 1 degree) and, per set of surface points, the shadow map
//! (default 0.25 degrees, [`crate::shadow`]) and the sky terms `c_shape` that depend on the shape.
//!
//! The per-pixel model (Jensen, Andersen & Madsen 2006, section 4.2) needs for every point its
//! sky term `c_shape` ([`crate::transfer`]) and its sun term `k = s max(0, n . l)`. The cosine
//! uses the current sun direction every frame (a dot product); only the shadow ray and the
//! shape's SH expansion are cached. A [`SkyTracker`] counts its shapes (`generation`), so every
//! cache knows when its sky terms are stale.

use glam::Vec3;
use ibl_core::Rgb;
use ibl_scene::GeometryLayer;

use crate::OutdoorError;
use crate::shadow::ShadowState;
use crate::sky::{SkyModel, SkyShape};
use crate::transfer::{AmbientTransfer, SurfacePoint};

/// Default sky-shape threshold, radians (1 degree).
pub const DEFAULT_SKY_THRESHOLD_RAD: f32 = std::f32::consts::PI / 180.0;

/// The current sky shape.
#[derive(Clone, Debug)]
pub struct SkyTracker {
    model: SkyModel,
    bands: usize,
    threshold_rad: f32,
    shape: Option<SkyShape>,
    generation: u64,
}

impl SkyTracker {
    /// No shape yet; `bands` SH bands (those of the transfer vectors).
    pub fn new(model: SkyModel, bands: usize, threshold_rad: f32) -> SkyTracker {
        SkyTracker {
            model,
            bands,
            threshold_rad: threshold_rad.max(0.0),
            shape: None,
            generation: 0,
        }
    }

    /// Makes the shape current for `sun`; returns whether it was re-made.
    pub fn update(&mut self, sun: Vec3) -> Result<bool, OutdoorError> {
        if let Some(shape) = &self.shape
            && shape.sun().dot(sun).clamp(-1.0, 1.0).acos() <= self.threshold_rad
        {
            return Ok(false);
        }
        self.shape = Some(SkyShape::new(self.model, sun, self.bands)?);
        self.generation += 1;
        Ok(true)
    }

    /// The current shape; an error before the first [`Self::update`].
    pub fn shape(&self) -> Result<&SkyShape, OutdoorError> {
        self.shape
            .as_ref()
            .ok_or_else(|| OutdoorError::Parameter("the sky has no sun direction yet".into()))
    }

    /// How many shapes were made (0 before the first update).
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The model.
    pub fn model(&self) -> SkyModel {
        self.model
    }
}

/// The sun-dependent terms of a set of surface points.
#[derive(Clone, Debug)]
pub struct PointLighting {
    shadow: ShadowState,
    sky_terms: Vec<Rgb>,
    sky_generation: u64,
}

impl PointLighting {
    /// Empty; shadows re-cast when the sun moves more than `shadow_threshold_rad`.
    pub fn new(shadow_threshold_rad: f32) -> PointLighting {
        PointLighting {
            shadow: ShadowState::new(shadow_threshold_rad),
            sky_terms: Vec::new(),
            sky_generation: 0,
        }
    }

    /// Brings the shadows and sky terms of `points` (with their `transfer`) up to date for the
    /// sun towards `sun` and the tracker's shape (which must be current).
    pub fn update(
        &mut self,
        layer: &GeometryLayer,
        points: &[SurfacePoint],
        transfer: &AmbientTransfer,
        sky: &SkyTracker,
        sun: Vec3,
    ) -> Result<(), OutdoorError> {
        self.shadow.update(layer, points, sun);
        if self.sky_generation != sky.generation() || self.sky_terms.len() != points.len() {
            self.sky_terms = transfer.sky_ambient_all(sky.shape()?);
            self.sky_generation = sky.generation();
        }
        Ok(())
    }

    /// `c_shape` per point.
    pub fn sky_terms(&self) -> &[Rgb] {
        &self.sky_terms
    }

    /// `s` per point.
    pub fn shadow(&self) -> &ShadowState {
        &self.shadow
    }

    /// `k = s max(0, n . l)` of point `i` with normal `normal` for the sun towards `sun`.
    pub fn sun_term(&self, i: usize, normal: Vec3, sun: Vec3) -> f32 {
        self.shadow.visibility()[i] * normal.dot(sun).max(0.0)
    }
}
