"""Confidence ellipses of impact points (north/east in metres from the pad, NED world frame)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np


def chi2_scale(level: float) -> float:
    """Squared Mahalanobis radius k^2 enclosing ``level`` of a 2-D normal: ``chi2.ppf(level, 2)``.

    For two degrees of freedom this equals ``-2 ln(1 - level)``.
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"confidence level must lie strictly between 0 and 1, got {level}")
    from scipy.stats import chi2  # here, not at import: scipy.stats takes ~0.6 s before a run's first flight

    return float(chi2.ppf(level, df=2))


@dataclass(frozen=True)
class Ellipse:
    """Confidence ellipse in the horizontal plane.

    Centre and semi-axes in metres (north/east from the pad); ``orientation_deg`` is the azimuth
    of the major axis, clockwise from north, in [0, 180); ``n`` the number of points used.
    """

    level: float
    center_north_m: float
    center_east_m: float
    semi_major_m: float
    semi_minor_m: float
    orientation_deg: float
    n: int

    @property
    def area_m2(self) -> float:
        """Area pi*a*b [m^2]."""
        return float(np.pi * self.semi_major_m * self.semi_minor_m)

    def to_dict(self) -> dict:
        """Plain JSON-serialisable dict of the fields plus ``area_m2``."""
        return {**asdict(self), "area_m2": self.area_m2}

    def _axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit vectors (north, east) of the major and minor axes."""
        az = np.deg2rad(self.orientation_deg)
        return np.array([np.cos(az), np.sin(az)]), np.array([-np.sin(az), np.cos(az)])

    def boundary(self, n_points: int = 200) -> tuple[np.ndarray, np.ndarray]:
        """Closed outline as ``(north, east)`` arrays [m] of ``n_points`` (first = last point)."""
        t = np.linspace(0.0, 2.0 * np.pi, n_points)
        major, minor = self._axes()
        a = self.semi_major_m * np.cos(t)
        b = self.semi_minor_m * np.sin(t)
        north = self.center_north_m + a * major[0] + b * minor[0]
        east = self.center_east_m + a * major[1] + b * minor[1]
        return north, east

    def contains(self, north, east) -> np.ndarray:
        """Boolean array: which points (north, east) [m] lie inside or on the ellipse.

        A degenerate (zero-width) axis only admits points exactly on it.
        """
        dn = np.asarray(north, dtype=float) - self.center_north_m
        de = np.asarray(east, dtype=float) - self.center_east_m
        major, minor = self._axes()
        x = dn * major[0] + de * major[1]
        y = dn * minor[0] + de * minor[1]
        return _normalised_sq(x, self.semi_major_m) + _normalised_sq(y, self.semi_minor_m) <= 1.0


def _normalised_sq(x: np.ndarray, semi_axis: float) -> np.ndarray:
    """(x / semi_axis)^2, with 0/0 = 0 and x/0 = inf."""
    if semi_axis > 0.0:
        return (x / semi_axis) ** 2
    return np.where(x == 0.0, 0.0, np.inf)


def confidence_ellipse(north, east, level: float = 0.95) -> Ellipse:
    """Ellipse expected to hold ``level`` of the impact points, assuming they are 2-D normal.

    ``north``, ``east``: impact coordinates [m] from the pad (NED). Pairs with a non-finite
    coordinate (failed realizations) are ignored. Uses the sample mean and sample covariance
    (ddof=1) scaled by k^2 = ``chi2.ppf(level, df=2)``: semi-axes are sqrt(k^2 * eigenvalues).
    """
    north = np.asarray(north, dtype=float).ravel()
    east = np.asarray(east, dtype=float).ravel()
    if north.shape != east.shape:
        raise ValueError(f"north and east differ in length: {north.size} vs {east.size}")
    k2 = chi2_scale(level)
    finite = np.isfinite(north) & np.isfinite(east)
    n = int(finite.sum())
    if n < 3:
        raise ValueError(
            f"a confidence ellipse needs at least 3 finite (north, east) points, got {n} "
            f"of {north.size}"
        )
    points = np.stack([north[finite], east[finite]])
    center = points.mean(axis=1)
    eigval, eigvec = np.linalg.eigh(np.cov(points, ddof=1))  # ascending eigenvalues
    eigval = np.clip(eigval, 0.0, None)  # round-off can make a zero eigenvalue slightly negative
    major = eigvec[:, 1]
    orientation = float(np.degrees(np.arctan2(major[1], major[0])) % 180.0)
    if orientation >= 180.0:  # -tiny % 180 rounds to 180.0
        orientation = 0.0
    return Ellipse(
        level=float(level),
        center_north_m=float(center[0]),
        center_east_m=float(center[1]),
        semi_major_m=float(np.sqrt(k2 * eigval[1])),
        semi_minor_m=float(np.sqrt(k2 * eigval[0])),
        orientation_deg=orientation,
        n=n,
    )


def ellipse_area_m2(north, east, level: float = 0.95, axis: int = -1):
    """Area π·k²·sqrt(det Σ) [m²] of the ``level`` ellipse of points along ``axis`` (sample covariance
    Σ, ddof=1; the same area as ``confidence_ellipse``), vectorised for the bootstrap."""
    dn = north - np.mean(north, axis=axis, keepdims=True)
    de = east - np.mean(east, axis=axis, keepdims=True)
    m = np.shape(north)[axis] - 1
    det = np.mean(dn * dn, axis=axis) * np.mean(de * de, axis=axis) - np.mean(dn * de, axis=axis) ** 2
    return np.pi * chi2_scale(level) * np.sqrt(np.clip(det, 0.0, None)) * (m + 1) / m


MIN_BOOTSTRAP_POINTS = 10
"""Fewest impact points given bootstrap intervals (report, compare): with fewer, resamples drawing
two or fewer distinct points (a zero area) stop being rare."""


def percentile_interval(samples, statistic, paired: bool = True, confidence: float = 0.95, n_resamples: int = 2000,
                        seed=0) -> tuple[float, float]:  # fmt: skip
    """Percentile-bootstrap interval (``scipy.stats.bootstrap``) of ``statistic(*samples, axis=-1)``,
    vectorised, at ``confidence``: each sample's last axis (its points) resampled, with the same indices
    for all samples when ``paired``, independently otherwise."""
    from scipy.stats import bootstrap  # as in ``chi2_scale``

    result = bootstrap(samples, statistic, paired=paired, vectorized=True, axis=-1, confidence_level=confidence,
                       n_resamples=n_resamples, method="percentile", random_state=seed)  # fmt: skip
    return float(result.confidence_interval.low), float(result.confidence_interval.high)


def bootstrap_intervals(north, east, level: float = 0.95, confidence: float = 0.95, n_resamples: int = 2000, seed=0):
    """Percentile-bootstrap intervals (``scipy.stats.bootstrap``, resampling impact points in pairs) of
    the ``level`` ellipse's area [m²] and centre [m], at ``confidence``:
    ``{"area_m2": (low, high), "center_north_m": (low, high), "center_east_m": (low, high)}``.

    Percentile rather than BCa: BCa's jackknife costs O(N²), too much at N = 10⁵; for these smooth
    statistics of N ≥ 100 points the two agree (tests/analysis/test_ellipse.py checks coverage)."""
    north = np.asarray(north, dtype=float)
    east = np.asarray(east, dtype=float)
    finite = np.isfinite(north) & np.isfinite(east)
    north, east = north[finite], east[finite]
    statistics = {
        "area_m2": lambda n, e, axis=-1: ellipse_area_m2(n, e, level, axis),
        "center_north_m": lambda n, e, axis=-1: np.mean(n, axis=axis),
        "center_east_m": lambda n, e, axis=-1: np.mean(e, axis=axis),
    }
    return {name: percentile_interval((north, east), statistic, True, confidence, n_resamples, seed)
            for name, statistic in statistics.items()}  # fmt: skip


class AreaConvergence:
    """``--until-converged``: the impacts so far, and whether the 95 % bootstrap interval of the 95 %
    ellipse's area is narrower than ``target`` (a fraction) of the area. Checked when the ok points
    have grown by 10 % since the last check (the bootstrap costs ~1 s per 10⁴ points), from 100 on."""

    MIN_POINTS = 100

    def __init__(self, target: float):
        self.target, self.chunks, self.n, self.checked_at = target, [], 0, 0
        self.converged, self.area_m2, self.width = False, float("nan"), float("inf")

    def add(self, outputs: dict) -> None:
        ok = outputs["status"] == 0
        self.chunks.append((outputs["impact_north_m"][ok], outputs["impact_east_m"][ok]))
        self.n += len(outputs["status"])

    def check(self) -> bool:
        north, east = (np.concatenate(parts) for parts in zip(*self.chunks)) if self.chunks else ([], [])
        if len(north) < max(self.MIN_POINTS, 1.1 * self.checked_at):
            return False
        self.checked_at = len(north)
        self.area_m2 = float(ellipse_area_m2(north, east))
        low, high = bootstrap_intervals(north, east, n_resamples=1000)["area_m2"]
        self.width = (high - low) / self.area_m2
        self.converged = self.width < self.target
        return self.converged
