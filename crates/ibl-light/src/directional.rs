//! Directional light sets (CONVENTIONS sections 4 and 7).
//!
//! A light `i` has a unit direction `w_i` (towards the light, world frame), a radiance `L_i` (linear
//! RGB), a solid angle `A_i` (sr) and `I_i = L_i A_i`, the irradiance it gives a surface facing it.
//! The irradiance of a set at normal `n` is `E(n) = sum_i I_i max(0, n . w_i)`. Irradiance is kept
//! in f64 so that region methods conserve the probe's power to rounding (`sum_i I_i` equals
//! `sum_p L_p dOmega_p`).

use glam::DVec3;
use ibl_core::Rgb;
use serde::{Deserialize, Serialize};

/// An axis-aligned block of lat-long pixels: columns `x0..x1`, rows `y0..y1` (half-open).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PixelRegion {
    /// First column.
    pub x0: usize,
    /// First row (row 0 at the top).
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl PixelRegion {
    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.y1 - self.y0
    }
}

/// One directional light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    /// Unit direction towards the light, world frame (+Y up, -Z forward).
    pub direction: [f64; 3],
    /// Radiance `L = I / A`, linear RGB (the probe's unit).
    pub radiance: Rgb,
    /// Solid angle `A` of the source, sr.
    pub solid_angle_sr: f64,
    /// `I = L A` per channel: the irradiance on a surface facing the light (probe unit x sr).
    pub irradiance: [f64; 3],
    /// The probe pixels this light stands for (region methods only).
    pub region: Option<PixelRegion>,
}

impl Light {
    /// Direction as a vector.
    pub fn dir(&self) -> DVec3 {
        DVec3::from_array(self.direction)
    }
}

/// A set of directional lights approximating a probe, with the method that made it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LightSet {
    /// Method name, e.g. `median-cut`.
    pub method: String,
    /// The lights.
    pub lights: Vec<Light>,
}

impl LightSet {
    /// Irradiance at unit normal `n`, per channel: `sum_i I_i max(0, n . w_i)`. Cost O(N).
    pub fn irradiance_at(&self, n: DVec3) -> [f64; 3] {
        let mut e = [0.0; 3];
        for l in &self.lights {
            let c = n.dot(l.dir()).max(0.0);
            for (ec, ic) in e.iter_mut().zip(l.irradiance) {
                *ec += ic * c;
            }
        }
        e
    }

    /// Total power of the set per channel, `sum_i I_i` (equals the probe's `sum L dOmega` for
    /// region methods).
    pub fn total_power(&self) -> [f64; 3] {
        let mut p = [0.0; 3];
        for l in &self.lights {
            for (pc, ic) in p.iter_mut().zip(l.irradiance) {
                *pc += ic;
            }
        }
        p
    }
}
