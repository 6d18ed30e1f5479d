//! The comparison report as text: `report.csv` (one line per probe, method and N) and
//! `report.md`, a short summary of which method needs how many lights for 1 % and 5 % error, in
//! memory as `String`s (the caller writes them).
//!
//! "Lights needed for X %" is the smallest N in the sweep whose error is at or below X %
//! (`mean_err%` or `max_err%` of CONVENTIONS section 5, per cent of the channel's mean irradiance,
//! averaged over RGB); it is read off the sweep, not interpolated, and an error curve need not be
//! monotonic, so a larger N can be above X % again. `> N_max` means no N in the sweep reached it.
//! Averages over probes exist only where every probe has an `ok` row.

use std::fmt::Write as _;

use crate::sweep::{AverageRow, FastPathRow, Report, Row, Status};

/// The header line of `report.csv`.
pub const CSV_HEADER: &str = "probe,method,n,lights,mean_err_pct,max_err_pct,rel_mean_err_pct,rel_max_err_pct,seconds,status";

/// The error thresholds of the summary, per cent of the mean irradiance.
pub const THRESHOLDS_PCT: [f64; 2] = [1.0, 5.0];

/// Light counts whose method averages `report.md` tabulates (when they were swept).
pub const SUMMARY_COUNTS: [usize; 2] = [16, 64];

/// A CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// An optional number for CSV: shortest round-trip form, or empty.
fn csv_number(v: Option<f64>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

/// The status word of a row.
fn status_name(s: Status) -> &'static str {
    match s {
        Status::Ok => "ok",
        Status::Skipped => "skipped",
        Status::Failed => "failed",
    }
}

/// `report.csv`: [`CSV_HEADER`] then one line per probe, method and N (the rows of
/// `report.json`, in its order); missing values are empty fields.
pub fn csv(report: &Report) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for p in &report.probes {
        for r in &p.rows {
            let _ = writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{}",
                csv_field(&p.name),
                csv_field(&r.method),
                r.n,
                r.lights.map(|l| l.to_string()).unwrap_or_default(),
                csv_number(r.mean_err_pct),
                csv_number(r.max_err_pct),
                csv_number(r.rel_mean_err_pct),
                csv_number(r.rel_max_err_pct),
                csv_number(r.seconds),
                status_name(r.status),
            );
        }
    }
    out
}

/// `(n, mean_err%, max_err%)` points of one method.
type Points = Vec<(usize, f64, f64)>;

/// The smallest N of `points` whose error (mean or max, picked by `error`) is at or below
/// `threshold`.
fn smallest_n(
    points: &Points,
    error: fn(&(usize, f64, f64)) -> f64,
    threshold: f64,
) -> Option<usize> {
    points
        .iter()
        .filter(|p| error(p) <= threshold)
        .map(|(n, _, _)| *n)
        .min()
}

/// How many lights one method needs for each threshold of [`THRESHOLDS_PCT`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LightsNeeded {
    /// Method name.
    pub method: String,
    /// Number of N with a score (0: the method never ran successfully).
    pub scored: usize,
    /// Smallest N with `mean_err% <=` each threshold (`None`: no N in the sweep reached it).
    pub mean_err: [Option<usize>; 2],
    /// Smallest N with `max_err% <=` each threshold.
    pub max_err: [Option<usize>; 2],
}

impl LightsNeeded {
    fn from_points(method: &str, points: &Points) -> Self {
        LightsNeeded {
            method: method.to_string(),
            scored: points.len(),
            mean_err: THRESHOLDS_PCT.map(|t| smallest_n(points, |p| p.1, t)),
            max_err: THRESHOLDS_PCT.map(|t| smallest_n(points, |p| p.2, t)),
        }
    }

    /// Per method, from the averages over every probe.
    pub fn average(report: &Report) -> Vec<LightsNeeded> {
        report
            .methods
            .iter()
            .map(|m| Self::from_points(m, &average_points(&report.averages, m)))
            .collect()
    }

    /// Per method, on probe `index` (empty if there is no such probe).
    pub fn for_probe(report: &Report, index: usize) -> Vec<LightsNeeded> {
        let Some(p) = report.probes.get(index) else {
            return Vec::new();
        };
        report
            .methods
            .iter()
            .map(|m| Self::from_points(m, &probe_points(&p.rows, m)))
            .collect()
    }

    /// The four cells `mean <= 1 %, mean <= 5 %, max <= 1 %, max <= 5 %` as text: N, `> largest`
    /// when none reached it, or `no data`.
    pub fn cells(&self, largest: usize) -> [String; 4] {
        let cell = |v: Option<usize>| {
            if self.scored == 0 {
                "no data".to_string()
            } else {
                v.map_or_else(|| format!("> {largest}"), |n| n.to_string())
            }
        };
        [
            cell(self.mean_err[0]),
            cell(self.mean_err[1]),
            cell(self.max_err[0]),
            cell(self.max_err[1]),
        ]
    }
}

/// Points of one method on one probe (ok rows only).
fn probe_points(rows: &[Row], method: &str) -> Points {
    rows.iter()
        .filter(|r| r.method == method && r.status == Status::Ok)
        .filter_map(|r| Some((r.n, r.mean_err_pct?, r.max_err_pct?)))
        .collect()
}

/// Points of one method averaged over probes.
fn average_points(averages: &[AverageRow], method: &str) -> Points {
    averages
        .iter()
        .filter(|a| a.method == method)
        .map(|a| (a.n, a.mean_err_pct, a.max_err_pct))
        .collect()
}

/// A percentage with three significant digits (`-` when missing).
fn pct(v: Option<f64>) -> String {
    match v {
        None => "-".to_string(),
        Some(v) if !v.is_finite() => v.to_string(),
        Some(v) if v == 0.0 || v.abs() >= 100.0 => format!("{v:.0}"),
        Some(v) if v.abs() >= 10.0 => format!("{v:.1}"),
        Some(v) if v.abs() >= 1.0 => format!("{v:.2}"),
        Some(v) => format!("{v:.3}"),
    }
}

/// Writes the "lights needed" tables.
fn write_needed(out: &mut String, report: &Report) {
    let largest = report.counts.iter().copied().max().unwrap_or(0);
    let head = "| mean_err <= 1 % | mean_err <= 5 % | max_err <= 1 % | max_err <= 5 % |";
    let rule = "|---|---:|---:|---:|---:|";
    let k = report.probes.len();
    let _ = writeln!(out, "## Lights needed for 1 % and 5 % error\n");
    let _ = writeln!(
        out,
        "Smallest N in the sweep ({}) whose error is at or below the threshold; `> {largest}`: \
         no N reached it; `no data`: no N ran on every probe.\n",
        list(&report.counts)
    );
    let _ = writeln!(out, "### Average over {k} probe{}\n", plural(k));
    let _ = writeln!(out, "| method {head}\n{rule}");
    for x in LightsNeeded::average(report) {
        let _ = writeln!(out, "| {} | {} |", x.method, x.cells(largest).join(" | "));
    }
    let _ = writeln!(out, "\n### Per probe\n");
    let _ = writeln!(out, "| probe | method {head}\n|---{rule}");
    for (i, p) in report.probes.iter().enumerate() {
        for x in LightsNeeded::for_probe(report, i) {
            let cells = x.cells(largest).join(" | ");
            let _ = writeln!(out, "| {} | {} | {cells} |", p.name, x.method);
        }
    }
    out.push('\n');
}

/// Writes the method averages at [`SUMMARY_COUNTS`].
fn write_averages_at(out: &mut String, report: &Report) {
    let counts: Vec<usize> = SUMMARY_COUNTS
        .into_iter()
        .filter(|n| report.counts.contains(n))
        .collect();
    let _ = writeln!(out, "## Method averages at N = {}\n", list(&SUMMARY_COUNTS));
    if counts.is_empty() {
        let _ = writeln!(
            out,
            "Not swept (the sweep's N: {}).\n",
            list(&report.counts)
        );
        return;
    }
    let _ = writeln!(
        out,
        "Mean over the probes; `-` where some probe has no `ok` row.\n\n\
         | method | N | mean_err % | max_err % | rel_mean % | rel_max % | seconds |\n\
         |---|---:|---:|---:|---:|---:|---:|"
    );
    for m in &report.methods {
        for &n in &counts {
            match report.averages.iter().find(|a| &a.method == m && a.n == n) {
                Some(a) => {
                    let _ = writeln!(
                        out,
                        "| {m} | {n} | {} | {} | {} | {} | {:.3} |",
                        pct(Some(a.mean_err_pct)),
                        pct(Some(a.max_err_pct)),
                        pct(Some(a.rel_mean_err_pct)),
                        pct(Some(a.rel_max_err_pct)),
                        a.seconds
                    );
                }
                None => {
                    let _ = writeln!(out, "| {m} | {n} | - | - | - | - | - |");
                }
            }
        }
    }
    out.push('\n');
}

/// Writes the fast irradiance paths (block reduction, SH) averaged over the probes.
fn write_fast_paths(out: &mut String, report: &Report) {
    let Some(first) = report.probes.first() else {
        return;
    };
    let _ = writeln!(
        out,
        "## Fast irradiance paths against the exact ground truth\n\n\
         No lights: the probe reduced to energy-conserving blocks, or its spherical harmonics \
         Lambert-convolved (`shB` = B bands; sh3 is the usual 9 coefficients). Mean over the \
         probes.\n\n\
         | path | mean_err % | max_err % | seconds |\n\
         |---|---:|---:|---:|"
    );
    for (i, path) in first.fast_paths.iter().enumerate() {
        let rows: Vec<&FastPathRow> = report
            .probes
            .iter()
            .filter_map(|p| p.fast_paths.get(i).filter(|r| r.name == path.name))
            .collect();
        if rows.len() != report.probes.len() {
            continue;
        }
        let k = rows.len() as f64;
        let mean = |f: fn(&FastPathRow) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / k;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.4} |",
            path.name,
            pct(Some(mean(|r| r.mean_err_pct))),
            pct(Some(mean(|r| r.max_err_pct))),
            mean(|r| r.seconds)
        );
    }
    out.push('\n');
}

/// Writes the rows that did not run, grouped by method, N and reason.
fn write_not_ok(out: &mut String, report: &Report) {
    // (method, n, status, reason) -> probes
    type Key = (String, usize, Status, String);
    let mut groups: Vec<(Key, Vec<String>)> = Vec::new();
    for p in &report.probes {
        for r in p.rows.iter().filter(|r| r.status != Status::Ok) {
            let key = (
                r.method.clone(),
                r.n,
                r.status,
                r.reason.clone().unwrap_or_default(),
            );
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, probes)) => probes.push(p.name.clone()),
                None => groups.push((key, vec![p.name.clone()])),
            }
        }
    }
    if groups.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "## Skipped and failed runs\n\n| method | N | status | probes | reason |\n|---|---:|---|---|---|"
    );
    let k = report.probes.len();
    for ((method, n, status, reason), probes) in groups {
        let who = if probes.len() == k && k > 1 {
            "all".to_string()
        } else {
            probes.join(", ")
        };
        let _ = writeln!(
            out,
            "| {method} | {n} | {} | {who} | {} |",
            status_name(status),
            reason.replace('|', "\\|").replace('\n', " ")
        );
    }
    out.push('\n');
}

/// Writes the power check of region methods and any fit that did not converge.
fn write_checks(out: &mut String, report: &Report) {
    let region: Vec<&str> = ibl_light::Method::ALL
        .into_iter()
        .filter(|m| m.is_region_based())
        .map(|m| m.name())
        .filter(|m| report.methods.iter().any(|x| x == m))
        .collect();
    let _ = writeln!(out, "## Checks\n");
    for m in region {
        let worst = report
            .probes
            .iter()
            .flat_map(|p| p.rows.iter())
            .filter(|r| r.method == m)
            .filter_map(|r| r.power_change_pct)
            .map(f64::abs)
            .fold(None, |a: Option<f64>, v| Some(a.map_or(v, |a| a.max(v))));
        if let Some(w) = worst {
            let _ = writeln!(
                out,
                "- {m} (a region method) conserves the probe's power: largest |change| {w:.2e} %."
            );
        }
    }
    let unconverged: Vec<String> = report
        .probes
        .iter()
        .flat_map(|p| p.rows.iter().map(move |r| (p, r)))
        .filter(|(_, r)| {
            r.parameters
                .get("converged")
                .and_then(serde_json::Value::as_f64)
                == Some(0.0)
        })
        .map(|(p, r)| format!("{} N = {} on {}", r.method, r.n, p.name))
        .collect();
    let fitted = report
        .probes
        .iter()
        .flat_map(|p| p.rows.iter())
        .filter(|r| r.parameters.contains_key("converged"))
        .count();
    if fitted > 0 {
        let _ = writeln!(
            out,
            "- Fitted runs that met their convergence test: {} of {fitted}.",
            fitted - unconverged.len()
        );
    }
    if !unconverged.is_empty() {
        let _ = writeln!(
            out,
            "- Fits that stopped before converging (still scored): {}.",
            unconverged.join("; ")
        );
    }
    let _ = writeln!(
        out,
        "- Every run's parameters (splits, seeds, iterations, convergence) are in `{}`.\n",
        if report.files.json.is_empty() {
            "report.json"
        } else {
            &report.files.json
        }
    );
}

/// Writes the links to the plots and figures.
fn write_files(out: &mut String, report: &Report) {
    let f = &report.files;
    if !f.plots.is_empty() {
        let _ = writeln!(
            out,
            "## Error against number of lights\n\nLog-log; left mean error, right max error, per \
             cent of the mean irradiance; one colour per method; dashed grey lines at 1 % and 5 %.\n"
        );
        for p in &f.plots {
            let title = p.probe.clone().unwrap_or_else(|| {
                format!(
                    "average over {} probe{}",
                    report.probes.len(),
                    plural(report.probes.len())
                )
            });
            let _ = writeln!(
                out,
                "### {title}\n\n![{title}]({}) ([SVG]({}))\n",
                p.png, p.svg
            );
        }
    }
    if !f.figures.is_empty() {
        let ns: Vec<usize> = {
            let mut v: Vec<usize> = f.figures.iter().map(|x| x.n).collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        let _ = writeln!(
            out,
            "## Irradiance spheres and light overlays (N = {})\n\n\
             Spheres (the paper's Figure 4): irradiance on a unit sphere seen from +Z and from -Z, \
             ground truth and approximation with the same exposure, and the error \
             `mean_c |E - E_gt| / mu_c` in false colour.\n\n\
             | probe | method | N | spheres | overlay |\n|---|---|---:|---|---|",
            list(&ns)
        );
        for x in &f.figures {
            let link = |p: &Option<String>| match p {
                Some(p) => format!("[png]({p})"),
                None => "-".to_string(),
            };
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} |",
                x.probe,
                x.method,
                x.n,
                link(&x.sphere),
                link(&x.overlay)
            );
        }
        out.push('\n');
    }
}

fn plural(k: usize) -> &'static str {
    if k == 1 { "" } else { "s" }
}

fn list(v: &[usize]) -> String {
    v.iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// `report.md`: the summary of a report (settings, lights needed for 1 % and 5 % error averaged
/// over probes and per probe, method averages at N = 16 and 64, skipped and failed runs, checks,
/// and links to the plots and figures listed in [`Report::files`]).
pub fn markdown(report: &Report) -> String {
    let mut out = String::new();
    let k = report.probes.len();
    let names: Vec<&str> = report.probes.iter().map(|p| p.name.as_str()).collect();
    let _ = writeln!(
        out,
        "# Directional light approximation: comparison report\n\n\
         iblkit {}, after Madsen & Laursen 2006, section 5 (format `{}`).\n",
        report.tool_version, report.format
    );
    let _ = writeln!(
        out,
        "- Probes ({k}): {}\n- Methods: {}\n- Light counts N: {}\n- Seed: {}\n\
         - Scored on {}.\n- Fitted methods: {}.\n\
         - `mean_err` = 100 mean_c(mean_k |e - g| / mu_c) and `max_err` = 100 mean_c(max_k |e - g| / mu_c): \
         per cent of the channel's mean ground-truth irradiance mu_c, averaged over RGB (CONVENTIONS \
         section 5); `rel_*` divide by each normal's own irradiance instead (floored at 1e-3 mu_c).\n",
        names.join(", "),
        report.methods.join(", "),
        list(&report.counts),
        report.seed,
        report.scoring_normals,
        report.fit_normals_note
    );
    write_needed(&mut out, report);
    write_averages_at(&mut out, report);
    write_fast_paths(&mut out, report);
    write_not_ok(&mut out, report);
    write_checks(&mut out, report);
    write_files(&mut out, report);
    let _ = writeln!(
        out,
        "Data: `{}` (every row) and `{}` (the same rows as CSV).",
        or_default(&report.files.json, "report.json"),
        or_default(&report.files.csv, "report.csv")
    );
    out
}

fn or_default<'a>(s: &'a str, default: &'a str) -> &'a str {
    if s.is_empty() { default } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_needed_is_the_smallest_n_at_or_below() {
        let pts = vec![
            (1, 30.0, 90.0),
            (2, 4.0, 20.0),
            (4, 6.0, 5.0),
            (8, 1.0, 3.0),
        ];
        let x = LightsNeeded::from_points("m", &pts);
        assert_eq!(x.mean_err, [Some(8), Some(2)]);
        assert_eq!(x.max_err, [None, Some(4)]);
        assert_eq!(x.cells(8), ["8", "2", "> 8", "4"].map(String::from));
        let none = LightsNeeded::from_points("m", &Vec::new());
        assert_eq!(none.cells(8)[0], "no data");
    }

    #[test]
    fn csv_fields_are_quoted_when_needed() {
        assert_eq!(csv_field("sky"), "sky");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"x\""), "\"say \"\"x\"\"\"");
    }

    #[test]
    fn percentages_keep_three_digits() {
        assert_eq!(pct(Some(123.4)), "123");
        assert_eq!(pct(Some(12.34)), "12.3");
        assert_eq!(pct(Some(1.234)), "1.23");
        assert_eq!(pct(Some(0.1234)), "0.123");
        assert_eq!(pct(None), "-");
    }
}
