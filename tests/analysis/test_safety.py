"""The probability of landing outside a radius or a polygon, against the Clopper-Pearson interval's closed form in
beta quantiles (independent of binomtest's code path) and the rule of three."""

import json

import numpy as np
import pytest
from scipy.stats import beta

from rocketmc.analysis import load_run
from rocketmc.analysis.safety import format_outside, outside_polygon, outside_radius, read_polygon

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


SITE = (41.8087, 14.0543)
HALF_M = 900.0  # the square's half side [m]


def _square(tmp_path):
    """The square |north|, |east| <= HALF_M around the pad as a GeoJSON Feature and as a CSV (lat_deg,lon_deg)."""
    from rocketmc.env.site import latitude_longitude_deg

    corners = np.array([(-1, -1), (-1, 1), (1, 1), (1, -1), (-1, -1)], float) * HALF_M  # (north, east)
    lat, lon = latitude_longitude_deg(corners[:, 0], corners[:, 1], *SITE)
    geojson, csv = tmp_path / "range.geojson", tmp_path / "range.csv"
    geojson.write_text(json.dumps({"type": "Feature", "properties": {},
                                   "geometry": {"type": "Polygon", "coordinates": [np.column_stack([lon, lat]).tolist()]}}))  # fmt: skip
    csv.write_text("lat_deg,lon_deg\n" + "".join(f"{a!r},{o!r}\n" for a, o in zip(lat[:-1].tolist(), lon[:-1].tolist())))  # an open ring
    return geojson, csv


def test_outside_a_square_polygon_against_the_hand_count(run, tmp_path):
    """Outside the square: |north| or |east| beyond HALF_M counted by hand (no radius), plus the flights without an
    impact point; GeoJSON and CSV alike, the interval as for the radius."""
    run, outputs = run
    north, east = outputs["impact_north_m"], outputs["impact_east_m"]
    no_point = ~np.isfinite(north)
    k = int(((np.abs(north) > HALF_M) | (np.abs(east) > HALF_M))[~no_point].sum()) + int(no_point.sum())
    assert 0 < k < len(north) - 50  # the square cuts the footprint
    n = len(north)
    for path in _square(tmp_path):
        result = outside_polygon(run, read_polygon(path, *SITE), path.name)
        assert (result["outside"], result["n"], result["without_impact_point"]) == (k, n, 3)
        assert result["interval"] == pytest.approx([beta.ppf(0.025, k, n - k + 1), beta.ppf(0.975, k + 1, n - k)])
        assert f"outside the allowed area {path.name}: {k} of {n}" in format_outside(result)


@pytest.mark.parametrize("name, text, field", [
    ("a.geojson", '{"type": "Point", "coordinates": [14, 41]}', "'type' is 'Point'"),
    ("a.geojson", '{"type": "Polygon", "coordinates": [[[14, 41], [14.1, "x"], [14, 41.1]]]}', "'coordinates' ring 0"),
    ("a.geojson", '{"type": "Polygon"', "not JSON"),
    ("a.csv", "lat,lon\n41,14\n", "no 'lat_deg' column"),
    ("a.csv", "lat_deg,lon_deg\n41,14\n41.1,14\n", "'lat_deg/lon_deg' ring 0 needs at least 3"),
    ("a.csv", "lat_deg,lon_deg\n91,14\n41.1,14\n41,14.1\n", "latitude beyond"),
    ("a.txt", "", "expected a .geojson or .csv"),
])  # fmt: skip
def test_malformed_polygon_files_name_the_file_and_field(tmp_path, name, text, field):
    from rocketmc.errors import RocketmcError

    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(RocketmcError) as info:
        read_polygon(path, *SITE)
    assert str(path) in str(info.value) and field in str(info.value)
