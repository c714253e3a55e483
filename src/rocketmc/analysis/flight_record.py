"""One flight's full time series (``rocketmc fly``): a campaign's nominal flight, or its realization I bit for bit
as a campaign run flies it, with what the model computes at each period start.

The flight is ``sim.flight.fly``, the step every campaign flies, on ``campaign.runner.LANES`` vmapped lanes that
all hold it, its parameters made inside the vmap from the realization's index as the runner makes them: the same
vector code, hence the same bits (one unbatched flight differs from the campaign's row by ulps, seen: 1e-12 m at
impact). Its summary is ``flight_summary`` of the state at the end of the first block of ``block_steps`` periods
at which the flight is done, where the runner stops it.

Sample k is the state at the start of period k (the first at t = 0 at rest on the rail), with ``sim.loads.loads``
there: the gust and canard deflections of the period starting at that instant, i.e. its first RK4 stage. The
periods are the flight's own (``control_dt_s``, longer in steady descent under canopy). Positions along the rocket
(CG, centre of pressure) are distances from the nose tip [m], angles in degrees, everything else SI.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple
from xml.etree import ElementTree

import h5py
import jax
import jax.numpy as jnp
import numpy as np
import pandas as pd

from .. import __version__
from ..aero.stability import centre_of_pressure_at
from ..campaign import Campaign
from ..campaign.fingerprint import fingerprint, setup
from ..campaign.model import flight_params
from ..campaign.runner import LANES, realization_params, sim_settings
from ..campaign.sampling import realization_key
from ..dynamics.servo import deflection_at
from ..env import G0
from ..env.site import latitude_longitude_deg
from ..files import replacing, replacing_hdf5
from ..sim.flight import flight_done, fly, initial_state, period_gust
from ..sim.loads import loads
from ..sim.outputs import DEPLOY_TIME_SUFFIX, Metric, flight_summary, metric
from ..sim.state import Status
from .export import KML_NAMESPACE

OUT_SUFFIXES = (".csv", ".h5")


def _kept(state):
    """The part of a ``FlightState`` the record keeps: all but the sensors' and the navigation filters' state."""
    gnc = None if state.gnc is None else dataclasses.replace(state.gnc, navigation=None)
    return dataclasses.replace(state, avionics=None, gnc=gnc)


def _deflections(p, state):
    """The canard deflections at the period start [rad]: the servos' with their offsets, or neutral."""
    if p.gnc is None:
        return jnp.zeros(p.rocket.aero.n_canards)
    return deflection_at(p.gnc.servo, state.gnc.servo, 0.0)


def _at_start(p, state):
    """What the model computes at the start of the period beginning at ``state`` (SI, body FRD / NED)."""
    _, _, gust = period_gust(p, state)
    deflections = _deflections(p, state)
    f = loads(state.t, state.body, p, deflections, gust, state.events)
    cp_x = centre_of_pressure_at(p.rocket.aero, f.air, f.mass.cg_x)
    return {
        "loads": f, "deflections": deflections,
        # u/V = cos α cos β for α = atan2(w, u), β = asin(v/V): the body axis against the air-relative velocity
        "total_alpha": jnp.arccos(jnp.clip(jnp.cos(f.air.alpha) * jnp.cos(f.air.beta), -1.0, 1.0)),
        "cp_x": cp_x,
        "static_margin": (f.mass.cg_x - cp_x) / p.rocket.aero.reference_length_m,
        "aero_power": state.body.q_nb.rotate(f.aero_force_b).dot(state.body.v_n),
    }  # fmt: skip


def _power_at_end(p, start, end):
    """The aerodynamic force's power [W] at the end of the period from ``start`` to ``end``, with that period's
    gust and the events at its start (as its RK4 stages saw them)."""
    _, _, gust = period_gust(p, start)
    f = loads(end.t, end.body, p, _deflections(p, end), gust, start.events)
    return end.body.q_nb.rotate(f.aero_force_b).dot(end.body.v_n)


_compiled: dict = {}


def _flight_function(campaign: Campaign, nominal: bool):
    """The compiled flight: index -> (samples, end-of-period powers, per-period summaries, statuses, done flags),
    kept per campaign set-up."""
    key = fingerprint(setup(campaign)), nominal
    if key in _compiled:
        return _compiled[key]
    settings = sim_settings(campaign)
    longest = math.ceil(settings.max_time_s / settings.control_dt_s)  # periods last at least control_dt_s
    n_periods = -(-longest // settings.block_steps) * settings.block_steps
    master = jax.random.key(campaign.config.seed)

    def params_of(index):
        if nominal:  # ``campaign.nominal_params``, with the index traced as the runner's
            return flight_params(campaign, campaign.nominal, realization_key(master, index))
        return realization_params(campaign, master, index)[0]

    def lane(index):
        p = params_of(index)
        record = lambda s: (_kept(s), *flight_summary(p, s), flight_done(settings, s))  # noqa: E731
        return fly(p, settings, n_periods, record=record)[1]

    def flown(index):
        states, summaries, statuses, done = jax.tree_util.tree_map(
            lambda x: x[0], jax.vmap(lane)(jnp.full(LANES, index, dtype=jnp.uint32)))  # fmt: skip
        p = params_of(index)
        states = jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a[None], b]), _kept(initial_state(p)), states)
        first = jax.tree_util.tree_map(lambda x: x[:-1], states)
        then = jax.tree_util.tree_map(lambda x: x[1:], states)
        samples = jax.vmap(lambda s: _at_start(p, s))(states)
        power_end = jax.vmap(lambda a, b: _power_at_end(p, a, b))(first, then)
        jumps = jnp.stack([jnp.asarray(a, dtype=float) for a in p.environment.wind.jump_altitudes_m()] or [jnp.zeros(0)])
        return states, samples, power_end, summaries, statuses, done, jumps.ravel()

    _compiled.clear()  # one flight function at a time: each holds ~15 000 periods' buffers
    _compiled[key] = jax.jit(flown)
    return _compiled[key]


@dataclass(frozen=True)
class FlightRecord:
    """One flight: ``series`` (a DataFrame, one row per period start, columns named as ``units``' keys), the units
    and meanings of its columns, its ``flight_summary`` (host floats, the campaign row's bits) and status code,
    ``aero_power_end_w``: the aerodynamic force's power at the end of each period but the last, with that
    period's gust [W], and ``wind_jumps_m``, the heights above the pad where the mean wind jumps [m] (both for
    ``energy_balance``), and the campaign and realization (None: the nominal flight)."""

    campaign: Campaign
    realization: int | None
    series: pd.DataFrame
    columns: dict[str, Metric]
    summary: dict[str, float]
    status: int
    aero_power_end_w: np.ndarray
    wind_jumps_m: np.ndarray

    @property
    def label(self) -> str:
        which = "nominal flight" if self.realization is None else f"realization {self.realization}"
        return f"{self.campaign.config.name}, {which}"


def check_realization(campaign: Campaign, realization: int | None, option: str = "--realization") -> None:
    """ValueError naming ``option`` unless ``realization`` is None (the nominal flight) or one of ``campaign``."""
    n = campaign.config.n_realizations
    if realization is not None and not 0 <= realization < n:
        raise ValueError(f"{option} {realization}: not a realization of {campaign.config.name} (0 to {n - 1})")


def flight_record(campaign: Campaign, realization: int | None = None) -> FlightRecord:
    """The ``FlightRecord`` of ``campaign``'s nominal flight (its undispersed values and realization 0's
    turbulence noise, ``campaign.nominal_params``) or of realization ``realization``. ValueError for a realization
    outside the campaign."""
    check_realization(campaign, realization)
    run = _flight_function(campaign, realization is None)
    states, samples, power_end, summaries, statuses, done, jumps = jax.tree_util.tree_map(
        np.asarray, run(np.uint32(realization or 0)))  # fmt: skip
    steps = sim_settings(campaign).block_steps
    block_ends = np.arange(steps - 1, len(done), steps)
    end = block_ends[np.argmax(done[block_ends])]  # the runner's last block
    summary = {k: float(v[end]) for k, v in summaries.items()}
    status = int(statuses[end])
    impact = summary["impact_time_s"]
    t = states.t
    last = end + 1 if math.isnan(impact) else int(np.argmax(t >= impact))  # samples through impact
    keep = slice(0, last + 1)
    series, columns = _series(campaign, jax.tree_util.tree_map(lambda x: x[keep], states),
                              jax.tree_util.tree_map(lambda x: x[keep], samples), summary)  # fmt: skip
    return FlightRecord(campaign, realization, series, columns, summary, status, power_end[:last], jumps)


def _series(campaign: Campaign, states, samples, summary) -> tuple[pd.DataFrame, dict[str, Metric]]:
    """The time-series columns (name -> array) and their ``Metric``s from the sampled states and loads (numpy)."""
    rocket = campaign.config.rocket
    nose = rocket.from_nose(rocket.reference_point_m)  # the body origin's distance from the nose tip [m]
    body, f = states.body, samples["loads"]
    air, mass = f.air, f.mass
    yaw, pitch, roll = (np.degrees(np.asarray(a)) for a in body.q_nb.to_euler())
    deg = np.degrees
    columns: dict[str, tuple[np.ndarray, str, str]] = {
        "time": (states.t, "s", "time since the start on the rail (ignition at rocket.motor.ignition_delay_s)"),
        "north": (body.r_n.x, "m", "CG north of the pad"),
        "east": (body.r_n.y, "m", "CG east of the pad"),
        "altitude": (-body.r_n.z, "m", "CG altitude above the pad"),
        "v_north": (body.v_n.x, "m/s", "CG velocity north"),
        "v_east": (body.v_n.y, "m/s", "CG velocity east"),
        "v_down": (body.v_n.z, "m/s", "CG velocity down"),
        "speed": (np.sqrt(body.v_n.x**2 + body.v_n.y**2 + body.v_n.z**2), "m/s", "CG speed over ground"),
        **{f"q_{c}": (getattr(body.q_nb, c), "1", f"attitude quaternion q_nb, {c} component (scalar first)")
           for c in "wxyz"},
        "yaw": (yaw, "deg", "3-2-1 Euler yaw, clockwise from north"),
        "pitch": (pitch, "deg", "3-2-1 Euler pitch, above the horizon"),
        "roll": (roll, "deg", "3-2-1 Euler roll"),
        "p": (deg(body.omega_b.x), "deg/s", "body roll rate (FRD x)"),
        "q": (deg(body.omega_b.y), "deg/s", "body pitch rate (FRD y)"),
        "r": (deg(body.omega_b.z), "deg/s", "body yaw rate (FRD z)"),
        "airspeed": (air.airspeed, "m/s", "speed relative to the air (mean wind and gust)"),
        "alpha": (deg(air.alpha), "deg", "angle of attack atan2(w, u) of the air-relative velocity"),
        "beta": (deg(air.beta), "deg", "sideslip asin(v/V) of the air-relative velocity"),
        "total_alpha": (deg(samples["total_alpha"]), "deg", "angle between the body axis and the air-relative velocity"),
        "mach": (air.mach, "1", "Mach number"),
        "dynamic_pressure": (air.qbar, "Pa", "dynamic pressure ½ρV²"),
        "density": (air.density, "kg/m^3", "air density (the campaign's atmosphere)"),
        "thrust": (f.thrust_n, "N", "motor thrust along the body axis"),
        **{f"aero_force_{a}": (getattr(f.aero_force_b, a), "N", f"aerodynamic force, body {a} (FRD)") for a in "xyz"},
        **{f"chute_force_{n}": (getattr(f.chute_force_n, a), "N", f"parachutes' force, {n}")
           for a, n in zip("xyz", ("north", "east", "down"))},
        **{f"moment_{a}": (getattr(f.moment_b, a), "N·m", f"moment of all forces about the CG, body {a} (FRD)")
           for a in "xyz"},
        "mass": (mass.mass, "kg", "mass, propellant included"),
        "cg": (nose - mass.cg_x, "m", "centre of mass from the nose tip"),
        "ixx": (mass.ixx, "kg·m^2", "axial moment of inertia about the CG"),
        "iyy": (mass.iyy, "kg·m^2", "transverse moment of inertia about the CG"),
        "cp": (nose - samples["cp_x"], "m", "centre of pressure from the nose tip: x_ref + d·Cmα/CNα at the flight's "
               "Mach, small angle"),
        "static_margin": (samples["static_margin"], "cal", "static margin (CP − CG)/d, d the reference length"),
        "mechanical_energy": (0.5 * mass.mass * (body.v_n.x**2 + body.v_n.y**2 + body.v_n.z**2) - mass.mass * G0 * body.r_n.z,
                              "J", "½mV² + m·g0·altitude of the CG"),
        "aero_power": (samples["aero_power"], "W", "power of the aerodynamic force on the CG's motion, F·v"),
    }  # fmt: skip
    if states.gnc is not None:
        for i in range(samples["deflections"].shape[1]):
            columns[f"canard_{i + 1}"] = (deg(samples["deflections"][:, i]), "deg", f"canard {i + 1} deflection, offset included")
        for a, name in zip("xyz", ("yaw", "pitch", "roll")):
            columns[f"command_{name}"] = (deg(getattr(states.gnc.command, a)), "deg", f"virtual {name} command held")
        for a, name in zip("xyz", ("p", "q", "r")):
            columns[f"integrator_{name}"] = (deg(getattr(states.gnc.integrators, a)), "deg",
                                             f"LQI rate-error integrator e_{name}")  # fmt: skip
    frame = pd.DataFrame({name: np.asarray(v[0], dtype=float) for name, v in columns.items()})
    frame["phase"] = _phases(campaign, frame["time"].to_numpy(), summary)
    units = {name: Metric(unit, meaning) for name, (_, unit, meaning) in columns.items()}
    units["phase"] = Metric("-", "rail, powered, coast, the last parachute deployed, landed")
    return frame, units


def _phases(campaign: Campaign, t, summary) -> np.ndarray:
    """The flight phase at each time ``t`` [s] from the summary's event times."""
    phase = np.full(t.shape, "rail", dtype=object)
    marks = [("powered", summary["rail_exit_time_s"]), ("coast", summary["burnout_time_s"])]
    marks += [(c.name, summary[c.name + DEPLOY_TIME_SUFFIX]) for c in campaign.config.rocket.parachutes]
    marks += [("landed", summary["impact_time_s"])]
    for name, time in sorted((m for m in marks if not math.isnan(m[1])), key=lambda m: m[1]):
        phase[t >= time] = name
    return phase


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
    RK4 nor the trapezoid is accurate (seen: 11 J of the 12 J difference over the lynx_nominal coast).

    tolerance: the trapezoid's error, h³/12·|P''| per period, with P'' from the differences of neighbouring
    periods' secant slopes, doubled (that estimate is itself an estimate); RK4's own error, O(h⁵) per step, and
    rounding (1e-16 of ~10⁵ J) are far below."""
    s, t = record.series, record.series["time"].to_numpy()
    first = int(np.argmax(t >= record.summary["burnout_time_s"]))
    last = int(np.nonzero(t <= record.summary["apogee_time_s"])[0][-1])
    h = np.diff(t[first : last + 1])
    start = s["aero_power"].to_numpy()[first:last]
    end = record.aero_power_end_w[first:last]
    slope = (end - start) / h
    curvature = np.gradient(slope, np.cumsum(h) - 0.5 * h)
    altitude = s["altitude"].to_numpy()[first : last + 1]
    low, high = np.minimum(altitude[:-1], altitude[1:]), np.maximum(altitude[:-1], altitude[1:])
    smooth = ~np.any((low[:, None] <= record.wind_jumps_m) & (record.wind_jumps_m <= high[:, None]), axis=1)
    energy = np.diff(s["mechanical_energy"].to_numpy()[first : last + 1])
    work = 0.5 * h * (start + end)
    tolerance = 2.0 * float(np.sum((h**3 / 12.0 * np.abs(curvature))[smooth]))
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
        _write_columns(f.create_group("series"), record.series, record.columns)
        for name, value in record.summary.items():
            data = f.create_dataset(f"summary/{name}", data=value)
            data.attrs.update({"unit": metric(name).unit, "description": metric(name).meaning})
    return path


def _write_columns(group: h5py.Group, series: pd.DataFrame, columns: dict[str, Metric]) -> None:
    """Each column of ``series`` as a dataset of ``group`` (strings as bytes) with ``unit`` and ``description``."""
    for name, m in columns.items():
        values = series[name].to_numpy()
        data = group.create_dataset(name, data=values.astype("S") if values.dtype == object else values)
        data.attrs.update({"unit": m.unit, "description": m.meaning})


TRAJECTORY_RULE = ("the flight record's series (rocketmc fly --realization I) decimated: the first sample in each "
                   "interval_s-long bin of time [k*interval_s, (k+1)*interval_s) and the last (at or after impact)")
"""What ``/trajectories`` of a result file holds (its ``description`` attribute)."""


def decimate(series: pd.DataFrame, interval_s: float) -> pd.DataFrame:
    """The rows of ``series`` that are the first in each ``interval_s``-long bin of time [k·S, (k+1)·S) [s], and
    its last row: at most t_end/S + 2 rows, every row when the periods are longer than S."""
    bins = np.floor(series["time"].to_numpy() / interval_s)
    keep = np.diff(bins, prepend=-1.0) > 0
    keep[-1] = True
    return series[keep].reset_index(drop=True)


def write_trajectories(group: h5py.Group, campaign: Campaign, realizations, interval_s: float) -> None:
    """Fly each of ``realizations`` of ``campaign`` (``flight_record``, the campaign's bits) and write its series,
    ``decimate``d to ``interval_s`` [s], to ``group/<index>``: one dataset per column in the series' order, with
    ``unit`` and ``description``; the flight's ``status``, ``status_message`` and ``samples`` (before decimation)
    as the subgroup's attributes; ``TRAJECTORY_RULE`` as the group's ``description``."""
    group.attrs["description"] = TRAJECTORY_RULE
    for index in realizations:
        record = flight_record(campaign, index)
        g = group.create_group(str(index), track_order=True)
        g.attrs.update({"status": record.status, "status_message": Status(record.status).message,
                        "samples": len(record.series)})  # fmt: skip
        _write_columns(g, decimate(record.series, interval_s), record.columns)


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
