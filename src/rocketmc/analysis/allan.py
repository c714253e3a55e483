"""Allan deviation of rate-type sensor records (gyro, accelerometer) and its white-noise and
rate-random-walk terms, on the host (numpy, scipy, matplotlib).

A rate signal y (e.g. rad/s) sampled at f [Hz], n samples; cluster time τ = m/f [s] for m samples.
The overlapping Allan variance (IEEE Std 952-1997, Annex C) is half the mean square difference of
adjacent m-sample averages, computed from the integrated signal θ_k = Σ_{i<k} y_i / f (θ_0 = 0):

    σ²(τ) = Σ_{k=0}^{n−2m} (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ² (n + 1 − 2m)).

Closed forms: white rate noise of per-sample standard deviation σ gives σ/√(fτ) = N/√τ with
N = σ/√f [unit·√s] (a gyro's angle random walk); a rate random walk y' = K·w (w white of unit
spectral density) gives K·√(τ/3) [unit/√s]; a ramp y = R·t gives R·τ/√2.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from scipy.optimize import nnls

from .plots import save_figure

DOMINANCE = 10.0
"""A term's region: the taus where its Allan variance exceeds the other term's this many times."""


def allan_deviation(samples, rate_hz: float, taus=None) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping Allan deviation of ``samples`` [unit], shape (n,) or (n, k) with independent
    columns, sampled at ``rate_hz``: (taus [s], adev [unit]) with adev of shape (len(taus),) or
    (len(taus), k).

    ``taus`` [s] are rounded to whole samples m = round(τ·f), 1 ≤ m ≤ n/2, and returned as m/f.
    Default: about 10 per decade, m log-spaced from 1 to n // 10, unique. O(n) per tau (cumulative
    sums in float64, of the samples less their mean, which the Allan variance ignores).
    """
    y = np.asarray(samples, dtype=float)
    n = y.shape[0]
    if y.ndim not in (1, 2) or n < 10:
        raise ValueError(f"allan_deviation: need samples of shape (n,) or (n, k) with n ≥ 10, got {y.shape}")
    if taus is None:
        top = n // 10
        m = np.unique(np.rint(np.logspace(0.0, np.log10(top), int(10 * np.log10(top)) + 1)).astype(int))
    else:
        m = np.rint(np.atleast_1d(np.asarray(taus, dtype=float)) * rate_hz).astype(int)
        if m.ndim != 1 or np.any(m < 1) or np.any(2 * m > n):
            raise ValueError(f"allan_deviation: taus must be 1 to {n // 2} samples of 1/{rate_hz} s")
    theta = np.concatenate([np.zeros((1, *y.shape[1:])), np.cumsum(y - y.mean(axis=0), axis=0)])  # [unit·samples]
    adev = np.stack([np.sqrt(np.mean((theta[2 * k :] - 2.0 * theta[k : n + 1 - k] + theta[: n + 1 - 2 * k]) ** 2,
                                     axis=0) / 2.0) / k for k in m])  # fmt: skip
    return m / rate_hz, adev


def noise_terms(taus, adev) -> dict[str, float]:
    """White-noise and rate-random-walk terms of one channel's Allan deviation (``taus`` [s], ``adev`` [unit]).

    ``N`` [unit·√s] and ``K`` [unit/√s] fit σ²(τ) = N²/τ + K²τ/3 by non-negative least squares, each
    point weighted by the inverse of its standard error: the equivalent degrees of freedom of the
    overlapping estimator are ~n/m for both terms, so that error is ∝ σ²·√τ (σ² the fit of a first
    pass weighted by the measured values, which would favour points that scatter low). N is the white
    part's value at τ = 1 s, K the walk part's value at τ = 3 s; ``crossover_s`` = √3·N/K, where the
    two are equal. ``white_slope`` and ``walk_slope``: least-squares slopes of log σ against log τ
    (weights 1/√τ, the same errors) over the taus where that term's variance exceeds the other's
    ``DOMINANCE`` times (τ ≤ crossover/√10, τ ≥ crossover·√10), of the measured σ² times the term's
    share of the fit (the other term's tail, 1/11 at a region's edge, would bend the slope there by
    0.09); NaN with fewer than 3 taus in a region.
    """
    taus, avar = np.asarray(taus, dtype=float), np.asarray(adev, dtype=float) ** 2
    basis = np.stack([1.0 / taus, taus / 3.0], axis=1)
    scale = avar
    for _ in range(2):
        weight = 1.0 / (scale * np.sqrt(taus))
        (n2, k2), _ = nnls(basis * weight[:, None], avar * weight)
        scale = basis @ [n2, k2]
    n_, k_ = float(np.sqrt(n2)), float(np.sqrt(k2))
    crossover = np.sqrt(3.0) * n_ / k_ if k_ > 0.0 else np.inf
    white, walk = n2 / taus, k2 * taus / 3.0

    def slope(inside, share):
        if inside.sum() < 3:
            return float("nan")
        part = avar[inside] * share[inside] / (white + walk)[inside]
        return float(np.polyfit(np.log(taus[inside]), np.log(part) / 2.0, 1, w=1.0 / np.sqrt(taus[inside]))[0])

    return {"N": n_, "K": k_, "crossover_s": float(crossover),
            "white_slope": slope(taus <= crossover / np.sqrt(DOMINANCE), white),
            "walk_slope": slope(taus >= crossover * np.sqrt(DOMINANCE), walk)}  # fmt: skip


def plot_allan(series: dict[str, tuple[np.ndarray, np.ndarray]], path: str | Path | None, unit: str) -> Figure:
    """Log-log Allan deviations ``{label: (taus [s], adev [unit])}``, one line each, with reference
    lines of slope −½ (white noise) through the first series' first point and +½ (rate random walk)
    through its last; saved to ``path`` (PNG at 150 dpi) if given."""
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax = fig.add_subplot()
    for label, (taus, adev) in series.items():
        ax.loglog(taus, adev, marker=".", markersize=4, label=label)
    taus, adev = (np.asarray(a, dtype=float) for a in next(iter(series.values())))
    lo, hi = min(float(np.min(t)) for t, _ in series.values()), max(float(np.max(t)) for t, _ in series.values())
    grid = np.geomspace(lo, hi, 50)
    ax.loglog(grid, adev[0] * np.sqrt(taus[0] / grid), "k--", linewidth=0.8, label="slope −½: white noise")
    ax.loglog(grid, adev[-1] * np.sqrt(grid / taus[-1]), "k:", linewidth=0.8, label="slope +½: rate random walk")
    ax.set_xlabel("cluster time τ [s]")
    ax.set_ylabel(f"Allan deviation [{unit}]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    if path is not None:
        save_figure(fig, path)
    return fig
