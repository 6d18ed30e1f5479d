//! Linear RGB triples, used for radiance (W sr^-1 m^-2 per channel, or relative units when a probe
//! is not calibrated), irradiance and power.
//!
//! The primaries are Rec. 709 / sRGB with a linear transfer; luminance uses the Rec. 709 weights
//! (0.2126, 0.7152, 0.0722). A plain `#[repr(C)]` struct rather than `glam::Vec3` so that colour and
//! geometry can never be mixed up by accident.

use std::ops::{Add, AddAssign, Div, Index, Mul, MulAssign, Sub};

use serde::{Deserialize, Serialize};

/// Rec. 709 luminance weights for linear R, G and B.
pub const LUMINANCE_WEIGHTS: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// A linear-light RGB triple (Rec. 709 primaries).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Rgb {
    /// Red channel, linear.
    pub r: f32,
    /// Green channel, linear.
    pub g: f32,
    /// Blue channel, linear.
    pub b: f32,
}

impl Rgb {
    /// Black.
    pub const ZERO: Rgb = Rgb::new(0.0, 0.0, 0.0);
    /// White, 1 in every channel.
    pub const ONE: Rgb = Rgb::new(1.0, 1.0, 1.0);

    /// Builds a triple from its three channels.
    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Rgb { r, g, b }
    }

    /// The same value in all three channels.
    pub const fn splat(v: f32) -> Self {
        Rgb::new(v, v, v)
    }

    /// The channels as an array `[r, g, b]`.
    pub const fn to_array(self) -> [f32; 3] {
        [self.r, self.g, self.b]
    }

    /// Builds a triple from an array `[r, g, b]`.
    pub const fn from_array(a: [f32; 3]) -> Self {
        Rgb::new(a[0], a[1], a[2])
    }

    /// Rec. 709 luminance of a linear triple (same unit as the channels).
    pub fn luminance(self) -> f32 {
        LUMINANCE_WEIGHTS[0] * self.r
            + LUMINANCE_WEIGHTS[1] * self.g
            + LUMINANCE_WEIGHTS[2] * self.b
    }

    /// Largest of the three channels.
    pub fn max_channel(self) -> f32 {
        self.r.max(self.g).max(self.b)
    }

    /// Whether every channel is finite and not negative (a valid radiance).
    pub fn is_valid_radiance(self) -> bool {
        self.to_array().iter().all(|c| c.is_finite() && *c >= 0.0)
    }

    /// Applies `f` to each channel.
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Rgb::new(f(self.r), f(self.g), f(self.b))
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        Rgb::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}

impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}

impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}

impl Mul<f32> for Rgb {
    type Output = Rgb;
    fn mul(self, s: f32) -> Rgb {
        Rgb::new(self.r * s, self.g * s, self.b * s)
    }
}

impl Mul<Rgb> for Rgb {
    type Output = Rgb;
    fn mul(self, o: Rgb) -> Rgb {
        Rgb::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}

impl MulAssign<f32> for Rgb {
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}

impl Div<f32> for Rgb {
    type Output = Rgb;
    fn div(self, s: f32) -> Rgb {
        Rgb::new(self.r / s, self.g / s, self.b / s)
    }
}

impl Index<usize> for Rgb {
    type Output = f32;
    fn index(&self, c: usize) -> &f32 {
        match c {
            0 => &self.r,
            1 => &self.g,
            _ => &self.b,
        }
    }
}

/// An RGB triple accumulated in f64, for sums over many pixels (power, means) whose result must
/// not depend on summation order more than f64 rounding allows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Rgb64 {
    /// Red channel.
    pub r: f64,
    /// Green channel.
    pub g: f64,
    /// Blue channel.
    pub b: f64,
}

impl Rgb64 {
    /// Zero in every channel.
    pub const ZERO: Rgb64 = Rgb64 {
        r: 0.0,
        g: 0.0,
        b: 0.0,
    };

    /// Builds a triple from its three channels.
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Rgb64 { r, g, b }
    }

    /// Builds a triple from an array `[r, g, b]`.
    pub const fn from_array(a: [f64; 3]) -> Self {
        Rgb64::new(a[0], a[1], a[2])
    }

    /// Applies `f` to each channel.
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Rgb64::new(f(self.r), f(self.g), f(self.b))
    }

    /// Whether any channel is positive.
    pub fn any_positive(self) -> bool {
        self.r > 0.0 || self.g > 0.0 || self.b > 0.0
    }

    /// Adds `c * w` (a radiance times a weight such as a solid angle).
    pub fn add_weighted(&mut self, c: Rgb, w: f64) {
        self.r += f64::from(c.r) * w;
        self.g += f64::from(c.g) * w;
        self.b += f64::from(c.b) * w;
    }

    /// The channels as `[r, g, b]`.
    pub const fn to_array(self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }

    /// Rec. 709 luminance.
    pub fn luminance(self) -> f64 {
        f64::from(LUMINANCE_WEIGHTS[0]) * self.r
            + f64::from(LUMINANCE_WEIGHTS[1]) * self.g
            + f64::from(LUMINANCE_WEIGHTS[2]) * self.b
    }
}

impl Add for Rgb64 {
    type Output = Rgb64;
    fn add(self, o: Rgb64) -> Rgb64 {
        Rgb64 {
            r: self.r + o.r,
            g: self.g + o.g,
            b: self.b + o.b,
        }
    }
}

impl Index<usize> for Rgb64 {
    type Output = f64;
    fn index(&self, c: usize) -> &f64 {
        match c {
            0 => &self.r,
            1 => &self.g,
            _ => &self.b,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luminance_of_white_is_one() {
        assert!((Rgb::ONE.luminance() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn validity_rejects_negative_and_nan() {
        assert!(Rgb::new(0.0, 1.0, 2.0).is_valid_radiance());
        assert!(!Rgb::new(-1.0, 1.0, 2.0).is_valid_radiance());
        assert!(!Rgb::new(f32::NAN, 1.0, 2.0).is_valid_radiance());
        assert!(!Rgb::new(f32::INFINITY, 1.0, 2.0).is_valid_radiance());
    }
}
