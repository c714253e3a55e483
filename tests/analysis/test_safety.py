"""The probability of landing outside a radius, against the Clopper-Pearson interval's closed form in
beta quantiles (independent of binomtest's code path) and the rule of three."""

import numpy as np
import pytest
from scipy.stats import beta

from rocketmc.analysis import load_run
from rocketmc.analysis.safety import format_outside, outside_radius

from .test_results import _synthetic, _write


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    outputs, inputs = _synthetic()
    path = tmp_path_factory.mktemp("safety") / "run.h5"
    _write(path, outputs, inputs)
    return load_run(path), outputs


def test_counts_and_exact_interval(run):
    run, outputs = run
    distance = np.hypot(outputs["impact_north_m"], outputs["impact_east_m"])
    no_point = ~np.isfinite(distance)  # the 3 status-1 rows: counted as outside
    k = int((distance[~no_point] > 1000.0).sum()) + int(no_point.sum())
    n = len(distance)
    result = outside_radius(run, 1000.0)
    assert (result["outside"], result["n"], result["without_impact_point"]) == (k, n, 3)
    low, high = beta.ppf(0.025, k, n - k + 1), beta.ppf(0.975, k + 1, n - k)  # Clopper-Pearson's definition
    assert result["interval"] == pytest.approx([low, high], rel=1e-9)  # two quantile routes, round-off only
    assert result["upper_bound_none_outside"] is None


def test_none_outside_gives_the_rule_of_three(run):
    run, _ = run
    result = outside_radius(run.__class__(run.outputs[run.has_impact].reset_index(drop=True), run.inputs, run.attrs,
                                          run.units, run.status_codes), 1e6)  # fmt: skip
    n = result["n"]
    assert result["outside"] == 0 and result["interval"][0] == 0.0
    assert result["upper_bound_none_outside"] == pytest.approx(1 - 0.05 ** (1 / n), rel=1e-12)  # closed form
    assert result["upper_bound_none_outside"] == pytest.approx(3 / n, rel=0.01)  # -ln 0.05 = 2.996 and N = 397
    assert "rule of three" in format_outside(result)
