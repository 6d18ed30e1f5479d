//! Variance minimisation (Viriyothai & Debevec 2009, "Variance minimization light probe
//! sampling", SIGGRAPH 2009 poster): median cut whose cuts minimise the spatial spread of the
//! energy in the two halves instead of halving the energy, so that a cut passes between bright
//! sources rather than through one.
//!
//! # Variance
//! The variance of a region is the energy-weighted squared distance of its pixels to their
//! energy centroid, measured in 3-D on the unit sphere (world frame):
//!
//! ```text
//! V = sum_p E_p |d_p - m|^2 = P - |S|^2 / P,   P = sum E_p,  S = sum E_p d_p,  m = S / P
//! ```
//!
//! with `E_p` = luminance x exact solid angle (CONVENTIONS section 4) and `d_p` the pixel's unit
//! direction. For a small region this is the squared angular distance of the poster's lat-long
//! form with the azimuth scaled by `sin(theta)`, but it has no distortion near the poles and
//! needs only the tables `E, E d_x, E d_y, E d_z` (shared with adaptive median cut), so every
//! candidate cut costs O(1).
//!
//! # Algorithm
//! 1. The whole lat-long probe is one region.
//! 2. Each region's cut is the one, over every column boundary and every row boundary, of least
//!    `V(left) + V(right)`; a black region is cut like median cut (the middle of its longest
//!    angular dimension).
//! 3. While there are fewer than N regions, cut the region of largest V (ties: the larger region,
//!    then the older). A single pixel cannot be cut; with N <= W H there is always another region,
//!    so the result has exactly N lights.
//! 4. Each region becomes one light as in median cut: the region's power per channel `I = sum L
//!    dOmega`, solid angle `A`, `L = I / A`, direction of the energy centroid. The lights' power
//!    equals the probe's to f64 rounding.
//!
//! The poster splits every region in each of K rounds (2^K lights) and minimises the larger of
//! the two halves' variances. Splitting one region at a time gives any N; against the poster's
//! rule the sum measured the same overall (mean over the five bundled probes, mean% / max%, the
//! CONVENTIONS section 5 metrics on 20000 Fibonacci normals):
//!
//! | N | least sum (chosen) | least maximum (poster) |
//! |---|---|---|
//! | 8 | 5.83 / 23.1 | 5.68 / 20.5 |
//! | 16 | 2.31 / 9.82 | 2.79 / 9.72 |
//! | 32 | 0.926 / 4.44 | 1.10 / 4.58 |
//! | 64 | 0.459 / 2.41 | 0.414 / 1.79 |
//! | 128 | 0.200 / 1.13 | 0.213 / 1.27 |
//! | 256 | 0.092 / 0.565 | 0.089 / 0.531 |
//!
//! Cutting next the region whose cut lowers the total variance the most instead of the one of
//! largest variance gave 2.35 / 10.1 % at N = 16 and 0.445 / 2.54 % at N = 64.
//!
//! # Cost
//! O(W H) for the tables (parallel over bands of rows) and the final per-region sums (parallel
//! over regions), O(N (W + H)) table look-ups for the cuts and O(N log N) for the queue: a few
//! milliseconds for a 512 x 256 probe and N = 256 on 2 cores (`benches/extract.rs`).

use ibl_core::{Image, Rgb};
use ibl_light::{Extraction, LightSet, PixelRegion, Provenance};

use crate::ExtractError;
use crate::region_stats::{
    DirectionTable, Grid, SplitPlan, direction_table, median_cut_split, region_lights,
    sphere_variance, split_best_first,
};

/// Variance minimisation of a lat-long probe into exactly `n` lights (`1 <= n <= W H`).
pub fn variance_minimization(probe: &Image<Rgb>, n: usize) -> Result<LightSet, ExtractError> {
    let grid = Grid::new(probe)?;
    if n == 0 || n > grid.pixels() {
        return Err(ExtractError::Parameter(format!(
            "variance minimisation makes 1 to {} lights for a {} x {} probe (one per pixel at most); got {n}",
            grid.pixels(),
            grid.w,
            grid.h
        )));
    }
    let table = direction_table(probe, &grid);
    let regions = split_best_first(&grid, n, |r| plan(r, &grid, &table));
    Ok(LightSet {
        provenance: Provenance::extracted(Extraction::VarianceMinimization),
        lights: region_lights(probe, &grid, &regions, Some(&table)),
    })
}

/// The cut of least combined variance of a region (over every column and row boundary), with
/// its priority; `None` for a single pixel. A black region is cut like median cut (down the
/// middle of its longest dimension). Cost O(W + H) table look-ups.
fn plan(r: &PixelRegion, grid: &Grid, table: &DirectionTable) -> Option<SplitPlan> {
    let whole = table.region(r);
    let mut best: Option<(f64, (PixelRegion, PixelRegion))> = None;
    if whole[0] > 0.0 {
        let mut consider = |a: PixelRegion, b: PixelRegion| {
            let first = table.region(&a);
            let second: [f64; 4] = std::array::from_fn(|k| whole[k] - first[k]);
            let cost = sphere_variance(first) + sphere_variance(second);
            if best.is_none_or(|(c, _)| cost < c) {
                best = Some((cost, (a, b)));
            }
        };
        for c in r.x0 + 1..r.x1 {
            consider(PixelRegion { x1: c, ..*r }, PixelRegion { x0: c, ..*r });
        }
        for c in r.y0 + 1..r.y1 {
            consider(PixelRegion { y1: c, ..*r }, PixelRegion { y0: c, ..*r });
        }
    }
    let halves = match best {
        Some((_, halves)) => halves,
        None => median_cut_split(r, grid, |_, _, _, _| 0.0)?,
    };
    Some(SplitPlan {
        priority: sphere_variance(whole),
        halves,
    })
}
