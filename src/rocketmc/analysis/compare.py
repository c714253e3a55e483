"""Landing dispersion of several runs against the first (the baseline): each run's 95 % impact ellipse
with bootstrap intervals of its area and centre (as ``report``), and the ratio of each area to the
baseline's with a percentile-bootstrap interval, paired when realization i met the same draws in both
runs (:func:`unpaired_reason`: the same seed and N, and the same dispersions; docs/conventions.md,
Randomness), else resampling the runs independently. Impact points are north/east [m] from the pad;
intervals are 95 % ones."""

from __future__ import annotations

import json
from collections.abc import Sequence

import numpy as np

from ..campaign.schema import FAULT_SECTIONS
from ..errors import RocketmcError
from ..ellipse import MIN_BOOTSTRAP_POINTS, bootstrap_intervals, confidence_ellipse, ellipse_area_m2, percentile_interval
from .results import Run, apogee_about, apogee_target_m, format_apogee_about, navigation_warnings, text_table

LEVEL = 0.95
"""Confidence level of the compared ellipses (the one ``report`` gives bootstrap intervals for)."""


class CompareError(RocketmcError, ValueError):
    """Runs that cannot be compared: too few ok flights, a baseline of no area."""


def dispersion(run: Run, level: float = LEVEL) -> dict:
    """The ``level`` impact ellipse of ``run``'s ok flights (``Ellipse.to_dict()``, metres) with the
    bootstrap intervals of its area [m²] and centre [m] (``bootstrap_intervals``): keys
    ``campaign_name, label`` (``Run.label``: with the switches flown), ``seed, n_realizations, n_ok, ellipse, intervals`` and ``navigation_diverged``, the flights of
    any status whose navigation estimate diverged (``Run.diverged``; they stay in the ellipse)."""
    north, east = run.ok_impacts()
    _enough(north.size, "ok flight(s) with an impact point")
    return {
        "campaign_name": run.attrs.get("campaign_name", ""),
        "label": run.label,
        "seed": run.attrs.get("seed"),
        "n_realizations": len(run.outputs),
        "n_ok": int(north.size),
        "ellipse": confidence_ellipse(north, east, level).to_dict(),
        "intervals": bootstrap_intervals(north, east, level),
        "navigation_diverged": int(run.diverged.sum()),
    }


SHOWN_PATHS = 3
"""Dispersions an unpaired reason names before 'and n more'."""


def unpaired_reason(baseline: Run, other: Run, names: tuple[str, str] = ("the baseline", "the run")) -> str | None:
    """None where realization i of both runs drew the same random inputs (pairing them flight by flight makes
    sense), else why not, naming the runs ``names``: another seed or N, or dispersions (``[dispersions]``, the
    faults drawn) that one run draws and the other does not, or draws another way. A dispersion or fault of a
    section (``[gnc]``, ``[avionics]``) the other run does not fly at all goes with that switch, the controller or
    sensors off, and leaves the shared draws alike (each has its own stream): it does not unpair them."""
    runs = (baseline, other)
    reasons = [f"{what} differ ({names[0]} {values[0]}, {names[1]} {values[1]})" for what, values in
               (("seeds", [run.attrs.get("seed") for run in runs]), ("N", [len(run.outputs) for run in runs]))
               if values[0] is None or values[0] != values[1]]  # fmt: skip
    if any("setup" not in run.attrs for run in runs):
        return "; ".join([*reasons, "a file does not record its campaign set-up (its dispersions)"])
    configs = [json.loads(run.attrs["setup"])["config"] for run in runs]
    drawn = [_drawn(config) for config in configs]
    for mine, theirs in ((0, 1), (1, 0)):
        flown = {section for section in SWITCHED_SECTIONS if configs[theirs][section] is not None}
        reasons += [f"{names[mine]} disperses {path}, which {names[theirs]} does not" for path in drawn[mine]
                    if path not in drawn[theirs] and _section(path) not in SWITCHED_SECTIONS - flown]  # fmt: skip
    reasons += [f"{path} is dispersed differently ({_spec(drawn[0][path])} in {names[0]}, {_spec(drawn[1][path])} in "
                f"{names[1]})" for path in drawn[0] if path in drawn[1] and drawn[0][path] != drawn[1][path]]  # fmt: skip
    if not reasons:
        return None
    more = len(reasons) - SHOWN_REASONS
    return "; ".join(reasons[:SHOWN_REASONS]) + (f"; and {more} more" if more > 0 else "")


SHOWN_REASONS = 3
"""Differing dispersions an unpaired reason names before 'and n more'."""
SWITCHED_SECTIONS = {"gnc", "avionics"}
"""Sections a run may fly or not (``--controller``, ``--sensors``): their dispersions and faults go with them."""


def _drawn(config: dict) -> dict[str, dict]:
    """What a resolved campaign config (a file's ``setup``) draws per flight: each dispersion's settings by its
    path, each fault some flight can have by ``faults.<fault>``."""
    drawn = {path: {k: v for k, v in spec.items() if v is not None} for path, spec in config["dispersions"].items()}
    faults = config.get("faults") or {}
    drawn.update({f"faults.{name}": f for name, f in faults.items() if f is not None and f["probability"] > 0.0})
    return drawn


def _section(path: str) -> str:
    """The campaign section a drawn ``path`` acts on: its first part, a fault's ``FAULT_SECTIONS``."""
    first, _, rest = path.partition(".")
    return FAULT_SECTIONS[rest] if first == "faults" else first


def _spec(spec: dict) -> str:
    """A dispersion's settings in words: ``normal std 0.18, high 90``."""
    return ", ".join(f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in spec.items())


def area_ratio(baseline: Run, other: Run, level: float = LEVEL,
               names: tuple[str, str] = ("the baseline", "the run")) -> dict:  # fmt: skip
    """Ratio of ``other``'s ``level`` ellipse area to ``baseline``'s and its percentile-bootstrap interval.

    Paired (no :func:`unpaired_reason`, the runs named ``names`` in it): the realizations landed in both runs,
    the others (``n_dropped``) dropped from both, resampled with the same indices in both; unpaired: each run's
    ok flights, resampled independently (``n_dropped`` None). Keys ``paired, unpaired_reason, n_used, n_dropped,
    ratio, interval`` and the relative change (ratio − 1) [%] ``change_pct, change_pct_interval``."""
    reason = unpaired_reason(baseline, other, names)
    paired = reason is None
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
        "unpaired_reason": reason,
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
    target = next((t for _, run in runs if (t := apogee_target_m(run)) is not None), None)
    return {
        "apogee_target": None if target is None else [{"file": file, **(apogee_about(run, target) or {})} for file, run in runs],
        "apogee_rms_ratios": None if target is None else [
            {"file": file, "baseline": base_file, **apogee_rms_ratio(baseline, run, target, (base_file, file))}
            for file, run in others],  # fmt: skip
        "level": level,
        "warnings": [f"{file}: {line}" for file, run in runs for line in navigation_warnings(run)],
        "runs": [{"file": file, **_naming(file, dispersion, run, level)} for file, run in runs],
        "ratios": [{"file": file, "baseline": base_file,
                    **_naming(f"{file} against {base_file}", area_ratio, baseline, run, level, (base_file, file))}
                   for file, run in others],  # fmt: skip
    }


def apogee_rms_ratio(baseline: Run, other: Run, target_m: float, names: tuple[str, str]) -> dict:
    """Ratio of ``other``'s RMS apogee error to ``target_m`` [m] to ``baseline``'s, with its percentile-bootstrap
    interval: paired as ``area_ratio`` (the flights ok in both), else each run's ok flights."""
    reason = unpaired_reason(baseline, other, names)
    paired = reason is None
    kept = baseline.ok & other.ok if paired else None
    errors = [run.outputs["apogee_agl_m"].to_numpy(dtype=float)[run.ok if kept is None else kept] - target_m
              for run in (baseline, other)]  # fmt: skip
    errors = [e[np.isfinite(e)] for e in errors] if not paired else errors
    _enough(min(e.size for e in errors), "flight(s) with an apogee")

    def ratio(base, run, axis=-1):
        return np.sqrt(np.mean(run**2, axis=axis) / np.mean(base**2, axis=axis))

    return {"paired": paired, "ratio": float(ratio(*errors)), "interval": list(percentile_interval(errors, ratio, paired))}


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
    out += text_table(
        ["file", "campaign", "ok / N", "area [km^2]", "interval", "N [m]", "interval", "E [m]", "interval"],
        [
            [r["file"], r["label"], f"{r['n_ok']} / {r['n_realizations']}",
             f"{r['ellipse']['area_m2'] / 1e6:.4g}", _interval(r["intervals"]["area_m2"], 1e6),
             f"{r['ellipse']['center_north_m']:.1f}", _interval(r["intervals"]["center_north_m"], fmt="{:.1f}"),
             f"{r['ellipse']['center_east_m']:.1f}", _interval(r["intervals"]["center_east_m"], fmt="{:.1f}")]
            for r in comparison["runs"]
        ],  # fmt: skip
        align="llrrrrrrr",
    )
    if comparison["ratios"]:
        out += ["", f"{level} ellipse area against {comparison['ratios'][0]['baseline']} (the baseline)"]
        out += text_table(
            ["file", "resampling", "area ratio", "interval", "change [%]", "interval"],
            [
                [r["file"], f"paired, {r['n_dropped']} dropped (not ok in both)" if r["paired"] else "unpaired",
                 f"{r['ratio']:.4g}", _interval(r["interval"]), f"{r['change_pct']:+.1f}",
                 _interval(r["change_pct_interval"], fmt="{:+.1f}")]
                for r in comparison["ratios"]
            ],  # fmt: skip
            align="llrrrr",
        )
        out += [f"{r['file']}: unpaired, {r['unpaired_reason']}: the runs resampled independently"
                for r in comparison["ratios"] if not r["paired"]]  # fmt: skip
    if comparison["apogee_target"]:
        out += ["", "Apogee against the air brakes' target (ok realizations)"]
        out += [f"  {r['file']}: {format_apogee_about(r)}" for r in comparison["apogee_target"] if "n" in r]
        out += [f"  {r['file']}: RMS error {r['ratio']:.4g}x the baseline's ({_interval(r['interval'])}, "
                f"{'paired' if r['paired'] else 'unpaired'})" for r in comparison["apogee_rms_ratios"]]  # fmt: skip
    out += [f"Warning: {line}" for line in comparison["warnings"]]
    return "\n".join(out)
