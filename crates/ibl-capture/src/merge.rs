//! Merging a bracket of exposures into one HDR image of relative radiance (Debevec & Malik 1997,
//! section 2.2, equation 6), per pixel and channel:
//!
//! ```text
//! ln E = sum_j w_j (g(Z_j) - ln dt_j) / sum_j w_j        (8-bit codes, `merge`)
//!    E = sum_j w_j (X_j / dt_j)       / sum_j w_j        (linear values, `merge_linear`)
//! ```
//!
//! where `g` is the camera's [`ResponseCurve`], `Z_j` the code and `dt_j` the exposure time (s) of
//! exposure j. The result is linear radiance in the curve's relative unit (an unknown global scale
//! from a photometric calibration is left to the caller). Linear inputs are averaged in the linear
//! domain: the maximum-likelihood estimate for photon (Poisson) noise, and it keeps values near
//! zero unbiased.
//!
//! **Weights.** With `b` = [`MergeOptions::black_level`] and `s` =
//! [`MergeOptions::saturation_level`], a code is *black* when `Z <= b` and *saturated* when
//! `Z >= s`; both get weight 0. Between them:
//! - [`Weighting::Hat`]: `w = hat(Z) = min(Z - b, s - Z) / ((s - b) / 2)` (the paper's triangle);
//! - [`Weighting::NoiseAware`]: `w = hat(Z) dt_j / max_k dt_k`. For a shot-noise-limited sensor
//!   the variance of the radiance estimate `X_j / dt_j` (and of its logarithm) of one pixel falls
//!   as `1 / dt_j`, so weights proportional to `dt_j` are inverse-variance weights (Granados et
//!   al., "Optimal HDR reconstruction with linear digital cameras", CVPR 2010, with the read noise
//!   neglected); the hat keeps the weights falling to zero towards black and saturation.
//!
//! Optional per-image, per-pixel weights in [0, 1] (e.g. ghost suppression) multiply `w`; where
//! they remove every usable exposure of a pixel they are ignored for that pixel.
//! Linear inputs (`X` in [0, 1], 1 = the sensor's clip point) use the same rules on the
//! code-equivalent `255 X`, i.e. `b / 255` and `s / 255` of full scale.
//!
//! **No usable exposure.** A pixel channel with every code outside `(b, s)` takes the shortest
//! exposure's value when that one is saturated (a lower bound on the radiance; counted in
//! [`MergeResult::saturated_pixels`]), otherwise the longest exposure's value (an upper bound;
//! counted in [`MergeResult::black_pixels`]). If no pixel channel has a usable exposure the merge
//! fails. A single exposure is accepted (it gives `g(Z) - ln dt`, or `X / dt`).
//!
//! Cost: `O(W H P)` for P exposures, rows in parallel (rayon), the exposures accumulated one after
//! the other within a row; per exposure a 256-entry table of `g(z) - ln dt` and of weights makes
//! the 8-bit path two look-ups per value. Every pixel is summed in the same order whatever the
//! thread count, so the result does not depend on it.

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::CaptureError;
use crate::response::{LEVELS_8BIT, ResponseCurve, check_bracket};

/// How each exposure's value is weighted (see the module notes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Weighting {
    /// Debevec & Malik's triangle over the codes between black and saturation.
    #[default]
    Hat,
    /// The triangle times the exposure time: inverse-variance weights for photon noise.
    NoiseAware,
}

/// Parameters of [`merge`] and [`merge_linear`].
#[derive(Clone, Debug, PartialEq)]
pub struct MergeOptions {
    /// Weight function.
    pub weighting: Weighting,
    /// Codes at or below this are black (no information); default 2.
    pub black_level: u8,
    /// Codes at or above this are saturated (no information); default 250.
    pub saturation_level: u8,
    /// Extra weights in [0, 1], one image per exposure of the bracket's size (e.g. ghost
    /// suppression), multiplying the weights above.
    pub pixel_weights: Option<Vec<Image<f32>>>,
}

impl Default for MergeOptions {
    fn default() -> Self {
        MergeOptions {
            weighting: Weighting::Hat,
            black_level: 2,
            saturation_level: 250,
            pixel_weights: None,
        }
    }
}

/// A merged HDR image and how many pixels had no usable exposure.
#[derive(Clone, Debug, PartialEq)]
pub struct MergeResult {
    /// Linear radiance, relative units (the response curve's), row 0 at the top.
    pub image: Image<Rgb>,
    /// Pixels with at least one channel saturated in every exposure (their value is a lower bound,
    /// taken from the shortest exposure).
    pub saturated_pixels: usize,
    /// Pixels with at least one channel black in every exposure (their value is an upper bound,
    /// taken from the longest exposure).
    pub black_pixels: usize,
}

/// Per-row tallies: (saturated pixels, black pixels, usable pixel channels).
type Tally = (usize, usize, usize);

/// Merges 8-bit exposures of one scene (aligned, times in seconds) through the camera response
/// `curve` into relative linear radiance (module notes).
///
/// Errors: `Invalid` for no images, a time missing or not finite and positive, sizes that differ,
/// a curve without 256 codes, or no usable exposure anywhere (every pixel saturated or black in
/// every exposure); `Parameter` for `black_level + 1 >= saturation_level` or pixel weights of the
/// wrong count, size or range.
pub fn merge(
    images: &[Image<[u8; 3]>],
    exposure_times_s: &[f64],
    curve: &ResponseCurve,
    options: &MergeOptions,
) -> Result<MergeResult, CaptureError> {
    let (width, height) = check_bracket(images, exposure_times_s)?;
    if curve.levels() != LEVELS_8BIT {
        return Err(CaptureError::Invalid(format!(
            "the response curve has {} codes but 8-bit exposures need {LEVELS_8BIT}",
            curve.levels()
        )));
    }
    let plan = Plan::new(images.len(), width, height, exposure_times_s, options)?;

    // Per exposure: weight of each code, and g(z) - ln dt per channel and code.
    let g = curve.log_exposure();
    let weights: Vec<[f32; LEVELS_8BIT]> = (0..images.len())
        .map(|j| std::array::from_fn(|z| plan.weight(z as f32, j)))
        .collect();
    let log_radiance: Vec<[[f32; LEVELS_8BIT]; 3]> = exposure_times_s
        .iter()
        .map(|t| {
            let ln_t = t.ln() as f32;
            std::array::from_fn(|c| std::array::from_fn(|z| g[c][z] - ln_t))
        })
        .collect();
    let saturation = options.saturation_level;
    let sample = |j: usize, p: [u8; 3]| -> [[f32; 3]; 2] {
        let z = p.map(usize::from);
        [
            std::array::from_fn(|c| weights[j][z[c]]),
            std::array::from_fn(|c| log_radiance[j][c][z[c]]),
        ]
    };
    merge_rows(
        images,
        &plan,
        sample,
        |p: [u8; 3], c| p[c] >= saturation,
        f32::exp,
    )
}

/// Merges linear exposures (RAW-like values already decoded: 0 = black, 1 = the sensor's clip
/// point; times in seconds) into linear radiance `E = sum w X / dt / sum w` (module notes); the
/// black and saturation levels apply as fractions `level / 255` of full scale.
///
/// Errors: as [`merge`] (without the curve), plus `Invalid` for a value that is not finite.
pub fn merge_linear(
    images: &[Image<Rgb>],
    exposure_times_s: &[f64],
    options: &MergeOptions,
) -> Result<MergeResult, CaptureError> {
    let (width, height) = check_bracket(images, exposure_times_s)?;
    let plan = Plan::new(images.len(), width, height, exposure_times_s, options)?;
    for (k, image) in images.iter().enumerate() {
        if let Some(p) = image
            .pixels()
            .iter()
            .position(|v| !(v.r.is_finite() && v.g.is_finite() && v.b.is_finite()))
        {
            return Err(CaptureError::Invalid(format!(
                "exposure {k} has a value that is not finite at pixel ({}, {})",
                p % width,
                p / width
            )));
        }
    }
    let saturation = f32::from(options.saturation_level) / 255.0;
    let inv_dt: Vec<f32> = exposure_times_s.iter().map(|t| (1.0 / t) as f32).collect();
    let sample = |j: usize, p: Rgb| -> [[f32; 3]; 2] {
        let v = p.to_array();
        [
            v.map(|v| plan.weight(v * 255.0, j)),
            v.map(|v| v * inv_dt[j]),
        ]
    };
    merge_rows(
        images,
        &plan,
        sample,
        |p: Rgb, c| p.to_array()[c] >= saturation,
        |e: f32| e.max(0.0),
    )
}

/// The merge loop shared by both paths: `sample(j, pixel)` gives the weights and the per-exposure
/// estimates (log or linear radiance) of the three channels, `is_saturated(pixel, c)` tells a
/// saturated value, `to_radiance` turns the weighted mean of estimates into radiance. Rows run in
/// parallel; within a row the exposures are accumulated one after the other.
fn merge_rows<P: Copy + Sync>(
    images: &[Image<P>],
    plan: &Plan,
    sample: impl Fn(usize, P) -> [[f32; 3]; 2] + Sync,
    is_saturated: impl Fn(P, usize) -> bool + Sync,
    to_radiance: impl Fn(f32) -> f32 + Sync,
) -> Result<MergeResult, CaptureError> {
    let (width, height) = (images[0].width(), images[0].height());
    let mut out = Image::filled(width, height, Rgb::ZERO);
    let tally = out
        .pixels_mut()
        .par_chunks_mut(width)
        .enumerate()
        .map_init(Vec::new, |sums: &mut Vec<[[f32; 3]; 2]>, (y, row)| {
            let rows: Vec<&[P]> = images.iter().map(|im| im.row(y)).collect();
            let pixel_weight_rows = plan.pixel_weight_rows(y);
            // sums[x] = [sum of w, sum of w * estimate] per channel.
            sums.clear();
            sums.resize(width, [[0.0; 3]; 2]);
            for (j, r) in rows.iter().enumerate() {
                let accumulate = |acc: &mut [[f32; 3]; 2], w: [f32; 3], e: [f32; 3]| {
                    for c in 0..3 {
                        acc[0][c] += w[c];
                        acc[1][c] += w[c] * e[c];
                    }
                };
                match pixel_weight_rows.as_ref().map(|p| p[j]) {
                    Some(pw) => {
                        for ((acc, &p), &k) in sums.iter_mut().zip(r.iter()).zip(pw) {
                            let [w, e] = sample(j, p);
                            accumulate(acc, w.map(|w| w * k), e);
                        }
                    }
                    None => {
                        for (acc, &p) in sums.iter_mut().zip(r.iter()) {
                            let [w, e] = sample(j, p);
                            accumulate(acc, w, e);
                        }
                    }
                }
            }
            let mut tally: Tally = (0, 0, 0);
            for (x, (value, acc)) in row.iter_mut().zip(sums.iter()).enumerate() {
                let mut radiance = [0.0f32; 3];
                let (mut saturated, mut black) = (false, false);
                for (c, out_c) in radiance.iter_mut().enumerate() {
                    let (mut sw, mut s) = (acc[0][c], acc[1][c]);
                    if sw <= 0.0 && pixel_weight_rows.is_some() {
                        // The pixel weights removed every usable exposure: ignore them here.
                        (sw, s) = (0.0, 0.0);
                        for (j, r) in rows.iter().enumerate() {
                            let [w, e] = sample(j, r[x]);
                            sw += w[c];
                            s += w[c] * e[c];
                        }
                    }
                    *out_c = if sw > 0.0 {
                        tally.2 += 1;
                        to_radiance(s / sw)
                    } else if is_saturated(rows[plan.shortest][x], c) {
                        saturated = true;
                        to_radiance(sample(plan.shortest, rows[plan.shortest][x])[1][c])
                    } else {
                        black = true;
                        to_radiance(sample(plan.longest, rows[plan.longest][x])[1][c])
                    };
                }
                *value = Rgb::from_array(radiance);
                tally.0 += usize::from(saturated);
                tally.1 += usize::from(black);
            }
            tally
        })
        .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    plan.finish(out, tally)
}

/// What both merges share: validated options, the exposures' order and the weight function.
struct Plan<'a> {
    shortest: usize,
    longest: usize,
    black: f32,
    saturation: f32,
    /// Weight factor per exposure: 1, or `dt / max dt` for [`Weighting::NoiseAware`].
    time_factor: Vec<f32>,
    pixel_weights: Option<&'a [Image<f32>]>,
}

impl<'a> Plan<'a> {
    fn new(
        exposures: usize,
        width: usize,
        height: usize,
        exposure_times_s: &[f64],
        options: &'a MergeOptions,
    ) -> Result<Self, CaptureError> {
        let (black, saturation) = (options.black_level, options.saturation_level);
        if u16::from(black) + 1 >= u16::from(saturation) {
            return Err(CaptureError::Parameter(format!(
                "black level {black} and saturation level {saturation} leave no usable code \
                 between them"
            )));
        }
        if let Some(maps) = &options.pixel_weights {
            if maps.len() != exposures {
                return Err(CaptureError::Parameter(format!(
                    "{} pixel-weight images for {exposures} exposures",
                    maps.len()
                )));
            }
            for (k, map) in maps.iter().enumerate() {
                if map.width() != width || map.height() != height {
                    return Err(CaptureError::Parameter(format!(
                        "pixel-weight image {k} is {} x {} pixels, the exposures {width} x \
                         {height}",
                        map.width(),
                        map.height()
                    )));
                }
                if let Some(p) = map.pixels().iter().position(|w| !(0.0..=1.0).contains(w)) {
                    return Err(CaptureError::Parameter(format!(
                        "pixel weight {} of image {k} at ({}, {}) is outside [0, 1]",
                        map.pixels()[p],
                        p % width,
                        p / width
                    )));
                }
            }
        }
        let by_time = |a: &usize, b: &usize| exposure_times_s[*a].total_cmp(&exposure_times_s[*b]);
        let shortest = (0..exposures).min_by(by_time).unwrap_or(0);
        let longest = (0..exposures).max_by(by_time).unwrap_or(0);
        let max_time = exposure_times_s[longest];
        let time_factor = exposure_times_s
            .iter()
            .map(|t| match options.weighting {
                Weighting::Hat => 1.0,
                Weighting::NoiseAware => (t / max_time) as f32,
            })
            .collect();
        Ok(Plan {
            shortest,
            longest,
            black: f32::from(black),
            saturation: f32::from(saturation),
            time_factor,
            pixel_weights: options.pixel_weights.as_deref(),
        })
    }

    /// Weight of code (or code-equivalent) `z` in exposure `j`.
    fn weight(&self, z: f32, j: usize) -> f32 {
        if z <= self.black || z >= self.saturation {
            return 0.0;
        }
        let half = 0.5 * (self.saturation - self.black);
        (z - self.black).min(self.saturation - z) / half * self.time_factor[j]
    }

    /// Row `y` of every pixel-weight image, if any.
    fn pixel_weight_rows(&self, y: usize) -> Option<Vec<&'a [f32]>> {
        self.pixel_weights
            .map(|maps| maps.iter().map(|m| m.row(y)).collect())
    }

    /// Fails when no pixel channel had a usable exposure; otherwise the result.
    fn finish(&self, image: Image<Rgb>, tally: Tally) -> Result<MergeResult, CaptureError> {
        let (saturated_pixels, black_pixels, usable) = tally;
        if usable == 0 {
            let pixels = image.len();
            let why = if saturated_pixels == pixels {
                "every pixel is saturated in every exposure (shorter exposures are needed)"
            } else if black_pixels == pixels {
                "every pixel is black in every exposure (longer exposures are needed)"
            } else {
                "every pixel is saturated or black in every exposure"
            };
            return Err(CaptureError::Invalid(format!(
                "no usable exposure: {why} (black level {}, saturation level {})",
                self.black, self.saturation
            )));
        }
        Ok(MergeResult {
            image,
            saturated_pixels,
            black_pixels,
        })
    }
}
