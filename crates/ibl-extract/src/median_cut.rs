//! Median cut (Debevec 2005), as Madsen & Laursen 2006 section 4.2 describe it.
//!
//! 1. The whole lat-long probe is one region.
//! 2. Every region is cut in two across its longest dimension so that each half holds as nearly as
//!    possible half of the region's energy. Energy is luminance x exact pixel solid angle, so the
//!    over-sampled poles count for what they cover; the angular width of a region is measured at
//!    its latitude (`width_px * 2 pi / W * sin(theta_centre)`), its height is `height_px * pi / H`.
//! 3. After K rounds there are 2^K regions of (nearly) equal energy.
//! 4. Each region becomes one light carrying the region's total power per channel (`I = sum L
//!    dOmega`), with `A` the region's solid angle, `L = I / A`, and the direction of the region's
//!    energy centroid on the sphere (the normalised luminance x solid-angle weighted mean of its
//!    pixel directions; the solid-angle weighted mean where the region is black).
//!
//! Cuts fall between pixels, so "half" is met to within one row or column of the region. A region
//! of a single pixel cannot be cut and stays whole (this only happens when 2^K approaches the pixel
//! count). Negative, NaN and infinite radiance counts as 0.
//!
//! Cost: O(W H) for the energy summed-area table (one pass, parallel over bands of rows) and for
//! the final per-region sums (parallel over regions, or over rows within a large region), and
//! O(2^K (log W + log H)) for the cuts: under a millisecond for a 512 x 256 probe on 2 cores for
//! any K <= 8 (`benches/extract.rs`). The lights' power equals the probe's to f64 rounding. The
//! table, cut and light code is shared with adaptive median cut and variance minimisation
//! (`region_stats.rs`).

use ibl_core::{Image, Rgb};
use ibl_light::{Extraction, LightSet, MAX_MEDIAN_CUT_SPLITS, Provenance};

use crate::ExtractError;
use crate::region_stats::{Grid, energy_table, median_cut_split, region_lights};

/// Median cut of a lat-long probe into `2^splits` lights.
pub fn median_cut(probe: &Image<Rgb>, splits: u32) -> Result<LightSet, ExtractError> {
    let grid = Grid::new(probe)?;
    if splits > MAX_MEDIAN_CUT_SPLITS {
        return Err(ExtractError::Parameter(format!(
            "median cut with {splits} rounds would make 2^{splits} lights (at most {MAX_MEDIAN_CUT_SPLITS} rounds)"
        )));
    }
    let energy = energy_table(probe, &grid);
    let mut regions = vec![grid.full()];
    for _ in 0..splits {
        regions = regions
            .iter()
            .flat_map(|r| {
                match median_cut_split(r, &grid, |x0, y0, x1, y1| energy.sum(x0, y0, x1, y1)[0]) {
                    Some((a, b)) => vec![a, b],
                    None => vec![*r],
                }
            })
            .collect();
    }
    Ok(LightSet {
        provenance: Provenance::extracted(Extraction::MedianCut { splits }),
        lights: region_lights(probe, &grid, &regions, None),
    })
}
