//! LightGen-style clustering (Cohen & Debevec 2001, the LightGen HDRShop plugin; Madsen &
//! Laursen 2006 section 4.1 list it without describing it): the probe's energy is clustered on
//! the sphere into N groups and each group becomes one light.
//!
//! # Algorithm
//! Weighted spherical k-means. Every pixel p has the energy `E_p = Y(L_p) dOmega_p` (Rec. 709
//! luminance x exact solid angle, CONVENTIONS section 4; invalid radiance counts as 0) and the
//! unit direction `d_p` (world frame, +Y up, -Z forward). For clusters `C_k` with unit centres
//! `c_k` the objective is the weighted within-cluster spread
//!
//! ```text
//! J = sum_k sum_{p in C_k} E_p (1 - d_p . c_k) = sum_k (P_k - |S_k|)   at c_k = S_k / |S_k|
//! ```
//!
//! with `P_k = sum E_p` and `S_k = sum E_p d_p`: half the energy-weighted squared chord length,
//! and the irradiance-error bound `P - |S|` that orders adaptive median cut. Lloyd rounds assign
//! each point to its nearest centre (largest `d . c_k`) and move each centre to its cluster's
//! normalised energy centroid; both steps lower J. The rounds stop when one lowers J by at most
//! 1e-5 of J, or after 100. Hamerly's (2010) bounds on chord lengths skip the points that cannot
//! change cluster, so later rounds cost far less than the first. A cluster left without energy
//! is reseeded with the point that adds most to J (taken from a cluster that keeps other energy).
//! Seeds are k-means++ (probability proportional to `E_p (1 - d_p . c)` for the nearest seed c)
//! drawn from a `rand_pcg::Pcg64`; the restarts' generators are seeded by numbers drawn in order
//! from one seeded by [`LightGenOptions::seed`]. Of the [`LightGenOptions::restarts`] runs the one
//! of least J is kept (ties: the earlier).
//!
//! # Lights
//! Each cluster becomes one light: direction `S_k / |S_k|` (the exact energy centroid of its
//! pixels), power per channel `I = sum L_p dOmega_p` over its pixels, solid angle `A = sum
//! dOmega_p`, radiance `I / A`. Every pixel belongs to exactly one cluster, so the lights' power
//! equals the probe's to f64 rounding. Lights are listed by decreasing luminance power.
//!
//! # Reduction
//! Clustering all W H pixels would cost O(W H N) per round. The probe is first reduced, conserving
//! power, to about 8192 blocks (4 x 4 pixels for 512 x 256; more, smaller blocks when 4 N >
//! 8192), each a point with its blocks' exact energy, moment `S`, power and solid angle, and
//! every pixel holding at least 1/4096 of the probe's energy is a point of its own, so that a
//! sun stays sharp and can be split between clusters pixel by pixel. Where fewer than N points
//! carry energy, every pixel with energy becomes its own point. Measured on the bundled probes,
//! 32768 blocks give the same errors (N = 16: 1.61 / 8.11 % against 1.59 / 7.45 %), 2048 blocks
//! slightly larger ones (1.69 / 8.10 %).
//!
//! # Exactly N lights
//! Always N lights, for 1 <= N <= min(W H, [`MAX_LIGHTS`]) (other N are
//! [`ExtractError::Parameter`]). A probe with fewer than N pixels that carry energy cannot fill N clusters with
//! energy: the surplus lights have zero power (they stand for black parts of the probe, at the
//! solid-angle weighted mean direction of their pixels); a black probe gives N zero lights.
//!
//! # Cost
//! O(W H) for the reduction, then O(R I P N) at worst for R restarts of I rounds (about 30 to 70)
//! over P points (about 8192 plus the bright pixels), in parallel over restarts and over points.
//! Every sum has a fixed order, so the lights are bit-identical whatever the thread count. See
//! `benches/extract.rs` for timings (tens of ms for N = 64, a few hundred for N = 256 on 2 cores).

use glam::DVec3;
use ibl_core::{Image, Rgb};
use ibl_light::spread::WIDEST_CORE_IN_A_CLUSTER;
use ibl_light::{Extraction, Light, LightSet, Provenance, SpreadHistogram};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

use crate::ExtractError;
use crate::region_stats::{Grid, clamped, core_fraction, light};

/// Clustering settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightGenOptions {
    /// Seed of the random initialisations; equal seeds give bit-identical lights.
    pub seed: u64,
    /// Number of restarts (1 to [`MAX_RESTARTS`]); the clustering of least spread is kept.
    pub restarts: usize,
}

impl Default for LightGenOptions {
    fn default() -> Self {
        LightGenOptions {
            seed: 1,
            restarts: 4,
        }
    }
}

/// Largest number of restarts accepted.
pub const MAX_RESTARTS: usize = 1000;

/// Largest number of lights accepted (the clustering costs O(N) per point and round).
pub const MAX_LIGHTS: usize = 4096;

/// Largest number of Lloyd rounds per restart.
const MAX_ROUNDS: usize = 100;

/// The rounds stop when one lowers the spread J by no more than this fraction of J.
const CONVERGED: f64 = 1e-5;

/// Blocks the reduction aims at (at least 4 N).
const TARGET_BLOCKS: usize = 8192;

/// A pixel holding at least this fraction of the probe's energy is a point of its own.
const BRIGHT_FRACTION: f64 = 1.0 / 4096.0;

/// One point of the reduced probe: a block of pixels or a single bright pixel.
#[derive(Clone, Copy, Debug)]
struct Point {
    /// Energy `sum E_p` (luminance x sr).
    energy: f64,
    /// Moment `sum E_p d_p`.
    moment: DVec3,
    /// Solid-angle weighted direction sum `sum dOmega_p d_p` (sr).
    geometric: DVec3,
    /// Unit direction used for assignment: `moment` normalised (`geometric` where black).
    dir: DVec3,
    /// Power per channel, `sum L_p dOmega_p`.
    power: [f64; 3],
    /// Solid angle, sr.
    solid_angle: f64,
    /// `sum E_p dOmega_p`, sr^2 x luminance: its pixels' own extent in a light's spread.
    extent: f64,
}

impl Point {
    fn empty() -> Point {
        Point {
            energy: 0.0,
            moment: DVec3::ZERO,
            geometric: DVec3::ZERO,
            dir: DVec3::Y,
            power: [0.0; 3],
            solid_angle: 0.0,
            extent: 0.0,
        }
    }

    fn add_pixel(&mut self, l: [f64; 3], energy: f64, d: DVec3, sr: f64) {
        self.energy += energy;
        self.moment += energy * d;
        self.geometric += sr * d;
        for (p, lc) in self.power.iter_mut().zip(l) {
            *p += lc * sr;
        }
        self.solid_angle += sr;
        self.extent += energy * sr;
    }

    fn finish(mut self) -> Point {
        self.dir = self
            .moment
            .try_normalize()
            .or_else(|| self.geometric.try_normalize())
            .unwrap_or(DVec3::Y);
        self
    }
}

/// LightGen-style clustering of a lat-long probe into exactly `n` lights (`1 <= n <= W H` and
/// `n <= MAX_LIGHTS`).
pub fn lightgen(
    probe: &Image<Rgb>,
    n: usize,
    o: &LightGenOptions,
) -> Result<LightSet, ExtractError> {
    let grid = Grid::new(probe)?;
    if n == 0 || n > grid.pixels().min(MAX_LIGHTS) {
        return Err(ExtractError::Parameter(format!(
            "lightgen makes 1 to {} lights for a {} x {} probe (one per pixel, {MAX_LIGHTS} at most); got {n}",
            grid.pixels().min(MAX_LIGHTS),
            grid.w,
            grid.h
        )));
    }
    if o.restarts == 0 || o.restarts > MAX_RESTARTS {
        return Err(ExtractError::Parameter(format!(
            "lightgen needs 1 to {MAX_RESTARTS} restarts; got {}",
            o.restarts
        )));
    }
    let rows: Vec<f64> = (0..grid.h)
        .into_par_iter()
        .map(|j| {
            let row: f64 = probe.row(j).iter().map(|p| clamped(*p).1).sum();
            row * grid.row_sr[j]
        })
        .collect();
    let total: f64 = rows.iter().sum();
    let mut points = reduce(probe, &grid, n, total * BRIGHT_FRACTION);
    if points.iter().filter(|p| p.energy > 0.0).count() < n {
        points = reduce(probe, &grid, n, 0.0);
    }
    let mut master = Pcg64::seed_from_u64(o.seed);
    let seeds: Vec<u64> = (0..o.restarts).map(|_| master.random()).collect();
    let runs: Vec<Clustering> = seeds.par_iter().map(|&s| cluster(&points, n, s)).collect();
    let mut best = &runs[0];
    for run in &runs[1..] {
        if run.spread < best.spread {
            best = run;
        }
    }
    let mut sums = vec![Point::empty(); n];
    for (p, &k) in points.iter().zip(&best.assignment) {
        let s = &mut sums[k];
        s.energy += p.energy;
        s.moment += p.moment;
        s.geometric += p.geometric;
        for (sc, pc) in s.power.iter_mut().zip(p.power) {
            *sc += pc;
        }
        s.solid_angle += p.solid_angle;
    }
    let mut lights: Vec<(f64, Light)> = sums
        .iter()
        .zip(&best.centres)
        .map(|(s, c)| {
            let dir = s
                .moment
                .try_normalize()
                .or_else(|| s.geometric.try_normalize())
                .unwrap_or(*c);
            (s.energy, light(dir, s.power, s.solid_angle, None, None))
        })
        .collect();
    // Each light's spread about its direction from its points ([`ibl_light::spread`]; a
    // block's own extent taken as its pixels' mean solid angle).
    let mut spreads = vec![SpreadHistogram::new(); n];
    for (p, &k) in points.iter().zip(&best.assignment) {
        if p.energy > 0.0 {
            let key = 1.0 - p.dir.dot(lights[k].1.direction);
            spreads[k].add(key, p.energy, p.extent / p.energy);
        }
    }
    for ((_, l), h) in lights.iter_mut().zip(&spreads) {
        l.spread_sr = h.spread_sr();
        l.core_fraction = core_fraction(h, l, WIDEST_CORE_IN_A_CLUSTER);
    }
    lights.sort_by(|a, b| b.0.total_cmp(&a.0));
    Ok(LightSet {
        provenance: Provenance::extracted(Extraction::LightGen {
            restarts: o.restarts,
            seed: o.seed,
        }),
        lights: lights.into_iter().map(|(_, l)| l).collect(),
    })
}

/// The probe as points: square blocks of about `W H / max(8192, 4 n)` pixels, less every pixel
/// with energy above 0 and at least `bright` (each a point of its own, listed after its block
/// row's blocks). Cost O(W H), parallel over block rows.
fn reduce(probe: &Image<Rgb>, grid: &Grid, n: usize, bright: f64) -> Vec<Point> {
    let target = TARGET_BLOCKS.max(4 * n);
    let side = ((grid.pixels() as f64 / target as f64).sqrt().ceil() as usize).max(1);
    let (bx, by) = (grid.w.div_ceil(side), grid.h.div_ceil(side));
    (0..by)
        .into_par_iter()
        .flat_map_iter(|b| {
            let (y0, y1) = (b * side, ((b + 1) * side).min(grid.h));
            let mut blocks = vec![Point::empty(); bx];
            let mut singles = Vec::new();
            for j in y0..y1 {
                let sr = grid.row_sr[j];
                for (i, p) in probe.row(j).iter().enumerate() {
                    let (l, y) = clamped(*p);
                    let (e, d) = (y * sr, grid.dir(i, j));
                    if e > 0.0 && e >= bright {
                        let mut single = Point::empty();
                        single.add_pixel(l, e, d, sr);
                        singles.push(single.finish());
                    } else {
                        blocks[i / side].add_pixel(l, e, d, sr);
                    }
                }
            }
            blocks
                .into_iter()
                .filter(|p| p.solid_angle > 0.0)
                .map(Point::finish)
                .chain(singles)
        })
        .collect()
}

/// One k-means run: the cluster of every point, the unit centres and the spread J.
struct Clustering {
    assignment: Vec<usize>,
    centres: Vec<DVec3>,
    spread: f64,
}

/// A point's cluster with Hamerly's (2010) bounds on chord lengths (Euclidean distances between
/// unit vectors, `sqrt(2 - 2 d . c)`, a metric in which the nearest centre is the one of largest
/// dot product): `upper` >= the distance to its cluster's centre, `lower` <= the distance to
/// every other centre. While `upper < lower` the cluster cannot change.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    cluster: usize,
    upper: f64,
    lower: f64,
}

/// Margin by which the bounds must be apart before a point keeps its cluster unchecked, far
/// above the rounding of the distances.
const BOUND_SLACK: f64 = 1e-6;

/// Chord length between unit vectors from their dot product.
fn chord(dot: f64) -> f64 {
    (2.0 - 2.0 * dot).max(0.0).sqrt()
}

/// Centres per block of the nearest-centre search.
const SEARCH_BLOCK: usize = 32;

/// The centre nearest to `d` (largest dot product, the first on ties) with exact bounds. The dot
/// products are computed a block of centres at a time (a loop the compiler vectorises), and a
/// block whose largest dot product cannot beat the second best so far is passed over.
fn nearest(d: DVec3, cx: &[f64], cy: &[f64], cz: &[f64]) -> Bounds {
    let (mut first, mut cluster, mut second) = (f64::NEG_INFINITY, 0, f64::NEG_INFINITY);
    let mut dots = [0.0f64; SEARCH_BLOCK];
    let mut start = 0;
    while start < cx.len() {
        let x = &cx[start..(start + SEARCH_BLOCK).min(cx.len())];
        let (y, z, dots) = (
            &cy[start..][..x.len()],
            &cz[start..][..x.len()],
            &mut dots[..x.len()],
        );
        for i in 0..x.len() {
            dots[i] = d.x * x[i] + d.y * y[i] + d.z * z[i];
        }
        let top = dots
            .iter()
            .fold(f64::NEG_INFINITY, |m, &v| if v > m { v } else { m });
        if top > second {
            for (i, &dot) in dots.iter().enumerate() {
                if dot > first {
                    second = first;
                    first = dot;
                    cluster = start + i;
                } else if dot > second {
                    second = dot;
                }
            }
        }
        start += x.len();
    }
    Bounds {
        cluster,
        upper: chord(first),
        lower: if second == f64::NEG_INFINITY {
            f64::INFINITY
        } else {
            chord(second)
        },
    }
}

/// Unit centres of the clusters: each cluster's normalised moment (unchanged where it has none).
fn update_centres(points: &[Point], bounds: &[Bounds], centres: &mut [DVec3]) {
    let mut moment = vec![DVec3::ZERO; centres.len()];
    for (p, b) in points.iter().zip(bounds) {
        moment[b.cluster] += p.moment;
    }
    for (c, m) in centres.iter_mut().zip(moment) {
        if let Some(m) = m.try_normalize() {
            *c = m;
        }
    }
}

/// k-means++ seeds followed by Lloyd rounds (see the module doc), with Hamerly's bounds so that
/// the later rounds check only the points near a cluster boundary.
fn cluster(points: &[Point], n: usize, seed: u64) -> Clustering {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut centres = seeds(points, n, &mut rng);
    let soa = |c: &[DVec3]| -> [Vec<f64>; 3] {
        [
            c.iter().map(|c| c.x).collect(),
            c.iter().map(|c| c.y).collect(),
            c.iter().map(|c| c.z).collect(),
        ]
    };
    let [cx, cy, cz] = soa(&centres);
    let mut bounds: Vec<Bounds> = points
        .par_iter()
        .with_min_len(256)
        .map(|p| nearest(p.dir, &cx, &cy, &cz))
        .collect();
    let mut previous = f64::INFINITY;
    for _ in 0..MAX_ROUNDS {
        let reseeded = reseed(points, &mut bounds, &centres, n);
        let old = centres.clone();
        update_centres(points, &bounds, &mut centres);
        let j = spread(points, &bounds, &centres);
        if !reseeded && previous - j <= CONVERGED * j {
            break;
        }
        previous = j;
        let shift: Vec<f64> = old
            .iter()
            .zip(&centres)
            .map(|(a, b)| a.distance(*b))
            .collect();
        // Largest shift, its cluster, and the largest shift of any other cluster.
        let (mut top, mut top_k, mut runner_up) = (0.0f64, usize::MAX, 0.0f64);
        for (k, &s) in shift.iter().enumerate() {
            if s > top {
                runner_up = top;
                top = s;
                top_k = k;
            } else if s > runner_up {
                runner_up = s;
            }
        }
        let [cx, cy, cz] = soa(&centres);
        let next: Vec<Bounds> = points
            .par_iter()
            .zip(&bounds)
            .with_min_len(256)
            .map(|(p, b)| {
                let others = if b.cluster == top_k { runner_up } else { top };
                let lower = b.lower - others;
                let upper = b.upper + shift[b.cluster];
                if upper + BOUND_SLACK < lower {
                    return Bounds { upper, lower, ..*b };
                }
                let c = centres[b.cluster];
                let upper = chord(p.dir.dot(c));
                if upper + BOUND_SLACK < lower {
                    return Bounds { upper, lower, ..*b };
                }
                nearest(p.dir, &cx, &cy, &cz)
            })
            .collect();
        let changed = next
            .iter()
            .zip(&bounds)
            .any(|(a, b)| a.cluster != b.cluster);
        bounds = next;
        if !changed && !reseeded {
            break;
        }
    }
    update_centres(points, &bounds, &mut centres);
    Clustering {
        spread: spread(points, &bounds, &centres),
        assignment: bounds.iter().map(|b| b.cluster).collect(),
        centres,
    }
}

/// The spread `J = sum_p (E_p - S_p . c_k)` of an assignment (summed in point order).
fn spread(points: &[Point], bounds: &[Bounds], centres: &[DVec3]) -> f64 {
    points
        .iter()
        .zip(bounds)
        .map(|(p, b)| p.energy - p.moment.dot(centres[b.cluster]))
        .sum()
}

/// Moves into every cluster without energy the point with energy that adds most to the spread
/// `E - S . c`, taken from a cluster that keeps other points with energy; a moved point's bounds
/// are reset so that the next round checks it. True if any moved.
fn reseed(points: &[Point], bounds: &mut [Bounds], centres: &[DVec3], n: usize) -> bool {
    let mut members = vec![0usize; n];
    for (p, b) in points.iter().zip(bounds.iter()) {
        if p.energy > 0.0 {
            members[b.cluster] += 1;
        }
    }
    let mut moved = false;
    for k in 0..n {
        if members[k] > 0 {
            continue;
        }
        let mut worst: Option<(f64, usize)> = None;
        for (i, (p, b)) in points.iter().zip(bounds.iter()).enumerate() {
            let cost = p.energy - p.moment.dot(centres[b.cluster]);
            if p.energy > 0.0 && members[b.cluster] > 1 && cost > worst.map_or(0.0, |w| w.0) {
                worst = Some((cost, i));
            }
        }
        let Some((_, i)) = worst else { break };
        members[bounds[i].cluster] -= 1;
        members[k] += 1;
        bounds[i] = Bounds {
            cluster: k,
            upper: f64::INFINITY,
            lower: 0.0,
        };
        moved = true;
    }
    moved
}

/// k-means++ seeds: the first with probability proportional to energy, each next one with
/// probability proportional to `E (1 - d . c)` from its nearest seed; where no energy is left
/// unrepresented (fewer points with energy than n) the point farthest from every seed.
fn seeds(points: &[Point], n: usize, rng: &mut Pcg64) -> Vec<DVec3> {
    let mut centres = Vec::with_capacity(n);
    // Distance `1 - d . c` of every point to its nearest seed (2 before the first).
    let mut dist = vec![2.0f64; points.len()];
    while centres.len() < n {
        let weights: Vec<f64> = points
            .iter()
            .zip(&dist)
            .map(|(p, d)| p.energy * d.max(0.0))
            .collect();
        let total: f64 = weights.iter().sum();
        let pick = if total > 0.0 {
            let target = rng.random::<f64>() * total;
            let mut acc = 0.0;
            let mut pick = None;
            for (i, w) in weights.iter().enumerate() {
                if *w > 0.0 {
                    acc += w;
                    pick = Some(i);
                    if acc > target {
                        break;
                    }
                }
            }
            pick
        } else {
            None
        };
        let i = pick.unwrap_or_else(|| {
            dist.iter()
                .enumerate()
                .fold(
                    (0, f64::NEG_INFINITY),
                    |b, (i, d)| {
                        if *d > b.1 { (i, *d) } else { b }
                    },
                )
                .0
        });
        let c = points.get(i).map_or(DVec3::Y, |p| p.dir);
        centres.push(c);
        for (d, p) in dist.iter_mut().zip(points) {
            *d = d.min(1.0 - p.dir.dot(c));
        }
        // Exactly 0 (not rounding noise), so that no point is drawn twice.
        if let Some(d) = dist.get_mut(i) {
            *d = 0.0;
        }
    }
    centres
}
