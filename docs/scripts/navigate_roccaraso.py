"""The navigation filters replayed on the real Roccaraso 2021 log (the navigation's acceptance): ``python
docs/scripts/navigate_roccaraso.py`` replays the log (``analysis.replay``, as ``rocketmc navigate``) with the site,
rail and [gnc.filters] tuning of data/campaigns/lynx_roccaraso_2021.toml (the thesis's tuning) and the variants of
``TUNINGS``, prints the estimates against the log's barometric height and GNSS velocity per window, and writes
docs/figures/roccaraso_navigate_*.png (``SHOWN``).

Two static pressures: the MS5803 barometer in the avionics bay (the log's barometer) and the pitot's static port
(``flight_log.read_pitot_static``). ``static_sources`` prints each one's height (against its own pad pressure) beside
the GNSS's down velocity integrated, and each one's rise from t to apogee beside two bounds that use neither: the
physics' (after burnout the rocket decelerates upward at g or more, so it still rises ≥ ½ g (t_apogee − t)²) and the
IMU's (its axial specific force along the GNSS flight-path angle, plus −g, integrated back from zero vertical speed
at apogee; geometric metres, also divided by ``WARM_DAY``). Every run's height is compared with both static sources,
each above its own pad pressure.

Windows (``replay.flight_windows``, seconds since liftoff): the coast from burnout to apogee, the descent from
apogee to landing, and the coast from ``REFERENCES_SETTLED_S``: before it both references are distorted (SOURCE.md:
the MS5803 from 2 to 5 s, by the flow over the avionics bay near Mach 0.6; the GNSS velocity's direction is
visibly wrong until ~4.5 s, its receiver catching up after the 8 g boost: the flight-path angle dips to 50°).

The as-flown tuning (``AS_FLOWN``): the real avionics' parts, each value's reason beside it. It lives here, not in
the campaign's [gnc.filters]: a campaign with a [gnc] section designs the canard controller's gains when it loads,
and the 2021 Lynx had no canards (ConfigError), so lynx_roccaraso_2021 cannot carry one. Its runs start from the
attitude of the log's first accelerometer sample (``replay.accelerometer_attitude``: 83.2° above the horizon, where
the campaign's trajectory fit has 79°). The body axis is compared with the GNSS velocity and with the air velocity,
the GNSS velocity less the wind measured under the canopies (the campaign's profile, at the estimated height).
"""

from __future__ import annotations

from importlib import resources
import dataclasses
import math
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from rocketmc.analysis import replay
from rocketmc.analysis.flight_log import ROCCARASO_2021, load_roccaraso_2021, read_pitot_static, reduce_flight
from rocketmc.analysis.sensor_log import high_frequency_noise, read_sensor_log
from rocketmc.campaign import load_campaign
from rocketmc.campaign.schema import PositionFilterConfig
from rocketmc.campaign.model import filter_params
from rocketmc.env.atmosphere import pressure_height_m
from rocketmc.math import Vec3

ROOT = Path(__file__).parents[2]
G0 = 9.80665  # m/s²
REFERENCES_SETTLED_S = 5.0
WARM_DAY = 1.036
"""Geometric height over ISA pressure height [-] on the day (T/T_ISA): the GNSS Doppler's drogue descent rate over
the MS5803's (docs/validation.md, the Roccaraso flight: air ~10 K warmer than the ISA); the IMU's rises are divided
by it to compare with the static sources' pressure heights."""
GNSS_STD = (5.0, 0.5)  # m, m/s: the NEO-M9N's open-sky accuracy, rounded up (its 0.05 m/s CEP is for still air)
TUNINGS = {
    "thesis, barometer off": {"barometer": False},
    "thesis, barometer on": {"barometer": True},
    "σ_b 200, barometer on": {"barometer": True, "field_direction_std": 200.0},
    "σ_b 200, baro, GNSS 5 m 0.5 m/s": {"barometer": True, "field_direction_std": 200.0, "gnss_after_s": 0.0,
                                        "gnss_std": GNSS_STD},
    "σ_b 200, baro, GNSS horizontal": {"barometer": True, "field_direction_std": 200.0, "gnss_after_s": 0.0,
                                       "gnss_std": GNSS_STD, "gnss": "horizontal"},
}  # fmt: skip
"""Label → ``replay.retuned``'s knobs over the thesis's tuning (GNSS on every axis but altitude, 500 m and 50 m/s
from 10.5 s, field direction σ_b 2); σ_b 200: the magnetometer all but ignored, the gyroscope trusted."""
NAS_BAROMETER_R_PA2 = 4.37
"""Skyward's NAS (2021) barometer update: a static pressure measurement through the ISA with R = 4.37 Pa²
(docs/gnc.md §3; boardcore's ``NAS::correctBaro`` innovates in pascals)."""
PAD_PRESSURE_PA = 85_690.0  # the MS5803's, as the replay takes it (printed by ``main``)
AS_FLOWN_ALTITUDE_STD_M = float(pressure_height_m(PAD_PRESSURE_PA - math.sqrt(NAS_BAROMETER_R_PA2), PAD_PRESSURE_PA))
"""The NAS's barometer σ as a height [m] at the pad (√4.37 Pa over ρg there: 0.20 m; 0.23 m at apogee, the air
thinner): the filters update with the barometric height, in metres."""
BAROMETER_STD_SWEEP_M = (0.1, 0.2, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0)  # the as-flown pitot-static runs (5: the schema)
SCHEMA_ALTITUDE_STD_M = PositionFilterConfig.model_fields["altitude_std_m"].default  # [m]: the thesis's part's 50 Pa
AS_FLOWN_KNOBS = {"barometer": True, "barometer_std": AS_FLOWN_ALTITUDE_STD_M, "gnss": "all", "gnss_after_s": 0.0,
                  "gnss_std": GNSS_STD, "field_direction_std": 1e4}  # fmt: skip
"""The as-flown tuning's [gnc.filters] knobs through ``replay.retuned``: the barometer (MS5803) on, at the NAS's
σ (``AS_FLOWN_ALTITUDE_STD_M``); the NEO-M9N's fixes from liftoff (it had 16 satellites on the pad) on every axis
the log holds (its down velocity too: Skyward's avionics used north and east only for the GNSS's poor altitude,
which the log lacks) at GNSS_STD; the magnetometer all but ignored (σ_b 1e4): its field reads 25 µT where the model
has 45 µT, its dip 65° against the model dipole's 60.7° (whose declination is 16° off IGRF-13's), and a sphere fit of
the flight's samples puts a ~2 µT hard-iron offset on it, so its direction is 5-10° off and the MEKF would follow
that."""
AS_FLOWN_ATTITUDE = {
    "gyro_noise": math.radians(0.1),  # σ_v [rad/s/√s]: the BMX160's 0.007 °/s/√Hz, ×15 for vibration, scale factor
    "bias_walk": math.radians(0.01),  # σ_u [rad/s²/√s]: its bias stays within 0.2 °/s over the flight (landed mean)
    "initial_attitude_std": math.radians(5.0),  # [rad]: the rail's azimuth, fitted on a 5° grid
    "initial_bias_std": math.radians(0.5),  # [rad/s]: at rest after landing it reads 0.16, 0.06, 0.03 °/s
}
GATES = {"field_gate": None, "gnss_gate": 20.1, "altitude_gate": 8.8}  # the 99.7 % χ² quantiles: 6 and 1 dof
LOCKOUT_MACH = 0.5
"""The barometer's lock-out above this estimated Mach number [-] (``replay.replay``'s barometer_max_mach): a static
port's error grows with the dynamic pressure (½ γ p M²: 17.5 % of the static pressure at Mach 0.5); the Lynx peaks
near Mach 0.6 at burnout."""
SHOWN = ("thesis, barometer on", "as flown", "as flown, pitot static", "as flown, pitot static, GNSS horizontal")
ROWS = {
    "height − MS5803 [m]": "height_{}_{}_m",
    "height − pitot static [m]": "pitot_height_{}_{}_m",
    "flight-path angle − GNSS [deg]": "gamma_{}_{}_deg",
    "heading − GNSS [deg]": "heading_{}_{}_deg",
    "body x to GNSS velocity [deg]": "body_to_velocity_{}_{}_deg",
}


def as_flown(params, **gates):
    """``params`` with the as-flown tuning (``AS_FLOWN_KNOBS``, ``AS_FLOWN_ATTITUDE``) and ``gates`` [-]."""
    params = replay.retuned(params, **AS_FLOWN_KNOBS)
    attitude = dataclasses.replace(params.attitude, **{k: jnp.asarray(v) for k, v in AS_FLOWN_ATTITUDE.items()})
    return dataclasses.replace(params, attitude=attitude, **gates)


def body_to_air_velocity_deg(nav, log, wind: pd.DataFrame) -> pd.DataFrame:
    """At each GNSS sample: t_s and the angle [deg] between the estimated body x axis and the air velocity, the GNSS
    velocity less the wind (``wind``: altitude_agl_m, speed_mps, from_deg) at the estimated height."""
    c = replay.gnss_comparison(nav, log)
    gnss = log["gnss"]
    v = np.column_stack([gnss[f"vel_{d}_mps"].to_numpy(dtype=float) for d in ("north", "east", "down")])
    height = np.interp(c["t_s"], nav["t_s"], nav["height_m"])
    speed = np.interp(height, wind["altitude_agl_m"], wind["speed_mps"])
    toward = np.radians(np.interp(height, wind["altitude_agl_m"], wind["from_deg"])) + np.pi
    air = v - np.column_stack([speed * np.cos(toward), speed * np.sin(toward), np.zeros_like(speed)])
    axis = np.column_stack([np.interp(c["t_s"], nav["t_s"], column) for column in replay.body_axis_n(nav).T])
    cosine = np.sum(axis * air, axis=1) / np.linalg.norm(axis, axis=1) / np.linalg.norm(air, axis=1)
    return pd.DataFrame({"t_s": c["t_s"], "angle_deg": np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))})


def static_sources(log, pitot_log, apogee_s: float) -> None:
    """Print the two static sources' heights [m] (each above its first sample, ``replay.barometric_height``) against
    the GNSS's down velocity integrated (trapezoids from 0 at liftoff), and their rises to ``apogee_s`` [s] against
    the physics' and the IMU's bounds (module docstring); heights smoothed over 0.5 s (quadratic Savitzky–Golay) for
    the rises, the sources' noise (1-7 m a sample) being no part of the question."""
    sources = {name: replay.barometric_height(lg, lg["baro"]["pressure_pa"].iloc[0])
               for name, lg in (("MS5803", log), ("pitot static", pitot_log))}  # fmt: skip
    ms5803, pitot = ((lg["baro"]["pressure_pa"].iloc[0], lg["baro"][lg["baro"]["t_s"] > 115.0]["pressure_pa"].median())
                     for lg in (log, pitot_log))  # fmt: skip
    print(f"pitot static − MS5803 [Pa]: sample 0 {pitot[0] - ms5803[0]:.1f}, landed (median from 115 s) "
          f"{pitot[1] - ms5803[1]:.1f}")
    gnss, imu = log["gnss"], log["imu"]
    t_g, v_down = gnss["t_s"].to_numpy(), gnss["vel_down_mps"].to_numpy()
    integrated = np.r_[0.0, np.cumsum(-0.5 * (v_down[1:] + v_down[:-1]) * np.diff(t_g))]
    spans = {"boost": (0.0, 3.2), "coast to 5 s": (3.2, 5.0), "coast from 5 s": (5.0, apogee_s),
             "drogue": (30.0, 60.0), "main": (70.0, 100.0), "landed": (110.0, 129.0)}  # fmt: skip
    print("noise per new sample [m] (second differences, robust): " + "; ".join(
        f"{span} " + ", ".join(f"{name} {high_frequency_noise(h, ['height_m'], *spans[span], order=2)['height_m']:.2f}"
                               for name, h in sources.items()) for span in spans))  # fmt: skip
    print("height [m] (0.1 s means): t, " + ", ".join(sources) + ", GNSS down velocity integrated")
    for t in (1.0, 2.0, 3.0, 3.2, 3.4, 3.6, 3.7, 3.8, 3.9, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0, 10.0, 14.0, apogee_s, 30.0,
              60.0, 100.0):  # fmt: skip
        near = [h[(h.t_s >= t - 0.05) & (h.t_s < t + 0.05)].height_m.mean() for h in sources.values()]
        print(f"  {t:6.2f} " + " ".join(f"{h:8.1f}" for h in near) + f" {np.interp(t, t_g, integrated):8.1f}")
    gamma, _ = replay.velocity_direction_deg(*(gnss[f"vel_{d}_mps"] for d in ("north", "east", "down")))
    dt = 0.001
    t = np.arange(apogee_s, 3.0, -dt)  # back from apogee
    a_up = -G0 + np.interp(t, imu["t_s"], imu["acc_x_mps2"]) * np.sin(np.radians(np.interp(t, t_g, gamma)))
    v_up = np.r_[0.0, np.cumsum(-a_up[:-1] * dt)]
    rise_imu = np.r_[0.0, np.cumsum(v_up[:-1] * dt)]
    smooth = {name: savgol_filter(h.height_m, int(round(0.5 / np.median(np.diff(h.t_s)))) | 1, 2)
              for name, h in sources.items()}  # fmt: skip
    print(f"rise to apogee ({apogee_s:.2f} s) [m]: t, ½ g (t_apogee − t)², IMU, IMU / {WARM_DAY:g}, "
          + ", ".join(sources) + "; the IMU's vertical speed [m/s]")  # fmt: skip
    for start in (3.3, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0):
        rises = [np.interp(apogee_s, h.t_s, smooth[n]) - np.interp(start, h.t_s, smooth[n]) for n, h in sources.items()]
        imu_rise = np.interp(start, t[::-1], rise_imu[::-1])
        print(f"  {start:5.1f} {0.5 * G0 * (apogee_s - start) ** 2:7.0f} {imu_rise:7.0f} {imu_rise / WARM_DAY:7.0f} "
              + " ".join(f"{r:7.0f}" for r in rises) + f"; {np.interp(start, t[::-1], v_up[::-1]):5.1f}")  # fmt: skip


def main() -> None:
    campaign = load_campaign(Path(str(resources.files("rocketmc") / "data" / "campaigns" / "lynx_roccaraso_2021.toml")))
    launch, site = campaign.config.launch, campaign.config.site
    log = read_sensor_log(ROCCARASO_2021)
    pitot_log = {**log, "baro": read_pitot_static(ROCCARASO_2021)}
    q_nb0 = replay.rail_attitude(launch.elevation_deg, launch.azimuth_deg)
    params = filter_params(campaign)
    runs = {label: replay.replay(log, replay.retuned(params, **knobs), q_nb0, site) for label, knobs in TUNINGS.items()}
    thesis = replay.retuned(params, barometer=True)
    runs["thesis, barometer on, pitot static"] = replay.replay(pitot_log, thesis, q_nb0, site)
    runs[f"thesis, barometer on, pitot static, lock-out above Mach {LOCKOUT_MACH:g}"] = replay.replay(
        pitot_log, thesis, q_nb0, site, barometer_max_mach=LOCKOUT_MACH)  # fmt: skip
    q_log = replay.accelerometer_attitude(log, launch.azimuth_deg)
    runs["as flown, from the rail's 79°"] = replay.replay(log, as_flown(params), q_nb0, site)
    runs["as flown"] = replay.replay(log, as_flown(params), q_log, site)
    runs["as flown, barometer off"] = replay.replay(log, replay.retuned(as_flown(params), barometer=False), q_log, site)
    runs["as flown, GNSS gate"] = replay.replay(log, as_flown(params, gnss_gate=GATES["gnss_gate"]), q_log, site)
    runs["as flown, both gates"] = replay.replay(log, as_flown(params, **GATES), q_log, site)
    horizontal = replay.retuned(as_flown(params), gnss="horizontal")
    runs["as flown, barometer off, GNSS horizontal"] = replay.replay(log, replay.retuned(horizontal, barometer=False),
                                                                     q_log, site)  # fmt: skip
    sweep = {std: replay.replay(pitot_log, replay.retuned(as_flown(params), barometer_std=std), q_log, site)
             for std in BAROMETER_STD_SWEEP_M}  # fmt: skip
    runs["as flown, pitot static"] = replay.replay(pitot_log, as_flown(params), q_log, site)
    runs[f"as flown, pitot static, barometer σ {SCHEMA_ALTITUDE_STD_M:g} m"] = sweep[SCHEMA_ALTITUDE_STD_M]
    runs["as flown, pitot static, GNSS horizontal"] = replay.replay(pitot_log, horizontal, q_log, site)
    runs[f"as flown, pitot static, GNSS horizontal, lock-out above Mach {LOCKOUT_MACH:g}"] = replay.replay(
        pitot_log, horizontal, q_log, site, barometer_max_mach=LOCKOUT_MACH)  # fmt: skip
    first = runs[next(iter(runs))]
    windows = replay.flight_windows(first, log)
    windows["coast from 5 s"] = (REFERENCES_SETTLED_S, windows["coast"][1])
    static_sources(log, pitot_log, windows["coast"][1])
    pads = {"MS5803": replay.pad_pressure(first), "pitot static": replay.pad_pressure(runs["as flown, pitot static"])}
    events = reduce_flight(load_roccaraso_2021())
    print(f"windows [s]: coast {windows['coast'][0]:.2f}-{windows['coast'][1]:.2f}, descent to {windows['descent'][1]:.2f} "
          f"(flight_log.reduce_flight: burnout {events.burnout_time_s:.2f}, apogee {events.apogee_time_s:.2f}, landing "
          f"shock {events.landing_time_s:.2f}); pad pressures: MS5803 {pads['MS5803']:.1f} Pa, pitot static "
          f"{pads['pitot static']:.1f} Pa")  # fmt: skip
    print("as flown, pitot static, by the barometer's σ [m]: height − pitot static RMS, coast / descent [m], "
          "flight-path angle − GNSS RMS, coast [deg]: " + "; ".join(
              f"{std:g} {m['height_rms_coast_m']:.2f} / {m['height_rms_descent_m']:.2f}, {m['gamma_rms_coast_deg']:.2f}"
              for std, m in ((std, replay.navigation_metrics(nav, pitot_log, windows, pads["pitot static"]))
                             for std, nav in sweep.items())))  # fmt: skip
    metrics = {}
    for label, nav in runs.items():
        metrics[label] = replay.navigation_metrics(nav, log, windows, pads["MS5803"])
        pitot = replay.navigation_metrics(nav, pitot_log, windows, pads["pitot static"])
        metrics[label].update({f"pitot_{k}": v for k, v in pitot.items() if k.startswith("height")})
    table = []
    for quantity, key in ROWS.items():
        for window in ("coast", "coast from 5 s", "descent") if quantity.startswith("height") else ("coast", "coast from 5 s"):
            row = {"quantity": quantity, "window": window}
            for label, m in metrics.items():
                row[label] = f"{m[key.format('rms', window)]:.1f} / {m[key.format('max', window)]:.1f}"
            table.append(row)
    pd.set_option("display.width", 250)
    print("RMS / max of each difference")
    print(pd.DataFrame(table).to_string(index=False))
    wind = pd.read_csv(ROOT / "src" / "rocketmc" / "data" / "wind" / campaign.config.environment.wind.file, comment="#")
    for window in ("coast", "coast from 5 s"):
        start, end = windows[window]
        angles = {label: body_to_air_velocity_deg(nav, log, wind) for label, nav in runs.items()}
        print(f"body x to air velocity (GNSS less the measured wind), {window} [deg], RMS / max: " + ", ".join(
            f"{label} {np.sqrt(np.mean(a[(a.t_s >= start) & (a.t_s <= end)].angle_deg ** 2)):.1f} / "
            f"{a[(a.t_s >= start) & (a.t_s <= end)].angle_deg.max():.1f}" for label, a in angles.items()))  # fmt: skip
    print("rejected by the gates (magnetometer, GNSS, barometer): " + ", ".join(
        f"{label} {nav.rejected_field.iloc[-1]}, {nav.rejected_gnss.iloc[-1]}, {nav.rejected_baro.iloc[-1]}"
        for label, nav in runs.items() if "gate" in label))  # fmt: skip
    print("mean pitch − GNSS flight-path angle, coast from 5 s [deg]: "
          + ", ".join(f"{label} {m['pitch_minus_gamma_mean_coast from 5 s_deg']:+.1f}" for label, m in metrics.items()))
    for label, nav in runs.items():
        v_n = Vec3(*(jnp.asarray(nav[f"v_{d}_mps"].to_numpy()) for d in ("north", "east", "down")))
        mach = np.asarray(replay.estimated_mach(v_n, jnp.asarray(nav["down_m"].to_numpy()), site.altitude_m))
        fast = nav["t_s"][mach > LOCKOUT_MACH]
        top = nav["height_m"].idxmax()
        burnout = np.interp(windows["coast"][0], nav["t_s"], nav["height_m"])
        print(f"{label}: estimated height at burnout {burnout:.1f} m, apogee {nav['height_m'][top]:.1f} m at "
              f"{nav['t_s'][top]:.2f} s, its largest Mach {mach.max():.3f}"
              + (f", above {LOCKOUT_MACH:g} {fast.min():.2f}-{fast.max():.2f} s" if len(fast) else ""))  # fmt: skip
    heights = {f"{name} (ISA)": replay.barometric_height(lg, pads[name])
               for name, lg in (("pitot static", pitot_log), ("MS5803", log))}  # fmt: skip
    paths = replay.plot_navigation({label: runs[label] for label in SHOWN}, log, windows, ROOT / "docs" / "figures",
                                   "Roccaraso 2021", prefix="roccaraso_", heights=heights)  # fmt: skip
    print("wrote " + ", ".join(str(p.relative_to(ROOT)) for p in paths))


if __name__ == "__main__":
    main()
