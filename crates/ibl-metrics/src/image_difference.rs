//! Pixel-wise error metrics between a test image `a` and a reference image `b` of the same size
//! (linear RGB, any unit; row 0 at the top), optionally restricted to a mask of pixels.
//!
//! With `N` compared pixels and channels `c` in R, G, B:
//!
//! ```text
//! mse          = 1/(3N) sum_p sum_c (a - b)^2           rmse = sqrt(mse)
//! relative_mse = 1/(3N) sum_p sum_c (a - b)^2 / (b^2 + eps),   eps = RELATIVE_MSE_EPSILON = 0.01
//! mean_abs     = 1/(3N) sum_p sum_c |a - b|              max_abs = max_p max_c |a - b|
//! psnr_db      = 10 log10(peak^2 / mse),                  peak = largest reference channel value
//! ```
//!
//! The relative MSE is the form used throughout the Monte Carlo rendering and denoising literature
//! (the squared error divided by the squared *reference* value, so that bright and dark regions
//! count alike); `eps` keeps nearly black reference pixels from dominating. Papers use values from
//! 1e-3 to 1e-2; we use 1e-2, so a reference value `b` much above 0.1 is measured relatively and
//! one much below it absolutely (in units of 0.1).
//!
//! Per-pixel maps ([`relative_squared_error_map`], [`absolute_error_map`]) hold the mean over the
//! three channels of the same per-channel terms, so their mean over the pixels is the scalar
//! metric; [`MapStatistics`] gives the mean and percentiles of a map (as for the FLIP map of
//! [`mod@crate::flip`]). Drawing a map in false colour is `ibl-eval`'s.
//!
//! Sums are f64, per row in column order, then over rows in row order (fixed partition): results
//! are bit-identical whatever the rayon thread count. Cost O(W H); percentiles O(N log N).

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::comparison::{DifferenceError, check_mask, check_sizes, selected};

/// `eps` of the relative MSE, `(a - b)^2 / (b^2 + eps)`, in squared image units.
pub const RELATIVE_MSE_EPSILON: f64 = 0.01;

/// The scalar error metrics of a test image against a reference (see the module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDifference {
    /// Number of pixels compared (all, or those in the mask).
    pub pixels: u64,
    /// Root mean squared error over pixels and channels, in image units.
    pub rmse: f64,
    /// Mean over pixels and channels of `(a - b)^2 / (b^2 + 0.01)` (dimensionless).
    pub relative_mse: f64,
    /// Mean absolute error over pixels and channels, in image units.
    pub mean_abs: f64,
    /// Largest absolute channel error, in image units.
    pub max_abs: f64,
    /// `10 log10(peak^2 / mse)` with `peak` the largest reference channel value over the compared
    /// pixels, in dB; `None` when the images are identical there or the reference is black.
    pub psnr_db: Option<f64>,
}

/// Per-row partial sums of [`ImageDifference`].
#[derive(Clone, Copy, Default)]
struct RowSums {
    pixels: u64,
    squared: f64,
    relative: f64,
    abs: f64,
    max_abs: f64,
    peak: f64,
}

impl ImageDifference {
    /// Compares `test` against `reference` over every pixel, or over the pixels where `mask` is
    /// true. Fails when the sizes differ or nothing is selected. O(W H), rayon over rows.
    pub fn between(
        test: &Image<Rgb>,
        reference: &Image<Rgb>,
        mask: Option<&Image<bool>>,
    ) -> Result<Self, DifferenceError> {
        check_sizes(test, reference)?;
        check_mask(reference, mask)?;
        let w = reference.width();
        let rows: Vec<RowSums> = (0..reference.height())
            .into_par_iter()
            .map(|y| {
                let mut s = RowSums::default();
                for (x, (a, b)) in test.row(y).iter().zip(reference.row(y)).enumerate() {
                    if !selected(mask, y * w + x) {
                        continue;
                    }
                    s.pixels += 1;
                    for c in 0..3 {
                        let (a, b) = (f64::from(a[c]), f64::from(b[c]));
                        let d = a - b;
                        s.squared += d * d;
                        s.relative += d * d / (b * b + RELATIVE_MSE_EPSILON);
                        s.abs += d.abs();
                        s.max_abs = s.max_abs.max(d.abs());
                        s.peak = s.peak.max(b);
                    }
                }
                s
            })
            .collect();
        let mut t = RowSums::default();
        for r in &rows {
            t.pixels += r.pixels;
            t.squared += r.squared;
            t.relative += r.relative;
            t.abs += r.abs;
            t.max_abs = t.max_abs.max(r.max_abs);
            t.peak = t.peak.max(r.peak);
        }
        let values = 3.0 * t.pixels as f64;
        let mse = t.squared / values;
        let psnr_db = (mse > 0.0 && t.peak > 0.0).then(|| 10.0 * (t.peak * t.peak / mse).log10());
        Ok(ImageDifference {
            pixels: t.pixels,
            rmse: mse.sqrt(),
            relative_mse: t.relative / values,
            mean_abs: t.abs / values,
            max_abs: t.max_abs,
            psnr_db,
        })
    }
}

/// Per-pixel map of `f(a_c, b_c)` averaged over the three channels.
fn channel_mean_map(
    test: &Image<Rgb>,
    reference: &Image<Rgb>,
    f: impl Fn(f64, f64) -> f64 + Sync,
) -> Result<Image<f32>, DifferenceError> {
    check_sizes(test, reference)?;
    let w = reference.width();
    Ok(Image::from_fn_par(w, reference.height(), |x, y| {
        let (a, b) = (test.get(x, y), reference.get(x, y));
        let sum: f64 = (0..3).map(|c| f(f64::from(a[c]), f64::from(b[c]))).sum();
        (sum / 3.0) as f32
    }))
}

/// Per-pixel relative squared error, `1/3 sum_c (a_c - b_c)^2 / (b_c^2 + 0.01)`: the map whose
/// mean is [`ImageDifference::relative_mse`]. O(W H).
pub fn relative_squared_error_map(
    test: &Image<Rgb>,
    reference: &Image<Rgb>,
) -> Result<Image<f32>, DifferenceError> {
    channel_mean_map(test, reference, |a, b| {
        (a - b) * (a - b) / (b * b + RELATIVE_MSE_EPSILON)
    })
}

/// Per-pixel absolute error, `1/3 sum_c |a_c - b_c|`, in image units: the map whose mean is
/// [`ImageDifference::mean_abs`]. O(W H).
pub fn absolute_error_map(
    test: &Image<Rgb>,
    reference: &Image<Rgb>,
) -> Result<Image<f32>, DifferenceError> {
    channel_mean_map(test, reference, |a, b| (a - b).abs())
}

/// Mean, percentiles and maximum of a per-pixel error map over the selected pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapStatistics {
    /// Number of pixels.
    pub pixels: u64,
    /// Mean value.
    pub mean: f64,
    /// Median (nearest rank).
    pub p50: f64,
    /// 90th percentile (nearest rank).
    pub p90: f64,
    /// 99th percentile (nearest rank).
    pub p99: f64,
    /// Largest value.
    pub max: f64,
}

impl MapStatistics {
    /// Statistics of `map` over every pixel or those where `mask` is true. The `p`-th percentile
    /// is the nearest-rank one: the `ceil(p N / 100)`-th smallest value. O(N log N).
    pub fn of(map: &Image<f32>, mask: Option<&Image<bool>>) -> Result<Self, DifferenceError> {
        check_mask(map, mask)?;
        let w = map.width();
        let rows: Vec<(u64, f64)> = (0..map.height())
            .into_par_iter()
            .map(|y| {
                let mut n = 0u64;
                let mut sum = 0.0f64;
                for (x, v) in map.row(y).iter().enumerate() {
                    if selected(mask, y * w + x) {
                        n += 1;
                        sum += f64::from(*v);
                    }
                }
                (n, sum)
            })
            .collect();
        let (n, sum) = rows
            .iter()
            .fold((0u64, 0.0f64), |(n, s), &(rn, rs)| (n + rn, s + rs));
        let mut values: Vec<f32> = map
            .pixels()
            .iter()
            .enumerate()
            .filter(|&(i, _)| selected(mask, i))
            .map(|(_, v)| *v)
            .collect();
        values.par_sort_unstable_by(f32::total_cmp);
        let rank = |p: f64| {
            let k = ((p / 100.0) * values.len() as f64).ceil() as usize;
            f64::from(values[k.clamp(1, values.len()) - 1])
        };
        Ok(MapStatistics {
            pixels: n,
            mean: sum / n as f64,
            p50: rank(50.0),
            p90: rank(90.0),
            p99: rank(99.0),
            max: rank(100.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(w: usize, h: usize, v: Rgb) -> Image<Rgb> {
        Image::filled(w, h, v)
    }

    fn ramp(w: usize, h: usize) -> Image<Rgb> {
        Image::from_fn_par(w, h, |x, y| {
            Rgb::new(x as f32 * 0.1, y as f32 * 0.3, (x + y) as f32 * 0.05 + 0.2)
        })
    }

    #[test]
    fn identical_images_have_zero_error() {
        let img = ramp(13, 7);
        let d = ImageDifference::between(&img, &img, None).unwrap();
        assert_eq!(d.pixels, 91);
        assert_eq!(
            (d.rmse, d.relative_mse, d.mean_abs, d.max_abs),
            (0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!(d.psnr_db, None);
        let rel = relative_squared_error_map(&img, &img).unwrap();
        let abs = absolute_error_map(&img, &img).unwrap();
        assert!(rel.pixels().iter().chain(abs.pixels()).all(|&v| v == 0.0));
    }

    #[test]
    fn constant_offset_gives_the_closed_form() {
        // a = b + delta everywhere, b = 0.5 in every channel:
        // rmse = mean_abs = max_abs = delta, relMSE = delta^2 / (0.25 + 0.01),
        // psnr = 10 log10(0.5^2 / delta^2).
        let (b, delta) = (0.5f32, 0.125f32);
        let reference = constant(8, 4, Rgb::splat(b));
        let test = constant(8, 4, Rgb::splat(b + delta));
        let d = ImageDifference::between(&test, &reference, None).unwrap();
        let dd = f64::from(delta);
        let tol = 1e-12;
        assert!((d.rmse - dd).abs() < tol, "{}", d.rmse);
        assert!((d.mean_abs - dd).abs() < tol);
        assert!((d.max_abs - dd).abs() < tol);
        let want = dd * dd / (0.25 + RELATIVE_MSE_EPSILON);
        assert!((d.relative_mse - want).abs() < tol, "{}", d.relative_mse);
        let psnr = 10.0 * (0.25 / (dd * dd)).log10();
        assert!((d.psnr_db.unwrap() - psnr).abs() < 1e-9);
        // The per-pixel map averages to the scalar.
        let map = relative_squared_error_map(&test, &reference).unwrap();
        let stats = MapStatistics::of(&map, None).unwrap();
        assert!((stats.mean - want).abs() < 1e-7);
        assert!((stats.p50 - want).abs() < 1e-7 && (stats.max - want).abs() < 1e-7);
    }

    #[test]
    fn offsets_per_channel_and_black_reference() {
        // Reference black: relMSE = delta^2 / eps; per-channel offsets (0.1, 0.2, 0.3):
        // mse = (0.01 + 0.04 + 0.09) / 3, mean_abs = 0.2, max_abs = 0.3.
        let reference = constant(5, 5, Rgb::ZERO);
        let test = constant(5, 5, Rgb::new(0.1, 0.2, 0.3));
        let d = ImageDifference::between(&test, &reference, None).unwrap();
        let mse = (0.01 + 0.04 + 0.09) / 3.0;
        assert!((d.rmse - f64::sqrt(mse)).abs() < 1e-7);
        assert!((d.relative_mse - mse / RELATIVE_MSE_EPSILON).abs() < 1e-6);
        assert!((d.mean_abs - 0.2).abs() < 1e-7);
        assert!((d.max_abs - 0.3).abs() < 1e-7);
        assert_eq!(d.psnr_db, None, "a black reference has no peak");
    }

    #[test]
    fn mask_restricts_the_pixels() {
        // Left half: error 1; right half: error 0. Masking the right half gives 0.
        let reference = constant(8, 2, Rgb::ONE);
        let test = Image::from_fn_par(8, 2, |x, _| if x < 4 { Rgb::splat(2.0) } else { Rgb::ONE });
        let right = Image::from_fn_par(8, 2, |x, _| x >= 4);
        let d = ImageDifference::between(&test, &reference, Some(&right)).unwrap();
        assert_eq!(d.pixels, 8);
        assert_eq!(d.rmse, 0.0);
        let all = ImageDifference::between(&test, &reference, None).unwrap();
        assert!((all.mean_abs - 0.5).abs() < 1e-12 && (all.rmse - f64::sqrt(0.5)).abs() < 1e-12);
        let none = Image::filled(8, 2, false);
        assert_eq!(
            ImageDifference::between(&test, &reference, Some(&none)),
            Err(DifferenceError::NoPixels)
        );
    }

    #[test]
    fn differing_sizes_are_an_error() {
        let a = constant(4, 4, Rgb::ONE);
        let b = constant(4, 3, Rgb::ONE);
        let want = DifferenceError::SizeMismatch {
            test: [4, 4],
            reference: [4, 3],
        };
        assert_eq!(ImageDifference::between(&a, &b, None), Err(want.clone()));
        assert_eq!(relative_squared_error_map(&a, &b), Err(want.clone()));
        assert_eq!(absolute_error_map(&a, &b), Err(want));
        let mask = Image::filled(3, 3, true);
        assert!(matches!(
            ImageDifference::between(&a, &a, Some(&mask)),
            Err(DifferenceError::MaskSizeMismatch { .. })
        ));
        let empty = Image::<Rgb>::filled(0, 0, Rgb::ZERO);
        assert_eq!(
            ImageDifference::between(&empty, &empty, None),
            Err(DifferenceError::NoPixels)
        );
    }

    #[test]
    fn percentiles_are_nearest_rank() {
        // Values 1..=100: p50 = 50, p90 = 90, p99 = 99, max = 100, mean = 50.5.
        let map = Image::from_fn_par(10, 10, |x, y| (y * 10 + x + 1) as f32);
        let s = MapStatistics::of(&map, None).unwrap();
        assert_eq!((s.p50, s.p90, s.p99, s.max), (50.0, 90.0, 99.0, 100.0));
        assert!((s.mean - 50.5).abs() < 1e-12);
        assert_eq!(s.pixels, 100);
    }

    #[test]
    fn sums_do_not_depend_on_the_thread_count() {
        let a = ramp(301, 157);
        let b = Image::from_fn_par(301, 157, |x, y| *a.get(x, y) * 1.01 + Rgb::splat(0.003));
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| ImageDifference::between(&a, &b, None).unwrap());
        let many = rayon::ThreadPoolBuilder::new()
            .num_threads(5)
            .build()
            .unwrap()
            .install(|| ImageDifference::between(&a, &b, None).unwrap());
        assert_eq!(one, many);
    }
}
