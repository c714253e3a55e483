"""The landing-ellipse notebook runs top to bottom with a small N and draws its figures."""

import json
import sys
import tomllib
from pathlib import Path

import nbformat
import pandas as pd
import pytest
from nbclient import NotebookClient

from rocketmc.analysis import load_run
from rocketmc.sim.outputs import CONTROL_METRICS

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

REPO = Path(__file__).resolve().parents[1]
N = 64


N_WITHOUT_CANARDS = 16
"""Flights per campaign of the run without canards: enough for the bootstrap and the regression's 6 inputs."""


def _execute(tmp_path, monkeypatch, campaign: str, n: int):
    """The notebook run top to bottom on ``campaigns/<campaign>.toml`` with N = ``n``, its results in
    ``tmp_path/results``, then a cell printing the kernel's Python: the executed notebook and its figures (base64
    PNGs)."""
    monkeypatch.setenv("ROCKETMC_NOTEBOOK_CAMPAIGN", str(REPO / "campaigns" / f"{campaign}.toml"))
    monkeypatch.setenv("ROCKETMC_NOTEBOOK_N", str(n))
    monkeypatch.setenv("ROCKETMC_NOTEBOOK_OUT", str(tmp_path / "results"))
    nb = nbformat.read(REPO / "notebooks" / "landing_ellipses.ipynb", as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell("import sys\nprint(sys.executable)"))
    client = NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # raises CellExecutionError at the first cell that fails

    assert nb.cells[-1].outputs[0]["text"].strip() == sys.executable  # the kernel is this environment's Python
    images = [output["data"]["image/png"] for cell in nb.cells for output in cell.get("outputs", [])
              if "image/png" in output.get("data", {})]  # fmt: skip
    return nb, images


def test_landing_ellipses_notebook(tmp_path, monkeypatch):
    nb, images = _execute(tmp_path, monkeypatch, "lynx_nominal", N)
    assert len(images) == 4  # impacts with ellipses, the comparisons, the sensitivities, controller off and on
    assert all(len(image) > 20_000 for image in images)  # base64 PNGs with content, not empty axes
    runs = {path.name: load_run(path) for path in sorted((tmp_path / "results").glob("*.h5"))}
    variants = ("controller_on_", "", "no_turbulence_", "simplified_")  # as written: controller off, not flown twice
    assert list(runs) == [f"lynx_nominal_{variant}n{N}.h5" for variant in variants]
    assert all(run.attrs["n_realizations"] == N for run in runs.values())
    calm = runs[f"lynx_nominal_no_turbulence_n{N}.h5"]
    assert "turbulence" not in tomllib.loads(calm.attrs["campaign_toml"])["environment"]
    assert not any(name.startswith("environment.turbulence") for name in calm.inputs)

    # Section 5: the same flights with the controller off (the campaign as written) and on.
    off, on = runs[f"lynx_nominal_n{N}.h5"], runs[f"lynx_nominal_controller_on_n{N}.h5"]
    assert json.loads(off.attrs["setup"])["config"]["gnc"] is None
    assert json.loads(on.attrs["setup"])["config"]["gnc"] is not None
    assert not set(CONTROL_METRICS) & set(off.outputs)
    assert set(CONTROL_METRICS) <= set(on.outputs)
    assert (on.outputs.control_active_time_s[on.ok] > 0).all()
    assert on.attrs["seed"] == off.attrs["seed"] and len(on.outputs) == len(off.outputs) == N
    pd.testing.assert_frame_equal(on.inputs, off.inputs)  # flight i drew the same inputs in both


def test_landing_ellipses_notebook_without_canards(tmp_path, monkeypatch):
    """A rocket without canards (campaigns/custom_rocket.toml) runs to the end: the controller's section prints why
    it is skipped, draws and flies nothing; the three other figures and result files are there."""
    nb, images = _execute(tmp_path, monkeypatch, "custom_rocket", N_WITHOUT_CANARDS)
    printed = "".join(output["text"] for cell in nb.cells for output in cell.get("outputs", [])
                      if output.get("name") == "stdout")  # fmt: skip
    assert ("Section 5 skipped: custom_rocket cannot fly the controller (gnc: the controller steers four canards; "
            "this rocket's aerodynamic model has 0 (rocket.geometry.canards)).\n") in printed
    assert len(images) == 3  # impacts with ellipses, the comparisons, the sensitivities
    names = sorted(path.name for path in (tmp_path / "results").glob("*.h5"))
    n = N_WITHOUT_CANARDS
    assert names == [f"custom_rocket_{variant}n{n}.h5" for variant in ("", "no_turbulence_", "simplified_")]
