"""One realization's sensor outputs, as a log in the format of the real Lynx log (``rocketmc sensors simulate``).

The flight is flown with every period a GNC period (no long descent steps), so that the sensors sample at
their rates from the rail to the ground; the bus is recorded after each period (``sim.flight.fly``), and each
log keeps the ticks at which its sensor delivered a sample. Times are from liftoff, as in the real log (which
starts there), or from t = 0 for a static record (the rocket at rest on the pad, its motor never lit).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np
import pandas as pd

from ..env.site import latitude_longitude_deg
from ..sim.flight import fly
from .errors import ConfigError
from .flights import compiled_flight
from .record import Campaign
from .runner import realization_params, sim_settings

AFTER_LANDING_S = 20.0
"""How long a flight's log goes on after impact [s]: the real log has ~19 s at rest on the ground."""
MICROTESLA = 1e6
"""The log's magnetometer unit per tesla."""


def sensor_record(campaign: Campaign, realization: int = 0, static_s: float | None = None,
                  log: Callable[[str], None] = lambda line: None) -> dict[str, pd.DataFrame]:  # fmt: skip
    """The sensor log of realization ``realization`` (its drawn errors and gusts), by stream name ("imu", "baro",
    "gnss"), each a DataFrame of the time ``t_s`` [s] and the real log's value columns (``analysis.sensor_log.LOG_FILES``); ``static_s``:
    instead the rocket at rest on the pad for that long [s]; ``log`` receives a progress line once the request
    is checked. ConfigError without an [avionics] section or for a realization outside the campaign."""
    config = campaign.config
    if config.avionics is None:
        raise ConfigError('avionics: the campaign has no [avionics] section, no sensors to simulate (add one, e.g. '
                          '[avionics] part = "thesis")')  # fmt: skip
    if not 0 <= realization < config.n_realizations:
        raise ConfigError(f"--realization: {realization} is not a realization of the campaign (0 to {config.n_realizations - 1})")
    what = "its flight" if static_s is None else f"{static_s:g} s at rest on the pad"
    log(f"{config.name}: realization {realization}, {what} (compiling, then flying)")
    dt = config.simulation.control_dt_s
    settings = dataclasses.replace(sim_settings(campaign), descent_dt_s=dt, point_mass_descent=False)
    params, _ = realization_params(campaign, jax.random.key(config.seed), np.uint32(realization))
    if static_s is not None:
        motor = dataclasses.replace(params.rocket.motor, ignition_time_s=jnp.asarray(jnp.inf))
        params = dataclasses.replace(params, rocket=dataclasses.replace(params.rocket, motor=motor))
    n_periods = math.ceil((config.simulation.max_time_s if static_s is None else static_s) / dt)
    record = lambda s: (s.avionics.bus, s.body.v_n.norm() > 0.0)  # noqa: E731
    flown = compiled_flight(campaign, ("sensor log", n_periods), lambda _: lambda p: fly(p, settings, n_periods, record=record))
    final, (bus, moving) = flown(params)
    t = np.arange(n_periods) * dt  # each period's start: its samples' time
    keep = np.ones(n_periods, bool)
    if static_s is None:
        liftoff = t[np.argmax(np.asarray(moving))]
        end = float(final.events.impact_time) + AFTER_LANDING_S
        keep, t = (t >= liftoff) & (t <= end), t - liftoff
    return _frames(jax.tree_util.tree_map(np.asarray, bus), t, keep, config.site)


def _frames(bus, t, keep, site) -> dict[str, pd.DataFrame]:
    """The log's streams from the recorded bus (numpy), the samples' times [s] and the rows to keep."""

    def rows(reading):
        return keep & reading.fresh

    imu = rows(bus.gyroscope)
    acc, gyro, mag = bus.accelerometer.value[imu], bus.gyroscope.value[imu], bus.magnetometer.value[imu] * MICROTESLA
    baro = rows(bus.barometer)
    fix = rows(bus.gnss)
    r, v = bus.gnss.value[fix, :3], bus.gnss.value[fix, 3:]
    latitude, longitude = latitude_longitude_deg(r[:, 0], r[:, 1], site.latitude_deg, site.longitude_deg)
    return {
        "imu": pd.DataFrame({"t_s": t[imu],
                             **{f"acc_{a}_mps2": acc[:, i] for i, a in enumerate("xyz")},
                             **{f"gyro_{a}_radps": gyro[:, i] for i, a in enumerate("xyz")},
                             **{f"mag_{a}": mag[:, i] for i, a in enumerate("xyz")}}),
        "baro": pd.DataFrame({"t_s": t[baro], "pressure_pa": bus.barometer.value[baro, 0]}),
        "gnss": pd.DataFrame({"t_s": t[fix],
                              "lat_deg": latitude, "lon_deg": longitude,
                              "vel_north_mps": v[:, 0], "vel_east_mps": v[:, 1], "vel_down_mps": v[:, 2],
                              "num_sats": np.full(len(r), np.nan)}),
    }  # fmt: skip
