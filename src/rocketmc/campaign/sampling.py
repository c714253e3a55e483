"""Dispersion sampling: realization ``i`` draws from ``fold_in(master_key, i)`` (pure, jittable).

Each dispersed parameter draws from its own stream, ``fold_in(key_i, crc32(path))``, so adding a
dispersion to a campaign leaves the draws of the others unchanged; the turbulence's white noise
has the stream ``"environment.turbulence"``; each draw of a fault, ``"faults.<fault>.<what>"``.
"""

from __future__ import annotations

import zlib

import jax
import jax.numpy as jnp

from .record import Campaign
from .schema import FaultsConfig


def realization_key(master_key, index):
    """Key of realization ``index``."""
    return jax.random.fold_in(master_key, index)


def stream_key(key, name: str):
    """The key of the random stream ``name`` (a dotted path) of the realization with ``key``."""
    return jax.random.fold_in(key, zlib.crc32(name.encode()))


def sample_dispersions(campaign: Campaign, key) -> dict:
    """Draw every dispersed parameter of one realization: dotted path -> scalar."""
    drawn = {}
    for path, d in campaign.config.dispersions.items():
        k = stream_key(key, path)
        if d.dist == "normal":
            mean = campaign.nominal[path] if d.mean is None else d.mean
            x = mean + d.std * jax.random.normal(k)
            x = jnp.clip(x, d.low, d.high) if (d.low is not None or d.high is not None) else x
        elif d.dist == "uniform":
            x = jax.random.uniform(k, minval=d.low, maxval=d.high)
        else:
            weights = jnp.ones(len(d.values)) if d.weights is None else jnp.asarray(d.weights)
            x = jnp.asarray(d.values)[jax.random.categorical(k, jnp.log(weights))]
        drawn[path] = x
    return drawn


UNIT_FIELDS = {"magnetometer_step": ("magnitude_ut", "step_ut"), "gyroscope_bias_jump": ("magnitude_deg_s", "jump_deg_s"),
               "accelerometer_bias_jump": ("magnitude_mps2", "jump_mps2")}  # fmt: skip
"""The vector faults: their magnitude's field and the drawn vector's name, in the same unit."""


def sample_faults(faults: FaultsConfig | None, key, n_fins: int = 4) -> dict:
    """Draw the faults of one realization (``FaultsConfig.active``): dotted path -> scalar, each fault's
    ``faults.<fault>.happened`` (1 or 0) and what it was, NaN where it did not happen: ``time_s`` [s]; a canard's
    ``fin`` (1..n_fins); an outage's ``start_s`` and ``end_s`` [s]; the magnetometer's ``step_ut.<i>`` [µT, body
    frame], a bias jump's ``jump_deg_s.<i>`` or ``jump_mps2.<i>`` (sensor frame), uniform in direction."""
    drawn = {}
    for name, f in ({} if faults is None else faults.active()).items():
        path = f"faults.{name}"
        k = lambda what: stream_key(key, f"{path}.{what}")  # noqa: E731
        happened = jax.random.uniform(k("happened")) < f.probability
        values = {}
        if name == "gnss_outage":
            values["start_s"] = jax.random.uniform(k("start_s"), minval=f.start_s[0], maxval=f.start_s[1])
            values["end_s"] = values["start_s"] + jax.random.uniform(k("duration_s"), minval=f.duration_s[0],
                                                                     maxval=f.duration_s[1])  # fmt: skip
        else:
            values["time_s"] = jax.random.uniform(k("time_s"), minval=f.time_s[0], maxval=f.time_s[1])
        if name in ("stuck_canard", "slow_canard"):
            values["fin"] = jax.random.randint(k("fin"), (), 1, n_fins + 1).astype(float) if f.fin is None else f.fin * 1.0
        if name in UNIT_FIELDS:
            magnitude, vector = UNIT_FIELDS[name]
            direction = jax.random.normal(k("direction"), (3,))
            direction = direction / jnp.linalg.norm(direction)
            values.update({f"{vector}.{i}": getattr(f, magnitude) * direction[i] for i in range(3)})
        drawn[f"{path}.happened"] = jnp.where(happened, 1.0, 0.0)
        drawn.update({f"{path}.{what}": jnp.where(happened, jnp.asarray(x, dtype=float), jnp.nan)
                      for what, x in values.items()})  # fmt: skip
    return drawn
