"""Allan deviations of 2-hour static records of the accelerometer and gyroscope of each part (the sensors' acceptance):
``python docs/scripts/sensor_allan.py [SECONDS]`` prints, per part and axis, the white-noise level N at τ = 1 s and
the rate-random-walk level K (fitted by ``analysis.allan.noise_terms``) against the configured values, with the
fitted slopes, and writes docs/figures/sensor_allan.png.

Each record is `rocketmc sensors simulate --static` of lynx_nominal with the part's [avionics]: the rocket at rest
on the rail, the flight code's sensors sampling gravity and zero rates at 50 Hz, errors drawn as in a campaign.
"""

from __future__ import annotations

import math
import sys
import tomllib
from pathlib import Path

import numpy as np

from rocketmc.analysis.allan import allan_deviation, noise_terms, plot_allan
from rocketmc.campaign import campaign_from_dict
from rocketmc.campaign.sensor_record import sensor_record

ROOT = Path(__file__).parents[2]
PARTS = ("thesis", "bmx160_uncalibrated")  # the datasheet part docs/validation.md measured (calibrated: the same noise)
CHANNELS = {"accelerometer": ("acc", "m/s²", 1.0), "gyroscope": ("gyro", "deg/s", 180.0 / math.pi)}


def configured(sensor) -> tuple[float, float]:
    """(N [unit/√Hz]: the Allan deviation at 1 s of the white noise, K [unit/√s]) of a sensor's config."""
    white = sensor.noise_density if sensor.noise_density is not None else sensor.noise_std / math.sqrt(sensor.rate_hz)
    return white, sensor.bias_walk


def main(seconds: float = 7200.0) -> None:
    raw = tomllib.loads((ROOT / "campaigns" / "lynx_nominal.toml").read_text())
    series, rows = {}, []
    for part in PARTS:
        campaign = campaign_from_dict({**raw, "avionics": {"part": part}}, ROOT / "campaigns")
        imu = sensor_record(campaign, 0, static_s=seconds)["imu"]
        for sensor, (prefix, unit, scale) in CHANNELS.items():
            config = getattr(campaign.config.avionics, sensor)
            n_set, k_set = configured(config)
            variances = []
            for axis in "xyz":
                column = f"{prefix}_{axis}_{'mps2' if prefix == 'acc' else 'radps'}"
                taus, adev = allan_deviation(imu[column].to_numpy() * scale, config.rate_hz)
                fit = noise_terms(taus, adev)
                series[f"{part} {sensor} {axis} [{unit}]"] = (taus, adev)
                variances.append(adev**2)
                rows.append((part, sensor, axis, unit, n_set, fit["N"], fit["white_slope"], k_set, fit["K"], fit["walk_slope"]))
            # the three axes share N and K: their mean Allan variance has three times the degrees of freedom
            fit = noise_terms(taus, np.sqrt(np.mean(variances, axis=0)))
            rows.append((part, sensor, "mean", unit, n_set, fit["N"], fit["white_slope"], k_set, fit["K"], fit["walk_slope"]))
    print(f"{'part':<8}{'sensor':<15}{'axis':<5}{'unit':<7}{'N set':>11}{'N fit':>11}{'ratio':>7}{'slope':>7}"
          f"{'K set':>11}{'K fit':>11}{'ratio':>7}{'slope':>7}")
    for part, sensor, axis, unit, n_set, n_fit, white_slope, k_set, k_fit, walk_slope in rows:
        k_ratio = k_fit / k_set if k_set else float("nan")
        print(f"{part:<8}{sensor:<15}{axis:<5}{unit:<7}{n_set:>11.4g}{n_fit:>11.4g}{n_fit / n_set:>7.3f}{white_slope:>7.3f}"
              f"{k_set:>11.4g}{k_fit:>11.4g}{k_ratio:>7.3f}{walk_slope:>7.3f}")
    figure = ROOT / "docs" / "figures" / "sensor_allan.png"
    plot_allan({k: v for k, v in series.items() if k.endswith(("x [m/s²]", "x [deg/s]"))}, figure, "unit")
    print(f"wrote {figure}")


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:]))
