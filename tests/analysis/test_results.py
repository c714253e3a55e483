"""Result-file reading and summaries, on a small synthetic HDF5 file written here with h5py."""

import json
import math

import h5py
import numpy as np
import pandas as pd
import pytest

from rocketmc.analysis import (
    format_summary,
    load_inputs,
    load_outputs,
    load_run,
    summarize,
)

N = 400
CODES = {"0": "ok", "1": "non-finite state", "2": "max time reached before impact"}
UNITS = {
    "apogee_agl_m": "m",
    "apogee_time_s": "s",
    "max_mach": "1",
    "max_dynamic_pressure_pa": "Pa",
    "rail_exit_speed_mps": "m/s",
    "impact_north_m": "m",
    "impact_east_m": "m",
    "impact_time_s": "s",
    "impact_speed_mps": "m/s",
}


def _synthetic(seed=7, n=N):
    """Outputs (with a few failed rows set to NaN) and inputs as dicts of arrays."""
    rng = np.random.default_rng(seed)
    out = {
        "apogee_agl_m": rng.normal(3000.0, 80.0, n),
        "apogee_time_s": rng.normal(25.0, 0.5, n),
        "max_mach": rng.normal(0.85, 0.02, n),
        "max_dynamic_pressure_pa": rng.normal(1.2e5, 5e3, n),
        "rail_exit_speed_mps": rng.normal(30.0, 1.0, n),
        "impact_north_m": rng.normal(800.0, 300.0, n),
        "impact_east_m": rng.normal(-200.0, 120.0, n),
        "impact_time_s": rng.normal(160.0, 5.0, n),
        "impact_speed_mps": rng.normal(6.0, 0.3, n),
    }
    out["impact_east_m"] += 0.3 * out["impact_north_m"]  # correlated footprint
    status = np.zeros(n, dtype=np.int32)
    status[[3, 50, 51]] = 1
    status[[200]] = 2
    for name in ("apogee_agl_m", "impact_north_m", "impact_east_m", "impact_time_s"):
        out[name][status == 1] = np.nan
    out["max_mach"][10] = np.nan  # an ok row with one missing metric
    out["status"] = status
    inputs = {
        "environment.wind.layers.0.speed_mps": rng.normal(5.0, 1.0, n),
        "rocket.mass_kg": rng.normal(12.0, 0.1, n),
    }
    return out, inputs


def _write(path, outputs, inputs, complete=True, with_outputs=True):
    with h5py.File(path, "w") as f:
        f.attrs["campaign_name"] = "synthetic"
        f.attrs["campaign_toml"] = 'name = "synthetic"\n'
        f.attrs["rocketmc_version"] = "0.1.0"
        f.attrs["seed"] = 1234
        f.attrs["n_realizations"] = len(outputs["status"])
        f.attrs["complete"] = complete
        if with_outputs:
            g = f.create_group("outputs")
            for name, values in outputs.items():
                ds = g.create_dataset(name, data=values)
                if name == "status":
                    ds.attrs["unit"] = "1"
                    ds.attrs["codes"] = json.dumps(CODES)
                else:
                    ds.attrs["unit"] = {**UNITS, "navigation_diverged": "1"}[name]
        g = f.create_group("inputs")
        for name, values in inputs.items():
            g.create_dataset(name, data=values)


@pytest.fixture
def result_file(tmp_path):
    outputs, inputs = _synthetic()
    path = tmp_path / "run.h5"
    _write(path, outputs, inputs)
    return path, outputs, inputs


def test_load_outputs_round_trip(result_file):
    path, outputs, _ = result_file
    df = load_outputs(path)
    assert isinstance(df, pd.DataFrame)
    assert set(df.columns) == set(outputs)
    assert len(df) == N and df.index.tolist() == list(range(N))
    for name, values in outputs.items():
        np.testing.assert_array_equal(df[name].to_numpy(), values)
    assert df["status"].dtype == np.int32
    assert df["apogee_agl_m"].dtype == np.float64


def test_load_inputs_round_trip(result_file):
    path, _, inputs = result_file
    df = load_inputs(path)
    assert set(df.columns) == set(inputs)
    for name, values in inputs.items():
        np.testing.assert_array_equal(df[name].to_numpy(), values)


def test_load_run_attrs_units_codes(result_file):
    path, outputs, _ = result_file
    run = load_run(path)
    assert run.attrs["campaign_name"] == "synthetic"
    assert run.attrs["seed"] == 1234 and type(run.attrs["seed"]) is int
    assert run.attrs["complete"] is True
    assert run.units["max_dynamic_pressure_pa"] == "Pa"
    assert run.units["status"] == "1"
    assert run.status_codes == {0: "ok", 1: "non-finite state", 2: "max time reached before impact"}
    np.testing.assert_array_equal(run.ok, outputs["status"] == 0)
    json.dumps(run.attrs)  # attributes are plain Python values


def test_summary_matches_independent_numbers(result_file):
    path, outputs, _ = result_file
    s = summarize(load_run(path))
    json.dumps(s, allow_nan=False)  # strictly JSON-serialisable

    assert s["campaign_name"] == "synthetic" and s["seed"] == 1234
    assert s["n_realizations"] == N and s["n_ok"] == N - 4
    assert s["status"] == [
        {"code": 0, "message": "ok", "count": N - 4},
        {"code": 1, "message": "non-finite state", "count": 3},
        {"code": 2, "message": "max time reached before impact", "count": 1},
    ]
    assert "status" not in s["metrics"]
    assert set(s["metrics"]) == set(UNITS)

    ok = outputs["status"] == 0
    for name, unit in UNITS.items():
        x = pd.Series(outputs[name][ok]).dropna()  # pandas as the independent reference
        m = s["metrics"][name]
        assert m["unit"] == unit and m["n"] == len(x)
        # Same data and formulas, different implementation: only summation-order round-off.
        ref = {"mean": x.mean(), "std": x.std(ddof=1), "min": x.min(), "max": x.max(),
               "p5": x.quantile(0.05), "p50": x.median(), "p95": x.quantile(0.95)}
        for key, value in ref.items():
            assert m[key] == pytest.approx(value, rel=1e-12), (name, key)
    assert s["metrics"]["max_mach"]["n"] == N - 4 - 1


def test_summary_ellipses(result_file):
    path, outputs, _ = result_file
    s = summarize(load_run(path))
    ok = outputs["status"] == 0
    pts = np.stack([outputs["impact_north_m"][ok], outputs["impact_east_m"][ok]])
    cov = np.cov(pts)
    snn, see, sne = cov[0, 0], cov[1, 1], cov[0, 1]
    half_sum, root = 0.5 * (snn + see), math.hypot(0.5 * (snn - see), sne)
    levels = [e["level"] for e in s["impact_ellipses"]]
    assert levels == [0.5, 0.95, 0.99]
    for e in s["impact_ellipses"]:
        k2 = -2.0 * math.log(1.0 - e["level"])
        # Closed-form 2x2 eigenvalues vs eigh: round-off only.
        assert e["semi_major_m"] == pytest.approx(math.sqrt(k2 * (half_sum + root)), rel=1e-9)
        assert e["semi_minor_m"] == pytest.approx(math.sqrt(k2 * (half_sum - root)), rel=1e-9)
        assert e["center_north_m"] == pytest.approx(pts[0].mean(), rel=1e-12)
        assert e["center_east_m"] == pytest.approx(pts[1].mean(), rel=1e-12)
        assert e["n"] == ok.sum()
        az = math.degrees(0.5 * math.atan2(2.0 * sne, snn - see)) % 180.0
        assert e["orientation_deg"] == pytest.approx(az, abs=1e-9)


def test_format_summary(result_file):
    path, _, _ = result_file
    s = summarize(load_run(path))
    text = format_summary(s)
    assert "synthetic" in text and "seed 1234" in text
    assert f"{N} total, {N - 4} ok" in text
    assert "max time reached before impact" in text
    for name in UNITS:
        assert name in text
    assert "Pa" in text and "m/s" in text
    assert "95 %" in text and "km^2" in text and "m^2" in text
    lines = text.splitlines()
    table = lines[lines.index("Metrics (ok realizations)") + 1:][: len(UNITS) + 1]
    assert len({len(line) for line in table}) == 1  # aligned columns


def test_incomplete_file_refused(tmp_path):
    outputs, inputs = _synthetic()
    path = tmp_path / "partial.h5"
    _write(path, outputs, inputs, complete=False)
    for loader in (load_outputs, load_inputs, load_run):
        with pytest.raises(ValueError, match="incomplete"):
            loader(path)


def test_file_without_outputs_refused(tmp_path):
    outputs, inputs = _synthetic()
    path = tmp_path / "empty.h5"
    _write(path, outputs, inputs, with_outputs=False)
    with pytest.raises(ValueError, match="no /outputs"):
        load_run(path)


def test_mismatched_lengths_refused(tmp_path):
    outputs, inputs = _synthetic()
    outputs["impact_speed_mps"] = outputs["impact_speed_mps"][:-1]
    path = tmp_path / "bad.h5"
    _write(path, outputs, inputs)
    with pytest.raises(ValueError, match="differ in length"):
        load_outputs(path)


def test_summary_without_enough_ok_impacts(tmp_path):
    outputs, inputs = _synthetic()
    outputs["status"][2:] = 2  # only two ok realizations
    path = tmp_path / "tiny.h5"
    _write(path, outputs, inputs)
    s = summarize(load_run(path))
    assert s["impact_ellipses"] == []
    assert "not available" in format_summary(s)


def test_failed_realizations_are_counted_apart(tmp_path):
    """Failed flights are out of the ellipses but counted per status: the status-1 rows of the synthetic
    file have NaN impacts (no impact point), the status-2 row kept its impact point (it landed)."""
    outputs, inputs = _synthetic()
    path = tmp_path / "run.h5"
    _write(path, outputs, inputs)
    summary = summarize(load_run(path))
    failed = {s["code"]: s for s in summary["failed"]}
    assert set(failed) == {1, 2}
    assert (failed[1]["count"], failed[1]["landed"], failed[1]["no_impact_point"]) == (3, 0, 3)
    assert (failed[2]["count"], failed[2]["landed"], failed[2]["no_impact_point"]) == (1, 1, 0)
    assert summary["impact_ellipses"][0]["n"] == N - 4
    assert "Failed realizations" in format_summary(summary)


def test_ellipse_coverage_is_the_mahalanobis_fraction(tmp_path):
    """Each ellipse's ``coverage``: the fraction of ok points with Mahalanobis d² ≤ chi2.ppf(level, 2) under
    the sample mean and covariance (closed form, independent of Ellipse.contains)."""
    from scipy.stats import chi2

    outputs, inputs = _synthetic()
    path = tmp_path / "run.h5"
    _write(path, outputs, inputs)
    run = load_run(path)
    points = np.stack(run.ok_impacts())
    d = points - points.mean(axis=1, keepdims=True)
    d2 = np.einsum("in,ij,jn->n", d, np.linalg.inv(np.cov(points)), d)
    for e in summarize(run)["impact_ellipses"]:
        assert e["coverage"] == pytest.approx(np.mean(d2 <= chi2.ppf(e["level"], 2)), abs=1.5 / points.shape[1])  # a point on the boundary may round either way


def _with_diverged(tmp_path, diverged_rows):
    """The synthetic run with a ``navigation_diverged`` output, 1 at ``diverged_rows``: its path."""
    outputs, inputs = _synthetic()
    outputs["navigation_diverged"] = np.zeros(N)
    outputs["navigation_diverged"][diverged_rows] = 1.0
    path = tmp_path / "nav.h5"
    _write(path, outputs, inputs)
    return path


def test_diverged_navigation_is_counted_and_warned(tmp_path, capsys):
    """Flights whose navigation diverged are counted over every status (rows 3 and 200 failed, 7 and 8 ok) and
    warned of in the summary, its text and, from ``rocketmc report``, on stderr; the ok ones stay in the ellipse."""
    from rocketmc.cli import main

    path = _with_diverged(tmp_path, [3, 7, 8, 200])
    summary = summarize(load_run(path))
    assert summary["navigation_diverged"] == 4
    assert summary["impact_ellipses"][0]["n"] == N - 4  # the ok diverged flights are kept
    (line,) = [w for w in summary["warnings"] if "diverged" in w]
    assert "diverged in 4 of 400 flights" in line and "2 of them are in the impact ellipses" in line
    assert f"Warning: {line}" in format_summary(summary)
    assert main(["report", str(path)]) == 0
    assert f"rocketmc: warning: {line}" in capsys.readouterr().err


def test_no_diverged_flight_no_warning(tmp_path, capsys):
    """The flag all 0: counted 0, no warning; a run without the flag (no navigation filters): None."""
    from rocketmc.cli import main

    summary = summarize(load_run(_with_diverged(tmp_path, [])))
    assert summary["navigation_diverged"] == 0 and summary["warnings"] == []
    assert main(["report", str(tmp_path / "nav.h5")]) == 0
    assert "warning" not in capsys.readouterr().err
    outputs, inputs = _synthetic()
    _write(tmp_path / "plain.h5", outputs, inputs)
    assert summarize(load_run(tmp_path / "plain.h5"))["navigation_diverged"] is None
