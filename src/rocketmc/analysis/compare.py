"""Landing dispersion of several runs against the first (the baseline): each run's 95 % impact ellipse
with bootstrap intervals of its area and centre (as ``report``), and the ratio of each area to the
baseline's with a percentile-bootstrap interval, paired when realization i met the same draws in both
runs (the same seed and N, docs/conventions.md, Randomness), else resampling the runs independently.
Impact points are north/east [m] from the pad; intervals are 95 % ones."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import RocketmcError
from ..ellipse import MIN_BOOTSTRAP_POINTS, bootstrap_intervals, confidence_ellipse, ellipse_area_m2, percentile_interval
from .results import Run, _table, navigation_warnings

LEVEL = 0.95
"""Confidence level of the compared ellipses (the one ``report`` gives bootstrap intervals for)."""


class CompareError(RocketmcError, ValueError):
    """Runs that cannot be compared: too few ok flights, a baseline of no area."""


def dispersion(run: Run, level: float = LEVEL) -> dict:
    """The ``level`` impact ellipse of ``run``'s ok flights (``Ellipse.to_dict()``, metres) with the
    bootstrap intervals of its area [m²] and centre [m] (``bootstrap_intervals``): keys
    ``campaign_name, seed, n_realizations, n_ok, ellipse, intervals`` and ``navigation_diverged``, the flights of
    any status whose navigation estimate diverged (``Run.diverged``; they stay in the ellipse)."""
    north, east = run.ok_impacts()
    _enough(north.size, "ok flight(s) with an impact point")
    return {
        "campaign_name": run.attrs.get("campaign_name", ""),
        "seed": run.attrs.get("seed"),
        "n_realizations": len(run.outputs),
        "n_ok": int(north.size),
        "ellipse": confidence_ellipse(north, east, level).to_dict(),
        "intervals": bootstrap_intervals(north, east, level),
        "navigation_diverged": int(run.diverged.sum()),
    }


def is_paired(baseline: Run, other: Run) -> bool:
    """Whether realization i of both runs drew the same dispersions and turbulence: same seed and N."""
    seed = baseline.attrs.get("seed")
    return seed is not None and seed == other.attrs.get("seed") and len(baseline.outputs) == len(other.outputs)


def area_ratio(baseline: Run, other: Run, level: float = LEVEL) -> dict:
    """Ratio of ``other``'s ``level`` ellipse area to ``baseline``'s and its percentile-bootstrap interval.

    Paired (:func:`is_paired`): the realizations landed in both runs, the others (``n_dropped``) dropped
    from both, resampled with the same indices in both; unpaired: each run's ok flights, resampled
    independently (``n_dropped`` None). Keys ``paired, n_used, n_dropped, ratio, interval`` and the
    relative change (ratio − 1) [%] ``change_pct, change_pct_interval``."""
    paired = is_paired(baseline, other)
    kept = baseline.landed & other.landed if paired else None
    samples = (np.stack(baseline.ok_impacts(kept)), np.stack(other.ok_impacts(kept)))
    _enough(min(s.shape[1] for s in samples), "flight(s) landed in both runs" if paired else "ok flight(s)")

    def ratio(base, run, axis=-1):
        return ellipse_area_m2(*run, level, axis) / ellipse_area_m2(*base, level, axis)

    if not ellipse_area_m2(*samples[0], level) > 0.0:
        raise CompareError("the baseline's impact points span no area (all on one line); no ratio to it")
    value = float(ratio(*samples))
    interval = percentile_interval(samples, ratio, paired)
    return {
        "paired": paired,
        "n_used": [s.shape[1] for s in samples],
        "n_dropped": int(kept.size - kept.sum()) if paired else None,
        "ratio": value,
        "interval": list(interval),
        "change_pct": 100.0 * (value - 1.0),
        "change_pct_interval": [100.0 * (r - 1.0) for r in interval],
    }


def compare(runs: Sequence[tuple[str, Run]], level: float = LEVEL) -> dict:
    """Each run ``(file name, run)``'s :func:`dispersion`, then each later run's :func:`area_ratio`
    to the first, and each run's ``navigation_warnings`` prefixed with its file name: ``{"level", "runs":
    [{"file", ...}], "ratios": [{"file", "baseline", ...}], "warnings"}``."""
    (base_file, baseline), others = runs[0], runs[1:]
    return {
        "level": level,
        "warnings": [f"{file}: {line}" for file, run in runs for line in navigation_warnings(run)],
        "runs": [{"file": file, **_naming(file, dispersion, run, level)} for file, run in runs],
        "ratios": [{"file": file, "baseline": base_file,
                    **_naming(f"{file} against {base_file}", area_ratio, baseline, run, level)}
                   for file, run in others],  # fmt: skip
    }


def _naming(what: str, function, *args):
    """``function(*args)``, its CompareError prefixed with ``what``."""
    try:
        return function(*args)
    except CompareError as e:
        raise CompareError(f"{what}: {e}") from None


def _enough(n: int, what: str) -> None:
    """A CompareError unless ``n`` points are enough for bootstrap intervals."""
    if n < MIN_BOOTSTRAP_POINTS:
        raise CompareError(f"{n} {what}; comparing needs at least {MIN_BOOTSTRAP_POINTS}")


def _interval(pair, scale: float = 1.0, fmt: str = "{:.4g}") -> str:
    """``low…high`` of an interval ``pair`` divided by ``scale``."""
    return "…".join(fmt.format(x / scale) for x in pair)


def format_comparison(comparison: dict) -> str:
    """Compact human-readable table of a :func:`compare` dict."""
    level = f"{100 * comparison['level']:g} %"
    out = [f"Impact {level} ellipses (north/east from pad; interval: 95 % bootstrap interval)"]
    out += _table(
        ["file", "campaign", "ok / N", "area [km^2]", "interval", "N [m]", "interval", "E [m]", "interval"],
        [
            [r["file"], r["campaign_name"], f"{r['n_ok']} / {r['n_realizations']}",
             f"{r['ellipse']['area_m2'] / 1e6:.4g}", _interval(r["intervals"]["area_m2"], 1e6),
             f"{r['ellipse']['center_north_m']:.1f}", _interval(r["intervals"]["center_north_m"], fmt="{:.1f}"),
             f"{r['ellipse']['center_east_m']:.1f}", _interval(r["intervals"]["center_east_m"], fmt="{:.1f}")]
            for r in comparison["runs"]
        ],  # fmt: skip
        align="llrrrrrrr",
    )
    if comparison["ratios"]:
        out += ["", f"{level} ellipse area against {comparison['ratios'][0]['baseline']} (the baseline)"]
        out += _table(
            ["file", "resampling", "area ratio", "interval", "change [%]", "interval"],
            [
                [r["file"], f"paired, {r['n_dropped']} dropped (not ok in both)" if r["paired"] else "unpaired",
                 f"{r['ratio']:.4g}", _interval(r["interval"]), f"{r['change_pct']:+.1f}",
                 _interval(r["change_pct_interval"], fmt="{:+.1f}")]
                for r in comparison["ratios"]
            ],  # fmt: skip
            align="llrrrr",
        )
    out += [f"Warning: {line}" for line in comparison["warnings"]]
    return "\n".join(out)
