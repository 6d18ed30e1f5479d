//! The batch job's three steps for schedulers written in Python (`iblkit.batch` hands
//! `batch_run_item` to Dask workers): plan, run one item, finish; and the whole batch on this
//! machine (`ibl batch`'s job). The spec is read afresh by each call (a worker gets a path, not
//! an object), and every call releases the GIL.

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_pipeline::batch::{self, BatchItem, BatchPlan};
use ibl_pipeline::batch_spec::BatchSpec;
use pyo3::prelude::*;

use crate::errors::to_py;
use crate::images::json_to_py;
use crate::progress::PyProgress;

fn read(spec: &Path, retry_failed: bool) -> PyResult<(BatchSpec, BatchPlan)> {
    let spec = BatchSpec::read(spec).map_err(to_py)?;
    let plan = batch::plan(&spec, retry_failed).map_err(to_py)?;
    Ok((spec, plan))
}

/// The batch's probes: a dict with `items` (each `id`, `probe`, `done`), `steps_sha256`, and
/// the output folder and rows file.
#[pyfunction]
#[pyo3(signature = (spec, retry_failed=false))]
fn batch_plan(py: Python<'_>, spec: PathBuf, retry_failed: bool) -> PyResult<Bound<'_, PyAny>> {
    let (spec, plan) = py.detach(|| read(&spec, retry_failed))?;
    let mut value = serde_json::to_value(&plan).unwrap_or_default();
    value["out"] = spec.out.display().to_string().into();
    value["rows"] = spec.rows.display().to_string().into();
    json_to_py(py, &value)
}

/// Runs every step on one item of a plan (its `id` and `probe`, as `batch_plan` listed them)
/// and writes its files and `row.json`; returns the row. The spec is read, not planned again:
/// a worker's call costs one item's work, not a listing of the whole input.
#[pyfunction]
fn batch_run_item<'py>(
    py: Python<'py>,
    spec: PathBuf,
    id: String,
    probe: PathBuf,
) -> PyResult<Bound<'py, PyAny>> {
    let row = py.detach(|| {
        let spec = BatchSpec::read(&spec).map_err(to_py)?;
        let item = BatchItem {
            id,
            probe,
            done: false,
        };
        batch::run_item(&spec, &item).map_err(to_py)
    })?;
    json_to_py(py, &row)
}

/// Gathers the rows into the rows file; `ran` and `skipped` are how many items this run ran
/// and found done before. Returns the summary.
#[pyfunction]
#[pyo3(signature = (spec, ran=0, skipped=0))]
fn batch_finish(
    py: Python<'_>,
    spec: PathBuf,
    ran: usize,
    skipped: usize,
) -> PyResult<Bound<'_, PyAny>> {
    let start = Instant::now();
    let summary = py.detach(|| {
        // The listing, not the plan: `finish` reads each row once, the plan would read it too.
        let spec = BatchSpec::read(&spec).map_err(to_py)?;
        let listing = batch::listing(&spec).map_err(to_py)?;
        batch::finish(&spec, &listing, ran, skipped, start).map_err(to_py)
    })?;
    json_to_py(py, &summary)
}

/// The whole batch on this machine, `jobs` probes at a time (as `ibl batch --jobs`); progress
/// per probe. Returns the summary.
#[pyfunction]
#[pyo3(signature = (spec, jobs=1, retry_failed=false, progress=None))]
fn run_batch(
    py: Python<'_>,
    spec: PathBuf,
    jobs: usize,
    retry_failed: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'_, PyAny>> {
    let reporter = PyProgress::new(progress);
    let summary = py.detach(|| {
        let spec = BatchSpec::read(&spec)?;
        batch::run_batch(&spec, jobs, retry_failed, &reporter)
    });
    reporter.finish()?;
    let summary = summary.map_err(to_py)?;
    json_to_py(py, &summary)
}

/// Adds this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(batch_plan, m)?)?;
    m.add_function(wrap_pyfunction!(batch_run_item, m)?)?;
    m.add_function(wrap_pyfunction!(batch_finish, m)?)?;
    m.add_function(wrap_pyfunction!(run_batch, m)?)?;
    Ok(())
}
