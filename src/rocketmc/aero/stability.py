"""Static stability from the aerodynamic model: the centre of pressure at small angles (from the normal-force
and pitching-moment slopes at α = β = δ = 0) against the centre of mass, in calibers (the reference length d,
the body diameter)."""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp

from ..math import Vec3
from .airdata import AirData
from .model import LinearAero, TableAero, linear_derivatives, table_coefficients

ALPHA_STEP_RAD = 1e-4
"""Half-step of the central difference in α on interpolated tables [rad]: inside the cells around zero, as
``simplify``'s, so the slope is theirs."""


def normal_force_slopes(aero: TableAero | LinearAero, mach: float, altitude_m: float = 0.0) -> tuple[float, float]:
    """(CNα, Cmα) [per rad] at α = β = δ = 0, zero rates, ``mach`` and ``altitude_m`` [m MSL], moments about
    the moment reference: a ``LinearAero``'s derivatives, or the central difference of a ``TableAero``'s
    coefficients at that one point (``simplify`` does it on the whole grid)."""
    if isinstance(aero, LinearAero):
        c = linear_derivatives(aero, mach, altitude_m)
        return c["CNa"], c["Cma"]
    cn_alpha, cm_alpha = _table_slopes(aero, jnp.asarray(mach, float), jnp.asarray(altitude_m, float))
    return float(cn_alpha), float(cm_alpha)


@jax.jit
def _table_slopes(aero: TableAero, mach, altitude_m):
    """(CNα, Cmα) of ``normal_force_slopes`` for interpolated tables, compiled (op by op it takes seconds)."""
    neutral, still = jnp.zeros(aero.canard_roll_rad.shape), Vec3(0.0, 0.0, 0.0)

    def at(alpha):
        c = table_coefficients(aero, AirData(1.0, alpha, 0.0, mach, 0.5, 1.0, altitude_m), still,
                               aero.moment_ref_x_m, neutral)[0]  # fmt: skip
        return jnp.stack([c.cn, c.cm])

    return (at(ALPHA_STEP_RAD) - at(-ALPHA_STEP_RAD)) / (2 * ALPHA_STEP_RAD)


def centre_of_pressure_x_m(aero: TableAero | LinearAero, mach: float, altitude_m: float = 0.0) -> float:
    """Body-frame x of the centre of pressure at α → 0 [m, from the reference point, positive toward the nose]:
    x_mref + d·Cmα/CNα (``normal_force_slopes``); NaN where CNα ≤ 0 (no restoring normal force)."""
    cn_alpha, cm_alpha = normal_force_slopes(aero, mach, altitude_m)
    if not cn_alpha > 0:
        return math.nan
    return float(aero.moment_ref_x_m) + cm_alpha * float(aero.reference_length_m) / cn_alpha


def static_margin_calibers(aero: TableAero | LinearAero, cg_x_m: float, mach: float, altitude_m: float = 0.0) -> float:
    """Static margin [calibers]: (x_cg − x_cp)/d, the centre of mass ahead of the centre of pressure by that
    many reference lengths d; positive is statically stable. ``cg_x_m``: body-frame x of the centre of mass
    [m, from the reference point, positive toward the nose] (``sim.flight.mass_properties(p, t).cg_x``);
    ``mach``, ``altitude_m`` [m MSL]: where the slopes are read (``centre_of_pressure_x_m``)."""
    return (cg_x_m - centre_of_pressure_x_m(aero, mach, altitude_m)) / float(aero.reference_length_m)
