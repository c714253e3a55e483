"""Parachutes: triggered after apogee, opening linearly, drag applied at the attachment point."""

from __future__ import annotations

import jax.numpy as jnp

from ..math import Vec3
from ..pytree import pytree_dataclass, static_field


@pytree_dataclass
class Parachute:
    """cd_s_m2: drag area Cd·S of the open canopy [m²]; trigger_altitude_agl_m: it is triggered at the
    first moment after apogee when the altitude is at or below this value [m] (``inf``: at apogee);
    delay_s: from trigger to the start of opening [s]; opening_time_s: the drag area grows linearly
    from 0 to Cd·S over this time [s]; attach_x_m: body-frame x of the attachment point [m]; name: a label such as "drogue" (static);
    released_by: the index of the parachute that cuts this one away when it starts opening (static; None: stays
    attached)."""

    cd_s_m2: jnp.ndarray
    trigger_altitude_agl_m: jnp.ndarray
    delay_s: jnp.ndarray
    opening_time_s: jnp.ndarray
    attach_x_m: jnp.ndarray
    name: str = static_field(default="parachute")
    released_by: int | None = static_field(default=None)


def open_fraction(chute: Parachute, trigger_time, t):
    """Fraction of the drag area deployed at time ``t`` [s]; ``trigger_time = inf`` before the trigger."""
    start = trigger_time + chute.delay_s
    return jnp.clip((t - start) / jnp.maximum(chute.opening_time_s, 1e-6), 0.0, 1.0)


def parachute_drag_n(chute: Parachute, fraction, v_air_n: Vec3, density) -> Vec3:
    """Drag −½ρ|v|v·Cd·S·fraction [N, NED] of the canopy moving at ``v_air_n`` relative to the air."""
    return v_air_n * (-0.5 * density * v_air_n.norm() * chute.cd_s_m2 * fraction)
