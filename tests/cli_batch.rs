//! `ibl batch` (issue 19) as a user runs it: a folder with a good and a corrupt probe runs
//! both, prints the summary, names the failed probe, exits 2 like `python -m iblkit.batch`, and
//! a rerun skips both (the failed one until `--retry-failed`).

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use common::{ibl, probe, stderr};

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn a_failed_probe_is_a_row_and_the_batch_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let probes = dir.path().join("probes");
    std::fs::create_dir(&probes).unwrap();
    std::fs::copy(probe("sky.exr"), probes.join("sky.exr")).unwrap();
    std::fs::write(probes.join("broken.exr"), b"not an exr at all").unwrap();
    let spec = dir.path().join("spec.toml");
    std::fs::write(
        &spec,
        "[input]\nfolder = \"probes\"\n[output]\nfolder = \"out\"\n\
         [steps.lights]\nn = 4\n[steps.sh]\n",
    )
    .unwrap();
    let spec = spec.to_str().unwrap();

    let o = ibl(&["batch", spec, "--json"]);
    let (out, err) = (stdout(&o), stderr(&o));
    assert_eq!(o.status.code(), Some(2), "{out}\n{err}");
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(summary["items"], 2, "{out}");
    assert_eq!(summary["ok"], 1, "{out}");
    assert_eq!(summary["failed"][0][0], "broken", "{out}");
    assert!(err.contains("1 of 2 probes failed"), "{err}");
    assert!(dir.path().join("out/sky/lights.json").is_file());
    let rows = std::fs::read_to_string(dir.path().join("out/results.jsonl")).unwrap();
    assert_eq!(rows.lines().count(), 2, "{rows}");
    let broken: serde_json::Value = serde_json::from_str(rows.lines().next().unwrap()).unwrap();
    assert_eq!(broken["status"], "failed", "{rows}");
    assert_eq!(broken["error_kind"], "bad-input", "{rows}");
    assert!(
        broken["error"].as_str().unwrap().contains("broken.exr"),
        "{rows}"
    );

    // Rerun: nothing runs; the failed row still fails the batch.
    let o = ibl(&["batch", spec]);
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(2), "{out}");
    assert!(out.contains("0 run now, 2 done before"), "{out}");
    assert!(out.contains("failed broken"), "{out}");
    // --retry-failed runs the failed one again (and it fails again).
    let o = ibl(&["batch", spec, "--retry-failed"]);
    assert!(
        stdout(&o).contains("1 run now, 1 done before"),
        "{}",
        stdout(&o)
    );
}
