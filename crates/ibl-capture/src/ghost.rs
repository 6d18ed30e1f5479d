//! Ghost suppression for brackets of a scene with moving things: per exposure, a weight in
//! [0, 1] that is 1 where the exposure agrees with a reference exposure and 0 where it sees
//! something else. A merge multiplies these into its own per-pixel weights, so a person who walked
//! through one frame leaves no translucent copy in the HDR result. This is the reference-based
//! consistency test of Grosch 2006 ("Fast and Robust High Dynamic Range Image Generation with
//! Camera and Object Movement"), with the tolerance set by each code's quantisation step instead
//! of a fixed ratio.
//!
//! **Radiance.** Code `z` of channel `c` in an exposure of `t` seconds means relative radiance
//! `L = X_c(z) / t`, where `X_c(z) = exposure_of(c, z)` is the camera's *linear* relative exposure
//! for that code (the inverted response, not its logarithm). The test works in `ln L`.
//!
//! **Observations.** Each channel of each pixel is one of:
//! - *valid* (`dark_code < z < bright_code`): `ln L` with relative uncertainty
//!   `sigma(z) = sqrt((dX(z) / X(z))^2 + relative_noise^2)`, where `dX(z) = (X(z+1) - X(z-1)) / 2`
//!   is the quantisation step at that code (in `ln` units `dX / X` is one code's width);
//! - *saturated* (`z >= bright_code`): only a lower bound, `ln L >= ln(X(bright_code - 1) / t)`;
//! - *dark* (`z <= dark_code`): only an upper bound, `ln L <= ln(X(dark_code + 1) / t)`.
//!
//! Bounds carry the uncertainty of the code that defines them. Each observation is thus an
//! interval `[lo, hi]` in `ln L` (a point when valid).
//!
//! **Test.** The *reference* is the exposure with the most well-exposed pixels (every channel in
//! [`WELL_EXPOSED`]; ties go to the earlier one); its weights are all 1. For another exposure `i`
//! at a pixel, per channel, the gap between the intervals `d = max(0, lo_i - hi_r, lo_r - hi_i)`
//! is measured in combined sigmas `k = d / sqrt(sigma_i^2 + sigma_r^2)`; `k_max` is the largest
//! over the three channels and the raw weight is
//! `w = clamp((reject_sigmas - k_max) / (reject_sigmas - agree_sigmas), 0, 1)`: 1 while every
//! channel agrees within `agree_sigmas` (default 3), 0 beyond `reject_sigmas` (default 6), linear
//! between. Two clipped observations on the same side never disagree, so clipped areas keep
//! weight 1 (the merge's own weights already ignore clipped codes).
//!
//! **Smoothing.** The edge of a moving object is partly covered and may pass the test, so the raw
//! weights are eroded with a `(2 r + 1)^2` minimum filter (every rejected pixel rejects its
//! neighbourhood: the ghost region is dilated by `r`) and then averaged with a `(2 r + 1)^2` box,
//! which ramps the weights back to 1 over another `r` pixels (`r = smoothing_radius`, default 2:
//! 5 x 5 windows). Windows are clipped at the image border.
//!
//! Cost: O(N W H r) for N exposures of W x H pixels: one pass for the test through per-exposure
//! tables of the 3 x 256 code intervals, then the separable filters as whole-row slice
//! operations, `2 r + 1` per pixel and pass (vectorised); rows in parallel.

use std::ops::RangeInclusive;

use ibl_core::Image;
use rayon::prelude::*;

use crate::CaptureError;
use crate::response::check_bracket;

/// Codes that count as well exposed when choosing the reference (all three channels must lie in
/// this range: 10 % to 90 % of the code range).
pub const WELL_EXPOSED: RangeInclusive<u8> = 26..=229;

/// Thresholds of the consistency test and the smoothing of its result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GhostOptions {
    /// Codes at or below this are clipped dark (an upper bound on radiance). Default 4.
    pub dark_code: u8,
    /// Codes at or above this are saturated (a lower bound on radiance). Default 250. Must exceed
    /// `dark_code` by at least 2.
    pub bright_code: u8,
    /// Up to this many combined sigmas of disagreement the weight stays 1. Default 3.
    pub agree_sigmas: f32,
    /// From this many combined sigmas on the weight is 0; must exceed `agree_sigmas`. Default 6.
    pub reject_sigmas: f32,
    /// Relative noise added in quadrature to each code's quantisation step (sensor noise,
    /// compression, response error; 0.04 = 4 %). Default 0.04.
    pub relative_noise: f32,
    /// Radius `r` in pixels of the minimum and box filters (`(2 r + 1)^2` windows); 0 disables
    /// the smoothing. Default 2.
    pub smoothing_radius: usize,
}

impl Default for GhostOptions {
    fn default() -> Self {
        GhostOptions {
            dark_code: 4,
            bright_code: 250,
            agree_sigmas: 3.0,
            reject_sigmas: 6.0,
            relative_noise: 0.04,
            smoothing_radius: 2,
        }
    }
}

impl GhostOptions {
    fn validate(&self) -> Result<(), CaptureError> {
        if u16::from(self.dark_code) + 2 > u16::from(self.bright_code) {
            return Err(CaptureError::Parameter(format!(
                "ghost test: bright_code ({}) must exceed dark_code ({}) by at least 2",
                self.bright_code, self.dark_code
            )));
        }
        if !(self.agree_sigmas.is_finite()
            && self.reject_sigmas.is_finite()
            && self.agree_sigmas >= 0.0
            && self.reject_sigmas > self.agree_sigmas)
        {
            return Err(CaptureError::Parameter(format!(
                "ghost test: need 0 <= agree_sigmas ({}) < reject_sigmas ({}), both finite",
                self.agree_sigmas, self.reject_sigmas
            )));
        }
        if !(self.relative_noise.is_finite() && self.relative_noise >= 0.0) {
            return Err(CaptureError::Parameter(format!(
                "ghost test: relative_noise ({}) must be finite and >= 0",
                self.relative_noise
            )));
        }
        Ok(())
    }
}

/// Per-exposure ghost weights in [0, 1], one image per exposure in the order given; the
/// reference exposure's (see [`reference_exposure`]) are all 1.
///
/// `exposure_times_s` are the exposure times in seconds; `exposure_of(channel, code)` is the
/// camera's linear relative exposure for an 8-bit code of channel 0 (R), 1 (G) or 2 (B) (the
/// inverted response curve, e.g. `exp(g(z))` of Debevec & Malik). It is tabulated once.
///
/// Errors: [`CaptureError::Invalid`] if there are no images, they are empty or differ in size, the
/// number of times differs from the number of images or a time is not finite and positive;
/// [`CaptureError::Parameter`] if the options are out of range or `exposure_of` gives a value
/// that is not finite, negative, or not positive above `dark_code`.
pub fn ghost_weights(
    images: &[Image<[u8; 3]>],
    exposure_times_s: &[f32],
    exposure_of: &dyn Fn(usize, u8) -> f32,
    options: &GhostOptions,
) -> Result<Vec<Image<f32>>, CaptureError> {
    options.validate()?;
    check_bracket(images, exposure_times_s)?;
    let observe = Observer::new(exposure_of, options)?;
    let reference = reference_exposure(images)?;
    let (w, h) = (images[0].width(), images[0].height());
    let reference_pixels = images[reference].pixels();
    let reference_table = observe.table(exposure_times_s[reference]);
    let ramp = options.reject_sigmas - options.agree_sigmas;
    Ok(images
        .iter()
        .zip(exposure_times_s)
        .enumerate()
        .map(|(i, (image, &t))| {
            if i == reference {
                return Image::filled(w, h, 1.0);
            }
            let table = observe.table(t);
            let mut weights = Image::filled(w, h, 0.0f32);
            weights
                .pixels_mut()
                .par_chunks_mut(w.max(1))
                .zip(image.pixels().par_chunks(w.max(1)))
                .zip(reference_pixels.par_chunks(w.max(1)))
                .for_each(|((out, mine), theirs)| {
                    for ((weight, a), b) in out.iter_mut().zip(mine).zip(theirs) {
                        let k_max = (0..3)
                            .map(|c| {
                                let ia = &table[c][usize::from(a[c])];
                                let ib = &reference_table[c][usize::from(b[c])];
                                ia.gap_sigmas(ib)
                            })
                            .fold(0.0f32, f32::max);
                        *weight = ((options.reject_sigmas - k_max) / ramp).clamp(0.0, 1.0);
                    }
                });
            smooth(&mut weights, options.smoothing_radius);
            weights
        })
        .collect())
}

/// Index of the exposure with the most well-exposed pixels (every channel in [`WELL_EXPOSED`]);
/// ties go to the earlier exposure. This is the reference of [`ghost_weights`].
///
/// Errors: [`CaptureError::Invalid`] if there are no images.
pub fn reference_exposure(images: &[Image<[u8; 3]>]) -> Result<usize, CaptureError> {
    if images.is_empty() {
        return Err(CaptureError::Invalid(
            "ghost test: no exposures given".into(),
        ));
    }
    let counts: Vec<usize> = images
        .par_iter()
        .map(|image| {
            image
                .pixels()
                .iter()
                .filter(|p| p.iter().all(|z| WELL_EXPOSED.contains(z)))
                .count()
        })
        .collect();
    let mut best = 0;
    for (i, &count) in counts.iter().enumerate() {
        if count > counts[best] {
            best = i;
        }
    }
    Ok(best)
}

/// What one channel code says about `ln L`: `lo <= ln L <= hi` (equal when the code is valid),
/// with variance `sigma2` in `ln` units squared.
#[derive(Clone, Copy, Debug, Default)]
struct Interval {
    lo: f32,
    hi: f32,
    sigma2: f32,
}

impl Interval {
    /// Gap between two intervals in combined sigmas (0 when they overlap).
    fn gap_sigmas(&self, other: &Interval) -> f32 {
        let gap = (self.lo - other.hi).max(other.lo - self.hi);
        if gap <= 0.0 {
            return 0.0;
        }
        gap / (self.sigma2 + other.sigma2).sqrt()
    }
}

/// The tabulated response: per channel and code, `ln X(z)` and `sigma(z)` (see the module notes).
struct Observer {
    ln_exposure: [[f32; 256]; 3],
    sigma: [[f32; 256]; 3],
    dark_code: u8,
    bright_code: u8,
}

impl Observer {
    fn new(
        exposure_of: &dyn Fn(usize, u8) -> f32,
        options: &GhostOptions,
    ) -> Result<Self, CaptureError> {
        let mut ln_exposure = [[0.0f32; 256]; 3];
        let mut sigma = [[0.0f32; 256]; 3];
        for c in 0..3 {
            let mut x = [0.0f32; 256];
            for (z, value) in x.iter_mut().enumerate() {
                let code = z as u8;
                *value = exposure_of(c, code);
                if !(value.is_finite() && *value >= 0.0) {
                    return Err(CaptureError::Parameter(format!(
                        "response: exposure of code {z} in channel {c} is {value} (must be finite and >= 0)"
                    )));
                }
                if code > options.dark_code && *value <= 0.0 {
                    return Err(CaptureError::Parameter(format!(
                        "response: exposure of code {z} in channel {c} is 0 although above the dark code {}",
                        options.dark_code
                    )));
                }
            }
            for z in usize::from(options.dark_code) + 1..256 {
                ln_exposure[c][z] = x[z].ln();
                let below = x[z - 1];
                let above = x[(z + 1).min(255)];
                let span = if z == 255 { 1.0 } else { 2.0 };
                let step = (above - below).abs() / span / x[z];
                sigma[c][z] = step.hypot(options.relative_noise);
            }
        }
        Ok(Observer {
            ln_exposure,
            sigma,
            dark_code: options.dark_code,
            bright_code: options.bright_code,
        })
    }

    /// The interval of `ln L` that each code of each channel gives in an exposure of `t` seconds.
    fn table(&self, t: f32) -> [[Interval; 256]; 3] {
        let ln_t = t.ln();
        let dark_bound = usize::from(self.dark_code) + 1;
        let bright_bound = usize::from(self.bright_code) - 1;
        let mut table = [[Interval::default(); 256]; 3];
        for (c, codes) in table.iter_mut().enumerate() {
            let (ln_x, sigma) = (&self.ln_exposure[c], &self.sigma[c]);
            for (z, interval) in codes.iter_mut().enumerate() {
                *interval = if z <= usize::from(self.dark_code) {
                    Interval {
                        lo: f32::NEG_INFINITY,
                        hi: ln_x[dark_bound] - ln_t,
                        sigma2: sigma[dark_bound].powi(2),
                    }
                } else if z >= usize::from(self.bright_code) {
                    Interval {
                        lo: ln_x[bright_bound] - ln_t,
                        hi: f32::INFINITY,
                        sigma2: sigma[bright_bound].powi(2),
                    }
                } else {
                    Interval {
                        lo: ln_x[z] - ln_t,
                        hi: ln_x[z] - ln_t,
                        sigma2: sigma[z].powi(2),
                    }
                };
            }
        }
        table
    }
}

/// Minimum filter then box filter, both `(2 r + 1)^2`, separable, windows clipped at the border,
/// in place.
fn smooth(weights: &mut Image<f32>, r: usize) {
    if r == 0 || weights.is_empty() {
        return;
    }
    let (w, h) = (weights.width(), weights.height());
    let rows = horizontal(weights.pixels(), w, r, Window::Min);
    vertical(&rows, w, h, r, Window::Min, weights.pixels_mut());
    let rows = horizontal(weights.pixels(), w, r, Window::Mean);
    vertical(&rows, w, h, r, Window::Mean, weights.pixels_mut());
}

/// Minimum or mean over columns `[x - r, x + r]` (clipped) of every row of `w` pixels, rows in
/// parallel, as whole-row slice operations per offset (O(r) per pixel, vectorised).
fn horizontal(src: &[f32], w: usize, r: usize, window: Window) -> Vec<f32> {
    let mut out = src.to_vec();
    out.par_chunks_mut(w)
        .zip(src.par_chunks(w))
        .for_each(|(out, row)| {
            for offset in 1..=r.min(w.saturating_sub(1)) {
                let (left, right) = (&row[..w - offset], &row[offset..]);
                match window {
                    Window::Min => {
                        out[offset..]
                            .iter_mut()
                            .zip(left)
                            .for_each(|(o, &v)| *o = o.min(v));
                        out[..w - offset]
                            .iter_mut()
                            .zip(right)
                            .for_each(|(o, &v)| *o = o.min(v));
                    }
                    Window::Mean => {
                        out[offset..]
                            .iter_mut()
                            .zip(left)
                            .for_each(|(o, &v)| *o += v);
                        out[..w - offset]
                            .iter_mut()
                            .zip(right)
                            .for_each(|(o, &v)| *o += v);
                    }
                }
            }
            if let Window::Mean = window {
                for (x, o) in out.iter_mut().enumerate() {
                    let count = x.min(r) + (w - 1 - x).min(r) + 1;
                    *o /= count as f32;
                }
            }
        });
    out
}

/// How [`horizontal`] and [`vertical`] reduce a window.
#[derive(Clone, Copy)]
enum Window {
    Min,
    Mean,
}

/// Minimum or mean over rows `[y - r, y + r]` (clipped) for every row `y`, whole rows at a time
/// (O(r) per pixel, vectorised along the row), output rows in parallel, into `out`.
fn vertical(src: &[f32], w: usize, h: usize, r: usize, window: Window, out: &mut [f32]) {
    out.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let first = y.saturating_sub(r);
        let last = (y + r).min(h - 1);
        out.copy_from_slice(&src[first * w..(first + 1) * w]);
        for row in src[(first + 1) * w..(last + 1) * w].chunks_exact(w) {
            match window {
                Window::Min => out.iter_mut().zip(row).for_each(|(o, &v)| *o = o.min(v)),
                Window::Mean => out.iter_mut().zip(row).for_each(|(o, &v)| *o += v),
            }
        }
        if let Window::Mean = window {
            let scale = 1.0 / (last + 1 - first) as f32;
            out.iter_mut().for_each(|o| *o *= scale);
        }
    });
}
