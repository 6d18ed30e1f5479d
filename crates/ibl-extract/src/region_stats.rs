//! Shared machinery of the region methods (median cut, adaptive median cut, variance
//! minimisation): the lat-long geometry with its trigonometry tabulated once, summed-area tables
//! of energy moments, the median-cut cut, a greedy best-first splitter and the light that stands
//! for a region.
//!
//! # Quantities (CONVENTIONS sections 2 and 4)
//! For pixel p with clamped radiance `L_p` (negative, NaN and infinite channels count as 0), exact
//! solid angle `dOmega_p` (sr) and centre direction `d_p = (sin t sin f, cos t, -sin t cos f)`:
//!
//! ```text
//! energy     E_p = Y(L_p) dOmega_p         Y = Rec. 709 luminance, in f64
//! moment     S_p = E_p d_p                 (3-vector, world frame)
//! ```
//!
//! A region's power is `P = sum E_p` and its energy-weighted mean direction is `m = S / P` with
//! `S = sum S_p` and `|m| <= 1`. Two region statistics follow from `(P, S)` alone:
//!
//! - **Irradiance-error bound** `P - |S| = P (1 - |m|)`: replacing the region by a light of power P
//!   at `m / |m|` changes the irradiance on any normal n that sees the whole region by
//!   `|n . S - P n . m/|m|| = |n . m/|m|| (P - |S|) <= P - |S|`.
//! - **Spatial variance on the sphere** `sum E_p |d_p - m|^2 = P - |S|^2 / P = P (1 - |m|^2)`:
//!   the energy-weighted squared chordal distance of the region's pixels to their mean point.
//!
//! # Summed-area tables
//! [`MomentTable`] holds prefix sums of K channels (`E` alone for median cut, `E, S_x, S_y, S_z`
//! for the adaptive and variance methods) in f64, so each region's `P` and `S` cost O(1): four
//! look-ups. Building costs O(K W H) in one pass over the pixels, parallel over bands of 16 rows
//! (each band sums its rows from its own top; a band's offset row adds the bands above it at
//! look-up). The bands and the order of every addition are fixed, so the tables are bit-identical
//! whatever the thread count. Rows whose values are all valid (checked once, [`Grid::clean`])
//! skip the clamping ([`each_pixel`]).
//!
//! # Lights
//! [`region_lights`] sums each region's power per pixel (not from the tables, so that the
//! lights' power is exact to f64 rounding: the sum over a partition equals the probe's power to
//! about 1e-15 relative): power per channel `I = sum L_p dOmega_p`, solid angle `A = sum
//! dOmega_p`, radiance `I / A`, direction `S / |S|` (the solid-angle weighted mean direction where
//! the region is black), with S summed per pixel too (median cut) or taken from the direction
//! table (adaptive median cut, variance minimisation), and the spread: the solid angle of the
//! uniform cone with the region's half-energy angle about that direction
//! ([`ibl_light::spread`], a second pass over the pixels), which sizes the light's soft shadow
//! (a sun in a region of sky casts the sun's sharp one). Cost O(W H) over a
//! partition, in parallel over regions.

use std::collections::BinaryHeap;

use glam::DVec3;
use ibl_core::{Image, LatLong, Rgb};
use rayon::prelude::*;

use crate::ExtractError;
use ibl_core::rgb::Rgb64;
use ibl_light::spread::WIDEST_CORE_IN_A_REGION;
use ibl_light::{Light, PixelRegion, SpreadHistogram};

/// Rec. 709 luminance weights in f64 (the same numbers as `ibl_core::rgb::LUMINANCE_WEIGHTS`).
const LUMINANCE: [f64; 3] = [
    ibl_core::rgb::LUMINANCE_WEIGHTS[0] as f64,
    ibl_core::rgb::LUMINANCE_WEIGHTS[1] as f64,
    ibl_core::rgb::LUMINANCE_WEIGHTS[2] as f64,
];

/// A radiance channel as f64, with negative, NaN and infinite values counted as 0.
fn valid(v: f32) -> f64 {
    if v.is_finite() && v > 0.0 {
        f64::from(v)
    } else {
        0.0
    }
}

/// A pixel's clamped radiance per channel and its luminance (probe unit).
pub(crate) fn clamped(p: Rgb) -> ([f64; 3], f64) {
    let l = [valid(p.r), valid(p.g), valid(p.b)];
    (l, luminance(l))
}

/// Rec. 709 luminance of a clamped radiance.
fn luminance(l: [f64; 3]) -> f64 {
    LUMINANCE[0] * l[0] + LUMINANCE[1] * l[1] + LUMINANCE[2] * l[2]
}

/// Whether every channel of every pixel of `row` is already a valid radiance (finite, not
/// negative, not -0): then [`each_pixel`] needs no clamps. Branch-free, so it vectorises.
fn is_clean(row: &[Rgb]) -> bool {
    // Bit 31 of `flag(v)` is set for a negative value (sign bit) and for an all-ones exponent
    // (infinite or NaN): the carry of `exponent + 1` reaches bit 31.
    let flag = |v: f32| {
        let b = v.to_bits();
        b | ((b & 0x7f80_0000) + 0x0080_0000)
    };
    row.iter()
        .fold(0u32, |m, p| m | flag(p.r) | flag(p.g) | flag(p.b))
        & 0x8000_0000
        == 0
}

/// Calls `f(item, radiance, luminance)` for every pixel of `row` paired with the items of
/// `with`, radiance clamped as by [`clamped`]. A `clean` row (see [`is_clean`]; the common case,
/// files are clamped when read) takes a loop without the clamps, which the compiler can
/// vectorise; both loops give identical values.
#[inline(always)]
pub(crate) fn each_pixel<T>(
    row: &[Rgb],
    clean: bool,
    with: impl IntoIterator<Item = T>,
    mut f: impl FnMut(T, [f64; 3], f64),
) {
    if clean {
        for (t, p) in with.into_iter().zip(row) {
            let l = [f64::from(p.r), f64::from(p.g), f64::from(p.b)];
            f(t, l, luminance(l));
        }
    } else {
        for (t, p) in with.into_iter().zip(row) {
            let (l, y) = clamped(*p);
            f(t, l, y);
        }
    }
}

/// The lat-long geometry of a W x H probe with its trigonometry tabulated: row `j` has polar
/// angle `t_j = pi (j + 0.5) / H` and exact pixel solid angle `dOmega_j` (sr), column `i` has
/// azimuth `f_i = 2 pi ((i + 0.5) / W - 0.5)`. `dir(i, j)` equals `LatLong::pixel_dir64` bit for
/// bit.
#[derive(Clone, Debug)]
pub(crate) struct Grid {
    /// Width in pixels.
    pub w: usize,
    /// Height in pixels.
    pub h: usize,
    /// Exact solid angle of one pixel per row, sr.
    pub row_sr: Vec<f64>,
    /// `(sin t_j, cos t_j)` per row.
    pub row_trig: Vec<(f64, f64)>,
    /// `(sin f_i, cos f_i)` per column.
    pub col_trig: Vec<(f64, f64)>,
    /// Prefix sums over columns `0..i` of `(sin f, cos f)`, `W + 1` entries.
    col_prefix: Vec<(f64, f64)>,
    /// Per row, whether it needs no clamping ([`is_clean`]).
    pub clean: Vec<bool>,
}

impl Grid {
    /// The geometry of `probe` and which of its rows need no clamping; an image without pixels
    /// is [`ExtractError::Invalid`]. Cost O(W H), parallel over rows.
    pub fn new(probe: &Image<Rgb>) -> Result<Grid, ExtractError> {
        let (w, h) = (probe.width(), probe.height());
        if w == 0 || h == 0 {
            return Err(ExtractError::Invalid("the probe has no pixels".into()));
        }
        let ll = LatLong::new(w, h);
        let row_trig = (0..h)
            .map(|j| (std::f64::consts::PI * ((j as f64 + 0.5) / h as f64)).sin_cos())
            .collect();
        let col_trig: Vec<(f64, f64)> = (0..w)
            .map(|i| (std::f64::consts::TAU * ((i as f64 + 0.5) / w as f64 - 0.5)).sin_cos())
            .collect();
        let mut col_prefix = Vec::with_capacity(w + 1);
        let mut acc = (0.0, 0.0);
        col_prefix.push(acc);
        for &(s, c) in &col_trig {
            acc = (acc.0 + s, acc.1 + c);
            col_prefix.push(acc);
        }
        Ok(Grid {
            w,
            h,
            row_sr: ll.row_solid_angles(),
            row_trig,
            col_trig,
            col_prefix,
            clean: (0..h)
                .into_par_iter()
                .map(|j| is_clean(probe.row(j)))
                .collect(),
        })
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.w * self.h
    }

    /// Centre direction of pixel (i, j), unit, world frame.
    pub fn dir(&self, i: usize, j: usize) -> DVec3 {
        let (st, ct) = self.row_trig[j];
        let (sp, cp) = self.col_trig[i];
        DVec3::new(st * sp, ct, -st * cp)
    }

    /// The whole probe as one region.
    pub fn full(&self) -> PixelRegion {
        PixelRegion {
            x0: 0,
            y0: 0,
            x1: self.w,
            y1: self.h,
        }
    }

    /// Solid angle of a region, sr, and its solid-angle weighted direction sum
    /// `sum dOmega_p d_p` (sr). Cost O(height) from the column prefix sums.
    pub fn geometry(&self, r: &PixelRegion) -> (f64, DVec3) {
        let n = r.width() as f64;
        let (s0, c0) = self.col_prefix[r.x0];
        let (s1, c1) = self.col_prefix[r.x1];
        let (sum_sin, sum_cos) = (s1 - s0, c1 - c0);
        let mut sr = 0.0;
        let mut g = DVec3::ZERO;
        for j in r.y0..r.y1 {
            let (st, ct) = self.row_trig[j];
            let o = self.row_sr[j];
            sr += o;
            g += o * DVec3::new(st * sum_sin, ct * n, -st * sum_cos);
        }
        (sr * n, g)
    }
}

/// Summed-area tables of K f64 channels over a W x H probe: `at(x, y)` is the sum over columns
/// `< x` and rows `< y`.
///
/// The rows are cut into bands of [`BAND_ROWS`] rows, built independently in parallel: `table`
/// holds each row's sums from the top of its band, and `offsets[b]` the sums of every row above
/// band `b`, so that `at(x, y) = table[y - 1][x] + offsets[band of row y - 1][x]`. Building is one
/// parallel pass over the pixels with every row cache-hot (no separate vertical pass); the bands
/// do not depend on the thread count, so neither does any sum.
#[derive(Clone, Debug)]
pub(crate) struct MomentTable<const K: usize> {
    /// `W + 1`.
    stride: usize,
    /// H rows of `stride` entries (a leading zero, then the prefix sums within the band).
    table: Vec<[f64; K]>,
    /// Per band, the sums of every row above it (`stride` entries).
    offsets: Vec<Vec<[f64; K]>>,
}

/// Rows per band of a [`MomentTable`].
const BAND_ROWS: usize = 16;

impl<const K: usize> MomentTable<K> {
    /// Builds the table; `fill(j, row, above)` writes into `row` (W entries) the running sums of
    /// the K values of row `j`'s pixels plus `above` (the previous row of the band, or zeros),
    /// using [`running`]. Cost O(K W H), parallel over bands of rows.
    fn build(grid: &Grid, fill: impl Fn(usize, &mut [[f64; K]], &[[f64; K]]) + Sync) -> Self {
        let stride = grid.w + 1;
        let zeros = vec![[0.0; K]; stride];
        let mut table = vec![[0.0; K]; stride * grid.h];
        table
            .par_chunks_mut(stride * BAND_ROWS)
            .enumerate()
            .for_each(|(b, band)| {
                for r in 0..band.len() / stride {
                    let (above, rest) = band.split_at_mut(r * stride);
                    let above = if r == 0 {
                        &zeros[1..]
                    } else {
                        &above[(r - 1) * stride + 1..]
                    };
                    fill(b * BAND_ROWS + r, &mut rest[1..stride], above);
                }
            });
        let mut offsets = Vec::with_capacity(grid.h.div_ceil(BAND_ROWS));
        let mut above = vec![[0.0; K]; stride];
        for band in table.chunks(stride * BAND_ROWS) {
            offsets.push(above.clone());
            for (a, l) in above.iter_mut().zip(&band[band.len() - stride..]) {
                for k in 0..K {
                    a[k] += l[k];
                }
            }
        }
        MomentTable {
            stride,
            table,
            offsets,
        }
    }

    /// Sums over columns `< x` and rows `< y`.
    fn at(&self, x: usize, y: usize) -> [f64; K] {
        if y == 0 {
            return [0.0; K];
        }
        let (v, o) = (
            self.table[(y - 1) * self.stride + x],
            self.offsets[(y - 1) / BAND_ROWS][x],
        );
        std::array::from_fn(|k| v[k] + o[k])
    }

    /// Sums of every channel over columns `x0..x1`, rows `y0..y1` (bounds within the probe).
    pub fn sum(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> [f64; K] {
        let (a, b) = (self.at(x1, y1), self.at(x1, y0));
        let (c, d) = (self.at(x0, y1), self.at(x0, y0));
        std::array::from_fn(|k| (a[k] - b[k]) - (c[k] - d[k]))
    }

    /// Sums of every channel over a region.
    pub fn region(&self, r: &PixelRegion) -> [f64; K] {
        self.sum(r.x0, r.y0, r.x1, r.y1)
    }
}

/// One step of a summed-area row: adds `v` to the running row sum `acc` and returns it plus
/// `up`, the entry above.
#[inline(always)]
fn running<const K: usize>(acc: &mut [f64; K], v: [f64; K], up: &[f64; K]) -> [f64; K] {
    std::array::from_fn(|k| {
        acc[k] += v[k];
        acc[k] + up[k]
    })
}

/// Energy `E = Y dOmega` alone (median cut's cuts).
pub(crate) type EnergyTable = MomentTable<1>;

/// Energy and its direction moments `E, E d_x, E d_y, E d_z` (adaptive median cut, variance
/// minimisation).
pub(crate) type DirectionTable = MomentTable<4>;

/// The energy table of a probe. Cost O(W H).
pub(crate) fn energy_table(probe: &Image<Rgb>, grid: &Grid) -> EnergyTable {
    MomentTable::build(grid, |j, row, above| {
        let o = grid.row_sr[j];
        let mut acc = [0.0];
        let cells = row.iter_mut().zip(above);
        each_pixel(probe.row(j), grid.clean[j], cells, |(v, up), _, y| {
            *v = running(&mut acc, [y * o], up);
        });
    })
}

/// The energy and direction-moment table of a probe. Cost O(W H).
pub(crate) fn direction_table(probe: &Image<Rgb>, grid: &Grid) -> DirectionTable {
    MomentTable::build(grid, |j, row, above| {
        let o = grid.row_sr[j];
        let (st, ct) = grid.row_trig[j];
        let (a, b) = (o * st, o * ct);
        let mut acc = [0.0; 4];
        let cells = row.iter_mut().zip(above).zip(&grid.col_trig);
        each_pixel(
            probe.row(j),
            grid.clean[j],
            cells,
            |((v, up), &(sp, cp)), _, y| {
                *v = running(&mut acc, [y * o, y * a * sp, y * b, -(y * a * cp)], up);
            },
        );
    })
}

/// Power `P` and direction moment `S` of a region's entry in a [`DirectionTable`] sum, with
/// rounding noise of the table differences clamped (`P >= 0`).
pub(crate) fn power_and_moment(s: [f64; 4]) -> (f64, DVec3) {
    (s[0].max(0.0), DVec3::new(s[1], s[2], s[3]))
}

/// The irradiance-error bound `P - |S|` of a region (see the module doc), >= 0.
pub(crate) fn error_bound(s: [f64; 4]) -> f64 {
    let (p, m) = power_and_moment(s);
    (p - m.length()).max(0.0)
}

/// The spatial variance on the sphere `P - |S|^2 / P` of a region (see the module doc), >= 0;
/// 0 for a black region.
pub(crate) fn sphere_variance(s: [f64; 4]) -> f64 {
    let (p, m) = power_and_moment(s);
    if p > 0.0 {
        (p - m.length_squared() / p).max(0.0)
    } else {
        0.0
    }
}

/// Median cut's cut of a region (Debevec 2005): across its longest angular dimension
/// (`width_px * 2 pi / W * sin(theta_centre)` against `height_px * pi / H`) at the energy
/// median; `energy(x0, y0, x1, y1)` is a rectangle's energy. `None` for a single pixel. Cost
/// O(log W + log H) energy look-ups.
pub(crate) fn median_cut_split(
    r: &PixelRegion,
    grid: &Grid,
    energy: impl Fn(usize, usize, usize, usize) -> f64,
) -> Option<(PixelRegion, PixelRegion)> {
    let theta_centre = std::f64::consts::PI * (r.y0 + r.y1) as f64 / (2.0 * grid.h as f64);
    let angular_width =
        r.width() as f64 * std::f64::consts::TAU / grid.w as f64 * theta_centre.sin();
    let angular_height = r.height() as f64 * std::f64::consts::PI / grid.h as f64;
    let cut_columns = if r.width() > 1 && r.height() > 1 {
        angular_width >= angular_height
    } else {
        r.width() > 1
    };
    if cut_columns {
        let c = median(r.x0, r.x1, |c| energy(r.x0, r.y0, c, r.y1));
        Some((PixelRegion { x1: c, ..*r }, PixelRegion { x0: c, ..*r }))
    } else if r.height() > 1 {
        let c = median(r.y0, r.y1, |c| energy(r.x0, r.y0, r.x1, c));
        Some((PixelRegion { y1: c, ..*r }, PixelRegion { y0: c, ..*r }))
    } else {
        None
    }
}

/// The cut `c` in `lo+1..hi` whose prefix energy `prefix(c)` is closest to half the total
/// (`prefix` is non-decreasing up to rounding); the middle when the range holds no energy.
/// Binary search.
fn median(lo: usize, hi: usize, prefix: impl Fn(usize) -> f64) -> usize {
    let half = prefix(hi) / 2.0;
    if half.is_nan() || half <= 0.0 {
        return lo + (hi - lo) / 2;
    }
    // Smallest c in lo+1..=hi-1 with prefix(c) >= half, else hi-1.
    let (mut a, mut b) = (lo + 1, hi - 1);
    while a < b {
        let m = a + (b - a) / 2;
        if prefix(m) >= half { b = m } else { a = m + 1 }
    }
    if a > lo + 1 && (half - prefix(a - 1)) < (prefix(a) - half) {
        a - 1
    } else {
        a
    }
}

/// How a region would be split, and how urgent that split is.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SplitPlan {
    /// Larger splits first; must not be NaN.
    pub priority: f64,
    /// The two halves.
    pub halves: (PixelRegion, PixelRegion),
}

/// A region waiting in the best-first queue.
#[derive(Debug)]
struct Pending {
    plan: SplitPlan,
    region: PixelRegion,
    /// Creation order, for deterministic ties (earlier first).
    order: usize,
}

impl Pending {
    fn key(&self) -> (f64, usize, std::cmp::Reverse<usize>) {
        let area = self.region.width() * self.region.height();
        (self.plan.priority, area, std::cmp::Reverse(self.order))
    }
}

impl PartialEq for Pending {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}

impl Eq for Pending {}

impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Pending {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        let (a, b) = (self.key(), other.key());
        a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2))
    }
}

/// Splits the whole probe best-first into exactly `n` regions: `plan(r)` says how region `r`
/// would be cut and with what priority (`None`: it cannot be cut, a single pixel); the pending
/// region of highest priority is cut next (ties: the larger region, then the older). Needs
/// `1 <= n <= W H`, which guarantees n regions. Returns the regions sorted by (row, column) of
/// their top-left pixel. Cost O(n log n) plus n calls of `plan`.
pub(crate) fn split_best_first(
    grid: &Grid,
    n: usize,
    plan: impl Fn(&PixelRegion) -> Option<SplitPlan>,
) -> Vec<PixelRegion> {
    let mut done = Vec::with_capacity(n);
    let mut queue = BinaryHeap::with_capacity(n);
    let mut order = 0usize;
    let mut add = |r: PixelRegion, done: &mut Vec<PixelRegion>, queue: &mut BinaryHeap<_>| {
        match plan(&r) {
            Some(plan) => queue.push(Pending {
                plan,
                region: r,
                order,
            }),
            None => done.push(r),
        }
        order += 1;
    };
    add(grid.full(), &mut done, &mut queue);
    while done.len() + queue.len() < n {
        let Some(top) = queue.pop() else { break };
        let (a, b) = top.plan.halves;
        add(a, &mut done, &mut queue);
        add(b, &mut done, &mut queue);
    }
    done.extend(queue.into_iter().map(|p| p.region));
    done.sort_by_key(|r| (r.y0, r.x0));
    done
}

/// The light standing for each region (see the module doc), in parallel over regions. With a
/// [`DirectionTable`] the region's moment `S` (its light's direction) comes from the table (to
/// rounding of about 1e-16 of the probe's energy, 12 % fewer instructions for adaptive median
/// cut) and only the power is summed per pixel; without, both are.
pub(crate) fn region_lights(
    probe: &Image<Rgb>,
    grid: &Grid,
    regions: &[PixelRegion],
    moments: Option<&DirectionTable>,
) -> Vec<Light> {
    regions
        .par_iter()
        .map(|r| match moments {
            Some(t) => region_light::<false>(probe, grid, *r, power_and_moment(t.region(r)).1),
            None => region_light::<true>(probe, grid, *r, DVec3::ZERO),
        })
        .collect()
}

/// Regions of more pixels than this sum their rows in parallel.
const PARALLEL_AREA: usize = 16_384;

/// The light standing for one region: its power, solid angle and energy centroid, the moment
/// summed per pixel when `SUM_MOMENT`, else `moment`. Cost O(area); the per-row sums of a large
/// region are computed in parallel and added in row order either way.
fn region_light<const SUM_MOMENT: bool>(
    probe: &Image<Rgb>,
    grid: &Grid,
    r: PixelRegion,
    mut moment: DVec3,
) -> Light {
    let row_sums = |j: usize| {
        let mut s = [0.0f64; 6];
        let trig = &grid.col_trig[r.x0..r.x1];
        let row = &probe.row(j)[r.x0..r.x1];
        each_pixel(row, grid.clean[j], trig, |&(sp, cp), l, y| {
            s[0] += l[0];
            s[1] += l[1];
            s[2] += l[2];
            if SUM_MOMENT {
                s[3] += y * sp;
                s[4] += y;
                s[5] += y * cp;
            }
        });
        s
    };
    let rows: Vec<[f64; 6]> = if r.width() * r.height() > PARALLEL_AREA {
        (r.y0..r.y1).into_par_iter().map(row_sums).collect()
    } else {
        (r.y0..r.y1).map(row_sums).collect()
    };
    let mut power = [0.0f64; 3];
    for (j, s) in (r.y0..r.y1).zip(rows) {
        let o = grid.row_sr[j];
        for (pc, rc) in power.iter_mut().zip(&s[..3]) {
            *pc += rc * o;
        }
        if SUM_MOMENT {
            let (st, ct) = grid.row_trig[j];
            moment += o * DVec3::new(st * s[3], ct * s[4], -st * s[5]);
        }
    }
    if power == [0.0; 3] {
        // Black: the table's moment is rounding noise, if anything.
        moment = DVec3::ZERO;
    }
    let (solid_angle, geometric) = grid.geometry(&r);
    let dir = moment
        .try_normalize()
        .or_else(|| geometric.try_normalize())
        .unwrap_or(DVec3::Y);
    let histogram = region_spread(probe, grid, &r, dir);
    let mut l = light(dir, power, solid_angle, histogram.spread_sr(), Some(r));
    l.core_fraction = core_fraction(&histogram, &l, WIDEST_CORE_IN_A_REGION);
    l
}

/// A light's [`Light::core_fraction`] from the histogram of its pixels, a halo only for cores
/// of at most `widest_core` of its source ([`SpreadHistogram::core_fraction`]): `None` where it
/// has no spread.
pub(crate) fn core_fraction(
    histogram: &SpreadHistogram,
    light: &Light,
    widest_core: f64,
) -> Option<f64> {
    let core_sr = light.shadow_solid_angle_sr();
    light
        .spread_sr
        .map(|_| histogram.core_fraction(core_sr, light.solid_angle_sr, widest_core))
}

/// Rows per chunk of [`region_spread`]'s parallel histograms.
const SPREAD_ROWS: usize = 16;

/// The histogram of region `r`'s power about `dir` (unit) that gives its spread and core
/// ([`ibl_light::spread`]): a second pass over its pixels. A large region's rows are histogrammed in
/// chunks of [`SPREAD_ROWS`] in parallel and merged in row order, so the result does not depend
/// on the thread count. Cost O(area).
fn region_spread(probe: &Image<Rgb>, grid: &Grid, r: &PixelRegion, dir: DVec3) -> SpreadHistogram {
    // Per row: the keys and luminances first (a loop the compiler can vectorise), then the
    // histogram's runs.
    let add_row = |h: &mut SpreadHistogram, keys: &mut Vec<(f64, f64)>, j: usize| {
        let o = grid.row_sr[j];
        let (st, ct) = grid.row_trig[j];
        // d_p . w with d_p = (st sp, ct, -st cp).
        let (a, b, c) = (st * dir.x, ct * dir.y, st * dir.z);
        let trig = &grid.col_trig[r.x0..r.x1];
        let row = &probe.row(j)[r.x0..r.x1];
        keys.clear();
        each_pixel(row, grid.clean[j], trig, |&(sp, cp), _, y| {
            keys.push((1.0 - (a * sp + b - c * cp), y));
        });
        h.add_pixels(keys, o);
    };
    let histogram_of = |rows: std::ops::Range<usize>| {
        let mut h = SpreadHistogram::new();
        let mut keys = Vec::with_capacity(r.width());
        for j in rows {
            add_row(&mut h, &mut keys, j);
        }
        h
    };
    if r.width() * r.height() > PARALLEL_AREA {
        let starts: Vec<usize> = (r.y0..r.y1).step_by(SPREAD_ROWS).collect();
        let parts: Vec<SpreadHistogram> = starts
            .into_par_iter()
            .map(|y0| histogram_of(y0..(y0 + SPREAD_ROWS).min(r.y1)))
            .collect();
        parts.iter().fold(SpreadHistogram::new(), |mut all, h| {
            all.merge(h);
            all
        })
    } else {
        histogram_of(r.y0..r.y1)
    }
}

/// A light from its direction (unit), power per channel (probe unit x sr), solid angle (sr) and
/// spread (sr, [`Light::spread_sr`]).
pub(crate) fn light(
    dir: DVec3,
    power: [f64; 3],
    solid_angle: f64,
    spread: Option<f64>,
    region: Option<PixelRegion>,
) -> Light {
    let radiance = if solid_angle > 0.0 {
        Rgb::new(
            (power[0] / solid_angle) as f32,
            (power[1] / solid_angle) as f32,
            (power[2] / solid_angle) as f32,
        )
    } else {
        Rgb::ZERO
    };
    Light {
        direction: dir,
        radiance,
        solid_angle_sr: solid_angle,
        irradiance: Rgb64::from_array(power),
        region,
        spread_sr: spread,
        core_fraction: None,
        side: None,
    }
}
