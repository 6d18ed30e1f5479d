//! One entry point that runs any extraction method ([`ibl_light::Method`]) for any N; the set it
//! returns records the method and its parameters in its provenance.
//!
//! Median cut makes only powers of two (the paper's algorithm); every other method takes any
//! N >= 1. The fitted method (irradiance optimisation) fits on its own normals, never on the
//! 20000 Fibonacci normals that `ibl-eval` scores on (see the [`crate::irradiance_optimization`](mod@crate::irradiance_optimization) module).

use ibl_core::{Image, Rgb};
use ibl_light::{LightSet, Method};

use crate::ExtractError;

/// What irradiance optimisation fits its lights to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FitDomain {
    /// One fit to the whole sphere's irradiance (Madsen et al. 2003, the paper's; the default):
    /// the lowest irradiance error on unshadowed normals, but a light may stand for light from
    /// both sides of the horizon, which a ground then shadows whole.
    #[default]
    Sphere,
    /// The lights above and below the horizon fitted apart, each set to its hemisphere's
    /// irradiance, with the lights shared by power ([`crate::fit_hemispheres`]): what a ground plane
    /// lets through is then the upper lights' share, as it is the probe's. Renders with shadows
    /// use it ([`crate::ExtractOptions::for_rendering`]); its unshadowed irradiance error is 2
    /// to 8 times the whole-sphere fit's (BENCHMARKS.md).
    Hemispheres,
}

impl FitDomain {
    /// The name files and command lines use: `sphere` or `hemispheres`.
    pub fn name(self) -> &'static str {
        match self {
            FitDomain::Sphere => "sphere",
            FitDomain::Hemispheres => "hemispheres",
        }
    }
}

impl std::str::FromStr for FitDomain {
    type Err = ExtractError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [FitDomain::Sphere, FitDomain::Hemispheres]
            .into_iter()
            .find(|d| d.name() == s)
            .ok_or_else(|| {
                ExtractError::Parameter(format!("unknown fit domain `{s}` (sphere, hemispheres)"))
            })
    }
}

/// Settings shared by the methods (each uses what applies to it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExtractOptions {
    /// Seed of every random choice (clustering restarts); equal seeds give equal lights.
    pub seed: u64,
    /// What irradiance optimisation fits: the whole sphere (the paper's, the default) or the
    /// hemispheres apart ([`FitDomain`]).
    pub fit_domain: FitDomain,
}

impl ExtractOptions {
    /// The options for lights that will be rendered with shadows (renders, the viewer, light
    /// files): irradiance optimisation fits the hemispheres apart, so that a ground plane
    /// shadows the probe's lower share only ([`FitDomain::Hemispheres`]).
    pub fn for_rendering(seed: u64) -> Self {
        ExtractOptions {
            seed,
            fit_domain: FitDomain::Hemispheres,
        }
    }
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions {
            seed: 1,
            fit_domain: FitDomain::default(),
        }
    }
}

/// Runs `method` on a lat-long probe for exactly `n` lights.
pub fn extract(
    probe: &Image<Rgb>,
    method: Method,
    n: usize,
    options: &ExtractOptions,
) -> Result<LightSet, ExtractError> {
    if !method.accepts(n) {
        return Err(ExtractError::Parameter(match method {
            Method::MedianCut => format!("median cut makes a power of two lights; {n} is not one"),
            _ => format!("{method} needs at least one light; got {n}"),
        }));
    }
    Ok(match method {
        Method::MedianCut => crate::median_cut(probe, n.trailing_zeros())?,
        Method::AdaptiveMedianCut => crate::adaptive_median_cut(probe, n)?,
        Method::VarianceMinimization => crate::variance_minimization(probe, n)?,
        Method::LightGen => {
            let o = crate::LightGenOptions {
                seed: options.seed,
                ..Default::default()
            };
            crate::lightgen(probe, n, &o)?
        }
        Method::IrradianceOptimization => {
            let o = crate::OptimizationOptions::default();
            match options.fit_domain {
                FitDomain::Sphere => crate::irradiance_optimization(probe, n, &o)?.set,
                FitDomain::Hemispheres => crate::fit_hemispheres(probe, n, &o)?.set,
            }
        }
    })
}
