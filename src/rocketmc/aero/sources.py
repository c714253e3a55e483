"""Where a rocket's ``AeroTables`` come from: the component build-up from its geometry, a table file
or a built-in table, with an optional Cd-vs-Mach curve for the axial force. Host-side numpy.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from . import buildup, drag, io
from .geometry import RocketGeometry
from .tables import BODY_COEFFS, AeroTables, GriddedCoefficients

_ANGLES_DEG = np.array([-30, -22, -15, -10, -7.5, -5, -2.5, -1, 0, 1, 2.5, 5, 7.5, 10, 15, 22, 30], dtype=float)
BUILDUP_GRID = {
    "alpha": np.deg2rad(_ANGLES_DEG),
    "beta": np.deg2rad(_ANGLES_DEG),
    "mach": np.round(np.arange(0.05, 1.301, 0.05), 2),
    "altitude": np.array([0.0, 2000.0, 4000.0, 8000.0, 12000.0]),
}
"""Grid of build-up body tables: α, β [rad], Mach, altitude above MSL [m] (Reynolds number)."""
CANARD_GRID = {
    "incidence": np.deg2rad([-40, -30, -22, -15, -10, -7.5, -5, -2.5, -1, 0, 1, 2.5, 5, 7.5, 10, 15, 22, 30, 40]),
    "deflection": np.deg2rad([-15, -10, -7.5, -5, -2.5, -1, 0, 1, 2.5, 5, 7.5, 10, 15]),
    "mach": BUILDUP_GRID["mach"],
}
"""Grid of build-up canard panel tables: local incidence, deflection [rad], Mach."""


BUILTIN_TABLES = {"lynx_datcom": io.lynx_datcom_tables}
"""Tables shipped with rocketmc, by the name a campaign's ``rocket.aero.tables`` gives."""


def axial_angle_factor(total_angle_rad):
    """OpenRocket's multiplier of the zero-lift axial force at a total angle of attack α_t (Niskanen
    2009, §3.4.7): cubic Hermite from 1 at 0 to 1.3 at 17° (zero slopes), then down to 0 at 90°."""
    a = np.minimum(np.abs(total_angle_rad), np.pi / 2)
    knot = np.deg2rad(17.0)
    s1 = np.clip(a / knot, 0.0, 1.0)
    s2 = np.clip((a - knot) / (np.pi / 2 - knot), 0.0, 1.0)
    rise = 1.0 + 0.3 * (3 * s1**2 - 2 * s1**3)
    fall = 1.3 * (1.0 - (3 * s2**2 - 2 * s2**3))
    return np.where(a <= knot, rise, fall)


@functools.lru_cache(maxsize=8)
def build_up_tables(geometry: RocketGeometry, moment_reference_m: float) -> AeroTables:
    """Body table over (α, β, Mach, altitude) from the component build-up (``aero.buildup`` for the
    normal forces, moments and damping, ``aero.drag`` for the zero-lift axial force, power off),
    plus the canard panel table if the geometry has canards. Moments about ``moment_reference_m``
    from the nose tip [m]. Cached: do not modify the arrays of the result."""
    g = BUILDUP_GRID
    alpha, beta, mach, altitude = np.meshgrid(g["alpha"], g["beta"], g["mach"], g["altitude"], indexing="ij")
    coefficients = buildup.body_coefficients(geometry, alpha, beta, mach, moment_reference_m)
    total_angle = np.arccos(np.clip(np.cos(alpha) * np.cos(beta), -1.0, 1.0))
    coefficients["CA"] = drag.zero_lift_axial_coefficient(geometry, mach, altitude) * axial_angle_factor(total_angle)
    body = GriddedCoefficients(
        ("alpha", "beta", "mach", "altitude"),
        tuple(g[name] for name in ("alpha", "beta", "mach", "altitude")),
        BODY_COEFFS,
        np.stack([np.broadcast_to(coefficients[name], alpha.shape) for name in BODY_COEFFS], axis=-1),
    )
    tables = AeroTables(
        geometry.reference_area_m2,
        geometry.body_diameter_m,
        moment_reference_m,
        body,
        source="rocketmc component build-up from geometry (Barrowman/OpenRocket, NACA 1307 interference)",
    )
    return with_canards(tables, geometry)


def with_canards(tables: AeroTables, geometry: RocketGeometry) -> AeroTables:
    """``tables`` with the build-up panel table of the geometry's canards (if it has any and the
    tables do not), in the tables' reference area, length and moment point."""
    if geometry.canards is None or tables.canards is not None:
        return tables
    if not np.isclose(tables.reference_length_m, geometry.body_diameter_m) or not np.isclose(
        tables.reference_area_m2, geometry.reference_area_m2
    ):
        raise ValueError(
            f"tables' reference area/length ({tables.reference_area_m2:g} m², {tables.reference_length_m:g} m) "
            f"differ from the geometry's body cross-section and diameter; the canard build-up uses the latter"
        )
    c = CANARD_GRID
    panels = buildup.canard_panel_table(geometry, tables.moment_reference_m, c["incidence"], c["deflection"], c["mach"])
    return dataclasses.replace(tables, canards=panels, source=f"{tables.source}; canards from the build-up")


def _with_mach_points(body: GriddedCoefficients, mach) -> GriddedCoefficients:
    """``body`` with the Mach numbers ``mach`` strictly inside its Mach axis and not on it inserted there, every
    output interpolated linearly along Mach at them: the table's multilinear interpolant is unchanged."""
    k = body.axis_names.index("mach")
    axis = body.axes[k]
    mach = np.asarray(mach, dtype=float)
    new = mach[(mach > axis[0]) & (mach < axis[-1]) & ~np.isin(mach, axis)]
    if new.size == 0:
        return body
    merged = np.union1d(axis, new)
    i = np.clip(np.searchsorted(axis, merged, side="right") - 1, 0, axis.size - 2)
    weight = ((merged - axis[i]) / (axis[i + 1] - axis[i])).reshape([-1 if n == k else 1 for n in range(body.values.ndim)])
    values = np.take(body.values, i, axis=k) * (1.0 - weight) + np.take(body.values, i + 1, axis=k) * weight
    return dataclasses.replace(body, axes=body.axes[:k] + (merged,) + body.axes[k + 1 :], values=values)


def with_axial_curve(tables: AeroTables, mach, cd) -> AeroTables:
    """``tables`` whose zero-lift axial force follows a Cd-vs-Mach curve (linear between points,
    constant beyond them); the dependence on α, β and altitude of the table is kept as an increment
    over its own zero-angle value at each Mach. The curve's points inside the table's Mach range
    and between its grid points are inserted in the Mach axis (``_with_mach_points``), so that a
    curve finer than the grid flies as given."""
    if "mach" not in tables.body.axis_names:
        raise ValueError("a Cd-vs-Mach curve needs a body table with a mach axis")
    body = _with_mach_points(tables.body, mach)
    names = body.axis_names
    index = []
    for name, axis in zip(names, body.axes):
        zeros = np.flatnonzero(axis == 0.0) if name in ("alpha", "beta") else None
        if zeros is not None and zeros.size == 0:
            raise ValueError(f"the body table's {name} axis has no 0 point to anchor a Cd-vs-Mach curve")
        index.append(slice(None) if zeros is None else slice(zeros[0], zeros[0] + 1))
    ca = body.output("CA")
    zero_angle = ca[tuple(index)]  # size 1 along the angle axes, so it broadcasts over them
    shape = [1] * len(names)
    shape[names.index("mach")] = -1
    curve = np.interp(body.axes[names.index("mach")], mach, cd).reshape(shape)
    values = body.values.copy()
    values[..., BODY_COEFFS.index("CA")] = ca - zero_angle + curve
    return dataclasses.replace(
        tables, body=dataclasses.replace(body, values=values), source=f"{tables.source}; axial force from a Cd-vs-Mach curve"
    )


def power_on_axial_increment(geometry: RocketGeometry, motor_diameter_m: float) -> tuple[np.ndarray, np.ndarray]:
    """(Mach, ΔCA) the burning motor adds to the build-up's zero-lift axial force: the base drag of
    the exhaust's area removed, as OpenRocket does (``aero.drag``; altitude does not enter)."""
    mach = BUILDUP_GRID["mach"]
    on = drag.zero_lift_axial_coefficient(geometry, mach, 0.0, power_on=True, motor_diameter_m=motor_diameter_m)
    return mach, on - drag.zero_lift_axial_coefficient(geometry, mach, 0.0)
