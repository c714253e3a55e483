"""``rocketmc sensitivities``: the variance shares against closed forms (result files written by hand with known
linear flights), the wind layers' change of variables, the command on a real campaign and its bad input."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from rocketmc.analysis.sensitivities import FLAG_MISMATCH, sensitivity_table
from rocketmc.campaign.derivatives import DIFFERENTIATED_OUTPUTS, MISMATCH, spread
from rocketmc.cli import main

from ..conftest import CAMPAIGNS

N = 20_000


def _file(path, wrt, drawn, derivatives, outputs, dispersions, layers=(), mismatch=None):
    """A result file with derivatives, as ``rocketmc sensitivities`` writes it, of flights given by hand."""
    config = {"dispersions": dispersions, "environment": {"wind": {"layers": list(layers)}}}
    with h5py.File(path, "w") as f:
        f.attrs["setup"] = json.dumps({"config": config})
        f.create_dataset("outputs/status", data=np.zeros(N, dtype=np.int32))
        for name in DIFFERENTIATED_OUTPUTS:
            f.create_dataset(f"outputs/{name}", data=outputs.get(name, np.zeros(N)))
            f.create_dataset(f"derivatives/{name}", data=derivatives.get(name, np.zeros((N, len(wrt)))))
        for name, values in drawn.items():
            f.create_dataset(f"inputs/{name}", data=values)
        f["derivatives"].attrs.update({"wrt": json.dumps(wrt), "outputs": json.dumps(list(DIFFERENTIATED_OUTPUTS))})
        f.create_dataset(f"derivatives/{MISMATCH}", data=np.zeros((N, 4)) if mismatch is None else mismatch)
    return path


def test_shares_of_a_linear_flight_are_its_variance_fractions(tmp_path):
    # apogee = 3 m₁ + 0.5 m₂ + noise: shares 9σ₁²/V and 0.25σ₂²/V, what is left the noise's
    rng = np.random.default_rng(1)
    sigma1, low, high, noise = 2.0, -3.0, 5.0, 1.5
    x1, x2 = rng.normal(10.0, sigma1, N), rng.uniform(low, high, N)
    apogee = 3.0 * x1 + 0.5 * x2 + rng.normal(0.0, noise, N)
    gradient = np.tile([3.0, 0.5], (N, 1))
    dispersions = {"a": {"dist": "normal", "std": sigma1}, "b": {"dist": "uniform", "low": low, "high": high}}
    table = sensitivity_table(_file(tmp_path / "linear.h5", ["a", "b"], {"a": x1, "b": x2}, {"apogee_agl_m": gradient},
                                    {"apogee_agl_m": apogee}, dispersions))  # fmt: skip
    variance = 9 * sigma1**2 + 0.25 * (high - low) ** 2 / 12 + noise**2
    shares = {row["input"]: row["apogee_share"] for row in table["inputs"]}
    # the sample's variances: 1/√N relative (0.7 %) each, 5 standard errors
    assert shares["a"] == pytest.approx(9 * sigma1**2 / variance, rel=0.035)
    assert shares["b"] == pytest.approx(0.25 * (high - low) ** 2 / 12 / variance, rel=0.035)
    assert table["apogee_share_sum"] == pytest.approx(1 - noise**2 / variance, rel=0.035)
    assert spread(dispersions["b"]) == pytest.approx((high - low) / np.sqrt(12))


def test_a_wind_layer_is_shared_in_its_velocity_components(tmp_path):
    # impact = K · (wind velocity): linear in the components, not in speed and direction; the chain rule must give
    # K back in every flight, and the shares of the pair must add up to the whole variance
    rng = np.random.default_rng(2)
    speed, from_deg = rng.uniform(0.0, 15.0, N), rng.uniform(0.0, 360.0, N)
    theta = np.deg2rad(from_deg)
    wind_north, wind_east = -speed * np.cos(theta), -speed * np.sin(theta)
    k = np.array([[40.0, 5.0], [-3.0, 25.0]])  # (north, east) of the impact per (north, east) of the wind
    impact = k @ np.stack([wind_north, wind_east])
    per_speed = k @ np.stack([-np.cos(theta), -np.sin(theta)])  # ∂impact/∂s
    per_degree = k @ np.stack([speed * np.sin(theta), -speed * np.cos(theta)]) * np.pi / 180  # ∂impact/∂θ [1/deg]
    wrt = ["environment.wind.layers.0.speed_mps", "environment.wind.layers.0.from_deg"]
    derivatives = {name: np.stack([per_speed[i], per_degree[i]], axis=1) for i, name in enumerate(DIFFERENTIATED_OUTPUTS[:2])}
    dispersions = {path: {"dist": "uniform", "low": 0.0, "high": h} for path, h in zip(wrt, (15.0, 360.0))}
    path = _file(tmp_path / "wind.h5", wrt, dict(zip(wrt, (speed, from_deg))), derivatives,
                 dict(zip(DIFFERENTIATED_OUTPUTS[:2], impact)), dispersions, [{"speed_mps": 7.5, "from_deg": 180.0}])  # fmt: skip
    table = sensitivity_table(path)
    (row,) = table["inputs"]
    assert row["input"] == "environment.wind.layers.0 (north, east)"
    # exact but for the samples' covariance against their expectation (1/√N)
    assert row["impact_share"] == pytest.approx(1.0, rel=0.02)
    assert row["impact_rms_derivative"] == pytest.approx(np.sqrt((k**2).sum()), rel=1e-9)  # K in every flight


def test_flagged_flights_are_counted_and_left_out(tmp_path):
    rng = np.random.default_rng(3)
    x = rng.normal(0.0, 1.0, N)
    gradient = np.ones((N, 1))
    gradient[:100] = 50.0  # derivatives not to trust where the check failed
    mismatch = np.zeros((N, 4))
    mismatch[:100, 2] = 2 * FLAG_MISMATCH
    table = sensitivity_table(_file(tmp_path / "flagged.h5", ["a"], {"a": x}, {"apogee_agl_m": gradient},
                                    {"apogee_agl_m": x}, {"a": {"dist": "normal", "std": 1.0}}, mismatch=mismatch))  # fmt: skip
    assert table["flagged"]["apogee_agl_m"] == 100
    assert table["apogee_share_sum"] == pytest.approx(1.0, rel=0.035)  # the 100 flights' 50 left out


def test_sensitivities_command(tmp_path, capsys):
    out, png = tmp_path / "s.h5", tmp_path / "tornado.png"
    campaign = str(CAMPAIGNS / "lynx_ballistic.toml")
    args = ["sensitivities", campaign, "-n", "8", "--out", str(out), "--wrt", "rocket.aero.cl0", "--quiet"]
    assert main([*args, "--json", "--plot", str(png)]) == 0
    table = json.loads(capsys.readouterr().out)
    assert table["n"] == 8 and png.stat().st_size > 0
    with h5py.File(out) as f:
        wrt = json.loads(f["derivatives"].attrs["wrt"])
        assert wrt[-1] == "rocket.aero.cl0" and "environment.turbulence.severity" not in wrt  # a choice: discrete
        assert f["derivatives/impact_north_m"].shape == (8, len(wrt))
        assert f[f"derivatives/{MISMATCH}"].shape == (8, len(DIFFERENTIATED_OUTPUTS))
        assert f.attrs["complete"]
    assert main(["report", str(out)]) == 0  # a result file like run's


@pytest.mark.parametrize(("wrt", "said"), [
    ("rocket.geometry.fins.span_m", "--wrt rocket.geometry.fins.span_m: fixed for the whole campaign"),
    ("rocket.dry_mass", "--wrt rocket.dry_mass: not a number of this campaign"),
])  # fmt: skip
def test_bad_inputs_one_line_exit_2_no_file(tmp_path, capsys, wrt, said):
    out = tmp_path / "s.h5"
    assert main(["sensitivities", str(CAMPAIGNS / "lynx_ballistic.toml"), "--out", str(out), "--wrt", wrt]) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and len(err.splitlines()) == 1
    assert not out.exists() and not (tmp_path / "s.h5.partial").exists()


def test_a_partial_run_with_derivatives_resumes_only_with_the_same_inputs(tmp_path):
    from rocketmc.campaign import load_campaign
    from rocketmc.campaign.store import ResultWriter, ResumeError

    campaign = load_campaign(CAMPAIGNS / "lynx_ballistic.toml")
    out = tmp_path / "s.h5"
    ResultWriter(out, campaign, 8, derivatives=["rocket.dry_mass_kg"]).close()
    with pytest.raises(ResumeError, match="another campaign or set-up \\(derivatives differ\\)"):
        ResultWriter(out, campaign, 8, resume=True, derivatives=["launch.elevation_deg"])
    with pytest.raises(ResumeError, match="derivatives differ"):
        ResultWriter(out, campaign, 8, resume=True)  # a plain run resuming a run with derivatives
    ResultWriter(out, campaign, 8, resume=True, derivatives=["rocket.dry_mass_kg"]).close()
