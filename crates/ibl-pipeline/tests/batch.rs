//! The batch job (`ibl_pipeline::batch`, issue 19): the spec's checks, item ids, rows, restarts,
//! failures as rows, and the files equal to the single jobs'. Probes are small synthetic skies
//! written to a temporary folder, so each test takes well under a second.

use std::path::{Path, PathBuf};

use ibl_core::SyntheticSky;
use ibl_io::WriteOptions;
use ibl_pipeline::Silent;
use ibl_pipeline::batch::{self, run_batch};
use ibl_pipeline::batch_spec::{BatchSpec, join_lexically};
use serde_json::Value;

fn write_probe(path: &Path, sun_x: f64) {
    let sky = SyntheticSky {
        sun_direction: glam::DVec3::new(sun_x, 0.5, -0.8).normalize(),
        ..SyntheticSky::default()
    };
    ibl_io::write_image(path, &sky.render(64, 32), &WriteOptions::default()).expect("write probe");
}

/// A folder with `n` probes `probe0.exr` ... and a spec over it.
fn batch_folder(n: usize, steps: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("temp dir");
    let probes = dir.path().join("probes");
    std::fs::create_dir(&probes).expect("mkdir");
    for i in 0..n {
        write_probe(&probes.join(format!("probe{i}.exr")), 0.1 * i as f64);
    }
    let spec = dir.path().join("spec.toml");
    let text = format!("[input]\nfolder = \"probes\"\n\n[output]\nfolder = \"out\"\n\n{steps}");
    std::fs::write(&spec, text).expect("write spec");
    (dir, spec)
}

const STEPS: &str = "[steps.info]\n[steps.lights]\nn = 4\n[steps.sh]\n[steps.preview]\n";

fn rows(spec: &BatchSpec) -> Vec<Value> {
    let text = std::fs::read_to_string(&spec.rows).expect("rows file");
    text.lines()
        .map(|l| serde_json::from_str(l).expect("a JSON row"))
        .collect()
}

#[test]
fn a_batch_writes_every_probe_files_and_one_row_each() {
    let (_dir, path) = batch_folder(3, STEPS);
    let spec = BatchSpec::read(&path).expect("spec");
    let summary = run_batch(&spec, 2, false, &Silent).expect("batch");
    assert_eq!((summary.items, summary.ran, summary.ok), (3, 3, 3));
    let rows = rows(&spec);
    assert_eq!(rows.len(), 3);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row["id"], format!("probe{i}"));
        assert_eq!(row["status"], "ok");
        assert_eq!(row["format"], batch::ROW_FORMAT);
        assert_eq!(row["lights"]["n"], 4);
        assert_eq!(row["sh"]["coefficients"].as_array().map(Vec::len), Some(9));
        for file in ["lights.json", "sh.json", "preview.png", "row.json"] {
            assert!(
                spec.out.join(format!("probe{i}")).join(file).is_file(),
                "{file}"
            );
        }
    }
}

#[test]
fn batch_files_equal_the_single_jobs_files() {
    let (dir, path) = batch_folder(
        1,
        "[steps.lights]\nn = 8\nmethod = \"lightgen\"\nseed = 5\n",
    );
    let spec = BatchSpec::read(&path).expect("spec");
    run_batch(&spec, 1, false, &Silent).expect("batch");
    let single = dir.path().join("single.json");
    let options = ibl_pipeline::lights::LightsOptions {
        probe: dir.path().join("probes/probe0.exr"),
        mapping: None,
        count: 8,
        method: ibl_light::Method::LightGen,
        seed: 5,
        fit_domain: ibl_extract::FitDomain::Hemispheres,
        outputs: vec![single.clone()],
        frame: ibl_core::FramePreset::Gltf,
        lux_per_unit: 1.0,
        overlay: None,
        ambient_sh: None,
    };
    ibl_pipeline::lights::lights(&options, &Silent).expect("lights job");
    let batch_file = spec.out.join("probe0/lights.json");
    assert_eq!(
        std::fs::read(batch_file).expect("batch file"),
        std::fs::read(single).expect("single file")
    );
}

#[test]
fn a_rerun_skips_done_items_and_other_steps_redo_them() {
    let (_dir, path) = batch_folder(2, STEPS);
    let spec = BatchSpec::read(&path).expect("spec");
    run_batch(&spec, 1, false, &Silent).expect("first");
    let again = run_batch(&spec, 1, false, &Silent).expect("again");
    assert_eq!((again.ran, again.skipped, again.ok), (0, 2, 2));
    // A lost row (a run killed before it was written) is run again; the rest are kept.
    std::fs::remove_file(spec.out.join("probe1/row.json")).expect("remove row");
    let resumed = run_batch(&spec, 1, false, &Silent).expect("resumed");
    assert_eq!((resumed.ran, resumed.skipped), (1, 1));
    assert_eq!(rows(&spec).len(), 2);
    // Other settings make other rows: every item is done again.
    let other = std::fs::read_to_string(&path)
        .expect("spec text")
        .replace("n = 4", "n = 8");
    std::fs::write(&path, other).expect("write spec");
    let changed = BatchSpec::read(&path).expect("spec");
    assert_ne!(changed.steps_sha256(), spec.steps_sha256());
    let redone = run_batch(&changed, 1, false, &Silent).expect("redone");
    assert_eq!((redone.ran, redone.skipped), (2, 0));
    assert!(rows(&changed).iter().all(|r| r["lights"]["n"] == 8));
}

#[test]
fn a_failed_probe_is_a_row_and_the_batch_goes_on() {
    let (dir, path) = batch_folder(2, STEPS);
    std::fs::write(dir.path().join("probes/broken.exr"), b"not an exr").expect("write");
    let spec = BatchSpec::read(&path).expect("spec");
    let summary = run_batch(&spec, 1, false, &Silent).expect("batch");
    assert_eq!((summary.ok, summary.failed.len()), (2, 1));
    let failed = &rows(&spec)[0];
    assert_eq!(failed["id"], "broken");
    assert_eq!(failed["status"], "failed");
    assert_eq!(failed["error_kind"], "bad-input");
    assert!(
        failed["error"]
            .as_str()
            .is_some_and(|e| e.contains("broken.exr"))
    );
    // Failures are done unless asked again.
    let again = run_batch(&spec, 1, false, &Silent).expect("again");
    assert_eq!(again.ran, 0);
    let retried = run_batch(&spec, 1, true, &Silent).expect("retry");
    assert_eq!(retried.ran, 1);
}

#[test]
fn probes_that_share_a_stem_get_ids_with_a_hash() {
    let (dir, path) = batch_folder(1, STEPS);
    write_probe(&dir.path().join("probes/probe0.hdr"), 0.5);
    let spec = BatchSpec::read(&path).expect("spec");
    let plan = batch::plan(&spec, false).expect("plan");
    let ids: Vec<&str> = plan.items.iter().map(|i| i.id.as_str()).collect();
    assert_eq!(ids.len(), 2);
    assert!(
        ids.iter()
            .all(|id| id.starts_with("probe0-") && id.len() == "probe0-".len() + 8)
    );
    assert_ne!(ids[0], ids[1]);
    // The same ids on every plan (a hash of the path, not a counter).
    let again = batch::plan(&spec, false).expect("plan");
    assert_eq!(plan.items, again.items);
}

#[test]
fn the_input_may_be_a_list_a_glob_or_files() {
    let (dir, _) = batch_folder(3, STEPS);
    let list = dir.path().join("list.txt");
    std::fs::write(
        &list,
        "# two of them\nprobes/probe2.exr\n\nprobes/probe0.exr\n",
    )
    .expect("list");
    for input in [
        "list = \"list.txt\"",
        "glob = \"probes/probe[02].exr\"",
        "files = [\"probes/probe0.exr\", \"probes/probe2.exr\"]",
    ] {
        let path = dir.path().join("other.toml");
        let text = format!("[input]\n{input}\n[output]\nfolder = \"o\"\n{STEPS}");
        std::fs::write(&path, text).expect("spec");
        let spec = BatchSpec::read(&path).expect("spec");
        let plan = batch::plan(&spec, false).expect("plan");
        let mut ids: Vec<&str> = plan.items.iter().map(|i| i.id.as_str()).collect();
        ids.sort_unstable();
        assert_eq!(ids, ["probe0", "probe2"], "{input}");
    }
}

#[test]
fn a_bad_spec_is_refused_by_name() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("spec.toml");
    let cases = [
        (
            "[input]\nfolder = \"p\"\n[output]\nfolder = \"o\"\n",
            "no [steps",
        ),
        (
            "[input]\nfolder = \"p\"\nglob = \"*\"\n[output]\nfolder = \"o\"\n[steps.info]\n",
            "exactly one of",
        ),
        (
            "[input]\nfolder = \"p\"\n[output]\nfolder = \"o\"\n[steps.lights]\nn = 4\nmethd = 1\n",
            "methd",
        ),
        (
            "[input]\nfolder = \"p\"\n[output]\nfolder = \"o\"\n[steps.lights]\nn = 4\nmethod = \"kmeans\"\n",
            "[steps.lights] method",
        ),
        (
            "[input]\nfolder = \"p\"\n[output]\nfolder = \"o\"\n[steps.sh]\nformat = \"unreal\"\n",
            "[steps.sh] format",
        ),
        (
            "[input]\nfolder = \"p\"\n[output]\nfolder = \"o\"\nrows = \"../r.jsonl\"\n[steps.info]\n",
            "rows",
        ),
        (
            "[input]\nfiles = []\n[output]\nfolder = \"o\"\n[steps.info]\n",
            "files is empty",
        ),
    ];
    for (text, expected) in cases {
        std::fs::write(&path, text).expect("spec");
        let err = BatchSpec::read(&path).expect_err(text).to_string();
        assert!(err.contains(expected), "{err:?} lacks {expected:?}");
        assert!(err.contains("spec.toml"), "{err:?} names no file");
    }
}

#[test]
fn a_probe_inside_the_output_folder_is_refused_before_any_work() {
    let (dir, _) = batch_folder(1, STEPS);
    let path = dir.path().join("inside.toml");
    std::fs::write(
        &path,
        format!("[input]\nfolder = \"probes\"\n[output]\nfolder = \"probes\"\n{STEPS}"),
    )
    .expect("spec");
    let spec = BatchSpec::read(&path).expect("spec");
    let err = run_batch(&spec, 1, false, &Silent).expect_err("refused");
    assert!(err.is_bad_input() && err.to_string().contains("inside the output folder"));
    assert!(
        !dir.path().join("probes/probe0").exists(),
        "nothing was written"
    );
}

#[test]
fn paths_join_lexically() {
    assert_eq!(
        join_lexically(Path::new("assets/batch"), "../probes"),
        Path::new("assets/probes")
    );
    assert_eq!(join_lexically(Path::new(""), "../x"), Path::new("../x"));
    assert_eq!(
        join_lexically(Path::new("a"), "/abs/b"),
        Path::new("/abs/b")
    );
    assert_eq!(
        join_lexically(Path::new("a/b"), "./../../c"),
        Path::new("c")
    );
}
