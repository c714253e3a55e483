"""The navigation filters replayed on the real Roccaraso 2021 log (issue 18's acceptance): ``python
docs/scripts/navigate_roccaraso.py`` replays the log (``analysis.replay``, as ``rocketmc navigate``) with the site,
rail and [gnc.filters] tuning of data/campaigns/lynx_roccaraso_2021.toml (the thesis's tuning) and the variants of
``TUNINGS``, prints the estimates against the log's barometric height and GNSS velocity per window, and writes
docs/figures/roccaraso_navigate_*.png (the thesis's tuning and ``SHOWN``).

Windows (``replay.flight_windows``, seconds since liftoff): the coast from burnout to apogee, the descent from
apogee to landing, and the coast from ``REFERENCES_SETTLED_S``: before it both references are distorted (SOURCE.md:
the barometer from 2 to 5 s, by the flow over the static port near Mach 0.6; the GNSS velocity's direction is
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

from rocketmc.analysis import replay
from rocketmc.analysis.flight_log import ROCCARASO_2021, load_roccaraso_2021, reduce_flight
from rocketmc.analysis.sensor_log import read_sensor_log
from rocketmc.campaign import load_campaign
from rocketmc.campaign.model import filter_params

ROOT = Path(__file__).parents[2]
REFERENCES_SETTLED_S = 5.0
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
AS_FLOWN_KNOBS = {"barometer": True, "gnss": "all", "gnss_after_s": 0.0, "gnss_std": GNSS_STD,
                  "field_direction_std": 1e4}  # fmt: skip
"""The as-flown tuning's [gnc.filters] knobs through ``replay.retuned``: the barometer (MS5803) on at the schema's
5 m; the NEO-M9N's fixes from liftoff (it had 16 satellites on the pad) on every axis the log holds (its down
velocity too: Skyward's avionics used north and east only for the GNSS's poor altitude, which the log lacks) at
GNSS_STD; the magnetometer all but ignored (σ_b 1e4): its field reads 25 µT where the model has 45 µT, its dip 65°
against the model dipole's 60.7° (whose declination is 16° off IGRF-13's), and a sphere fit of the flight's
samples puts a ~2 µT hard-iron offset on it, so its direction is 5-10° off and the MEKF would follow that."""
AS_FLOWN_ATTITUDE = {
    "gyro_noise": math.radians(0.1),  # σ_v [rad/s/√s]: the BMX160's 0.007 °/s/√Hz, ×15 for vibration, scale factor
    "bias_walk": math.radians(0.01),  # σ_u [rad/s²/√s]: its bias stays within 0.2 °/s over the flight (landed mean)
    "initial_attitude_std": math.radians(5.0),  # [rad]: the rail's azimuth, fitted on a 5° grid
    "initial_bias_std": math.radians(0.5),  # [rad/s]: at rest after landing it reads 0.16, 0.06, 0.03 °/s
}
GATES = {"field_gate": None, "gnss_gate": 20.1, "altitude_gate": 8.8}  # the 99.7 % χ² quantiles: 6 and 1 dof
SHOWN = ("thesis, barometer on", "as flown")
ROWS = {
    "height − baro [m]": "height_{}_{}_m",
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


def main() -> None:
    campaign = load_campaign(Path(str(resources.files("rocketmc") / "data" / "campaigns" / "lynx_roccaraso_2021.toml")))
    launch, site = campaign.config.launch, campaign.config.site
    log = read_sensor_log(ROCCARASO_2021)
    q_nb0 = replay.rail_attitude(launch.elevation_deg, launch.azimuth_deg)
    params = filter_params(campaign)
    runs = {label: replay.replay(log, replay.retuned(params, **knobs), q_nb0, site) for label, knobs in TUNINGS.items()}
    q_log = replay.accelerometer_attitude(log, launch.azimuth_deg)
    runs["as flown, from the rail's 79°"] = replay.replay(log, as_flown(params), q_nb0, site)
    runs["as flown"] = replay.replay(log, as_flown(params), q_log, site)
    runs["as flown, barometer off"] = replay.replay(log, replay.retuned(as_flown(params), barometer=False), q_log, site)
    runs["as flown, GNSS gate"] = replay.replay(log, as_flown(params, gnss_gate=GATES["gnss_gate"]), q_log, site)
    runs["as flown, both gates"] = replay.replay(log, as_flown(params, **GATES), q_log, site)
    first = runs[next(iter(runs))]
    windows = replay.flight_windows(first, log)
    windows["coast from 5 s"] = (REFERENCES_SETTLED_S, windows["coast"][1])
    events = reduce_flight(load_roccaraso_2021())
    print(f"windows [s]: coast {windows['coast'][0]:.2f}-{windows['coast'][1]:.2f}, descent to {windows['descent'][1]:.2f} "
          f"(flight_log.reduce_flight: burnout {events.burnout_time_s:.2f}, apogee {events.apogee_time_s:.2f}, landing "
          f"shock {events.landing_time_s:.2f}); pad pressure {replay.pad_pressure(first):.1f} Pa")  # fmt: skip
    metrics = {label: replay.navigation_metrics(nav, log, windows) for label, nav in runs.items()}
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
    paths = replay.plot_navigation({label: runs[label] for label in SHOWN}, log, windows, ROOT / "docs" / "figures",
                                   "Roccaraso 2021", prefix="roccaraso_")  # fmt: skip
    print("wrote " + ", ".join(str(p.relative_to(ROOT)) for p in paths))


if __name__ == "__main__":
    main()
