"""The probability of landing outside a radius from the pad, with its exact (Clopper-Pearson) interval.

Counting, for a range-safety officer: every realization is a trial. A flight that failed but landed (a
tumble) counts by where it landed; one without an impact point (a NaN state, still airborne at
``max_time_s``) counts as outside, since nothing shows it landed inside. Impact points are north/east [m]
from the pad (NED)."""

from __future__ import annotations

import numpy as np
from scipy.stats import binomtest

from .results import Run


def outside_radius(run: Run, radius_m: float, confidence: float = 0.95) -> dict:
    """Flights landing farther than ``radius_m`` [m] from the pad out of all N, the fraction, its two-sided
    exact ``confidence`` interval (``binomtest(...).proportion_ci(method="exact")``) and, when none fell
    outside, the one-sided upper bound 1 − (1 − confidence)^(1/N) (≈ 3/N at 95 %: the rule of three)."""
    north, east = run.outputs["impact_north_m"].to_numpy(float), run.outputs["impact_east_m"].to_numpy(float)
    landed = run.has_impact
    n, no_point = len(north), int((~landed).sum())
    k = int((np.hypot(north, east)[landed] > radius_m).sum()) + no_point
    ci = binomtest(k, n).proportion_ci(confidence, method="exact") if n else None
    return {
        "radius_m": radius_m, "n": n, "outside": k, "without_impact_point": no_point,
        "fraction": k / n if n else None, "confidence": confidence,
        "interval": None if ci is None else [float(ci.low), float(ci.high)],
        "upper_bound_none_outside": 1.0 - (1.0 - confidence) ** (1.0 / n) if n and k == 0 else None,
    }  # fmt: skip


def format_outside(result: dict) -> str:
    """One paragraph saying what :func:`outside_radius` found and what it means."""
    r, level = result, f"{100 * result['confidence']:g} %"
    lines = [f"Outside {r['radius_m']:g} m from the pad: {r['outside']} of {r['n']} flights "
             f"({r['without_impact_point']} without an impact point, counted as outside; failed flights that "
             f"landed counted by where they landed)"]  # fmt: skip
    if r["n"]:
        low, high = r["interval"]
        lines.append(f"  probability {r['fraction']:.4g}, exact (Clopper-Pearson) {level} interval {low:.4g}…{high:.4g}")
    if r["upper_bound_none_outside"] is not None:
        lines.append(f"  none outside: the probability is below {r['upper_bound_none_outside']:.3g} at {level} "
                     f"confidence (one-sided; the rule of three's 3/N = {3 / r['n']:.3g}), not zero")  # fmt: skip
    return "\n".join(lines)
