//! Differences between two lat-long probes (a captured or unwrapped probe against the truth),
//! weighted by each texel's exact solid angle (CONVENTIONS section 4) so that the over-sampled
//! poles count for what they cover:
//!
//! ```text
//! relative MAE of luminance = sum_p |Y(a_p) - Y(b_p)| dOmega_p / sum_p Y(b_p) dOmega_p
//! ```
//!
//! over the selected texels (all, or a mask), `Y` the Rec. 709 luminance. Sums are f64, per row
//! then over rows in order: deterministic whatever the thread count. Cost O(W H).

use ibl_core::{Image, LatLong, Rgb};
use rayon::prelude::*;

use crate::comparison::{DifferenceError, check_mask, check_sizes, selected};

/// The relative mean absolute error of luminance of `test` against `reference` (lat-long probes
/// of the same size) over the texels `mask` selects (all when `None`). Fails when the sizes
/// differ, nothing is selected, or the reference is black there.
pub fn relative_luminance_mae(
    test: &Image<Rgb>,
    reference: &Image<Rgb>,
    mask: Option<&Image<bool>>,
) -> Result<f64, DifferenceError> {
    check_sizes(test, reference)?;
    check_mask(reference, mask)?;
    let ll = LatLong::new(reference.width(), reference.height());
    let w = reference.width();
    let rows: Vec<(f64, f64)> = (0..reference.height())
        .into_par_iter()
        .map(|j| {
            let (mut err, mut sum) = (0.0f64, 0.0f64);
            for (i, (a, b)) in test.row(j).iter().zip(reference.row(j)).enumerate() {
                if selected(mask, j * w + i) {
                    let (ya, yb) = (a.luminance(), b.luminance());
                    err += f64::from((ya - yb).abs());
                    sum += f64::from(yb);
                }
            }
            let d_omega = ll.row_solid_angle(j);
            (err * d_omega, sum * d_omega)
        })
        .collect();
    let (err, sum) = rows
        .iter()
        .fold((0.0, 0.0), |(e, s), &(re, rs)| (e + re, s + rs));
    if sum > 0.0 {
        Ok(err / sum)
    } else {
        Err(DifferenceError::NoPixels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_ten_percent_error_is_ten_percent() {
        let b = Image::filled(32, 16, Rgb::splat(2.0));
        let a = Image::filled(32, 16, Rgb::splat(2.2));
        // |2.2 - 2| / 2 in f32 luminances, summed in f64: 0.1 to f32 rounding (1e-7 relative).
        let e = relative_luminance_mae(&a, &b, None).unwrap_or(f64::NAN);
        assert!((e - 0.1).abs() < 1e-6, "{e}");
        // A mask keeping only the top half, where the test is right: no error.
        let top = Image::from_fn_par(32, 16, |_, y| y < 8);
        let half = Image::from_fn_par(
            32,
            16,
            |_, y| if y < 8 { Rgb::splat(2.0) } else { Rgb::ONE },
        );
        assert_eq!(relative_luminance_mae(&half, &b, Some(&top)), Ok(0.0));
        let black = Image::filled(32, 16, Rgb::ZERO);
        assert_eq!(
            relative_luminance_mae(&a, &black, None),
            Err(DifferenceError::NoPixels)
        );
    }
}
