"""Air data: the aerodynamic state seen by the body."""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp

from ..env.atmosphere import AtmosphereState
from ..math import Vec3, safe_arctan2


class AirData(NamedTuple):
    """airspeed [m/s], angle of attack α = atan2(w, u) and sideslip β = asin(v/V) [rad] of the
    air-relative velocity (u, v, w) of the body in FRD, Mach number [-], dynamic pressure ½ρV² [Pa],
    density [kg/m³] and altitude above mean sea level [m]."""

    airspeed: jnp.ndarray
    alpha: jnp.ndarray
    beta: jnp.ndarray
    mach: jnp.ndarray
    qbar: jnp.ndarray
    density: jnp.ndarray
    altitude_msl: jnp.ndarray


def air_data(v_air_b: Vec3, atmosphere: AtmosphereState, altitude_msl) -> AirData:
    """Air data from the velocity relative to the air in the body frame [m/s]."""
    speed = v_air_b.norm()
    safe_speed = jnp.maximum(speed, 1e-9)
    alpha = safe_arctan2(v_air_b.z, v_air_b.x)
    beta = jnp.arcsin(jnp.clip(v_air_b.y / safe_speed, -1.0, 1.0))
    return AirData(
        speed,
        alpha,
        beta,
        speed / atmosphere.speed_of_sound,
        0.5 * atmosphere.density * speed**2,
        atmosphere.density,
        altitude_msl,
    )
