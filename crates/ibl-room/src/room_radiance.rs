//! The room's radiance as Grosch 2005 displays it (sections 3.2 and 4.4): a point of a surface
//! the probe saw has the probe's radiance in its direction (the photograph projected onto the
//! model); a point the probe did not see, by the omnidirectional depth map, has the radiance
//! estimate `L = B / pi` of its patch, which for a hidden patch is `rho E / pi` (section 3.2,
//! step 4). Patches are Lambertian, so the radiance leaving a point is the same in every
//! direction; this is what a ray from anywhere in the room (a key point of the irradiance
//! volume, a moved camera) sees.
//!
//! **The depth test.** The probe saw world point `x` when the depth-map pixel in `x`'s direction
//! is not nearer than `|x - probe|` by more than `d tan(80 deg) pi / (2 H)` (`d` the distance,
//! `H` the probe's rows): the pixel's centre is up to half a pixel (`pi / (2 H)` rad at the
//! equator) off `x`'s direction, and on a surface seen at up to 80 degrees from its normal the
//! depth changes by `d tan(theta)` per radian there; one more millimetre absorbs f32 rounding.
//! The texture is the probe pixel in `x`'s direction (nearest pixel, as the depth test). World
//! frame and metres as `docs/CONVENTIONS.md`; radiance in the probe's units.
//!
//! **New lights** ([`RoomRadiance::with_added_light`], section 4.2): their radiance at `x`
//! ([`LightAddition::radiance_at`], direct light per point with its shadow ray, indirect per
//! patch) is added on both sides of the depth test, so a moved camera sees their pools and
//! shadows at its own resolution rather than the probe's.

use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};

use crate::added_light::LightAddition;
use crate::depth_map::ProbeDepthMap;
use crate::reflectance::Estimate;
use crate::{Room, RoomError};

/// `tan(80 deg)`: the steepest view of a surface the depth test allows for (module doc).
const STEEPEST_VIEW_TAN: f32 = 5.671_282;
/// Depth-test slack for f32 rounding, metres.
const DEPTH_SLACK_M: f32 = 1e-3;

/// What a ray met, with the radiance coming back along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadianceHit {
    /// The patch whose front the ray met.
    pub patch: u32,
    /// Distance along the (unit) ray, metres.
    pub distance_m: f32,
    /// Radiance leaving the point towards the ray's origin, probe units.
    pub radiance: Rgb,
    /// Whether the radiance is the probe's (the probe saw the point) rather than the estimate's.
    pub seen: bool,
}

/// The room's radiance field: the probe where it saw, the estimate where it did not.
#[derive(Clone, Debug)]
pub struct RoomRadiance<'a> {
    room: &'a Room,
    depth: &'a ProbeDepthMap,
    probe: &'a Image<Rgb>,
    /// Per patch, the estimate's radiance `B / pi`.
    estimate: Vec<Rgb>,
    /// New lights whose radiance is added everywhere.
    added: Option<&'a LightAddition>,
}

impl<'a> RoomRadiance<'a> {
    /// The field of `room` seen in `probe` (lat-long radiance) through `depth` (the probe's depth
    /// map, same size), filled by `estimate` (one entry per patch).
    pub fn new(
        room: &'a Room,
        depth: &'a ProbeDepthMap,
        probe: &'a Image<Rgb>,
        estimate: &Estimate,
    ) -> Result<RoomRadiance<'a>, RoomError> {
        if probe.width() != depth.width() || probe.height() != depth.height() {
            return Err(RoomError::Parameter(format!(
                "the probe is {} x {} but the depth map {} x {}",
                probe.width(),
                probe.height(),
                depth.width(),
                depth.height()
            )));
        }
        if estimate.patches.len() != room.patches.len() {
            return Err(RoomError::Parameter(format!(
                "an estimate of {} patches for a room of {}",
                estimate.patches.len(),
                room.patches.len()
            )));
        }
        Ok(RoomRadiance {
            room,
            depth,
            probe,
            estimate: estimate
                .patches
                .iter()
                .map(|p| p.radiosity / std::f32::consts::PI)
                .collect(),
            added: None,
        })
    }

    /// The same field with the radiance of the new lights `added` (made for this room) added at
    /// every point.
    pub fn with_added_light(mut self, added: &'a LightAddition) -> RoomRadiance<'a> {
        self.added = Some(added);
        self
    }

    /// The room.
    pub fn room(&self) -> &Room {
        self.room
    }

    /// The radiance leaving world point `point` of patch `patch`, and whether it is the probe's.
    pub fn at(&self, point: Vec3, patch: usize) -> (Rgb, bool) {
        let (radiance, seen) = self.before_lights(point, patch);
        match self.added {
            Some(added) => (radiance + added.radiance_at(self.room, patch, point), seen),
            None => (radiance, seen),
        }
    }

    /// [`Self::at`] without the new lights.
    fn before_lights(&self, point: Vec3, patch: usize) -> (Rgb, bool) {
        let distance = (point - self.room.probe_position).length();
        let tolerance = distance * STEEPEST_VIEW_TAN * std::f32::consts::PI
            / (2.0 * self.depth.height() as f32)
            + DEPTH_SLACK_M;
        if self.depth.sees(self.room, point, tolerance) {
            let probe_dir =
                self.room.world_from_probe.transpose() * (point - self.room.probe_position);
            let (i, j) = LatLong::new(self.probe.width(), self.probe.height())
                .dir_to_pixel(probe_dir.as_dvec3());
            (*self.probe.get(i, j), true)
        } else {
            (self.estimate[patch], false)
        }
    }

    /// What the unit ray `origin + t direction` (`t > t_min`) meets first and the radiance it
    /// brings back; `None` when it meets a back side (inside a box, a gap in the model) or
    /// nothing (an open model).
    pub fn along(&self, origin: Vec3, direction: Vec3, t_min: f32) -> Option<RadianceHit> {
        let hit = self.room.hit(origin, direction, t_min, f32::INFINITY)?;
        if !hit.front {
            return None;
        }
        let (radiance, seen) = self.at(origin + direction * hit.distance_m, hit.patch as usize);
        Some(RadianceHit {
            patch: hit.patch,
            distance_m: hit.distance_m,
            radiance,
            seen,
        })
    }
}
