"""Shared fixtures: the repository's bundled data and the `ibl` binary the Rust tests built.

`IBL_BIN` names the binary; by default `target/debug/ibl` (what `cargo nextest run` builds,
which `.ci/run` runs before this suite).
"""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
PROBES = ROOT / "assets" / "probes"


@pytest.fixture(scope="session")
def ibl():
    """Runs `ibl ARGS...`; returns the completed process (check=True)."""
    binary = pathlib.Path(os.environ.get("IBL_BIN", ROOT / "target" / "debug" / "ibl"))
    if not binary.exists():
        pytest.fail(f"{binary}: no ibl binary; build it (cargo build) or set IBL_BIN")

    def run(*args, check=True):
        return subprocess.run(
            [str(binary), *map(str, args)], capture_output=True, text=True, check=check
        )

    return run


@pytest.fixture(scope="session")
def sky():
    return PROBES / "sky.exr"


def read_json(path):
    return json.loads(pathlib.Path(path).read_text())
