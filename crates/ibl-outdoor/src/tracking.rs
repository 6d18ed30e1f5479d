//! What changes with the sun, and when to recompute it: the sky shape (re-made when the sun has
//! moved more than a threshold, default 1 degree, or when the sky turns overcast or clears) and, per set of surface points, the shadow map
//! (default 0.25 degrees, [`crate::shadow`]) and the sky terms `c_shape` that depend on the shape.
//!
//! The per-pixel model (Jensen, Andersen & Madsen 2006, section 4.2) needs for every point its
//! sky term `c_shape` ([`crate::transfer`]) and its sun term `k = s max(0, n . l)`. The cosine
//! uses the current sun direction every frame (a dot product); only the shadow ray and the
//! shape's SH expansion are cached. A [`SkyTracker`] counts its shapes (`generation`), so every
//! cache knows when its sky terms are stale.

use std::sync::Arc;

use glam::Vec3;
use ibl_core::Rgb;
use ibl_scene::GeometryLayer;

use crate::OutdoorError;
use crate::shadow::ShadowState;
use crate::sky::{SkyModel, SkyShape};
use crate::transfer::{AmbientTransfer, SurfacePoint};

/// Default sky-shape threshold, radians (1 degree).
pub const DEFAULT_SKY_THRESHOLD_RAD: f32 = std::f32::consts::PI / 180.0;

/// Whether the sky is clear or overcast (which shape a frame uses).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum SkyCondition {
    /// The clear-sky model of the settings (Preetham, or uniform).
    Clear,
    /// The CIE overcast sky (no sun).
    Overcast,
}

/// The current sky shape.
#[derive(Clone, Debug)]
pub struct SkyTracker {
    model: SkyModel,
    condition: SkyCondition,
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
            condition: SkyCondition::Clear,
            bands,
            threshold_rad: threshold_rad.max(0.0),
            shape: None,
            generation: 0,
        }
    }

    /// Makes the shape current for `sun` under the current condition; returns whether it was
    /// re-made.
    pub fn update(&mut self, sun: Vec3) -> Result<bool, OutdoorError> {
        if let Some(shape) = &self.shape
            && shape.sun().dot(sun).clamp(-1.0, 1.0).acos() <= self.threshold_rad
        {
            return Ok(false);
        }
        let model = match self.condition {
            SkyCondition::Clear => self.model,
            SkyCondition::Overcast => SkyModel::CieOvercast,
        };
        self.shape = Some(SkyShape::new(model, sun, self.bands)?);
        self.generation += 1;
        Ok(true)
    }

    /// Switches between the clear and the overcast shape (re-made at once for `sun` when the
    /// condition changes); returns whether it changed.
    pub fn set_condition(
        &mut self,
        condition: SkyCondition,
        sun: Vec3,
    ) -> Result<bool, OutdoorError> {
        if condition == self.condition && self.shape.is_some() {
            return Ok(false);
        }
        self.condition = condition;
        self.shape = None;
        self.update(sun)?;
        Ok(true)
    }

    /// The current condition.
    pub fn condition(&self) -> SkyCondition {
        self.condition
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

/// The sun-dependent terms of a set of surface points, each seen through a pixel whose
/// footprint is `per_point` sub-pixel rays ([`crate::view::pixel_footprint`]): the sun term is
/// their mean, `k = (1 / S) sum_j s_j max(0, n_j . l)` (a sub-ray that sees the sky adds 0), so a
/// pixel across a shadow edge, a penumbra ([`crate::shadow`]) or a geometric edge gets the
/// fraction of sunlight its footprint receives (the sky term uses the centre's transfer vector).
#[derive(Clone, Debug)]
pub struct PointLighting {
    footprints: Arc<[Option<SurfacePoint>]>,
    per_point: usize,
    shadow: ShadowState,
    sky_terms: Vec<Rgb>,
    sky_generation: u64,
}

impl PointLighting {
    /// Empty; `footprints` holds `per_point` sub-points per point, in point order (`None`: a
    /// sub-ray that sees the sky); shadows are re-cast when the sun moves more than
    /// `shadow_threshold_rad`.
    pub fn new(
        shadow_threshold_rad: f32,
        footprints: Arc<[Option<SurfacePoint>]>,
        per_point: usize,
    ) -> PointLighting {
        PointLighting {
            footprints,
            per_point: per_point.max(1),
            shadow: ShadowState::new(shadow_threshold_rad, per_point.max(1)),
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
        if self.footprints.len() != points.len() * self.per_point {
            return Err(OutdoorError::Parameter(format!(
                "{} footprint points for {} points of {} each",
                self.footprints.len(),
                points.len(),
                self.per_point
            )));
        }
        self.shadow.update(layer, &self.footprints, sun);
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

    /// `s` per sub-point, and the sun it was cast for.
    pub fn shadow(&self) -> &ShadowState {
        &self.shadow
    }

    /// Sub-rays per point.
    pub fn per_point(&self) -> usize {
        self.per_point
    }

    /// The footprint of point `i` (`None`: a sub-ray that sees the sky).
    pub fn footprint(&self, i: usize) -> &[Option<SurfacePoint>] {
        &self.footprints[i * self.per_point..(i + 1) * self.per_point]
    }

    /// `s` of the sub-points of point `i` (after an update).
    pub fn visibility(&self, i: usize) -> &[f32] {
        &self.shadow.visibility()[i * self.per_point..(i + 1) * self.per_point]
    }

    /// `k` of point `i` for the sun towards `sun`: the footprint's mean of `s max(0, n . l)`.
    pub fn sun_term(&self, i: usize, sun: Vec3) -> f32 {
        let sum: f32 = self
            .footprint(i)
            .iter()
            .zip(self.visibility(i))
            .map(|(p, v)| p.map_or(0.0, |p| v * p.normal.dot(sun).max(0.0)))
            .sum();
        sum / self.per_point as f32
    }

    /// The sunlit normal sum of point `i`, `(1 / S) sum_j s_j n_j` over the sub-points that
    /// faced the sun when the shadows were cast: `k = N . l` for any sun near that one (the
    /// sun term linear in the sun direction between two casts).
    pub fn sunlit_normal(&self, i: usize) -> Vec3 {
        let Some(cast_for) = self.shadow.sun() else {
            return Vec3::ZERO;
        };
        let sum: Vec3 = self
            .footprint(i)
            .iter()
            .zip(self.visibility(i))
            .filter_map(|(p, v)| {
                p.filter(|p| *v > 0.0 && p.normal.dot(cast_for) > 0.0)
                    .map(|p| p.normal * *v)
            })
            .sum();
        sum / self.per_point as f32
    }
}
