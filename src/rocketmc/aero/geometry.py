"""External geometry of a rocket, in the vocabulary of RocketPy and OpenRocket.

Plain host-side dataclasses (they build tables, they are never traced). Positions are distances
from the nose tip, positive aft [m]; a fin set's position is the leading edge of its root chord.

The body of revolution is the nose (base diameter ``body_diameter_m``, the reference length) followed by
cylinders and conical transitions: each transition (and the aft ``boat_tail``) starts at its ``position_m``,
the body between them is a cylinder of the diameter the previous one ended with. A transition whose fore
diameter differs from that diameter makes a step (a forward- or aft-facing annulus).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

NOSE_KINDS = ("von_karman", "ogive", "conical", "elliptical", "parabolic", "haack_lv")
FIN_PROFILES = ("rounded", "square", "airfoil")
"""A fin's cross-section at its edges (``aero.drag.fin_pressure_drag_coefficient``)."""
DEFAULT_ROUGHNESS_M = 20e-6
"""Surface roughness height when none is given [m]: 20 µm, smooth paint (OpenRocket's "smooth")."""


@dataclasses.dataclass(frozen=True)
class Nose:
    """Nose cone of ``kind`` (one of ``NOSE_KINDS``) and length [m], base diameter = body diameter."""

    kind: str
    length_m: float

    def __post_init__(self):
        if self.kind not in NOSE_KINDS:
            raise ValueError(f"nose kind {self.kind!r} is not one of {', '.join(NOSE_KINDS)}")
        if not self.length_m > 0:
            raise ValueError(f"nose length must be > 0 m, got {self.length_m}")


def nose_radius_m(kind: str, length_m: float, radius_m: float, x_m) -> np.ndarray:
    """Radius [m] of a nose of ``kind``, length and base radius [m], at ``x_m`` from its tip [m] (held at
    the tip's and the base's values outside [0, length]). OpenRocket appendix A: tangent ogive, full
    parabola (K' = 1), half prolate spheroid, Haack series with C = 0 (von Kármán) and 1/3 (LV)."""
    x = np.clip(np.asarray(x_m, dtype=float), 0.0, length_m)
    xi = x / length_m
    if kind == "conical":
        return radius_m * xi
    if kind == "ogive":  # circle of radius rho through the tip, tangent to the body at the base
        rho = (radius_m**2 + length_m**2) / (2 * radius_m)
        return np.sqrt(np.maximum(rho**2 - (length_m - x) ** 2, 0.0)) + radius_m - rho
    if kind == "elliptical":
        return radius_m * np.sqrt(1 - (1 - xi) ** 2)
    if kind == "parabolic":
        return radius_m * (2 * xi - xi**2)
    c = {"von_karman": 0.0, "haack_lv": 1.0 / 3.0}[kind]
    theta = np.arccos(1 - 2 * xi)
    series = np.maximum(theta - np.sin(2 * theta) / 2 + c * np.sin(theta) ** 3, 0.0)  # π (r/R)²
    return radius_m / math.sqrt(math.pi) * np.sqrt(series)


@dataclasses.dataclass(frozen=True)
class FinSet:
    """``count`` identical trapezoidal panels equally spaced in roll.

    root_chord_m, tip_chord_m, span_m (exposed, from the body surface) [m]; sweep_m: axial distance
    from the root's leading edge to the tip's leading edge [m]; position_m: root leading edge from
    the nose tip [m]; thickness_m: panel thickness [m]; cant_deg: fixed cant of every panel, positive
    giving a negative roll moment like a positive canard deflection [deg]; first_panel_deg: roll
    position of panel 1 (see ``panel_roll_angles``) [deg].
    """

    count: int
    root_chord_m: float
    tip_chord_m: float
    span_m: float
    sweep_m: float
    position_m: float
    thickness_m: float = 0.005
    cant_deg: float = 0.0
    first_panel_deg: float = 0.0
    profile: str = "rounded"
    surface_roughness_m: float | None = None

    def __post_init__(self):
        if self.profile not in FIN_PROFILES:
            raise ValueError(f"fin profile must be one of {FIN_PROFILES}, got {self.profile!r}")
        if self.count < 1:
            raise ValueError(f"fin count must be >= 1, got {self.count}")
        for name in ("root_chord_m", "span_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"fin {name} must be > 0, got {getattr(self, name)}")
        if not 0 <= self.tip_chord_m:
            raise ValueError(f"fin tip_chord_m must be >= 0, got {self.tip_chord_m}")

    @property
    def panel_area_m2(self) -> float:
        """Exposed planform area of one panel [m²]."""
        return 0.5 * (self.root_chord_m + self.tip_chord_m) * self.span_m

    @property
    def mid_chord_sweep_rad(self) -> float:
        """Sweep angle of the mid-chord line [rad]."""
        return math.atan2(self.sweep_m + 0.5 * (self.tip_chord_m - self.root_chord_m), self.span_m)

    def panel_roll_angles(self) -> tuple[float, ...]:
        """Roll angle φ_i [rad] of each panel: its span direction in body FRD is (0, sin φ, −cos φ)
        (φ = 0 points up, 90° to starboard); a positive deflection or cant pushes the panel along
        its normal (0, −cos φ, −sin φ)."""
        return tuple(math.radians(self.first_panel_deg) + 2 * math.pi * i / self.count for i in range(self.count))


@dataclasses.dataclass(frozen=True)
class BoatTail:
    """Conical transition from the body diameter to ``aft_diameter_m`` over ``length_m``, starting
    ``position_m`` from the nose tip [m]."""

    length_m: float
    aft_diameter_m: float
    position_m: float


@dataclasses.dataclass(frozen=True)
class Transition:
    """Conical section from ``fore_diameter_m`` to ``aft_diameter_m`` over ``length_m``, its front
    ``position_m`` from the nose tip [m]; narrowing or widening. cd_override: a drag coefficient [-] on the
    reference area flown instead of the section's own friction and pressure drag, and its base drag if it ends the
    body (OpenRocket's component drag override; None: computed from the shape)."""

    position_m: float
    length_m: float
    fore_diameter_m: float
    aft_diameter_m: float
    cd_override: float | None = None

    def __post_init__(self):
        if not self.length_m > 0:
            raise ValueError(f"transition length must be > 0 m, got {self.length_m}")
        if not (self.fore_diameter_m >= 0 and self.aft_diameter_m >= 0):
            raise ValueError("transition diameters must be >= 0 m")


@dataclasses.dataclass(frozen=True)
class LaunchLug:
    """A launch lug: a tube along the body, its front end ``position_m`` from the nose tip [m]."""

    position_m: float
    length_m: float
    outer_diameter_m: float
    inner_diameter_m: float


@dataclasses.dataclass(frozen=True)
class RailButton:
    """A rail button standing ``height_m`` off the body at ``position_m`` (its axis) [m]: a flange of
    ``outer_diameter_m`` whose waist (``inner_diameter_m``, ``inner_height_m`` high) holds the rail."""

    position_m: float
    height_m: float
    outer_diameter_m: float
    inner_diameter_m: float
    inner_height_m: float

    @property
    def frontal_area_m2(self) -> float:
        """Area the button shows the flow [m²]: its side profile less the waist's notch."""
        notch = (self.outer_diameter_m - self.inner_diameter_m) * self.inner_height_m
        return self.height_m * self.outer_diameter_m - notch


@dataclasses.dataclass(frozen=True)
class RocketGeometry:
    """Body of revolution (nose, then cylinders and conical ``transitions``, the optional ``boat_tail``
    at the aft end, ``length_m`` from the tip) with tail fin sets, optional movable canards, launch lugs
    and rail buttons [m]. surface_roughness_m: the body's roughness height [m]."""

    body_diameter_m: float
    length_m: float
    nose: Nose
    fins: tuple[FinSet, ...] = ()
    canards: FinSet | None = None
    boat_tail: BoatTail | None = None
    transitions: tuple[Transition, ...] = ()
    launch_lugs: tuple[LaunchLug, ...] = ()
    rail_buttons: tuple[RailButton, ...] = ()
    surface_roughness_m: float = DEFAULT_ROUGHNESS_M

    @property
    def body_radius_m(self) -> float:
        return 0.5 * self.body_diameter_m

    @property
    def reference_area_m2(self) -> float:
        """Cross-section of the body, the usual reference area [m²]."""
        return math.pi * self.body_radius_m**2

    def sections(self) -> tuple[Transition, ...]:
        """Every conical section aft of the nose, front to back: the transitions and the boat-tail
        (from the diameter before it)."""
        ordered = sorted(self.transitions, key=lambda t: t.position_m)
        tail = self.boat_tail
        if tail is not None:
            before = [t for t in ordered if t.position_m < tail.position_m]
            fore = before[-1].aft_diameter_m if before else self.body_diameter_m
            ordered.append(Transition(tail.position_m, tail.length_m, fore, tail.aft_diameter_m))
        return tuple(ordered)

    def step_diameters_m(self) -> list[tuple[float, float, float]]:
        """(position [m], diameter before, diameter after [m]) at each section's front: where the body's
        diameter jumps (the two equal when it does not)."""
        steps, diameter = [], self.body_diameter_m
        for t in self.sections():
            steps.append((t.position_m, diameter, t.fore_diameter_m))
            diameter = t.aft_diameter_m
        return steps

    @property
    def aft_diameter_m(self) -> float:
        """The body's diameter at its aft end [m]."""
        sections = self.sections()
        return sections[-1].aft_diameter_m if sections else self.body_diameter_m


def body_radius_m(geometry: RocketGeometry, x_m) -> np.ndarray:
    """Radius of the body of revolution [m] at ``x_m`` from the nose tip [m] (0 outside the body); at a
    step, the section's fore radius."""
    x = np.asarray(x_m, dtype=float)
    big_r = geometry.body_radius_m
    nose = geometry.nose
    r = np.where(x < nose.length_m, nose_radius_m(nose.kind, nose.length_m, big_r, x), big_r)
    for t in geometry.sections():
        fore, aft = 0.5 * t.fore_diameter_m, 0.5 * t.aft_diameter_m
        frac = np.clip((x - t.position_m) / t.length_m, 0.0, 1.0)
        r = np.where(x >= t.position_m, fore + frac * (aft - fore), r)
    return np.where((x >= 0) & (x <= geometry.length_m), r, 0.0)


LYNX_AS_FLOWN = RocketGeometry(
    body_diameter_m=0.150,
    length_m=2.495,
    nose=Nose("von_karman", 0.26),
    fins=(FinSet(3, 0.35, 0.12, 0.12, 0.23, 2.145, thickness_m=0.003),),
)
"""Skyward's Lynx as flown in 2021: 3 tail fins, no canards (docs/lynx.md; DATCOM deck FINSET1)."""

LYNX_CANARDS = dataclasses.replace(
    LYNX_AS_FLOWN,
    fins=(FinSet(4, 0.35, 0.12, 0.12, 0.23, 2.145, thickness_m=0.003),),
    canards=FinSet(4, 0.150, 0.080, 0.080, 0.035, 0.325, thickness_m=0.005),
)
"""The thesis's modified Lynx: 4 tail fins and 4 canards at 0/90/180/270° (for005 4fins_4canards deck)."""
