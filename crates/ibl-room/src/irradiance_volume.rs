//! The room's irradiance volume (Greger, Shirley, Hubbard & Greenberg 1998; Grosch 2005, section
//! 4.1): a regular grid of key points over the room's bounding box, each holding two irradiances,
//! **all light** (every patch) and **unimportant light** (every patch but the important ones of
//! [`crate::important`], whose direct light a renderer recomputes with shadows). The volume is
//! `ibl-sh`'s [`KeyPointVolume`] (layers [`VolumeLayer::AllLight`] and
//! [`VolumeLayer::UnimportantLight`]).
//!
//! **Gathering.** From each key point `K` unit directions of a Fibonacci sphere (each of solid
//! angle `4 pi / K`) are cast into the room; a ray that meets a patch's front brings back the
//! room's radiance at that point ([`RoomRadiance`]: the probe's texture where the probe saw it,
//! the estimate `rho E / pi` where the depth map says it did not). A key point from which more
//! than a quarter of the rays meet a back side or nothing is inside a box or outside the room and
//! is marked **invalid**: it is never interpolated from (the outdoor volume's rule). World frame,
//! metres; irradiance in the probe's radiance units times sr.
//!
//! **Look-up** ([`RoomVolume::sample`]): trilinear between the cell's eight key points, invalid
//! ones excluded, and, with [`KeyPointVisibility::Unoccluded`], every key point that a room
//! surface hides from the position (one occlusion ray each) excluded too, so light does not leak
//! through a wall or a box face; the remaining weights are renormalised.
//!
//! **SH L2 or ambient cube.** Both are linear in the radiance: they are gathered by the same
//! rays and interpolated by the same weights ([`GatheredIrradiance`]), so the comparison is of
//! the representation alone. Measured on the synthetic room of `docs/ROOMS.md` (grid 0.5 m, 1024
//! rays per key point; 200 random positions in the open, 64 normals each, against a direct gather
//! of 4096 rays there; `volume_error`, `tests/irradiance_volume.rs`' slow tier), the mean error
//! per position (`ibl-metrics`' `mean_err%`), all light / unimportant light:
//!
//! | | interpolated | at the point itself | floats per layer and key point | 1000 look-ups (with / without the visibility rays) |
//! |---|---|---|---|---|
//! | SH L2 | 5.4 % / 4.7 % | 2.6 % / 1.2 % | 27 | 1.23 ms / 0.126 ms |
//! | ambient cube | 15.2 % / 9.9 % | 13.5 % / 8.2 % | 18 | 1.20 ms / 0.100 ms |
//!
//! The cube's `n_a^2` lobes are too narrow for a room's broad light (one distant light at 45
//! degrees to an axis is read 29 % low), and its error at the point alone is larger than SH L2's
//! after interpolation. Its savings are a third of the memory and 3 % of a look-up with the
//! visibility test, whose eight occlusion rays take 90 % of it (20 % without;
//! `benches/irradiance_volume.rs`, 2 idle cores), and building either costs the same rays (0.20 s
//! and 0.17 s for 693 key points). So the volume stores **SH L2**: three times as accurate, and
//! the type `ibl-outdoor` shares.

use glam::{Mat3, Vec3};
use ibl_core::Rgb;
use ibl_sh::{
    IrradianceL2, KeyPointIrradiance, KeyPointVolume, LeakControl, VolumeGrid, VolumeLayer,
    VolumeLayers, eval_basis, lambert_factor,
};
use rayon::prelude::*;

use crate::RoomError;
use crate::important::ImportantLights;
use crate::room_radiance::RoomRadiance;

/// A key-point irradiance that can be gathered from rays: what the volume stores.
pub trait GatheredIrradiance: KeyPointIrradiance {
    /// Adds the light of radiance `radiance` arriving from unit direction `w` (world frame,
    /// towards the light) over a solid angle `d_omega` (sr).
    fn add_light(&mut self, w: Vec3, radiance: Rgb, d_omega: f32);
}

impl GatheredIrradiance for IrradianceL2 {
    /// Irradiance coefficients `E_lm += A_l Y_lm(w) L dOmega` (Ramamoorthi & Hanrahan 2001: the
    /// Lambert convolution of the radiance's projection).
    fn add_light(&mut self, w: Vec3, radiance: Rgb, d_omega: f32) {
        let mut y = [0.0f64; 9];
        eval_basis(w.as_dvec3(), 3, &mut y);
        for (k, c) in self.coefficients.iter_mut().enumerate() {
            let band = match k {
                0 => 0,
                1..=3 => 1,
                _ => 2,
            };
            let weight = (y[k] * lambert_factor(band)) as f32 * d_omega;
            for ch in 0..3 {
                c[ch] += weight * radiance[ch];
            }
        }
    }
}

/// How the volume is laid out and gathered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeSettings {
    /// Largest distance between neighbouring key points, metres.
    pub spacing_m: f32,
    /// The grid covers the room's bounding box shrunk by this on every side, metres: key points
    /// stay off the shell's own planes (a ray from a point on a surface is ill-defined) but close
    /// enough that a position beside a wall interpolates rather than clamps.
    pub inset_m: f32,
    /// Rays per key point (Fibonacci directions).
    pub rays: u32,
}

impl Default for VolumeSettings {
    fn default() -> Self {
        VolumeSettings {
            spacing_m: 0.5,
            inset_m: 0.05,
            rays: 1024,
        }
    }
}

/// Largest rays per key point accepted.
pub const MAX_RAYS: u32 = 1 << 20;

/// A key point is invalid when more than this fraction of its rays meet a back side or nothing
/// (inside a box most rays meet its faces from behind; the outdoor volume uses the same quarter).
const LOST_FRACTION_LIMIT: f32 = 0.25;

/// Occlusion rays start and stop this far from their ends, metres (as the form factors' offset).
const VISIBILITY_OFFSET_M: f32 = 1e-4;

/// Fixed directions over the whole sphere, each standing for an equal solid angle.
#[derive(Clone, Debug, PartialEq)]
pub struct GatherDirections {
    directions: Vec<Vec3>,
    d_omega: f32,
}

impl GatherDirections {
    /// `count` Fibonacci directions (`ibl_core::fibonacci_normals`), turned by `rotation`.
    pub fn fibonacci(count: u32, rotation: Mat3) -> Result<GatherDirections, RoomError> {
        if count == 0 || count > MAX_RAYS {
            return Err(RoomError::Parameter(format!(
                "{count} gather rays per point is not in 1..={MAX_RAYS}"
            )));
        }
        Ok(GatherDirections {
            directions: ibl_core::fibonacci_normals(count as usize)
                .into_iter()
                .map(|d| (rotation * d.as_vec3()).normalize())
                .collect(),
            d_omega: (4.0 * std::f64::consts::PI / f64::from(count)) as f32,
        })
    }

    /// The directions, unit, world frame.
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// The solid angle each direction stands for, sr.
    pub fn d_omega(&self) -> f32 {
        self.d_omega
    }
}

/// What the rays from one point gathered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointGather<P> {
    /// Irradiance from every patch.
    pub all: P,
    /// Irradiance from every patch but the important ones.
    pub unimportant: P,
    /// Fraction of the rays that met a back side or nothing.
    pub lost_fraction: f32,
    /// Distance to the nearest surface a ray met, metres (infinite when none).
    pub nearest_m: f32,
}

impl<P> PointGather<P> {
    /// Whether the point is inside a box or outside the room.
    pub fn is_inside_geometry(&self) -> bool {
        is_inside_geometry(self.lost_fraction)
    }
}

/// Whether a point from which `lost_fraction` of the rays met a back side or nothing is inside a
/// box or outside the room (more than a quarter lost).
pub fn is_inside_geometry(lost_fraction: f32) -> bool {
    lost_fraction > LOST_FRACTION_LIMIT
}

/// Casts `directions` from `point` into `radiance`'s room and calls `visit(w, radiance,
/// important)` for every ray that meets a patch's front (`important`: the patch is one of
/// `important`'s lights); returns the fraction of rays lost (back side or nothing) and the
/// distance to the nearest surface met (metres, infinite when none). One ray per direction.
pub fn trace_point(
    radiance: &RoomRadiance,
    important: &[bool],
    directions: &GatherDirections,
    point: Vec3,
    mut visit: impl FnMut(Vec3, Rgb, bool),
) -> (f32, f32) {
    let mut lost = 0usize;
    let mut nearest = f32::INFINITY;
    for &w in &directions.directions {
        match radiance.along(point, w, 0.0) {
            Some(hit) => {
                nearest = nearest.min(hit.distance_m);
                visit(w, hit.radiance, important[hit.patch as usize]);
            }
            None => lost += 1,
        }
    }
    (lost as f32 / directions.directions.len() as f32, nearest)
}

/// Gathers the room's radiance at `point` along `directions` into both layers (see
/// [`trace_point`]).
pub fn gather_point<P: GatheredIrradiance>(
    radiance: &RoomRadiance,
    important: &[bool],
    directions: &GatherDirections,
    point: Vec3,
) -> PointGather<P> {
    let mut all = P::ZERO;
    let mut unimportant = P::ZERO;
    let d_omega = directions.d_omega;
    let (lost_fraction, nearest_m) = trace_point(
        radiance,
        important,
        directions,
        point,
        |w, l, is_important| {
            all.add_light(w, l, d_omega);
            if !is_important {
                unimportant.add_light(w, l, d_omega);
            }
        },
    );
    PointGather {
        all,
        unimportant,
        lost_fraction,
        nearest_m,
    }
}

/// Which corner key points a look-up may use besides the valid ones.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KeyPointVisibility {
    /// Every valid corner (trilinear with validity only).
    Any,
    /// Only the corners no room surface hides from the position (one occlusion ray each).
    #[default]
    Unoccluded,
}

/// The room's irradiance volume: two layers of `P` per key point (SH L2 by default).
#[derive(Clone, Debug, PartialEq)]
pub struct RoomVolume<P = IrradianceL2> {
    volume: KeyPointVolume<P>,
    /// The settings it was built with.
    pub settings: VolumeSettings,
    /// Key points inside a box or outside the room.
    pub invalid_points: usize,
}

/// Per patch, whether it is one of `important`'s lights.
pub fn important_mask(patches: usize, important: &ImportantLights) -> Vec<bool> {
    let mut mask = vec![false; patches];
    for light in &important.important {
        if let Some(m) = mask.get_mut(light.patch as usize) {
            *m = true;
        }
    }
    mask
}

impl<P: GatheredIrradiance> RoomVolume<P> {
    /// Gathers the volume of `radiance`'s room with `important`'s patches left out of the
    /// unimportant layer. Key points in parallel; the result does not depend on the thread count.
    /// Cost: key points x `settings.rays` rays.
    pub fn build(
        radiance: &RoomRadiance,
        important: &ImportantLights,
        settings: &VolumeSettings,
    ) -> Result<RoomVolume<P>, RoomError> {
        let room = radiance.room();
        let (min, max) = room
            .bounds()
            .ok_or_else(|| RoomError::Parameter("the room has no surfaces".into()))?;
        let inset = Vec3::splat(settings.inset_m);
        if !(settings.inset_m >= 0.0 && (max - min).cmpgt(2.0 * inset).all()) {
            return Err(RoomError::Parameter(format!(
                "an inset of {} m leaves nothing of the room's {} m box",
                settings.inset_m,
                max - min
            )));
        }
        let grid = VolumeGrid::covering(
            (min + inset).as_dvec3(),
            (max - inset).as_dvec3(),
            f64::from(settings.spacing_m),
        )
        .map_err(|e| RoomError::Parameter(e.to_string()))?;
        let directions = GatherDirections::fibonacci(settings.rays, Mat3::IDENTITY)?;
        let mask = important_mask(room.patches.len(), important);
        let gathered: Vec<PointGather<P>> = (0..grid.len())
            .into_par_iter()
            .map(|k| gather_point(radiance, &mask, &directions, grid.position(k).as_vec3()))
            .collect();
        let mut volume = KeyPointVolume::new(grid, VolumeLayers::AllAndUnimportant);
        let mut invalid_points = 0;
        for (k, g) in gathered.iter().enumerate() {
            let inside = g.is_inside_geometry();
            volume.set_valid(k, !inside);
            invalid_points += usize::from(inside);
        }
        let all: Vec<P> = gathered.iter().map(|g| g.all).collect();
        let unimportant: Vec<P> = gathered.iter().map(|g| g.unimportant).collect();
        for (layer, values) in [
            (VolumeLayer::AllLight, all),
            (VolumeLayer::UnimportantLight, unimportant),
        ] {
            volume
                .layer_mut(layer)
                .map_err(|e| RoomError::Numerical(e.to_string()))?
                .copy_from_slice(&values);
        }
        Ok(RoomVolume {
            volume,
            settings: *settings,
            invalid_points,
        })
    }

    /// The key points.
    pub fn volume(&self) -> &KeyPointVolume<P> {
        &self.volume
    }

    /// The interpolated irradiance of `layer` at `position` in `room` (the room it was built
    /// for): trilinear over the valid corners (and, with `leak`'s [`LeakControl::Facing`], the
    /// corners in front of a surface weighted up), with `visibility`'s occlusion test; `None`
    /// when no corner is left (the position is inside a box or walled off from every corner).
    pub fn sample(
        &self,
        room: &crate::Room,
        position: Vec3,
        layer: VolumeLayer,
        leak: LeakControl,
        visibility: KeyPointVisibility,
    ) -> Option<P> {
        let visible = |key: Vec3| match visibility {
            KeyPointVisibility::Any => true,
            KeyPointVisibility::Unoccluded => {
                let d = key - position;
                let length = d.length();
                length <= 2.0 * VISIBILITY_OFFSET_M
                    || !room.occluded(
                        position,
                        d / length,
                        VISIBILITY_OFFSET_M,
                        length - VISIBILITY_OFFSET_M,
                    )
            }
        };
        // Both layers exist (built with `AllAndUnimportant`), so the look-up cannot fail.
        self.volume
            .sample_visible(position, layer, leak, visible)
            .ok()
            .flatten()
    }
}
