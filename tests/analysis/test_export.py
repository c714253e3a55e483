"""Impact maps: the local tangent plane against the sphere, GeoJSON (RFC 7946) and KML 2.2 structure,
and the ellipses' outlines back on the plane."""

from __future__ import annotations

import json
from xml.etree import ElementTree

import numpy as np
import pandas as pd
import pytest

from rocketmc.analysis import Run, confidence_ellipse
from rocketmc.analysis.export import KML_NAMESPACE, to_geojson, to_kml, write_map
from rocketmc.env.site import latitude_longitude_deg, north_east_m

SITE = (41.8087, 14.0543)  # Roccaraso


@pytest.fixture(scope="module")
def run():
    rng = np.random.default_rng(3)
    north, east = rng.normal(-300.0, 600.0, 500), rng.normal(400.0, 350.0, 500)
    east += 0.4 * north  # a tilted footprint
    status = np.zeros(500, dtype=np.int32)
    status[:7] = 2
    apogee = rng.normal(3000.0, 80.0, 500)
    apogee[8] = np.nan  # an ok flight without an apogee: null on the map
    outputs = pd.DataFrame({"impact_north_m": north, "impact_east_m": east, "status": status, "apogee_agl_m": apogee})
    toml = f'name = "map"\n[site]\nname = "Roccaraso"\nlatitude_deg = {SITE[0]}\nlongitude_deg = {SITE[1]}\naltitude_m = 1416.0\n'
    return Run(outputs, pd.DataFrame(), {"campaign_name": "map", "campaign_toml": toml}, {}, {0: "ok", 2: "tumbled"})


def test_local_plane_round_trip_and_against_the_sphere():
    north, east = np.array([-4000.0, 0.0, 2500.0]), np.array([3000.0, -5000.0, 0.0])
    lat, lon = latitude_longitude_deg(north, east, *SITE)
    back = north_east_m(lat, lon, *SITE)
    np.testing.assert_allclose(back, (north, east), atol=1e-9)  # exact inverses: rounding only
    # Haversine on a sphere of 6371 km: the ellipsoid's radii differ from it by < 0.5 % at 42°N.
    phi1, phi2, dlon = np.radians(SITE[0]), np.radians(lat), np.radians(lon - SITE[1])
    h = np.sin((phi2 - phi1) / 2) ** 2 + np.cos(phi1) * np.cos(phi2) * np.sin(dlon / 2) ** 2
    np.testing.assert_allclose(2 * 6371e3 * np.arcsin(np.sqrt(h)), np.hypot(north, east), rtol=5e-3)


def test_geojson_is_valid_and_ellipses_lie_on_the_ellipse(run):
    data = json.loads(json.dumps(to_geojson(run)))  # plain JSON types only
    assert data["type"] == "FeatureCollection"
    kinds = [f["geometry"]["type"] for f in data["features"]]
    assert kinds == ["Point", "Polygon", "Polygon", "Polygon"] + ["Point"] * 500  # a Point per flight, failed last
    assert data["features"][0]["geometry"]["coordinates"] == [SITE[1], SITE[0]]  # [longitude, latitude]
    north, east = run.ok_impacts()
    for feature in data["features"][1:4]:
        assert feature["type"] == "Feature" and "properties" in feature
        (ring,) = feature["geometry"]["coordinates"]
        assert len(ring) >= 4 and ring[0] == ring[-1]  # RFC 7946 §3.1.6: closed linear ring
        x, y = np.asarray(ring[:-1]).T
        assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0  # exterior ring counterclockwise
        assert np.all(np.abs(x) <= 180) and np.all(np.abs(y) <= 90)
        ellipse = confidence_ellipse(north, east, feature["properties"]["level"])
        ring_north, ring_east = north_east_m(y, x, *SITE)
        # back on the plane, every vertex is on the ellipse: normalised radius 1 (1e-9: rounding)
        a, b = ellipse._axes()
        dn, de = ring_north - ellipse.center_north_m, ring_east - ellipse.center_east_m
        radius2 = ((dn * a[0] + de * a[1]) / ellipse.semi_major_m) ** 2 + ((dn * b[0] + de * b[1]) / ellipse.semi_minor_m) ** 2
        np.testing.assert_allclose(radius2, 1.0, atol=1e-9)


def _expected_position(run, index):
    """(longitude, latitude) [deg] of realization ``index``'s impact point."""
    lat, lon = latitude_longitude_deg(run.outputs["impact_north_m"][index], run.outputs["impact_east_m"][index], *SITE)
    return [float(lon), float(lat)]


def test_geojson_points_carry_their_flight(run, tmp_path):
    """Read back from the written file: one Point per flight that landed, with its realization's index,
    status and apogee [m] (null where NaN), where that realization landed, coloured by status."""
    data = json.loads(write_map(run, tmp_path / "m.geojson").read_text())
    points = data["features"][4:]
    assert sorted(p["properties"]["index"] for p in points) == list(range(500))
    apogee = run.outputs["apogee_agl_m"]
    for p in points:
        i, props = p["properties"]["index"], p["properties"]
        assert props["status"] == run.outputs["status"][i] and props["name"] == f"impact {i}"
        assert props["apogee_m"] == (None if i == 8 else apogee[i])  # exact: JSON keeps the float's repr
        assert props["message"] == ("ok" if i >= 7 else "tumbled")
        assert props["marker-color"] == ("#1f77b4" if i >= 7 else "#000000")
        np.testing.assert_allclose(p["geometry"]["coordinates"], _expected_position(run, i), rtol=0, atol=1e-12)


def test_kml_placemarks_carry_their_flight(run, tmp_path):
    """Read back from the written KML: each impact placemark is named by its realization, described with its
    status and apogee, its index/status/apogee_m in ExtendedData, styled #ok or #failed."""
    ns = {"k": KML_NAMESPACE}
    document = ElementTree.parse(write_map(run, tmp_path / "m.kml")).getroot().find("k:Document", ns)
    assert {s.get("id") for s in document.findall("k:Style", ns)} >= {"ok", "failed"}
    marks = document.findall("k:Folder/k:Placemark", ns)
    assert len(marks) == 500
    for mark in marks:
        data = {d.get("name"): d.findtext("k:value", namespaces=ns) for d in mark.findall("k:ExtendedData/k:Data", ns)}
        i = int(data["index"])
        status = int(run.outputs["status"][i])
        assert int(data["status"]) == status and mark.findtext("k:name", namespaces=ns) == f"impact {i}"
        assert data["apogee_m"] == ("" if i == 8 else str(run.outputs["apogee_agl_m"][i]))
        assert mark.findtext("k:styleUrl", namespaces=ns) == ("#ok" if status == 0 else "#failed")
        description = mark.findtext("k:description", namespaces=ns)
        assert description.startswith(f"realization {i}, status {status} ({'ok' if status == 0 else 'tumbled'})")
        assert ("no apogee" if i == 8 else f"apogee {run.outputs['apogee_agl_m'][i]:.0f} m") in description
        lon, lat, _ = map(float, mark.findtext("k:Point/k:coordinates", namespaces=ns).split(","))
        np.testing.assert_allclose([lon, lat], _expected_position(run, i), rtol=0, atol=1e-7)  # 7 decimals written


def test_kml_parses_and_follows_the_schema_order(run):
    root = ElementTree.fromstring(to_kml(run).encode())
    ns = {"k": KML_NAMESPACE}
    assert root.tag == f"{{{KML_NAMESPACE}}}kml"
    document = root.find("k:Document", ns)
    tags = [child.tag.split("}")[1] for child in document]
    assert tags[0] == "name" and tags.index("Placemark") > max(i for i, t in enumerate(tags) if t == "Style")
    rings = document.findall("k:Placemark/k:Polygon/k:outerBoundaryIs/k:LinearRing/k:coordinates", ns)
    assert len(rings) == 3
    for ring in rings:
        points = [tuple(map(float, p.split(","))) for p in ring.text.split()]
        assert points[0] == points[-1] and all(len(p) == 3 for p in points)
    assert len(document.findall("k:Folder/k:Placemark/k:Point", ns)) == 500  # 493 ok impacts, the failed landed apart
    assert len(document.findall("k:Folder", ns)[0].findall("k:Placemark", ns)) == 493
    for mark in document.iter(f"{{{KML_NAMESPACE}}}Placemark"):
        children = [c.tag.split("}")[1] for c in mark]
        assert children[0] == "name" and children[-1] in ("Point", "Polygon")  # styleUrl before the geometry


def test_write_map_by_suffix_and_errors(run, tmp_path):
    assert write_map(run, tmp_path / "m.geojson").read_text().startswith("{")
    assert write_map(run, tmp_path / "m.kml").read_text().startswith("<?xml")
    with pytest.raises(ValueError, match="expected a .kml or .geojson"):
        write_map(run, tmp_path / "m.txt")
    no_site = Run(run.outputs, run.inputs, {"campaign_toml": 'name = "x"\n'}, {}, {})
    with pytest.raises(ValueError, match=r"no \[site\]"):
        to_geojson(no_site)
