"""The navigation filters replayed on a sensor log (``rocketmc navigate``): the real Roccaraso 2021 log or a
simulated one (``rocketmc sensors simulate``), both in ``analysis.sensor_log``'s format.

What: the flight's own filters (``gnc.navigation.filter_step``: the MEKF and the position/velocity Kalman filter,
docs/gnc.md §2-3) run over the log as the avionics would have run them, at the IMU's 50 Hz ticks, and their estimates
compared with what the log measured independently of them: the barometric height, the GNSS velocity and its
direction.

How: on the host (numpy), ``log_ticks`` puts every stream on the IMU's ticks as the avionics bus delivers them in
flight (``sim.flight.step``): at tick t_k the gyroscope's and magnetometer's samples of t_k, the accelerometer's of
t_{k-1} (its sample of the period start, delivered at the period's end), and the barometer's and GNSS's latest
sample when a new one arrived since t_{k-1} (fresh), else none; the log is in the body frame (the mountings are
identity). Liftoff is sensed as in flight, from the accelerometer along x (``navigation.liftoff_sensed``'s
threshold), and stays sensed. The GNSS's latitude and longitude become north and east from the site on its WGS84
tangent plane (``env.site.north_east_m``). Then one ``jax.lax.scan`` of ``filter_step`` over the ticks, compiled
once per filter configuration (``_scan``); the a-posteriori estimates of every tick come back as a DataFrame.

Differences from the flight, each forced by the log: the log has no GNSS altitude, so the GNSS's down position is
never measured (``NO_GNSS_ALTITUDE_STD_M``; its down velocity is, with ``gnss = "all"``); the filters are never idle
(in flight they freeze once a parachute is triggered: here the descent is navigated too); a log starts at liftoff,
so the pad pressure of the barometric height is the mean of the barometer's samples before liftoff is sensed (the
first one or two) and a TRIAD initialisation from pad samples is impossible (ValueError): the attitude at liftoff is
the rail's (``rail_attitude``) or the tilt of the log's first accelerometer sample (``accelerometer_attitude``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..env.atmosphere import isa
from ..env.site import north_east_m
from ..gnc.navigation import LIFTOFF_SPECIFIC_FORCE_MPS2, FilterParams, Measurements, filter_step, initial_filters
from ..math import Quat, Vec3
from ..sim.params import Launch
from .flight_log import pressure_altitude_agl_m
from .plots import RUN_COLORS, save_figure

NO_GNSS_ALTITUDE_STD_M = 1e6
"""The standard deviation [m] given to the GNSS's down position, which the log does not hold: read as the filter's
own last estimate with this spread, its gain is below 1e-6 (the down position's variance stays below ~1e5 m²) and
its innovation a tick's motion, so it moves the estimate by less than a millimetre: not measured."""
SAME_TIME_S = 1e-6
"""Nominal times closer than this [s] are the same instant: ``t_s`` is sample × period in floating point, so a
barometer sample at 4 × 0.015 s and the tick at 3 × 0.020 s differ by rounding only."""
LANDED_SPEED_MPS = 2.0
"""GNSS speed [m/s] below which the rocket is on the ground for good: under the main parachute it descends at
~6 m/s, at rest the receiver's velocity noise is ~0.1 m/s per axis. Landing is after the last GNSS sample faster."""
MIN_HORIZONTAL_SPEED_MPS = 5.0
"""Headings are compared where the GNSS's horizontal speed exceeds this [m/s]: its velocity noise (~0.1 m/s per
axis at rest, more in flight) makes a slower heading uncertain by more than a degree (~0.1/5 rad)."""
FIGURES = ("navigate_height.png", "navigate_velocity.png", "navigate_direction.png", "navigate_attitude.png")
"""The files ``plot_navigation`` writes into its folder."""


@dataclasses.dataclass(frozen=True)
class Ticks:
    """A log on the IMU's ticks: t_s (n,) [s since liftoff]; measurements, ``navigation.Measurements`` of numpy
    arrays (n,) (the GNSS's (n, 6): north, east, 0 [m] from the site, velocity N, E, D [m/s]); moving (n,): liftoff
    sensed at or before the tick."""

    t_s: np.ndarray
    measurements: Measurements
    moving: np.ndarray


def new_samples(values: np.ndarray) -> np.ndarray:
    """True for each sample (rows of ``values``) that differs from the one before: a repeat is the sensor's previous
    sample again (the real log's barometer repeats every 6th: it delivered ~55.6 Hz), not a new measurement."""
    values = np.asarray(values).reshape(len(values), -1)
    return np.r_[True, np.any(values[1:] != values[:-1], axis=1)] if len(values) else np.zeros(0, bool)


def _on_ticks(t_ticks: np.ndarray, t_samples: np.ndarray, new: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(index, fresh) per tick: the latest sample at or before the tick (index −1: none yet) and whether a new
    sample (``new``) arrived since the tick before."""
    latest = np.searchsorted(t_samples, t_ticks + SAME_TIME_S, side="right") - 1
    arrived = np.r_[0, np.cumsum(new)]  # new samples among the first i
    count = arrived[latest + 1]
    return latest, count > np.r_[0, count[:-1]]


def log_ticks(log: Mapping[str, pd.DataFrame], site) -> Ticks:
    """The streams of ``log`` (``sensor_log.read_sensor_log``) as the filters read them at the IMU's ticks (module
    docstring); ``site``: its ``latitude_deg``, ``longitude_deg`` are the origin of north and east."""
    imu, baro, gnss = log["imu"], log["baro"], log["gnss"]
    t = imu["t_s"].to_numpy(dtype=float)
    n = len(t)

    def axes(prefix, suffix=""):
        return np.stack([imu[f"{prefix}_{a}{suffix}"].to_numpy(dtype=float) for a in "xyz"])

    acc, gyro, mag = axes("acc", "_mps2"), axes("gyro", "_radps"), axes("mag")
    force = np.concatenate([np.zeros((3, 1)), acc[:, :-1]], axis=1)  # tick k reads the sample of t_{k-1}
    force_fresh = np.arange(n) > 0
    moving = np.logical_or.accumulate(force_fresh & (force[0] > LIFTOFF_SPECIFIC_FORCE_MPS2))

    pressure = baro["pressure_pa"].to_numpy(dtype=float)
    k_baro, baro_fresh = _on_ticks(t, baro["t_s"].to_numpy(dtype=float), new_samples(pressure))
    north, east = north_east_m(gnss["lat_deg"].to_numpy(dtype=float), gnss["lon_deg"].to_numpy(dtype=float),
                               site.latitude_deg, site.longitude_deg)  # fmt: skip
    fixes = np.column_stack([north, east, np.zeros_like(north),
                             *(gnss[f"vel_{d}_mps"].to_numpy(dtype=float) for d in ("north", "east", "down"))])  # fmt: skip
    k_gnss, gnss_fresh = _on_ticks(t, gnss["t_s"].to_numpy(dtype=float), np.ones(len(fixes), bool))
    true = np.ones(n, bool)
    m = Measurements(
        Vec3(*force), force_fresh, Vec3(*gyro), true, Vec3(*mag), true,
        np.where(k_baro >= 0, pressure[np.maximum(k_baro, 0)], np.nan), baro_fresh & (k_baro >= 0),
        np.where((k_gnss >= 0)[:, None], fixes[np.maximum(k_gnss, 0)], 0.0), gnss_fresh & (k_gnss >= 0),
    )  # fmt: skip
    return Ticks(t, m, moving)


def estimated_mach(v_n: Vec3, down_m, site_altitude_m):
    """The Mach number of the estimated velocity ``v_n`` [m/s, NED] at the estimated position's ``down_m`` [m below
    the pad] in the ISA over a pad ``site_altitude_m`` [m above mean sea level]: its ground speed over the speed of
    sound (the wind, ~10 m/s, moves it by < 0.03)."""
    return v_n.norm() / isa(site_altitude_m - down_m).speed_of_sound


@jax.jit
def _scan(params: FilterParams, q_nb0: Quat, r_n0: Vec3, m: Measurements, t, moving, max_mach, site_altitude_m):
    """The filters' states after each tick, stacked (``filter_step`` over the ticks from ``initial_filters``); a
    barometer sample is withheld (not fresh) while the estimate before its tick is faster than ``max_mach`` [-]."""

    def tick(state, inputs):
        m, t, moving = inputs
        gnss = m.gnss.at[2].set(state.position.r_n.z)  # no GNSS altitude (NO_GNSS_ALTITUDE_STD_M)
        slow = estimated_mach(state.position.v_n, state.position.r_n.z, site_altitude_m) <= max_mach
        m = dataclasses.replace(m, gnss=gnss, pressure_fresh=m.pressure_fresh & slow)
        _, state = filter_step(params, state, m, t, moving, False)
        return state, state

    return jax.lax.scan(tick, initial_filters(params, q_nb0, r_n0), (m, t, moving))[1]


def replay(log: Mapping[str, pd.DataFrame], params: FilterParams, q_nb0: Quat, site,
           r_n0: Vec3 | None = None, barometer_max_mach: float | None = None) -> pd.DataFrame:  # fmt: skip
    """The filters' a-posteriori estimates at each of the log's IMU ticks (module docstring).

    params: the filters (``campaign.model.filter_params``; ``pad_samples`` must be 0: the log starts at liftoff);
    q_nb0: the attitude at liftoff (body FRD → NED; the rail's, ``sim.params.Launch.from_angles``); site: the origin
    of north and east (``latitude_deg``, ``longitude_deg``) and the pad's ``altitude_m`` [m above mean sea level];
    r_n0: the position at liftoff [m, NED from the site] (default: the first GNSS fix's north and east, at the pad's
    height: the barometric heights are the pad's); barometer_max_mach: the barometer's lock-out [-], its samples
    unused while the filter's estimate (of the tick before) is faster (``estimated_mach``: a static port's error
    grows with the dynamic pressure; None: never locked out). The barometer's samples are ``log["baro"]``'s: another
    static source replaces that stream (``flight_log.read_pitot_static``).

    Columns: t_s [s since liftoff]; moving (liftoff sensed); q_w, q_x, q_y, q_z (body → NED) and yaw_deg, pitch_deg,
    roll_deg (3-2-1); north_m, east_m, down_m [m from the site] and height_m (= −down) [m above the pad];
    v_north_mps, v_east_mps, v_down_mps; bias_{x,y,z}_deg_s, the gyro bias [deg/s, body]; the standard deviations
    attitude_std_{x,y,z}_deg (body axes), bias_std_{x,y,z}_deg_s, {north,east,down}_std_m,
    v_{north,east,down}_std_mps (square roots of the covariances' diagonals); pad_pressure_pa (the mean of the
    barometer's samples before liftoff was sensed; NaN before any); failed (a covariance went bad: estimates held);
    rejected_field, rejected_gnss, rejected_baro: the fresh samples the updates' innovation gates rejected so far
    (``FilterParams.field_gate`` etc.; 0 without a gate).
    """
    if params.pad_samples:
        raise ValueError('gnc.filters.initialisation = "pad" needs samples on the pad, and a log starts at liftoff '
                         '(use "rail")')  # fmt: skip
    ticks = log_ticks(log, site)
    if r_n0 is None:
        first = ticks.measurements.gnss[np.argmax(ticks.measurements.gnss_fresh)]
        r_n0 = Vec3(first[0], first[1], 0.0)
    gnss_std = params.position.gnss_position_std._replace(z=jnp.asarray(NO_GNSS_ALTITUDE_STD_M))
    params = dataclasses.replace(params, position=dataclasses.replace(params.position, gnss_position_std=gnss_std))
    r_n0 = Vec3(*(jnp.asarray(c, dtype=float) for c in r_n0))
    max_mach = np.inf if barometer_max_mach is None else float(barometer_max_mach)
    states = jax.tree_util.tree_map(np.asarray, _scan(params, q_nb0, r_n0, ticks.measurements, ticks.t_s, ticks.moving,
                                                      max_mach, float(site.altitude_m)))  # fmt: skip
    att, pos = states.attitude, states.position
    yaw, pitch, roll = (np.degrees(np.asarray(a)) for a in att.q_nb.to_euler())
    attitude_std = np.degrees(np.sqrt(np.diagonal(att.cov, axis1=1, axis2=2)))
    columns = {"t_s": ticks.t_s, "moving": ticks.moving, **{f"q_{c}": getattr(att.q_nb, c) for c in "wxyz"},
               "yaw_deg": yaw, "pitch_deg": pitch, "roll_deg": roll}  # fmt: skip
    for i, d in enumerate(("north", "east", "down")):
        columns[f"{d}_m"] = pos.r_n[i]
    columns["height_m"] = -pos.r_n.z
    for i, d in enumerate(("north", "east", "down")):
        columns[f"v_{d}_mps"] = pos.v_n[i]
    for i, a in enumerate("xyz"):
        columns[f"bias_{a}_deg_s"] = np.degrees(att.bias_b[i])
    for i, a in enumerate("xyz"):
        columns[f"attitude_std_{a}_deg"] = attitude_std[:, i]
    for i, a in enumerate("xyz"):
        columns[f"bias_std_{a}_deg_s"] = attitude_std[:, 3 + i]
    for i, d in enumerate(("north", "east", "down")):
        columns[f"{d}_std_m"] = np.sqrt(pos.p_rr[i])
    for i, d in enumerate(("north", "east", "down")):
        columns[f"v_{d}_std_mps"] = np.sqrt(pos.p_vv[i])
    count = states.pad_pressure_count
    columns["pad_pressure_pa"] = np.where(count > 0, states.pad_pressure_sum / np.maximum(count, 1), np.nan)
    columns["failed"] = states.failed
    for i, sensor in enumerate(("field", "gnss", "baro")):
        columns[f"rejected_{sensor}"] = states.rejected[:, i]
    return pd.DataFrame(columns)


# --- what the log measured independently of the filters, and the comparison ----------------------------------


def barometric_height(log: Mapping[str, pd.DataFrame], pad_pressure_pa: float) -> pd.DataFrame:
    """The barometer's new samples (``new_samples``) as ``t_s`` and ``height_m``, the ISA height above the level of
    ``pad_pressure_pa`` [m] (``flight_log.pressure_altitude_agl_m``)."""
    baro = log["baro"][new_samples(log["baro"]["pressure_pa"].to_numpy())]
    return pd.DataFrame({"t_s": baro["t_s"].to_numpy(),
                         "height_m": pressure_altitude_agl_m(baro["pressure_pa"], pad_pressure_pa)})  # fmt: skip


def velocity_direction_deg(v_north, v_east, v_down) -> tuple[np.ndarray, np.ndarray]:
    """(flight-path angle, heading) [deg] of NED velocities: above the horizon, clockwise from north in [0, 360)."""
    v_north, v_east, v_down = (np.asarray(v, dtype=float) for v in (v_north, v_east, v_down))
    return np.degrees(np.arctan2(-v_down, np.hypot(v_north, v_east))), np.degrees(np.arctan2(v_east, v_north)) % 360.0


def _wrap_deg(angle):
    """Angles [deg] into (−180, 180]."""
    return -((180.0 - np.asarray(angle)) % 360.0 - 180.0)


def _at(nav: pd.DataFrame, t: np.ndarray, column: str) -> np.ndarray:
    """The estimate's ``column`` at times ``t`` [s] (linear between ticks; the GNSS's times are ticks)."""
    return np.interp(t, nav["t_s"], nav[column])


def body_axis_n(nav: pd.DataFrame) -> np.ndarray:
    """(n, 3): the body x axis (toward the nose) in NED of the attitude estimate at each tick (a row of q_nb's
    matrix: x_n = q ⊗ (1, 0, 0) ⊗ q*)."""
    q = Quat(*(nav[f"q_{c}"].to_numpy() for c in "wxyz"))
    one, zero = np.ones(len(nav)), np.zeros(len(nav))
    return np.asarray(q.rotate(Vec3(one, zero, zero)).to_array())


def gnss_comparison(nav: pd.DataFrame, log: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """At each GNSS sample: its velocity's flight-path angle and heading [deg], the estimated velocity's, and the
    angle between the estimated body x axis and the GNSS velocity, body_to_velocity_deg [deg], with the attitude's
    pitch, pitch_deg; horizontal_speed_mps, the GNSS's."""
    gnss = log["gnss"]
    t = gnss["t_s"].to_numpy()
    v = np.column_stack([gnss[f"vel_{d}_mps"].to_numpy(dtype=float) for d in ("north", "east", "down")])
    gamma, heading = velocity_direction_deg(*v.T)
    est_gamma, est_heading = velocity_direction_deg(*(_at(nav, t, f"v_{d}_mps") for d in ("north", "east", "down")))
    axis = np.column_stack([np.interp(t, nav["t_s"], column) for column in body_axis_n(nav).T])
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    speed = np.linalg.norm(v, axis=1)
    cosine = np.clip(np.sum(axis * v, axis=1) / np.where(speed > 0.0, speed, np.nan), -1.0, 1.0)
    return pd.DataFrame({"t_s": t, "gamma_deg": gamma, "heading_deg": heading, "est_gamma_deg": est_gamma,
                         "est_heading_deg": est_heading, "body_to_velocity_deg": np.degrees(np.arccos(cosine)),
                         "pitch_deg": _at(nav, t, "pitch_deg"), "horizontal_speed_mps": np.hypot(v[:, 0], v[:, 1])})  # fmt: skip


def flight_windows(nav: pd.DataFrame, log: Mapping[str, pd.DataFrame]) -> dict[str, tuple[float, float]]:
    """{"coast": (burnout, apogee), "descent": (apogee, landing)} [s since liftoff]: burnout where the axial
    specific force first turns negative after liftoff was sensed (as ``flight_log.reduce_flight``), apogee where
    the GNSS's vertical velocity first turns downward after it (the barometer's highest reading is the drogue's
    ejection transient, 1.4 s later in the real log), landing after the last GNSS sample faster than
    ``LANDED_SPEED_MPS``."""
    imu, gnss = log["imu"], log["gnss"]
    coasting = nav["moving"].to_numpy() & (imu["acc_x_mps2"].to_numpy() < 0.0)
    if not coasting.any():
        raise ValueError("sensor log: no liftoff (acc_x above 2 g) followed by a burnout (acc_x below 0)")
    burnout = float(imu["t_s"].iloc[np.argmax(coasting)])
    t = gnss["t_s"].to_numpy()
    falling = (t > burnout) & (gnss["vel_down_mps"].to_numpy() >= 0.0)
    if not falling.any():
        raise ValueError(f"sensor log: no apogee (the GNSS never descends after the burnout at {burnout:.2f} s)")
    apogee = float(t[np.argmax(falling)])
    speed = np.linalg.norm(gnss[[f"vel_{d}_mps" for d in ("north", "east", "down")]].to_numpy(dtype=float), axis=1)
    fast = np.flatnonzero(speed > LANDED_SPEED_MPS)
    landing = float(t[min(fast[-1] + 1, len(t) - 1)]) if fast.size else float(t[-1])
    return {"coast": (burnout, apogee), "descent": (apogee, landing)}


def pad_pressure(nav: pd.DataFrame) -> float:
    """The pad pressure [Pa] the filters measured heights from (``replay``'s pad_pressure_pa once liftoff is sensed)."""
    return float(nav["pad_pressure_pa"].iloc[-1])


def _rms_max(error) -> tuple[float, float]:
    """(root mean square, maximum magnitude) of ``error``; NaN for none."""
    error = np.asarray(error, dtype=float)
    if not error.size:
        return np.nan, np.nan
    return float(np.sqrt(np.mean(error**2))), float(np.max(np.abs(error)))


def navigation_metrics(nav: pd.DataFrame, log: Mapping[str, pd.DataFrame], windows: Mapping[str, tuple[float, float]],
                       pad_pressure_pa: float | None = None) -> dict[str, float]:  # fmt: skip
    """The estimates against the log's own measurements over each window W of ``windows`` ({W: (start, end)} [s],
    e.g. ``flight_windows``'s), as root mean square and maximum magnitude: the height less the barometric height of
    ``log["baro"]`` above ``pad_pressure_pa`` [Pa] (default: the filters' own, ``pad_pressure``; another static
    source's heights are measured from its own pad level) (``height_{rms,max}_W_m``); the estimated velocity's
    flight-path angle and heading less the GNSS velocity's (``gamma_{rms,max}_W_deg``, ``heading_{rms,max}_W_deg``,
    headings where the GNSS's horizontal speed exceeds ``MIN_HORIZONTAL_SPEED_MPS``); the angle between the
    estimated body axis and the GNSS velocity (``body_to_velocity_{rms,max}_W_deg``); and the mean of the attitude's pitch less the GNSS flight-path angle
    (``pitch_minus_gamma_mean_W_deg``). NaN where a window holds no sample."""
    metrics = {}
    height = barometric_height(log, pad_pressure(nav) if pad_pressure_pa is None else pad_pressure_pa)
    comparison = gnss_comparison(nav, log)
    for name, (start, end) in windows.items():
        h = height[(height["t_s"] >= start) & (height["t_s"] <= end)]
        c = comparison[(comparison["t_s"] >= start) & (comparison["t_s"] <= end)]
        fast = c[c["horizontal_speed_mps"] > MIN_HORIZONTAL_SPEED_MPS]
        errors = {"height": (_at(nav, h["t_s"].to_numpy(), "height_m") - h["height_m"].to_numpy(), "m"),
                  "gamma": (c["est_gamma_deg"] - c["gamma_deg"], "deg"),
                  "heading": (_wrap_deg(fast["est_heading_deg"] - fast["heading_deg"]), "deg"),
                  "body_to_velocity": (c["body_to_velocity_deg"], "deg")}  # fmt: skip
        for quantity, (error, unit) in errors.items():
            metrics[f"{quantity}_rms_{name}_{unit}"], metrics[f"{quantity}_max_{name}_{unit}"] = _rms_max(error)
        pitch_error = (c["pitch_deg"] - c["gamma_deg"]).to_numpy()
        metrics[f"pitch_minus_gamma_mean_{name}_deg"] = float(pitch_error.mean()) if pitch_error.size else np.nan
    return metrics


# --- figures -------------------------------------------------------------------------------------------------


def format_navigation(nav: pd.DataFrame, log: Mapping[str, pd.DataFrame], windows: Mapping[str, tuple[float, float]],
                      params: FilterParams, title: str, static_source: str, barometer_max_mach: float | None) -> str:
    """The replay's report (``rocketmc navigate``): the filters' settings after ``title``, the flight's events as
    sensed, the gates' rejections, the estimated apogee and ``navigation_metrics`` against the log (RMS and max);
    ``static_source`` and ``barometer_max_mach`` as the replay was given them."""
    m = navigation_metrics(nav, log, windows)
    (burnout, apogee), landing = windows["coast"], windows["descent"][1]
    top = int(nav["height_m"].idxmax())
    gnss = "north and east" if params.horizontal_only else "all axes (no altitude in the log)"
    gates = ", ".join(f"{name} {'off' if gate is None else f'{gate:g}'}" for name, gate in
                      (("magnetometer", params.field_gate), ("GNSS", params.gnss_gate), ("barometer", params.altitude_gate)))  # fmt: skip
    lockout = "" if barometer_max_mach is None else f", locked out above Mach {barometer_max_mach:g}"
    lines = [
        f"{title}; GNSS {gnss} from {float(params.gnss_after_s):g} s, barometer {'on' if params.barometer else 'off'} "
        f"({static_source}, σ {float(params.position.altitude_std):g} m{lockout}), field direction σ "
        f"{float(params.attitude.field_direction_std):g}; innovation gates (χ²): {gates}",
        f"  liftoff sensed at {nav['t_s'][nav['moving']].iloc[0]:.2f} s, burnout {burnout:.2f} s, apogee "
        f"{apogee:.2f} s (GNSS), landing {landing:.2f} s; pad pressure {pad_pressure(nav):.1f} Pa",
        f"  rejected by the gates: {nav['rejected_field'].iloc[-1]} magnetometer, {nav['rejected_gnss'].iloc[-1]} "
        f"GNSS and {nav['rejected_baro'].iloc[-1]} barometer samples",
        f"  estimated apogee {nav['height_m'][top]:.1f} m at {nav['t_s'][top]:.2f} s"
        + ("; the covariance failed, estimates held from then" if nav["failed"].any() else ""),
        f"  {'against the log':<46}{'RMS':>8}{'max':>8}",
    ]  # fmt: skip
    rows = [("height − barometric height, coast [m]", "height_{}_coast_m"),
            ("height − barometric height, descent [m]", "height_{}_descent_m"),
            ("flight-path angle − GNSS's, coast [deg]", "gamma_{}_coast_deg"),
            ("heading − GNSS's, coast [deg]", "heading_{}_coast_deg"),
            ("body x axis to GNSS velocity, coast [deg]", "body_to_velocity_{}_coast_deg")]  # fmt: skip
    lines += [f"  {label:<46}{m[key.format('rms')]:>8.2f}{m[key.format('max')]:>8.2f}" for label, key in rows]
    return "\n".join(lines)


def _panels(rows: int, title: str, height: float = 2.6) -> tuple[Figure, np.ndarray]:
    fig = Figure(figsize=(11.0, height * rows + 0.7), layout="constrained")
    fig.suptitle(title)
    return fig, fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]


def _decorate(axes, windows, end_s: float) -> None:
    """Grid, the coast's span shaded and the x axis to ``end_s`` on every panel; a legend on the first."""
    for ax in axes:
        start, stop = windows["coast"]
        ax.axvspan(start, stop, color="0.9", zorder=0, label="coast")
        ax.grid(True, alpha=0.4)
        ax.set_xlim(0.0, end_s)
    axes[-1].set_xlabel("time since liftoff [s]")
    axes[0].legend(fontsize="small", loc="best", framealpha=0.9)


def plot_navigation(runs: Mapping[str, pd.DataFrame], log: Mapping[str, pd.DataFrame],
                    windows: Mapping[str, tuple[float, float]], directory: str | Path, title: str = "",
                    prefix: str = "", heights: Mapping[str, pd.DataFrame] | None = None) -> list[Path]:  # fmt: skip
    """The ``FIGURES`` in ``directory`` (created if need be), each run of ``runs`` ({label: ``replay``'s frame}, in
    its colour) against the log (black): height against the barometric heights ``heights`` ({label:
    ``barometric_height``'s frame}, the first black and the reference of the difference, the others grey; default:
    the log's barometer above the first run's pad pressure), with the difference; velocity N, E, D
    against the GNSS's; the velocity's flight-path angle and heading against the GNSS velocity's, through the coast;
    the attitude's pitch against the GNSS flight-path angle and the angle between the body axis and the GNSS velocity,
    through the coast. File names: ``prefix`` then the ``FIGURES``'. Returns the paths written."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    label = f"{title}: " if title else ""
    if heights is None:
        heights = {"barometer (ISA)": barometric_height(log, pad_pressure(next(iter(runs.values()))))}
    reference = next(iter(heights))
    height = heights[reference]
    end = windows["descent"][1] + 5.0
    colors = dict(zip(runs, RUN_COLORS))
    paths = [directory / f"{prefix}{name}" for name in FIGURES]

    fig, (ax, ax_error) = _panels(2, f"{label}height above the pad", 3.2)
    for name, h in heights.items():
        ax.plot(h["t_s"], h["height_m"], color="black" if name == reference else "0.6", linewidth=1.0, label=name)
    for name, nav in runs.items():
        ax.plot(nav["t_s"], nav["height_m"], color=colors[name], linewidth=1.0, label=name)
        error = _at(nav, height["t_s"].to_numpy(), "height_m") - height["height_m"].to_numpy()
        ax_error.plot(height["t_s"], error, color=colors[name], linewidth=0.7)
    ax.set_ylabel("height [m]")
    ax_error.set_ylabel(f"estimate − {reference} [m]")
    _decorate((ax, ax_error), windows, end)
    save_figure(fig, paths[0])

    gnss = log["gnss"]
    fig, axes = _panels(3, f"{label}velocity (NED)")
    for ax, d in zip(axes, ("north", "east", "down")):
        ax.plot(gnss["t_s"], gnss[f"vel_{d}_mps"], color="black", linewidth=1.0, label="GNSS")
        for name, nav in runs.items():
            ax.plot(nav["t_s"], nav[f"v_{d}_mps"], color=colors[name], linewidth=1.0, label=name)
        ax.set_ylabel(f"v {d} [m/s]")
    _decorate(axes, windows, end)
    save_figure(fig, paths[1])

    coast_end = windows["coast"][1] + 2.0
    fig, axes = _panels(3, f"{label}direction of the velocity")
    for k, (name, nav) in enumerate(runs.items()):
        c = gnss_comparison(nav, log)
        if k == 0:
            axes[0].plot(c["t_s"], c["gamma_deg"], color="black", linewidth=1.0, label="GNSS")
            axes[1].plot(c["t_s"], c["heading_deg"], color="black", linewidth=1.0)
        axes[0].plot(c["t_s"], c["est_gamma_deg"], color=colors[name], linewidth=1.0, label=name)
        axes[1].plot(c["t_s"], c["est_heading_deg"], color=colors[name], linewidth=1.0)
        fast = c["horizontal_speed_mps"] > MIN_HORIZONTAL_SPEED_MPS
        axes[2].plot(c["t_s"], c["est_gamma_deg"] - c["gamma_deg"], color=colors[name], linewidth=0.8,
                     label=f"{name}: flight-path angle")  # fmt: skip
        axes[2].plot(c["t_s"][fast], _wrap_deg(c["est_heading_deg"] - c["heading_deg"])[fast], color=colors[name],
                     linewidth=0.8, linestyle="--", label=f"{name}: heading")  # fmt: skip
    axes[0].set_ylabel("flight-path angle [deg]")
    axes[0].set_ylim(-90.0, 90.0)
    axes[1].set_ylabel("heading [deg]")
    axes[1].set_ylim(0.0, 360.0)
    axes[2].set_ylabel("estimate − GNSS [deg]")
    axes[2].set_ylim(-10.0, 10.0)
    axes[2].legend(fontsize="small", loc="best", framealpha=0.9)
    _decorate(axes, windows, coast_end)
    save_figure(fig, paths[2])

    fig, axes = _panels(2, f"{label}attitude against the GNSS velocity", 3.2)
    for k, (name, nav) in enumerate(runs.items()):
        c = gnss_comparison(nav, log)
        if k == 0:
            axes[0].plot(c["t_s"], c["gamma_deg"], color="black", linewidth=1.0, label="GNSS flight-path angle")
        axes[0].plot(c["t_s"], c["pitch_deg"], color=colors[name], linewidth=1.0, label=f"{name}: pitch")
        axes[1].plot(c["t_s"], c["body_to_velocity_deg"], color=colors[name], linewidth=1.0, label=name)
    axes[0].set_ylabel("[deg]")
    axes[1].set_ylabel("body x to GNSS velocity [deg]")
    axes[1].set_ylim(0.0, 30.0)
    _decorate(axes, windows, coast_end)
    save_figure(fig, paths[3])
    return paths


def rail_attitude(elevation_deg: float, azimuth_deg: float) -> Quat:
    """q_nb on a rail of ``elevation_deg`` above the horizon toward ``azimuth_deg`` (yaw = azimuth, pitch = elevation,
    no roll), as ``sim.params.Launch.from_angles`` sets the flight's."""
    return Launch.from_angles(1.0, math.radians(elevation_deg), math.radians(azimuth_deg)).q_nb0


def accelerometer_attitude(log: Mapping[str, pd.DataFrame], azimuth_deg: float) -> Quat:
    """q_nb at liftoff with the pitch and roll of the log's first accelerometer sample (at rest on the rail, it reads
    "up", g (sin θ, −cos θ sin φ, −cos θ cos φ) in FRD: θ = atan2(f_x, √(f_y² + f_z²)), φ = atan2(−f_y, −f_z)) and
    the yaw ``azimuth_deg`` (the accelerometer cannot see it). The real log's sample 0 reads 83.2° (the thesis's
    rail: 84°), where the campaign's trajectory fit has 79°."""
    f = log["imu"][[f"acc_{a}_mps2" for a in "xyz"]].to_numpy(dtype=float)[0]
    return Quat.from_euler(jnp.asarray(math.radians(azimuth_deg)), jnp.arctan2(f[0], math.hypot(f[1], f[2])),
                           jnp.arctan2(-f[1], -f[2]))  # fmt: skip


def retuned(params: FilterParams, barometer: bool | None = None, gnss: str | None = None,
            gnss_after_s: float | None = None, gnss_std: tuple[float, float] | None = None,
            field_direction_std: float | None = None, gates: bool | None = None,
            barometer_std: float | None = None) -> FilterParams:  # fmt: skip
    """``params`` with the knobs of ``rocketmc navigate`` replaced where given (the fields of ``[gnc.filters]``):
    the barometric height update; the GNSS's axes ("all" or "horizontal"), the time from which its fixes are used
    [s since liftoff] and its standard deviations (position [m], velocity [m/s], the same on every axis); the
    magnetometer's field direction standard deviation [-]; gates False: every innovation gate off (True: the
    campaign's); the barometric height's standard deviation [m]."""
    position, attitude = params.position, params.attitude
    if barometer_std is not None:
        position = dataclasses.replace(position, altitude_std=jnp.asarray(float(barometer_std)))
    if gnss_std is not None:
        position = dataclasses.replace(position, gnss_position_std=Vec3(*(jnp.asarray(float(gnss_std[0])),) * 3),
                                       gnss_velocity_std=Vec3(*(jnp.asarray(float(gnss_std[1])),) * 3))  # fmt: skip
    if field_direction_std is not None:
        attitude = dataclasses.replace(attitude, field_direction_std=jnp.asarray(float(field_direction_std)))
    if gates is False:
        params = dataclasses.replace(params, field_gate=None, gnss_gate=None, altitude_gate=None)
    return dataclasses.replace(
        params, attitude=attitude, position=position,
        barometer=params.barometer if barometer is None else barometer,
        horizontal_only=params.horizontal_only if gnss is None else gnss == "horizontal",
        gnss_after_s=params.gnss_after_s if gnss_after_s is None else jnp.asarray(float(gnss_after_s)),
    )  # fmt: skip
