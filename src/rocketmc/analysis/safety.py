"""The probability of landing outside a radius from the pad or outside the range's allowed area (a polygon),
with its exact (Clopper-Pearson) interval.

Counting, for a range-safety officer: every realization is a trial. A flight that failed but landed (a
tumble) counts by where it landed; one without an impact point (a NaN state, still airborne at
``max_time_s``) counts as outside, since nothing shows it landed inside. Impact points are north/east [m]
from the pad (NED); a polygon's WGS84 vertices are put on the pad's tangent plane (env/site.py)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.path import Path as Outline
from scipy.stats import binomtest

from ..env.site import north_east_m
from ..errors import RocketmcError
from .results import Run

POLYGON_SUFFIXES = (".geojson", ".json", ".csv")


def _count_outside(run: Run, outside: np.ndarray, confidence: float) -> dict:
    """The counts, fraction and intervals of :func:`outside_radius`, ``outside`` a mask over all flights (read
    only where they landed; those without an impact point count as outside)."""
    landed = run.has_impact
    n, no_point = len(landed), int((~landed).sum())
    k = int(outside[landed].sum()) + no_point
    ci = binomtest(k, n).proportion_ci(confidence, method="exact") if n else None
    return {
        "n": n, "outside": k, "without_impact_point": no_point,
        "fraction": k / n if n else None, "confidence": confidence,
        "interval": None if ci is None else [float(ci.low), float(ci.high)],
        "upper_bound_none_outside": 1.0 - (1.0 - confidence) ** (1.0 / n) if n and k == 0 else None,
    }  # fmt: skip


def outside_radius(run: Run, radius_m: float, confidence: float = 0.95) -> dict:
    """Flights landing farther than ``radius_m`` [m] from the pad out of all N, the fraction, its two-sided
    exact ``confidence`` interval (``binomtest(...).proportion_ci(method="exact")``) and, when none fell
    outside, the one-sided upper bound 1 − (1 − confidence)^(1/N) (≈ 3/N at 95 %: the rule of three)."""
    north, east = run.outputs["impact_north_m"].to_numpy(float), run.outputs["impact_east_m"].to_numpy(float)
    with np.errstate(invalid="ignore"):
        outside = np.hypot(north, east) > radius_m
    return {"radius_m": radius_m, "region": f"more than {radius_m:g} m from the pad",
            **_count_outside(run, outside, confidence)}  # fmt: skip


def read_polygon(path: str | Path, site_latitude_deg: float, site_longitude_deg: float) -> list[np.ndarray]:
    """The rings of the allowed area in ``path`` as (K, 2) north/east [m] from the site: a GeoJSON Polygon
    (a geometry, a Feature or a FeatureCollection of one; its exterior ring then any holes) or a CSV with
    ``lat_deg,lon_deg`` columns [deg] (one ring). A malformed file: a RocketmcError naming it and the field."""
    path = Path(path)
    if path.suffix.lower() not in POLYGON_SUFFIXES:
        raise RocketmcError(f"--outside-polygon {path}: expected a .geojson or .csv file name")
    if path.suffix.lower() == ".csv":
        try:
            table = pd.read_csv(path)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
            raise RocketmcError(f"{path}: not a CSV table ({' '.join(str(e).split())})") from None
        for column in ("lat_deg", "lon_deg"):
            if column not in table:
                raise RocketmcError(f"{path}: no '{column}' column (expected lat_deg,lon_deg)")
        rings = [table[["lon_deg", "lat_deg"]].to_numpy()]
        field = "lat_deg/lon_deg"
    else:
        try:
            data = json.loads(path.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError) as e:
            raise RocketmcError(f"{path}: not JSON ({e})") from None
        if isinstance(data, dict) and data.get("type") == "FeatureCollection":
            features = data.get("features")
            if not isinstance(features, list) or len(features) != 1:
                raise RocketmcError(f"{path}: 'features' must hold exactly one Polygon feature")
            data = features[0]
        if isinstance(data, dict) and data.get("type") == "Feature":
            data = data.get("geometry")
        if not isinstance(data, dict) or data.get("type") != "Polygon":
            found = data.get("type") if isinstance(data, dict) else type(data).__name__
            raise RocketmcError(f"{path}: 'type' is {found!r}, expected a GeoJSON Polygon")
        rings, field = data.get("coordinates"), "coordinates"
        if not isinstance(rings, list) or not rings:
            raise RocketmcError(f"{path}: 'coordinates' must be a list of rings of [longitude, latitude]")
    outlines = []
    for i, ring in enumerate(rings):
        try:
            lon_lat = np.asarray(ring, dtype=float)
        except (TypeError, ValueError):
            raise RocketmcError(f"{path}: '{field}' ring {i} holds a value that is not a number") from None
        if lon_lat.ndim != 2 or lon_lat.shape[1] < 2 or len(lon_lat) < 3 or not np.isfinite(lon_lat[:, :2]).all():
            raise RocketmcError(f"{path}: '{field}' ring {i} needs at least 3 finite [longitude, latitude] points")
        lon, lat = lon_lat[:, 0], lon_lat[:, 1]
        if np.any(np.abs(lat) > 90) or np.any(np.abs(lon) > 180):
            raise RocketmcError(f"{path}: '{field}' ring {i} has a latitude beyond ±90° or a longitude beyond ±180°")
        outlines.append(np.column_stack(north_east_m(lat, lon, site_latitude_deg, site_longitude_deg)))
    return outlines


def outside_polygon(run: Run, rings: list[np.ndarray], name: str = "", confidence: float = 0.95) -> dict:
    """As :func:`outside_radius` for the allowed area ``rings`` (north/east [m], of :func:`read_polygon`):
    inside its exterior ring and no hole (``matplotlib.path.Path.contains_points``) is inside."""
    points = np.nan_to_num(run.outputs[["impact_north_m", "impact_east_m"]].to_numpy(float))  # NaN: not read
    exterior, *holes = (Outline(ring).contains_points(points) for ring in rings)
    inside = exterior & ~np.any(holes, axis=0) if holes else exterior
    return {"polygon": name, "region": f"outside the allowed area {name}".rstrip(),
            **_count_outside(run, ~inside, confidence)}  # fmt: skip


def format_outside(result: dict) -> str:
    """One paragraph saying what :func:`outside_radius` or :func:`outside_polygon` found and what it means."""
    r, level = result, f"{100 * result['confidence']:g} %"
    lines = [f"Landing {r['region']}: {r['outside']} of {r['n']} flights "
             f"({r['without_impact_point']} without an impact point, counted as outside; failed flights that "
             f"landed counted by where they landed)"]  # fmt: skip
    if r["n"]:
        low, high = r["interval"]
        lines.append(f"  probability {r['fraction']:.4g}, exact (Clopper-Pearson) {level} interval {low:.4g}…{high:.4g}")
    if r["upper_bound_none_outside"] is not None:
        lines.append(f"  none outside: the probability is below {r['upper_bound_none_outside']:.3g} at {level} "
                     f"confidence (one-sided; the rule of three's 3/N = {3 / r['n']:.3g}), not zero")  # fmt: skip
    return "\n".join(lines)
