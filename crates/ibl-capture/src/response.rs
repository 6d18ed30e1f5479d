//! Camera response curves: the map from a pixel code `z` to the exposure `X = E dt` (radiance
//! times exposure time) that produced it, recovered from a bracket of photographs as in
//! P. Debevec and J. Malik, "Recovering High Dynamic Range Radiance Maps from Photographs",
//! SIGGRAPH 1997, section 2.
//!
//! A curve holds, per channel (R, G, B), `g(z) = ln f^-1(z) = ln E + ln dt` for every code
//! `z in 0..levels` (256 for 8-bit photographs), in natural-log units of relative exposure: only
//! differences of `g` are meaningful, the absolute level is fixed by convention (`g(128) = 0` for a
//! recovered curve, `g(levels - 1) = 0` for [`ResponseCurve::linear`]).
//!
//! **Recovery.** With pixel `i` of radiance `E_i` seen with code `Z_ij` in exposure `j` of length
//! `dt_j`, the unknowns `g(0..L)` and `ln E_i` minimise, per channel,
//!
//! ```text
//! sum_ij [w(Z_ij) (g(Z_ij) - ln E_i - ln dt_j)]^2 + lambda_eff sum_{z=1}^{L-2} [w(z) g''(z)]^2,
//! g''(z) = g(z-1) - 2 g(z) + g(z+1),      g(L/2) = 0,
//! ```
//!
//! with the hat weight `w(z) = min(z, L-1-z) / ((L-1)/2)` (zero at black and at saturation) and
//! `lambda_eff = lambda N P / L` for N sample pixels and P exposures, so that the balance between
//! the data and the smoothness terms does not change with the number of samples (`lambda` is the
//! smoothness weight per data equation per code; [`RecoverOptions::smoothness`]).
//! The normal equations are formed directly from the sparse rows, and the `ln E_i` are eliminated
//! per sample (each is coupled only to the codes that sample shows: a Schur complement), leaving an
//! L x L symmetric positive-definite system solved by Cholesky (nalgebra). Cost per channel:
//! `O(N P^2)` to form it plus `O(L^3 / 3)` (about 6 Mflop for L = 256) to solve it; the three
//! channels run in parallel. A least-squares curve may dip where the data are noisy; it is made
//! monotonic afterwards by a running maximum (then shifted so that `g(L/2) = 0` again).
//!
//! **Samples.** The exposures are sorted by time and the middle one is the reference. Candidate
//! pixels lie on a regular square grid over the whole image (about 65 536 of them); a candidate is
//! usable when its code lies strictly between 0 and `L-1` in at least two exposures (a pixel
//! saturated or black everywhere says nothing about `g`). Usable candidates are binned by their
//! code in the reference exposure, each bin ordered flattest first (smallest difference to the
//! four neighbours, which keeps samples away from edges a slight misalignment would smear); the
//! N samples are then taken for N target codes spread evenly over `0..L`, each from the nearest
//! bin that still has candidates. N defaults to twice the paper's minimum `N (P-1) > L-1`, at
//! least 512: the eliminated form makes samples cheap, and more of them average the noise out (on
//! the synthetic brackets of the tests the largest curve error falls from about 0.02 in ln X with
//! 128 samples to about 0.01 with 512). Fewer usable pixels than the minimum is an error.
//! Everything is deterministic.
//!
//! **Scale and white balance.** Each channel is recovered on its own with `g(128) = 0`, i.e. code
//! 128 is taken as the same exposure in all three channels, as a white-balanced camera renders a
//! neutral grey with equal codes. Any other white balance, and the absolute scale, are left to a
//! calibration by the caller.

use ibl_core::{Image, Rgb};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::CaptureError;

/// Number of codes of an 8-bit channel.
pub const LEVELS_8BIT: usize = 256;

/// Approximate number of candidate pixels examined when choosing samples (a regular grid).
const MAX_CANDIDATES: usize = 1 << 16;

/// Smallest default number of sample pixels per channel.
const MIN_DEFAULT_SAMPLES: usize = 512;

const CHANNEL_NAMES: [&str; 3] = ["red", "green", "blue"];

/// A camera response curve: per channel, the log exposure `g(z) = ln(E dt)` (natural log,
/// relative units) of every code `z`; non-decreasing in `z`.
#[derive(Clone, Debug, PartialEq)]
pub struct ResponseCurve {
    log_exposure: [Vec<f32>; 3],
}

/// Parameters of [`ResponseCurve::recover`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecoverOptions {
    /// Smoothness weight `lambda` per data equation per code (dimensionless, > 0); the solver uses
    /// `lambda N P / L` for N samples, P exposures and L codes. Default 50.
    pub smoothness: f64,
    /// Sample pixels per channel; `None` picks twice the paper's minimum `N (P-1) > L-1`, at least
    /// 512. Fewer are taken when fewer usable pixels exist.
    pub sample_pixels: Option<usize>,
}

impl Default for RecoverOptions {
    fn default() -> Self {
        RecoverOptions {
            smoothness: 50.0,
            sample_pixels: None,
        }
    }
}

impl ResponseCurve {
    /// The response of a linear sensor (RAW-like data): `g(z) = ln(z / (levels - 1))`, so the top
    /// code is exposure 1. Code 0 stands for everything that rounds to it and takes the centre of
    /// that interval, `g(0) = ln(0.25 / (levels - 1))`, keeping the curve finite and increasing.
    ///
    /// Errors: `Parameter` when `levels < 2`.
    pub fn linear(levels: usize) -> Result<Self, CaptureError> {
        if levels < 2 {
            return Err(CaptureError::Parameter(format!(
                "a response curve needs at least 2 codes, got {levels}"
            )));
        }
        let top = (levels - 1) as f64;
        let table: Vec<f32> = (0..levels)
            .map(|z| {
                let code = if z == 0 { 0.25 } else { z as f64 };
                (code / top).ln() as f32
            })
            .collect();
        Ok(ResponseCurve {
            log_exposure: [table.clone(), table.clone(), table],
        })
    }

    /// A given curve: per channel (R, G, B) `g(z)` for `z in 0..levels`, natural log of relative
    /// exposure.
    ///
    /// Errors: `Invalid` when the channels differ in length, have fewer than 2 codes, hold a value
    /// that is not finite, or decrease anywhere.
    pub fn from_table(log_exposure: [Vec<f32>; 3]) -> Result<Self, CaptureError> {
        let levels = log_exposure[0].len();
        if levels < 2 {
            return Err(CaptureError::Invalid(format!(
                "a response curve needs at least 2 codes, got {levels}"
            )));
        }
        for (c, table) in log_exposure.iter().enumerate() {
            let name = CHANNEL_NAMES[c];
            if table.len() != levels {
                return Err(CaptureError::Invalid(format!(
                    "response curve: the {name} channel has {} codes but red has {levels}",
                    table.len()
                )));
            }
            if let Some(z) = table.iter().position(|v| !v.is_finite()) {
                return Err(CaptureError::Invalid(format!(
                    "response curve: {name} g({z}) = {} is not finite",
                    table[z]
                )));
            }
            if let Some(z) = (1..levels).find(|&z| table[z] < table[z - 1]) {
                return Err(CaptureError::Invalid(format!(
                    "response curve: {name} g({z}) = {} is below g({}) = {}; a response curve \
                     must not decrease",
                    table[z],
                    z - 1,
                    table[z - 1]
                )));
            }
        }
        Ok(ResponseCurve { log_exposure })
    }

    /// Recovers the response of the camera that took `images` (one scene, aligned, 8-bit sRGB-like
    /// codes) with the exposure times `exposure_times_s` (seconds, any common scale), by the method
    /// in the module notes. `g(128) = 0` for every channel.
    ///
    /// Errors: `Invalid` for fewer than 2 images, sizes that differ, empty images, a time missing,
    /// not finite or not positive, all times equal, or too few usable sample pixels (the bracket is
    /// saturated or black everywhere); `Parameter` for a smoothness that is not finite and
    /// positive or a sample count below the minimum; `Numerical` if the system is singular.
    pub fn recover(
        images: &[Image<[u8; 3]>],
        exposure_times_s: &[f64],
        options: &RecoverOptions,
    ) -> Result<Self, CaptureError> {
        if images.len() < 2 {
            return Err(CaptureError::Invalid(format!(
                "recovering a response curve needs at least 2 exposures of the same scene, got {}",
                images.len()
            )));
        }
        check_bracket(images, exposure_times_s)?;
        let first = exposure_times_s[0];
        if exposure_times_s.iter().all(|&t| t == first) {
            return Err(CaptureError::Invalid(format!(
                "every exposure time is {first} s; recovering a response curve needs different \
                 exposure times"
            )));
        }
        if !(options.smoothness.is_finite() && options.smoothness > 0.0) {
            return Err(CaptureError::Parameter(format!(
                "smoothness must be finite and positive, got {}",
                options.smoothness
            )));
        }
        let levels = LEVELS_8BIT;
        let exposures = images.len();
        let minimum = (levels - 1) / (exposures - 1) + 1;
        let target = match options.sample_pixels {
            Some(n) if n < minimum => {
                return Err(CaptureError::Parameter(format!(
                    "{n} sample pixels are too few for {exposures} exposures: at least {minimum} \
                     are needed (N (P-1) > {})",
                    levels - 1
                )));
            }
            Some(n) => n,
            None => (2 * minimum).max(MIN_DEFAULT_SAMPLES),
        };

        let mut order: Vec<usize> = (0..exposures).collect();
        order.sort_by(|&a, &b| exposure_times_s[a].total_cmp(&exposure_times_s[b]));
        let reference = order[exposures / 2];
        let ln_dt: Vec<f64> = exposure_times_s.iter().map(|t| t.ln()).collect();

        let tables = (0..3)
            .into_par_iter()
            .map(|c| {
                let samples = select_samples(images, reference, c, target, minimum)?;
                let lambda =
                    options.smoothness * (samples.len() * exposures) as f64 / levels as f64;
                let g = solve_channel(&samples, &ln_dt, lambda, levels, c)?;
                Ok(monotonic(g))
            })
            .collect::<Result<Vec<Vec<f32>>, CaptureError>>()?;
        let [r, g, b]: [Vec<f32>; 3] = tables
            .try_into()
            .map_err(|_| CaptureError::Numerical("expected three channels".into()))?;
        Ok(ResponseCurve {
            log_exposure: [r, g, b],
        })
    }

    /// Number of codes per channel (256 for 8-bit data).
    pub fn levels(&self) -> usize {
        self.log_exposure[0].len()
    }

    /// The tables `g(z)` of the red, green and blue channels (natural log of relative exposure).
    pub fn log_exposure(&self) -> [&[f32]; 3] {
        [
            &self.log_exposure[0],
            &self.log_exposure[1],
            &self.log_exposure[2],
        ]
    }

    /// Relative exposure `exp(g(z))` (radiance times time, relative units) of code `code` in each
    /// channel; codes past the top read the top code.
    pub fn exposure_of(&self, code: usize) -> Rgb {
        let z = code.min(self.levels() - 1);
        Rgb::new(
            self.log_exposure[0][z].exp(),
            self.log_exposure[1][z].exp(),
            self.log_exposure[2][z].exp(),
        )
    }

    /// The curve as CSV: a header `code,r,g,b`, then one row per code with `g(z)` of each channel
    /// (natural log of relative exposure), written so that [`ResponseCurve::from_csv`] reads back
    /// exactly the same numbers.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("code,r,g,b\n");
        for z in 0..self.levels() {
            out.push_str(&format!(
                "{z},{},{},{}\n",
                self.log_exposure[0][z], self.log_exposure[1][z], self.log_exposure[2][z]
            ));
        }
        out
    }

    /// Reads a curve written by [`ResponseCurve::to_csv`]: an optional `code,r,g,b` header, then
    /// rows `z,r,g,b` with codes 0, 1, 2, ... in order; blank lines and lines starting with `#` are
    /// skipped. The table is then validated as by [`ResponseCurve::from_table`].
    ///
    /// Errors: `Invalid`, naming the line, for anything else.
    pub fn from_csv(text: &str) -> Result<Self, CaptureError> {
        let mut tables: [Vec<f32>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        let mut seen_row = false;
        for (index, raw) in text.lines().enumerate() {
            let line_no = index + 1;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if !seen_row
                && tables[0].is_empty()
                && fields.first().is_some_and(|f| f.parse::<usize>().is_err())
            {
                let header: Vec<String> = fields.iter().map(|f| f.to_ascii_lowercase()).collect();
                if header != ["code", "r", "g", "b"] {
                    return Err(CaptureError::Invalid(format!(
                        "response curve CSV line {line_no}: expected the header `code,r,g,b`, \
                         got `{line}`"
                    )));
                }
                seen_row = true;
                continue;
            }
            seen_row = true;
            if fields.len() != 4 {
                return Err(CaptureError::Invalid(format!(
                    "response curve CSV line {line_no}: expected 4 fields `code,r,g,b`, got {}",
                    fields.len()
                )));
            }
            let expected = tables[0].len();
            match fields[0].parse::<usize>() {
                Ok(code) if code == expected => {}
                _ => {
                    return Err(CaptureError::Invalid(format!(
                        "response curve CSV line {line_no}: expected code {expected}, got `{}`",
                        fields[0]
                    )));
                }
            }
            for (c, table) in tables.iter_mut().enumerate() {
                let value = fields[c + 1].parse::<f32>().map_err(|_| {
                    CaptureError::Invalid(format!(
                        "response curve CSV line {line_no}: `{}` is not a number",
                        fields[c + 1]
                    ))
                })?;
                table.push(value);
            }
        }
        ResponseCurve::from_table(tables)
    }
}

/// Checks a bracket of exposures: at least one image, one positive finite time per image, every
/// image the same non-zero size. Returns (width, height).
pub(crate) fn check_bracket<T>(
    images: &[Image<T>],
    exposure_times_s: &[impl Copy + Into<f64>],
) -> Result<(usize, usize), CaptureError> {
    if !images.is_empty() && exposure_times_s.len() != images.len() {
        return Err(CaptureError::Invalid(format!(
            "{} exposures but {} exposure times: every exposure needs its time",
            images.len(),
            exposure_times_s.len()
        )));
    }
    let size = check_same_size(images)?;
    for (k, &t) in exposure_times_s.iter().enumerate() {
        let t: f64 = t.into();
        if !(t.is_finite() && t > 0.0) {
            return Err(CaptureError::Invalid(format!(
                "exposure time {k} is {t} s: exposure times must be finite and positive"
            )));
        }
    }
    Ok(size)
}

/// Checks that there is at least one image and that all have the same non-zero size. Returns
/// (width, height).
pub(crate) fn check_same_size<'a, T: 'a>(
    images: impl IntoIterator<Item = &'a Image<T>>,
) -> Result<(usize, usize), CaptureError> {
    let mut images = images.into_iter();
    let Some(first) = images.next() else {
        return Err(CaptureError::Invalid("no exposures given".into()));
    };
    let (width, height) = (first.width(), first.height());
    if first.is_empty() {
        return Err(CaptureError::Invalid(format!(
            "the exposures are empty ({width} x {height} pixels)"
        )));
    }
    for (k, image) in images.enumerate() {
        if image.width() != width || image.height() != height {
            return Err(CaptureError::Invalid(format!(
                "exposure {} is {} x {} pixels but exposure 0 is {width} x {height}: every \
                 exposure of a bracket must have the same size",
                k + 1,
                image.width(),
                image.height()
            )));
        }
    }
    Ok((width, height))
}

/// Hat weight of code `z` among `levels` codes: `min(z, L-1-z) / ((L-1)/2)`, 0 at both ends.
fn hat(z: usize, levels: usize) -> f64 {
    let top = (levels - 1) as f64;
    let z = z as f64;
    z.min(top - z) / (0.5 * top)
}

/// Chooses up to `target` sample pixels of channel `c` (see the module notes); returns each
/// sample's codes in every exposure.
fn select_samples(
    images: &[Image<[u8; 3]>],
    reference: usize,
    c: usize,
    target: usize,
    minimum: usize,
) -> Result<Vec<Vec<u8>>, CaptureError> {
    let levels = LEVELS_8BIT;
    let (width, height) = (images[0].width(), images[0].height());
    let step = ((width * height) as f64 / MAX_CANDIDATES as f64)
        .sqrt()
        .floor()
        .max(1.0) as usize;
    let top = (levels - 1) as u8;
    let code = |k: usize, x: usize, y: usize| images[k].row(y)[x][c];

    // bins[z]: (contrast, x, y) of usable candidates whose reference code is z.
    let mut bins: Vec<Vec<(u8, usize, usize)>> = vec![Vec::new(); levels];
    let mut candidates = 0usize;
    for y in ((step / 2).min(height - 1)..height).step_by(step) {
        for x in ((step / 2).min(width - 1)..width).step_by(step) {
            candidates += 1;
            let usable = (0..images.len())
                .filter(|&k| {
                    let z = code(k, x, y);
                    z > 0 && z < top
                })
                .count();
            if usable < 2 {
                continue;
            }
            let z = code(reference, x, y);
            let neighbours = [
                (x.saturating_sub(1), y),
                ((x + 1).min(width - 1), y),
                (x, y.saturating_sub(1)),
                (x, (y + 1).min(height - 1)),
            ];
            let contrast = neighbours
                .iter()
                .map(|&(nx, ny)| code(reference, nx, ny).abs_diff(z))
                .max()
                .unwrap_or(0);
            bins[z as usize].push((contrast, x, y));
        }
    }
    let usable: usize = bins.iter().map(Vec::len).sum();
    if usable < minimum {
        return Err(CaptureError::Invalid(format!(
            "only {usable} of {candidates} sampled pixels are neither black nor saturated in the \
             {} channel of at least two exposures; recovering the response curve needs at least \
             {minimum}: the bracket is saturated or black almost everywhere (or too small)",
            CHANNEL_NAMES[c]
        )));
    }
    for bin in &mut bins {
        // Stable: ties keep raster order.
        bin.sort_by_key(|&(contrast, _, _)| contrast);
    }
    let count = target.min(usable);
    let mut next = vec![0usize; levels];
    let mut samples = Vec::with_capacity(count);
    for k in 0..count {
        let wanted = ((2 * k + 1) * levels) / (2 * count);
        let chosen = (0..levels).find_map(|d| {
            [wanted.checked_sub(d), Some(wanted + d)]
                .into_iter()
                .flatten()
                .find(|&z| z < levels && next[z] < bins[z].len())
        });
        // `count <= usable`, so a bin with candidates left always exists.
        let Some(z) = chosen else { break };
        let (_, x, y) = bins[z][next[z]];
        next[z] += 1;
        samples.push((0..images.len()).map(|k| code(k, x, y)).collect());
    }
    Ok(samples)
}

/// Solves the weighted least-squares problem of the module notes for one channel, eliminating
/// the per-sample `ln E_i`; returns `g(0..levels)`.
fn solve_channel(
    samples: &[Vec<u8>],
    ln_dt: &[f64],
    lambda: f64,
    levels: usize,
    c: usize,
) -> Result<Vec<f64>, CaptureError> {
    let mut normal = DMatrix::<f64>::zeros(levels, levels);
    let mut rhs = DVector::<f64>::zeros(levels);
    // u[z]: sum of w^2 over the sample's exposures showing code z.
    let mut u: Vec<(usize, f64)> = Vec::with_capacity(ln_dt.len());
    for codes in samples {
        u.clear();
        let mut d = 0.0; // sum_j w_j^2
        let mut s = 0.0; // sum_j w_j^2 ln dt_j
        for (&z, &ln_t) in codes.iter().zip(ln_dt) {
            let z = z as usize;
            let w2 = hat(z, levels).powi(2);
            if w2 == 0.0 {
                continue;
            }
            normal[(z, z)] += w2;
            rhs[z] += w2 * ln_t;
            d += w2;
            s += w2 * ln_t;
            match u.iter_mut().find(|(code, _)| *code == z) {
                Some(entry) => entry.1 += w2,
                None => u.push((z, w2)),
            }
        }
        if d == 0.0 {
            continue;
        }
        // Schur complement of the sample's ln E_i: subtract u u^T / d and u s / d.
        for &(za, ua) in &u {
            rhs[za] -= ua * s / d;
            for &(zb, ub) in &u {
                normal[(za, zb)] -= ua * ub / d;
            }
        }
    }
    for z in 1..levels - 1 {
        let weight = lambda * hat(z, levels).powi(2);
        let taps = [(z - 1, 1.0), (z, -2.0), (z + 1, 1.0)];
        for &(za, a) in &taps {
            for &(zb, b) in &taps {
                normal[(za, zb)] += weight * a * b;
            }
        }
    }
    let anchor = levels / 2;
    normal[(anchor, anchor)] += 1.0;
    let cholesky = normal.cholesky().ok_or_else(|| {
        CaptureError::Numerical(format!(
            "the response curve system of the {} channel is singular",
            CHANNEL_NAMES[c]
        ))
    })?;
    let g = cholesky.solve(&rhs);
    if g.iter().any(|v| !v.is_finite()) {
        return Err(CaptureError::Numerical(format!(
            "the response curve of the {} channel is not finite",
            CHANNEL_NAMES[c]
        )));
    }
    Ok(g.iter().copied().collect())
}

/// Running maximum (a non-decreasing curve), shifted so that `g(levels/2) = 0`.
fn monotonic(mut g: Vec<f64>) -> Vec<f32> {
    let mut running = f64::NEG_INFINITY;
    for v in &mut g {
        running = running.max(*v);
        *v = running;
    }
    let anchor = g[g.len() / 2];
    g.iter().map(|v| (v - anchor) as f32).collect()
}
