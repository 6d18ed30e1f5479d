//! The comparison of Madsen & Laursen 2006, section 5, on any lat-long probes (`ibl eval`, and
//! the demo's `eval/`): every extraction method at every light count N, scored against the exact
//! irradiance on M Fibonacci normals (CONVENTIONS section 5), written as a report folder:
//!
//! ```text
//! DIR/report.json   every row (schema iblkit.eval/1)      DIR/plots/average.svg|png
//! DIR/report.csv    the same rows as CSV                  DIR/plots/<probe>.svg|png
//! DIR/report.md     lights needed for 1 % and 5 % error   DIR/spheres/<probe>-<method>-<N>.png
//!                                                         DIR/overlays/<probe>-<method>-<N>.png
//! ```
//!
//! The algorithms live in `ibl-eval` (sweep, report text, plots, sphere figures); this module
//! loads the probes, reports progress, names and writes the files (atomically, never over an
//! input).

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use ibl_core::{Image, Rgb, RowIrradiance};
use ibl_eval::overlay::OverlayOptions;
use ibl_eval::sphere_image::{DEFAULT_ERROR_RANGE_PCT, DEFAULT_SPHERE_SIZE};
use ibl_eval::sweep::{Stage, SweepProgress};
use ibl_eval::{
    ErrorChart, FigureFiles, PLOT_SIZE, PlotFiles, ProbeInput, Report, SphereField, SphereFigure,
    SweepOptions,
};
use ibl_extract::{ExtractOptions, FitDomain, ModelSpec};
use ibl_light::Method;

use crate::envmap_files::EnvMapping;
use crate::error::{PipelineError, Result};
use crate::probe_input::load_probe;
use crate::progress::Progress;

/// Light counts swept by default: the paper's powers of two, 1 to 256.
pub const DEFAULT_COUNTS: [usize; 9] = [1, 2, 4, 8, 16, 32, 64, 128, 256];

/// Light count of the sphere figures and overlays when it was swept.
pub const DEFAULT_FIGURE_N: usize = 16;

/// Largest light count accepted.
const MAX_COUNT: usize = 4096;

/// Largest number of scoring normals accepted.
const MAX_NORMALS: usize = 1_000_000;

/// What to evaluate (parsed and checked arguments).
#[derive(Clone, Debug)]
pub struct EvalSettings {
    /// Methods in report order.
    pub methods: Vec<ModelSpec>,
    /// Light counts, increasing, without repeats.
    pub counts: Vec<usize>,
    /// Number of scoring normals.
    pub normals: usize,
    /// Seed of the randomised methods.
    pub seed: u64,
    /// Light count of the sphere figures and overlays (one of `counts`).
    pub figure_n: usize,
    /// Mapping of every probe (`None`: each detected from its shape).
    pub mapping: Option<EnvMapping>,
    /// What irradiance optimisation fits (default: the whole sphere, the paper's fit).
    pub fit_domain: FitDomain,
}

impl EvalSettings {
    /// Checks and normalises the settings (counts sorted and deduplicated; the figure N defaults
    /// to 16 when swept, else the largest N).
    pub fn new(
        methods: Vec<ModelSpec>,
        mut counts: Vec<usize>,
        normals: usize,
        seed: u64,
        figure_n: Option<usize>,
    ) -> Result<Self> {
        if methods.is_empty() {
            return Err(PipelineError::parameter("--methods names no method"));
        }
        counts.sort_unstable();
        counts.dedup();
        match (counts.first(), counts.last()) {
            (Some(&lo), Some(&hi)) if lo >= 1 && hi <= MAX_COUNT => {}
            _ => {
                return Err(PipelineError::parameter(format!(
                    "--n needs light counts between 1 and {MAX_COUNT}"
                )));
            }
        }
        if normals == 0 || normals > MAX_NORMALS {
            return Err(PipelineError::parameter(format!(
                "--normals must be between 1 and {MAX_NORMALS}"
            )));
        }
        let figure_n = match figure_n {
            Some(n) if counts.contains(&n) => n,
            Some(n) => {
                return Err(PipelineError::parameter(format!(
                    "--overlay-n {n} is not one of the swept counts (--n)"
                )));
            }
            None if counts.contains(&DEFAULT_FIGURE_N) => DEFAULT_FIGURE_N,
            None => counts.last().copied().unwrap_or(1),
        };
        Ok(EvalSettings {
            methods,
            counts,
            normals,
            seed,
            figure_n,
            mapping: None,
            fit_domain: FitDomain::default(),
        })
    }
}

/// Parses `all` or a comma-separated list of method names (repeats dropped).
pub fn parse_methods(list: &str) -> Result<Vec<ModelSpec>> {
    if list.trim() == "all" {
        return Ok(Method::ALL.map(ModelSpec::from).to_vec());
    }
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let m: ModelSpec = name
            .parse()
            .map_err(|e| PipelineError::parameter(format!("--methods: {e}")))?;
        if !out.contains(&m) {
            out.push(m);
        }
    }
    Ok(out)
}

/// A loaded probe.
struct Probe {
    path: PathBuf,
    name: String,
    sha256: String,
    image: Image<Rgb>,
}

/// A name usable in file names: letters, digits, `.`, `_` and `-`; anything else becomes `-`.
fn file_safe(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '-'
            }
        })
        .collect();
    let s = s.trim_start_matches('.').to_string();
    if s.is_empty() { "probe".to_string() } else { s }
}

/// Loads every probe as a lat-long map; names are file stems made unique (and never `average`,
/// the name of the averaged plot).
fn load_probes(
    paths: &[PathBuf],
    mapping: Option<EnvMapping>,
    progress: &dyn Progress,
) -> Result<Vec<Probe>> {
    let mut taken: HashSet<String> = HashSet::from(["average".to_string()]);
    let mut probes = Vec::with_capacity(paths.len());
    for path in paths {
        let env = load_probe(path, mapping, progress)?.env;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let base = file_safe(&stem);
        let mut name = base.clone();
        let mut k = 2;
        while taken.contains(&name) {
            name = format!("{base}-{k}");
            k += 1;
        }
        taken.insert(name.clone());
        probes.push(Probe {
            path: path.clone(),
            sha256: ibl_io::light_file::sha256_file(path)?,
            name,
            image: env.image,
        });
    }
    Ok(probes)
}

/// Writes one output file atomically under `out`, refusing to write over an input.
fn write_output(out: &Path, relative: &str, bytes: &[u8], inputs: &[&Path]) -> Result<()> {
    let path = out.join(relative);
    if let Some(dir) = path.parent() {
        ibl_io::create_dir_all(dir)?;
    }
    crate::output_paths::check_output_path(&path, inputs)?;
    ibl_io::write_atomically(&path, bytes)?;
    Ok(())
}

/// File stem of the figures of one probe, method and N.
fn figure_stem(probe: &str, method: ModelSpec, n: usize) -> String {
    format!("{probe}-{method}-{n}")
}

/// Every file `evaluate` may write, relative to the output folder.
fn planned_outputs(probes: &[Probe], settings: &EvalSettings) -> Vec<String> {
    let mut files: Vec<String> = ["report.json", "report.csv", "report.md"]
        .map(String::from)
        .to_vec();
    let stems = std::iter::once("average").chain(probes.iter().map(|p| p.name.as_str()));
    for stem in stems {
        files.push(format!("plots/{stem}.svg"));
        files.push(format!("plots/{stem}.png"));
    }
    for p in probes {
        // Figures show light sets: models with an SH part have none.
        for &m in settings
            .methods
            .iter()
            .filter(|m| matches!(m, ModelSpec::Lights(_)))
        {
            let stem = figure_stem(&p.name, m, settings.figure_n);
            files.push(format!("spheres/{stem}.png"));
            files.push(format!("overlays/{stem}.png"));
        }
    }
    files
}

/// Encodes an 8-bit image as PNG.
fn png(image: &Image<[u8; 3]>, what: &str) -> Result<Vec<u8>> {
    ibl_io::ldr::encode_png(image).map_err(|e| e.with_path(Path::new(what)).into())
}

/// Progress message of a sweep step.
fn progress_message(p: &SweepProgress) -> String {
    match p.stage {
        Stage::GroundTruth => format!("{}: ground truth", p.probe),
        Stage::Extract { method, n } => format!("{}: {method} N={n}", p.probe),
        Stage::Finished => "figures".to_string(),
    }
}

/// Runs the whole evaluation on `paths` and writes the report folder `out`; returns the report
/// (with its file list). Used by `ibl eval` and `ibl demo`.
pub fn evaluate(
    paths: &[PathBuf],
    settings: &EvalSettings,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Report> {
    crate::output_paths::check_output_folder(out)?;
    let probes = load_probes(paths, settings.mapping, progress)?;
    ibl_io::create_dir_all(out)?;
    let inputs: Vec<&Path> = probes.iter().map(|p| p.path.as_path()).collect();
    // Refuse before the (long) sweep if any planned output is an input.
    for relative in planned_outputs(&probes, settings) {
        ibl_io::ensure_output_is_not_input(&out.join(relative), &inputs)?;
    }
    progress.begin("eval", 1);
    let on_progress = |p: SweepProgress| {
        progress.update(p.done as u64, p.total as u64, Some(&progress_message(&p)));
    };
    let inputs_for_sweep: Vec<ProbeInput<'_>> = probes
        .iter()
        .map(|p| ProbeInput {
            name: &p.name,
            sha256: &p.sha256,
            image: &p.image,
        })
        .collect();
    let options = SweepOptions {
        methods: settings.methods.clone(),
        counts: settings.counts.clone(),
        normals: settings.normals,
        extract: ExtractOptions {
            seed: settings.seed,
            fit_domain: settings.fit_domain,
        },
        keep_sets_at: Some(settings.figure_n),
    };
    let sweep = ibl_eval::sweep(&inputs_for_sweep, &options, &on_progress);
    let written = sweep
        .map_err(PipelineError::from)
        .and_then(|sweep| write_report(sweep, &probes, out, &inputs));
    progress.end();
    written
}

/// The plots, figures and report files of a finished sweep; returns the report with its file
/// list.
fn write_report(
    sweep: ibl_eval::Sweep,
    probes: &[Probe],
    out: &Path,
    inputs: &[&Path],
) -> Result<Report> {
    let mut report = sweep.report;

    // Error-vs-N plots: the average, then one per probe.
    let mut charts = vec![("average".to_string(), None, ErrorChart::average(&report))];
    for (i, p) in report.probes.iter().enumerate() {
        if let Some(chart) = ErrorChart::for_probe(&report, i) {
            charts.push((p.name.clone(), Some(p.name.clone()), chart));
        }
    }
    for (stem, probe, chart) in charts {
        let svg = format!("plots/{stem}.svg");
        let png_path = format!("plots/{stem}.png");
        let svg_text = ibl_eval::render_svg(&chart, PLOT_SIZE)?;
        write_output(out, &svg, svg_text.as_bytes(), inputs)?;
        let image = ibl_eval::render_png(&chart, PLOT_SIZE)?;
        write_output(out, &png_path, &png(&image, &png_path)?, inputs)?;
        report.files.plots.push(PlotFiles {
            probe,
            svg,
            png: png_path,
        });
    }

    // Spheres (and overlays) at the figure N, one ground-truth field per probe.
    let mut truths: Vec<Option<SphereField>> = vec![None; probes.len()];
    for kept in &sweep.sets {
        let probe = &probes[kept.probe];
        let truth = match &mut truths[kept.probe] {
            Some(t) => t,
            slot => slot.insert(SphereField::ground_truth(
                &RowIrradiance::new(&probe.image),
                DEFAULT_SPHERE_SIZE,
            )),
        };
        let approx = SphereField::of_light_set(&kept.set, DEFAULT_SPHERE_SIZE);
        let p = &report.probes[kept.probe];
        let row = p
            .rows
            .iter()
            .find(|r| r.method == kept.method.to_string() && r.n == kept.n);
        let scores = row
            .and_then(|r| Some((r.mean_err_pct?, r.max_err_pct?)))
            .map(|(mean, max)| format!("mean_err {mean:.2} %, max_err {max:.2} %"))
            .unwrap_or_default();
        let labels = SphereFigure {
            title: format!("{}: {} with {} lights", p.name, kept.method, kept.n),
            subtitle: format!(
                "irradiance on a unit sphere; {scores}; error colour scale 0 to {DEFAULT_ERROR_RANGE_PCT} % of the mean irradiance"
            ),
            approx_label: format!("{}, N = {}", kept.method, kept.n),
            error_range_pct: DEFAULT_ERROR_RANGE_PCT,
        };
        let figure = ibl_eval::sphere_image::figure(truth, &approx, p.mean_irradiance, &labels)?;
        let stem = figure_stem(&p.name, kept.method, kept.n);
        let sphere = format!("spheres/{stem}.png");
        write_output(out, &sphere, &png(&figure, &sphere)?, inputs)?;
        let overlay_image =
            ibl_eval::overlay::draw_overlay(&probe.image, &kept.set, &OverlayOptions::default());
        let overlay = format!("overlays/{stem}.png");
        write_output(out, &overlay, &png(&overlay_image, &overlay)?, inputs)?;
        report.files.figures.push(FigureFiles {
            probe: p.name.clone(),
            method: kept.method.to_string(),
            n: kept.n,
            sphere: Some(sphere),
            overlay: Some(overlay),
        });
    }

    report.files.json = "report.json".to_string();
    report.files.csv = "report.csv".to_string();
    report.files.markdown = "report.md".to_string();
    write_output(
        out,
        "report.csv",
        ibl_eval::report::csv(&report).as_bytes(),
        inputs,
    )?;
    write_output(
        out,
        "report.md",
        ibl_eval::report::markdown(&report).as_bytes(),
        inputs,
    )?;
    // Serialising plain data to a string cannot fail.
    let json = serde_json::to_string_pretty(&report).unwrap_or_default();
    write_output(out, "report.json", json.as_bytes(), inputs)?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_lists_parse() {
        assert_eq!(
            parse_methods("all").unwrap(),
            Method::ALL.map(ModelSpec::from).to_vec()
        );
        assert_eq!(
            parse_methods("median-cut, lightgen,median-cut,sun+sh3").unwrap(),
            vec![
                Method::MedianCut.into(),
                Method::LightGen.into(),
                "sun+sh3".parse().unwrap()
            ]
        );
        assert!(parse_methods("nope").is_err());
    }

    #[test]
    fn settings_pick_the_figure_n() {
        let s = EvalSettings::new(
            vec![Method::MedianCut.into()],
            vec![4, 1, 16, 4],
            100,
            1,
            None,
        )
        .unwrap();
        assert_eq!(s.counts, vec![1, 4, 16]);
        assert_eq!(s.figure_n, 16);
        let s =
            EvalSettings::new(vec![Method::MedianCut.into()], vec![1, 2], 100, 1, None).unwrap();
        assert_eq!(s.figure_n, 2);
        assert!(
            EvalSettings::new(vec![Method::MedianCut.into()], vec![1, 2], 100, 1, Some(8)).is_err()
        );
        assert!(EvalSettings::new(vec![Method::MedianCut.into()], vec![0], 100, 1, None).is_err());
        assert!(EvalSettings::new(vec![Method::MedianCut.into()], vec![1], 0, 1, None).is_err());
    }

    #[test]
    fn file_names_are_safe() {
        assert_eq!(file_safe("sky"), "sky");
        assert_eq!(file_safe("a b/c"), "a-b-c");
        assert_eq!(file_safe("..x"), "x");
        assert_eq!(file_safe(""), "probe");
    }
}
