"""``rocketmc bench``: bad arguments, the packaged campaign, float64 flying float32's realizations,
the impact comparison. The project's timing ratios are in tests/test_performance.py."""

import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import jax
import numpy as np
import pytest

from rocketmc.bench import DEFAULT_CAMPAIGN, PRECISIONS, _impact_difference, _subprocess, float32_draws
from rocketmc.cli import main

CAMPAIGN = Path(__file__).parents[1] / "campaigns" / "lynx_nominal.toml"

DRAWS = """
import json, sys
import jax
from rocketmc.campaign import flight_params, load_campaign
from rocketmc.campaign.sampling import realization_key, sample_dispersions
from rocketmc.env.turbulence import turbulence_noise

def draws(campaign, i):
    key = realization_key(jax.random.key(campaign.config.seed), i)
    drawn = sample_dispersions(campaign, key)
    gusts = turbulence_noise(flight_params(campaign, {**campaign.nominal, **drawn}, key).environment.turbulence, 0, 4)
    return {**drawn, "gusts": gusts}

if __name__ == "__main__":
    campaign = load_campaign(sys.argv[1])
    print(json.dumps([{k: jax.numpy.asarray(v).tolist() for k, v in draws(campaign, i).items()} for i in range(8)]))
"""


def test_bad_arguments_one_line_exit_2(tmp_path, capsys):
    for argv in (["--n", "1000", "0"], ["--chunk-size", "0"], ["--models", "exact"]):
        with pytest.raises(SystemExit) as info:
            main(["bench", *argv])
        assert info.value.code == 2, argv
    assert main(["bench", "--campaign", str(tmp_path / "missing.toml")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 4 and all(line.startswith("rocketmc: error: ") for line in lines), lines
    assert "--n" in lines[0] and "--chunk-size" in lines[1] and "exact" in lines[2] and "not found" in lines[3]


def test_the_repository_campaign_is_the_packaged_one():
    # campaigns/lynx_nominal.toml links to the file that a pip install carries (bench's default).
    assert CAMPAIGN.read_bytes() == DEFAULT_CAMPAIGN.read_bytes()


def test_float64_draws_float32s_dispersions_and_gusts(lynx_campaign):
    """Under ``float32_draws`` float64's dispersions and turbulence noise are float32's draws (up to
    the float32 rounding of ``mean + std * x``: 1e-6 relative); without it the dispersions differ
    entirely, the noise (always drawn in float32) does not."""
    env = {**os.environ, "ROCKETMC_PRECISION": "float32"}
    done = subprocess.run([sys.executable, "-c", DRAWS, CAMPAIGN], env=env, capture_output=True, text=True, check=True)
    float32 = json.loads(done.stdout)
    namespace = {"__name__": "draws"}
    exec(DRAWS, namespace)
    draws, normal = namespace["draws"], jax.random.normal
    with float32_draws():
        same = [draws(lynx_campaign, i) for i in range(8)]
    assert jax.random.normal is normal
    other = [draws(lynx_campaign, i) for i in range(8)]
    for a, b, c in zip(same, float32, other):
        assert a.keys() == b.keys()
        for name in a:
            assert a[name].dtype == np.float64
            np.testing.assert_allclose(a[name], b[name], rtol=1e-6, atol=1e-6, err_msg=name)
        # the turbulence noise is drawn in float32 in both precisions (turbulence_noise) ...
        np.testing.assert_allclose(c["gusts"], b["gusts"], rtol=1e-6, atol=1e-6)
        # ... the dispersions are not
        assert not all(np.allclose(c[name], b[name], rtol=1e-3) for name in c if name != "gusts")


def test_float32_flies_the_same_realizations_without_failures(tmp_path):
    """The measuring processes of ``rocketmc bench``: float32 flies 16 lynx_nominal realizations, all
    ok, and float64 (under ``float32_draws``) the same ones: inputs equal to float32 rounding, impact
    points centimetres apart (median over 200 flights: 0.01 m; other realizations: hundreds of metres)."""
    impacts = {p: str(tmp_path / f"{p}.npz") for p in PRECISIONS}

    def measure(p):
        return _subprocess(p, kind="throughput", campaign=str(CAMPAIGN), model="simplified", n=16, chunk_size=None,
                           impacts=impacts[p], float32_draws=p == "float64")  # fmt: skip

    with ThreadPoolExecutor() as pool:  # the two processes compile at once
        for p, r in zip(PRECISIONS, pool.map(measure, PRECISIONS)):
            assert (r["precision"], r["ok"], r["failed"]) == (p, 16, {}), r
    c = _impact_difference(impacts["float64"], impacts["float32"])
    assert c["compared"] == 16 and c["inputs_max_relative_difference"] < 1e-6, c
    assert c["impact_difference_m"]["median"] < 1.0, c


def test_impact_difference(tmp_path):
    """Known offsets give known distances; float32 points spread 1 % wider about their mean give an
    ellipse 2.01 % larger; a realization that failed in either precision is left out."""
    rng = np.random.default_rng(0)
    north, east = rng.normal(0.0, 500.0, 1000), rng.normal(0.0, 300.0, 1000)
    status = np.zeros(1000, dtype=np.int32)
    inputs = {"rocket.dry_mass_kg": rng.normal(18.0, 0.2, 1000)}
    np.savez(tmp_path / "f64.npz", impact_north_m=north, impact_east_m=east, status=status, **inputs)
    wider_north = north.mean() + 1.01 * (north - north.mean())
    wider_east = east.mean() + 1.01 * (east - east.mean())
    failed = status.copy()
    failed[0] = 1
    np.savez(tmp_path / "f32.npz", impact_north_m=wider_north, impact_east_m=wider_east, status=failed, **inputs)
    c = _impact_difference(str(tmp_path / "f64.npz"), str(tmp_path / "f32.npz"))
    d = 0.01 * np.hypot(north - north.mean(), east - east.mean())[1:]
    assert c["compared"] == 999 and c["status_differs"] == 1 and c["inputs_max_relative_difference"] == 0.0
    assert c["impact_difference_m"]["max"] == pytest.approx(d.max(), rel=1e-9)
    assert c["impact_difference_m"]["median"] == pytest.approx(np.median(d), rel=1e-9)
    assert c["ellipse95_area_m2"]["relative_difference"] == pytest.approx(1.01**2 - 1, rel=1e-9)


def test_gradient_cost_times_the_ellipse_area_forward(monkeypatch):
    """The bench's forward pass of the ellipse's area (the reverse pass shares its function; its compilation, ~2 min,
    is left to `rocketmc bench`): it compiles, runs and reports in the report's fields."""
    from rocketmc import bench
    from rocketmc.campaign import load_campaign

    monkeypatch.setattr(bench, "GRADIENT_FLIGHTS", 4)
    result = bench.gradient_cost(load_campaign(CAMPAIGN.parent / "lynx_ballistic.toml"), "forward", repeats=1)
    assert result["mode"] == "forward" and result["flights"] == 4 and result["params"] == list(bench.GRADIENT_PARAMS)
    assert result["compile_s"] > 0.0 and result["run_s"] > 0.0
