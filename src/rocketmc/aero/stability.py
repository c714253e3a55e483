"""Static stability from the aerodynamic model: the centre of pressure at small angles (from the normal-force
and pitching-moment slopes at α = β = δ = 0) against the centre of mass, in calibers (the reference length d,
the body diameter)."""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp

from ..math import Vec3
from .airdata import AirData
from .model import LinearAero, TableAero, aero_coefficients, linear_derivatives

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
    return slopes_at(aero, AirData(1.0, 0.0, 0.0, mach, 0.5, 1.0, altitude_m), aero.moment_ref_x_m)


def slopes_at(aero: TableAero | LinearAero, air: AirData, cg_x_m):
    """(CNα, Cmα) [per rad], traceable: the central difference of the model's own CN and Cm (about its moment
    reference) at α = ±``ALPHA_STEP_RAD``, β = 0, no rates, canards neutral, at the Mach number and altitude of
    ``air``; ``cg_x_m``: the CG's body x [m] (the canard tables' incidences)."""

    def at(alpha):
        c, _ = aero_coefficients(aero, air._replace(alpha=alpha, beta=0.0 * alpha), Vec3.zeros(alpha), cg_x_m,
                                 jnp.zeros(aero.n_canards))  # fmt: skip
        return jnp.stack([c.cn, c.cm])

    step = jnp.asarray(ALPHA_STEP_RAD)
    cn_alpha, cm_alpha = (at(step) - at(-step)) / (2 * ALPHA_STEP_RAD)
    return cn_alpha, cm_alpha


def centre_of_pressure_at(aero: TableAero | LinearAero, air: AirData, cg_x_m):
    """Body-frame x of the centre of pressure [m, from the reference point, positive toward the nose],
    traceable: x_mref + d·Cmα/CNα from ``slopes_at`` (for a flight's time series)."""
    cn_alpha, cm_alpha = slopes_at(aero, air, cg_x_m)
    return aero.moment_ref_x_m + aero.reference_length_m * cm_alpha / cn_alpha


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
    [m, from the reference point, positive toward the nose] (``sim.loads.mass_properties(p, t).cg_x``);
    ``mach``, ``altitude_m`` [m MSL]: where the slopes are read (``centre_of_pressure_x_m``)."""
    return (cg_x_m - centre_of_pressure_x_m(aero, mach, altitude_m)) / float(aero.reference_length_m)
