"""Mass properties of the parts of an OpenRocket design, and the trapezoid equivalent to a fin planform (host side).

Every function returns ``MassProperties`` (``dynamics.rigid_body``): mass [kg], the CG's axial position [m] in the
frame the caller gives (distances from a component's front end, growing aft), and the inertias about that CG along the
axis and across it [kg·m²]. The parts are axisymmetric about the rocket's axis; fins and lugs are averaged in roll.
"""

from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np

from ..dynamics.rigid_body import MassProperties, combine_on_axis

SHELL_SLICES = 2000
"""Slices of a nose or transition shell along its length: the midpoint rule's error on the mass of a 0.1 m ogive with
a 2 mm wall is below 1e-5 of it (tested against the conical shell's closed form)."""


def tube(outer_radius_m: float, inner_radius_m: float, length_m: float, density_kgm3: float) -> MassProperties:
    """A hollow cylinder (a tube, ring, bulkhead with ``inner_radius_m`` 0) from x = 0 to ``length_m`` [m]:
    m = ρπ(Ro² − Ri²)L, Ixx = m(Ro² + Ri²)/2, Iyy = m(3(Ro² + Ri²) + L²)/12 about its centre."""
    radii_sq = outer_radius_m**2 + inner_radius_m**2
    mass = density_kgm3 * math.pi * (outer_radius_m**2 - inner_radius_m**2) * length_m
    return MassProperties(mass, length_m / 2, mass * radii_sq / 2, mass * (3 * radii_sq + length_m**2) / 12)


def solid_cylinder(mass_kg: float, radius_m: float, length_m: float) -> MassProperties:
    """A solid cylinder of ``mass_kg`` from x = 0 to ``length_m`` [m] (OpenRocket's packed parachutes, cords, mass
    components and motors)."""
    return MassProperties(mass_kg, length_m / 2, mass_kg * radius_m**2 / 2, mass_kg * (3 * radius_m**2 + length_m**2) / 12)


def point(mass_kg: float, x_m: float) -> MassProperties:
    """A point mass at ``x_m`` [m]."""
    return MassProperties(mass_kg, x_m, 0.0, 0.0)


def moved(part: MassProperties, dx_m: float) -> MassProperties:
    """``part`` moved ``dx_m`` [m] along the axis."""
    return part._replace(cg_x=part.cg_x + dx_m)


def scaled(part: MassProperties, mass_kg: float) -> MassProperties:
    """``part`` with its mass set to ``mass_kg``, its CG and radii of gyration kept (a mass override)."""
    ratio = mass_kg / part.mass if part.mass > 0 else 0.0
    return MassProperties(mass_kg, part.cg_x, part.ixx * ratio, part.iyy * ratio)


def combined(parts: list[MassProperties]) -> MassProperties | None:
    """The parts together (parallel axes; ``combine_on_axis``), without the massless ones; None if none has mass."""
    massive = [p for p in parts if p is not None and p.mass > 0]
    return combine_on_axis(massive) if massive else None


def shell_of_revolution(radius_at: Callable[[np.ndarray], np.ndarray], length_m: float, thickness_m: float,
                        density_kgm3: float, filled: bool = False) -> MassProperties:
    """A nose cone or transition: the body of revolution of outer radius ``radius_at(x)`` [m] for x in [0, length]
    with a wall ``thickness_m`` thick normal to its surface (OpenRocket's convention), or ``filled``; sliced into
    ``SHELL_SLICES`` rings (midpoint rule)."""
    dx = length_m / SHELL_SLICES
    edges = np.linspace(0.0, length_m, SHELL_SLICES + 1)
    r_edges = radius_at(edges)
    x = 0.5 * (edges[1:] + edges[:-1])
    r_out = radius_at(x)
    slope = np.diff(r_edges) / dx
    r_in = np.zeros_like(r_out) if filled else np.maximum(r_out - thickness_m * np.sqrt(1 + slope**2), 0.0)
    dm = density_kgm3 * math.pi * (r_out**2 - r_in**2) * dx
    mass = float(dm.sum())
    cg_x = float((dm * x).sum() / mass)
    radii_sq = r_out**2 + r_in**2
    ixx = float((dm * radii_sq / 2).sum())
    iyy = float((dm * (radii_sq / 4 + dx**2 / 12 + (x - cg_x) ** 2)).sum())
    return MassProperties(mass, cg_x, ixx, iyy)


class Planform(NamedTuple):
    """A fin's planform: area [m²], its centroid (x aft of the root's leading edge, y out from the root) [m] and
    the second moments ∫x² dA, ∫y² dA [m⁴] about the root's leading edge."""

    area_m2: float
    x_m: float
    y_m: float
    xx_m4: float
    yy_m4: float


def planform(points: np.ndarray) -> Planform:
    """The planform of the polygon ``points`` ((n, 2): x aft, y outward [m], the root along y = 0 closing it), by
    Green's theorem."""
    x, y = np.asarray(points, dtype=float).T
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2
    sign = 1.0 if area >= 0 else -1.0
    area = abs(area)
    return Planform(
        area,
        float(sign * ((x + x1) * cross).sum() / (6 * area)),
        float(sign * ((y + y1) * cross).sum() / (6 * area)),
        float(sign * ((x * x + x * x1 + x1 * x1) * cross).sum() / 12),
        float(sign * ((y * y + y * y1 + y1 * y1) * cross).sum() / 12),
    )


def fin_set(shape: Planform, count: int, thickness_m: float, density_kgm3: float, body_radius_m: float,
            volume_factor: float = 1.0) -> MassProperties:
    """``count`` flat fins of planform ``shape`` on a body of ``body_radius_m`` [m], x from the root's leading
    edge: each m = ρ·t·A·``volume_factor`` (OpenRocket's cross-section factor: 1 square, 0.99 rounded, 0.85
    airfoil); Ixx = Σ ρt∫(R + y)² dA; Iyy about the set's CG = Σ ρt(∫(x − x̄)² dA + ½∫(R + y)² dA), the ½ the
    average of sin² over fins spread evenly in roll (the wall thickness's own share neglected)."""
    areal_density = density_kgm3 * thickness_m * volume_factor
    radial_sq = body_radius_m**2 * shape.area_m2 + 2 * body_radius_m * shape.area_m2 * shape.y_m + shape.yy_m4
    axial_sq = shape.xx_m4 - shape.area_m2 * shape.x_m**2
    mass = count * areal_density * shape.area_m2
    return MassProperties(mass, shape.x_m, count * areal_density * radial_sq,
                          count * areal_density * (axial_sq + radial_sq / 2))


def trapezoid_points(root_chord_m: float, tip_chord_m: float, span_m: float, sweep_m: float) -> np.ndarray:
    """The polygon of a trapezoidal fin (x aft from the root's leading edge, y outward) [m]."""
    return np.array([[0.0, 0.0], [sweep_m, span_m], [sweep_m + tip_chord_m, span_m], [root_chord_m, 0.0]])


def ellipse_points(root_chord_m: float, span_m: float, count: int = 200) -> np.ndarray:
    """The polygon of an elliptical fin: half an ellipse on the root chord, ``span_m`` high [m]."""
    theta = np.linspace(math.pi, 0.0, count)
    return np.column_stack([root_chord_m * (1 + np.cos(theta)) / 2, span_m * np.sin(theta)])


class Trapezoid(NamedTuple):
    """rocketmc's trapezoidal fin equivalent to another planform [m]; ``area_kept``: whether its area is the
    original's (a planform smaller than the triangle on its root chord and span is not)."""

    root_chord_m: float
    tip_chord_m: float
    span_m: float
    sweep_m: float
    area_kept: bool


def equivalent_trapezoid(points: np.ndarray) -> Trapezoid:
    """The trapezoid with the same span (the largest y), root chord (the largest x on the root, y = 0), planform
    area and axial area centroid as the polygon ``points`` [m]. Its tip chord c_t = 2A/s − c_r (0 when negative,
    the area then larger than the original's); its sweep puts the centroid, x̄ = (c_r² + c_r c_t + c_t² +
    sweep (c_r + 2 c_t)) / (3 (c_r + c_t)), at the original's. The spanwise centroid follows from the chords."""
    points = np.asarray(points, dtype=float)
    shape = planform(points)
    span = float(points[:, 1].max())
    root = float(points[np.isclose(points[:, 1], 0.0), 0].max())
    tip = 2 * shape.area_m2 / span - root
    area_kept = tip >= 0
    tip = max(tip, 0.0)
    sweep = (3 * (root + tip) * shape.x_m - (root**2 + root * tip + tip**2)) / (root + 2 * tip)
    return Trapezoid(root, tip, span, sweep, bool(area_kept))
