//! Hybrid lighting: K "important" directional lights plus a spherical-harmonic ambient that carries
//! the rest of the probe (Grosch 2005's important and unimportant light; the outdoor paper's sun
//! and sky).
//!
//! The lights come from any extraction method. The ambient is the probe's radiance minus what the
//! lights take, in SH: each light `i` is a point source of power `I_i` at `w_i`, whose projection
//! is `I_i Y_lm(w_i)`, so
//!
//! ```text
//! ambient_lm = probe_lm - sum_i I_i Y_lm(w_i)
//! E(n)       = sum_i I_i max(0, n . w_i)  +  sum_lm A_l ambient_lm Y_lm(n)
//! ```
//!
//! Total power is conserved exactly: the ambient's band 0 loses exactly the lights' power. The
//! low bands of the irradiance equal the probe's own (the lights' low-band part is subtracted
//! from the ambient and added back by the lights), and the lights bring the sharp terminators of
//! compact sources that a few SH bands cannot. With the ambient's bands going to infinity the
//! hybrid tends to the exact irradiance whatever the lights.

use ibl_core::glam::DVec3;
use ibl_core::{Image, Rgb};
use ibl_light::LightSet;
use ibl_sh::{IrradianceSh, RadianceSh, Window, project_latlong, subtract_point_sources};
use rayon::prelude::*;

use crate::ExtractError;

/// Directional lights plus an SH ambient (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Hybrid {
    /// The important lights.
    pub lights: LightSet,
    /// The ambient radiance: the probe minus the lights, in SH (world frame).
    pub ambient: RadianceSh,
    /// The ambient's irradiance (Lambert-convolved, windowed).
    ambient_irradiance: IrradianceSh,
}

impl Hybrid {
    /// The hybrid of `lights` and the probe's radiance `probe_sh`; the ambient's irradiance uses
    /// `window`. An error if a light is not finite. O(K bands^2).
    pub fn new(
        probe_sh: &RadianceSh,
        lights: LightSet,
        window: Window,
    ) -> Result<Hybrid, ExtractError> {
        let bands = probe_sh.bands();
        let mut coeffs = probe_sh.coefficients().to_vec();
        subtract_point_sources(
            &mut coeffs,
            bands,
            lights
                .lights
                .iter()
                .map(|l| (l.direction, l.irradiance.to_array())),
        );
        let ambient = RadianceSh::new(bands, coeffs)
            .map_err(|e| ExtractError::Invalid(format!("hybrid ambient: {e}")))?;
        let ambient_irradiance = ambient.irradiance(window);
        Ok(Hybrid {
            lights,
            ambient,
            ambient_irradiance,
        })
    }

    /// The hybrid of `lights` and a lat-long probe projected on `bands` bands.
    pub fn from_probe(
        probe: &Image<Rgb>,
        lights: LightSet,
        bands: usize,
        window: Window,
    ) -> Result<Hybrid, ExtractError> {
        let sh =
            project_latlong(probe, bands).map_err(|e| ExtractError::Parameter(e.to_string()))?;
        Hybrid::new(&sh, lights, window)
    }

    /// Irradiance on a surface with unit normal `n`: the lights' plus the ambient's. O(K + B^2).
    pub fn irradiance_at(&self, n: DVec3) -> [f64; 3] {
        let l = self.lights.irradiance_at(n);
        let a = self.ambient_irradiance.irradiance(n);
        [l[0] + a[0], l[1] + a[1], l[2] + a[2]]
    }

    /// [`Hybrid::irradiance_at`] for many normals, in parallel.
    pub fn irradiance_many(&self, normals: &[DVec3]) -> Vec<[f64; 3]> {
        let ambient = self.ambient_irradiance.eval_many(normals);
        normals
            .par_iter()
            .zip(ambient)
            .map(|(n, a)| {
                let l = self.lights.irradiance_at(*n);
                [l[0] + a[0], l[1] + a[1], l[2] + a[2]]
            })
            .collect()
    }

    /// Total power `sum L dOmega` per channel: the lights' plus the ambient's (`2 sqrt(pi) c_00`);
    /// equal to the probe's.
    pub fn total_power(&self) -> [f64; 3] {
        let lights = self.lights.total_power();
        let c00 = self.ambient.coefficients()[0];
        let k = 2.0 * std::f64::consts::PI.sqrt();
        [0, 1, 2].map(|c| lights[c] + k * c00[c])
    }
}
