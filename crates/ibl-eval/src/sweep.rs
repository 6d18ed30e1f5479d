//! The comparison sweep of Madsen & Laursen 2006, section 5: every extraction method at every
//! light count N on every probe, scored against the exact irradiance.
//!
//! For each probe the ground truth `g_k = E(n_k)` is computed once on M Fibonacci normals
//! (CONVENTIONS section 5, [`GroundTruth::fibonacci`], timed). Then for each method and N the
//! method runs through [`ibl_extract::extract`] (timed, wall clock), its light set gives
//! `e_k = sum_i I_i max(0, n_k . w_i)` on the same normals (data-parallel with rayon) and
//! [`GroundTruth::error_of`] turns the pair into the four metrics of [`ibl_metrics`]
//! (`mean_err%`, `max_err%`, `rel_mean%`, `rel_max%`, per cent of the channel's mean irradiance
//! or of the normal's own irradiance).
//!
//! A method that cannot make N lights (median cut and a count that is not a power of two) gives
//! a `skipped` row, and a method that fails (an error, a panic, or non-finite irradiance) a
//! `failed` row; both keep the reason and the sweep goes on. The fitted method is fitted on its
//! own normals, never on the scoring normals (`FIT_NORMALS_NOTE` of
//! [`mod@ibl_extract::irradiance_optimization`], recorded in the report).
//!
//! Each row also records the relative change of total power `100 mean_c((sum_i I_ic - P_c) /
//! P_c)` against the probe's power `P_c = sum_p L_pc dOmega_p` (CONVENTIONS section 4): region
//! methods conserve power, so theirs must be ~0 (rounding); fitted and clustered methods need not.
//!
//! The result is plain serde data ([`Report`], the `report.json` schema `iblkit.eval/1`) plus the
//! light sets at one chosen N for the figures. The library never prints: progress goes to a
//! callback.

use std::collections::BTreeMap;
use std::fmt;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use ibl_core::{Image, LatLong, Rgb};
use ibl_extract::{ExtractOptions, Model, ModelSpec};
use ibl_light::{LightSet, Method};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::GroundTruth;
use crate::report_files::ReportFiles;

/// The `format` field of `report.json`.
pub const REPORT_FORMAT: &str = "iblkit.eval/1";

/// One probe to evaluate: a lat-long radiance map (row 0 at the top, world frame) with the name
/// and file hash the report gives it.
#[derive(Clone, Copy, Debug)]
pub struct ProbeInput<'a> {
    /// Name in the report and in file names (normally the file stem).
    pub name: &'a str,
    /// SHA-256 of the probe file, lower-case hex.
    pub sha256: &'a str,
    /// The radiance map.
    pub image: &'a Image<Rgb>,
}

/// What to sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepOptions {
    /// Methods (lighting models: light sets, hybrids, SH), in the order the report lists them.
    pub methods: Vec<ModelSpec>,
    /// Light counts N (each at least 1), in the order the report lists them.
    pub counts: Vec<usize>,
    /// Number M of Fibonacci scoring normals (at least 1; 20000 in the paper).
    pub normals: usize,
    /// Settings passed to every method (seed of the randomised ones).
    pub extract: ExtractOptions,
    /// The light count whose light sets [`Sweep::sets`] keeps for figures (`None`: keep none).
    pub keep_sets_at: Option<usize>,
}

/// Why a sweep could not start.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepError(pub String);

impl fmt::Display for SweepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl SweepError {
    /// Always true: a sweep fails only on unusable options (see [`sweep`]).
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

impl std::error::Error for SweepError {}

/// The step a sweep is about to run (or [`Stage::Finished`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Exact irradiance of the probe on the scoring normals.
    GroundTruth,
    /// One method at one light count.
    Extract {
        /// The method.
        method: ModelSpec,
        /// The light count.
        n: usize,
    },
    /// Every step is done.
    Finished,
}

/// A progress report: sent before each step starts and once at the end.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepProgress {
    /// Steps finished so far.
    pub done: usize,
    /// Steps in the whole sweep: probes x (1 + methods x counts).
    pub total: usize,
    /// Name of the probe the step works on (empty when finished).
    pub probe: String,
    /// The step about to run.
    pub stage: Stage,
}

/// Outcome of one method at one N.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// The method ran and was scored.
    Ok,
    /// The method cannot make this many lights (e.g. median cut and N not a power of two).
    Skipped,
    /// The method returned an error, panicked, or gave non-finite irradiance.
    Failed,
}

/// One method at one N on one probe. Metrics are `None` unless the status is `ok`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Method name (`median-cut`, ...).
    pub method: String,
    /// Requested light count N.
    pub n: usize,
    /// Lights actually made (may differ from N if a method merges or drops lights).
    pub lights: Option<usize>,
    /// `100 mean_c(mean_k |e - g| / mu_c)`, per cent of the mean irradiance.
    pub mean_err_pct: Option<f64>,
    /// `100 mean_c(max_k |e - g| / mu_c)`, per cent of the mean irradiance.
    pub max_err_pct: Option<f64>,
    /// `100 mean_kc |e - g| / max(g, 1e-3 mu_c)`, per cent of each normal's irradiance.
    pub rel_mean_err_pct: Option<f64>,
    /// `100 max_kc |e - g| / max(g, 1e-3 mu_c)`, per cent of each normal's irradiance.
    pub rel_max_err_pct: Option<f64>,
    /// Wall-clock seconds of the extraction alone (not the scoring).
    pub seconds: Option<f64>,
    /// Relative change of total power, `100 mean_c((sum_i I_ic - P_c) / P_c)` over channels with
    /// `P_c > 0`, per cent; ~0 for region methods.
    pub power_change_pct: Option<f64>,
    /// `ok`, `skipped` or `failed`.
    pub status: Status,
    /// Why the row was skipped or failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The method's parameters and diagnostics (e.g. `splits`, `iterations`, `converged`);
    /// non-finite values are written as `null`.
    #[serde(default)]
    pub parameters: BTreeMap<String, serde_json::Value>,
}

/// One probe's results.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProbeReport {
    /// Probe name.
    pub name: String,
    /// SHA-256 of the probe file.
    pub sha256: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Wall-clock seconds of the ground truth on the scoring normals.
    pub ground_truth_seconds: f64,
    /// Mean ground-truth irradiance per channel `mu_c` (the scale of the `*_err_pct` metrics).
    pub mean_irradiance: [f64; 3],
    /// Probe power per channel `sum_p L_p dOmega_p` (radiance x sr).
    pub power: [f64; 3],
    /// One row per method and N, methods in sweep order, N in sweep order within a method.
    pub rows: Vec<Row>,
    /// The fast irradiance paths (no lights) against the exact ground truth on the same normals.
    #[serde(default)]
    pub fast_paths: Vec<FastPathRow>,
}

/// A fast approximation of the irradiance, scored like a method (see [`fast_paths`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FastPathRow {
    /// `blocks-64x32` (the probe reduced to energy-conserving blocks) or `sh<B>` (Lambert-convolved
    /// spherical harmonics of B bands).
    pub name: String,
    /// `mean_err%` against the exact ground truth.
    pub mean_err_pct: f64,
    /// `max_err%` against the exact ground truth.
    pub max_err_pct: f64,
    /// Wall-clock seconds (projection or reduction included).
    pub seconds: f64,
}

/// SH band counts scored as fast paths.
pub const FAST_PATH_SH_BANDS: [usize; 3] = [3, 9, 21];

/// The fast irradiance paths on one probe: the 64 x 32 block reduction and SH of
/// [`FAST_PATH_SH_BANDS`] bands, each scored against the exact ground truth.
pub fn fast_paths(image: &Image<Rgb>, truth: &GroundTruth) -> Vec<FastPathRow> {
    let row = |name: String, start: Instant, approx: Vec<[f64; 3]>| {
        let seconds = start.elapsed().as_secs_f64();
        let err = truth.error_of(&approx);
        FastPathRow {
            name,
            mean_err_pct: err.mean_err_pct,
            max_err_pct: err.max_err_pct,
            seconds,
        }
    };
    let start = Instant::now();
    let blocks = crate::irradiance_fast(image, &truth.normals, crate::FAST_DEFAULT_SIZE);
    let (bw, bh) = crate::FAST_DEFAULT_SIZE;
    let mut rows = vec![row(format!("blocks-{bw}x{bh}"), start, blocks)];
    for bands in FAST_PATH_SH_BANDS {
        let start = Instant::now();
        if let Ok(sh) = ibl_sh::project_latlong(image, bands) {
            let approx = sh
                .irradiance(ibl_sh::Window::None)
                .eval_many(&truth.normals);
            rows.push(row(format!("sh{bands}"), start, approx));
        }
    }
    rows
}

/// The mean over probes of one method at one N (only where every probe has an `ok` row).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AverageRow {
    /// Method name.
    pub method: String,
    /// Light count N.
    pub n: usize,
    /// Number of probes averaged (all of them).
    pub probes: usize,
    /// Mean over probes of `mean_err_pct`.
    pub mean_err_pct: f64,
    /// Mean over probes of `max_err_pct`.
    pub max_err_pct: f64,
    /// Mean over probes of `rel_mean_err_pct`.
    pub rel_mean_err_pct: f64,
    /// Mean over probes of `rel_max_err_pct`.
    pub rel_max_err_pct: f64,
    /// Mean over probes of the extraction seconds.
    pub seconds: f64,
}

/// The whole comparison: the `report.json` schema `iblkit.eval/1`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Always [`REPORT_FORMAT`].
    pub format: String,
    /// Version of iblkit that made the report.
    pub tool_version: String,
    /// Number M of Fibonacci scoring normals.
    pub normals: usize,
    /// Which normals the scores use.
    pub scoring_normals: String,
    /// Which normals the fitted method fits on (never the scoring normals).
    pub fit_normals_note: String,
    /// The metric definitions (CONVENTIONS section 5).
    pub metrics: BTreeMap<String, String>,
    /// Methods swept, in order.
    pub methods: Vec<String>,
    /// Light counts swept, in order.
    pub counts: Vec<usize>,
    /// Seed given to the randomised methods.
    pub seed: u64,
    /// Per-probe results.
    pub probes: Vec<ProbeReport>,
    /// Means over probes per method and N.
    pub averages: Vec<AverageRow>,
    /// The files written beside `report.json` (paths relative to it); empty until the caller
    /// writes them.
    #[serde(default)]
    pub files: ReportFiles,
}

/// The light set of one method at the kept N on one probe.
#[derive(Clone, Debug, PartialEq)]
pub struct KeptSet {
    /// Index of the probe in the input.
    pub probe: usize,
    /// The method.
    pub method: ModelSpec,
    /// The light count asked for.
    pub n: usize,
    /// The lights.
    pub set: LightSet,
}

/// A finished sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// Everything that goes into `report.json`.
    pub report: Report,
    /// The light sets at [`SweepOptions::keep_sets_at`] (ok rows only).
    pub sets: Vec<KeptSet>,
}

/// The metric definitions written into every report.
fn metric_definitions() -> BTreeMap<String, String> {
    [
        (
            "mean_err_pct",
            "100 mean_c(mean_k |e - g| / mu_c): mean error, per cent of the channel's mean irradiance mu_c",
        ),
        (
            "max_err_pct",
            "100 mean_c(max_k |e - g| / mu_c): max error, per cent of the channel's mean irradiance mu_c",
        ),
        (
            "rel_mean_err_pct",
            "100 mean_kc |e - g| / max(g, 1e-3 mu_c): mean error relative to each normal's irradiance",
        ),
        (
            "rel_max_err_pct",
            "100 max_kc |e - g| / max(g, 1e-3 mu_c): max error relative to each normal's irradiance",
        ),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect()
}

/// Probe power per channel `sum_p L_p dOmega_p`, per-row f64 sums then summed over rows in order
/// (CONVENTIONS section 4); invalid radiance counts as 0.
pub fn probe_power(probe: &Image<Rgb>) -> [f64; 3] {
    let ll = LatLong::new(probe.width().max(1), probe.height().max(1));
    let rows: Vec<[f64; 3]> = (0..probe.height())
        .into_par_iter()
        .map(|j| {
            let mut s = [0.0f64; 3];
            for px in probe.row(j) {
                for (sc, v) in s.iter_mut().zip(px.to_array()) {
                    if v.is_finite() && v > 0.0 {
                        *sc += f64::from(v);
                    }
                }
            }
            let omega = ll.row_solid_angle(j);
            s.map(|v| v * omega)
        })
        .collect();
    let mut p = [0.0f64; 3];
    for r in rows {
        for c in 0..3 {
            p[c] += r[c];
        }
    }
    p
}

/// `100 mean_c((set_c - probe_c) / probe_c)` over channels with `probe_c > 0` (`None` if none).
fn power_change_pct(set: [f64; 3], probe: [f64; 3]) -> Option<f64> {
    let changes: Vec<f64> = (0..3)
        .filter(|&c| probe[c] > 0.0)
        .map(|c| (set[c] - probe[c]) / probe[c])
        .collect();
    (!changes.is_empty()).then(|| 100.0 * changes.iter().sum::<f64>() / changes.len() as f64)
}

/// A JSON number, or `null` for a non-finite value.
fn json_number(v: f64) -> serde_json::Value {
    serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

/// A row with no metrics.
fn empty_row(method: ModelSpec, n: usize, status: Status, reason: Option<String>) -> Row {
    Row {
        method: method.to_string(),
        n,
        lights: None,
        mean_err_pct: None,
        max_err_pct: None,
        rel_mean_err_pct: None,
        rel_max_err_pct: None,
        seconds: None,
        power_change_pct: None,
        status,
        reason,
        parameters: BTreeMap::new(),
    }
}

/// The message of a caught panic.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Runs one method at one N and scores it; returns the row and, when it ran, its light set.
fn run_one(
    image: &Image<Rgb>,
    truth: &GroundTruth,
    power: [f64; 3],
    method: ModelSpec,
    n: usize,
    options: &ExtractOptions,
) -> (Row, Option<LightSet>) {
    if !method.accepts(n) {
        let reason = match method.method() {
            Some(Method::MedianCut) => {
                format!("median cut makes a power of two lights; {n} is not one")
            }
            _ => format!("{method} cannot make {n} lights"),
        };
        return (empty_row(method, n, Status::Skipped, Some(reason)), None);
    }
    let start = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| {
        ibl_extract::build_model(image, method, n, options)
    }));
    let seconds = start.elapsed().as_secs_f64();
    let (model, parameters) = match result {
        Ok(Ok(x)) => x,
        Ok(Err(e)) => {
            return (
                empty_row(method, n, Status::Failed, Some(e.to_string())),
                None,
            );
        }
        Err(payload) => {
            let reason = format!("panicked: {}", panic_message(payload.as_ref()));
            return (empty_row(method, n, Status::Failed, Some(reason)), None);
        }
    };
    let approx = model.irradiance_many(&truth.normals);
    let mut row = empty_row(method, n, Status::Ok, None);
    row.lights = Some(model.lights().map_or(0, |set| set.lights.len()));
    row.seconds = Some(seconds);
    row.parameters = parameters
        .iter()
        .map(|(k, v)| (k.clone(), json_number(*v)))
        .collect();
    row.power_change_pct = power_change_pct(model.total_power(), power);
    if approx.iter().flatten().any(|v| !v.is_finite()) {
        row.status = Status::Failed;
        row.reason = Some("the model gives non-finite irradiance".to_string());
        return (row, None);
    }
    let err = truth.error_of(&approx);
    row.mean_err_pct = Some(err.mean_err_pct);
    row.max_err_pct = Some(err.max_err_pct);
    row.rel_mean_err_pct = Some(err.rel_mean_err_pct);
    row.rel_max_err_pct = Some(err.rel_max_err_pct);
    let set = match model {
        Model::Lights(set) => Some(set),
        Model::Hybrid(h) => Some(h.lights),
        Model::Sh(_) => None,
    };
    (row, set)
}

/// Means over probes per method and N, where every probe has an `ok` row with every metric.
pub fn averages(probes: &[ProbeReport], methods: &[String], counts: &[usize]) -> Vec<AverageRow> {
    let mut out = Vec::new();
    if probes.is_empty() {
        return out;
    }
    for method in methods {
        for &n in counts {
            let rows: Option<Vec<&Row>> = probes
                .iter()
                .map(|p| {
                    p.rows
                        .iter()
                        .find(|r| &r.method == method && r.n == n && r.status == Status::Ok)
                })
                .collect();
            let Some(rows) = rows else { continue };
            let mean = |f: fn(&Row) -> Option<f64>| -> Option<f64> {
                let v: Option<Vec<f64>> = rows.iter().map(|r| f(r)).collect();
                v.map(|v| v.iter().sum::<f64>() / v.len() as f64)
            };
            let (Some(mean_err), Some(max_err), Some(rel_mean), Some(rel_max), Some(seconds)) = (
                mean(|r| r.mean_err_pct),
                mean(|r| r.max_err_pct),
                mean(|r| r.rel_mean_err_pct),
                mean(|r| r.rel_max_err_pct),
                mean(|r| r.seconds),
            ) else {
                continue;
            };
            out.push(AverageRow {
                method: method.clone(),
                n,
                probes: rows.len(),
                mean_err_pct: mean_err,
                max_err_pct: max_err,
                rel_mean_err_pct: rel_mean,
                rel_max_err_pct: rel_max,
                seconds,
            });
        }
    }
    out
}

/// Runs the sweep: ground truth per probe, then every method at every N, scored on the same
/// normals. `progress` is called before each step and once when finished.
///
/// Fails only on unusable options (no probes, methods or counts; M = 0; N = 0); a method that
/// fails for some N is recorded in its row and the sweep goes on.
pub fn sweep(
    probes: &[ProbeInput<'_>],
    options: &SweepOptions,
    progress: &(dyn Fn(SweepProgress) + Sync),
) -> Result<Sweep, SweepError> {
    if probes.is_empty() || options.methods.is_empty() || options.counts.is_empty() {
        return Err(SweepError(
            "a sweep needs at least one probe, one method and one light count".into(),
        ));
    }
    if options.normals == 0 {
        return Err(SweepError(
            "the number of scoring normals must be at least 1".into(),
        ));
    }
    if options.counts.contains(&0) {
        return Err(SweepError("light counts must be at least 1".into()));
    }
    let total = probes.len() * (1 + options.methods.len() * options.counts.len());
    let mut done = 0usize;
    let mut probe_reports = Vec::with_capacity(probes.len());
    let mut sets = Vec::new();
    for (index, probe) in probes.iter().enumerate() {
        progress(SweepProgress {
            done,
            total,
            probe: probe.name.to_string(),
            stage: Stage::GroundTruth,
        });
        let start = Instant::now();
        let truth = GroundTruth::fibonacci(probe.image, options.normals);
        let ground_truth_seconds = start.elapsed().as_secs_f64();
        let power = probe_power(probe.image);
        done += 1;
        let mut rows = Vec::with_capacity(options.methods.len() * options.counts.len());
        for &method in &options.methods {
            for &n in &options.counts {
                progress(SweepProgress {
                    done,
                    total,
                    probe: probe.name.to_string(),
                    stage: Stage::Extract { method, n },
                });
                let (row, set) = run_one(probe.image, &truth, power, method, n, &options.extract);
                rows.push(row);
                // Figures are of light sets alone: models with an SH part keep none.
                let keep =
                    options.keep_sets_at == Some(n) && matches!(method, ModelSpec::Lights(_));
                if let Some(set) = set.filter(|_| keep) {
                    sets.push(KeptSet {
                        probe: index,
                        method,
                        n,
                        set,
                    });
                }
                done += 1;
            }
        }
        probe_reports.push(ProbeReport {
            name: probe.name.to_string(),
            sha256: probe.sha256.to_string(),
            width: probe.image.width(),
            height: probe.image.height(),
            ground_truth_seconds,
            mean_irradiance: truth.mean,
            power,
            rows,
            fast_paths: fast_paths(probe.image, &truth),
        });
    }
    progress(SweepProgress {
        done,
        total,
        probe: String::new(),
        stage: Stage::Finished,
    });
    let methods: Vec<String> = options.methods.iter().map(|m| m.to_string()).collect();
    let averages = averages(&probe_reports, &methods, &options.counts);
    let report = Report {
        format: REPORT_FORMAT.to_string(),
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        normals: options.normals,
        scoring_normals: format!(
            "{} Fibonacci normals (CONVENTIONS section 5: y = 1 - (2k + 1) / M, a = k pi (3 - sqrt 5))",
            options.normals
        ),
        fit_normals_note: ibl_extract::irradiance_optimization::FIT_NORMALS_NOTE.to_string(),
        metrics: metric_definitions(),
        methods,
        counts: options.counts.clone(),
        seed: options.extract.seed,
        probes: probe_reports,
        averages,
        files: ReportFiles::default(),
    };
    Ok(Sweep { report, sets })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_change_ignores_black_channels() {
        assert_eq!(
            power_change_pct([1.0, 2.0, 0.0], [1.0, 1.0, 0.0]),
            Some(50.0)
        );
        assert_eq!(power_change_pct([1.0; 3], [0.0; 3]), None);
    }

    #[test]
    fn constant_probe_power_is_four_pi_l() {
        let img = Image::filled(64, 32, Rgb::new(1.0, 2.0, 0.5));
        let p = probe_power(&img);
        let four_pi = 4.0 * std::f64::consts::PI;
        for (c, l) in [1.0, 2.0, 0.5].into_iter().enumerate() {
            assert!((p[c] - four_pi * l).abs() < 1e-9, "{p:?}");
        }
    }

    #[test]
    fn non_finite_parameters_become_null() {
        assert_eq!(json_number(f64::NAN), serde_json::Value::Null);
        assert_eq!(json_number(2.0), serde_json::json!(2.0));
    }
}
