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
//! count). Cost: O(W H) for the summed-area table and the final per-region sums, O(2^K log W) for
//! the cuts. The lights' power equals the probe's to f64 rounding.

use glam::DVec3;
use ibl_core::{Image, LatLong, Rgb, SummedAreaTable};

use crate::ExtractError;
use crate::light_set::{Light, LightSet, PixelRegion};

/// Largest number of rounds accepted (2^16 lights).
pub const MAX_SPLITS: u32 = 16;

/// Median cut of a lat-long probe into `2^splits` lights.
pub fn median_cut(probe: &Image<Rgb>, splits: u32) -> Result<LightSet, ExtractError> {
    let (w, h) = (probe.width(), probe.height());
    if w == 0 || h == 0 {
        return Err(ExtractError::Invalid("the probe has no pixels".into()));
    }
    if splits > MAX_SPLITS {
        return Err(ExtractError::Parameter(format!(
            "median cut with {splits} rounds would make 2^{splits} lights (at most {MAX_SPLITS} rounds)"
        )));
    }
    let ll = LatLong::new(w, h);
    let row_sr = ll.row_solid_angles();
    let energy = SummedAreaTable::new(w, h, |x, y| {
        f64::from(probe.get(x, y).luminance().max(0.0)) * row_sr[y]
    });
    let mut regions = vec![PixelRegion {
        x0: 0,
        y0: 0,
        x1: w,
        y1: h,
    }];
    for _ in 0..splits {
        regions = regions
            .iter()
            .flat_map(|r| split(r, &energy, w, h))
            .collect();
    }
    let lights = regions
        .iter()
        .map(|r| region_light(probe, &ll, &row_sr, *r))
        .collect();
    Ok(LightSet {
        method: "median-cut".into(),
        lights,
    })
}

/// Cuts a region in two across its longest angular dimension at the energy median; a
/// single-pixel region is returned unchanged.
fn split(r: &PixelRegion, energy: &SummedAreaTable, w: usize, h: usize) -> Vec<PixelRegion> {
    let theta_centre = std::f64::consts::PI * (r.y0 + r.y1) as f64 / (2.0 * h as f64);
    let angular_width = r.width() as f64 * std::f64::consts::TAU / w as f64 * theta_centre.sin();
    let angular_height = r.height() as f64 * std::f64::consts::PI / h as f64;
    let cut_columns = if r.width() > 1 && r.height() > 1 {
        angular_width >= angular_height
    } else {
        r.width() > 1
    };
    if cut_columns {
        let c = median(r.x0, r.x1, |c| energy.sum(r.x0, r.y0, c, r.y1));
        vec![PixelRegion { x1: c, ..*r }, PixelRegion { x0: c, ..*r }]
    } else if r.height() > 1 {
        let c = median(r.y0, r.y1, |c| energy.sum(r.x0, r.y0, r.x1, c));
        vec![PixelRegion { y1: c, ..*r }, PixelRegion { y0: c, ..*r }]
    } else {
        vec![*r]
    }
}

/// The cut `c` in `lo+1..hi` whose prefix energy `prefix(c)` is closest to half the total
/// (`prefix` is non-decreasing); the middle when the range holds no energy. Binary search.
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

/// The light standing for one region: its power, solid angle and energy centroid.
fn region_light(probe: &Image<Rgb>, ll: &LatLong, row_sr: &[f64], r: PixelRegion) -> Light {
    let mut power = [0.0f64; 3];
    let mut solid_angle = 0.0f64;
    let mut centroid = DVec3::ZERO;
    let mut geometric = DVec3::ZERO;
    for (y, &sr) in row_sr.iter().enumerate().take(r.y1).skip(r.y0) {
        for x in r.x0..r.x1 {
            let p = *probe.get(x, y);
            let d = ll.pixel_dir64(x, y);
            for (pc, v) in power.iter_mut().zip(p.to_array()) {
                *pc += f64::from(v) * sr;
            }
            solid_angle += sr;
            centroid += d * (f64::from(p.luminance().max(0.0)) * sr);
            geometric += d * sr;
        }
    }
    let dir = centroid
        .try_normalize()
        .or_else(|| geometric.try_normalize())
        .unwrap_or(DVec3::Y);
    let radiance = Rgb::new(
        (power[0] / solid_angle) as f32,
        (power[1] / solid_angle) as f32,
        (power[2] / solid_angle) as f32,
    );
    Light {
        direction: dir.to_array(),
        radiance,
        solid_angle_sr: solid_angle,
        irradiance: power,
        region: Some(r),
    }
}
