"""External geometry of a rocket, in the vocabulary of RocketPy and OpenRocket.

Plain host-side dataclasses (they build tables, they are never traced). Positions are distances
from the nose tip, positive aft [m]; a fin set's position is the leading edge of its root chord.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

NOSE_KINDS = ("von_karman", "ogive", "conical", "elliptical", "parabolic", "haack_lv")


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

    def __post_init__(self):
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
class RocketGeometry:
    """Body of revolution (nose + cylinder of ``body_diameter_m`` up to ``length_m`` from the tip,
    optional boat-tail at its end) with tail fin sets and optional movable canards [m]."""

    body_diameter_m: float
    length_m: float
    nose: Nose
    fins: tuple[FinSet, ...] = ()
    canards: FinSet | None = None
    boat_tail: BoatTail | None = None

    @property
    def body_radius_m(self) -> float:
        return 0.5 * self.body_diameter_m

    @property
    def reference_area_m2(self) -> float:
        """Cross-section of the body, the usual reference area [m²]."""
        return math.pi * self.body_radius_m**2


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
