//! `ibl eval`: the comparison of Madsen & Laursen 2006, section 5, on any lat-long probes, written
//! as a report folder (`ibl_pipeline::eval`); prints how many lights each method needs.

use std::path::PathBuf;

use clap::Args;
use ibl_eval::Report;
use ibl_eval::report::LightsNeeded;
use ibl_pipeline::eval::{DEFAULT_COUNTS, EvalSettings, evaluate};

use crate::probe_arg::ProbeMappingArgs;
use crate::progress::Bars;
use crate::values::{self, ModelList};

/// Arguments of `ibl eval`.
#[derive(Args)]
#[command(after_help = "\
Examples:
  ibl eval assets/probes/*.exr --out eval-out            every method, N = 1..256, 20000 normals
  ibl eval sky.exr --methods median-cut,lightgen --n 1,2,4,8,16 --out eval-sky
  ibl eval probe.hdr --n 8,16,32 --normals 5000 --overlay-n 8 --out eval --json

Writes DIR/report.json, report.csv, report.md (lights needed for 1 % and 5 % error), error-vs-N
plots (plots/, SVG and PNG), irradiance spheres (spheres/) and light overlays (overlays/).")]
pub struct EvalArgs {
    /// Probes (.exr, .hdr, .pfm, .png, .jpg), lat-long or any mapping `--mapping` names.
    #[arg(required = true, value_name = "PROBE")]
    pub probes: Vec<PathBuf>,
    #[command(flatten)]
    pub probe_mapping: ProbeMappingArgs,
    /// Methods: `all` (the five light methods), or a comma-separated list of median-cut,
    /// adaptive-median-cut, lightgen, variance-minimization, irradiance-optimization, sun (the
    /// dominant light, N = 1), any of them with an SH ambient (`lightgen+sh3`, `sun+sh3`: 1 sun +
    /// SH9), or SH alone (`sh3`, `sh21`).
    #[arg(long, default_value = "all", value_name = "LIST", value_parser = values::models)]
    pub methods: ModelList,
    /// Light counts N, comma-separated (median cut runs only on powers of two).
    #[arg(
        short = 'n',
        long = "n",
        value_delimiter = ',',
        default_values_t = DEFAULT_COUNTS,
        value_name = "N,..."
    )]
    pub counts: Vec<usize>,
    /// Number of Fibonacci scoring normals M.
    #[arg(long, default_value_t = ibl_core::fibonacci::DEFAULT_NORMAL_COUNT, value_name = "M")]
    pub normals: usize,
    /// Output folder (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Print the report as JSON on stdout (with the paths of every file written).
    #[arg(long)]
    pub json: bool,
    /// Seed of the randomised methods (equal seeds give equal light sets).
    #[arg(long, default_value_t = 1, value_name = "S")]
    pub seed: u64,
    /// Light count of the spheres and overlays; must be one of --n (default 16 when swept, else
    /// the largest N).
    #[arg(long, value_name = "N")]
    pub overlay_n: Option<usize>,
}

/// Prints, per method, how many lights the averages need for 1 % and 5 % error.
pub fn print_lights_needed(report: &Report) {
    let largest = report.counts.iter().copied().max().unwrap_or(0);
    let k = report.probes.len();
    println!(
        "lights needed (smallest N swept), average over {k} probe{}:",
        if k == 1 { "" } else { "s" }
    );
    println!(
        "  {:<24} {:>9} {:>9} {:>9} {:>9}",
        "method", "mean<=1%", "mean<=5%", "max<=1%", "max<=5%"
    );
    for x in LightsNeeded::average(report) {
        let [a, b, c, d] = x.cells(largest);
        println!("  {:<24} {a:>9} {b:>9} {c:>9} {d:>9}", x.method);
    }
    let not_ok = report
        .probes
        .iter()
        .flat_map(|p| &p.rows)
        .filter(|r| r.status != ibl_eval::Status::Ok)
        .count();
    if not_ok > 0 {
        println!("  ({not_ok} runs skipped or failed; see the report)");
    }
}

/// Runs `ibl eval`.
pub fn run(args: &EvalArgs) -> anyhow::Result<()> {
    let mut settings = EvalSettings::new(
        args.methods.0.clone(),
        args.counts.clone(),
        args.normals,
        args.seed,
        args.overlay_n,
    )?;
    settings.mapping = args.probe_mapping.mapping()?;
    let report = evaluate(&args.probes, &settings, &args.out, &Bars::default())?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    print_lights_needed(&report);
    let out = args.out.display();
    println!("report in {out}/report.md ({out}/report.json, {out}/report.csv)");
    println!("  plots in {out}/plots/, spheres in {out}/spheres/, overlays in {out}/overlays/");
    Ok(())
}
