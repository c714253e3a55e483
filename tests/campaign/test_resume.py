"""A run killed with SIGKILL and resumed gives the same result file as an uninterrupted one (the full GNC: the
sensors, the navigation filters and the controller, under parachutes, with every error source and every fault on,
tests/campaign/error_sources.py); foreign or damaged partial runs are refused, never overwritten."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from rocketmc.cli import main

from ..conftest import CAMPAIGNS
from .error_sources import assert_every_fault_recorded, write_every_error_source

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

ARGS = ["-n", "160", "--chunk-size", "16", "--seed", "5"]  # 10 chunks of ~0.3 s each after compilation


def contents(path):
    with h5py.File(path) as f:
        return {f"{g}/{k}": ds[()] for g in ("outputs", "inputs") for k, ds in f[g].items()}, dict(f.attrs)


def assert_same(got: dict, want: dict) -> None:
    assert got.keys() == want.keys()
    for name in want:
        np.testing.assert_array_equal(got[name], want[name], err_msg=name)  # bit-identical, NaNs included


@pytest.fixture(scope="module")
def campaign(tmp_path_factory) -> str:
    """lynx_nominal_gnc_1s with every error source and every fault on."""
    return str(write_every_error_source(CAMPAIGNS / "lynx_nominal_gnc_1s.toml", tmp_path_factory.mktemp("campaign")))


def test_killed_run_resumes_to_the_same_bits(tmp_path, capsys, campaign):
    reference = tmp_path / "reference.h5"
    assert main(["run", campaign, *ARGS, "--out", str(reference), "--quiet"]) == 0
    assert capsys.readouterr().err == ""  # --quiet: no progress lines

    out = tmp_path / "killed.h5"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    process = subprocess.Popen([sys.executable, "-m", "rocketmc.cli", "run", campaign, *ARGS, "--out", str(out)],
                               env=env, stderr=subprocess.DEVNULL)  # fmt: skip
    partial = Path(str(out) + ".partial")
    deadline = time.monotonic() + 300
    while not list(partial.glob("chunk_*.h5")) and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.02)
    time.sleep(0.15)  # a fixed moment, about half a chunk after the first one is written: mid-chunk
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert process.returncode == -signal.SIGKILL  # killed mid-run: ≥ 1.5 s of chunks were left after the first
    assert not out.exists() and partial.is_dir()
    assert 1 <= len(list(partial.glob("chunk_*.h5"))) < 10
    assert main(["run", campaign, *ARGS, "--out", str(out), "--resume"]) == 0
    assert not partial.exists()
    (got, got_attrs), (want, want_attrs) = contents(out), contents(reference)
    assert got.keys() == want.keys() and got_attrs["campaign_toml"] == want_attrs["campaign_toml"]
    for name in want:
        np.testing.assert_array_equal(got[name], want[name], err_msg=name)  # bit-identical, NaNs included
    assert_every_fault_recorded(got, 160)
    assert got_attrs["complete"] and list(got_attrs["completed_chunks"]) == list(range(10))


def test_foreign_or_existing_partial_runs_are_refused(tmp_path, capsys, campaign):
    out = tmp_path / "run.h5"
    partial = Path(str(out) + ".partial")
    partial.mkdir()
    (partial / "manifest.json").write_text(json.dumps({"campaign_name": "other", "seed": 1}))
    (partial / "chunk_000000.h5").write_bytes(b"keep me")
    assert main(["run", campaign, *ARGS, "--out", str(out), "--resume"]) == 2
    assert "another campaign" in capsys.readouterr().err
    assert main(["run", campaign, *ARGS, "--out", str(out)]) == 2
    assert "--resume" in capsys.readouterr().err
    assert (partial / "chunk_000000.h5").read_bytes() == b"keep me" and not out.exists()  # untouched
    (partial / "manifest.json").write_text("{not json")
    assert main(["run", campaign, *ARGS, "--out", str(out), "--resume"]) == 2
    assert "not a rocketmc partial run" in capsys.readouterr().err
    assert main(["run", campaign, *ARGS, "--out", str(tmp_path / "never_started.h5"), "--resume"]) == 2
    assert "not a rocketmc partial run" in capsys.readouterr().err
