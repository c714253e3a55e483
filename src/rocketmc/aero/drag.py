"""Zero-lift axial force (drag) of a rocket built up from its geometry, after OpenRocket.

Host-side numpy (never traced): it fills the CA0 column of coefficient tables.

Method (S. Niskanen, "Development of an Open Source model rocket simulation software", M.Sc. thesis,
Helsinki University of Technology, 2009, and the OpenRocket technical documentation built on it,
ch. 3.4 and appendix B; checked against OpenRocket's BarrowmanCalculator, SymmetricComponentCalc
and FinSetCalc). Every term is a drag coefficient referenced to ``geometry.reference_area_m2``:

- Skin friction: Reynolds number of the whole rocket, Re = V·L/ν, with the ISA state at the
  altitude and Sutherland's viscosity. Fully turbulent Cf = 1/(1.50 ln Re − 5.6)² (constant below
  Re = 10⁴), or, for ``boundary_layer="transitional"`` (OpenRocket's "perfect finish"), laminar
  1.328/√Re below Re = 5.39·10⁵ and 1/(1.50 ln Re − 5.6)² − 1700/Re above it. Roughness limit
  Cf = 0.032 (Rs/L)^0.2 above Re_crit = 51 (Rs/L)^−1.039 (the larger of the two is used).
  Compressibility: ×(1 − 0.1 M²) subsonic, turbulent ÷(1 + 0.15 M²)^0.58 and roughness-limited
  ÷(1 + 0.18 M²) supersonic, blended linearly over M 0.9–1.1.
  Body: Cf·(1 + 1/(2 f_B))·A_wet with f_B = L/d and A_wet the nose surface plus the cylinder and
  the boat-tail; fins and canards: Cf·(1 + 2t/c̄)·2·N·A_panel with c̄ the mean aerodynamic chord.
- Nose pressure drag (appendix B): cone CD = 2.1 sin²ε + 0.5 sinε/√(M²−1) above M 1.3, a cubic
  between M 1 and 1.3 matching CD(1) = sin ε and the slope 4/(γ+1)·(1 − 0.5 sin ε); tangent ogive
  as the cone of the same fineness; the other shapes from NASA TR-R-100 curves at fineness 3
  scaled to the nose fineness f_N by C0·(C3/C0)^log₄(f_N+1), C0 the blunt-cylinder stagnation
  drag. Below the first transonic point CD = a·M^b + 0.8 sin²φ (φ the shoulder angle, zero for
  every shape here except the cone) with a, b matching the value and slope there.
- Fin pressure drag per unit frontal area N·t·s: leading edge (rounded: (1 − M²)^−0.417 − 1
  subsonic, Barrowman; square: the stagnation drag 0.85·q_stag/q) times cos² of the leading-edge
  sweep, plus the trailing edge (square: the base drag, rounded: half of it, airfoil: none).
- Base drag 0.12 + 0.13 M² (M < 1), 0.25/M (M > 1) on the aft cross-section; with the motor
  burning, on the annulus around the motor (OpenRocket subtracts the motor's area).
- Transitions (conical sections anywhere on the body, the boat-tail among them): a narrowing one the
  base drag on the area it removes, times 1, (3 − γ)/2 or 0 for a length-to-height ratio
  γ = l/(d₁ − d₂) below 1, between 1 and 3, above 3; a widening one the cone's pressure drag above
  (a conical shoulder of fineness l/(d₂ − d₁) and half-angle ε, 0.8 sin²ε at rest) on the ring it adds
  (OpenRocket technical documentation §3.4.3 and appendix B). A step in the body's diameter at a
  section's front: the stagnation drag on the ring facing the flow, the base drag on the ring facing aft.
- Skin friction per surface finish: each component's Cf is the larger of the smooth turbulent Cf and
  the roughness limit of its own roughness height (OpenRocket's finishes: rough 500 µm, unfinished
  150 µm, regular paint 60 µm, smooth paint 20 µm, polished 2 µm; ``OPENROCKET_FINISHES_M``).
- Launch lugs (parasitic drag, Niskanen 2009 §3.4.5 after Hoerner, Fluid-Dynamic Drag (1965) ch. 3; checked against
  OpenRocket's launch-lug calculation, which uses the same factor and area):
  a tube in axial flow, max(1.3 − l/d, 1) times the stagnation drag on its frontal area
  π(r_o² − r_i² max(1 − l/d, 0)) (a short lug's bore passes its air; a long one's, slowed by the
  friction inside, counts as blocked).
- Rail buttons: a cylinder in crossflow, the circular cylinder's drag against Mach (Gowen & Perkins,
  NACA TN 2960 (1953), fig. 7: 1.2 at low speed) times the finite cylinder's ratio for its free end
  (White, Fluid Mechanics, table 7.2: 0.68 at l/d = 2, the button and its mirror image in the body)
  on the button's side profile less its waist's notch,
  at the mean dynamic pressure over its height inside the turbulent boundary layer of the body
  (u/U = (y/δ)^(1/7), δ = 0.37 x Re_x^−0.2 at its distance x from the nose tip; Schlichting, Boundary-
  Layer Theory, ch. XXI), as OpenRocket's RailButtonCalc reduces it.

At zero angle of attack the drag is along the body axis: CA0 = CD0. Where OpenRocket's code and its
documentation differ this follows the documentation: f_B = L/d (the code divides by the radius) and
the tangent ogive's wave drag is the cone's (the code scales it by the shoulder angle, which is nearly
zero for a tangent ogive). Rail buttons: OpenRocket also multiplies the cylinder's drag by the
stagnation drag (0.85 q_stag/q); here the cylinder's measured drag stands alone.
"""

from __future__ import annotations

import math

import numpy as np

from ..env.atmosphere import isa
from .geometry import FinSet, RocketGeometry, nose_radius_m

GAMMA_AIR = 1.4  # ratio of specific heats [-]
SUTHERLAND_BETA = 1.458e-6  # Sutherland's law constant [kg/(m·s·K^0.5)] (USSA 1976)
SUTHERLAND_S = 110.4  # Sutherland's temperature [K]
BOUNDARY_LAYERS = ("turbulent", "transitional")
OPENROCKET_FINISHES_M = {"rough": 500e-6, "unfinished": 150e-6, "normal": 60e-6, "smooth": 20e-6,
                         "polished": 2e-6, "mirror": 0.0}  # fmt: skip
"""OpenRocket's surface finishes and their roughness heights [m] (its ExternalComponent.Finish; "normal" is
"regular paint", "smooth" "smooth paint")."""
# Drag of a circular cylinder in crossflow vs Mach, subcritical Reynolds numbers (Gowen & Perkins, NACA TN
# 2960, fig. 7, as transcribed in OpenRocket's RailButtonCalc); held at the last value beyond.
_CYLINDER_MACH = (0.0, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 1.0, 1.6, 2.0, 2.8)
_CYLINDER_CD = (1.2, 1.22, 1.25, 1.3, 1.4, 1.5, 1.6, 2.1, 1.5, 1.45, 1.33)
# A finite cylinder's drag over the infinite one's vs its length over diameter (White, Fluid Mechanics, table 7.2,
# after Hoerner); a button standing on the body is half of a cylinder twice its height (the wall a mirror).
_FINITE_CYLINDER_LD = (1.0, 2.0, 5.0, 10.0, 20.0, 40.0)
_FINITE_CYLINDER_RATIO = (0.64, 0.68, 0.74, 0.82, 0.91, 0.98)

# Pressure drag of noses of fineness ratio 3 vs Mach (NASA TR-R-100, "Collection of zero-lift drag
# data on bodies of revolution from free-flight investigations", p. 16, as tabulated in OpenRocket's
# SymmetricComponentCalc); zero below the first Mach, held constant after the last.
_FINENESS_3_NOSE_DRAG = {
    "von_karman": (
        (0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.4, 1.6, 2.0, 3.0),
        (0.0, 0.010, 0.027, 0.055, 0.070, 0.081, 0.095, 0.097, 0.091, 0.083),
    ),
    "haack_lv": (
        (0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.4, 1.6, 2.0),
        (0.0, 0.010, 0.024, 0.066, 0.084, 0.100, 0.114, 0.117, 0.113),
    ),
    "parabolic": (
        (0.95, 0.975, 1.0, 1.05, 1.1, 1.2, 1.4, 1.7),
        (0.0, 0.016, 0.041, 0.092, 0.109, 0.119, 0.113, 0.108),
    ),
    "elliptical": (
        (1.2, 1.25, 1.3, 1.4, 1.6, 2.0, 2.4),
        (0.110, 0.128, 0.140, 0.148, 0.152, 0.159, 0.162),
    ),
}


def dynamic_viscosity(temperature_k):
    """Dynamic viscosity of air by Sutherland's law [Pa·s] at ``temperature_k`` [K]."""
    t = np.asarray(temperature_k, dtype=float)
    return SUTHERLAND_BETA * t**1.5 / (t + SUTHERLAND_S)


def skin_friction_coefficient(reynolds, mach, relative_roughness, boundary_layer="turbulent"):
    """Compressibility-corrected skin friction coefficient Cf [-] (per wetted area).

    reynolds: Re of the whole rocket [-]; relative_roughness: roughness height over rocket length
    Rs/L [-]; boundary_layer: "turbulent" (OpenRocket's default) or "transitional" (laminar start,
    OpenRocket's "perfect finish").
    """
    if boundary_layer not in BOUNDARY_LAYERS:
        raise ValueError(f"boundary_layer must be one of {BOUNDARY_LAYERS}, got {boundary_layer!r}")
    re = np.maximum(np.asarray(reynolds, dtype=float), 1e4)  # held at its Re = 1e4 value below
    m2 = np.asarray(mach, dtype=float) ** 2
    turbulent = 1.0 / (1.50 * np.log(re) - 5.6) ** 2
    if boundary_layer == "turbulent":
        cf = turbulent
        subsonic, supersonic = 1 - 0.1 * m2, (1 + 0.15 * m2) ** -0.58
    else:
        cf = np.where(re < 5.39e5, 1.328 / np.sqrt(re), turbulent - 1700 / re)
        # The compressibility correction fades in with the turbulent part, Re 1e6 .. 3e6.
        turbulent_share = np.clip((re - 1e6) / 2e6, 0.0, 1.0)
        subsonic = 1 - 0.1 * m2 * turbulent_share
        supersonic = 1 + ((1 + 0.045 * m2) ** -0.25 - 1) * turbulent_share
    cf = cf * _blend_through_mach_one(mach, subsonic, supersonic)
    roughness = 0.032 * np.asarray(relative_roughness, dtype=float) ** 0.2
    # Between M 0.9 and 1.1 the roughness-limited correction blends its values at the two ends.
    roughness = roughness * _blend_through_mach_one(
        mach, 1 - 0.1 * np.minimum(m2, 0.81), 1 / (1 + 0.18 * np.maximum(m2, 1.21))
    )
    rough_applies = roughness > cf if boundary_layer == "turbulent" else (roughness > cf) & (re > 1e6)
    return np.where(rough_applies, roughness, cf)


def _blend_through_mach_one(mach, subsonic, supersonic):
    """``subsonic`` below M 0.9, ``supersonic`` above M 1.1, linear in Mach between."""
    w = np.clip((np.asarray(mach, dtype=float) - 0.9) / 0.2, 0.0, 1.0)
    return (1 - w) * subsonic + w * supersonic


def base_drag_coefficient(mach):
    """Base drag coefficient [-] referenced to the base area: 0.12 + 0.13 M² (M ≤ 1), 0.25/M above."""
    m = np.asarray(mach, dtype=float)
    return np.where(m <= 1, 0.12 + 0.13 * m**2, 0.25 / np.maximum(m, 1.0))


def stagnation_drag_coefficient(mach):
    """Pressure drag [-] of a blunt face (flat cylinder front) referenced to its area, 0.85·q_stag/q."""
    m = np.maximum(np.asarray(mach, dtype=float), 1e-9)
    q_ratio = np.where(m <= 1, 1 + m**2 / 4 + m**4 / 40, 1.84 - 0.76 / m**2 + 0.166 / m**4 + 0.035 / m**6)
    return 0.85 * q_ratio


def nose_pressure_drag_coefficient(kind, fineness, mach):
    """Pressure (wave) drag [-] of a nose of ``kind`` and fineness length/diameter, referenced to
    its base area (OpenRocket appendix B)."""
    m = np.asarray(mach, dtype=float)
    if kind in ("conical", "ogive"):
        # The tangent ogive follows the cone of the same length (shape factor 0.72(κ−0.5)² + 0.82 = 1
        # at κ = 1) but joins the body smoothly, so its drag at M = 0 is zero.
        sin_cone = 1 / math.sqrt(1 + 4 * fineness**2)
        sin_shoulder = sin_cone if kind == "conical" else 0.0
        start_mach, start_value = 1.0, sin_cone
        start_slope = 4 / (GAMMA_AIR + 1) * (1 - 0.5 * sin_cone)
        supersonic = np.where(m < 1.3, _cone_transonic(sin_cone, m), _cone_supersonic(sin_cone, np.maximum(m, 1.3)))
    else:
        table_mach, table_drag = (np.asarray(v) for v in _FINENESS_3_NOSE_DRAG[kind])
        blunt = stagnation_drag_coefficient(table_mach)
        scaled = blunt * (table_drag / blunt) ** (math.log(fineness + 1) / math.log(4))
        sin_shoulder = 0.0  # these shapes join the body tangentially
        start_mach, start_value = table_mach[0], scaled[0]
        start_slope = (scaled[1] - scaled[0]) / (table_mach[1] - table_mach[0])
        supersonic = np.interp(m, table_mach, scaled)
    drag_at_rest = 0.8 * sin_shoulder**2
    if start_value <= drag_at_rest:  # the transonic curve starts at zero: nothing below it
        return np.where(m < start_mach, 0.0, supersonic)
    exponent = start_mach * start_slope / (start_value - drag_at_rest)
    subsonic = (start_value - drag_at_rest) * (np.minimum(m, start_mach) / start_mach) ** exponent + drag_at_rest
    return np.where(m < start_mach, subsonic, supersonic)


def _cone_supersonic(sin_cone, mach):
    return 2.1 * sin_cone**2 + 0.5 * sin_cone / np.sqrt(mach**2 - 1)


def _cone_transonic(sin_cone, mach):
    """Cubic Hermite over M 1..1.3 between CD(1) = sin ε with slope 4/(γ+1)(1 − 0.5 sin ε) and the
    supersonic formula with its slope at M 1.3."""
    m0, m1 = 1.0, 1.3
    v0, v1 = sin_cone, float(_cone_supersonic(sin_cone, m1))
    d0 = 4 / (GAMMA_AIR + 1) * (1 - 0.5 * sin_cone)
    d1 = -0.5 * sin_cone * m1 / (m1**2 - 1) ** 1.5
    h, t = m1 - m0, np.clip((mach - m0) / (m1 - m0), 0.0, 1.0)
    return (
        (2 * t**3 - 3 * t**2 + 1) * v0
        + (t**3 - 2 * t**2 + t) * h * d0
        + (-2 * t**3 + 3 * t**2) * v1
        + (t**3 - t**2) * h * d1
    )


def nose_wetted_area_m2(kind, length_m, radius_m, samples=4001):
    """Lateral surface of a nose of ``kind`` [m²] (sum of thin conical frusta)."""
    x = np.linspace(0.0, length_m, samples)
    r = nose_radius_m(kind, length_m, radius_m, x)
    return float(np.sum(np.pi * (r[1:] + r[:-1]) * np.hypot(np.diff(x), np.diff(r))))


def mean_aerodynamic_chord_m(fins: FinSet) -> float:
    """Mean aerodynamic chord of a trapezoidal panel [m]."""
    cr, ct = fins.root_chord_m, fins.tip_chord_m
    return 2 / 3 * (cr + ct - cr * ct / (cr + ct))


def fin_pressure_drag_coefficient(fins: FinSet, mach):
    """Pressure drag of a fin set [-] referenced to its frontal area N·t·s.

    By ``fins.profile``: "rounded" (rounded or bevelled edges, the default: the Lynx fins' hexagonal
    section has 45° bevels), "square" (flat leading and trailing faces) or "airfoil" (rounded leading
    edge, tapered trailing edge).
    """
    profile = fins.profile
    m = np.asarray(mach, dtype=float)
    if profile == "square":
        leading = stagnation_drag_coefficient(m)
    else:  # Barrowman's rounded leading edge, a cylinder in cross-flow without base drag
        m_above_1 = np.maximum(m, 1.0)
        leading = np.where(
            m < 0.9,
            (1 - np.minimum(m, 0.9) ** 2) ** -0.417 - 1,
            np.where(m < 1, 1 - 1.785 * (m - 0.9), 1.214 - 0.502 / m_above_1**2 + 0.1095 / m_above_1**4),
        )
    leading_edge_sweep = math.atan2(fins.sweep_m, fins.span_m)
    trailing = {"square": 1.0, "rounded": 0.5, "airfoil": 0.0}[profile] * base_drag_coefficient(m)
    return leading * math.cos(leading_edge_sweep) ** 2 + trailing


def _body_wetted_area_m2(geometry: RocketGeometry) -> float:
    """The body's surface [m²]: the nose, then each cylinder and conical section to the aft end."""
    nose = geometry.nose
    position, radius = nose.length_m, geometry.body_radius_m
    area = nose_wetted_area_m2(nose.kind, nose.length_m, radius)
    for section in geometry.sections():
        area += 2 * np.pi * radius * (section.position_m - position)
        fore, aft = 0.5 * section.fore_diameter_m, 0.5 * section.aft_diameter_m
        if section.cd_override is None:  # an overridden section's friction is in its override
            area += np.pi * (fore + aft) * math.hypot(section.length_m, fore - aft)
        position, radius = section.position_m + section.length_m, aft
    return area + 2 * np.pi * radius * max(geometry.length_m - position, 0.0)


def _check(geometry: RocketGeometry):
    end = geometry.nose.length_m
    for section in geometry.sections():
        if section.position_m < end - 1e-6:
            raise ValueError(f"the conical section at {section.position_m} m overlaps the one before it (ending {end} m)")
        end = section.position_m + section.length_m
    if end > geometry.length_m + 1e-3:
        raise ValueError(f"the body's sections end at {end} m, beyond its length {geometry.length_m} m")
    tail = geometry.boat_tail
    if tail and abs(tail.position_m + tail.length_m - geometry.length_m) > 1e-3:
        raise ValueError(
            f"the boat-tail ({tail.position_m} + {tail.length_m} m) must end at the body's length {geometry.length_m} m"
        )
    if tail and not 0 <= tail.aft_diameter_m < geometry.body_diameter_m:
        raise ValueError(f"boat-tail aft diameter {tail.aft_diameter_m} m must be below the body diameter")


def _section_pressure(geometry: RocketGeometry, mach, base_cd) -> np.ndarray:
    """Pressure drag [-] (ref S) of the conical sections and of the steps in front of them; an overridden section
    (``cd_override``) makes none of its own (the ring it adds in front included), the base of a step down before it
    being the part ahead's."""
    total = np.zeros_like(mach)
    stagnation = stagnation_drag_coefficient(mach)
    for (_, before, fore_d), section in zip(geometry.step_diameters_m(), geometry.sections()):
        ring = np.pi / 4 * (fore_d**2 - before**2)  # > 0: a ring facing the flow, < 0: facing aft
        if ring < 0 or section.cd_override is None:
            total = total + (stagnation * ring if ring > 0 else base_cd * -ring)
        if section.cd_override is not None:
            continue
        aft_d = section.aft_diameter_m
        ring = np.pi / 4 * (aft_d**2 - fore_d**2)
        if aft_d < fore_d:  # in radii, as the boat-tail's term has always been written: the same bits
            fore_r, aft_r = 0.5 * fore_d, 0.5 * aft_d
            height_ratio = section.length_m / (2 * (fore_r - aft_r))
            total = total + base_cd * np.clip((3 - height_ratio) / 2, 0.0, 1.0) * np.pi * (fore_r**2 - aft_r**2)
        elif aft_d > fore_d:
            fineness = section.length_m / (aft_d - fore_d)
            total = total + nose_pressure_drag_coefficient("conical", fineness, mach) * ring
    return total / geometry.reference_area_m2


def lug_drag_coefficient(geometry: RocketGeometry, mach) -> np.ndarray:
    """Pressure drag [-] (ref S) of the launch lugs: max(1.3 − l/d, 1)·C_stag on π(r_o² − r_i² max(1 − l/d, 0))."""
    total = np.zeros_like(np.asarray(mach, dtype=float))
    for lug in geometry.launch_lugs:
        slenderness = lug.length_m / lug.outer_diameter_m
        frontal = np.pi / 4 * (lug.outer_diameter_m**2 - lug.inner_diameter_m**2 * max(1 - slenderness, 0.0))
        total = total + max(1.3 - slenderness, 1.0) * stagnation_drag_coefficient(mach) * frontal
    return total / geometry.reference_area_m2


def rail_button_drag_coefficient(geometry: RocketGeometry, mach, reynolds_per_m) -> np.ndarray:
    """Pressure drag [-] (ref S) of the rail buttons: the cylinder's Cd(M), times the finite cylinder's ratio
    for twice the button's height, on each button's frontal area, at the mean dynamic pressure of the
    1/7-power turbulent boundary layer over its height.

    reynolds_per_m: V/ν of the flight [1/m], broadcast with ``mach``."""
    mach = np.asarray(mach, dtype=float)
    total = np.zeros_like(mach)
    cylinder = np.interp(mach, _CYLINDER_MACH, _CYLINDER_CD)
    for button in geometry.rail_buttons:
        x = max(button.position_m, 1e-3)
        thickness = 0.37 * x / np.maximum(reynolds_per_m * x, 1.0) ** 0.2
        inside = np.minimum(button.height_m, thickness)  # the part of the button inside the layer [m]
        q_ratio = (7 / 9 * inside * (inside / thickness) ** (2 / 7) + (button.height_m - inside)) / button.height_m
        finite = np.interp(2 * button.height_m / button.outer_diameter_m, _FINITE_CYLINDER_LD, _FINITE_CYLINDER_RATIO)
        total = total + finite * cylinder * q_ratio * button.frontal_area_m2
    return total / geometry.reference_area_m2


def _drag_components(geometry, mach, altitude_m, power_on, motor_diameter_m, boundary_layer):
    """Each drag term [-] (reference area of the geometry) broadcast over mach and altitude."""
    _check(geometry)
    mach, altitude_m = np.broadcast_arrays(np.asarray(mach, dtype=float), np.asarray(altitude_m, dtype=float))
    if np.any(mach < 0):
        raise ValueError("Mach must be >= 0")
    air = isa(altitude_m)
    temperature, density = np.asarray(air.temperature, dtype=float), np.asarray(air.density, dtype=float)
    speed = mach * np.asarray(air.speed_of_sound, dtype=float)
    length, s_ref = geometry.length_m, geometry.reference_area_m2
    reynolds = speed * length * density / dynamic_viscosity(temperature)

    def cf(roughness_m):
        return skin_friction_coefficient(reynolds, mach, roughness_m / length, boundary_layer)

    body_cf = cf(geometry.surface_roughness_m)

    def fin_friction(fins: FinSet):
        fin_cf = body_cf if fins.surface_roughness_m is None else cf(fins.surface_roughness_m)
        thickness_factor = 1 + 2 * fins.thickness_m / mean_aerodynamic_chord_m(fins)
        return fin_cf * thickness_factor * 2 * fins.count * fins.panel_area_m2 / s_ref

    def fin_pressure(fins: FinSet):
        frontal = fins.count * fins.thickness_m * fins.span_m
        return fin_pressure_drag_coefficient(fins, mach) * frontal / s_ref

    base_cd = base_drag_coefficient(mach)
    radius, aft_radius = geometry.body_radius_m, 0.5 * geometry.aft_diameter_m
    sections = geometry.sections()
    overrides = [s.cd_override for s in sections if s.cd_override is not None]
    ends_overridden = bool(sections) and sections[-1].cd_override is not None \
        and sections[-1].position_m + sections[-1].length_m >= geometry.length_m - 1e-6  # fmt: skip
    base_area = 0.0 if ends_overridden else np.pi * aft_radius**2
    if power_on:  # the jet fills the base over the motor's cross-section
        motor_radius = aft_radius if motor_diameter_m is None else 0.5 * motor_diameter_m
        base_area = max(base_area - np.pi * motor_radius**2, 0.0)
    zero = np.zeros_like(mach)
    canards = geometry.canards
    return {
        # 1 + 1/(2 f_B) with the fineness f_B = L/d: the body's curvature.
        "friction_body": body_cf * (1 + radius / length) * _body_wetted_area_m2(geometry) / s_ref,
        "friction_fins": sum((fin_friction(f) for f in geometry.fins), zero),
        "friction_canards": fin_friction(canards) if canards else zero,
        "nose_pressure": nose_pressure_drag_coefficient(
            geometry.nose.kind, geometry.nose.length_m / geometry.body_diameter_m, mach
        ),
        "fin_pressure": sum((fin_pressure(f) for f in geometry.fins), zero),
        "canard_pressure": fin_pressure(canards) if canards else zero,
        "transition_pressure": _section_pressure(geometry, mach, base_cd),
        "launch_lugs": lug_drag_coefficient(geometry, mach),
        "rail_buttons": rail_button_drag_coefficient(geometry, mach, reynolds / length),
        "base": base_cd * base_area / s_ref,
        "overrides": sum(overrides, zero),
    }


def zero_lift_axial_coefficient(
    geometry: RocketGeometry,
    mach,
    altitude_m,
    *,
    power_on: bool = False,
    motor_diameter_m: float | None = None,
    boundary_layer: str = "turbulent",
) -> np.ndarray:
    """Axial force coefficient at zero lift CA0 = CD0 [-] (reference ``geometry.reference_area_m2``).

    Broadcasts over ``mach`` [-] and ``altitude_m`` (above mean sea level, ISA) [m]. Includes the
    body, its transitions, every fin set, the canards at zero deflection, the launch lugs and rail
    buttons; each surface's roughness is the geometry's (``surface_roughness_m`` of the body and of
    each fin set). power_on: the motor is burning, and its jet fills ``motor_diameter_m`` [m] of the
    base (None: the whole base, no base drag); boundary_layer: see ``skin_friction_coefficient``.
    """
    terms = _drag_components(geometry, mach, altitude_m, power_on, motor_diameter_m, boundary_layer)
    return sum(terms.values())


def drag_breakdown(
    geometry: RocketGeometry,
    mach: float,
    altitude_m: float,
    power_on: bool = False,
    *,
    motor_diameter_m: float | None = None,
    boundary_layer: str = "turbulent",
) -> dict[str, float]:
    """CD0 [-] of each component at one Mach and altitude [m], plus their sum under "total".

    Keys: friction_body, friction_fins, friction_canards, nose_pressure, fin_pressure,
    canard_pressure, transition_pressure (the boat-tail's included), launch_lugs, rail_buttons, base, overrides,
    total; arguments as ``zero_lift_axial_coefficient``.
    """
    if np.ndim(mach) or np.ndim(altitude_m):
        raise ValueError("drag_breakdown takes a scalar Mach and altitude")
    terms = _drag_components(geometry, mach, altitude_m, power_on, motor_diameter_m, boundary_layer)
    breakdown = {name: float(value) for name, value in terms.items()}
    breakdown["total"] = sum(breakdown.values())
    return breakdown
