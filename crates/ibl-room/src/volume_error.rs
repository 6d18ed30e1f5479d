//! How far the irradiance volume's interpolation is from gathering at the point itself (Grosch
//! 2005, section 4.1: "we assume that the resulting irradiance gathered in the second value is
//! slowly varying and the error due to linear interpolation is small"; this measures it).
//!
//! Random positions uniform over the grid's box, or over a given region of it (a PCG stream of
//! the seed), are kept when they lie in the open (a direct gather there loses at most a quarter of its rays, the key points' rule).
//! At each, the **reference** is the irradiance on `normals` Fibonacci normals summed over the
//! rays of a denser direct gather (`E(n) = sum_i L_i max(0, n . w_i) 4 pi / K`, `K` rays turned by
//! 0.5 rad about (1, 1, 1) so that they share no direction with the key points' set). It is
//! compared with the volume's look-up at the position (**interpolated**) and with the volume's
//! representation gathered from the same reference rays (**at the point**: what the basis alone
//! loses, with no interpolation). The error of one position is `ibl-metrics`' `mean_err%` over
//! its normals (`100 mean_c(mean_k |e - g| / mean_k g)`, CONVENTIONS section 5); the statistics
//! are over positions. "Near" positions lie within one grid spacing of a surface, where leaks
//! show. Positions where the look-up finds no corner are counted and left out.

use glam::{Mat3, Vec3};
use ibl_metrics::IrradianceError;
use ibl_sh::{LeakControl, VolumeLayer};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use rayon::prelude::*;

use crate::RoomError;
use crate::important::ImportantLights;
use crate::irradiance_volume::{
    GatherDirections, GatheredIrradiance, KeyPointVisibility, RoomVolume, important_mask,
    is_inside_geometry, trace_point,
};
use crate::room_radiance::RoomRadiance;

/// What to measure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeErrorSettings {
    /// Positions to keep (in the open).
    pub points: usize,
    /// Normals per position.
    pub normals: usize,
    /// Rays of the reference gather at each position.
    pub rays: u32,
    /// Seed of the positions.
    pub seed: u64,
    /// The look-up's leak control.
    pub leak: LeakControl,
    /// The look-up's visibility test.
    pub visibility: KeyPointVisibility,
    /// Where positions are drawn, `[low, high]` corners, world frame, metres (`None`: the grid's
    /// box).
    pub region: Option<[Vec3; 2]>,
}

impl Default for VolumeErrorSettings {
    fn default() -> Self {
        VolumeErrorSettings {
            points: 200,
            normals: 64,
            rays: 4096,
            seed: 1,
            leak: LeakControl::ValidOnly,
            visibility: KeyPointVisibility::Unoccluded,
            region: None,
        }
    }
}

/// Candidate positions are drawn in rounds of `points`, at most this many rounds.
const MAX_ROUNDS: usize = 8;

/// The errors of one layer, `mean_err%` per position.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LayerError {
    /// Mean over positions of the interpolated look-up's error.
    pub mean_err_pct: f64,
    /// Its 95th percentile over positions.
    pub p95_err_pct: f64,
    /// Its largest value.
    pub max_err_pct: f64,
    /// Mean over the positions near a surface.
    pub near_mean_err_pct: f64,
    /// Mean over positions of the representation's error at the point itself (no interpolation).
    pub at_point_mean_err_pct: f64,
}

/// The volume's error against direct gathering.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VolumeError {
    /// Positions measured.
    pub points: usize,
    /// Of those, positions within one grid spacing of a surface.
    pub near_points: usize,
    /// Candidate positions dropped for lying inside a box or outside the room.
    pub rejected: usize,
    /// Positions where the look-up found no corner (left out of the statistics).
    pub failed: usize,
    /// The all-light layer.
    pub all_light: LayerError,
    /// The unimportant-light layer.
    pub unimportant: LayerError,
}

/// One position's errors: all light and unimportant, interpolated and at the point; `None` for
/// the interpolated pair when the look-up failed.
struct PositionError {
    near: bool,
    interpolated: Option<[f64; 2]>,
    at_point: [f64; 2],
}

/// Measures `volume` (built on `radiance` with `important`) against direct gathering.
pub fn volume_error<P: GatheredIrradiance>(
    radiance: &RoomRadiance,
    important: &ImportantLights,
    volume: &RoomVolume<P>,
    settings: &VolumeErrorSettings,
) -> Result<VolumeError, RoomError> {
    if settings.points == 0 || settings.normals == 0 {
        return Err(RoomError::Parameter(
            "the volume error needs at least one position and one normal".into(),
        ));
    }
    let room = radiance.room();
    let grid = *volume.volume().grid();
    let [low, high] = settings.region.unwrap_or_else(|| {
        let far = grid.spacing
            * glam::DVec3::new(
                (grid.counts[0] - 1) as f64,
                (grid.counts[1] - 1) as f64,
                (grid.counts[2] - 1) as f64,
            );
        [grid.origin.as_vec3(), (grid.origin + far).as_vec3()]
    });
    if !(low.is_finite() && high.is_finite() && high.cmpge(low).all()) {
        return Err(RoomError::Parameter(format!(
            "the region {low} to {high} is not a box"
        )));
    }
    let extent = high - low;
    let near_m = grid.spacing.max_element() as f32;
    let turn = Mat3::from_axis_angle(Vec3::ONE.normalize(), 0.5);
    let directions = GatherDirections::fibonacci(settings.rays, turn)?;
    let normals: Vec<Vec3> = ibl_core::fibonacci_normals(settings.normals)
        .iter()
        .map(|n| n.as_vec3())
        .collect();
    let mask = important_mask(room.patches.len(), important);
    let d_omega = directions.d_omega();
    let mut rng = Pcg32::seed_from_u64(settings.seed);
    let mut results: Vec<PositionError> = Vec::with_capacity(settings.points);
    let mut rejected = 0usize;
    for _ in 0..MAX_ROUNDS {
        let wanted = settings.points - results.len();
        if wanted == 0 {
            break;
        }
        let candidates: Vec<Vec3> = (0..settings.points)
            .map(|_| low + extent * Vec3::new(rng.random(), rng.random(), rng.random()))
            .collect();
        let round: Vec<Option<PositionError>> = candidates
            .par_iter()
            .map(|&p| {
                let mut basis = [P::ZERO; 2];
                let mut exact = vec![[[0.0f64; 3]; 2]; normals.len()];
                let (lost, nearest) =
                    trace_point(radiance, &mask, &directions, p, |w, l, is_important| {
                        let layers = if is_important { 1 } else { 2 };
                        for b in &mut basis[..layers] {
                            b.add_light(w, l, d_omega);
                        }
                        for (e, n) in exact.iter_mut().zip(&normals) {
                            let c = f64::from(n.dot(w).max(0.0) * d_omega);
                            for layer in e.iter_mut().take(layers) {
                                for ch in 0..3 {
                                    layer[ch] += c * f64::from(l[ch]);
                                }
                            }
                        }
                    });
                if is_inside_geometry(lost) {
                    return None;
                }
                let truth =
                    |layer: usize| -> Vec<[f64; 3]> { exact.iter().map(|e| e[layer]).collect() };
                let error = |layer: usize, value: &P| -> f64 {
                    let approx: Vec<[f64; 3]> = normals
                        .iter()
                        .map(|&n| value.irradiance(n).map(f64::from))
                        .collect();
                    IrradianceError::between(&truth(layer), &approx).mean_err_pct
                };
                // Layer 0 is all light, layer 1 the unimportant light (`basis`, `exact` order).
                let looked_up = [VolumeLayer::AllLight, VolumeLayer::UnimportantLight]
                    .map(|layer| volume.sample(room, p, layer, settings.leak, settings.visibility));
                let interpolated = match looked_up {
                    [Some(a), Some(u)] => Some([error(0, &a), error(1, &u)]),
                    _ => None,
                };
                Some(PositionError {
                    near: nearest < near_m,
                    interpolated,
                    at_point: [error(0, &basis[0]), error(1, &basis[1])],
                })
            })
            .collect();
        for r in round {
            match r {
                Some(e) if results.len() < settings.points => results.push(e),
                Some(_) => {}
                None => rejected += 1,
            }
        }
    }
    let failed = results.iter().filter(|r| r.interpolated.is_none()).count();
    let layer = |k: usize| -> LayerError {
        let mut values: Vec<f64> = results
            .iter()
            .filter_map(|r| r.interpolated.map(|v| v[k]))
            .collect();
        let near: Vec<f64> = results
            .iter()
            .filter(|r| r.near)
            .filter_map(|r| r.interpolated.map(|v| v[k]))
            .collect();
        values.sort_by(f64::total_cmp);
        let mean = |v: &[f64]| {
            if v.is_empty() {
                0.0
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        };
        let at_point: Vec<f64> = results.iter().map(|r| r.at_point[k]).collect();
        LayerError {
            mean_err_pct: mean(&values),
            p95_err_pct: values
                .get((0.95 * values.len() as f64) as usize)
                .or(values.last())
                .copied()
                .unwrap_or(0.0),
            max_err_pct: values.last().copied().unwrap_or(0.0),
            near_mean_err_pct: mean(&near),
            at_point_mean_err_pct: mean(&at_point),
        }
    };
    Ok(VolumeError {
        points: results.len(),
        near_points: results.iter().filter(|r| r.near).count(),
        rejected,
        failed,
        all_light: layer(0),
        unimportant: layer(1),
    })
}
