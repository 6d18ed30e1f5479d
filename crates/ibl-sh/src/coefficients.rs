//! SH coefficient sets: [`RadianceSh`] (what a probe projects to) and [`IrradianceSh`] (what a
//! Lambertian surface receives). They are different types so that radiance coefficients can never
//! be evaluated as irradiance by mistake (the two differ by the Lambert factors `A_l`, a factor pi in
//! band 0 alone). Both hold linear RGB per coefficient, in the world frame, in the basis of
//! CONVENTIONS section 6 (`coefficients()[sh_index(l, m)]`).

use ibl_core::glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::ShError;
use crate::basis::{MAX_BANDS, coefficient_count, eval_basis};
use crate::convolution::{Window, lambert_factor};
use crate::rotation::ShRotation;

/// Radiance `L(d) = sum_lm c_lm Y_lm(d)`, RGB, in the probe's units.
#[derive(Clone, Debug, PartialEq)]
pub struct RadianceSh {
    bands: usize,
    coeffs: Vec<[f64; 3]>,
}

/// Irradiance `E(n) = sum_lm e_lm Y_lm(n)` on a surface with normal `n`, RGB, in the probe's units
/// times sr.
#[derive(Clone, Debug, PartialEq)]
pub struct IrradianceSh {
    bands: usize,
    coeffs: Vec<[f64; 3]>,
}

/// Checks a band count and a coefficient vector's length.
fn validate(bands: usize, coeffs: &[[f64; 3]]) -> Result<(), ShError> {
    if bands == 0 || bands > MAX_BANDS {
        return Err(ShError::Parameter(format!(
            "SH band count must be 1 to {MAX_BANDS}; got {bands}"
        )));
    }
    if coeffs.len() != coefficient_count(bands) {
        return Err(ShError::Invalid(format!(
            "{bands} bands need {} coefficients; got {}",
            coefficient_count(bands),
            coeffs.len()
        )));
    }
    if let Some(k) = coeffs.iter().position(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(ShError::Invalid(format!(
            "coefficient {k} is not a finite number"
        )));
    }
    Ok(())
}

/// `sum_k c_k Y_k(d)` per channel. O(bands^2).
fn evaluate(bands: usize, coeffs: &[[f64; 3]], d: DVec3, scratch: &mut Vec<f64>) -> [f64; 3] {
    scratch.resize(coefficient_count(bands), 0.0);
    eval_basis(d, bands, scratch);
    let mut out = [0.0; 3];
    for (y, c) in scratch.iter().zip(coeffs) {
        for ch in 0..3 {
            out[ch] += y * c[ch];
        }
    }
    out
}

/// Per-channel `sum_m c_lm^2` for band `l`.
fn band_energy(coeffs: &[[f64; 3]], l: usize) -> [f64; 3] {
    let mut e = [0.0; 3];
    for c in &coeffs[l * l..(l + 1) * (l + 1)] {
        for ch in 0..3 {
            e[ch] += c[ch] * c[ch];
        }
    }
    e
}

macro_rules! shared_methods {
    ($t:ident) => {
        impl $t {
            /// From `bands^2` coefficients (world frame, CONVENTIONS section 6); an error if the
            /// count does not match, `bands` is 0 or above [`MAX_BANDS`], or a value is not finite.
            pub fn new(bands: usize, coeffs: Vec<[f64; 3]>) -> Result<Self, ShError> {
                validate(bands, &coeffs)?;
                Ok($t { bands, coeffs })
            }

            /// Number of bands (`l < bands`).
            pub fn bands(&self) -> usize {
                self.bands
            }

            /// The coefficients, `[sh_index(l, m)]`, RGB.
            pub fn coefficients(&self) -> &[[f64; 3]] {
                &self.coeffs
            }

            /// Per-channel energy `sum_m c_lm^2` of band `l` (0 beyond the last band); rotations
            /// keep it.
            pub fn band_energy(&self, l: usize) -> [f64; 3] {
                if l >= self.bands {
                    [0.0; 3]
                } else {
                    band_energy(&self.coeffs, l)
                }
            }

            /// The same function rotated by `rotation` (directions `d` go to `rotation d`, so the
            /// new function at `rotation d` equals the old one at `d`). O(bands^3).
            pub fn rotated(&self, rotation: DMat3) -> Self {
                let coeffs = ShRotation::new(rotation, self.bands).apply(&self.coeffs);
                $t {
                    bands: self.bands,
                    coeffs,
                }
            }

            /// The same function seen through any orthogonal matrix `m` (new directions `m d`): a
            /// rotation as [`Self::rotated`], a reflection (determinant -1, such as a change to a
            /// left-handed frame) as the rotation `-m` followed by the inversion `d -> -d`, which
            /// multiplies band `l` by `(-1)^l`. O(bands^3).
            pub fn transformed(&self, m: DMat3) -> Self {
                if m.determinant() > 0.0 {
                    return self.rotated(m);
                }
                let mut out = self.rotated(-m);
                for l in (1..self.bands).step_by(2) {
                    for c in &mut out.coeffs[l * l..(l + 1) * (l + 1)] {
                        *c = c.map(|v| -v);
                    }
                }
                out
            }

            /// The first `bands` bands (all of them if there are fewer).
            pub fn truncated(&self, bands: usize) -> Self {
                let bands = bands.clamp(1, self.bands);
                $t {
                    bands,
                    coeffs: self.coeffs[..coefficient_count(bands)].to_vec(),
                }
            }

            /// The expansion evaluated at many unit directions, in parallel. O(bands^2) each.
            pub fn eval_many(&self, dirs: &[DVec3]) -> Vec<[f64; 3]> {
                dirs.par_iter()
                    .map_init(Vec::new, |scratch, d| {
                        evaluate(self.bands, &self.coeffs, *d, scratch)
                    })
                    .collect()
            }
        }
    };
}

shared_methods!(RadianceSh);
shared_methods!(IrradianceSh);

impl RadianceSh {
    /// The radiance arriving from direction `d` (unit, world frame). O(bands^2).
    pub fn radiance(&self, d: DVec3) -> [f64; 3] {
        evaluate(self.bands, &self.coeffs, d, &mut Vec::new())
    }

    /// Lambert convolution (Ramamoorthi & Hanrahan 2001): band `l` times `A_l` and the window's
    /// weight.
    pub fn irradiance(&self, window: Window) -> IrradianceSh {
        let mut coeffs = self.coeffs.clone();
        for l in 0..self.bands {
            let f = lambert_factor(l) * window.weight(l, self.bands);
            for c in &mut coeffs[l * l..(l + 1) * (l + 1)] {
                for v in c.iter_mut() {
                    *v *= f;
                }
            }
        }
        IrradianceSh {
            bands: self.bands,
            coeffs,
        }
    }
}

impl IrradianceSh {
    /// The irradiance on a surface with unit normal `n` (world frame). O(bands^2).
    pub fn irradiance(&self, n: DVec3) -> [f64; 3] {
        evaluate(self.bands, &self.coeffs, n, &mut Vec::new())
    }
}
