//! Total power of an environment map: `P_c = sum_p L_p,c dOmega_p` per channel (CONVENTIONS
//! section 4), the quantity that every conversion must conserve.
//!
//! The pixel solid angles are the exact ones of [`crate::Mapping::texel_solid_angles`] (a dual
//! fisheye counts the overlap of its lenses once, with the blend weights). Sums are in f64 and
//! deterministic: each row is summed left to right (in parallel, one row per task), then the row
//! sums are added top to bottom on one thread, so the result never depends on the number of
//! threads. Cost O(W H).

use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::error::MappingError;
use crate::mapping::Mapping;
use crate::projection::{Geometry, Projection};

/// Total power `sum L dOmega` per channel (sr x radiance units), f64. Returns `[NaN; 3]` when the
/// image's shape does not fit `mapping` (use [`try_power`] to get the reason). Cost O(W H).
pub fn power(image: &Image<Rgb>, mapping: Mapping) -> [f64; 3] {
    try_power(image, mapping).unwrap_or([f64::NAN; 3])
}

/// [`power`], with an error when the image's shape does not fit `mapping`.
pub fn try_power(image: &Image<Rgb>, mapping: Mapping) -> Result<[f64; 3], MappingError> {
    let projection = Projection::new(mapping, image.width(), image.height())?;
    let row_sums: Vec<[f64; 3]> = match projection.0 {
        // Lat-long: one solid angle per row, no per-pixel table needed.
        Geometry::LatLong(ll) => (0..image.height())
            .into_par_iter()
            .map(|j| scale(row_sum(image.row(j), None), ll.row_solid_angle(j)))
            .collect(),
        _ => {
            return Ok(power_with_solid_angles(
                image,
                &projection.texel_solid_angles(),
            ));
        }
    };
    Ok(add_rows(row_sums))
}

/// [`power`] from solid angles already computed (`omega`: the image's size, from
/// [`Mapping::texel_solid_angles`]), for a caller that needs them for something else too; the
/// same sums, in the same order, as [`power`] for every mapping but lat-long (which sums each
/// row's radiance before weighting it). Cost O(W H).
pub fn power_with_solid_angles(image: &Image<Rgb>, omega: &Image<f64>) -> [f64; 3] {
    let w = image.width();
    if (omega.width(), omega.height()) != (w, image.height()) {
        return [f64::NAN; 3];
    }
    let row_sums: Vec<[f64; 3]> = (0..image.height())
        .into_par_iter()
        .map(|j| row_sum(image.row(j), Some(&omega.pixels()[j * w..(j + 1) * w])))
        .collect();
    add_rows(row_sums)
}

/// The row sums added top to bottom on one thread (deterministic whatever the thread count).
fn add_rows(row_sums: Vec<[f64; 3]>) -> [f64; 3] {
    let mut total = [0.0; 3];
    for s in row_sums {
        for c in 0..3 {
            total[c] += s[c];
        }
    }
    total
}

/// Sum of a row of radiances, each weighted by its solid angle if given.
fn row_sum(row: &[Rgb], omega: Option<&[f64]>) -> [f64; 3] {
    let mut s = [0.0; 3];
    for (i, c) in row.iter().enumerate() {
        let w = omega.map_or(1.0, |o| o[i]);
        s[0] += f64::from(c.r) * w;
        s[1] += f64::from(c.g) * w;
        s[2] += f64::from(c.b) * w;
    }
    s
}

fn scale(s: [f64; 3], k: f64) -> [f64; 3] {
    s.map(|v| v * k)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::mapping::CubeLayout;

    #[test]
    fn constant_environment_has_power_4pi_in_every_mapping() {
        for (m, w, h) in [
            (Mapping::LatLong, 64, 32),
            (Mapping::Angular, 33, 33),
            (Mapping::MirrorBall, 64, 64),
            (Mapping::Cube(CubeLayout::VerticalCross), 24, 32),
            (Mapping::Fisheye { fov_deg: 360.0 }, 40, 40),
            (Mapping::DualFisheye { fov_deg: 210.0 }, 64, 32),
        ] {
            let img = Image::filled(w, h, Rgb::new(1.0, 2.0, 0.5));
            let p = power(&img, m);
            for (c, k) in [1.0, 2.0, 0.5].iter().enumerate() {
                assert!((p[c] - 4.0 * PI * k).abs() < 1e-9, "{m:?} {p:?}");
            }
        }
        let half = power(
            &Image::filled(32, 32, Rgb::ONE),
            Mapping::Fisheye { fov_deg: 180.0 },
        );
        assert!((half[0] - 2.0 * PI).abs() < 1e-9);
    }

    #[test]
    fn mismatched_shape_is_nan_or_error() {
        let img = Image::filled(10, 7, Rgb::ONE);
        assert!(power(&img, Mapping::Angular)[0].is_nan());
        assert!(try_power(&img, Mapping::Angular).is_err());
    }
}
