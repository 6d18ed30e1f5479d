//! Daylight as two lights (Jensen, Andersen & Madsen 2006, section 3): the sun, the one direct
//! source outdoors, taken as purely directional, and the sky, which with everything the sun lights
//! makes the ambient. The paper estimates both per frame as RGB intensities for a Phong model: the
//! sun's with the sun direction from a solar-position model, the ambient's as one colour.
//!
//! Data only; `ibl-outdoor` estimates them, `ibl-render` and the viewer shade with them.

use ibl_core::{Rgb, UnitDir};

/// Solid angle of the solar disc seen from the Earth (0.53 degrees across), sr.
pub const SOLAR_DISC_SOLID_ANGLE_SR: f64 = 6.8e-5;

/// The sun as a directional light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Unit direction towards the sun, world frame.
    pub direction: UnitDir,
    /// Irradiance on a surface facing the sun (direct normal irradiance), linear RGB, W m^-2 or
    /// the probe's unit x sr.
    pub irradiance: Rgb,
    /// Solid angle of the disc, sr (soft shadows; [`SOLAR_DISC_SOLID_ANGLE_SR`] for the real sun).
    pub solid_angle_sr: f64,
}

/// The sky (and, in the paper's model, all indirect light) as seen by a shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sky {
    /// The same radiance from every direction of the upper hemisphere: a surface facing up gets
    /// `E = pi L`. This is the paper's ambient term.
    Uniform {
        /// Radiance, linear RGB, W sr^-1 m^-2 or the probe's unit.
        radiance: Rgb,
    },
}
