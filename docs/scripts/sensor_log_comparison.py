"""The simulated as-flown Lynx sensor log against the real Roccaraso 2021 log (the sensors' acceptance):
``python docs/scripts/sensor_log_comparison.py [REALIZATION]`` flies campaigns/lynx_roccaraso_2021_sensors.toml
(`rocketmc sensors simulate`), prints each channel's high-frequency noise in both logs through the coast (burnout
to apogee) and at rest after landing, and writes docs/figures/sensor_log_roccaraso.png (channel by channel) and
docs/figures/sensor_log_roccaraso_coast.png (the coast, zoomed).

Windows are the real log's events (``flight_log.reduce_flight``), in seconds since liftoff; the simulated flight's
coast and landing fall within ~2 % of them (docs/validation.md), the rest window is each log's last 19 s but 1.
Noise per sample: the robust spread of second differences (``analysis.sensor_log.high_frequency_noise``, order 2),
which cancels the signal's slope and its changes of slope at the sample rate (the coast's falling pressure, the
rocket's roll and coning) where first differences keep them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from rocketmc.analysis.flight_log import ROCCARASO_2021, load_roccaraso_2021, reduce_flight
from rocketmc.analysis.sensor_log import noise_comparison, plot_log_comparison, read_sensor_log
from rocketmc.campaign import load_campaign
from rocketmc.campaign.sensor_record import AFTER_LANDING_S, sensor_record

ROOT = Path(__file__).parents[2]
REST_S = 18.0  # the real log's last ~19 s at rest, less a second for the landing's ring-down


def main(realization: int = 0) -> None:
    campaign = load_campaign(ROOT / "campaigns" / "lynx_roccaraso_2021_sensors.toml")
    simulated = sensor_record(campaign, realization)
    real = read_sensor_log(ROCCARASO_2021)
    events = reduce_flight(load_roccaraso_2021())
    end = {name: float(log["imu"]["t_s"].iloc[-1]) for name, log in (("simulated", simulated), ("real", real))}
    coast = (events.burnout_time_s + 0.5, events.apogee_time_s - 0.5)
    rest = {name: (t - REST_S, t) for name, t in end.items()}
    table = pd.concat([
        noise_comparison(simulated, real, {"coast": coast}, order=2),
        noise_comparison(simulated, real, {"rest": rest["real"]}, order=2).assign(
            simulated=noise_comparison(simulated, simulated, {"rest": rest["simulated"]}, order=2)["simulated"]),
    ])  # fmt: skip
    table["ratio"] = table["simulated"] / table["real"]
    pd.set_option("display.width", 200)
    print(f"coast {coast[0]:.1f}-{coast[1]:.1f} s, rest: the last {REST_S:g} s (simulated: impact + {AFTER_LANDING_S:g} s)")
    print(table.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    figures = ROOT / "docs" / "figures"
    plot_log_comparison(simulated, real, figures / "sensor_log_roccaraso.png")
    coast_only = {name: {stream: f[(f["t_s"] >= coast[0]) & (f["t_s"] <= coast[1])] for stream, f in log.items()}
                  for name, log in (("simulated", simulated), ("real", real))}  # fmt: skip
    plot_log_comparison(coast_only["simulated"], coast_only["real"], figures / "sensor_log_roccaraso_coast.png")
    print(f"wrote {figures / 'sensor_log_roccaraso.png'} and {figures / 'sensor_log_roccaraso_coast.png'}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
