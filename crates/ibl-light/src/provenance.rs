//! What made a light set: the extraction method with the parameters it ran with (and, for the
//! fitted method, how the fit went), and the probe it was extracted from. Light files record both
//! (CONVENTIONS section 7: `method.name`, `method.parameters`, `probe`), reports list the
//! parameters of every run.
//!
//! The parameters are typed per method; [`Extraction::parameters`] flattens them to named numbers
//! (booleans as 1 or 0) for files and reports, and [`Extraction::from_parameters`] reads them back.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::{LightSource, Method};

/// The probe a light set was extracted from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ProbeRef {
    /// Path as the user gave it.
    pub path: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// SHA-256 of the file's bytes, lower-case hex.
    pub sha256: String,
}

/// How an irradiance-optimisation fit went (Madsen et al. 2003; `ibl-extract`'s module doc
/// defines the cost `F`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FitReport {
    /// Levenberg-Marquardt iterations at the final level.
    pub iterations: usize,
    /// Iterations over all continuation levels.
    pub total_iterations: usize,
    /// True when the final level stopped on its convergence test, not on the iteration cap.
    pub converged: bool,
    /// Cost `F` when the final level started.
    pub initial_cost: f64,
    /// Cost `F` at the end.
    pub final_cost: f64,
    /// RMS of the scaled residuals on the fitting normals at the end, % of mean irradiance
    /// (the lights as points; with the hemispheres apart, as soft shadows draw them: their
    /// cones folded onto their side, for which their powers were solved).
    pub fit_rms_err_pct: f64,
    /// Mean absolute error on the fitting normals at the end, % of mean irradiance (scored as
    /// `fit_rms_err_pct` is).
    pub fit_mean_abs_err_pct: f64,
    /// Number of fitting normals.
    pub fit_normals: usize,
    /// Lights fitted to the upper hemisphere's irradiance when the fit took the hemispheres
    /// apart (`ibl-extract`'s module `hemispheres`; the rest were fitted to the lower one), or
    /// `None` for one fit over the whole sphere (the paper's). With two fits, `initial_cost` and
    /// `final_cost` are the sums of the two fits' costs (each scaled by its own hemisphere's mean
    /// irradiance); the error percentages are those of all the lights against the whole probe.
    pub lights_above_horizon: Option<usize>,
}

/// An extraction method as it ran, with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Extraction {
    /// Median cut with `splits` rounds (2^splits lights asked).
    MedianCut {
        /// Rounds of cuts.
        splits: u32,
    },
    /// Adaptive median cut (no parameters).
    AdaptiveMedianCut,
    /// LightGen clustering.
    LightGen {
        /// k-means restarts; the best is kept.
        restarts: usize,
        /// Seed of the restarts.
        seed: u64,
    },
    /// Variance minimisation (no parameters).
    VarianceMinimization,
    /// Irradiance optimisation and how its fit went.
    IrradianceOptimization(FitReport),
    /// The probe's dominant compact light (`sun`).
    DominantLight,
    /// A room's important light patches (Grosch 2005, section 3.3: `ibl room lights`), read as
    /// directional lights seen from one point (`important-patches`).
    ImportantPatches {
        /// Patches in the area-light file.
        patches: u32,
    },
    /// A method this build does not know, named in a light file made elsewhere; its parameters
    /// are not kept.
    Unknown {
        /// The name in the file.
        name: String,
    },
}

/// A light file's method that this build knows but whose parameters do not fit it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("method '{method}': parameter '{parameter}' {problem}")]
pub struct ParameterError {
    /// The method's name.
    pub method: String,
    /// The parameter at fault.
    pub parameter: String,
    /// What is wrong with it.
    pub problem: String,
}

impl ParameterError {
    /// Always true: parameters come from a file or a caller.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

/// The method name of [`Extraction::ImportantPatches`].
pub const IMPORTANT_PATCHES: &str = "important-patches";

/// The parameter name of [`FitReport::lights_above_horizon`].
const LIGHTS_ABOVE_HORIZON: &str = "lights_above_horizon";

impl Extraction {
    /// The method's name in files (`median-cut`, ..., `sun`, or the unknown name as given).
    pub fn name(&self) -> &str {
        match self {
            Extraction::Unknown { name } => name,
            Extraction::ImportantPatches { .. } => IMPORTANT_PATCHES,
            other => other.source().map_or("", LightSource::name),
        }
    }

    /// The light source this run was, if this build knows it.
    pub fn source(&self) -> Option<LightSource> {
        Some(match self {
            Extraction::MedianCut { .. } => LightSource::Method(Method::MedianCut),
            Extraction::AdaptiveMedianCut => LightSource::Method(Method::AdaptiveMedianCut),
            Extraction::LightGen { .. } => LightSource::Method(Method::LightGen),
            Extraction::VarianceMinimization => LightSource::Method(Method::VarianceMinimization),
            Extraction::IrradianceOptimization(_) => {
                LightSource::Method(Method::IrradianceOptimization)
            }
            Extraction::DominantLight => LightSource::Sun,
            Extraction::ImportantPatches { .. } | Extraction::Unknown { .. } => return None,
        })
    }

    /// The fit report of an irradiance optimisation.
    pub fn fit_report(&self) -> Option<&FitReport> {
        match self {
            Extraction::IrradianceOptimization(r) => Some(r),
            _ => None,
        }
    }

    /// The parameters as named numbers (`converged` is 1 or 0), as files and reports hold them.
    pub fn parameters(&self) -> BTreeMap<String, f64> {
        let named = |pairs: &[(&str, f64)]| {
            pairs
                .iter()
                .map(|&(k, v)| (k.to_string(), v))
                .collect::<BTreeMap<String, f64>>()
        };
        match self {
            Extraction::MedianCut { splits } => named(&[("splits", f64::from(*splits))]),
            Extraction::ImportantPatches { patches } => named(&[("patches", f64::from(*patches))]),
            Extraction::LightGen { restarts, seed } => {
                named(&[("restarts", *restarts as f64), ("seed", *seed as f64)])
            }
            Extraction::IrradianceOptimization(r) => {
                let mut p = named(&[
                    ("iterations", r.iterations as f64),
                    ("total_iterations", r.total_iterations as f64),
                    ("converged", if r.converged { 1.0 } else { 0.0 }),
                    ("initial_cost", r.initial_cost),
                    ("final_cost", r.final_cost),
                    ("fit_rms_err_pct", r.fit_rms_err_pct),
                    ("fit_mean_abs_err_pct", r.fit_mean_abs_err_pct),
                    ("fit_normals", r.fit_normals as f64),
                ]);
                if let Some(k) = r.lights_above_horizon {
                    p.insert(LIGHTS_ABOVE_HORIZON.to_string(), k as f64);
                }
                p
            }
            Extraction::AdaptiveMedianCut
            | Extraction::VarianceMinimization
            | Extraction::DominantLight
            | Extraction::Unknown { .. } => BTreeMap::new(),
        }
    }

    /// Reads a run back from its name and parameters (a light file's `method`). A name this build
    /// does not know gives [`Extraction::Unknown`]; a known name needs its parameters, whole
    /// numbers where they count something, and unknown parameters are ignored (a newer file).
    pub fn from_parameters(
        name: &str,
        parameters: &BTreeMap<String, f64>,
    ) -> Result<Extraction, ParameterError> {
        let source = name.parse::<LightSource>();
        if source.is_err() && name != IMPORTANT_PATCHES {
            return Ok(Extraction::Unknown {
                name: name.to_string(),
            });
        }
        let number = |key: &str| -> Result<f64, ParameterError> {
            parameters.get(key).copied().ok_or_else(|| ParameterError {
                method: name.to_string(),
                parameter: key.to_string(),
                problem: "is missing".to_string(),
            })
        };
        let whole = |key: &str| -> Result<u64, ParameterError> {
            let v = number(key)?;
            if v.fract() == 0.0 && (0.0..=9_007_199_254_740_992.0).contains(&v) {
                Ok(v as u64)
            } else {
                Err(ParameterError {
                    method: name.to_string(),
                    parameter: key.to_string(),
                    problem: format!("must be a whole number (got {v})"),
                })
            }
        };
        let Ok(source) = source else {
            return Ok(Extraction::ImportantPatches {
                patches: u32::try_from(whole("patches")?).map_err(|_| ParameterError {
                    method: name.to_string(),
                    parameter: "patches".to_string(),
                    problem: "is too large".to_string(),
                })?,
            });
        };
        Ok(match source {
            LightSource::Sun => Extraction::DominantLight,
            LightSource::Method(Method::MedianCut) => Extraction::MedianCut {
                splits: u32::try_from(whole("splits")?).map_err(|_| ParameterError {
                    method: name.to_string(),
                    parameter: "splits".to_string(),
                    problem: "is too large".to_string(),
                })?,
            },
            LightSource::Method(Method::AdaptiveMedianCut) => Extraction::AdaptiveMedianCut,
            LightSource::Method(Method::VarianceMinimization) => Extraction::VarianceMinimization,
            LightSource::Method(Method::LightGen) => Extraction::LightGen {
                restarts: whole("restarts")? as usize,
                seed: whole("seed")?,
            },
            LightSource::Method(Method::IrradianceOptimization) => {
                Extraction::IrradianceOptimization(FitReport {
                    iterations: whole("iterations")? as usize,
                    total_iterations: whole("total_iterations")? as usize,
                    converged: number("converged")? != 0.0,
                    initial_cost: number("initial_cost")?,
                    final_cost: number("final_cost")?,
                    fit_rms_err_pct: number("fit_rms_err_pct")?,
                    fit_mean_abs_err_pct: number("fit_mean_abs_err_pct")?,
                    fit_normals: whole("fit_normals")? as usize,
                    // Absent in files of one whole-sphere fit (and in files before the
                    // hemispheres were fitted apart).
                    lights_above_horizon: match parameters.get(LIGHTS_ABOVE_HORIZON) {
                        Some(_) => Some(whole(LIGHTS_ABOVE_HORIZON)? as usize),
                        None => None,
                    },
                })
            }
        })
    }
}

/// What made a light set.
#[derive(Clone, Debug, PartialEq)]
pub struct Provenance {
    /// The method and its parameters.
    pub extraction: Extraction,
    /// The probe file it came from (`None` for a set extracted from an image in memory).
    pub probe: Option<ProbeRef>,
}

impl Provenance {
    /// A set extracted from an image in memory (no file known yet).
    pub fn extracted(extraction: Extraction) -> Provenance {
        Provenance {
            extraction,
            probe: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_round_trip_for_every_method() {
        let runs = [
            Extraction::MedianCut { splits: 4 },
            Extraction::AdaptiveMedianCut,
            Extraction::LightGen {
                restarts: 4,
                seed: 7,
            },
            Extraction::VarianceMinimization,
            Extraction::IrradianceOptimization(FitReport {
                iterations: 12,
                total_iterations: 40,
                converged: true,
                initial_cost: 0.5,
                final_cost: 0.125,
                fit_rms_err_pct: 1.5,
                fit_mean_abs_err_pct: 1.25,
                fit_normals: 4096,
                lights_above_horizon: None,
            }),
            Extraction::IrradianceOptimization(FitReport {
                iterations: 30,
                total_iterations: 90,
                converged: false,
                initial_cost: 0.75,
                final_cost: 0.25,
                fit_rms_err_pct: 2.5,
                fit_mean_abs_err_pct: 2.0,
                fit_normals: 6144,
                lights_above_horizon: Some(13),
            }),
            Extraction::DominantLight,
            Extraction::ImportantPatches { patches: 32 },
        ];
        for run in runs {
            let back = Extraction::from_parameters(run.name(), &run.parameters());
            assert_eq!(back, Ok(run));
        }
    }

    #[test]
    fn unknown_names_are_kept_and_bad_parameters_refused() {
        let none = BTreeMap::new();
        assert_eq!(
            Extraction::from_parameters("hand-made", &none),
            Ok(Extraction::Unknown {
                name: "hand-made".into()
            })
        );
        let e = Extraction::from_parameters("median-cut", &none).unwrap_err();
        assert_eq!(e.parameter, "splits");
        let half = BTreeMap::from([("splits".to_string(), 2.5)]);
        assert!(Extraction::from_parameters("median-cut", &half).is_err());
        // A fit's parameters with a fractional light count above the horizon.
        let mut fit = Extraction::IrradianceOptimization(FitReport::default()).parameters();
        fit.insert(LIGHTS_ABOVE_HORIZON.to_string(), 1.5);
        let e = Extraction::from_parameters("irradiance-optimization", &fit).unwrap_err();
        assert_eq!(e.parameter, LIGHTS_ABOVE_HORIZON);
    }
}
