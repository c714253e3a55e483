"""Dispersion sampling: realization ``i`` draws from ``fold_in(master_key, i)`` (pure, jittable).

Each dispersed parameter draws from its own stream, ``fold_in(key_i, crc32(path))``, so adding a
dispersion to a campaign leaves the draws of the others unchanged; the turbulence's white noise
has the stream ``"environment.turbulence"``.
"""

from __future__ import annotations

import zlib

import jax
import jax.numpy as jnp

from .config import Campaign


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
