"""Batches: a local two-worker Dask cluster over the bundled probes, results equal to the CLI's,
per-item failures, and a killed batch that finishes with every probe exactly once."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import iblkit
from iblkit import batch
from conftest import PROBES, read_json


def write_spec(folder, input_lines, steps):
    spec = folder / "spec.toml"
    spec.write_text(
        "\n".join(
            ["[input]", *input_lines, "", "[output]", 'folder = "out"', "", *steps, ""]
        )
    )
    return spec


STEPS = [
    "[steps.info]",
    "[steps.lights]",
    "n = 16",
    "[steps.sh]",
    "[steps.preview]",
]


def rows_of(spec):
    lines = (spec.parent / "out" / "results.jsonl").read_text().splitlines()
    return [json.loads(line) for line in lines]


def test_two_worker_cluster_runs_the_bundled_probes_like_the_cli(tmp_path, ibl):
    spec = write_spec(tmp_path, [f'folder = "{PROBES}"'], STEPS)
    summary = batch.run(spec, workers=2, threads_per_worker=1)
    probes = sorted(p for p in PROBES.iterdir() if p.suffix in (".exr", ".hdr", ".pfm", ".png"))
    assert summary["items"] == len(probes) == 10
    assert summary["ok"] == 10 and summary["failed"] == [] and summary["ran"] == 10
    rows = rows_of(spec)
    assert sorted(r["probe"] for r in rows) == sorted(map(str, probes))
    # sky.exr and sky.hdr share a stem: their ids carry a hash of the path.
    ids = [r["id"] for r in rows]
    assert len(set(ids)) == 10 and all(i.startswith(p.stem) for i, p in zip(ids, probes))
    for row in rows:
        probe = pathlib.Path(row["probe"])
        folder = spec.parent / "out" / row["id"]
        # The lights and SH files equal the commands' on the same probe.
        cli_lights = tmp_path / f"{row['id']}-lights.json"
        ibl("lights", probe, "-n", "16", "-o", cli_lights)
        assert (folder / "lights.json").read_bytes() == cli_lights.read_bytes()
        cli_sh = json.loads(ibl("sh", probe, "--format", "json").stdout)
        # The same numbers; the SH file's writer prints 17 significant digits, which can land
        # one unit in the last place from the value the row (shortest round trip) holds.
        np.testing.assert_allclose(row["sh"]["coefficients"], cli_sh["coefficients"], rtol=1e-15)
        assert row["info"]["power"] == pytest.approx(
            json.loads(ibl("info", probe, "--json").stdout)["power"], rel=1e-12
        )
        assert (folder / "preview.png").exists()
    # `ibl batch` on the same spec: every row's results equal (another output folder).
    (tmp_path / "cli").mkdir()
    spec2 = write_spec(tmp_path / "cli", [f'folder = "{PROBES}"'], STEPS)
    ibl("batch", spec2)
    for a, b in zip(rows, rows_of(spec2)):
        assert a["id"] == b["id"]
        a["lights"].pop("seconds"), b["lights"].pop("seconds")
        assert a["lights"] == b["lights"] and a["sh"] == b["sh"] and a["info"] == b["info"]


def test_a_rerun_skips_what_is_done_and_failures_are_rows(tmp_path):
    bad = tmp_path / "corrupt.exr"
    bad.write_bytes(b"\x76\x2f\x31\x01 truncated")
    listing = tmp_path / "list.txt"
    listing.write_text(f"# probes\n{PROBES / 'sky.exr'}\n{bad}\n{PROBES / 'night.exr'}\n")
    spec = write_spec(tmp_path, ['list = "list.txt"'], STEPS)
    first = batch.run(spec, workers=2, threads_per_worker=1)
    assert first["ok"] == 2 and [f[0] for f in first["failed"]] == ["corrupt"]
    failed = [r for r in rows_of(spec) if r["status"] == "failed"]
    assert failed[0]["error_kind"] == "bad-input" and "corrupt.exr" in failed[0]["error"]
    again = batch.run(spec, workers=1)
    assert again["ran"] == 0 and again["skipped"] == 3
    retried = batch.run(spec, workers=1, retry_failed=True)
    assert retried["ran"] == 1
    assert len(rows_of(spec)) == 3
    # The command line says which probe failed and exits 2.
    done = subprocess.run(
        [sys.executable, "-m", "iblkit.batch", str(spec), "--retry-failed"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2 and "corrupt" in done.stdout


def test_a_killed_batch_finishes_with_every_item_exactly_once(tmp_path):
    spec = write_spec(
        tmp_path,
        [f'folder = "{PROBES}"'],
        [*STEPS, "[steps.irradiance]", "width = 32"],
    )
    out = tmp_path / "out"
    first = subprocess.Popen(
        [sys.executable, "-m", "iblkit.batch", str(spec), "--workers", "2"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    # Kill the whole process group (the command and its Dask workers) once a probe is done.
    deadline = time.monotonic() + 120
    while not list(out.glob("*/row.json")) and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    done_before = {p.parent.name for p in out.glob("*/row.json")}
    assert 1 <= len(done_before) < 10, "the batch must be killed part of the way through"
    assert not (out / "results.jsonl").exists()
    summary = batch.run(spec, workers=2, threads_per_worker=1)
    assert summary["skipped"] == len(done_before)
    assert summary["ran"] == 10 - len(done_before)
    rows = rows_of(spec)
    assert len(rows) == 10 and len({r["id"] for r in rows}) == 10
    assert all(r["status"] == "ok" for r in rows)
    for row in rows:
        assert (out / row["id"] / "irradiance.exr").exists()


def test_a_bad_spec_names_the_key(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text('[input]\nfolder = "x"\n[output]\nfolder = "o"\n[steps.lights]\nn = 4\nmethd = "x"\n')
    with pytest.raises(iblkit.BadInputError, match="methd"):
        iblkit.batch_plan(spec)
