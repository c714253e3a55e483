"""Trajectories kept by a campaign run (``run --trajectories``): the flight record of each chosen
realization decimated, bit for bit, consistent with its ``/outputs`` row, bounded in rows; bad choices refused in
one line with nothing left; a killed run resumes to the same file; a run without them is unchanged."""

from __future__ import annotations

import json
import math
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest

from rocketmc.analysis import format_summary, load_outputs, load_run, load_trajectories, summarize
from rocketmc.campaign import flights as flights_module
from rocketmc.campaign import load_campaign, with_overrides
from rocketmc.campaign.flights import flight_record
from rocketmc.ellipse import AreaConvergence
from rocketmc.cli import main
from rocketmc.env import G0

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

CAMPAIGNS = Path(__file__).parents[2] / "campaigns"
N, SEED, KEPT, INTERVAL_S = 6, 3, (1, 4), 0.1
ARGS = ["-n", str(N), "--seed", str(SEED), "--quiet"]


@pytest.fixture(scope="module")
def campaign_file(tmp_path_factory):
    """lynx_ballistic (no parachutes: down in ~40 s) stopped at 60 s instead of 300 s: each flight record flies
    3000 periods instead of 15 000."""
    text = (CAMPAIGNS / "lynx_ballistic.toml").read_text()
    assert "max_time_s = 300.0" in text
    path = tmp_path_factory.mktemp("campaign") / "lynx_ballistic_60s.toml"
    path.write_text(text.replace("max_time_s = 300.0", "max_time_s = 60.0"))
    return path


@pytest.fixture(scope="module")
def campaign(campaign_file):
    """The campaign as ``run`` flies it: the same set-up, so ``flight_record`` reuses the run's compiled flight."""
    return with_overrides(load_campaign(campaign_file), n_realizations=N, seed=SEED)


@pytest.fixture(scope="module")
def kept(campaign_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("kept") / "kept.h5"
    assert main(["run", str(campaign_file), *ARGS, "--trajectories", "4,1,4", "--out", str(out)]) == 0
    return out


def contents(path) -> dict:
    """(values or None, attributes) of every dataset and group of an HDF5 file, by path ("/": the root)."""
    with h5py.File(path) as f:
        found = {"/": (None, dict(f.attrs))}
        f.visititems(lambda name, item: found.update({name: (item[()] if isinstance(item, h5py.Dataset) else None,
                                                             dict(item.attrs))}))  # fmt: skip
    return found


def assert_same(got: dict, want: dict) -> None:
    assert got.keys() == want.keys()
    for name, (values, attrs) in want.items():
        np.testing.assert_array_equal(got[name][0], values, err_msg=name)  # bit for bit, NaNs equal
        assert got[name][1].keys() == attrs.keys(), name
        for key in attrs:
            np.testing.assert_array_equal(got[name][1][key], attrs[key], err_msg=f"{name} {key}")


def test_the_kept_trajectories_are_the_flight_records_decimated(kept, campaign):
    trajectories = load_trajectories(kept)
    assert list(trajectories) == list(KEPT)  # ascending, each once
    for index, got in trajectories.items():
        record = flight_record(campaign, index)
        t = record.series["time"].to_numpy()
        rows = [k for k in range(len(t))  # the first sample of each 0.1 s of time, and the last
                if k in (0, len(t) - 1) or math.floor(t[k] / INTERVAL_S) > math.floor(t[k - 1] / INTERVAL_S)]
        pd.testing.assert_frame_equal(got, record.series.iloc[rows].reset_index(drop=True), check_exact=True)
        assert got.attrs["units"] == {name: (m.unit, m.meaning) for name, m in record.columns.items()}
        assert got.attrs["status"] == record.status
    with h5py.File(kept) as f:
        group = f["trajectories"]
        assert list(group.attrs["realizations"]) == list(KEPT) and group.attrs["interval_s"] == INTERVAL_S
        assert "decimated" in group.attrs["description"]
        assert group["1/altitude"].attrs["unit"] == "m" and group["1"].attrs["status_message"] == "ok"


def test_the_kept_trajectories_end_at_their_rows_impact(kept, campaign):
    outputs = load_outputs(kept)
    h = campaign.config.simulation.control_dt_s  # no parachute: every period is one control period
    for index, s in load_trajectories(kept).items():
        row = outputs.loc[index]
        assert row["status"] == s.attrs["status"] == 0
        t, last = s["time"].to_numpy(), s.iloc[-1]
        # the last row is the first period start at or after impact: within one period of it, below the pad and
        # as far from the impact point as the speed carries it in that time (the largest of the last two rows'
        # speeds, 1 % more: over one period the speed changes by ~g·h/V, 0.2 % at 100 m/s)
        assert row["impact_time_s"] <= last["time"] < row["impact_time_s"] + h * (1 + 1e-9)  # rounding of t's sum
        speed, v_down = (1.01 * s[name].abs().iloc[-2:].max() for name in ("speed", "v_down"))
        assert -v_down * h <= last["altitude"] <= 0.0
        assert math.hypot(last["north"] - row["impact_north_m"], last["east"] - row["impact_east_m"]) <= speed * h
        # the highest kept sample is at most S + h from the apogee, so below it by at most ½·a·(S + h)², a ≤ 2·g0
        # (gravity and the lift of a rocket pitching over, tests/analysis/test_flight_record.py); never above it
        # but for the Hermite apogee's own error (nanometres)
        top = int(np.argmax(s["altitude"].to_numpy()))
        assert abs(t[top] - row["apogee_time_s"]) <= INTERVAL_S + h
        assert -1e-6 <= row["apogee_agl_m"] - s["altitude"].iloc[top] <= G0 * (INTERVAL_S + h) ** 2


def test_the_kept_trajectories_are_bounded(kept):
    with h5py.File(kept) as f:
        for index in KEPT:
            group = f[f"trajectories/{index}"]
            rows, t_end = group["time"].shape[0], group["time"][-1]
            assert rows <= math.floor(t_end / INTERVAL_S) + 2  # the bound of docs/validation.md
            assert rows < group.attrs["samples"] / 4  # 20 ms periods: one in five kept (and the last)
            assert {ds.shape for ds in group.values()} == {(rows,)}


def test_a_run_without_trajectories_is_unchanged(kept, campaign_file, tmp_path):
    out = tmp_path / "plain.h5"
    assert main(["run", str(campaign_file), *ARGS, "--out", str(out)]) == 0
    plain, with_them = contents(out), contents(kept)
    assert "trajectories" in with_them and "trajectories" not in plain
    assert_same(plain, {k: v for k, v in with_them.items() if not k.startswith("trajectories")})  # same fingerprint
    assert load_trajectories(out) == {} and "Trajectories" not in format_summary(summarize(load_run(out)))


def test_report_says_which_trajectories_are_kept(kept, capsys):
    assert main(["report", str(kept)]) == 0
    assert "Trajectories kept (rocketmc.analysis.load_trajectories): realizations 1, 4" in capsys.readouterr().out
    assert main(["report", str(kept), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["trajectories"] == list(KEPT)


def exit_code(argv) -> int:
    try:
        return main(argv)
    except SystemExit as e:  # argparse's errors
        return e.code


@pytest.mark.parametrize("options, needle", [
    (["--trajectories", "1,x"], "--trajectories 1,x: expected realization indices"),
    (["--trajectories", "1,,2"], "expected realization indices"),
    (["--trajectories", "-1"], "expected realization indices"),
    (["--trajectories", ""], "expected realization indices"),
    (["--trajectories", "2,6"], "--trajectories 6: not a realization of lynx_ballistic (0 to 5)"),
    (["-n", "200", "--trajectories", ",".join(map(str, range(101)))], "101 realizations, at most 100"),
    (["--trajectories", "1", "--trajectory-interval", "0"], "argument --trajectory-interval: must be a positive time"),
    (["--trajectories", "1", "--trajectory-interval", "nan"], "argument --trajectory-interval: must be a positive time"),
])  # fmt: skip
def test_bad_trajectories_exit_2_and_leave_nothing(campaign_file, tmp_path, capsys, options, needle):
    out = tmp_path / "never.h5"
    assert exit_code(["run", str(campaign_file), "-n", str(N), *options, "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rocketmc: error: ") and needle in lines[0], lines
    assert not list(tmp_path.iterdir())  # no result file, no partial folder


def test_a_run_killed_while_flying_them_resumes_to_the_same_file(kept, campaign_file, tmp_path, capsys, monkeypatch):
    out = tmp_path / "killed.h5"
    argv = ["run", str(campaign_file), *ARGS, "--trajectories", "1,4", "--out", str(out)]
    flown = []

    def interrupted(campaign, index):  # the first flown, then a Ctrl-C while flying the second
        if flown:
            raise KeyboardInterrupt
        flown.append(index)
        return flight_record(campaign, index)

    monkeypatch.setattr(flights_module, "flight_record", interrupted)
    assert main(argv) == 130
    monkeypatch.undo()
    partial = Path(str(out) + ".partial")
    assert not out.exists() and sorted(p.name for p in partial.iterdir()) == ["chunk_000000.h5", "manifest.json", "run.lock"]
    capsys.readouterr()
    assert main([*argv[:-2], "--trajectories", "1", "--out", str(out), "--resume"]) == 2  # other trajectories
    assert "(trajectories.realizations differ)" in capsys.readouterr().err and not out.exists()
    assert main([*argv, "--resume"]) == 0 and not partial.exists()
    assert_same(contents(out), contents(kept))
    assert main([*argv, "--resume", "--trajectory-interval", "0.5"]) == 2  # complete already, with other ones
    assert "keeping other trajectories than asked" in capsys.readouterr().err


def test_trajectories_beyond_the_n_until_converged_reaches_are_left_out(campaign_file, tmp_path, capsys, monkeypatch):
    """--until-converged stopped at 4 of 6 (convergence made to come after 2 chunks of 2: the test is of what is
    kept, not of the bootstrap): realization 4's trajectory is left out, with a warning the file keeps."""

    def after_two_chunks(self):
        self.converged = self.n >= 4
        return self.converged

    monkeypatch.setattr(AreaConvergence, "check", after_two_chunks)
    out = tmp_path / "converged.h5"
    argv = ["run", str(campaign_file), *ARGS, "--chunk-size", "2", "--until-converged", "50", "--trajectories", "1,4"]
    assert main([*argv, "--out", str(out)]) == 0
    warning = "--trajectories 4: beyond the 4 realizations --until-converged kept, so not in /trajectories"
    assert f"rocketmc: warning: {warning}" in capsys.readouterr().err.splitlines()
    assert list(load_trajectories(out)) == [1]
    with h5py.File(out) as f:
        assert f.attrs["n_realizations"] == 4 and list(f["trajectories"].attrs["realizations"]) == [1, 4]
        assert warning in json.loads(f.attrs["warnings"])
