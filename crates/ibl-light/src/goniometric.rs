//! Goniometric point lights: a luminaire measured as a table of luminous intensity (candela) over
//! two angles, as IES LM-63 and EULUMDAT files hold it, placed and turned in the world.
//!
//! The light's own (photometric) frame: the vertical angle `gamma` is measured from the nadir
//! (`gamma = 0` points down the light frame's -Y, 180 degrees up +Y); the horizontal angle `C`
//! turns about +Y from +X (`C = 0`) towards -Z (`C = 90`). `world_from_light` takes that frame to
//! the world (CONVENTIONS section 1). The intensity towards a direction is the table's value
//! there (interpolated by the renderer) times [`GoniometricLight::intensity_per_candela`].
//!
//! Data only; an IES/EULUMDAT reader in `ibl-io` fills the table, `ibl-render` samples it.

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
    /// A table from its vertical angles (degrees, 0..=180 from the nadir), horizontal angles
    /// (degrees, 0..=360) and values in cd, row-major by horizontal angle
    /// (`candela[h * vertical.len() + v]`).
    pub fn new(
        vertical_deg: Vec<f32>,
        horizontal_deg: Vec<f32>,
        candela: Vec<f32>,
    ) -> Result<CandelaTable, PhotometryError> {
        check_angles("vertical", &vertical_deg, 180.0)?;
        check_angles("horizontal", &horizontal_deg, 360.0)?;
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

    /// Horizontal angles `C`, degrees, increasing.
    pub fn horizontal_deg(&self) -> &[f32] {
        &self.horizontal_deg
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
    /// per cd): the lamp's spectrum and the scene's exposure calibration.
    pub intensity_per_candela: Rgb,
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
        assert!(matches!(
            CandelaTable::new(vec![0.0, 90.0], vec![0.0], vec![1.0]),
            Err(PhotometryError::Size { .. })
        ));
        assert!(matches!(
            CandelaTable::new(vec![90.0, 0.0], vec![0.0], vec![1.0, 1.0]),
            Err(PhotometryError::Angles { .. })
        ));
        assert!(matches!(
            CandelaTable::new(vec![0.0], vec![0.0], vec![-1.0]),
            Err(PhotometryError::Value { .. })
        ));
    }
}
