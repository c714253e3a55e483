"""Measured flight logs and what they say about the flight, on the host (numpy, pandas, scipy).

A log is four sensor streams on a nominal time axis ``t_s`` = sample × period [s], sample 0 at
liftoff (no per-sample timestamps exist). The built-in log is Skyward's Lynx at Roccaraso,
18 Sept 2021 (``data/flights/roccaraso_2021``, see SOURCE.md there). Body axes are FRD, x toward
the nose; velocities are NED; altitudes are metres above the pad, from the barometer.
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from ..env.atmosphere import pressure_height_m
from ..env.site import north_east_m

ROCCARASO_2021 = resources.files("rocketmc") / "data" / "flights" / "roccaraso_2021"

# stream -> (file, sample period [s], {CSV column: column here}) for the Lynx log layout
_STREAMS = {
    "imu": ("imu_bmx160_50hz.csv", 0.020, {
        "acc_x_mps2": "accel_x_mps2", "acc_y_mps2": "accel_y_mps2", "acc_z_mps2": "accel_z_mps2",
        "gyro_x_radps": "gyro_x_radps", "gyro_y_radps": "gyro_y_radps", "gyro_z_radps": "gyro_z_radps",
        "mag_x": "mag_x_ut", "mag_y": "mag_y_ut", "mag_z": "mag_z_ut"}),
    "baro": ("baro_ms5803_66hz.csv", 0.015, {"pressure_pa": "pressure_pa"}),
    "pitot": ("pitot_42hz.csv", 0.024, {"static_pressure_pa": "static_pressure_pa", "airspeed_mps": "airspeed_mps"}),
    "gnss": ("gps_neom9n_25hz.csv", 0.040, {
        "lat_deg": "latitude_deg", "lon_deg": "longitude_deg", "vel_north_mps": "v_north_mps",
        "vel_east_mps": "v_east_mps", "vel_down_mps": "v_down_mps", "num_sats": "satellites"}),
}  # fmt: skip

SMOOTHING_WINDOW_S = 1.0
"""Savitzky–Golay window (quadratic) of the baro vertical speed: 67 samples at 66.7 Hz take the
~1 m altitude noise of one sample down to ~0.45 m/s."""
SPIKE_MPS2 = 30.0
"""|Specific force| [m/s²] of a deployment or impact shock (~3 g). In the Roccaraso log the coast
stays below 15, the steady descent below 21 (drogue) and 16 (main)."""
APOGEE_HALF_WINDOW_S = 1.0
"""Half-width [s] of the parabola fit around the highest baro sample before the drogue."""
EVENT_MARGIN_S = 0.1
"""The apogee fit ends this long [s] before the drogue shock (its pressure transient starts ~30 ms early)."""
DROGUE_SETTLE_S = 10.0
"""Time [s] after the drogue shock before the descent is steady: the rocket's own horizontal
velocity (~20 m/s at apogee) decays with τ ≈ (descent rate)/g ≈ 2.6 s."""
MAIN_SETTLE_S = 5.0
"""Time [s] after the main shock before the descent is steady (τ ≈ 0.6 s, shocks last ~1 s)."""
MAIN_MARGIN_S = 1.0
"""The drogue descent window ends this long [s] before the main shock."""
LANDING_MARGIN_S = 2.0
"""The main descent window ends this long [s] before the landing shock."""
WIND_BIN_M = 100.0
"""Altitude bin [m] of the wind profile: 4 s of GNSS under the drogue, ~18 s under the main."""
WIND_MIN_SAMPLES = 25
"""Bins with fewer GNSS samples (1 s) are left out of the wind profile."""


@dataclass(frozen=True)
class Site:
    """Launch pad: latitude, longitude [deg, WGS84] and altitude above mean sea level [m]."""

    name: str
    latitude_deg: float
    longitude_deg: float
    altitude_m: float


ROCCARASO_SITE = Site("Roccaraso", 41.8087, 14.0543, 1416.0)


@dataclass(frozen=True)
class FlightLog:
    """Measured streams, each a DataFrame with ``t_s`` [s] and SI columns.

    ``imu``: ``accel_{x,y,z}_mps2`` (specific force, body), ``gyro_{x,y,z}_radps``,
    ``mag_{x,y,z}_ut`` (µT, scale uncertain); ``baro``: ``pressure_pa``; ``pitot``:
    ``static_pressure_pa``, ``airspeed_mps``; ``gnss``: ``latitude_deg``, ``longitude_deg``,
    ``v_{north,east,down}_mps``, ``satellites``.
    """

    imu: pd.DataFrame
    baro: pd.DataFrame
    pitot: pd.DataFrame
    gnss: pd.DataFrame
    site: Site
    description: str


def read_stream(path: Traversable, period_s: float | None, columns: dict[str, str],
                 optional: tuple[str, ...] = ()) -> pd.DataFrame:  # fmt: skip
    """One CSV stream as ``t_s`` = the first ``t_nominal_s`` + sample × period [s] plus ``columns`` renamed;
    errors name the file. ``period_s`` None: the span of ``t_nominal_s`` / (rows − 1); ``optional``: columns
    that may hold no number (a simulated log's satellite count)."""
    if not path.is_file():
        raise FileNotFoundError(f"{path}: flight log file not found")
    try:
        with path.open("r") as f:
            raw = pd.read_csv(f)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: not a CSV table ({e})") from None
    needed = ["sample", "t_nominal_s", *columns]
    if missing := [c for c in needed if c not in raw]:
        raise ValueError(f"{path}: missing columns {', '.join(missing)}")
    values = raw[needed].apply(pd.to_numeric, errors="coerce")
    required = [c for c in needed if c not in optional]
    if not np.isfinite(values[required].to_numpy(dtype=float)).all():
        raise ValueError(f"{path}: every row needs finite numbers in {', '.join(required)}")
    if not np.array_equal(values["sample"], np.arange(len(values))):
        raise ValueError(f"{path}: sample must count 0, 1, 2, ... without gaps")
    first = float(values["t_nominal_s"].iloc[0]) if len(values) else 0.0
    if period_s is None:
        if len(values) < 2:
            raise ValueError(f"{path}: two samples or more needed for the period")
        period_s = (float(values["t_nominal_s"].iloc[-1]) - first) / (len(values) - 1)
    t_s = first + values["sample"].to_numpy() * period_s
    if not np.allclose(values["t_nominal_s"], t_s, rtol=0.0, atol=1e-3):
        raise ValueError(f"{path}: t_nominal_s is not {first} s + sample × {period_s} s")
    return pd.concat([pd.Series(t_s, name="t_s"), values[list(columns)].rename(columns=columns)], axis=1)


def read_flight_log(directory: str | os.PathLike | Traversable, site: Site, description: str) -> FlightLog:
    """The four streams of a log in the Lynx layout (file names and columns as in SOURCE.md)."""
    root = Path(directory) if isinstance(directory, (str, os.PathLike)) else directory
    streams = {name: read_stream(root / file, period, columns) for name, (file, period, columns) in _STREAMS.items()}
    return FlightLog(**streams, site=site, description=description)


def read_pitot_static(directory: str | os.PathLike | Traversable) -> pd.DataFrame:
    """The pitot's static port of a log in the Lynx layout (``pitot_42hz.csv``'s ``static_pressure_pa``) as a
    barometer stream: ``t_s`` = the first sample's time + sample × period [s], the period from ``t_nominal_s``, and
    ``pressure_pa`` [Pa] (its own level: the real log's reads 3050 Pa above the MS5803 on the pad and after landing)."""
    root = Path(directory) if isinstance(directory, (str, os.PathLike)) else directory
    return read_stream(root / _STREAMS["pitot"][0], None, {"static_pressure_pa": "pressure_pa"})


def load_roccaraso_2021() -> FlightLog:
    """The Lynx flight at Roccaraso, 18 Sept 2021, vendored in ``data/flights/roccaraso_2021``."""
    return read_flight_log(ROCCARASO_2021, ROCCARASO_SITE, "Skyward Lynx, Roccaraso, 18 Sept 2021: Cesaroni "
                           "L1350, airbrakes, drogue at apogee, main below ~350 m AGL (measured log)")  # fmt: skip


def pressure_altitude_agl_m(pressure_pa, pad_pressure_pa):
    """Geometric height [m] of the ISA troposphere level at ``pressure_pa`` above the one at ``pad_pressure_pa``."""
    return pressure_height_m(np.asarray(pressure_pa, dtype=float), float(pad_pressure_pa))


@dataclass(frozen=True)
class FlightReduction:
    """What a log says about the flight: times [s] from liftoff, altitudes [m] above the pad.

    Series: ``altitude`` (``t_s, altitude_agl_m, vertical_speed_mps``, barometer, up positive,
    distorted during the boost; ISA pressure heights, which fall short of geometric ones by T/T_ISA
    on a day warmer than the ISA), ``axial_specific_force`` (``t_s, specific_force_mps2``, IMU x),
    ``airspeed`` (``t_s, airspeed_mps``, pitot), ``gnss_velocity`` (``t_s, v_north_mps,
    v_east_mps, v_down_mps``).
    Events: burnout where the axial specific force (thrust − drag)/m turns negative; apogee at the
    vertex of a parabola through the baro altitude around its maximum before the drogue shock;
    drogue, main and landing at the first |specific force| above ``SPIKE_MPS2`` after burnout,
    after the drogue has settled and after the main has settled. ``landing_agl_m`` is the ground's
    baro altitude after landing.
    Descent rates [m/s, down positive] are the mean baro vertical speed over ``drogue_window_s``
    (``DROGUE_SETTLE_S`` after the drogue shock to ``MAIN_MARGIN_S`` before the main shock) and
    ``main_window_s`` (``MAIN_SETTLE_S`` after the main shock to ``LANDING_MARGIN_S`` before
    landing). ``landing_north_m``, ``landing_east_m``: GNSS landing point from the site's
    coordinates. ``wind_profile``: (altitude_agl_m, speed_mps, from_deg) from the mean GNSS
    horizontal velocity in the two windows per ``WIND_BIN_M`` altitude bin, altitude increasing.
    """

    altitude: pd.DataFrame
    axial_specific_force: pd.DataFrame
    airspeed: pd.DataFrame
    gnss_velocity: pd.DataFrame
    burnout_time_s: float
    max_axial_specific_force_mps2: float
    max_axial_specific_force_time_s: float
    max_airspeed_mps: float
    max_airspeed_time_s: float
    apogee_time_s: float
    apogee_agl_m: float
    drogue_time_s: float
    main_time_s: float
    landing_time_s: float
    landing_agl_m: float
    drogue_window_s: tuple[float, float]
    main_window_s: tuple[float, float]
    drogue_descent_rate_mps: float
    main_descent_rate_mps: float
    landing_north_m: float
    landing_east_m: float
    wind_profile: tuple[np.ndarray, np.ndarray, np.ndarray]


def _first_index(t: np.ndarray, hit: np.ndarray, after: float, what: str) -> int:
    """Index of the first sample later than ``after`` [s] where ``hit``; ValueError naming ``what``."""
    k = np.flatnonzero(hit & (t > after))
    if k.size == 0:
        raise ValueError(f"flight log: no {what} after t = {after:.2f} s")
    return int(k[0])


def _apogee(t: np.ndarray, altitude: np.ndarray, before: float) -> tuple[float, float]:
    """(time [s], altitude [m]) of the vertex of a least-squares parabola through the altitude
    within ``APOGEE_HALF_WINDOW_S`` of its highest sample before ``before``."""
    k = int(np.argmax(np.where(t < before, altitude, -np.inf)))
    window = (t < before) & (np.abs(t - t[k]) <= APOGEE_HALF_WINDOW_S)
    a, b, c = np.polyfit(t[window] - t[k], altitude[window], 2)
    t_top = t[k] - b / (2.0 * a)
    if not (a < 0.0 and t[window][0] <= t_top <= t[window][-1]):
        raise ValueError(f"flight log: no apogee vertex in the baro samples {t[window][0]:.2f}–{t[window][-1]:.2f} s")
    return float(t_top), float(c - b * b / (4.0 * a))


def _wind_profile(gnss: pd.DataFrame, altitude: pd.DataFrame, windows) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(altitude_agl_m, speed_mps, from_deg): the mean GNSS horizontal velocity per altitude bin within
    the time ``windows``; the altitude of a bin is the mean of its samples'."""
    t = gnss["t_s"].to_numpy()
    under = np.logical_or.reduce([(t >= start) & (t <= end) for start, end in windows])
    h = np.interp(t[under], altitude["t_s"], altitude["altitude_agl_m"])
    samples = pd.DataFrame({"h": h, "north": gnss["v_north_mps"].to_numpy()[under],
                            "east": gnss["v_east_mps"].to_numpy()[under]})  # fmt: skip
    bins = samples.groupby(np.floor(h / WIND_BIN_M))
    mean = bins.mean()[bins.size() >= WIND_MIN_SAMPLES]
    from_deg = np.degrees(np.arctan2(-mean["east"], -mean["north"])) % 360.0
    return mean["h"].to_numpy(), np.hypot(mean["north"], mean["east"]).to_numpy(), from_deg.to_numpy()


def reduce_flight(log: FlightLog) -> FlightReduction:
    """Events, maxima, descent rates, landing point and wind of a measured flight (see FlightReduction).

    The pad pressure is baro sample 0, the only one on the pad: the log starts at liftoff, and the
    next samples already carry ignition and rail transients (up to +17 Pa, 1.4 m).
    """
    t_imu = log.imu["t_s"].to_numpy()
    axial = log.imu["accel_x_mps2"].to_numpy()
    accel = log.imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()
    spike = np.linalg.norm(accel, axis=1) > SPIKE_MPS2
    k = _first_index(t_imu, axial < 0.0, 0.0, "burnout (axial specific force below zero)")
    burnout = float(t_imu[k - 1] + (t_imu[k] - t_imu[k - 1]) * axial[k - 1] / (axial[k - 1] - axial[k]))
    k_max = int(np.argmax(np.where(t_imu <= burnout, axial, -np.inf)))
    drogue = float(t_imu[_first_index(t_imu, spike, burnout, "drogue shock")])
    main = float(t_imu[_first_index(t_imu, spike, drogue + DROGUE_SETTLE_S, "main shock")])
    landing = float(t_imu[_first_index(t_imu, spike, main + MAIN_SETTLE_S, "landing shock")])

    t_baro = log.baro["t_s"].to_numpy()
    pressure = log.baro["pressure_pa"].to_numpy()
    height = pressure_altitude_agl_m(pressure, pressure[0])
    period = t_baro[1] - t_baro[0]
    vertical_speed = savgol_filter(height, int(round(SMOOTHING_WINDOW_S / period)) | 1, 2, deriv=1, delta=period)
    altitude = pd.DataFrame({"t_s": t_baro, "altitude_agl_m": height, "vertical_speed_mps": vertical_speed})
    apogee_time, apogee_agl = _apogee(t_baro, height, drogue - EVENT_MARGIN_S)
    drogue_window = (drogue + DROGUE_SETTLE_S, main - MAIN_MARGIN_S)
    main_window = (main + MAIN_SETTLE_S, landing - LANDING_MARGIN_S)

    def descent_rate(start, end):
        return -float(vertical_speed[(t_baro >= start) & (t_baro <= end)].mean())

    t_pitot = log.pitot["t_s"].to_numpy()
    k_air = int(np.argmax(np.where(t_pitot < drogue, log.pitot["airspeed_mps"], -np.inf)))
    landing_north, landing_east = (float(x) for x in north_east_m(
        *(np.interp(landing, log.gnss["t_s"], log.gnss[c]) for c in ("latitude_deg", "longitude_deg")),
        log.site.latitude_deg, log.site.longitude_deg,
    ))  # fmt: skip
    return FlightReduction(
        altitude=altitude,
        axial_specific_force=pd.DataFrame({"t_s": t_imu, "specific_force_mps2": axial}),
        airspeed=log.pitot[["t_s", "airspeed_mps"]].copy(),
        gnss_velocity=log.gnss[["t_s", "v_north_mps", "v_east_mps", "v_down_mps"]].copy(),
        burnout_time_s=burnout,
        max_axial_specific_force_mps2=float(axial[k_max]),
        max_axial_specific_force_time_s=float(t_imu[k_max]),
        max_airspeed_mps=float(log.pitot["airspeed_mps"].iloc[k_air]),
        max_airspeed_time_s=float(t_pitot[k_air]),
        apogee_time_s=apogee_time,
        apogee_agl_m=apogee_agl,
        drogue_time_s=drogue,
        main_time_s=main,
        landing_time_s=landing,
        landing_agl_m=float(np.median(height[t_baro > landing + LANDING_MARGIN_S])),
        drogue_window_s=drogue_window,
        main_window_s=main_window,
        drogue_descent_rate_mps=descent_rate(*drogue_window),
        main_descent_rate_mps=descent_rate(*main_window),
        landing_north_m=landing_north,
        landing_east_m=landing_east,
        wind_profile=_wind_profile(log.gnss, altitude, (drogue_window, main_window)),
    )


def write_wind_profile_csv(path: str | os.PathLike, profile, comment: str = "") -> None:
    """Write ``(altitude_agl_m, speed_mps, from_deg)`` arrays as the CSV that
    ``rocketmc.env.wind.read_wind_profile`` reads, after an optional ``#`` comment line."""
    with open(path, "w", newline="") as f:
        if comment:
            f.write(f"# {comment}\n")
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(["altitude_agl_m", "speed_mps", "from_deg"])
        writer.writerows([f"{h:.1f}", f"{v:.2f}", f"{d:.1f}"] for h, v, d in zip(*profile))
