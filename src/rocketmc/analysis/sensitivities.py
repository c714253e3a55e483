"""What each dispersed input contributes to the spread of the landing point and of the apogee, from the per-flight
derivatives of a result file (``rocketmc sensitivities``).

Each input's first-order share of an output's variance is E[(∂y/∂x_i · σ_i)²] / Var(y): its derivative in each
flight times its spread (``campaign.derivatives.spread``), squared and averaged over the flights (ok, and not flagged
by the linearity check), over the Monte Carlo variance of the same flights. For the landing point, y is the pair
(north, east) and the variances add. The shares sum to 1 when the flight is linear in its inputs over their spreads
and nothing else varies; they miss what is not an input (the gusts' white noise, the sensors' noise), and where
the flight is far from linear over a spread (a wind direction drawn over 360°) the local derivatives do not add up
to the variance.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import h5py
import numpy as np
from matplotlib.figure import Figure

from ..campaign.derivatives import MISMATCH
from .plots import save_figure
from .results import ResultFileError

FLAG_MISMATCH = 0.1
"""A flight whose linearity check (``campaign.derivatives.sensitivities``) misses the derivatives' prediction by more
than this fraction for an output is flagged for that output: a discontinuity lies within the check's step."""
IMPACT = ("impact_north_m", "impact_east_m")


WIND_LAYER = re.compile(r"environment\.wind\.layers\.(\d+)\.(speed_mps|from_deg)")


def _inputs(wrt: list[str], derivatives: dict, drawn: dict, config: dict) -> tuple[list, dict, dict]:
    """The inputs shares are taken over: (groups, derivatives, samples). Each group is (label, its columns); a wind
    layer whose speed or direction is differentiated becomes the pair of its velocity components (north, east)
    [m/s], by the chain rule (w_n = −s cos θ, w_e = −s sin θ for a wind of speed s from θ), one group: over a
    direction drawn around the compass, the impact point is nearly linear in the components and far from linear in
    the angle. ``samples``: each column's value per flight (drawn, or the nominal)."""
    columns = {path: k for k, path in enumerate(wrt)}
    layers = sorted({int(m.group(1)) for path in wrt if (m := WIND_LAYER.fullmatch(path))})
    nominal = config["environment"]["wind"].get("layers", [])
    n = len(next(iter(derivatives.values())))
    value = lambda path, default: drawn.get(path, np.full(n, float(default)))  # noqa: E731
    groups = [(path, [path]) for path in wrt if not WIND_LAYER.fullmatch(path)]
    samples = {path: value(path, np.nan) for path in wrt if not WIND_LAYER.fullmatch(path)}
    derived = {name: {path: d[:, columns[path]] for path in samples} for name, d in derivatives.items()}
    for layer in layers:
        speed_path, from_path = (f"environment.wind.layers.{layer}.{what}" for what in ("speed_mps", "from_deg"))
        speed, from_rad = value(speed_path, nominal[layer]["speed_mps"]), np.deg2rad(value(from_path, nominal[layer]["from_deg"]))
        north, east = f"environment.wind.layers.{layer}.north_mps", f"environment.wind.layers.{layer}.east_mps"
        samples[north], samples[east] = -speed * np.cos(from_rad), -speed * np.sin(from_rad)
        groups.append((f"environment.wind.layers.{layer} (north, east)", [north, east]))
        for name, d in derivatives.items():
            by_speed = d[:, columns[speed_path]] if speed_path in columns else 0.0
            by_angle = np.rad2deg(d[:, columns[from_path]]) if from_path in columns else 0.0  # per rad
            turning = np.divide(by_angle, speed, out=np.zeros(n), where=speed > 0.0)
            derived[name][north] = -np.cos(from_rad) * by_speed + np.sin(from_rad) * turning
            derived[name][east] = -np.sin(from_rad) * by_speed - np.cos(from_rad) * turning
    return groups, derived, samples


def sensitivity_table(path: str | Path) -> dict:
    """The shares of a result file with derivatives, as a JSON-able dict: ``n``, ``ok`` (status 0 with finite
    derivatives), ``flagged`` per output, the Monte Carlo variances ``impact_variance_m2`` (north + east) and
    ``apogee_variance_m2``, and per input (``_inputs``' groups; most to the landing point first) its spread over the
    flights (the components' for a wind layer), the RMS over the flights of |∂impact/∂x| and of |∂apogee/∂x|, and
    its ``impact_share`` and ``apogee_share`` (NaN for an input not dispersed), with their sums
    ``impact_share_sum`` and ``apogee_share_sum``. An input group's share is E[J Σ Jᵀ] / Var(y), Σ the covariance of
    its values over the flights."""
    with h5py.File(path, "r") as f:
        if "derivatives" not in f:
            raise ResultFileError(f"{path}: no /derivatives (a result file of rocketmc sensitivities, not of run)")
        group = f["derivatives"]
        wrt, outputs = json.loads(group.attrs["wrt"]), json.loads(group.attrs["outputs"])
        derivatives = {name: group[name][()] for name in outputs}
        mismatch = group[MISMATCH][()]
        status = f["outputs/status"][()]
        values = {name: f[f"outputs/{name}"][()] for name in outputs}
        drawn = {name: f[f"inputs/{name}"][()] for name in f.get("inputs", {}) if name in wrt}
        config = json.loads(f.attrs["setup"])["config"]
    finite = np.all([np.isfinite(d).all(axis=1) for d in derivatives.values()], axis=0)
    ok = (status == 0) & finite
    flagged = {name: ok & (mismatch[:, k] > FLAG_MISMATCH) for k, name in enumerate(outputs)}
    trusted = {"impact": ok & ~flagged[IMPACT[0]] & ~flagged[IMPACT[1]], "apogee": ok & ~flagged["apogee_agl_m"]}
    names = {"impact": IMPACT, "apogee": ("apogee_agl_m",)}
    variance = {key: sum(float(np.var(values[name][ok])) for name in names[key]) for key in names}
    groups, derived, samples = _inputs(wrt, derivatives, drawn, config)
    rows = []
    for label, members in groups:
        dispersed = all(m in drawn or m.endswith(("north_mps", "east_mps")) for m in members)
        covariance = np.atleast_2d(np.cov(np.stack([samples[m][ok] for m in members]))) if dispersed else None
        row = {"input": label, "spread": float(np.sqrt(np.trace(covariance))) if dispersed else 0.0}
        for key in names:
            J = {name: np.stack([derived[name][m][trusted[key]] for m in members], axis=1) for name in names[key]}
            row[f"{key}_rms_derivative"] = float(np.sqrt(np.mean(sum((j**2).sum(axis=1) for j in J.values()))))
            spread_in = sum(np.einsum("fi,ij,fj->f", j, covariance, j).mean() for j in J.values()) if dispersed else np.nan
            row[f"{key}_share"] = float(spread_in / variance[key]) if variance[key] > 0.0 else np.nan
        rows.append(row)
    rows.sort(key=lambda r: -np.nan_to_num(r["impact_share"], nan=-1.0))
    return {
        "file": str(path), "n": int(len(status)), "ok": int(ok.sum()),
        "flagged": {name: int(mask.sum()) for name, mask in flagged.items()},
        "flag_mismatch": FLAG_MISMATCH,
        "impact_variance_m2": variance["impact"], "apogee_variance_m2": variance["apogee"], "inputs": rows,
        "impact_share_sum": float(np.nansum([r["impact_share"] for r in rows])),
        "apogee_share_sum": float(np.nansum([r["apogee_share"] for r in rows])),
    }  # fmt: skip


def _percent(share: float) -> str:
    return "-" if np.isnan(share) else f"{100 * share:.1f} %"


def format_sensitivities(table: dict) -> str:
    """``sensitivity_table``'s dict as a ranked table and a few lines."""
    flagged = ", ".join(f"{name} {k}" for name, k in table["flagged"].items() if k) or "none"
    lines = [
        f"{table['file']}: {table['n']} flights, {table['ok']} ok with finite derivatives; flagged (a discontinuity "
        f"within the linearity check's step, mismatch > {table['flag_mismatch']:g}): {flagged}",
        f"Monte Carlo variance: landing point (north + east) {table['impact_variance_m2']:.4g} m², apogee "
        f"{table['apogee_variance_m2']:.4g} m²",
        f"  {'input':<44}{'spread':>10}{'RMS |dimpact/dx|':>18}{'impact share':>14}{'RMS dapogee/dx':>16}"
        f"{'apogee share':>14}",
    ]  # fmt: skip
    for r in table["inputs"]:
        lines.append(f"  {r['input']:<44}{r['spread']:>10.4g}{r['impact_rms_derivative']:>18.4g}"
                     f"{_percent(r['impact_share']):>14}{r['apogee_rms_derivative']:>16.4g}{_percent(r['apogee_share']):>14}")  # fmt: skip
    lines.append(f"first-order sum: {_percent(table['impact_share_sum'])} of the landing point's variance, "
                 f"{_percent(table['apogee_share_sum'])} of the apogee's (the rest: what is not an input, such as "
                 "the gusts' noise, and what a local derivative does not describe)")  # fmt: skip
    return "\n".join(lines)


TORNADO_INPUTS = 15
"""Inputs shown in the tornado plot, largest shares first."""


def plot_tornado(table: dict, path: str | Path) -> Path:
    """The first-order shares of the landing point's and the apogee's variance per input as horizontal bars,
    largest first (``TORNADO_INPUTS`` at most), saved to ``path``."""
    fig = Figure(figsize=(10, 0.35 * TORNADO_INPUTS + 1.5), layout="constrained")
    axes = fig.subplots(1, 2, sharey=True)
    rows = [r for r in table["inputs"] if not np.isnan(r["impact_share"])][:TORNADO_INPUTS][::-1]
    names = [r["input"] for r in rows]
    for ax, key, title in ((axes[0], "impact_share", "landing point"), (axes[1], "apogee_share", "apogee")):
        ax.barh(names, [100 * r[key] for r in rows], color="tab:blue")
        ax.set_xlabel("first-order share of the variance [%]")
        total = table[f"{key}_sum"]
        ax.set_title(f"{title}: sum {100 * total:.0f} % of the Monte Carlo variance", fontsize=10)
        ax.grid(axis="x", alpha=0.3)
    fig.suptitle(f"{Path(table['file']).name}: {table['ok']} flights", fontsize=11)
    save_figure(fig, path)
    return Path(path)
