"""The landing-ellipse notebook runs top to bottom with a small N and draws its figures."""

import sys
import tomllib
from pathlib import Path

import nbformat
from nbclient import NotebookClient

from rocketmc.analysis import load_run

REPO = Path(__file__).resolve().parents[1]
N = 64


def test_landing_ellipses_notebook(tmp_path, monkeypatch):
    monkeypatch.setenv("ROCKETMC_NOTEBOOK_CAMPAIGN", str(REPO / "campaigns" / "lynx_nominal.toml"))
    monkeypatch.setenv("ROCKETMC_NOTEBOOK_N", str(N))
    monkeypatch.setenv("ROCKETMC_NOTEBOOK_OUT", str(tmp_path / "results"))
    nb = nbformat.read(REPO / "notebooks" / "landing_ellipses.ipynb", as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell("import sys\nprint(sys.executable)"))
    client = NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    client.execute()  # raises CellExecutionError at the first cell that fails

    assert nb.cells[-1].outputs[0]["text"].strip() == sys.executable  # the kernel is this environment's Python
    images = [output["data"]["image/png"] for cell in nb.cells for output in cell.get("outputs", [])
              if "image/png" in output.get("data", {})]  # fmt: skip
    assert len(images) == 3  # impacts with ellipses, the comparisons, the sensitivities
    assert all(len(image) > 20_000 for image in images)  # base64 PNGs with content, not empty axes
    runs = {path.name: load_run(path) for path in sorted((tmp_path / "results").glob("*.h5"))}
    assert list(runs) == [f"lynx_nominal_{variant}n{N}.h5" for variant in ("", "no_turbulence_", "simplified_")]
    assert all(run.attrs["n_realizations"] == N for run in runs.values())
    calm = runs[f"lynx_nominal_no_turbulence_n{N}.h5"]
    assert "turbulence" not in tomllib.loads(calm.attrs["campaign_toml"])["environment"]
    assert not any(name.startswith("environment.turbulence") for name in calm.inputs)
