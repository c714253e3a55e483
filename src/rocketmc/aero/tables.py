"""Aerodynamic coefficient tables of one rocket: the host-side data that both models are built from.

Plain numpy (never traced): ``AeroTables`` is what files store, importers produce, the component
build-up computes and ``aero.model`` turns into the two JAX models.

Conventions (docs/conventions.md): body frame FRD; forces ``q̄S (−CA, CY, −CN)``, moments
``q̄Sd (Cl, Cm, Cn)`` about the moment reference point; α = atan2(w, u), β = asin(v/V); damping
derivatives per unit of the non-dimensional rate ω·d/(2V) (DATCOM's convention; CNq, CYr > 0 and
Cmq, Cnr, Clp < 0 for a stable rocket). Positions are distances from the nose tip, positive aft [m].
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..math.table import check_grid

BODY_AXES = ("alpha", "beta", "mach", "altitude")
"""Axes a body table may use (a subset, in any order): α, β [rad], Mach [-], altitude above MSL [m]."""
AXIS_UNITS = {"alpha": "rad", "beta": "rad", "mach": "-", "altitude": "m", "incidence": "rad", "deflection": "rad"}
BODY_COEFFS = ("CA", "CY", "CN", "Cl", "Cm", "Cn", "CNq", "Cmq", "CYr", "Cnr", "Clp")
"""Outputs of a body table, in this order."""
PANEL_AXES = ("incidence", "deflection", "mach")
"""Axes of a canard panel table: local incidence of the panel [rad], its deflection [rad], Mach."""
PANEL_COEFFS = ("CN", "CA", "CR")
"""Outputs of a canard panel table (reference S, d of the rocket): CN, the normal force along the
panel's normal (0, −cos φ, −sin φ) including its carry-over onto the body; CA, the axial force it
adds (induced drag); CR, the magnitude of its rolling moment about the body axis, the moment itself
being ``−q̄Sd·CR`` for every panel (a positive deflection rolls the rocket negatively)."""


@dataclasses.dataclass(frozen=True)
class GriddedCoefficients:
    """Coefficients on a rectilinear grid: ``values[i_0, ..., k]`` at ``(axes[0][i_0], ...)``."""

    axis_names: tuple[str, ...]
    axes: tuple[np.ndarray, ...]
    output_names: tuple[str, ...]
    values: np.ndarray

    def __post_init__(self):
        check_grid(self.axes, self.values, self.axis_names, self.output_names)
        if not np.all(np.isfinite(self.values)):
            raise ValueError("table values must be finite")

    def output(self, name: str) -> np.ndarray:
        """The grid of one output."""
        return self.values[..., self.output_names.index(name)]


@dataclasses.dataclass(frozen=True)
class CanardPanels:
    """Identical movable panels whose contributions superpose.

    table: per-panel coefficients over ``PANEL_AXES`` with outputs ``PANEL_COEFFS``;
    roll_angles_rad: roll position φ_i of each panel (span direction (0, sin φ, −cos φ) in FRD),
    in the order of the deflections δ1..δn; cp_m: where the panel's normal force acts, from the
    nose tip [m]; cp_radius_m: its distance from the body axis [m], where the panel's local
    incidence (including the body rates) is evaluated.
    """

    table: GriddedCoefficients
    roll_angles_rad: tuple[float, ...]
    cp_m: float
    cp_radius_m: float

    def __post_init__(self):
        if self.table.axis_names != PANEL_AXES or self.table.output_names != PANEL_COEFFS:
            raise ValueError(f"a canard panel table has axes {PANEL_AXES} and outputs {PANEL_COEFFS}")


@dataclasses.dataclass(frozen=True)
class AeroTables:
    """Everything the aerodynamic models need, with its provenance.

    reference_area_m2, reference_length_m: S [m²], d [m]; moment_reference_m: the point the
    moments are about, from the nose tip [m]; body: the rocket without its movable canards over
    a subset of ``BODY_AXES`` with outputs ``BODY_COEFFS``; canards: the movable panels, or None;
    source: one line saying where the numbers come from.
    """

    reference_area_m2: float
    reference_length_m: float
    moment_reference_m: float
    body: GriddedCoefficients
    canards: CanardPanels | None = None
    source: str = ""

    def __post_init__(self):
        if not set(self.body.axis_names) <= set(BODY_AXES) or len(set(self.body.axis_names)) != len(self.body.axis_names):
            raise ValueError(f"body table axes {self.body.axis_names} must be distinct names from {BODY_AXES}")
        if self.body.output_names != BODY_COEFFS:
            raise ValueError(f"body table outputs must be {BODY_COEFFS}, got {self.body.output_names}")
        for name in ("reference_area_m2", "reference_length_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")

    def re_referenced(self, moment_reference_m: float) -> AeroTables:
        """The same aerodynamics with moments about another point (from the nose tip) [m].

        A normal force CN acting at the old reference point pitches the body nose-up by CN·Δ/d
        about a point Δ = x' − x aft of it (Cm' = Cm + CN·Δ/d), and a side force yaws it by CY·Δ/d
        (Cn' = Cn + CY·Δ/d); the rate-induced forces shift the damping moments with the same arm. Canard panels keep their
        own point of action, so they need no change.
        """
        arm = (moment_reference_m - self.moment_reference_m) / self.reference_length_m
        c = {name: self.body.output(name) for name in BODY_COEFFS}
        c["Cm"] = c["Cm"] + c["CN"] * arm
        c["Cn"] = c["Cn"] + c["CY"] * arm
        # Rate derivatives: only the arm of the rate-induced force changes. The shift of the angle
        # of attack that a rate induces between the two points (ΔCNq = −2·CNα·Δ/d) is neglected, as
        # DATCOM and RocketPy neglect it: α is taken at the centre of mass in flight anyway.
        c["Cmq"] = c["Cmq"] + c["CNq"] * arm
        c["Cnr"] = c["Cnr"] + c["CYr"] * arm
        body = dataclasses.replace(self.body, values=np.stack([c[name] for name in BODY_COEFFS], axis=-1))
        return dataclasses.replace(self, moment_reference_m=moment_reference_m, body=body)
