"""The CLI's one error path: every failure
a user can cause is one line ``rocketmc: error: ...`` naming the option, field or file, exit code 2,
nothing printed before it and no file written. Result files are made here with h5py (the contract
of docs/conventions.md), so nothing is flown."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from rocketmc.cli import main

from .conftest import CAMPAIGNS


def write_result(path: Path, n: int = 50, drop: tuple[str, ...] = (), complete: bool = True, **datasets) -> Path:
    """A result file of ``n`` realizations with impacts spread around the pad; ``drop``: outputs left out."""
    rng = np.random.default_rng(0)
    outputs = {"status": np.zeros(n, np.int32), "impact_north_m": rng.normal(0, 300, n),
               "impact_east_m": rng.normal(100, 200, n), "apogee_agl_m": rng.normal(3000, 50, n), **datasets}  # fmt: skip
    with h5py.File(path, "w") as f:
        f.attrs.update({"campaign_name": "crafted", "seed": 1, "n_realizations": n, "complete": complete,
                        "campaign_toml": (CAMPAIGNS / "lynx_nominal.toml").read_text()})  # fmt: skip
        for name, values in outputs.items():
            if name not in drop:
                f.create_dataset(f"outputs/{name}", data=values)
        if "status" not in drop:
            f["outputs/status"].attrs["codes"] = json.dumps({"0": "ok"})
    return path


@pytest.fixture
def result(tmp_path):
    return write_result(tmp_path / "run.h5")


def one_line(capsys, argv, *needles, code=2) -> str:
    """Run the CLI: exit ``code``, nothing on stdout, one stderr line holding every needle."""
    try:
        assert main(argv) == code
    except SystemExit as e:  # argparse's errors exit
        assert e.code == code
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert captured.out == "" and len(lines) == 1 and lines[0].startswith("rocketmc: error: "), captured
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def files_in(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


# --- report: outputs that cannot be written are refused before anything is printed ----------------

@pytest.mark.parametrize("option", ["--plot", "--map"])
@pytest.mark.parametrize("target, needle", [
    ("missing_folder/out", "no folder"),
    ("a_folder", "is a folder"),
    ("a_file/out", "no folder"),  # under a file
])  # fmt: skip
def test_report_outputs_that_cannot_be_written(result, tmp_path, capsys, option, target, needle):
    (tmp_path / "a_folder.png").mkdir()
    (tmp_path / "a_folder.kml").mkdir()
    (tmp_path / "a_file").write_text("")
    suffix = ".png" if option == "--plot" else ".kml"
    before = files_in(tmp_path)
    one_line(capsys, ["report", str(result), option, str(tmp_path / target) + suffix], option, needle)
    assert files_in(tmp_path) == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_report_into_a_read_only_folder(result, tmp_path, capsys):
    folder = tmp_path / "read_only"
    folder.mkdir(mode=0o555)
    one_line(capsys, ["report", str(result), "--plot", str(folder / "x.png")], "--plot", "not writable")


@pytest.mark.parametrize("option, name", [("--plot", "impacts.xyz"), ("--plot", "impacts"), ("--map", "impacts.txt")])
def test_report_output_of_an_unknown_kind(result, tmp_path, capsys, option, name):
    one_line(capsys, ["report", str(result), option, str(tmp_path / name)], option, name, "expected a")
    assert files_in(tmp_path) == ["run.h5"]


def test_report_writes_its_figure_and_maps_whole(result, tmp_path, capsys):
    """The accepted outputs are written (through a temporary name: none is left behind)."""
    png, kml = tmp_path / "impacts.png", tmp_path / "impacts.kml"
    assert main(["report", str(result), "--plot", str(png), "--map", str(kml)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "<kml" in kml.read_text()
    assert files_in(tmp_path) == ["impacts.kml", "impacts.png", "run.h5"]


# --- report: files that are not complete result files ---------------------------------------------

@pytest.mark.parametrize("make, needle", [
    (lambda p: write_result(p, drop=("status",)), "/outputs/status"),
    (lambda p: write_result(p, drop=("impact_north_m", "impact_east_m")), "/outputs/impact_north_m"),
    (lambda p: write_result(p, complete=False), "incomplete"),
    (lambda p: write_result(p, apogee_agl_m=np.array([b"x"] * 50)), "/outputs/apogee_agl_m"),  # not numbers
    (lambda p: write_result(p, apogee_agl_m=np.zeros((50, 2))), "not a 1-D array"),
    (lambda p: write_result(p, apogee_agl_m=np.zeros(49)), "differ in length"),
    (lambda p: p.write_text("status,impact_north_m\n0,1\n"), "not an HDF5 file"),
    (lambda p: p.write_bytes(b""), "not an HDF5 file"),
    (lambda p: p.write_bytes(write_result(p).read_bytes()[:3000]), "not an HDF5 file, or damaged"),  # truncated
    (lambda p: h5py.File(p, "w").close(), "no /outputs group"),
    (lambda p: p.mkdir(), "not an HDF5 file"),
    (lambda p: None, "file not found"),
])  # fmt: skip
def test_report_on_a_file_that_is_not_a_result(tmp_path, capsys, make, needle):
    path = tmp_path / "file.h5"
    make(path)
    one_line(capsys, ["report", str(path)], str(path), needle)


def test_report_on_status_codes_that_are_not_json(tmp_path, capsys):
    path = write_result(tmp_path / "run.h5")
    with h5py.File(path, "r+") as f:
        f["outputs/status"].attrs["codes"] = "{not json"
    one_line(capsys, ["report", str(path)], str(path), "codes")


def test_report_into_a_closed_pipe_is_quiet(result):
    """``rocketmc report FILE | head -n 3``: the reader leaves early; no traceback, no message."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run(f"'{sys.executable}' -m rocketmc.cli report '{result}' | head -n 3", shell=True, env=env,
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert len(done.stdout.splitlines()) == 3 and done.stderr == "", done.stderr


# --- run, aero derivatives, validate: options and files ------------------------------------------

@pytest.mark.parametrize("argv, needle", [
    (["run", "CAMPAIGN", "--until-converged", "inf"], "--until-converged"),
    (["run", "CAMPAIGN", "--until-converged", "nan"], "--until-converged"),
    (["run", "CAMPAIGN", "--until-converged", "0"], "--until-converged"),
    (["run", "CAMPAIGN", "--until-converged", "150"], "--until-converged"),
    (["run", "CAMPAIGN", "--workers", "100000"], "--workers"),
    (["run", "CAMPAIGN", "-n", "0"], "-n"),
    (["run", "CAMPAIGN", "-n", "10000000000"], "n_realizations"),
    (["run", "CAMPAIGN", "--seed", "-1"], "seed"),
    (["run", "CAMPAIGN", "--seed", str(2**32)], "seed"),
    (["run", "CAMPAIGN", "--chunk-size", "0"], "--chunk-size"),
    (["aero", "derivatives", "lynx", "--mach", "nan"], "--mach"),
    (["aero", "derivatives", "lynx", "--mach", "-1"], "--mach"),
    (["aero", "derivatives", "lynx", "--altitude", "1e9"], "--altitude"),
    (["aero", "derivatives", 'lynx"\n[site]'], "rocket.preset"),
    (["aero", "derivatives", "missing.toml"], "missing.toml"),
])  # fmt: skip
def test_options_out_of_range(tmp_path, capsys, argv, needle):
    argv = [str(CAMPAIGNS / "lynx_nominal.toml") if a == "CAMPAIGN" else a for a in argv]
    monkey_out = ["--out", str(tmp_path / "x.h5")] if argv[0] == "run" else []
    one_line(capsys, [*argv, *monkey_out], needle)
    assert files_in(tmp_path) == []


@pytest.mark.parametrize("content, needle", [
    (b"\x89HDF\r\n\x1a\n\x00\x00\xff\xfe binary", "not valid"),  # binary bytes where TOML text is expected
    (b"name = 'x'\nn_realizations = [", "not valid TOML"),
])  # fmt: skip
def test_a_campaign_file_that_is_not_toml(tmp_path, capsys, content, needle):
    campaign = tmp_path / "c.toml"
    campaign.write_bytes(content)
    one_line(capsys, ["run", str(campaign), "--out", str(tmp_path / "x.h5")], str(campaign), needle)
    assert files_in(tmp_path) == ["c.toml"]


def test_aero_derivatives_of_a_campaign_with_a_binary_thrust_file(tmp_path, capsys):
    campaign = tmp_path / "c.toml"
    text = (CAMPAIGNS / "lynx_nominal.toml").read_text()
    campaign.write_text(text.replace('preset = "lynx"', 'preset = "lynx"\nmotor.thrust_curve = "motor.eng"'))
    (tmp_path / "motor.eng").write_bytes(bytes(range(256)) * 4)
    one_line(capsys, ["aero", "derivatives", str(campaign)], str(campaign), "rocket.motor.thrust_curve")


def test_validate_plots_into_a_file(tmp_path, capsys):
    (tmp_path / "a_file").write_text("")
    """Refused before the flight is flown."""
    one_line(capsys, ["validate", "roccaraso-2021", "--plot", str(tmp_path / "a_file" / "plots")], "a_file")


# --- data files are never overwritten without --force -----------------------------------------

def test_run_refuses_an_existing_result_file(tmp_path, capsys):
    """An existing --out is kept byte for byte; the line names it and the two ways on."""
    out = write_result(tmp_path / "x.h5")
    before = out.read_bytes()
    one_line(capsys, ["run", str(CAMPAIGNS / "lynx_ballistic.toml"), "--out", str(out)], "--out", str(out),
             "exists", "--resume", "--force")  # fmt: skip
    assert out.read_bytes() == before and files_in(tmp_path) == ["x.h5"]


def test_run_resume_and_force_are_exclusive(tmp_path, capsys):
    one_line(capsys, ["run", str(CAMPAIGNS / "lynx_ballistic.toml"), "--resume", "--force"], "--force", "--resume")


def test_report_refuses_an_existing_map_unless_forced(result, tmp_path, capsys):
    kml = tmp_path / "impacts.kml"
    kml.write_text("mine")
    one_line(capsys, ["report", str(result), "--map", str(kml)], "--map", "exists", "--force")
    assert kml.read_text() == "mine"
    assert main(["report", str(result), "--map", str(kml), "--force"]) == 0
    assert "<kml" in kml.read_text()


def test_navigate_and_sensors_refuse_existing_data_files(tmp_path, capsys):
    nav = tmp_path / "nav.csv"
    nav.write_text("mine")
    one_line(capsys, ["navigate", str(tmp_path), "--out", str(nav)], "--out", "exists", "--force")
    (tmp_path / "log").mkdir()
    (tmp_path / "log" / "baro_ms5803_66hz.csv").write_text("mine")
    one_line(capsys, ["sensors", "simulate", str(CAMPAIGNS / "lynx_nominal.toml"), "--out", str(tmp_path / "log")],
             "--out", "baro_ms5803_66hz.csv", "exists", "--force")  # fmt: skip
    assert nav.read_text() == "mine" and (tmp_path / "log" / "baro_ms5803_66hz.csv").read_text() == "mine"
