//! A FLIP-style perceptual difference map between a test image and a reference (linear RGB, row 0
//! at the top), after Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström and Fairchild,
//! "FLIP: A Difference Evaluator for Alternating Images" (HPG 2020), and its HDR extension
//! (Andersson et al., "Visualizing Errors in Rendered High Dynamic Range Images", Eurographics
//! 2021 short papers). Written from the papers' descriptions; not bit-identical to NVIDIA's code,
//! but checked against their `flip-evaluator` 1.7 (Python) on synthetic 128 x 96 pairs (noise,
//! tint, LDR and HDR, 20 to 150 ppd): means agree to 1e-4, per-pixel values to 2e-4, and the HDR
//! exposure brackets are the same.
//!
//! Every pixel gets an error in `[0, 1]`: 0 where the two images cannot be told apart when
//! flipped between at the given viewing distance, near 1 for black against white. The score is
//! the mean of the map.
//!
//! **LDR pipeline** ([`FlipRange::Ldr`]: values clamped to `[0, 1]`, read as display-linear RGB):
//!
//! 1. Linear sRGB to CIE XYZ (D65) to the opponent space YCxCz: `Yy = 116 Y/Yn - 16`,
//!    `Cx = 500 (X/Xn - Y/Yn)`, `Cz = 200 (Y/Yn - Z/Zn)` (CIELAB without the cube root, so it is
//!    linear and may be filtered).
//! 2. Each channel is convolved with the spatial form of its contrast sensitivity function,
//!    `s(r) = a1 sqrt(pi/b1) exp(-pi^2 r^2 / b1) + a2 sqrt(pi/b2) exp(-pi^2 r^2 / b2)` (r in
//!    degrees of visual angle, the Fourier pair of `a1 exp(-b1 f^2) + a2 exp(-b2 f^2)` with f in
//!    cycles per degree), normalised to sum 1. Constants from the FLIP paper (after Johnson and
//!    Fairchild's CSFs): achromatic `a1 = 1, b1 = 0.0047`; red-green `a1 = 1, b1 = 0.0053`;
//!    blue-yellow `a1 = 34.1, b1 = 0.04, a2 = 13.5, b2 = 0.025`. All three kernels share the radius
//!    `ceil(3 sqrt(0.04 / (2 pi^2)) ppd)` pixels (3 standard deviations of the widest Gaussian).
//! 3. Back to linear RGB, clamped to `[0, 1]`, to CIELAB (D65) with the Hunt adjustment
//!    `a' = 0.01 L a`, `b' = 0.01 L b` (chroma appears weaker at low luminance).
//! 4. Colour error: the HyAB distance `|L1 - L2| + sqrt((a1' - a2')^2 + (b1' - b2')^2)` raised to
//!    `qc = 0.7`, then mapped to `[0, 1]` piecewise-linearly: errors below `pc cmax` (`pc = 0.4`)
//!    onto `[0, pt]` (`pt = 0.95`), the rest onto `[pt, 1]`, where `cmax` is the compressed HyAB
//!    distance between pure green and pure blue (the largest the paper considers); larger errors
//!    are clamped to 1.
//! 5. Feature error, on the unfiltered luminance `Y/Yn` in `[0, 1]`: edges (first derivative of a
//!    Gaussian) and points (second derivative) with standard deviation `0.5 w ppd` pixels,
//!    `w = 0.082` degrees, radius `ceil(3 sigma)`; each derivative kernel's positive taps sum to
//!    1 and its negative taps to -1, the cross-direction Gaussian sums to 1. With `|e|` the
//!    gradient magnitude of the x and y edge responses and `|p|` that of the point responses,
//!    `df = (max(||e_t| - |e_r||, ||p_t| - |p_r||) / sqrt(2))^qf`, `qf = 0.5`, in `[0, 1]`.
//! 6. `flip = colour_error^(1 - feature_error)`: features amplify colour differences.
//!
//! **HDR** ([`FlipRange::Hdr`]): both images are exposed by `2^c` and tone-mapped per channel
//! with Narkowicz's ACES fit (including his 0.6 pre-scale, as HDR-FLIP does),
//! `t(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)` of `x = 0.6 * 2^c * v`, for exposures
//! `c` from `c_start = log2(t^-1(0.85) / Y_max)` to `c_stop = log2(t^-1(0.85) / Y_median)` (the
//! reference's largest and median luminance each mapped to 0.85), `n = max(2, ceil(c_stop -
//! c_start))` evenly spaced, capped at [`MAX_EXPOSURES`] (for a wider range the spacing exceeds
//! one stop); each pair goes through the LDR pipeline and the map keeps the largest error per
//! pixel. When the median luminance is 0 the mean luminance replaces it; a black reference gets
//! the single exposure 0.
//!
//! **Viewing condition**: pixels per degree, `ppd = d (N / W) pi / 180` for a screen W wide with
//! N pixels seen from d; the default 67 is 0.7 m from a 0.7 m wide 3840-pixel monitor (the
//! paper's default).
//!
//! Borders replicate the edge pixels. Every filter is separable (a Gaussian, or a sum of two for
//! blue-yellow), applied along rows then columns, rayon over rows; each output pixel sums its taps
//! in a fixed order, so maps are bit-identical whatever the thread count. Cost
//! O(n W H k) for n exposures and k taps (k = 21 at 67 ppd), memory about 16 W H f32 values.

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::comparison::{DifferenceError, check_sizes};

/// Default viewing condition, pixels per degree of visual angle: a 0.7 m wide 3840-pixel
/// monitor seen from 0.7 m (`0.7 * 3840 / 0.7 * pi / 180 = 67.0`).
pub const DEFAULT_PIXELS_PER_DEGREE: f64 = 67.0;
/// Smallest accepted pixels per degree.
pub const MIN_PIXELS_PER_DEGREE: f64 = 1.0;
/// Largest accepted pixels per degree (the filters then span up to 137 pixels each way).
pub const MAX_PIXELS_PER_DEGREE: f64 = 1000.0;
/// Largest number of exposures of the HDR mode.
pub const MAX_EXPOSURES: usize = 24;

/// Contrast sensitivity terms `(a, b)` per opponent channel: `a exp(-b f^2)`, f in cycles per
/// degree (FLIP paper, section 4.1). A zero `a` is an unused term.
const CSF: [[(f64, f64); 2]; 3] = [
    [(1.0, 0.0047), (0.0, 1.0e-5)],
    [(1.0, 0.0053), (0.0, 1.0e-5)],
    [(34.1, 0.04), (13.5, 0.025)],
];
/// Largest `b` of [`CSF`], which sets the common filter radius.
const CSF_B_MAX: f64 = 0.04;
/// Exponent of the HyAB colour distance.
const QC: f32 = 0.7;
/// Fraction of `cmax` where the colour-error mapping changes slope.
const PC: f32 = 0.4;
/// Error value at that point.
const PT: f32 = 0.95;
/// Exponent of the feature difference.
const QF: f32 = 0.5;
/// Spread of the edge and point detectors, degrees of visual angle.
const FEATURE_WIDTH_DEG: f64 = 0.082;
/// Tone-mapped value the reference's largest (first exposure) and median (last exposure)
/// luminance are mapped to in the HDR mode.
const HDR_TARGET: f64 = 0.85;
/// Narkowicz's ACES fit with his 0.6 pre-scale folded in:
/// `t(v) = (k0 v^2 + k1 v) / (k3 v^2 + k4 v + k5)`.
const ACES: [f64; 5] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

/// Linear sRGB (Rec. 709 primaries) to CIE XYZ, D65.
const XYZ_FROM_RGB: [[f32; 3]; 3] = [
    [0.412_456_4, 0.357_576_1, 0.180_437_5],
    [0.212_672_9, 0.715_152_2, 0.072_175],
    [0.019_333_9, 0.119_192, 0.950_304_1],
];
/// CIE XYZ (D65) to linear sRGB.
const RGB_FROM_XYZ: [[f32; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266, 1.876_010_8, 0.041_556],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];
/// XYZ of the D65 white (RGB 1, 1, 1).
const WHITE: [f32; 3] = [0.950_47, 1.0, 1.088_83];

/// Whether the inputs are display-referred or high dynamic range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlipRange {
    /// Values are display-linear in `[0, 1]` (e.g. decoded PNG/JPEG); larger values clip.
    Ldr,
    /// Linear radiance of any range: a bracket of tone-mapped exposures (HDR-FLIP).
    Hdr,
}

impl FlipRange {
    /// `"ldr"` or `"hdr"`.
    pub fn name(self) -> &'static str {
        match self {
            FlipRange::Ldr => "ldr",
            FlipRange::Hdr => "hdr",
        }
    }
}

/// How FLIP looks at the images.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipOptions {
    /// Viewing condition, pixels per degree of visual angle (1 to 1000).
    pub pixels_per_degree: f64,
    /// LDR or HDR inputs.
    pub range: FlipRange,
}

impl Default for FlipOptions {
    fn default() -> Self {
        FlipOptions {
            pixels_per_degree: DEFAULT_PIXELS_PER_DEGREE,
            range: FlipRange::Hdr,
        }
    }
}

/// A FLIP difference map and how it was made.
#[derive(Clone, Debug, PartialEq)]
pub struct Flip {
    /// Per-pixel perceived difference in `[0, 1]`.
    pub map: Image<f32>,
    /// Exposures used, in stops (`2^c` before tone mapping); empty in the LDR mode.
    pub exposures: Vec<f64>,
}

impl Flip {
    /// Mean of the map (the FLIP score): per-row f64 sums, then over rows in order.
    pub fn mean(&self) -> f64 {
        let rows: Vec<f64> = (0..self.map.height())
            .into_par_iter()
            .map(|y| self.map.row(y).iter().map(|&v| f64::from(v)).sum())
            .collect();
        rows.iter().sum::<f64>() / self.map.len().max(1) as f64
    }
}

/// The FLIP map of `test` against `reference` (see the module notes). Fails when the sizes
/// differ, the images are empty or the pixels per degree are out of range.
/// O(n W H k) for n exposures and k filter taps.
pub fn flip(
    test: &Image<Rgb>,
    reference: &Image<Rgb>,
    options: &FlipOptions,
) -> Result<Flip, DifferenceError> {
    check_sizes(test, reference)?;
    let ppd = options.pixels_per_degree;
    if !(MIN_PIXELS_PER_DEGREE..=MAX_PIXELS_PER_DEGREE).contains(&ppd) {
        return Err(DifferenceError::PixelsPerDegree {
            value: ppd,
            min: MIN_PIXELS_PER_DEGREE,
            max: MAX_PIXELS_PER_DEGREE,
        });
    }
    let kernels = Kernels::new(ppd);
    let cmax = colour_cmax();
    let (w, h) = (reference.width(), reference.height());
    let exposures = match options.range {
        FlipRange::Ldr => Vec::new(),
        FlipRange::Hdr => hdr_exposures(reference),
    };
    let pass = |exposure: Option<f64>| {
        let t = prepare(test, exposure, &kernels);
        let r = prepare(reference, exposure, &kernels);
        combine(&t, &r, cmax)
    };
    let data = if exposures.is_empty() {
        pass(None)
    } else {
        let mut worst = vec![0.0f32; w * h];
        for &c in &exposures {
            let map = pass(Some(c));
            worst
                .par_iter_mut()
                .zip(map.par_iter())
                .for_each(|(a, &b)| *a = a.max(b));
        }
        worst
    };
    let map = Image::from_vec(w, h, data).map_err(|_| DifferenceError::NoPixels)?;
    Ok(Flip { map, exposures })
}

/// The HDR-FLIP exposures for a reference, in stops (see the module notes): from the exposure
/// that maps its largest luminance to 0.85 to the one that maps its median there. O(W H).
pub fn hdr_exposures(reference: &Image<Rgb>) -> Vec<f64> {
    let mut lum: Vec<f32> = reference.pixels().iter().map(|p| p.luminance()).collect();
    let y_max = f64::from(lum.iter().copied().fold(0.0f32, f32::max));
    if !(y_max > 0.0 && y_max.is_finite()) {
        return vec![0.0];
    }
    let mid = lum.len() / 2;
    let (_, median, _) = lum.select_nth_unstable_by(mid, f32::total_cmp);
    let mut y_low = f64::from(*median);
    if y_low.is_nan() || y_low <= 0.0 {
        // A mostly black reference: its mean luminance (positive, since y_max is).
        y_low = lum.iter().map(|&v| f64::from(v)).sum::<f64>() / lum.len() as f64;
    }
    let x = aces_inverse(HDR_TARGET);
    let start = (x / y_max).log2();
    let stop = (x / y_low).log2();
    let n = ((stop - start).ceil() as usize).clamp(2, MAX_EXPOSURES);
    (0..n)
        .map(|i| start + (stop - start) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The tone curve of the HDR mode on an exposed value (`v >= 0`), in `[0, 1]`.
fn aces(v: f32) -> f32 {
    let [k0, k1, k3, k4, k5] = ACES.map(|k| k as f32);
    let v = v.min(1.0e4); // the curve is 1 long before; avoids inf / inf
    ((k0 * v * v + k1 * v) / (k3 * v * v + k4 * v + k5)).clamp(0.0, 1.0)
}

/// The exposed value `v > 0` that [`aces`] maps to `y` in `(0, 1)`: the positive root of
/// `(y k3 - k0) v^2 + (y k4 - k1) v + y k5 = 0`.
fn aces_inverse(y: f64) -> f64 {
    let [k0, k1, k3, k4, k5] = ACES;
    let (a, b, c) = (y * k3 - k0, y * k4 - k1, y * k5);
    (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)
}

/// One direction's taps of a separable filter, centred (length `2 r + 1`).
type Taps = Vec<f32>;

/// The filters for one viewing condition.
struct Kernels {
    /// Per opponent channel: `(weight, 1-D Gaussian)` terms; the 2-D filter is
    /// `sum weight g(x) g(y)` and sums to 1.
    csf: [Vec<(f32, Taps)>; 3],
    /// Normalised Gaussian across the feature direction.
    gauss: Taps,
    /// Edge detector along the feature direction (first derivative).
    edge: Taps,
    /// Point detector along the feature direction (second derivative).
    point: Taps,
}

impl Kernels {
    fn new(ppd: f64) -> Self {
        let pi2 = std::f64::consts::PI * std::f64::consts::PI;
        let radius = (3.0 * (CSF_B_MAX / (2.0 * pi2)).sqrt() * ppd).ceil() as i64;
        let csf = CSF.map(|terms| {
            let mut out: Vec<(f64, Vec<f64>)> = Vec::new();
            for (a, b) in terms.into_iter().filter(|t| t.0 != 0.0) {
                let taps: Vec<f64> = (-radius..=radius)
                    .map(|i| {
                        let x = i as f64 / ppd;
                        (-pi2 * x * x / b).exp()
                    })
                    .collect();
                out.push((a * (std::f64::consts::PI / b).sqrt(), taps));
            }
            // The 2-D sum of a term is its weight times the square of its 1-D sum.
            let total: f64 = out
                .iter()
                .map(|(wt, t)| wt * t.iter().sum::<f64>().powi(2))
                .sum();
            out.into_iter()
                .map(|(wt, t)| {
                    (
                        (wt / total) as f32,
                        t.into_iter().map(|v| v as f32).collect(),
                    )
                })
                .collect()
        });
        let sigma = 0.5 * FEATURE_WIDTH_DEG * ppd;
        let r = (3.0 * sigma).ceil() as i64;
        let g: Vec<f64> = (-r..=r)
            .map(|i| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp())
            .collect();
        let g_sum: f64 = g.iter().sum();
        let gauss = g.iter().map(|v| (v / g_sum) as f32).collect();
        let s2 = sigma * sigma;
        let edge = balanced((-r..=r).zip(&g).map(|(i, v)| -(i as f64) / s2 * v));
        let point = balanced(
            (-r..=r)
                .zip(&g)
                .map(|(i, v)| ((i * i) as f64 / (s2 * s2) - 1.0 / s2) * v),
        );
        Kernels {
            csf,
            gauss,
            edge,
            point,
        }
    }
}

/// Scales the positive taps to sum 1 and the negative ones to sum -1 (a part that is all zero
/// stays zero).
fn balanced(taps: impl Iterator<Item = f64>) -> Taps {
    let taps: Vec<f64> = taps.collect();
    let pos: f64 = taps.iter().filter(|v| **v > 0.0).sum();
    let neg: f64 = -taps.iter().filter(|v| **v < 0.0).sum::<f64>();
    taps.iter()
        .map(|&v| {
            let s = if v > 0.0 { pos } else { neg };
            if s > 0.0 { (v / s) as f32 } else { 0.0 }
        })
        .collect()
}

/// Convolves each row with `taps` (edge pixels replicated). Rayon over rows; each row is padded
/// once and the taps are accumulated tap by tap over the whole row (vectorisable; every pixel
/// still sums its taps in order).
fn filter_rows(src: &[f32], w: usize, taps: &[f32]) -> Vec<f32> {
    let r = taps.len() / 2;
    let mut out = vec![0.0f32; src.len()];
    out.par_chunks_mut(w)
        .zip(src.par_chunks(w))
        .for_each(|(o, s)| {
            let padded: Vec<f32> = (0..w + 2 * r)
                .map(|i| s[i.saturating_sub(r).min(w - 1)])
                .collect();
            for (k, t) in taps.iter().enumerate() {
                for (v, p) in o.iter_mut().zip(&padded[k..k + w]) {
                    *v += t * p;
                }
            }
        });
    out
}

/// Convolves each column with `taps` (edge pixels replicated), adding `weight` times the result
/// to `out`. Rayon over output rows.
fn add_filtered_columns(out: &mut [f32], src: &[f32], w: usize, taps: &[f32], weight: f32) {
    let h = src.len() / w;
    let r = taps.len() / 2;
    out.par_chunks_mut(w).enumerate().for_each(|(y, o)| {
        let mut acc = vec![0.0f32; w];
        for (k, t) in taps.iter().enumerate() {
            let sy = (y + k).saturating_sub(r).min(h - 1);
            for (a, s) in acc.iter_mut().zip(&src[sy * w..(sy + 1) * w]) {
                *a += t * s;
            }
        }
        for (v, a) in o.iter_mut().zip(acc) {
            *v += weight * a;
        }
    });
}

/// `M v` for a 3 x 3 matrix.
fn mul3(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// Linear RGB to YCxCz (D65 white).
fn ycxcz_from_rgb(rgb: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = mul3(&XYZ_FROM_RGB, rgb);
    let (x, y, z) = (x / WHITE[0], y / WHITE[1], z / WHITE[2]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// YCxCz to linear RGB (not clamped).
fn rgb_from_ycxcz(c: [f32; 3]) -> [f32; 3] {
    let y = (c[0] + 16.0) / 116.0;
    let x = c[1] / 500.0 + y;
    let z = y - c[2] / 200.0;
    mul3(&RGB_FROM_XYZ, [x * WHITE[0], y * WHITE[1], z * WHITE[2]])
}

/// Linear RGB in `[0, 1]` to Hunt-adjusted CIELAB `(L, 0.01 L a, 0.01 L b)`, D65 white.
fn hunt_lab_from_rgb(rgb: [f32; 3]) -> [f32; 3] {
    let f = |t: f32| {
        const D: f32 = 6.0 / 29.0;
        if t > D * D * D {
            t.cbrt()
        } else {
            t / (3.0 * D * D) + 4.0 / 29.0
        }
    };
    let [x, y, z] = mul3(&XYZ_FROM_RGB, rgb);
    let (fx, fy, fz) = (f(x / WHITE[0]), f(y / WHITE[1]), f(z / WHITE[2]));
    let l = 116.0 * fy - 16.0;
    [
        l,
        0.01 * l * 500.0 * (fx - fy),
        0.01 * l * 200.0 * (fy - fz),
    ]
}

/// HyAB distance between two Hunt-adjusted Lab colours.
fn hyab(p: [f32; 3], q: [f32; 3]) -> f32 {
    (p[0] - q[0]).abs() + ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

/// `cmax`: the compressed HyAB distance between pure green and pure blue.
fn colour_cmax() -> f32 {
    let green = hunt_lab_from_rgb([0.0, 1.0, 0.0]);
    let blue = hunt_lab_from_rgb([0.0, 0.0, 1.0]);
    hyab(green, blue).powf(QC)
}

/// What one image contributes to the comparison at one exposure.
struct Prepared {
    /// CSF-filtered colour, Hunt-adjusted Lab, per pixel.
    lab: Vec<[f32; 3]>,
    /// Edge magnitude of the luminance.
    edge: Vec<f32>,
    /// Point magnitude of the luminance.
    point: Vec<f32>,
}

/// Tone-maps (HDR, at `exposure` stops) or clamps (LDR) an image to `[0, 1]`, filters it with the
/// CSFs and detects its features.
fn prepare(image: &Image<Rgb>, exposure: Option<f64>, k: &Kernels) -> Prepared {
    let w = image.width();
    let scale = exposure.map(|c| c.exp2() as f32);
    // NaN displays as black; infinity as white.
    let display = |v: f32| match scale {
        _ if v.is_nan() => 0.0,
        Some(s) => aces(v * s),
        None => v.clamp(0.0, 1.0),
    };
    let opponent: Vec<[f32; 3]> = image
        .pixels()
        .par_iter()
        .map(|p| ycxcz_from_rgb([display(p.r), display(p.g), display(p.b)]))
        .collect();
    // Filter each opponent channel with its CSF.
    let mut filtered: [Vec<f32>; 3] = Default::default();
    for (c, out) in filtered.iter_mut().enumerate() {
        let plane: Vec<f32> = opponent.par_iter().map(|v| v[c]).collect();
        *out = vec![0.0f32; plane.len()];
        for (weight, taps) in &k.csf[c] {
            let rows = filter_rows(&plane, w, taps);
            add_filtered_columns(out, &rows, w, taps, *weight);
        }
    }
    let lab = (0..opponent.len())
        .into_par_iter()
        .map(|i| {
            let rgb = rgb_from_ycxcz([filtered[0][i], filtered[1][i], filtered[2][i]]);
            hunt_lab_from_rgb(rgb.map(|v| v.clamp(0.0, 1.0)))
        })
        .collect();
    // Features of the unfiltered luminance Y / Yn = (Yy + 16) / 116, in [0, 1].
    let luminance: Vec<f32> = opponent.par_iter().map(|v| (v[0] + 16.0) / 116.0).collect();
    drop(opponent);
    let along_gauss = filter_rows(&luminance, w, &k.gauss);
    // Derivative `d` along x with the Gaussian along y, and the transpose; their magnitude.
    let magnitude = |d: &Taps| {
        let mut x = vec![0.0f32; luminance.len()];
        let mut y = vec![0.0f32; luminance.len()];
        add_filtered_columns(&mut x, &filter_rows(&luminance, w, d), w, &k.gauss, 1.0);
        add_filtered_columns(&mut y, &along_gauss, w, d, 1.0);
        x.par_iter()
            .zip(y.par_iter())
            .map(|(a, b)| a.hypot(*b))
            .collect::<Vec<f32>>()
    };
    let edge = magnitude(&k.edge);
    let point = magnitude(&k.point);
    Prepared { lab, edge, point }
}

/// The per-pixel FLIP value of a prepared test and reference.
fn combine(t: &Prepared, r: &Prepared, cmax: f32) -> Vec<f32> {
    let knee = PC * cmax;
    (0..t.lab.len())
        .into_par_iter()
        .map(|i| {
            let e = hyab(t.lab[i], r.lab[i]).powf(QC);
            let colour = if e < knee {
                e * PT / knee
            } else {
                PT + (e - knee) / (cmax - knee) * (1.0 - PT)
            }
            .min(1.0);
            let df = (t.edge[i] - r.edge[i])
                .abs()
                .max((t.point[i] - r.point[i]).abs());
            let feature = (df / std::f32::consts::SQRT_2).powf(QF).min(1.0);
            colour.powf(1.0 - feature)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic standard normal sequence (splitmix64 + Box-Muller).
    struct Normal(u64);

    impl Normal {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }

        fn sample(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    /// A 64 x 48 test picture: a smooth colour gradient, a bright square and a thin line, with
    /// values up to `peak`.
    fn picture(peak: f32) -> Image<Rgb> {
        Image::from_fn_par(64, 48, |x, y| {
            let (u, v) = (x as f32 / 63.0, y as f32 / 47.0);
            let mut c = Rgb::new(0.2 + 0.6 * u, 0.3 + 0.4 * v, 0.5 - 0.3 * u * v) * (0.5 * peak);
            if (20..36).contains(&x) && (10..26).contains(&y) {
                c = Rgb::new(peak, 0.9 * peak, 0.6 * peak);
            }
            if x == 48 {
                c = Rgb::splat(0.02 * peak);
            }
            c
        })
    }

    fn noisy(img: &Image<Rgb>, sigma: f64, seed: u64) -> Image<Rgb> {
        let mut n = Normal(seed);
        let data = img
            .pixels()
            .iter()
            .map(|p| {
                let mut c = p.to_array();
                for v in &mut c {
                    *v = (f64::from(*v) + sigma * n.sample()).max(0.0) as f32;
                }
                Rgb::from_array(c)
            })
            .collect();
        Image::from_vec(img.width(), img.height(), data).unwrap()
    }

    fn ldr() -> FlipOptions {
        FlipOptions {
            range: FlipRange::Ldr,
            ..FlipOptions::default()
        }
    }

    #[test]
    fn identical_images_give_zero_everywhere() {
        for (img, options) in [
            (picture(1.0), ldr()),
            (picture(50.0), FlipOptions::default()),
        ] {
            let f = flip(&img, &img, &options).unwrap();
            assert!(f.map.pixels().iter().all(|&v| v == 0.0));
            assert_eq!(f.mean(), 0.0);
        }
    }

    #[test]
    fn black_against_white_is_near_one() {
        // Colour error 100^0.7 = 25.1 against cmax = 203^0.7 = 41.3: 0.95 + 0.05 * 8.6 / 24.8.
        let white = Image::filled(16, 16, Rgb::ONE);
        let black = Image::filled(16, 16, Rgb::ZERO);
        for options in [ldr(), FlipOptions::default()] {
            let f = flip(&black, &white, &options).unwrap();
            let m = f.mean();
            assert!(m > 0.96 && m <= 1.0, "{options:?}: {m}");
            assert!(f.map.pixels().iter().all(|&v| (v - m as f32).abs() < 1e-5));
        }
    }

    #[test]
    fn flip_grows_with_noise_and_stays_in_unit_range() {
        for (peak, options) in [(1.0, ldr()), (20.0, FlipOptions::default())] {
            let reference = picture(peak);
            let mut last = 0.0;
            for sigma in [0.003, 0.01, 0.03, 0.1, 0.3] {
                let test = noisy(&reference, sigma * f64::from(peak), 7);
                let f = flip(&test, &reference, &options).unwrap();
                let m = f.mean();
                assert!(m > last, "{options:?} sigma {sigma}: {m} after {last}");
                assert!(f.map.pixels().iter().all(|v| (0.0..=1.0).contains(v)));
                last = m;
            }
            assert!(last > 0.3, "{options:?}: heavy noise only {last}");
        }
    }

    #[test]
    fn hdr_exposures_span_max_to_median() {
        // Half the pixels at luminance 1, half at 64: median 64 (upper median), max 64, so the
        // bracket collapses to two equal exposures; with a 1/64 median it spans 6 stops.
        let bright = Image::from_fn_par(8, 8, |x, _| Rgb::splat(if x < 4 { 1.0 } else { 64.0 }));
        let e = hdr_exposures(&bright);
        let start = (aces_inverse(HDR_TARGET) / 64.0).log2();
        assert_eq!(e.len(), 2);
        assert!((e[0] - start).abs() < 1e-6 && (e[1] - start).abs() < 1e-6);
        let dim = Image::from_fn_par(8, 8, |x, y| Rgb::splat(if x + y == 0 { 64.0 } else { 1.0 }));
        let e = hdr_exposures(&dim);
        assert_eq!(e.len(), 6);
        assert!((e[5] - e[0] - 6.0).abs() < 1e-5, "{e:?}");
        assert!((f64::from(aces((2f64.powf(e[0]) * 64.0) as f32)) - HDR_TARGET).abs() < 1e-5);
        assert_eq!(hdr_exposures(&Image::filled(4, 4, Rgb::ZERO)), vec![0.0]);
    }

    #[test]
    fn filters_preserve_constants_and_find_no_features_there() {
        let k = Kernels::new(DEFAULT_PIXELS_PER_DEGREE);
        assert_eq!(k.csf[2][0].1.len(), 21, "radius ceil(3 * 0.045 * 67) = 10");
        let (w, h) = (23, 17);
        let plane = vec![0.7f32; w * h];
        for terms in &k.csf {
            let mut out = vec![0.0; w * h];
            for (weight, taps) in terms {
                add_filtered_columns(&mut out, &filter_rows(&plane, w, taps), w, taps, *weight);
            }
            assert!(out.iter().all(|v| (v - 0.7).abs() < 1e-5));
        }
        for taps in [&k.edge, &k.point] {
            let rows = filter_rows(&plane, w, taps);
            assert!(rows.iter().all(|v| v.abs() < 1e-6));
        }
        // Colour conversions invert each other.
        let c = [0.3, 0.6, 0.1];
        let back = rgb_from_ycxcz(ycxcz_from_rgb(c));
        assert!(c.iter().zip(back).all(|(a, b)| (a - b).abs() < 1e-5));
    }

    #[test]
    fn maps_do_not_depend_on_the_thread_count() {
        let reference = picture(5.0);
        let test = noisy(&reference, 0.2, 3);
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| flip(&test, &reference, &FlipOptions::default()).unwrap())
        };
        assert_eq!(run(1), run(4));
    }

    #[test]
    fn bad_sizes_and_viewing_conditions_are_errors() {
        let a = Image::filled(4, 4, Rgb::ONE);
        let b = Image::filled(5, 4, Rgb::ONE);
        assert!(matches!(
            flip(&a, &b, &FlipOptions::default()),
            Err(DifferenceError::SizeMismatch { .. })
        ));
        for ppd in [0.0, f64::NAN, 1.0e6] {
            let options = FlipOptions {
                pixels_per_degree: ppd,
                ..FlipOptions::default()
            };
            assert!(matches!(
                flip(&a, &a, &options),
                Err(DifferenceError::PixelsPerDegree { .. })
            ));
        }
    }
}
