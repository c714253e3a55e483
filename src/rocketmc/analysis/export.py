"""Impact points and confidence ellipses on the map: GeoJSON (RFC 7946) and KML 2.2, positioned by
the campaign's launch site (``[site]`` latitude/longitude, WGS84) through its local tangent plane."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from ..env.site import latitude_longitude_deg
from ..files import replacing
from .ellipse import confidence_ellipse
from .results import SUMMARY_LEVELS, Run

KML_NAMESPACE = "http://www.opengis.net/kml/2.2"
MAP_SUFFIXES = (".kml", ".geojson", ".json")
_ELLIPSE_POINTS = 120
_KML_COLORS = ("ff00a5ff", "ff0000ff", "ff800080")  # aabbggrr: orange, red, purple for 50/95/99 %


def _site(run: Run) -> tuple[str, float, float]:
    """(name, latitude [deg], longitude [deg]) of the run's launch site, from its campaign text."""
    try:
        site = tomllib.loads(run.attrs["campaign_toml"])["site"]
        return site.get("name", ""), float(site["latitude_deg"]), float(site["longitude_deg"])
    except (KeyError, tomllib.TOMLDecodeError, TypeError, ValueError):
        raise ValueError("the result file's campaign_toml attribute has no [site] latitude_deg/longitude_deg") from None


def map_features(run: Run, levels=SUMMARY_LEVELS) -> dict:
    """The pad, the ok impact points and the ``levels`` ellipses as lists of (longitude, latitude)
    [deg]: ``{"site": name, "pad": (lon, lat), "impacts": [(lon, lat), ...], "ellipses": {level: ring},
    "failed": {status code: [(lon, lat), ...]}}`` (the failed flights that landed, apart, per status);
    each ring is closed (last point = first) and counterclockwise seen from above."""
    name, lat0, lon0 = _site(run)
    north, east = run.ok_impacts()
    lat, lon = latitude_longitude_deg(north, east, lat0, lon0)
    ellipses = {}
    if north.size >= 3:
        for level in levels:
            b_north, b_east = confidence_ellipse(north, east, level).boundary(_ELLIPSE_POINTS)
            ring_lat, ring_lon = latitude_longitude_deg(b_north, b_east, lat0, lon0)
            ring = list(zip(ring_lon.tolist(), ring_lat.tolist()))
            ring = ring[:-1] if ring[0] == ring[-1] else ring
            if _signed_area(ring) < 0:  # RFC 7946: exterior rings counterclockwise
                ring = ring[::-1]
            ellipses[level] = [*ring, ring[0]]
    status = run.outputs["status"].to_numpy()
    failed = {}
    for code in sorted(set(status[~run.ok].tolist())):
        f_lat, f_lon = latitude_longitude_deg(*run.ok_impacts(run.has_impact & (status == code)), lat0, lon0)
        failed[code] = list(zip(f_lon.tolist(), f_lat.tolist()))
    return {"site": name, "pad": (lon0, lat0), "impacts": list(zip(lon.tolist(), lat.tolist())), "ellipses": ellipses,
            "failed": failed}  # fmt: skip


def _signed_area(ring) -> float:
    """Shoelace area of an open ring in (x, y); positive when counterclockwise."""
    x, y = np.asarray(ring).T
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def to_geojson(run: Run, levels=SUMMARY_LEVELS) -> dict:
    """A GeoJSON FeatureCollection: the pad, one MultiPoint of impacts, one Polygon per ellipse."""
    f = map_features(run, levels)
    name = run.attrs.get("campaign_name", "")
    features = [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": list(f["pad"])},
         "properties": {"name": f"pad ({f['site']})" if f["site"] else "pad"}},
        {"type": "Feature", "geometry": {"type": "MultiPoint", "coordinates": [list(p) for p in f["impacts"]]},
         "properties": {"name": f"{name}: impact points", "count": len(f["impacts"])}},
    ] + [
        {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [[list(p) for p in ring]]},
         "properties": {"name": f"{name}: {100 * level:g} % impact ellipse", "level": level}}
        for level, ring in f["ellipses"].items()
    ] + [
        {"type": "Feature", "geometry": {"type": "MultiPoint", "coordinates": [list(p) for p in points]},
         "properties": {"name": f"{name}: failed flights, status {code}", "status": code,
                        "message": run.status_codes.get(code, "unknown"), "count": len(points)}}
        for code, points in f["failed"].items()
    ]  # fmt: skip
    return {"type": "FeatureCollection", "features": features}


def to_kml(run: Run, levels=SUMMARY_LEVELS) -> str:
    """A KML 2.2 document: the pad, a folder of impact points, one polygon per ellipse."""
    f = map_features(run, levels)
    ElementTree.register_namespace("", KML_NAMESPACE)
    q = lambda tag: f"{{{KML_NAMESPACE}}}{tag}"  # noqa: E731
    kml = ElementTree.Element(q("kml"))
    document = ElementTree.SubElement(kml, q("Document"))
    ElementTree.SubElement(document, q("name")).text = run.attrs.get("campaign_name", "rocketmc campaign")

    def placemark(parent, name, geometry_tag, style=None):
        mark = ElementTree.SubElement(parent, q("Placemark"))
        ElementTree.SubElement(mark, q("name")).text = name
        if style is not None:
            ElementTree.SubElement(mark, q("styleUrl")).text = f"#{style}"
        return ElementTree.SubElement(mark, q(geometry_tag))

    def coordinates(parent, points):
        ElementTree.SubElement(parent, q("coordinates")).text = " ".join(f"{lon:.7f},{lat:.7f},0" for lon, lat in points)

    for i in range(len(f["ellipses"])):  # the schema puts a document's styles before its placemarks
        style = ElementTree.SubElement(document, q("Style"), id=f"ellipse{i}")
        line = ElementTree.SubElement(style, q("LineStyle"))
        ElementTree.SubElement(line, q("color")).text = _KML_COLORS[i % len(_KML_COLORS)]
        ElementTree.SubElement(line, q("width")).text = "2"
        ElementTree.SubElement(ElementTree.SubElement(style, q("PolyStyle")), q("fill")).text = "0"
    coordinates(placemark(document, f"pad ({f['site']})" if f["site"] else "pad", "Point"), [f["pad"]])
    for i, (level, ring) in enumerate(f["ellipses"].items()):
        polygon = placemark(document, f"{100 * level:g} % impact ellipse", "Polygon", style=f"ellipse{i}")
        outer = ElementTree.SubElement(ElementTree.SubElement(polygon, q("outerBoundaryIs")), q("LinearRing"))
        coordinates(outer, ring)
    folder = ElementTree.SubElement(document, q("Folder"))
    ElementTree.SubElement(folder, q("name")).text = f"impact points ({len(f['impacts'])})"
    for k, position in enumerate(f["impacts"]):
        coordinates(placemark(folder, f"impact {k}", "Point"), [position])
    for code, points in f["failed"].items():
        folder = ElementTree.SubElement(document, q("Folder"))
        ElementTree.SubElement(folder, q("name")).text = (f"failed flights, status {code} ({len(points)} landed): "
                                                          f"{run.status_codes.get(code, 'unknown')}")  # fmt: skip
        for k, position in enumerate(points):
            coordinates(placemark(folder, f"failed (status {code}) {k}", "Point"), [position])
    ElementTree.indent(kml)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ElementTree.tostring(kml, encoding="unicode") + "\n"


def to_csv_frame(run: Run):
    """One row per realization: its index, status and every output then input, columns named
    ``name [unit]`` (inputs ``input: dotted path [unit]``); NaN where an event did not happen."""
    def label(name, prefix=""):
        unit = run.units.get(name, "")
        return f"{prefix}{name}" + (f" [{unit}]" if unit else "")

    outputs = run.outputs.drop(columns="status").rename(columns=label)
    inputs = run.inputs.rename(columns=lambda name: label(name, "input: "))
    frame = outputs.join(inputs) if len(inputs.columns) else outputs
    frame.insert(0, "status", run.outputs["status"].to_numpy())
    return frame


def write_csv(run: Run, path: str | Path) -> Path:
    """Write :func:`to_csv_frame` to ``path`` (written under a temporary name and renamed)."""
    with replacing(path) as partial:
        to_csv_frame(run).to_csv(partial, index_label="realization")
    return Path(path)


def write_map(run: Run, path: str | Path) -> Path:
    """Write ``to_kml`` (``.kml``) or ``to_geojson`` (``.geojson``/``.json``) by the file's suffix."""
    path = Path(path)
    if path.suffix.lower() not in MAP_SUFFIXES:
        raise ValueError(f"{path}: expected a .kml or .geojson file name")
    with replacing(path) as partial:
        partial.write_text(to_kml(run) if path.suffix.lower() == ".kml" else json.dumps(to_geojson(run), indent=1))
    return path
