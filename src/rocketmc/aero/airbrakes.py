"""The air brakes' extra axial-force coefficient ΔCA against deployment (0 retracted … 1 fully out) and Mach.

From the panels' geometry (``panel_delta_ca``): each of n panels, w wide and extended by u·h_max out of the body into
the flow, is a flat plate normal to it,

    ΔCA(u, M) = n · C_D,plate · w · u·h_max / S_ref · (q_c/q)(M),

with C_D,plate = 1.17, Hoerner's square plate normal to the flow (S. F. Hoerner, *Fluid-Dynamic Drag*, 1965,
p. 3-16: 1.17 for square plates, about 1.2 for rectangles up to 5:1), and the compressible rise of a blunt body's
drag with the stagnation pressure (Hoerner ch. 15-1: the plate's drag follows the pressure on its face, the
stagnation pressure q_c = p_0 − p), q_c/q = ((1 + (γ−1)/2 M²)^(γ/(γ−1)) − 1)/(γ/2 M²), the isentropic relation of
NACA Report 1135 (1953), for M < 1. The body's boundary layer, which shelters the panels' root, is not modelled: for
panels not much taller than it the increment is an upper bound (set ``panel_cd`` lower, or give a measured table).

Or a team's own table (wind tunnel, CFD, DATCOM's protuberance runs). Either way the flight interpolates a
``Table`` over (deployment, mach) with the single output ``dCA``, clamped at its edges.
"""

from __future__ import annotations

import numpy as np

from ..math.table import Table

GAMMA_AIR = 1.4
HOERNER_SQUARE_PLATE_CD = 1.17
"""Drag coefficient of a square flat plate normal to the flow, on its area (Hoerner 1965, p. 3-16)."""
TABLE_MACHS = np.linspace(0.0, 0.95, 20)
"""The Mach grid a panel geometry is tabulated on (the brakes fly subsonic: ``max_mach`` < 1)."""
TABLE_DEPLOYMENTS = np.array([0.0, 1.0])
"""ΔCA of sliding panels is linear in the deployment: two points are exact."""


def stagnation_pressure_ratio(mach):
    """q_c/q, the isentropic impact pressure p_0 − p over the dynamic pressure ½ρV² at Mach ``mach`` < 1 [-];
    1 + M²/4 + M⁴/40 + … at low Mach."""
    mach = np.asarray(mach, dtype=float)
    m2 = np.maximum(mach * mach, 1e-12)
    k = (GAMMA_AIR - 1.0) / 2.0
    ratio = ((1.0 + k * m2) ** (GAMMA_AIR / (GAMMA_AIR - 1.0)) - 1.0) / (GAMMA_AIR / 2.0 * m2)
    return np.where(mach * mach < 1e-12, 1.0, ratio)


def panel_delta_ca(deployment, mach, n_panels: int, width_m: float, max_extension_m: float, reference_area_m2: float,
                   panel_cd: float = HOERNER_SQUARE_PLATE_CD):  # fmt: skip
    """ΔCA [-] on ``reference_area_m2`` of ``n_panels`` flat panels ``width_m`` wide, out by deployment·``max_extension_m``
    [m] into the flow at Mach ``mach`` (module docstring)."""
    plate_area_m2 = n_panels * width_m * max_extension_m * np.asarray(deployment, dtype=float)
    return panel_cd * plate_area_m2 / reference_area_m2 * stagnation_pressure_ratio(mach)


def drag_table(deployments, machs, delta_ca) -> Table:
    """The flight's ``Table`` of ΔCA over (deployment, mach) from host arrays, ``delta_ca`` (deployments, machs)."""
    values = np.asarray(delta_ca, dtype=float)[..., None]
    return Table.from_numpy((deployments, machs), values, ("deployment", "mach"), ("dCA",))


def panel_table(n_panels: int, width_m: float, max_extension_m: float, reference_area_m2: float,
                panel_cd: float = HOERNER_SQUARE_PLATE_CD) -> Table:  # fmt: skip
    """``panel_delta_ca`` tabulated on ``TABLE_DEPLOYMENTS`` × ``TABLE_MACHS``."""
    u, m = np.meshgrid(TABLE_DEPLOYMENTS, TABLE_MACHS, indexing="ij")
    return drag_table(TABLE_DEPLOYMENTS, TABLE_MACHS,
                      panel_delta_ca(u, m, n_panels, width_m, max_extension_m, reference_area_m2, panel_cd))  # fmt: skip
