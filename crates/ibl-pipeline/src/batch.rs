//! Batches at dataset scale (issue 19): one spec ([`crate::batch_spec`]), the same per-probe
//! pipeline on every probe of a folder, a glob or a list, one result row per probe.
//!
//! A batch is three calls, so that any scheduler can run the middle one wherever it likes:
//! [`plan`] lists the probes and which are done, [`run_item`] runs one probe (the `ibl batch`
//! command runs them on this machine's cores; `python -m iblkit.batch` hands them to Dask
//! workers), and [`finish`] gathers the rows into the rows file. [`run_batch`] is all three on
//! one machine.
//!
//! Each step is the command line's own job (`ibl info`, `ibl lights`, `ibl sh`, ...) with the
//! spec's settings, so a batch's files equal the commands' files on the same inputs.
//!
//! Layout of the output folder:
//!
//! ```text
//! OUT/<id>/row.json          the probe's row, written last (atomically): the item is done
//! OUT/<id>/lights.json ...   the steps' files (lights.*, lights.png, sh.*, irradiance.*,
//!                            prefilter.*, preview.png, eval/)
//! OUT/results.jsonl          every row in input order, one JSON object a line (by `finish`)
//! ```
//!
//! Restarts: an item is done when its `row.json` exists, names the same probe and was made by
//! the same steps (the hash of the steps' settings). A killed batch loses at most the items
//! running when it died; they run again, their files are replaced atomically, and every item has
//! exactly one row. Failed items are rows too (status `failed`, the message, whether the input
//! or iblkit is at fault); they are done unless `retry_failed` is asked.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use ibl_core::FramePreset;
use ibl_io::{ShFileFormat, light_file::sha256_hex};
use serde::Serialize;
use serde_json::{Value, json};

use crate::batch_spec::{BatchSpec, InputSource};
use crate::error::{PipelineError, Result};
use crate::progress::Progress;

/// Largest number of probes one batch takes (a list file of 10 million lines is ~1 GB).
pub const MAX_ITEMS: usize = 10_000_000;

/// Largest list file read, bytes.
const MAX_LIST_BYTES: u64 = 1 << 30;

/// Row format name, in every row.
pub const ROW_FORMAT: &str = "iblkit.batch-row/1";

/// One probe of a batch.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct BatchItem {
    /// Its folder's name in the output folder: the file stem, with a hash of the path when two
    /// probes share a stem.
    pub id: String,
    /// The probe file.
    pub probe: PathBuf,
    /// Whether its row is there already (skipped by a restart).
    pub done: bool,
}

/// What [`plan`] found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BatchPlan {
    /// Every probe, in input order.
    pub items: Vec<BatchItem>,
    /// Hash of the steps' settings.
    pub steps_sha256: String,
}

impl BatchPlan {
    /// The items still to run.
    pub fn pending(&self) -> impl Iterator<Item = &BatchItem> {
        self.items.iter().filter(|i| !i.done)
    }
}

/// What a batch did (the JSON of `ibl batch --json` and of `python -m iblkit.batch`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BatchSummary {
    /// Probes in the batch.
    pub items: usize,
    /// Items run by this call.
    pub ran: usize,
    /// Items skipped as done by an earlier run.
    pub skipped: usize,
    /// Rows whose status is `ok`.
    pub ok: usize,
    /// Rows whose status is `failed`: (id, message).
    pub failed: Vec<(String, String)>,
    /// The rows file.
    pub rows: String,
    /// Seconds this call took.
    pub seconds: f64,
}

impl BatchSummary {
    /// What `ibl batch` prints.
    pub fn text(&self) -> String {
        let mut text = format!(
            "{} probes: {} run now, {} done before; {} ok, {} failed, in {:.1} s\nrows: {}\n",
            self.items,
            self.ran,
            self.skipped,
            self.ok,
            self.failed.len(),
            self.seconds,
            self.rows
        );
        for (id, message) in &self.failed {
            text.push_str(&format!("  failed {id}: {message}\n"));
        }
        text
    }
}

/// Lists the spec's probes and marks the done ones. Checks the output folder first.
pub fn plan(spec: &BatchSpec, retry_failed: bool) -> Result<BatchPlan> {
    let mut plan = listing(spec)?;
    for item in &mut plan.items {
        item.done = match read_row(&spec.out.join(&item.id).join("row.json")) {
            Some(row) => {
                row["probe"] == item.probe.display().to_string()
                    && row["steps_sha256"] == plan.steps_sha256
                    && (row["status"] == "ok" || !retry_failed)
            }
            None => false,
        };
    }
    Ok(plan)
}

/// The spec's probes and their ids without reading any row (every `done` false): what
/// [`finish`] needs once the items have run. Checks the output folder first.
pub fn listing(spec: &BatchSpec) -> Result<BatchPlan> {
    crate::output_paths::check_output_folder(&spec.out)?;
    let probes = list_probes(spec)?;
    if probes.is_empty() {
        return Err(PipelineError::parameter(format!(
            "{}: the input names no probe",
            spec.path.display()
        )));
    }
    for p in &probes {
        // Every output of an item is inside OUT/<id>/; a probe there would be overwritten.
        if p.starts_with(&spec.out) {
            return Err(PipelineError::parameter(format!(
                "{}: the probe {} is inside the output folder {}",
                spec.path.display(),
                p.display(),
                spec.out.display()
            )));
        }
    }
    let ids = item_ids(&probes);
    let items = probes
        .into_iter()
        .zip(ids)
        .map(|(probe, id)| BatchItem {
            id,
            probe,
            done: false,
        })
        .collect();
    Ok(BatchPlan {
        items,
        steps_sha256: spec.steps_sha256(),
    })
}

/// The probe files of the spec's input, in a stable order (sorted for folders and globs, as
/// listed for lists and files).
fn list_probes(spec: &BatchSpec) -> Result<Vec<PathBuf>> {
    let shown = spec.path.display();
    let mut probes = match &spec.input {
        InputSource::Folder { folder, extensions } => {
            let mut files: Vec<PathBuf> = ibl_io::list_dir(folder)?
                .into_iter()
                .filter(|p| p.is_file())
                .filter(|p| {
                    p.extension()
                        .and_then(|e| e.to_str())
                        .is_some_and(|e| extensions.contains(&e.to_ascii_lowercase()))
                })
                .collect();
            files.sort();
            files
        }
        InputSource::Glob(pattern) => {
            let paths = glob::glob(pattern).map_err(|e| {
                PipelineError::parameter(format!("{shown}: [input] glob `{pattern}`: {e}"))
            })?;
            let mut files = Vec::new();
            for p in paths {
                let p =
                    p.map_err(|e| PipelineError::parameter(format!("{shown}: [input] glob: {e}")))?;
                if p.is_file() {
                    files.push(p);
                }
                if files.len() > MAX_ITEMS {
                    break;
                }
            }
            files.sort();
            files
        }
        InputSource::List(list) => {
            let text = ibl_io::read_text(list, MAX_LIST_BYTES)?;
            let base = list.parent().unwrap_or(Path::new(""));
            text.lines()
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with('#'))
                .take(MAX_ITEMS + 1)
                .map(|l| crate::batch_spec::join_lexically(base, l))
                .collect()
        }
        InputSource::Files(files) => files.clone(),
    };
    if probes.len() > MAX_ITEMS {
        return Err(PipelineError::parameter(format!(
            "{shown}: more than {MAX_ITEMS} probes in one batch; split it"
        )));
    }
    let mut seen = std::collections::HashSet::new();
    probes.retain(|p| seen.insert(p.clone()));
    Ok(probes)
}

/// Item ids: the file stem, or `stem-<8 hex digits of the path's hash>` for stems that more
/// than one probe shares (stable when files are added: a hash, not a counter).
fn item_ids(probes: &[PathBuf]) -> Vec<String> {
    let stem = |p: &Path| {
        let s: String = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
            .chars()
            .map(|c| {
                if c.is_alphanumeric() || "-_.".contains(c) {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        if s.is_empty() || s.starts_with('.') {
            format!("probe{s}")
        } else {
            s
        }
    };
    let mut count: HashMap<String, usize> = HashMap::new();
    for p in probes {
        *count.entry(stem(p)).or_default() += 1;
    }
    probes
        .iter()
        .map(|p| {
            let s = stem(p);
            if count[&s] > 1 {
                let hash = sha256_hex(p.to_string_lossy().as_bytes());
                format!("{s}-{}", &hash[..8])
            } else {
                s
            }
        })
        .collect()
}

fn read_row(path: &Path) -> Option<Value> {
    let text = ibl_io::read_text(path, 64 << 20).ok()?;
    serde_json::from_str(&text).ok()
}

/// A [`Progress`] that keeps the notes (they go into the row) and shows nothing.
#[derive(Default)]
struct Notes(Mutex<Vec<String>>);

impl Progress for Notes {
    fn begin(&self, _: &str, _: u64) {}
    fn update(&self, _: u64, _: u64, _: Option<&str>) {}
    fn end(&self) {}
    fn note(&self, text: &str) {
        if let Ok(mut notes) = self.0.lock() {
            notes.push(text.to_string());
        }
    }
}

/// Runs every step of the spec on one item and writes its files and, last, its `row.json`;
/// returns the row. A step's failure is the row's (status `failed`), not an error: only failing
/// to write the row itself is.
pub fn run_item(spec: &BatchSpec, item: &BatchItem) -> Result<Value> {
    let start = Instant::now();
    let folder = spec.out.join(&item.id);
    let notes = Notes::default();
    let mut row = json!({
        "format": ROW_FORMAT,
        "id": item.id,
        "probe": item.probe.display().to_string(),
        "steps_sha256": spec.steps_sha256(),
    });
    let steps = ibl_io::create_dir_all(&folder)
        .map_err(PipelineError::from)
        .and_then(|()| run_steps(spec, &item.probe, &folder, &notes));
    match steps {
        Ok(results) => {
            row["status"] = json!("ok");
            for (name, value) in results {
                row[name] = value;
            }
        }
        Err(e) => {
            row["status"] = json!("failed");
            row["error"] = json!(e.to_string());
            row["error_kind"] = json!(if e.is_bad_input() {
                "bad-input"
            } else {
                "internal"
            });
        }
    }
    row["notes"] = json!(notes.0.into_inner().unwrap_or_default());
    row["seconds"] = json!(start.elapsed().as_secs_f64());
    let text = serde_json::to_string(&row)
        .map_err(|e| PipelineError::parameter(format!("row of {}: {e}", item.id)))?;
    ibl_io::create_dir_all(&folder)?;
    ibl_io::write_atomically(&folder.join("row.json"), text.as_bytes())?;
    Ok(row)
}

/// The steps of the spec on `probe`, files in `folder`; each step's JSON summary by name.
fn run_steps(
    spec: &BatchSpec,
    probe: &Path,
    folder: &Path,
    progress: &dyn Progress,
) -> Result<Vec<(&'static str, Value)>> {
    let s = &spec.steps;
    let t = &spec.typed;
    let mapping = spec.mapping;
    let rel = |p: &Path| {
        p.strip_prefix(&spec.out)
            .unwrap_or(p)
            .to_string_lossy()
            .into_owned()
    };
    let mut out = Vec::new();
    if s.info.is_some() {
        let info = crate::info::probe_info(probe, mapping, FramePreset::Gltf)?;
        out.push(("info", to_json(&info)));
    }
    if let Some(l) = &s.lights {
        let outputs: Vec<PathBuf> = t
            .light_formats
            .iter()
            .map(|f| folder.join(format!("lights.{f}")))
            .collect();
        let overlay = l.overlay.then(|| folder.join("lights.png"));
        let options = crate::lights::LightsOptions {
            probe: probe.to_path_buf(),
            mapping,
            count: l.n,
            method: t.method,
            seed: l.seed,
            fit_domain: ibl_extract::FitDomain::Hemispheres,
            outputs: outputs.clone(),
            frame: FramePreset::Gltf,
            lux_per_unit: 1.0,
            overlay: overlay.clone(),
            ambient_sh: l.ambient_sh,
        };
        let r = crate::lights::lights(&options, progress)?;
        let lights: Vec<Value> = r
            .set
            .lights
            .iter()
            .map(|light| {
                json!({
                    "direction": light.direction.to_array(),
                    "radiance": light.radiance.to_array(),
                    "solid_angle_sr": light.solid_angle_sr,
                })
            })
            .collect();
        let mut files: Vec<String> = outputs.iter().map(|p| rel(p)).collect();
        files.extend(overlay.iter().map(|p| rel(p)));
        out.push((
            "lights",
            json!({
                "method": t.method.name(),
                "n": r.set.lights.len(),
                "requested": l.n,
                "seconds": r.seconds,
                "total_power": r.set.total_power(),
                "probe_power": r.probe_power,
                "lights": lights,
                "files": files,
            }),
        ));
    }
    if let Some(sh) = &s.sh {
        let (format, window, quantity) = t.sh;
        let path = folder.join(format!("sh.{}", sh_extension(format)));
        let options = crate::sh::ShOptions {
            source: crate::sh::ShSource::Probe(probe.to_path_buf(), mapping),
            format,
            bands: sh.bands,
            quantity,
            window,
        };
        let r = crate::sh::spherical_harmonics(&options, Some(&path), progress)?;
        out.push((
            "sh",
            json!({
                "format": format.name(),
                "bands": r.bands_written,
                "coefficients": r.file.coefficients,
                "file": rel(&path),
            }),
        ));
    }
    if let Some(i) = &s.irradiance {
        let (method, to) = t.irradiance;
        let path = folder.join(format!("irradiance.{}", i.extension));
        let options = crate::irradiance::IrradianceOptions {
            probe: probe.to_path_buf(),
            mapping,
            method,
            bands: i.bands,
            window: ibl_sh::Window::None,
            csv: None,
            normals: crate::irradiance::CHECK_NORMALS,
            output: Some(path.clone()),
            to,
            width: i.width,
        };
        let mut summary = to_json(&crate::irradiance::irradiance(&options, progress)?);
        summary["file"] = json!(rel(&path));
        out.push(("irradiance", summary));
    }
    if let Some(p) = &s.prefilter {
        let (target, texel) = t.prefilter;
        let path = folder.join(format!("prefilter.{}", p.extension));
        let irradiance = p
            .irradiance_size
            .map(|_| folder.join(format!("prefilter-irradiance.{}", p.extension)));
        let job = crate::prefilter::PrefilterJob {
            probe: Some(probe.to_path_buf()),
            mapping,
            target,
            face_size: p.face_size,
            samples: p.samples,
            texel,
            output: Some(path.clone()),
            latlong: None,
            latlong_width: None,
            irradiance,
            irradiance_size: p.irradiance_size.unwrap_or(32),
            sh: None,
            sh_format: ShFileFormat::Json,
            bands: 3,
            dfg: None,
            dfg_size: 128,
            dfg_layout: ibl_mapping::DfgLayout::ScaleBias,
            preview: None,
        };
        let mut summary = to_json(&crate::prefilter::prefilter(&job, progress)?);
        summary["file"] = json!(rel(&path));
        out.push(("prefilter", summary));
    }
    if let Some(p) = &s.preview {
        let path = folder.join("preview.png");
        let stops = crate::preview::preview(probe, &path, p.exposure, t.curve)?;
        out.push((
            "preview",
            json!({ "exposure_stops": stops, "curve": t.curve.name(), "file": rel(&path) }),
        ));
    }
    if let Some(e) = &s.eval {
        let mut settings = crate::eval::EvalSettings::new(
            t.eval_methods.clone(),
            e.n.clone(),
            e.normals,
            e.seed,
            None,
        )?;
        settings.mapping = mapping;
        let dir = folder.join("eval");
        let report = crate::eval::evaluate(&[probe.to_path_buf()], &settings, &dir, progress)?;
        out.push((
            "eval",
            json!({ "averages": to_json(&report.averages), "folder": rel(&dir) }),
        ));
    }
    Ok(out)
}

fn sh_extension(format: ShFileFormat) -> &'static str {
    match format {
        ShFileFormat::Json => "json",
        _ => "txt",
    }
}

fn to_json<T: Serialize>(value: &T) -> Value {
    serde_json::to_value(value).unwrap_or(Value::Null)
}

/// Gathers every item's row, in input order, into the rows file (written atomically); an item
/// without a row (not run yet) is left out and counted as missing in the summary's `failed`.
/// `ran` and `skipped` are the caller's counts of items run now and found done before.
pub fn finish(
    spec: &BatchSpec,
    plan: &BatchPlan,
    ran: usize,
    skipped: usize,
    start: Instant,
) -> Result<BatchSummary> {
    let mut text = String::new();
    let mut ok = 0;
    let mut failed = Vec::new();
    for item in &plan.items {
        let row = read_row(&spec.out.join(&item.id).join("row.json"))
            .filter(|r| r["steps_sha256"] == plan.steps_sha256);
        match row {
            Some(row) => {
                if row["status"] == "ok" {
                    ok += 1;
                } else {
                    let message = row["error"].as_str().unwrap_or("failed").to_string();
                    failed.push((item.id.clone(), message));
                }
                text.push_str(&row.to_string());
                text.push('\n');
            }
            None => failed.push((item.id.clone(), "not run".to_string())),
        }
    }
    ibl_io::write_atomically(&spec.rows, text.as_bytes())?;
    Ok(BatchSummary {
        items: plan.items.len(),
        ran,
        skipped,
        ok,
        failed,
        rows: spec.rows.display().to_string(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// A whole batch on this machine: the pending items `jobs` at a time (each step also spreads
/// its own loops over every core, through rayon's global pool), then [`finish`]. Progress: one
/// step per item.
pub fn run_batch(
    spec: &BatchSpec,
    jobs: usize,
    retry_failed: bool,
    progress: &dyn Progress,
) -> Result<BatchSummary> {
    let start = Instant::now();
    let plan = plan(spec, retry_failed)?;
    let pending: Vec<&BatchItem> = plan.pending().collect();
    let skipped = plan.items.len() - pending.len();
    if skipped > 0 {
        progress.note(&format!("{skipped} probes done by an earlier run: skipped"));
    }
    progress.begin("batch", pending.len() as u64);
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let first_error: Mutex<Option<PipelineError>> = Mutex::new(None);
    let worker = || {
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = pending.get(i) else { break };
            match run_item(spec, item) {
                Ok(row) => {
                    if row["status"] != "ok" {
                        progress.note(&format!(
                            "{}: {}",
                            item.probe.display(),
                            row["error"].as_str().unwrap_or("failed")
                        ));
                    }
                }
                Err(e) => {
                    // The row could not be written: the output folder broke; stop taking items.
                    if let Ok(mut slot) = first_error.lock() {
                        slot.get_or_insert(e);
                    }
                    next.store(pending.len(), Ordering::Relaxed);
                }
            }
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress.update(n as u64, pending.len() as u64, Some(&item.id));
        }
    };
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, pending.len().max(1)) {
            scope.spawn(worker);
        }
    });
    progress.end();
    if let Some(e) = first_error.into_inner().ok().flatten() {
        return Err(e);
    }
    finish(spec, &plan, pending.len(), skipped, start)
}
