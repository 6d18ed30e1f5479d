//! Form factors between patches by ray casting on the BVH (Grosch 2005, section 3.2, EQ2:
//! `E_e = sum_s B_s F_es`).
//!
//! The form factor `F_es` is the fraction of the light leaving patch `e` diffusely that arrives
//! at patch `s` directly: `F_es = 1/A_e int_e int_s cos(t_e) cos(t_s) / (pi r^2) V dA_s dA_e`.
//! Its Monte Carlo estimate is the fraction of cosine-distributed rays from uniform points on `e`
//! whose first hit is the front of `s` (Malley's method): no `1/r^2` singularity, exact
//! visibility, and the row sums to 1 in a closed room because every ray hits something.
//! By reciprocity `A_e F_es = A_s F_se`, the same number is the irradiance weight `E_e = sum_s
//! B_s F_es` for a receiver `e` of uniform irradiance: each ray gathers the radiosity of what it
//! hits.
//!
//! Sampling is stratified twice: `a x a` strata over the patch (unit-square coordinates mapped
//! by [`PatchShape::point`](crate::patches::PatchShape::point)) times `b x b` strata over the
//! cosine-weighted hemisphere (`r = sqrt(u1)`, `phi = 2 pi u2`), `a^2 b^2` rays per patch, every
//! ray jittered inside its two strata by a per-patch PCG stream: the result depends on the seed
//! and the patch only, never on the thread count. Rays start `1e-4 m` off the patch along its
//! normal. Rays that meet a back side (a gap in the model) or nothing (an open model) are counted
//! apart and belong to no patch. Rows are stored sparse (CSR): at most one entry per patch hit.
//! Cost: `P a^2 b^2` rays, O(log T) each.

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::Vec3;
use ibl_core::Rgb;
use ibl_scene::primitives::tangents;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use rayon::prelude::*;

use crate::{Room, RoomError};

/// How form factors are sampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FormFactorSettings {
    /// Rays per patch, rounded to `a^2 b^2` with `a ~ K^(1/4)` position strata per axis and
    /// `b ~ sqrt(K) / a` direction strata per axis.
    pub rays_per_patch: u32,
    /// Seed of the jitter.
    pub seed: u64,
}

impl Default for FormFactorSettings {
    fn default() -> Self {
        FormFactorSettings {
            rays_per_patch: 1024,
            seed: 1,
        }
    }
}

/// Largest accepted rays per patch.
pub const MAX_RAYS_PER_PATCH: u32 = 1 << 20;

/// Offset of ray origins from the patch along its normal, metres.
const RAY_OFFSET_M: f32 = 1e-4;

impl FormFactorSettings {
    /// `(a, b)`: position and direction strata per axis.
    pub fn strata(&self) -> (u32, u32) {
        let k = f64::from(self.rays_per_patch.max(1));
        let a = k.powf(0.25).round().max(1.0);
        let b = (k.sqrt() / a).round().max(1.0);
        (a as u32, b as u32)
    }

    /// Rays actually cast per patch, `a^2 b^2`.
    pub fn rays(&self) -> u32 {
        let (a, b) = self.strata();
        a * a * b * b
    }
}

/// The form-factor matrix, one sparse row per patch.
#[derive(Clone, Debug, PartialEq)]
pub struct FormFactors {
    row_start: Vec<u32>,
    columns: Vec<u32>,
    values: Vec<f32>,
    /// Per patch, the fraction of its rays that met nothing.
    pub escaped: Vec<f32>,
    /// Per patch, the fraction of its rays that met a back side.
    pub back: Vec<f32>,
    /// Rays cast per patch.
    pub rays_per_patch: u32,
}

impl FormFactors {
    /// Casts the rays of every patch of `room`. `progress(done, total)` is called as patches are
    /// finished, from worker threads.
    pub fn compute(
        room: &Room,
        settings: &FormFactorSettings,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<FormFactors, RoomError> {
        if settings.rays_per_patch == 0 || settings.rays_per_patch > MAX_RAYS_PER_PATCH {
            return Err(RoomError::Parameter(format!(
                "rays_per_patch {} is not in 1..={MAX_RAYS_PER_PATCH}",
                settings.rays_per_patch
            )));
        }
        let (a, b) = settings.strata();
        let rays = a * a * b * b;
        let n = room.patches.len();
        let done = AtomicUsize::new(0);
        let rows: Vec<PatchRow> = (0..n)
            .into_par_iter()
            .map(|e| {
                let row = patch_row(room, e, a, b, settings.seed);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, n);
                row
            })
            .collect();
        let mut row_start = Vec::with_capacity(n + 1);
        let mut columns = Vec::new();
        let mut values = Vec::new();
        let mut escaped = Vec::with_capacity(n);
        let mut back = Vec::with_capacity(n);
        row_start.push(0);
        for (entries, esc, bk) in rows {
            for (c, v) in entries {
                columns.push(c);
                values.push(v);
            }
            row_start.push(columns.len() as u32);
            escaped.push(esc);
            back.push(bk);
        }
        Ok(FormFactors {
            row_start,
            columns,
            values,
            escaped,
            back,
            rays_per_patch: rays,
        })
    }

    /// Number of rows (patches).
    pub fn len(&self) -> usize {
        self.escaped.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.escaped.is_empty()
    }

    /// Row `e`: the patches `s` with `F_es > 0` and their form factors.
    pub fn row(&self, e: usize) -> (&[u32], &[f32]) {
        let (a, b) = (self.row_start[e] as usize, self.row_start[e + 1] as usize);
        (&self.columns[a..b], &self.values[a..b])
    }

    /// `F_es` (zero when `s` is not in row `e`).
    pub fn get(&self, e: usize, s: usize) -> f32 {
        let (cols, vals) = self.row(e);
        cols.binary_search(&(s as u32))
            .map(|k| vals[k])
            .unwrap_or(0.0)
    }

    /// `sum_s F_es`: 1 in a closed, gap-free room.
    pub fn row_sum(&self, e: usize) -> f32 {
        self.row(e).1.iter().sum()
    }

    /// Stored entries.
    pub fn entries(&self) -> usize {
        self.values.len()
    }

    /// Irradiance `E_e = sum_s B_s F_es` of patch `e` (EQ2), summed in row order.
    pub fn gather_one(&self, e: usize, radiosity: &[Rgb]) -> Rgb {
        let (cols, vals) = self.row(e);
        let mut sum = [0.0f64; 3];
        for (&s, &f) in cols.iter().zip(vals) {
            let b = radiosity[s as usize];
            sum[0] += f64::from(b.r) * f64::from(f);
            sum[1] += f64::from(b.g) * f64::from(f);
            sum[2] += f64::from(b.b) * f64::from(f);
        }
        Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
    }

    /// Irradiance of every patch (EQ2), rows in parallel (each summed in order: deterministic).
    pub fn gather(&self, radiosity: &[Rgb]) -> Vec<Rgb> {
        (0..self.len())
            .into_par_iter()
            .map(|e| self.gather_one(e, radiosity))
            .collect()
    }
}

/// One patch's row: sorted `(patch, fraction)` entries, then the escaped and back fractions.
type PatchRow = (Vec<(u32, f32)>, f32, f32);

/// The hits of patch `e`'s rays.
fn patch_row(room: &Room, e: usize, a: u32, b: u32, seed: u64) -> PatchRow {
    let patch = &room.patches[e];
    let n = patch.normal;
    let (t1, t2) = tangents(n);
    let mut rng = Pcg32::seed_from_u64(seed ^ (e as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let mut hits: Vec<u32> = Vec::with_capacity((a * a * b * b) as usize);
    let (mut escaped, mut back) = (0u32, 0u32);
    let (fa, fb) = (a as f32, b as f32);
    for pi in 0..a * a {
        let (px, py) = ((pi % a) as f32, (pi / a) as f32);
        for di in 0..b * b {
            let (dx, dy) = ((di % b) as f32, (di / b) as f32);
            let s = (px + rng.random::<f32>()) / fa;
            let t = (py + rng.random::<f32>()) / fa;
            let u1 = (dx + rng.random::<f32>()) / fb;
            let u2 = (dy + rng.random::<f32>()) / fb;
            let r = u1.sqrt();
            let phi = std::f32::consts::TAU * u2;
            let z = (1.0 - u1).max(0.0).sqrt();
            let dir: Vec3 = (t1 * (r * phi.cos()) + t2 * (r * phi.sin()) + n * z).normalize();
            let origin = patch.shape.point(s.min(1.0), t.min(1.0)) + n * RAY_OFFSET_M;
            match room.hit(origin, dir, 0.0, f32::INFINITY) {
                Some(h) if h.front => hits.push(h.patch),
                Some(_) => back += 1,
                None => escaped += 1,
            }
        }
    }
    let total = (a * a * b * b) as f32;
    hits.sort_unstable();
    let mut row: Vec<(u32, f32)> = Vec::new();
    for &h in &hits {
        match row.last_mut() {
            Some((c, v)) if *c == h => *v += 1.0,
            _ => row.push((h, 1.0)),
        }
    }
    for (_, v) in &mut row {
        *v /= total;
    }
    (row, escaped as f32 / total, back as f32 / total)
}
