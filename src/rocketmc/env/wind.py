"""Layered wind: piecewise-constant speed and direction per altitude band."""

from __future__ import annotations

import jax.numpy as jnp

from ..math import Vec3
from ..pytree import pytree_dataclass


@pytree_dataclass
class WindLayers:
    """Horizontal wind per layer, in NED.

    ``bottom_m[k]`` is the lower edge of layer k above ground [m] (``bottom_m[0] = 0``, increasing);
    ``north_mps[k]``, ``east_mps[k]`` the velocity of the air (the direction it blows *to*) [m/s].
    The top layer extends upward without limit; below ground the first layer applies.
    """

    bottom_m: jnp.ndarray
    north_mps: jnp.ndarray
    east_mps: jnp.ndarray

    @classmethod
    def from_speed_direction(cls, bottom_m, speed_mps, from_rad) -> WindLayers:
        """Layers from speeds [m/s] and meteorological directions (where the wind comes *from*,
        clockwise from north) [rad]."""
        speed = jnp.asarray(speed_mps)
        return cls(jnp.asarray(bottom_m), -speed * jnp.cos(from_rad), -speed * jnp.sin(from_rad))


def layered_wind(layers: WindLayers, altitude_agl) -> Vec3:
    """Wind velocity ``wind_n`` [m/s] at ``altitude_agl`` [m] (no vertical component)."""
    north, east = layers.north_mps[0], layers.east_mps[0]
    for k in range(1, layers.bottom_m.shape[0]):
        above = altitude_agl >= layers.bottom_m[k]
        north = jnp.where(above, layers.north_mps[k], north)
        east = jnp.where(above, layers.east_mps[k], east)
    return Vec3(north, east, jnp.zeros_like(north))
