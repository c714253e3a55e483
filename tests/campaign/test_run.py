"""``run_campaign``, the one run loop (the CLI's ``run``, the notebook's and Python users'): the file it writes is
the CLI's bit for bit, its progress and warnings go where the caller says, and a partial folder is written by one
run at a time (an OS lock, released however the holder ends)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from rocketmc.campaign import load_campaign, with_overrides
from rocketmc.campaign.run import RunWarning, run_campaign
from rocketmc.campaign.store import ResultWriter, ResumeError
from rocketmc.cli import main
from rocketmc.errors import RocketmcError

from ..conftest import CAMPAIGNS

N, SEED, CHUNK = 16, 3, 8


@pytest.fixture(scope="module")
def campaign():
    return with_overrides(load_campaign(CAMPAIGNS / "lynx_ballistic.toml"), n_realizations=N, seed=SEED)


def rows(path):
    with h5py.File(path) as f:
        return {f"{g}/{k}": ds[()] for g in ("outputs", "inputs") for k, ds in f[g].items()}


def test_the_library_run_is_the_cli_run(campaign, tmp_path):
    lines = []
    out = run_campaign(campaign, tmp_path / "lib.h5", chunk_size=CHUNK, progress=lambda line, transient=False: lines.append(line))
    assert main(["run", str(CAMPAIGNS / "lynx_ballistic.toml"), "-n", str(N), "--seed", str(SEED), "--chunk-size",
                 str(CHUNK), "--out", str(tmp_path / "cli.h5"), "--quiet"]) == 0  # fmt: skip
    got, want = rows(out), rows(tmp_path / "cli.h5")
    assert got.keys() == want.keys()
    for name in want:
        np.testing.assert_array_equal(got[name], want[name], err_msg=name)
    assert lines[0].startswith("lynx_ballistic: 16 realizations, seed 3, 2 chunk(s) of 8")
    assert lines[-1].startswith(f"wrote {out}")
    with pytest.raises(RocketmcError, match="the file exists; use --resume"):
        run_campaign(campaign, out)


def test_warnings_are_python_warnings_by_default(tmp_path):
    unstable = with_overrides(load_campaign(CAMPAIGNS / "unstable_rocket.toml"), n_realizations=8)
    with pytest.warns(RunWarning) as caught:
        run_campaign(unstable, tmp_path / "unstable.h5")
    said = [str(w.message) for w in caught]  # the margins at liftoff and burnout, then where the tumbling flights went
    kinds = ("static margin", "left the aerodynamic tables' range", "opens at apogee there")  # the main's 800 m: above
    assert [tuple(kind in line for kind in kinds) for line in said] == [  # the tumbling flights' apogees
        (True, False, False), (True, False, False), (False, True, False), (False, False, True)], said


def test_trajectories_are_checked_before_any_flight(campaign, tmp_path):
    with pytest.raises(RocketmcError, match=f"--trajectories {N}: not a realization"):
        run_campaign(campaign, tmp_path / "t.h5", trajectories_of=[0, N])
    with pytest.raises(RocketmcError, match="at most 100 are kept"):
        run_campaign(campaign, tmp_path / "t.h5", trajectories_of=range(101))
    assert not list(tmp_path.iterdir())


def test_a_partial_folder_in_use_is_refused_and_freed_when_its_run_ends(campaign, tmp_path):
    out = tmp_path / "locked.h5"
    holder = ResultWriter(out, campaign, CHUNK)  # a run in progress in this process
    with pytest.raises(ResumeError, match="in use by another rocketmc run"):
        ResultWriter(out, campaign, CHUNK, resume=True)
    with pytest.raises(ResumeError, match="in use by another rocketmc run"):
        run_campaign(campaign, out, chunk_size=CHUNK, resume=True)
    holder.close()
    assert run_campaign(campaign, out, chunk_size=CHUNK, resume=True) == out and not Path(f"{out}.partial").exists()


def test_a_killed_holder_frees_the_folder(campaign, tmp_path):
    # Another process holds the lock, as a run writing its chunks does; SIGKILL leaves no chance to unlock: the
    # system releases it.
    out = tmp_path / "killed.h5"
    ResultWriter(out, campaign, CHUNK).close()  # the partial folder, with its manifest
    script = ("import fcntl, sys, time; f = open(sys.argv[1], 'a'); fcntl.flock(f, fcntl.LOCK_EX); "
              "print('held', flush=True); time.sleep(600)")  # fmt: skip
    process = subprocess.Popen([sys.executable, "-c", script, f"{out}.partial/run.lock"], stdout=subprocess.PIPE, text=True)
    try:
        assert process.stdout.readline().strip() == "held"
        code = main(["run", str(CAMPAIGNS / "lynx_ballistic.toml"), "-n", str(N), "--seed", str(SEED), "--chunk-size",
                     str(CHUNK), "--out", str(out), "--resume", "--quiet"])  # fmt: skip
        assert code == 2
    finally:
        os.kill(process.pid, signal.SIGKILL)
        process.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:  # the kernel releases the lock as the process is reaped
        try:
            ResultWriter(out, campaign, CHUNK, resume=True).close()
            break
        except ResumeError:
            time.sleep(0.05)
    else:
        pytest.fail("the lock outlived its holder")
