//! `ibl batch`: the per-probe pipeline of a batch spec over a folder, a glob or a list, on this
//! machine (`ibl_pipeline::batch`); `python -m iblkit.batch` runs the same spec on Dask.

use clap::Args;
use ibl_pipeline::{batch::run_batch, batch_spec::BatchSpec};

use crate::progress::Bars;

/// Arguments of `ibl batch`.
#[derive(Args)]
#[command(after_help = "\
The spec (TOML, docs/BATCH.md) names the probes ([input] folder, glob, list or files), the output
folder and the steps, [steps.info|lights|sh|irradiance|prefilter|preview|eval], set as the
commands of those names. OUT/<id>/ gets each probe's files and row.json, OUT/results.jsonl one
row per probe. A rerun skips the probes done; a failed probe is a row, not a stop (the
batch goes on, then exits 2).

Examples:
  ibl batch assets/batch/bundled.toml
  ibl batch spec.toml --jobs 2 --json")]
pub struct BatchArgs {
    /// The batch spec (TOML).
    spec: std::path::PathBuf,
    /// Probes run at once (each step also uses every core).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=256))]
    jobs: u32,
    /// Run again the probes whose earlier row says `failed`.
    #[arg(long)]
    retry_failed: bool,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs `ibl batch`.
pub fn run(args: &BatchArgs) -> anyhow::Result<()> {
    let (spec, bars) = (BatchSpec::read(&args.spec)?, Bars::default());
    let summary = run_batch(&spec, args.jobs as usize, args.retry_failed, &bars)?;
    match args.json {
        true => println!("{:#}", serde_json::to_value(&summary)?),
        false => print!("{}", summary.text()),
    }
    // Exit 2, as `python -m iblkit.batch`, when a probe failed (its row says why).
    let (n, items, rows) = (summary.failed.len(), summary.items, &summary.rows);
    let message = format!("{n} of {items} probes failed; their rows are in {rows}");
    match n {
        0 => Ok(()),
        _ => Err(ibl_pipeline::PipelineError::parameter(message).into()),
    }
}
