//! Irradiance optimisation (Madsen et al. 2003; Madsen & Laursen 2006, section 4.4): N
//! directional lights fitted in *irradiance* space.
//!
//! The probe's exact irradiance `G(n_k)` is computed on a set of M fitting normals
//! ([`fit_normals`]: 6144 Fibonacci normals turned away from the 20000 scoring normals, so scores
//! stay honest). Each light `i` has five parameters, its RGB power and its direction, and the
//! lights give `E_c(n) = sum_i I_ic max(0, n . w_i)` (`I = L A`, with the paper's fixed source size
//! `A` = [`SOURCE_SOLID_ANGLE_SR`], a 1 degree disc). The fit minimises
//!
//! ```text
//! F = 1/2 sum_k sum_c ((E_c(n_k) - G_c(n_k)) / mu_c)^2
//! ```
//!
//! where `mu_c` is the channel's mean irradiance, so every channel weighs as it does in the
//! error metrics of CONVENTIONS section 5.
//!
//! # Why it converges for every N (the paper's failed above 64)
//! * **Positivity by parameterisation.** Powers are `I = exp(s)`, so no step can make a light
//!   negative, and directions are moved in the tangent plane `w' = normalise(w + u t1 + v t2)`
//!   (re-centred every step), so there are no pole singularities and no angle wrap.
//! * **Levenberg-Marquardt with an analytic Jacobian and a trust test.** A step is kept only if
//!   the cost decreases; the damping follows Nielsen's gain-ratio rule. The cost can never rise,
//!   and the method stops at a stationary point.
//! * **Continuation with two ways to grow.** N lights start from the fitted `ceil(N/2)`, level
//!   by level from one light. A level grows in two ways, each followed by a short fit, and the
//!   better one goes on: *split* the strongest lights in two (half power each, a small angle
//!   apart: refines a sun or a window into several lights), or *insert* lights one at a time
//!   where they remove the most squared residual (matching pursuit over candidate directions:
//!   covers dim regions the strong lights leave short). Every level starts close to a good
//!   answer, so the dominant lights never "run away" with the energy before the weak ones have
//!   found theirs, the failure the paper describes.
//! * **Powers by non-negative least squares.** Whenever lights are added, the powers are first
//!   solved exactly for the fixed directions by NNLS ([`crate::nnls_gram`]); a light NNLS
//!   switches off is moved to the fitting normal with the largest deficit instead of being left
//!   dead.
//! * **Weak lights are moved.** A light the fit leaves with little power (below a tenth of the
//!   mean light's) drifts: Levenberg-Marquardt moves it a little per step for hundreds of steps
//!   while its log power swings, and gains little each time. After the final level such lights
//!   are taken out and put back where they remove the most residual (as in growth by
//!   insertion), the powers re-solved and the fit run again; the result is kept only if the cost
//!   is lower, for up to four rounds. On the bundled sky probe at N = 64 one round lowers the cost
//!   by about a quarter.
//! * **Convergence** is declared when three accepted steps in a row each lower the cost by less
//!   than [`OptimizationOptions::relative_tolerance`], when the residual is orthogonal to every
//!   Jacobian column to within a cosine of 1e-4 (MINPACK's `gtol`), or when no step lowers the
//!   cost even under heavy damping. [`FitReport::converged`] says whether one of these ended the
//!   fit rather than the iteration cap.
//!
//! # The lights' sources
//! The fit gives each light a direction and a power `I`; the paper's disc `A` only names a
//! radiance. A light shadowed by that disc is a point: 256 fitted lights render an indoor probe's
//! windows as 256 hard shadows. [`irradiance_optimization`] therefore sizes every fitted light by
//! its **cell**, the probe's pixels nearest its direction (module `light_cells`): its solid
//! angle becomes the cell's (radiance `I / Omega_cell`), and its spread and core fraction are
//! measured from the cell's power as for a LightGen cluster. The fit itself, its powers and its
//! directions are unchanged ([`fit_irradiance`], which has no probe, keeps the disc). On the
//! render study's scenes (converged, 64 spp; multiples of the reference's noise floor) this took
//! 16 lights from 140x to 44x indoors and from 28x to 6.5x outdoors (BENCHMARKS.md, "Fitted
//! lights sized by their cells").
//!
//! # The hemispheres apart
//! A light near the horizon may stand, in irradiance, for light from both sides of it, and a
//! ground plane then shadows it whole. [`crate::fit_hemispheres`] (what renders use) fits the
//! lights above and below the horizon apart, each set to its half of the probe: 32 lights went
//! from 42.5x to 2.3x the reference's noise floor indoors, at 2 to 8 times the whole-sphere
//! fit's unshadowed irradiance error.
//!
//! # Cost
//! The Jacobian has structure: with the light's features `c = n.w`, `a = n.t1`, `b = n.t2` (zero
//! where `n.w <= 0`) gathered in an M x 3N matrix `Phi`, every block of `J^T J` is a per-channel
//! weight times an entry of the Gram matrix `Phi^T Phi`, and the fitting normals are spread
//! evenly over the sphere, so that Gram matrix is taken in closed form (module `lune_gram`:
//! O(N^2), independent of M). It only chooses the step: the cost and the gradient are exact sums
//! over the normals (O(M N), in vector lanes: module `normal_lanes`), so a step is kept only if
//! it truly lowers the cost. (Against the exact `Phi^T Phi`, at twice the time, the fits end no
//! better.) The Cholesky solve costs O((5N)^3). Results are bit-identical whatever the thread
//! count.

use glam::{DMat3, DVec3};
use ibl_core::rgb::Rgb64;
use ibl_core::{Image, Rgb, RowIrradiance, channel_means, fibonacci_normals};
use ibl_light::{Extraction, FitReport, Light, LightSet, Provenance};
use nalgebra::{DMatrix, DMatrixViewMut, DVector};
use rayon::prelude::*;

use crate::cholesky::solve_spd;
use crate::lune_gram::{cosine_overlap, feature_block};
use crate::normal_lanes::{ChannelValues, NormalLanes};
use crate::{ExtractError, nnls_gram};

/// Number of fitting normals.
pub const FIT_NORMAL_COUNT: usize = 6144;

/// Solid angle given to every fitted light, sr: a disc of 1 degree, as the paper uses. The lights
/// [`irradiance_optimization`] returns are then sized by their cells of the probe (module doc).
pub const SOURCE_SOLID_ANGLE_SR: f64 = 2.392e-4;

/// Most lights one fit accepts.
pub const MAX_LIGHTS: usize = 1024;

/// What the fit is scored against, in words for reports: the fit never sees the scoring normals.
pub const FIT_NORMALS_NOTE: &str = "fitted on 6144 Fibonacci normals turned by 0.5 rad about the axis (1,1,1); scored on the 20000 Fibonacci normals of CONVENTIONS section 5";

/// Columns per parallel block of the Gram product in the power solve (fixed, so results do not
/// depend on the thread count).
const GRAM_BLOCK: usize = 32;

/// Optimisation settings. The fit is deterministic (no random choices).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OptimizationOptions {
    /// Most Levenberg-Marquardt iterations at the final level (a safety cap: fits on probes with
    /// small, very bright sources can need several hundred).
    pub max_iterations: usize,
    /// Most iterations at each intermediate continuation level.
    pub level_iterations: usize,
    /// Convergence: stop when three accepted steps in a row each lower the cost by less than this
    /// fraction.
    pub relative_tolerance: f64,
}

impl Default for OptimizationOptions {
    fn default() -> Self {
        OptimizationOptions {
            max_iterations: 2000,
            level_iterations: 20,
            relative_tolerance: 1e-3,
        }
    }
}

/// A fitted light set and its report.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The lights, strongest first.
    pub set: LightSet,
    /// How the fit went.
    pub report: FitReport,
}

/// The fitting normals: [`FIT_NORMAL_COUNT`] Fibonacci normals turned by 0.5 rad about
/// `(1, 1, 1)`, so that none coincides with the 20000 scoring normals.
pub fn fit_normals() -> Vec<DVec3> {
    let turn = DMat3::from_axis_angle(DVec3::ONE.normalize(), 0.5);
    fibonacci_normals(FIT_NORMAL_COUNT)
        .into_iter()
        .map(|n| (turn * n).normalize())
        .collect()
}

/// The fitting problem: normals, target irradiance and per-channel scales `1 / mu_c`.
struct Problem {
    normals: Vec<DVec3>,
    /// The normals again, in vector lanes.
    lanes: NormalLanes,
    /// Target irradiance per channel (padded like `lanes`).
    target: ChannelValues,
    inv_mu: [f64; 3],
    /// Where the lights may go.
    domain: LightDomain,
}

/// Lights being fitted: unit directions and log powers (`I = exp(s)`); a channel the probe does
/// not have (`mu_c = 0`) is ignored during the fit and written as 0.
#[derive(Clone, Debug)]
struct Lights {
    dirs: Vec<DVec3>,
    log_power: Vec<[f64; 3]>,
}

impl Lights {
    fn len(&self) -> usize {
        self.dirs.len()
    }

    fn power(&self, i: usize) -> [f64; 3] {
        self.log_power[i].map(f64::exp)
    }
}

/// Convergence on first-order optimality: largest cosine between the residual vector and a
/// Jacobian column.
const GRADIENT_TOLERANCE: f64 = 1e-4;

/// Convergence on the cost: this many accepted steps in a row each lowered it by less than the
/// relative tolerance (one small step may only mean heavy damping).
const SMALL_STEPS_TO_CONVERGE: usize = 3;

/// Fewest fitting normals [`fit_irradiance`] accepts.
const MIN_FIT_NORMALS: usize = 64;

/// A light is weak when its luminance power is below this share of the mean light's.
const WEAK_LIGHT_SHARE: f64 = 0.1;

/// Most rounds of moving weak lights after the final level's fit.
const RELOCATION_ROUNDS: usize = 4;

/// Candidate directions scanned for each light inserted at the deficits.
const INSERT_CANDIDATES: usize = 256;

/// Floor of a fitted power relative to the mean irradiance (keeps `log` finite).
const POWER_FLOOR: f64 = 1e-9;

/// Refuses a light count outside 1 to [`MAX_LIGHTS`].
pub(crate) fn check_light_count(n: usize) -> Result<(), ExtractError> {
    if n == 0 || n > MAX_LIGHTS {
        return Err(ExtractError::Parameter(format!(
            "irradiance optimisation fits 1 to {MAX_LIGHTS} lights; got {n}"
        )));
    }
    Ok(())
}

/// Irradiance optimisation into exactly `n` lights (see the module doc).
pub fn irradiance_optimization(
    probe: &Image<Rgb>,
    n: usize,
    options: &OptimizationOptions,
) -> Result<Fit, ExtractError> {
    if probe.width() == 0 || probe.height() == 0 {
        return Err(ExtractError::Invalid("the probe has no pixels".into()));
    }
    check_light_count(n)?;
    let normals = fit_normals();
    let target = RowIrradiance::new(probe).irradiance(&normals);
    let mut fit = fit_irradiance(normals, target, n, options)?;
    // Each light sized by the probe's pixels nearest it (module `light_cells`): its soft shadow
    // is its cell's, not the fit's 1-degree disc.
    let grid = crate::region_stats::Grid::new(probe)?;
    crate::light_cells::size_by_cells(probe, &grid, &mut fit.set.lights);
    Ok(fit)
}

/// Where a fit may put its lights' directions (world frame, +Y up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightDomain {
    /// Anywhere on the sphere (the paper's fit).
    Sphere,
    /// On or above the horizon (`y >= 0`): the lights of the upper half's fit
    /// ([`crate::fit_hemispheres`]).
    Above,
    /// On or below the horizon (`y <= 0`): the lights of the lower half's fit.
    Below,
}

impl LightDomain {
    /// `w` (unit) projected into the domain: a direction on the wrong side of the horizon is
    /// moved to the horizon at its own azimuth. A direction straight up or down that has no
    /// azimuth on the wrong side gives `None`.
    fn bound(self, w: DVec3) -> Option<DVec3> {
        let y = match self {
            LightDomain::Sphere => return Some(w),
            LightDomain::Above => w.y.max(0.0),
            LightDomain::Below => w.y.min(0.0),
        };
        DVec3::new(w.x, y, w.z).try_normalize()
    }

    /// Whether `w` lies in the domain.
    fn contains(self, w: DVec3) -> bool {
        match self {
            LightDomain::Sphere => true,
            LightDomain::Above => w.y >= 0.0,
            LightDomain::Below => w.y <= 0.0,
        }
    }
}

/// Fits `n` lights to the irradiance `target` given on `normals` (unit, world frame), by
/// continuation from one light (see the module doc). Public so that any irradiance data (a
/// measured or rendered one) can be fitted, not only a probe's.
///
/// The normals must cover the whole sphere evenly (as Fibonacci normals do; at least 64 of them):
/// the step is chosen with the closed-form Gram matrix of evenly spread normals. Normals whose
/// mean or second moment is far from an even spread's are refused with
/// [`ExtractError::Invalid`].
pub fn fit_irradiance(
    normals: Vec<DVec3>,
    target: Vec<[f64; 3]>,
    n: usize,
    options: &OptimizationOptions,
) -> Result<Fit, ExtractError> {
    fit_irradiance_in(normals, target, n, options, LightDomain::Sphere)
}

/// [`fit_irradiance`] with every light kept in `domain` throughout the fit: each step, split and
/// insertion that would take a light across the horizon puts it on the horizon instead
/// (a projected Levenberg-Marquardt step; the trust test still only keeps steps that lower the
/// cost). The halves of [`crate::fit_hemispheres`] are fitted so: a light of the upper half's fit
/// that drifted below the horizon would be shadowed whole by a ground plane, and one of the lower
/// half's that drifted above would light what the ground hides.
pub fn fit_irradiance_in(
    normals: Vec<DVec3>,
    target: Vec<[f64; 3]>,
    n: usize,
    options: &OptimizationOptions,
    domain: LightDomain,
) -> Result<Fit, ExtractError> {
    check_light_count(n)?;
    if normals.len() != target.len() {
        return Err(ExtractError::Invalid(format!(
            "{} normals for {} irradiance values (need equal counts)",
            normals.len(),
            target.len()
        )));
    }
    if let Some(problem) = uneven_spread(&normals) {
        return Err(ExtractError::Invalid(format!(
            "the fitting normals must cover the sphere evenly: {problem}"
        )));
    }
    let problem = Problem::new(normals, &target, domain);
    if problem.inv_mu.iter().all(|&v| v == 0.0) {
        return Ok(black_fit(n, problem.normals.len()));
    }
    // Continuation levels: n, ceil(n/2), ..., 1, fitted from the smallest.
    let mut levels = vec![n];
    while let Some(&last) = levels.last()
        && last > 1
    {
        levels.push(last.div_ceil(2));
    }
    levels.reverse();
    let mut lights = Lights {
        dirs: vec![problem.brightest_normal()],
        log_power: vec![[0.0; 3]],
    };
    let mut total_iterations = 0;
    let mut report = FitReport::default();
    for (li, &level) in levels.iter().enumerate() {
        let final_level = li + 1 == levels.len();
        if level > lights.len() || li == 0 {
            // Two ways to grow: split the strongest lights, or insert lights where the
            // irradiance is most lacking. Each gets a short fit; the better one goes on.
            let mut best: Option<(Lights, Outcome)> = None;
            for grow in [Growth::Split, Growth::Insert] {
                let mut candidate = lights.clone();
                match grow {
                    Growth::Split => split_strongest(&mut candidate, level, domain),
                    Growth::Insert => problem.insert_at_deficits(&mut candidate, level),
                }
                let outcome = problem.refit(&mut candidate, options.level_iterations, options);
                total_iterations += outcome.iterations;
                if best
                    .as_ref()
                    .is_none_or(|(_, b)| outcome.final_cost < b.final_cost)
                {
                    best = Some((candidate, outcome));
                }
                if li == 0 {
                    break; // one light: nothing to choose between
                }
            }
            if let Some((chosen, outcome)) = best {
                lights = chosen;
                if !final_level || outcome.converged {
                    if final_level {
                        report =
                            report_of(&problem, &outcome, outcome.iterations, total_iterations);
                    }
                    continue;
                }
            }
        }
        if final_level {
            let outcome = levenberg_marquardt(
                &problem,
                &mut lights,
                options.max_iterations,
                options.relative_tolerance,
            );
            total_iterations += outcome.iterations;
            report = report_of(&problem, &outcome, outcome.iterations, total_iterations);
        }
    }
    // Lights the fit left weak are moved to where the irradiance is most lacking.
    for _ in 0..RELOCATION_ROUNDS {
        let Some(mut candidate) = without_weak_lights(&lights) else {
            break;
        };
        problem.insert_at_deficits(&mut candidate, n);
        let outcome = problem.refit(&mut candidate, options.max_iterations, options);
        total_iterations += outcome.iterations;
        if outcome.final_cost >= report.final_cost {
            break;
        }
        lights = candidate;
        report = report_of(&problem, &outcome, outcome.iterations, total_iterations);
    }
    report.total_iterations = total_iterations;
    report.fit_mean_abs_err_pct = problem.mean_abs_err_pct(&lights);
    report.fit_normals = problem.normals.len();
    Ok(Fit {
        set: problem.light_set(&lights, &report),
        report,
    })
}

/// Why `normals` are not an even spread over the sphere, if they are not: each must be unit, at
/// least [`MIN_FIT_NORMALS`], their mean within 0.02 of zero and their second moment
/// `mean(n n^T)` within 0.02 of `I / 3` in every entry (Fibonacci normals: about 1e-4).
fn uneven_spread(normals: &[DVec3]) -> Option<String> {
    if normals.len() < MIN_FIT_NORMALS {
        return Some(format!(
            "{} normals, fewer than {MIN_FIT_NORMALS}",
            normals.len()
        ));
    }
    if let Some(k) = normals
        .iter()
        .position(|n| !n.is_finite() || (n.length() - 1.0).abs() > 1e-6)
    {
        return Some(format!("normal {k} is not a unit vector"));
    }
    let count = normals.len() as f64;
    let mean = normals.iter().sum::<DVec3>() / count;
    if mean.length() > 0.02 {
        return Some(format!("their mean has length {:.3}", mean.length()));
    }
    let moment = normals.iter().fold(DMat3::ZERO, |acc, n| {
        acc + DMat3::from_cols(*n * n.x, *n * n.y, *n * n.z)
    }) * (1.0 / count);
    let off = (moment - DMat3::from_diagonal(DVec3::splat(1.0 / 3.0)))
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    (off > 0.02).then(|| format!("their second moment is {off:.3} away from I/3"))
}

/// How a continuation level adds lights.
#[derive(Clone, Copy)]
enum Growth {
    /// Split the strongest lights ([`split_strongest`]).
    Split,
    /// Insert lights at the largest deficits ([`Problem::insert_at_deficits`]).
    Insert,
}

/// The report of a finished fit.
fn report_of(problem: &Problem, outcome: &Outcome, iterations: usize, total: usize) -> FitReport {
    FitReport {
        iterations,
        total_iterations: total,
        converged: outcome.converged,
        initial_cost: outcome.initial_cost,
        final_cost: outcome.final_cost,
        fit_rms_err_pct: 100.0
            * (2.0 * outcome.final_cost / (3 * problem.normals.len()) as f64).sqrt(),
        ..Default::default()
    }
}

/// `n` zero-power lights for a black probe (nothing to fit on `normals` normals; converged by
/// definition).
fn black_fit(n: usize, normals: usize) -> Fit {
    let lights = fibonacci_normals(n)
        .into_iter()
        .map(|d| Light {
            direction: d,
            radiance: Rgb::ZERO,
            solid_angle_sr: SOURCE_SOLID_ANGLE_SR,
            irradiance: Rgb64::ZERO,
            region: None,
            spread_sr: None,
            core_fraction: None,
            side: None,
        })
        .collect();
    let report = FitReport {
        converged: true,
        fit_normals: normals,
        ..Default::default()
    };
    Fit {
        set: LightSet {
            provenance: Provenance::extracted(Extraction::IrradianceOptimization(report.clone())),
            lights,
        },
        report,
    }
}

/// The lights without the weak ones (luminance power below [`WEAK_LIGHT_SHARE`] of the mean
/// light's), or `None` when no light is weak.
fn without_weak_lights(lights: &Lights) -> Option<Lights> {
    let lum: Vec<f64> = (0..lights.len())
        .map(|i| luminance(lights.power(i)))
        .collect();
    let mean = lum.iter().sum::<f64>() / lum.len().max(1) as f64;
    let keep: Vec<usize> = (0..lights.len())
        .filter(|&i| lum[i] >= WEAK_LIGHT_SHARE * mean)
        .collect();
    (keep.len() < lights.len()).then(|| Lights {
        dirs: keep.iter().map(|&i| lights.dirs[i]).collect(),
        log_power: keep.iter().map(|&i| lights.log_power[i]).collect(),
    })
}

/// Splits the strongest lights (by luminance power) until there are `count`: each becomes two
/// lights of half its power, a small angle apart along its first tangent.
fn split_strongest(lights: &mut Lights, count: usize, domain: LightDomain) {
    let mut order: Vec<usize> = (0..lights.len()).collect();
    order.sort_by(|&a, &b| luminance(lights.power(b)).total_cmp(&luminance(lights.power(a))));
    let spread = 0.25 * (4.0 * std::f64::consts::PI / count as f64).sqrt();
    for &i in order.iter().take(count - lights.len()) {
        let (t1, _) = tangents(lights.dirs[i]);
        let w = lights.dirs[i];
        let apart = |d: DVec3| domain.bound(d.normalize()).unwrap_or(w);
        lights.dirs[i] = apart(w + spread * t1);
        lights.dirs.push(apart(w - spread * t1));
        let half = lights.log_power[i].map(|s| s - std::f64::consts::LN_2);
        lights.log_power[i] = half;
        lights.log_power.push(half);
    }
}

/// Rec. 709 luminance of an RGB power (the project's weights, `Rgb64::luminance`).
fn luminance(p: [f64; 3]) -> f64 {
    Rgb64 {
        r: p[0],
        g: p[1],
        b: p[2],
    }
    .luminance()
}

/// An orthonormal tangent basis `(t1, t2)` at unit `w` (deterministic).
fn tangents(w: DVec3) -> (DVec3, DVec3) {
    let reference = if w.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t1 = w.cross(reference).normalize();
    (t1, w.cross(t1))
}

/// Where one Levenberg-Marquardt run ended.
struct Outcome {
    iterations: usize,
    converged: bool,
    initial_cost: f64,
    final_cost: f64,
}

impl Problem {
    /// The problem of fitting `target` on `normals` (equal counts), each channel scaled by its
    /// mean.
    fn new(normals: Vec<DVec3>, target: &[[f64; 3]], domain: LightDomain) -> Problem {
        let inv_mu = channel_means(target).map(|m| {
            if m.is_finite() && m > 0.0 {
                1.0 / m
            } else {
                0.0
            }
        });
        let lanes = NormalLanes::new(&normals);
        Problem {
            target: lanes.pad(target),
            normals,
            lanes,
            inv_mu,
            domain,
        }
    }

    /// Fits lights that were just added or moved: powers by NNLS, then Levenberg-Marquardt for
    /// at most `max_iterations`.
    fn refit(
        &self,
        lights: &mut Lights,
        max_iterations: usize,
        options: &OptimizationOptions,
    ) -> Outcome {
        self.solve_powers(lights);
        levenberg_marquardt(self, lights, max_iterations, options.relative_tolerance)
    }

    /// The fitting normal with the largest luminance-weighted irradiance (the start of the
    /// one-light fit).
    fn brightest_normal(&self) -> DVec3 {
        let score = |k: usize| {
            (0..3)
                .map(|c| self.target[c][k] * self.inv_mu[c])
                .sum::<f64>()
        };
        let home = match self.domain {
            LightDomain::Below => DVec3::NEG_Y,
            _ => DVec3::Y,
        };
        (0..self.normals.len())
            .filter(|&k| self.domain.contains(self.normals[k]))
            .max_by(|&a, &b| score(a).total_cmp(&score(b)))
            .map_or(home, |k| self.normals[k])
    }

    /// Adds lights until there are `count`, one at a time, each where it removes the most
    /// squared residual (matching pursuit): among [`INSERT_CANDIDATES`] fitting normals as
    /// candidate directions `w`, the one maximising `sum_c max(0, q_c(w))^2 / d(w)`, with
    /// `q_c(w) = sum_k d_kc phi_k(w)` against the scaled deficit `d`, `d(w) = sum_k phi_k(w)^2` and
    /// `phi_k(w) = max(0, n_k . w)`. The light gets the optimal power `q / d`; every candidate's
    /// `q` then loses that light's share, through the closed-form overlap of two cosine lobes
    /// ([`cosine_overlap`]). Cost O(M INSERT_CANDIDATES) once, then O(INSERT_CANDIDATES) per
    /// light; the powers are solved exactly afterwards ([`Problem::solve_powers`]).
    fn insert_at_deficits(&self, lights: &mut Lights, count: usize) {
        let (r, _) = self.residuals(lights);
        let deficit: ChannelValues = r.map(|v| v.into_iter().map(|x| -x).collect());
        let step = (self.normals.len() / INSERT_CANDIDATES).max(1);
        let candidates: Vec<DVec3> = self
            .normals
            .iter()
            .step_by(step)
            .copied()
            .filter(|&w| self.domain.contains(w))
            .collect();
        let mut sums: Vec<([f64; 3], f64)> = candidates
            .par_iter()
            .map(|w| self.lanes.pursuit_sums(*w, &deficit))
            .collect();
        let m = self.normals.len();
        while lights.len() < count {
            let gain = |(q, d): &([f64; 3], f64)| {
                q.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>() / d.max(1e-300)
            };
            let Some(best) = (0..sums.len())
                .max_by(|&a, &b| gain(&sums[a]).total_cmp(&gain(&sums[b])).then(b.cmp(&a)))
            else {
                break;
            };
            let w = candidates[best];
            let (q, d) = sums[best];
            let scaled_power = q.map(|v| v.max(0.0) / d.max(1e-300));
            for (candidate, (q, _)) in candidates.iter().zip(sums.iter_mut()) {
                let overlap = cosine_overlap(*candidate, w, m);
                for c in 0..3 {
                    q[c] -= scaled_power[c] * overlap;
                }
            }
            let power = [0, 1, 2].map(|c| {
                let mu = if self.inv_mu[c] > 0.0 {
                    1.0 / self.inv_mu[c]
                } else {
                    0.0
                };
                (scaled_power[c] * mu)
                    .max(POWER_FLOOR * mu)
                    .max(f64::MIN_POSITIVE)
            });
            lights.dirs.push(w);
            lights.log_power.push(power.map(f64::ln));
        }
    }

    /// Mean over normals and channels of `|E - G| / mu`, % (the reported mean error, on the
    /// fitting normals).
    fn mean_abs_err_pct(&self, lights: &Lights) -> f64 {
        let (r, _) = self.residuals(lights);
        let channels = self.inv_mu.iter().filter(|&&v| v > 0.0).count().max(1);
        let sum: f64 = r.iter().flatten().map(|v| v.abs()).sum();
        100.0 * sum / (self.normals.len() * channels) as f64
    }

    /// Scaled residuals `r_kc = (E_c(n_k) - G_kc) / mu_c` (padded, see [`NormalLanes`]) and the
    /// cost `1/2 |r|^2`. O(M N).
    fn residuals(&self, lights: &Lights) -> (ChannelValues, f64) {
        let powers: Vec<[f64; 3]> = (0..lights.len()).map(|i| lights.power(i)).collect();
        self.lanes
            .residuals(&lights.dirs, &powers, &self.target, self.inv_mu)
    }

    /// The gated cosine matrix `A_ki = max(0, n_k . w_i)` (M x N, column-major).
    fn cosines(&self, dirs: &[DVec3]) -> DMatrix<f64> {
        let m = self.normals.len();
        let mut a = DMatrix::zeros(m, dirs.len());
        a.as_mut_slice()
            .par_chunks_mut(m)
            .zip(dirs)
            .for_each(|(col, w)| {
                for (v, n) in col.iter_mut().zip(&self.normals) {
                    *v = n.dot(*w).max(0.0);
                }
            });
        a
    }

    /// Solves the powers for fixed directions by NNLS per channel; a light switched off is moved
    /// to the fitting normal with the largest remaining deficit and the powers are solved again
    /// (at most twice), then every power is floored for the log parameterisation.
    fn solve_powers(&self, lights: &mut Lights) {
        for round in 0..3 {
            let a = self.cosines(&lights.dirs);
            let q = gram(&a);
            let mut dead = vec![true; lights.len()];
            for ch in 0..3 {
                if self.inv_mu[ch] == 0.0 {
                    continue;
                }
                let y = DVector::from_column_slice(&self.target[ch][..self.normals.len()]);
                let b = a.tr_mul(&y);
                let x = nnls_gram(&q, &b);
                let floor = POWER_FLOOR / self.inv_mu[ch];
                for i in 0..lights.len() {
                    if x[i] > floor {
                        dead[i] = false;
                    }
                    lights.log_power[i][ch] = x[i].max(floor).ln();
                }
            }
            if round == 2 || !dead.iter().any(|&d| d) {
                break;
            }
            // Re-aim dead lights at the worst deficits (largest target minus fit, scaled) among
            // the normals in the domain.
            let (r, _) = self.residuals(lights);
            let mut deficit: Vec<(usize, f64)> = (0..self.normals.len())
                .filter(|&k| self.domain.contains(self.normals[k]))
                .map(|k| (k, -(r[0][k] + r[1][k] + r[2][k])))
                .collect();
            deficit.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            let mut next = deficit.iter();
            for (i, d) in dead.iter().enumerate() {
                if *d && let Some(&(k, _)) = next.next() {
                    lights.dirs[i] = self.normals[k];
                }
            }
        }
        for p in &mut lights.log_power {
            for (ch, s) in p.iter_mut().enumerate() {
                if self.inv_mu[ch] == 0.0 {
                    *s = (POWER_FLOOR).ln();
                }
            }
        }
    }

    /// The Gauss-Newton normal equations: writes the lower triangle of `H = J^T J` (5N x 5N,
    /// parameters per light `u, v, s_r, s_g, s_b`; the upper triangle is left as it was) into `h`
    /// and returns `g = J^T r`. See the module doc for the structure used: the gradient is exact,
    /// O(M N); `H` is built pair by pair from the closed-form Gram blocks, O(N^2).
    fn normal_equations(
        &self,
        lights: &Lights,
        r: &ChannelValues,
        h: &mut DMatrix<f64>,
    ) -> DVector<f64> {
        let nl = lights.len();
        let m = self.normals.len();
        let basis: Vec<(DVec3, DVec3)> = lights.dirs.iter().map(|w| tangents(*w)).collect();
        // Per light and channel, S = sum of r n over the normals facing the light: the features
        // c, a, b summed against the residual are w.S, t1.S, t2.S.
        let sums: Vec<[DVec3; 3]> = lights
            .dirs
            .par_iter()
            .map(|&w| self.lanes.lit_residual_sums(w, r))
            .collect();
        // alpha_ic = I_ic / mu_c: the Jacobian's per-light, per-channel factor.
        let alpha: Vec<[f64; 3]> = (0..nl)
            .map(|i| {
                let p = lights.power(i);
                [0, 1, 2].map(|c| p[c] * self.inv_mu[c])
            })
            .collect();
        let np = 5 * nl;
        let mut g = DVector::zeros(np);
        for i in 0..nl {
            let (w, (t1, t2)) = (lights.dirs[i], basis[i]);
            for c in 0..3 {
                g[5 * i] += alpha[i][c] * t1.dot(sums[i][c]);
                g[5 * i + 1] += alpha[i][c] * t2.dot(sums[i][c]);
                g[5 * i + 2 + c] = alpha[i][c] * w.dot(sums[i][c]);
            }
        }
        h.as_mut_slice()
            .par_chunks_mut(np * 5)
            .enumerate()
            .for_each(|(j, cols)| {
                // Columns 5j..5j+5 of H (column-major), rows of lights i >= j.
                for i in j..nl {
                    // q[x][y]: features x of light i against y of light j (0 = c, 1 = a, 2 = b).
                    let q = feature_block(lights.dirs[i], basis[i], lights.dirs[j], basis[j], m);
                    let w = [0, 1, 2].map(|c| alpha[i][c] * alpha[j][c]);
                    let ws = w[0] + w[1] + w[2];
                    let mut set = |row: usize, col: usize, v: f64| cols[col * np + 5 * i + row] = v;
                    set(0, 0, ws * q[1][1]);
                    set(1, 0, ws * q[2][1]);
                    set(0, 1, ws * q[1][2]);
                    set(1, 1, ws * q[2][2]);
                    for (c, wc) in w.into_iter().enumerate() {
                        set(2 + c, 0, wc * q[0][1]);
                        set(2 + c, 1, wc * q[0][2]);
                        set(0, 2 + c, wc * q[1][0]);
                        set(1, 2 + c, wc * q[2][0]);
                        for c2 in 0..3 {
                            set(2 + c, 2 + c2, if c == c2 { wc * q[0][0] } else { 0.0 });
                        }
                    }
                }
            });
        g
    }

    /// The fitted lights as a light set, strongest (luminance power) first, with the fit's report
    /// as its provenance.
    fn light_set(&self, lights: &Lights, report: &FitReport) -> LightSet {
        let mut out: Vec<Light> = (0..lights.len())
            .map(|i| {
                let p = lights.power(i);
                let irradiance = [0, 1, 2].map(|c| if self.inv_mu[c] == 0.0 { 0.0 } else { p[c] });
                let radiance = irradiance.map(|v| (v / SOURCE_SOLID_ANGLE_SR) as f32);
                Light {
                    direction: lights.dirs[i],
                    radiance: Rgb::new(radiance[0], radiance[1], radiance[2]),
                    solid_angle_sr: SOURCE_SOLID_ANGLE_SR,
                    irradiance: Rgb64::from_array(irradiance),
                    spread_sr: None,
                    core_fraction: None,
                    side: None,
                    region: None,
                }
            })
            .collect();
        let lum = |l: &Light| l.irradiance.luminance();
        out.sort_by(|a, b| lum(b).total_cmp(&lum(a)));
        LightSet {
            provenance: Provenance::extracted(Extraction::IrradianceOptimization(report.clone())),
            lights: out,
        }
    }
}

/// `X^T X` for a tall column-major matrix: its lower triangle by blocks of [`GRAM_BLOCK`] columns
/// (one matrix product each, in parallel), mirrored to the upper. O(M N^2 / 2).
pub(crate) fn gram(x: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = x.shape();
    let mut q = DMatrix::zeros(n, n);
    if n == 0 || m == 0 {
        return q;
    }
    // nalgebra's `gemm_tr` is a loop of dot products; `gemm` on the transpose is a blocked product.
    let xt = x.transpose();
    q.as_mut_slice()
        .par_chunks_mut(GRAM_BLOCK * n)
        .enumerate()
        .for_each(|(b, cols)| {
            let c0 = b * GRAM_BLOCK;
            let width = cols.len() / n;
            let mut block = DMatrixViewMut::from_slice(cols, n, width);
            block
                .rows_mut(c0, n - c0)
                .gemm(1.0, &xt.rows(c0, n - c0), &x.columns(c0, width), 0.0);
        });
    q.fill_upper_triangle_with_lower_triangle();
    q
}

/// Damped Gauss-Newton (Levenberg-Marquardt) on `lights`, at most `max_iterations` iterations.
fn levenberg_marquardt(
    problem: &Problem,
    lights: &mut Lights,
    max_iterations: usize,
    relative_tolerance: f64,
) -> Outcome {
    let (mut r, mut cost) = problem.residuals(lights);
    let initial_cost = cost;
    let mut lambda = 1e-3;
    let mut nu = 2.0;
    let mut iterations = 0;
    let mut converged = false;
    let mut small_steps = 0;
    // H (lower triangle) and the damped copy that is factored in place: allocated once per run.
    let np = 5 * lights.len();
    let mut h = DMatrix::zeros(np, np);
    let mut a = DMatrix::zeros(np, np);
    let mut hd = DVector::zeros(np);
    while iterations < max_iterations {
        iterations += 1;
        if cost <= 1e-30 {
            converged = true;
            break;
        }
        let g = problem.normal_equations(lights, &r, &mut h);
        // First-order optimality (MINPACK's gtol): the residual is orthogonal to every Jacobian
        // column to within GRADIENT_TOLERANCE (cosine of the angle between them).
        let r_norm = (2.0 * cost).sqrt();
        let cosine = (0..g.len())
            .map(|j| g[j].abs() / (h[(j, j)].sqrt() * r_norm).max(f64::MIN_POSITIVE))
            .fold(0.0f64, f64::max);
        if cosine <= GRADIENT_TOLERANCE {
            converged = true;
            break;
        }
        let max_diag = (0..h.nrows()).map(|i| h[(i, i)]).fold(0.0f64, f64::max);
        let floor = 1e-6 * max_diag.max(f64::MIN_POSITIVE);
        let mut accepted = false;
        while lambda < 1e16 {
            a.copy_from(&h);
            for i in 0..np {
                a[(i, i)] += lambda * h[(i, i)].max(floor);
            }
            let delta = solve_spd(&a, &(-&g));
            let Some(delta) = delta else {
                lambda *= nu;
                nu *= 2.0;
                continue;
            };
            let trial = apply_step(lights, &delta, problem.domain);
            let (tr, tcost) = problem.residuals(&trial);
            // Predicted reduction of the quadratic model: -g.d - 1/2 d.H.d (H's lower triangle).
            hd.sygemv(1.0, &h, &delta, 0.0);
            let predicted = -g.dot(&delta) - 0.5 * delta.dot(&hd);
            if tcost < cost && tcost.is_finite() {
                let rho = if predicted > 0.0 {
                    (cost - tcost) / predicted
                } else {
                    1.0
                };
                lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                let decrease = (cost - tcost) / cost;
                *lights = trial;
                r = tr;
                cost = tcost;
                accepted = true;
                if decrease < relative_tolerance {
                    small_steps += 1;
                    converged = small_steps >= SMALL_STEPS_TO_CONVERGE;
                } else {
                    small_steps = 0;
                }
                break;
            }
            lambda *= nu;
            nu *= 2.0;
        }
        if !accepted {
            // No step lowers the cost even with heavy damping: a stationary point.
            converged = true;
        }
        if converged {
            break;
        }
    }
    Outcome {
        iterations,
        converged,
        initial_cost,
        final_cost: cost,
    }
}

/// The lights after a parameter step `delta` (`u, v, s_r, s_g, s_b` per light); log-power steps
/// are limited to +-4 (a factor of 55) per iteration.
fn apply_step(lights: &Lights, delta: &DVector<f64>, domain: LightDomain) -> Lights {
    let mut out = lights.clone();
    for i in 0..lights.len() {
        let w = lights.dirs[i];
        let (t1, t2) = tangents(w);
        let moved = w + delta[5 * i] * t1 + delta[5 * i + 1] * t2;
        out.dirs[i] = moved
            .try_normalize()
            .and_then(|m| domain.bound(m))
            .unwrap_or(w);
        for c in 0..3 {
            out.log_power[i][c] += delta[5 * i + 2 + c].clamp(-4.0, 4.0);
        }
    }
    out
}
