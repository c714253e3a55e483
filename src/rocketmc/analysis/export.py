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
from ..ellipse import confidence_ellipse
from .results import SUMMARY_LEVELS, ResultFileError, Run

KML_NAMESPACE = "http://www.opengis.net/kml/2.2"
MAP_SUFFIXES = (".kml", ".geojson", ".json")
_ELLIPSE_POINTS = 120
_KML_COLORS = ("ff00a5ff", "ff0000ff", "ff800080")  # aabbggrr: orange, red, purple for 50/95/99 %
_MARKER_COLORS = {"ok": "#1f77b4", "failed": "#000000"}  # impact points by status: the figure's blue, black
_KML_MARKER_COLORS = {"ok": "ffb4771f", "failed": "ff000000"}  # the same in aabbggrr


def site_of(run: Run) -> tuple[str, float, float]:
    """(name, latitude [deg], longitude [deg]) of the run's launch site, from its validated campaign (the set-up's
    config: a campaign that extends another may not name its site in its own text), else from its campaign text."""
    try:
        config = json.loads(run.attrs["setup"])["config"] if "setup" in run.attrs else tomllib.loads(run.attrs["campaign_toml"])
        site = config["site"]
        return site.get("name") or "", float(site["latitude_deg"]), float(site["longitude_deg"])
    except (KeyError, json.JSONDecodeError, tomllib.TOMLDecodeError, TypeError, ValueError):
        raise ResultFileError("the result file's campaign has no [site] latitude_deg/longitude_deg") from None


def map_features(run: Run, levels=SUMMARY_LEVELS) -> dict:
    """The pad, the impact points and the ``levels`` ellipses as lists of (longitude, latitude) [deg]:
    ``{"site": name, "pad": (lon, lat), "impacts": [flight, ...], "ellipses": {level: ring},
    "failed": {status code: [flight, ...]}}``, the failed flights that landed apart, per status; each flight
    ``{"index": realization, "status": code, "message": its text, "apogee_m": apogee above the pad [m] or None,
    "position": (lon, lat)}``. Ellipses from the ok points only; each ring closed (last point = first) and
    counterclockwise seen from above."""
    name, lat0, lon0 = site_of(run)
    north, east = run.ok_impacts()
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
    apogee = run.outputs["apogee_agl_m"].to_numpy(float) if "apogee_agl_m" in run.outputs else np.full(len(status), np.nan)

    def flights(where):
        lat, lon = latitude_longitude_deg(*run.ok_impacts(where), lat0, lon0)
        return [{"index": int(i), "status": int(status[i]), "message": run.status_codes.get(int(status[i]), "unknown"),
                 "apogee_m": float(apogee[i]) if np.isfinite(apogee[i]) else None, "position": position}
                for i, position in zip(np.flatnonzero(where), zip(lon.tolist(), lat.tolist()))]  # fmt: skip

    failed = {code: flights(run.has_impact & (status == code)) for code in sorted(set(status[~run.ok].tolist()))}
    return {"site": name, "pad": (lon0, lat0), "impacts": flights(run.landed), "ellipses": ellipses, "failed": failed}


def _signed_area(ring) -> float:
    """Shoelace area of an open ring in (x, y); positive when counterclockwise."""
    x, y = np.asarray(ring).T
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _description(flight: dict) -> str:
    """One line on a map's impact point: realization, status and apogee [m]."""
    apogee = "no apogee" if flight["apogee_m"] is None else f"apogee {flight['apogee_m']:.0f} m above the pad"
    return f"realization {flight['index']}, status {flight['status']} ({flight['message']}), {apogee}"


def _kind(flight: dict) -> str:
    """``"ok"`` or ``"failed"``: the style of a flight's impact point."""
    return "ok" if flight["status"] == 0 else "failed"


def to_geojson(run: Run, levels=SUMMARY_LEVELS) -> dict:
    """A GeoJSON FeatureCollection: the pad, one Polygon per ellipse, then one Point per flight that landed
    (the ok ones, then the failed ones per status) with ``index``, ``status``, ``message`` and ``apogee_m``
    [m above the pad, null when none] as properties and a simplestyle ``marker-color`` by status."""
    f = map_features(run, levels)
    name = run.attrs.get("campaign_name", "")
    features = [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": list(f["pad"])},
         "properties": {"name": f"pad ({f['site']})" if f["site"] else "pad"}},
    ] + [
        {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [[list(p) for p in ring]]},
         "properties": {"name": f"{name}: {100 * level:g} % impact ellipse", "level": level}}
        for level, ring in f["ellipses"].items()
    ] + [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": list(flight["position"])},
         "properties": {"name": f"impact {flight['index']}", "description": _description(flight),
                        **{key: flight[key] for key in ("index", "status", "message", "apogee_m")},
                        "marker-color": _MARKER_COLORS[_kind(flight)]}}
        for flight in [*f["impacts"], *(flight for flights in f["failed"].values() for flight in flights)]
    ]  # fmt: skip
    return {"type": "FeatureCollection", "features": features}


def to_kml(run: Run, levels=SUMMARY_LEVELS) -> str:
    """A KML 2.2 document: the pad, one polygon per ellipse, a folder of the ok impact points and one per failed
    status; each point named ``impact <realization>``, described (status, apogee [m]) with ``index``,
    ``status`` and ``apogee_m`` as ExtendedData, styled ``#ok`` or ``#failed``."""
    f = map_features(run, levels)
    ElementTree.register_namespace("", KML_NAMESPACE)
    q = lambda tag: f"{{{KML_NAMESPACE}}}{tag}"  # noqa: E731
    kml = ElementTree.Element(q("kml"))
    document = ElementTree.SubElement(kml, q("Document"))
    ElementTree.SubElement(document, q("name")).text = run.attrs.get("campaign_name", "rocketmc campaign")

    def placemark(parent, name, geometry_tag, style=None, flight=None):
        mark = ElementTree.SubElement(parent, q("Placemark"))
        ElementTree.SubElement(mark, q("name")).text = name
        if flight is not None:
            ElementTree.SubElement(mark, q("description")).text = _description(flight)
        if style is not None:
            ElementTree.SubElement(mark, q("styleUrl")).text = f"#{style}"
        if flight is not None:
            data = ElementTree.SubElement(mark, q("ExtendedData"))
            for key in ("index", "status", "apogee_m"):
                value = "" if flight[key] is None else str(flight[key])  # repr: the float read back exactly
                ElementTree.SubElement(ElementTree.SubElement(data, q("Data"), name=key), q("value")).text = value
        return ElementTree.SubElement(mark, q(geometry_tag))

    def coordinates(parent, points):
        ElementTree.SubElement(parent, q("coordinates")).text = " ".join(f"{lon:.7f},{lat:.7f},0" for lon, lat in points)

    for i in range(len(f["ellipses"])):  # the schema puts a document's styles before its placemarks
        style = ElementTree.SubElement(document, q("Style"), id=f"ellipse{i}")
        line = ElementTree.SubElement(style, q("LineStyle"))
        ElementTree.SubElement(line, q("color")).text = _KML_COLORS[i % len(_KML_COLORS)]
        ElementTree.SubElement(line, q("width")).text = "2"
        ElementTree.SubElement(ElementTree.SubElement(style, q("PolyStyle")), q("fill")).text = "0"
    for kind, color in _KML_MARKER_COLORS.items():
        icon = ElementTree.SubElement(ElementTree.SubElement(document, q("Style"), id=kind), q("IconStyle"))
        ElementTree.SubElement(icon, q("color")).text = color
        ElementTree.SubElement(icon, q("scale")).text = "0.6"
    coordinates(placemark(document, f"pad ({f['site']})" if f["site"] else "pad", "Point"), [f["pad"]])
    for i, (level, ring) in enumerate(f["ellipses"].items()):
        polygon = placemark(document, f"{100 * level:g} % impact ellipse", "Polygon", style=f"ellipse{i}")
        outer = ElementTree.SubElement(ElementTree.SubElement(polygon, q("outerBoundaryIs")), q("LinearRing"))
        coordinates(outer, ring)
    folder = ElementTree.SubElement(document, q("Folder"))
    ElementTree.SubElement(folder, q("name")).text = f"impact points ({len(f['impacts'])})"
    for flight in f["impacts"]:
        coordinates(placemark(folder, f"impact {flight['index']}", "Point", _kind(flight), flight), [flight["position"]])
    for code, flights in f["failed"].items():
        folder = ElementTree.SubElement(document, q("Folder"))
        ElementTree.SubElement(folder, q("name")).text = (f"failed flights, status {code} ({len(flights)} landed): "
                                                          f"{run.status_codes.get(code, 'unknown')}")  # fmt: skip
        for flight in flights:
            coordinates(placemark(folder, f"impact {flight['index']}", "Point", "failed", flight), [flight["position"]])
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
