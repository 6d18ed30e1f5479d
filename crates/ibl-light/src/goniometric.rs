//! Goniometric point lights (Grosch 2005, section 4.2): a luminaire measured as a table of
//! luminous intensity (candela) over two angles, as IES LM-63 and EULUMDAT files hold it, placed
//! and turned in the world.
//!
//! The light's own (photometric) frame: the vertical angle `gamma` is measured from the nadir
//! (`gamma = 0` points down the light frame's -Y, 180 degrees up +Y); the horizontal angle `C`
//! turns about +Y from +X (`C = 0`) towards -Z (`C = 90`), counterclockwise seen from above, as
//! both file formats count it. The unit direction of travel is
//! `d = (sin gamma cos C, -cos gamma, -sin gamma sin C)` ([`interpolate::direction_from_angles`]).
//! `world_from_light` takes that frame to the world (CONVENTIONS section 1).
//!
//! The intensity towards a direction is the table's bilinear interpolant there ([`interpolate`])
//! times [`GoniometricLight::intensity_per_candela`]; the table's luminous flux is the exact
//! integral of that interpolant ([`flux`]); [`equal_area`] resamples it into an equal-area map for
//! fast look-ups (the paper's cube map, with every texel the same solid angle); [`irradiance`] is
//! the paper's EQ5, `E = I(theta, phi) cos theta_e / d^2`. The readers live in `ibl-io`
//! (`photometry`), which expands each file's symmetry into the full table kept here.
//!
//! Scale to the probe's radiance unit: CONVENTIONS section 6 reads probe values as cd/m^2 by
//! default (`--lux-per-unit 1`); a probe whose unit is `k` cd/m^2 gets
//! `intensity_per_candela = colour / (Y(colour) k)` ([`intensity_per_candela_for`]), so a light
//! of `I` cd delivers `I cos / d^2` lux, that is `I cos / (k d^2)` in the probe's unit of
//! irradiance, with the colour's chromaticity.

pub mod equal_area;
pub mod flux;
pub mod interpolate;
pub mod irradiance;

use glam::{Mat3, Vec3};
use ibl_core::Rgb;

/// A table that is not a photometric grid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PhotometryError {
    /// An angle list is empty, not increasing, not finite or out of range.
    #[error("{axis} angles: {problem}")]
    Angles {
        /// `vertical` or `horizontal`.
        axis: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// The number of values is not `horizontal x vertical`.
    #[error("{values} candela values for {horizontal} x {vertical} angles")]
    Size {
        /// Values given.
        values: usize,
        /// Horizontal angles.
        horizontal: usize,
        /// Vertical angles.
        vertical: usize,
    },
    /// A value is negative or not finite.
    #[error("candela value {index} is {value} (must be finite and not negative)")]
    Value {
        /// Index in the table.
        index: usize,
        /// The value.
        value: f32,
    },
}

impl PhotometryError {
    /// Always true: a table comes from a file or a caller.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

/// Luminous intensity, cd, on a grid of horizontal angles `C` by vertical angles `gamma`.
///
/// The grid covers the whole distribution: at least two vertical angles within 0..=180 degrees
/// (zero intensity outside them), and either one horizontal angle (rotationally symmetric) or
/// horizontal angles from exactly 0 to exactly 360 degrees (the last column is the `C = 360 =
/// 0` plane again). A file's symmetry is expanded by its reader before the table is made.
#[derive(Clone, Debug, PartialEq)]
pub struct CandelaTable {
    vertical_deg: Vec<f32>,
    horizontal_deg: Vec<f32>,
    candela: Vec<f32>,
}

/// Checks that `angles` are finite, strictly increasing and within `0..=max`.
fn check_angles(axis: &'static str, angles: &[f32], max: f32) -> Result<(), PhotometryError> {
    let bad = |problem: &str| PhotometryError::Angles {
        axis,
        problem: problem.to_string(),
    };
    if angles.is_empty() {
        return Err(bad("none given"));
    }
    if angles
        .iter()
        .any(|a| !a.is_finite() || *a < 0.0 || *a > max)
    {
        return Err(bad(&format!("must be finite degrees in 0..={max}")));
    }
    if angles.windows(2).any(|w| w[1] <= w[0]) {
        return Err(bad("must increase"));
    }
    Ok(())
}

impl CandelaTable {
    /// A table from its vertical angles (degrees, 0..=180 from the nadir, at least two),
    /// horizontal angles (degrees: one angle, or 0 to 360 inclusive) and values in cd, row-major
    /// by horizontal angle (`candela[h * vertical.len() + v]`).
    pub fn new(
        vertical_deg: Vec<f32>,
        horizontal_deg: Vec<f32>,
        candela: Vec<f32>,
    ) -> Result<CandelaTable, PhotometryError> {
        check_angles("vertical", &vertical_deg, 180.0)?;
        if vertical_deg.len() < 2 {
            return Err(PhotometryError::Angles {
                axis: "vertical",
                problem: "at least two are needed (one angle spans no solid angle)".into(),
            });
        }
        check_angles("horizontal", &horizontal_deg, 360.0)?;
        if horizontal_deg.len() > 1
            && (horizontal_deg[0] != 0.0 || horizontal_deg[horizontal_deg.len() - 1] != 360.0)
        {
            return Err(PhotometryError::Angles {
                axis: "horizontal",
                problem: "must be one angle (rotationally symmetric) or run from 0 to 360 \
                          (a reader expands a file's symmetry first)"
                    .into(),
            });
        }
        if candela.len() != vertical_deg.len() * horizontal_deg.len() {
            return Err(PhotometryError::Size {
                values: candela.len(),
                horizontal: horizontal_deg.len(),
                vertical: vertical_deg.len(),
            });
        }
        if let Some((index, &value)) = candela
            .iter()
            .enumerate()
            .find(|(_, c)| !c.is_finite() || **c < 0.0)
        {
            return Err(PhotometryError::Value { index, value });
        }
        Ok(CandelaTable {
            vertical_deg,
            horizontal_deg,
            candela,
        })
    }

    /// Vertical angles `gamma`, degrees from the nadir, increasing.
    pub fn vertical_deg(&self) -> &[f32] {
        &self.vertical_deg
    }

    /// Horizontal angles `C`, degrees, increasing: `[c]` or `0 ..= 360`.
    pub fn horizontal_deg(&self) -> &[f32] {
        &self.horizontal_deg
    }

    /// Whether the table has a single horizontal angle (the same in every plane `C`).
    pub fn is_rotationally_symmetric(&self) -> bool {
        self.horizontal_deg.len() == 1
    }

    /// The intensity at horizontal angle index `h` and vertical angle index `v`, cd.
    pub fn candela(&self, h: usize, v: usize) -> Option<f32> {
        if h < self.horizontal_deg.len() && v < self.vertical_deg.len() {
            self.candela.get(h * self.vertical_deg.len() + v).copied()
        } else {
            None
        }
    }

    /// Every value, row-major by horizontal angle, cd.
    pub fn values(&self) -> &[f32] {
        &self.candela
    }

    /// The largest value, cd (0 for an all-dark table).
    pub fn peak(&self) -> f32 {
        self.candela.iter().fold(0.0, |m, &c| m.max(c))
    }
}

/// A point light with a measured intensity distribution.
#[derive(Clone, Debug, PartialEq)]
pub struct GoniometricLight {
    /// Position, metres, world frame.
    pub position: Vec3,
    /// Rotation from the light's photometric frame (see the module doc) to the world.
    pub world_from_light: Mat3,
    /// The measured luminous intensity, cd.
    pub table: CandelaTable,
    /// Radiant intensity per candela in each channel (W sr^-1 cd^-1, or the scene's relative unit
    /// per cd): the lamp's spectrum and the scene's exposure calibration
    /// ([`intensity_per_candela_for`]).
    pub intensity_per_candela: Rgb,
}

/// The scale from candela to a probe's radiance unit: `colour / (Y(colour) nits_per_unit)`, where
/// `colour` is the lamp's linear Rec. 709 colour (any brightness; only its chromaticity counts)
/// and `nits_per_unit` the luminance, cd/m^2, of a probe value of 1 (1 when the probe is read as
/// cd/m^2, CONVENTIONS section 6). Black, negative or non-finite inputs give black.
pub fn intensity_per_candela_for(colour: Rgb, nits_per_unit: f32) -> Rgb {
    let y = colour.luminance();
    let usable = y > 0.0
        && y.is_finite()
        && nits_per_unit > 0.0
        && nits_per_unit.is_finite()
        && colour.is_valid_radiance();
    if !usable {
        return Rgb::ZERO;
    }
    colour / (y * nits_per_unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_are_checked() {
        let t =
            CandelaTable::new(vec![0.0, 90.0, 180.0], vec![0.0], vec![100.0, 50.0, 0.0]).unwrap();
        assert_eq!(t.candela(0, 1), Some(50.0));
        assert_eq!(t.candela(1, 0), None);
        assert_eq!(t.peak(), 100.0);
        assert!(matches!(
            CandelaTable::new(vec![0.0, 90.0], vec![0.0], vec![1.0]),
            Err(PhotometryError::Size { .. })
        ));
        assert!(matches!(
            CandelaTable::new(vec![90.0, 0.0], vec![0.0], vec![1.0, 1.0]),
            Err(PhotometryError::Angles { .. })
        ));
        assert!(matches!(
            CandelaTable::new(vec![0.0], vec![0.0], vec![1.0]),
            Err(PhotometryError::Angles { .. })
        ));
        assert!(matches!(
            CandelaTable::new(vec![0.0, 90.0], vec![0.0, 90.0], vec![1.0; 4]),
            Err(PhotometryError::Angles {
                axis: "horizontal",
                ..
            })
        ));
        assert!(matches!(
            CandelaTable::new(vec![0.0, 90.0], vec![0.0], vec![-1.0, 0.0]),
            Err(PhotometryError::Value { .. })
        ));
    }

    #[test]
    fn the_scale_keeps_chromaticity_and_sets_luminance() {
        let s = intensity_per_candela_for(Rgb::new(2.0, 1.0, 0.5), 4.0);
        // Y(s) = 1 / nits_per_unit: a candela lights a probe read at 4 cd/m^2 per unit by 1/4.
        assert!((s.luminance() - 0.25).abs() < 1e-6);
        assert!((s.r / s.g - 2.0).abs() < 1e-6);
        assert_eq!(intensity_per_candela_for(Rgb::ONE, 0.0), Rgb::ZERO);
        assert_eq!(intensity_per_candela_for(Rgb::ZERO, 1.0), Rgb::ZERO);
    }
}
