//! `ibl eval`: the comparison of Madsen & Laursen 2006, section 5, on any lat-long probes, written
//! as a report folder (`ibl_pipeline::eval`); prints how many lights each method needs.

use std::path::PathBuf;

use clap::Args;
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
    /// Irradiance optimisation only: fit the whole sphere at once (`sphere`, the paper's fit and
    /// its lowest unshadowed error) or the hemispheres apart (`hemispheres`, as renders use it).
    #[arg(long, value_enum, default_value = "sphere", value_name = "DOMAIN")]
    pub fit_domain: crate::cmd::lights::FitDomainArg,
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
    settings.fit_domain = args.fit_domain.domain();
    let report = evaluate(&args.probes, &settings, &args.out, &Bars::default())?;
    if super::print_json(args.json, &report)? {
        return Ok(());
    }
    print!("{}", ibl_pipeline::demo_text::lights_needed_text(&report));
    let out = args.out.display();
    println!("report in {out}/report.md ({out}/report.json, {out}/report.csv)");
    println!("  plots in {out}/plots/, spheres in {out}/spheres/, overlays in {out}/overlays/");
    Ok(())
}
