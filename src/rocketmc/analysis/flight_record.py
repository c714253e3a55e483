"""What is made of one flight's record (``campaign.flights.FlightRecord``, ``rocketmc fly``): its coast's energy
balance, the time series written as CSV or HDF5, its path as KML, its events, and the summary printed."""

from __future__ import annotations

import math
from pathlib import Path
from typing import NamedTuple
from xml.etree import ElementTree

import numpy as np
import pandas as pd

from ..runtime import __version__
from ..campaign.flights import FlightRecord
from ..campaign.store import write_columns
from ..env.site import latitude_longitude_deg
from ..files import replacing, replacing_hdf5
from ..sim.outputs import DEPLOY_TIME_SUFFIX, metric
from ..sim.state import Status
from .export import KML_NAMESPACE

OUT_SUFFIXES = (".csv", ".h5")


class EnergyBalance(NamedTuple):
    """The coast's energy balance (``energy_balance``): the window [s], the periods compared in it and those left
    out (a wind jump inside), the change of ½mV² + m·g0·h over the periods compared [J], the aerodynamic force's
    work over them [J] and the bound on their difference from the integration [J]."""

    start_s: float
    end_s: float
    periods: int
    left_out: int
    energy_change_j: float
    work_j: float
    tolerance_j: float


def energy_balance(record: FlightRecord) -> EnergyBalance:
    """The change of mechanical energy over the coast's periods (from the first period start at or after burnout
    to the last before apogee: constant mass, no thrust, no canopy, so d(½mV² + m·g0·h)/dt = F_aero·v exactly)
    against the aerodynamic work, each period integrated by the trapezoid rule from its two ends with its own gust.
    Periods that cross a height where the mean wind jumps are left out: the power jumps inside them, where neither
    RK4 nor the trapezoid is accurate (seen: 11 J of the 12 J difference over the lynx_nominal coast); so are their
    slopes from the curvature (a period that ends just past a jump, ``sim.flight.event_period``, has a steep one).

    tolerance: the trapezoid's error, h³/12·|P''| per period, with P'' from the differences of neighbouring
    periods' secant slopes, doubled (that estimate is itself an estimate); RK4's own error, O(h⁵) per step, and
    rounding (1e-16 of ~10⁵ J) are far below. With air brakes moving, each period start holds a new command, so the
    power's slope jumps there and the curvature from neighbouring periods underestimates the trapezoid's error
    (lynx_euroc_airbrakes' nominal flight: 33 J against a 25 J estimate, 6e-5 of the coast's work)."""
    s, t = record.series, record.series["time"].to_numpy()
    first = int(np.argmax(t >= record.summary["burnout_time_s"]))
    last = int(np.nonzero(t <= record.summary["apogee_time_s"])[0][-1])
    h = np.diff(t[first : last + 1])
    start = s["aero_power"].to_numpy()[first:last]
    end = record.aero_power_end_w[first:last]
    altitude = s["altitude"].to_numpy()[first : last + 1]
    low, high = np.minimum(altitude[:-1], altitude[1:]), np.maximum(altitude[:-1], altitude[1:])
    smooth = ~np.any((low[:, None] <= record.wind_jumps_m) & (record.wind_jumps_m <= high[:, None]), axis=1)
    slope = (end - start) / h  # the curvature from the smooth periods' slopes: a jump's would poison its neighbours'
    curvature = np.gradient(slope[smooth], (np.cumsum(h) - 0.5 * h)[smooth])
    energy = np.diff(s["mechanical_energy"].to_numpy()[first : last + 1])
    work = 0.5 * h * (start + end)
    tolerance = 2.0 * float(np.sum(h[smooth] ** 3 / 12.0 * np.abs(curvature)))
    return EnergyBalance(float(t[first]), float(t[last]), int(smooth.sum()), int((~smooth).sum()),
                         float(energy[smooth].sum()), float(work[smooth].sum()), tolerance)  # fmt: skip


def write_series(record: FlightRecord, path: str | Path) -> Path:
    """Write the time series as CSV (a header of ``name [unit]`` columns) or HDF5 (``/series/<name>`` with
    ``unit`` and ``description`` attributes, ``/summary/<metric>`` likewise, the campaign text, realization
    (-1: the nominal flight), status and version as root attributes), by the file's suffix."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in OUT_SUFFIXES:
        raise ValueError(f"{path}: expected a {' or '.join(OUT_SUFFIXES)} file name")
    if suffix == ".csv":
        frame = record.series.rename(columns={k: f"{k} [{m.unit}]" for k, m in record.columns.items()})
        with replacing(path) as partial:
            frame.to_csv(partial, index=False, lineterminator="\n", float_format="%.17g")
        return path
    with replacing_hdf5(path) as f:
        f.attrs.update({"campaign_name": record.campaign.config.name, "campaign_toml": record.campaign.text,
                        "realization": -1 if record.realization is None else record.realization,
                        "status": record.status, "status_message": Status(record.status).message,
                        "rocketmc_version": __version__})  # fmt: skip
        write_columns(f.create_group("series"), record.series, record.columns)
        for name, value in record.summary.items():
            data = f.create_dataset(f"summary/{name}", data=value)
            data.attrs.update({"unit": metric(name).unit, "description": metric(name).meaning})
    return path


def trajectory_kml(record: FlightRecord) -> str:
    """A KML 2.2 document of the flight: its path (altitude above mean sea level, WGS84 through the site's
    tangent plane) and a placemark at each event."""
    site = record.campaign.config.site
    s = record.series
    lat, lon = latitude_longitude_deg(s["north"].to_numpy(), s["east"].to_numpy(), site.latitude_deg, site.longitude_deg)
    altitude = site.altitude_m + s["altitude"].to_numpy()
    ElementTree.register_namespace("", KML_NAMESPACE)
    q = lambda tag: f"{{{KML_NAMESPACE}}}{tag}"  # noqa: E731
    kml = ElementTree.Element(q("kml"))
    document = ElementTree.SubElement(kml, q("Document"))
    ElementTree.SubElement(document, q("name")).text = record.label
    style = ElementTree.SubElement(document, q("Style"), id="path")
    line = ElementTree.SubElement(style, q("LineStyle"))
    ElementTree.SubElement(line, q("color")).text = "ff0000ff"
    ElementTree.SubElement(line, q("width")).text = "3"

    def placemark(name, tag, points, style_url=None):
        mark = ElementTree.SubElement(document, q("Placemark"))
        ElementTree.SubElement(mark, q("name")).text = name
        if style_url:
            ElementTree.SubElement(mark, q("styleUrl")).text = style_url
        geometry = ElementTree.SubElement(mark, q(tag))
        ElementTree.SubElement(geometry, q("altitudeMode")).text = "absolute"
        ElementTree.SubElement(geometry, q("coordinates")).text = " ".join(
            f"{x:.7f},{y:.7f},{z:.1f}" for x, y, z in points)  # fmt: skip

    placemark("flight path", "LineString", zip(lon, lat, altitude), "#path")
    for name, time in events(record):
        i = min(int(np.searchsorted(s["time"].to_numpy(), time)), len(s) - 1)
        placemark(f"{name} ({time:.2f} s)", "Point", [(lon[i], lat[i], altitude[i])])
    ElementTree.indent(kml)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ElementTree.tostring(kml, encoding="unicode") + "\n"


def write_kml(record: FlightRecord, path: str | Path) -> Path:
    """Write ``trajectory_kml`` to ``path``."""
    path = Path(path)
    with replacing(path) as partial:
        partial.write_text(trajectory_kml(record))
    return path


def events(record: FlightRecord) -> list[tuple[str, float]]:
    """(name, time [s]) of the flight's events that happened, in time order."""
    s = record.summary
    marks = [("rail exit", s["rail_exit_time_s"]), ("burnout", s["burnout_time_s"]), ("apogee", s["apogee_time_s"])]
    marks += [(f"{c.name} deployed", s[c.name + DEPLOY_TIME_SUFFIX]) for c in record.campaign.config.rocket.parachutes]
    marks += [("impact", s["impact_time_s"])]
    return sorted(((n, t) for n, t in marks if not math.isnan(t)), key=lambda m: m[1])


def _at(record: FlightRecord, column: str, time: float) -> float:
    """``column`` at the sample nearest ``time`` [s]."""
    t = record.series["time"].to_numpy()
    return float(record.series[column].to_numpy()[int(np.argmin(np.abs(t - time)))])


def ascent(record: FlightRecord) -> pd.DataFrame:
    """The samples from rail exit to apogee."""
    s, m = record.series, record.summary
    return s[(s["time"] >= m["rail_exit_time_s"]) & (s["time"] <= m["apogee_time_s"])]


def format_record(record: FlightRecord) -> str:
    """A printed summary in the spirit of RocketPy's ``Flight.all_info()``."""
    c, m, s = record.campaign.config, record.summary, record.series
    site, launch = c.site, c.launch
    lines = [f"{record.label}: {Status(record.status).message} ({len(s)} samples, {s['time'].iloc[-1]:.2f} s)",
             f"  site {site.name or ''} {site.latitude_deg:.4f}° N {site.longitude_deg:.4f}° E, {site.altitude_m:g} m "
             f"above sea level; rail {launch.rail_length_m:g} m at {launch.elevation_deg:g}° toward {launch.azimuth_deg:g}°",
             f"  mass {s['mass'].iloc[0]:.3f} kg at liftoff, {s['mass'].iloc[-1]:.3f} kg dry; CG {s['cg'].iloc[0]:.3f} m "
             f"→ {s['cg'].iloc[-1]:.3f} m from the nose tip"]  # fmt: skip
    if not math.isnan(m["rail_exit_time_s"]):
        t = m["rail_exit_time_s"]
        lines.append(f"  rail exit     {t:8.3f} s  speed {m['rail_exit_speed_mps']:.2f} m/s, static margin "
                     f"{_at(record, 'static_margin', t):.2f} cal")  # fmt: skip
    if not math.isnan(m["burnout_time_s"]):
        t = m["burnout_time_s"]
        lines.append(f"  burnout       {t:8.3f} s  altitude {m['burnout_altitude_agl_m']:.1f} m, speed "
                     f"{m['burnout_speed_mps']:.1f} m/s, Mach {_at(record, 'mach', t):.3f}")  # fmt: skip
    k, j = int(np.argmax(s["mach"].to_numpy())), int(np.argmax(s["dynamic_pressure"].to_numpy()))
    lines.append(f"  max Mach      {s['time'].iloc[k]:8.3f} s  {m['max_mach']:.4f} (speed {s['airspeed'].iloc[k]:.1f} m/s)")
    lines.append(f"  max q         {s['time'].iloc[j]:8.3f} s  {m['max_dynamic_pressure_pa'] / 1000:.2f} kPa")
    up = ascent(record)
    if len(up):
        margin = up["static_margin"].to_numpy()
        lo, hi = int(np.argmin(margin)), int(np.argmax(margin))
        lines.append(f"  static margin over the ascent: {margin[lo]:.2f} cal (at {up['time'].iloc[lo]:.2f} s, Mach "
                     f"{up['mach'].iloc[lo]:.2f}) to {margin[hi]:.2f} cal (at {up['time'].iloc[hi]:.2f} s); largest total "
                     f"angle of attack {up['total_alpha'].max():.2f}°")  # fmt: skip
    if not math.isnan(m["apogee_time_s"]):
        lines.append(f"  apogee        {m['apogee_time_s']:8.3f} s  {m['apogee_agl_m']:.1f} m above the pad "
                     f"({site.altitude_m + m['apogee_agl_m']:.1f} m above sea level), {m['apogee_north_m']:.1f} m N, "
                     f"{m['apogee_east_m']:.1f} m E")  # fmt: skip
    for chute in c.rocket.parachutes:
        t = m[chute.name + DEPLOY_TIME_SUFFIX]
        if not math.isnan(t):
            lines.append(f"  {chute.name + ' deploys':<14}{t:8.3f} s  altitude {_at(record, 'altitude', t):.1f} m, "
                         f"speed {_at(record, 'speed', t):.1f} m/s")  # fmt: skip
    if not math.isnan(m["impact_time_s"]):
        lines.append(f"  impact        {m['impact_time_s']:8.3f} s  {m['impact_north_m']:.1f} m N, {m['impact_east_m']:.1f} m E "
                     f"({math.hypot(m['impact_north_m'], m['impact_east_m']):.1f} m from the pad), speed "
                     f"{m['impact_speed_mps']:.2f} m/s")  # fmt: skip
        descent = s[s["phase"] == c.rocket.parachutes[-1].name]["v_down"] if c.rocket.parachutes else None
        if descent is not None and len(descent):
            lines.append(f"  descent rate under the {c.rocket.parachutes[-1].name}: {descent.iloc[-1]:.2f} m/s at impact")
    if not (math.isnan(m["burnout_time_s"]) or math.isnan(m["apogee_time_s"])):
        e = energy_balance(record)
        lines.append(f"  energy check, coast {e.start_s:.2f}-{e.end_s:.2f} s ({e.periods} periods, {e.left_out} across a "
                     f"wind jump left out): Δ(½mV² + mgh) {e.energy_change_j / 1e3:.3f} kJ, aerodynamic work "
                     f"{e.work_j / 1e3:.3f} kJ, difference {e.energy_change_j - e.work_j:.3f} J (integration bound "
                     f"{e.tolerance_j:.3f} J)")  # fmt: skip
    return "\n".join(lines)
