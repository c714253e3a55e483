"""Semi-empirical component build-up of the normal-force, moment and damping aerodynamics.

Host-side numpy (it builds tables, it is never traced). Zero-lift drag is ``aero.drag``'s job; this
module gives everything that comes from the normal force. Conventions are those of ``aero.tables``:
body frame FRD, α = atan2(w, u), β = asin(v/V), forces ``q̄S(−CA, CY, −CN)``, moments
``q̄Sd(Cl, Cm, Cn)`` about a point ``moment_reference_m`` aft of the nose tip, S the body cross-section,
d its diameter, damping per unit of ω·d/(2V). Positions are distances from the nose tip [m].

Methods and references
----------------------
* Body, linear: slender-body theory. A section of area A(x) carries dCN/dx = (2/S) d(A·α_local)/dx, so
  the nose gives CNα = 2 at Barrowman's x = L − V_nose/A, a conical boat-tail 2(A_aft − A)/S at the same
  kind of centroid, the cylinder nothing (Barrowman 1967; Niskanen 2009, OpenRocket technical
  documentation §3.2). Under a pitch rate the same formula gives the body's CNq and Cmq
  (the cylinder is no longer inert: α_local grows linearly along it).
* Body, non-linear: Jorgensen (NASA TR R-474, 1977): CN = (A_b/S) sin 2α_t cos(α_t/2) +
  η C_dc (A_p/S) sin²α_t, with the potential term split over nose and boat-tail and the viscous
  crossflow term acting at the planform centroid; η(l/d) is Allen & Perkins's (NACA TR 1048, 1951)
  finite-length crossflow factor and C_dc(M_c) the circular-cylinder crossflow drag for subcritical
  Reynolds numbers against the crossflow Mach M_c = M sin α_t (both as tabulated by Jorgensen).
* Fin panel alone: Diederich's lifting-surface formula as used by Barrowman and OpenRocket,
  (CNα)₁ = 2π (s_e²/S) / (1 + √(1 + (β s_e²/(A_f cos Γ_c))²)), β = √(1 − M²) (Prandtl–Glauert),
  s_e the exposed span, A_f the panel area, Γ_c the mid-chord sweep. Its centre of pressure is
  Barrowman's subsonic x_f; its spanwise centre is the mean-aerodynamic-chord station.
* Fin-body and fin-fin interference: slender-body theory in the crossflow plane, solved numerically
  for N panels on a circular body (``slender_body_factors``). For two panels it reproduces the closed
  forms of Pitts, Nielsen & Kaattari (NACA Report 1307, 1957): K_W(B), K_B(W) = (1 + τ)² − K_W(B)
  for body incidence and k_W(B) + k_B(W) = K_W(B) for panel deflection, τ = r/s (tests check these;
  k_W(B) itself matched to 1e-4 in development); for a cruciform it reproduced Adams & Dugan (NACA
  Report 1088, 1952) in development: roll damping 16/π² = 1.62× the planar wing's and a "rolling
  effectiveness" (pb/2V per δ) 0.47× the planar wing's. As in NACA 1307 the slender-body
  ratios multiply the lifting-surface panel lift (CNα)₁. Barrowman's K_T(B) = 1 + τ approximates
  K_W(B) alone and misses the lift the panels carry over onto the body, K_B(W) (≈ 0.58 for the Lynx
  tail): that is most of the gap between plain Barrowman (~6.9 /rad) and Missile DATCOM (10.1 /rad).
  For N ≥ 3 equally spaced panels the normal force is independent of roll; the three-fin set gets
  2.6 % more than the N/2 rule because the panels interfere less (solver, not a fitted factor).
* Roll: a panel's rolling moment is its own lift (not the carry-over: body pressures pass through the
  axis) times its spanwise centre, times the slender-body roll-interference ratio k_R (all panels
  deflected alike, relative to the same panels isolated). Roll damping uses the same k_R with the
  local incidence p·r/V at the spanwise centre.
* High incidence: each panel sees its own local angle α_i. Attached, a low-aspect-ratio panel gives
  (CNα)₁ sin α_i cos α_i plus the plate's crossflow term C_D90 (A_f/S) sin α_i |sin α_i|
  (Flax & Lawrence; Hoerner & Borst, Fluid-Dynamic Lift (1985) ch. 17), C_D90 = 1.17 the broadside
  flat plate (Hoerner, Fluid-Dynamic Drag (1965) §3-16). Past the stall it falls smoothly (logistic
  blend centred on ``FIN_STALL_RAD``) to the separated flat-plate value C_D90 (A_f/S) sin α_i. The
  stall angle of these panels (aspect ratio ~1–1.4) is a stated modelling choice, not a fit.
* Damping: component sums, each component seeing the local incidence q(x − x_ref)/V:
  CNq = 2 Σ CNα_i (x_i − x_ref)/d, Cmq = −2 Σ CNα_i ((x_i − x_ref)/d)², and CYr = CNq, Cnr = Cmq
  (a yaw rate r > 0 moves the tail to −y, the tail sees β < 0 and pushes +y).
* Validity: subsonic theory. The Prandtl–Glauert factor is held at its M = ``MAX_SUBSONIC_MACH``
  value above it, so everything stays smooth and finite up to M 1.3 but is not transonic; the
  crossflow Mach is clamped to the table (≤ 1). Total angles up to ~30° (Jorgensen's range).
* Not modelled: the canards' trailing vortices on the tail fins (downwash, and the roll they induce
  on the tail, which opposes canard roll control); base-flow and Reynolds-number effects on C_dc.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import NamedTuple

import numpy as np
from threadpoolctl import threadpool_limits

from .geometry import FinSet, RocketGeometry, Transition, body_radius_m
from .tables import PANEL_AXES, PANEL_COEFFS, CanardPanels, GriddedCoefficients

MAX_SUBSONIC_MACH = 0.9
"""Above this Mach the compressibility factor of the fin lift is held constant (subsonic theory)."""
FIN_STALL_RAD = math.radians(35.0)
"""Centre of the smooth stall of a low-aspect-ratio panel (local angle) [rad]."""
FIN_STALL_WIDTH_RAD = math.radians(5.0)
"""Width of the logistic blend from attached to flat-plate normal force [rad]."""
FLAT_PLATE_CD90 = 1.17
"""Normal-force coefficient of a flat plate broadside to the flow, on its own area (Hoerner)."""

# Allen & Perkins's ratio η of the crossflow drag of a finite cylinder to an infinite one, vs l/d.
_ETA_FINENESS = np.array([0.0, 2.0, 4.0, 8.0, 12.0, 16.0, 20.0, 28.0, 40.0])
_ETA = np.array([0.50, 0.56, 0.60, 0.65, 0.68, 0.70, 0.72, 0.75, 0.79])
# Crossflow drag coefficient of a circular cylinder (subcritical Re) vs crossflow Mach (Jorgensen).
_CDC_MACH = np.array([0.0, 0.2, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0])
_CDC = np.array([1.20, 1.20, 1.22, 1.30, 1.45, 1.60, 1.75, 1.90, 2.00])


class Component(NamedTuple):
    """One lifting component: name, linear CNα [1/rad, ref S] and centre of pressure from the nose [m]."""

    name: str
    cn_alpha: np.ndarray
    cp_m: float


# --- slender-body interference in the crossflow plane ------------------------------------------------


@dataclasses.dataclass(frozen=True)
class SlenderBodyFactors:
    """Slender-body interference ratios of N equal panels on a circular body, τ = r/s.

    Each is a slender-body load divided by the same load of the panel(s) alone (an exposed panel
    with its mirror image, i.e. half the wing formed by two panels joined, per panel):
    lift: body incidence, all panels plus their carry-over onto the body (K_W(B) + K_B(W) for two);
    lift_panels: the same on the panels only (K_W(B)); deflection: one panel deflected, the force
    along its normal on the whole configuration (k_W(B) + k_B(W) = K_W(B) for two); deflection_panel:
    on that panel only (its own load, what tilts with it; NACA 1307's k_W(B) is instead the load on
    one panel of a pair deflected together); roll: all panels deflected alike, rolling moment relative to the
    isolated panels' lift times their centroid a + 4(s − a)/(3π) (k_R).
    """

    lift: float
    lift_panels: float
    deflection: float
    deflection_panel: float
    roll: float


@functools.lru_cache(maxsize=64)
def slender_body_factors(count: int, tau: float, vortices_per_panel: int = 80) -> SlenderBodyFactors:
    """Interference ratios for ``count`` panels equally spaced on a body, τ = body radius / tip radius.

    Crossflow plane (X = y_FRD, Y = −z_FRD), tip radius 1: each panel is a sheet of discrete vortices
    (lumped-vortex rule, cosine spacing towards the tip), each with its Milne-Thomson image in the
    circle, so the body is a streamline and the total circulation is zero. Normal velocity is zero on
    every panel at the collocation points. In slender-body theory a panel's normal force is
    ρV Σ Γ_j (r_j − a), its carry-over onto the body ρV Σ Γ_j (a − a²/r_j) and its rolling moment
    ρV Σ Γ_j (r_j² − a²)/2.
    """
    if not 0 < tau < 1:
        raise ValueError(f"tau = body radius / tip radius must be in (0, 1), got {tau}")
    a, m = tau, vortices_per_panel
    phis = 2 * np.pi * np.arange(count) / count
    span_dir = 1j * np.exp(-1j * phis)  # (sin φ, cos φ) in (X, Y)
    normal = -np.exp(-1j * phis)  # (0, −cos φ, −sin φ) in FRD
    edges = a + (1 - a) * np.sin(np.linspace(0, np.pi / 2, m + 1))
    r_vortex = edges[1:] - 0.25 * np.diff(edges)
    r_colloc = edges[1:] - 0.75 * np.diff(edges)
    z_v = (r_vortex[None, :] * span_dir[:, None]).ravel()
    z_c = (r_colloc[None, :] * span_dir[:, None]).ravel()
    n_c = np.repeat(normal, m)
    z_image = a**2 / np.conj(z_v)
    conj_vel = -1j / (2 * np.pi) * (1 / (z_c[:, None] - z_v[None, :]) - 1 / (z_c[:, None] - z_image[None, :]))
    influence = np.real(np.conj(conj_vel) * np.conj(n_c)[:, None])  # normal velocity per unit Γ

    def loads(free_normal_velocity):
        with threadpool_limits(1):  # LAPACK's result depends on its BLAS threads: the same bits on every machine
            gamma = np.linalg.solve(influence, -free_normal_velocity).reshape(count, m)
        panel = (gamma * (r_vortex - a)).sum(axis=1)
        body = (gamma * (a - a**2 / r_vortex)).sum(axis=1)
        roll = (gamma * (r_vortex**2 - a**2) / 2).sum(axis=1)
        return panel, body, roll

    isolated = np.pi * (1 - a) ** 2 / 2  # lift of one panel alone per unit normal velocity
    # Body incidence: unit crossflow along panel 0's normal past the circle, u − iv = c̄ (1 − a²c/(c̄ z²))·…
    c = normal[0]
    crossflow = np.conj(c) - c * a**2 / z_c**2  # conjugate velocity of uniform flow c past the circle
    panel, body, _ = loads(np.real(np.conj(crossflow) * np.conj(n_c)))
    along = np.real(normal * np.conj(c))  # n_i · ĉ
    share = np.sum(along**2)
    lift = float(((panel + body) * along).sum() / (share * isolated))
    lift_panels = float((panel * along).sum() / (share * isolated))
    # One panel deflected: unit normal velocity on panel 0 only.
    panel, body, _ = loads(np.where(np.arange(count * m) < m, 1.0, 0.0))
    deflection = float(((panel + body) * along).sum() / isolated)
    deflection_panel = float(panel[0] / isolated)
    # All panels deflected alike (roll control).
    _, _, roll = loads(np.ones(count * m))
    roll_factor = float(roll.sum() / (count * isolated * (a + 4 * (1 - a) / (3 * np.pi))))
    return SlenderBodyFactors(lift, lift_panels, deflection, deflection_panel, roll_factor)


# --- geometry helpers ---------------------------------------------------------------------------------


def _integrate(y: np.ndarray, x: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def _area_step_cp(geometry: RocketGeometry, x_start: float, x_end: float, radius) -> tuple[float, float]:
    """Slender-body CNα [1/rad] and centre [m] of the section x_start..x_end of radius ``radius(x)`` [m]:
    2ΔA/S at ∫x dA / ΔA."""
    x = np.linspace(x_start, x_end, 2001)
    area = np.pi * radius(x) ** 2
    d_area = area[-1] - area[0]
    cp = (x_end * area[-1] - x_start * area[0] - _integrate(area, x)) / d_area
    return 2 * d_area / geometry.reference_area_m2, cp


def _section_cp(geometry: RocketGeometry, section: Transition) -> tuple[float, float]:
    """Slender-body CNα [1/rad] and centre [m] of a conical section between its own fore and aft radii
    (a step in front of it, where the flow separates as at a base, carries no normal force, as in
    Barrowman's method and OpenRocket); (0, its middle) when it neither narrows nor widens."""
    fore, aft, start = 0.5 * section.fore_diameter_m, 0.5 * section.aft_diameter_m, section.position_m
    if fore == aft:
        return 0.0, start + 0.5 * section.length_m

    def radius(x):
        return fore + np.clip((x - start) / section.length_m, 0.0, 1.0) * (aft - fore)

    return _area_step_cp(geometry, start, start + section.length_m, radius)


def _planform(geometry: RocketGeometry) -> tuple[float, float]:
    """Planform (side-view) area of the body [m²] and its centroid from the nose tip [m]."""
    x = np.linspace(0.0, geometry.length_m, 4001)
    width = 2 * body_radius_m(geometry, x)
    area = _integrate(width, x)
    return area, _integrate(width * x, x) / area


def _fin_cp_m(fins: FinSet) -> float:
    """Barrowman's subsonic centre of pressure of a trapezoidal panel, from the nose tip [m]."""
    cr, ct, xt = fins.root_chord_m, fins.tip_chord_m, fins.sweep_m
    return fins.position_m + xt / 3 * (cr + 2 * ct) / (cr + ct) + (cr + ct - cr * ct / (cr + ct)) / 6


def _fin_span_centroid_m(fins: FinSet) -> float:
    """Spanwise station of the mean aerodynamic chord, from the panel root [m]."""
    cr, ct = fins.root_chord_m, fins.tip_chord_m
    return fins.span_m / 3 * (cr + 2 * ct) / (cr + ct)


def _fin_root_radius_m(geometry: RocketGeometry, fins: FinSet) -> float:
    """The body's radius under a fin set, at its centre of pressure [m] (the body's own radius off the
    body): the radius its interference and roll arm are measured from."""
    r = float(body_radius_m(geometry, np.array(_fin_cp_m(fins))))
    return r if r > 0 else geometry.body_radius_m


def _fin_tau(geometry: RocketGeometry, fins: FinSet) -> float:
    r = _fin_root_radius_m(geometry, fins)
    return r / (r + fins.span_m)


def fin_panel_cn_alpha(geometry: RocketGeometry, fins: FinSet, mach) -> np.ndarray:
    """Diederich/Barrowman normal-force slope of one isolated panel, (CNα)₁ [1/rad, ref S]."""
    m = np.minimum(np.asarray(mach, dtype=float), MAX_SUBSONIC_MACH)
    beta = np.sqrt(1 - m**2)
    s2_over_af = fins.span_m**2 / fins.panel_area_m2
    x = beta * s2_over_af / math.cos(fins.mid_chord_sweep_rad)
    return 2 * np.pi * fins.span_m**2 / geometry.reference_area_m2 / (1 + np.sqrt(1 + x**2))


def _fin_cp_radius_m(geometry: RocketGeometry, fins: FinSet) -> float:
    return _fin_root_radius_m(geometry, fins) + _fin_span_centroid_m(fins)


# --- linear build-up ----------------------------------------------------------------------------------


def normal_force_components(geometry: RocketGeometry, mach, include_canards: bool = True) -> list[Component]:
    """Small-angle CNα [1/rad] and centre of pressure [m] of each component at ``mach``.

    Nose and boat-tail (slender-body theory), each fin set (N panels, interference included), and
    the canards at zero deflection when present and ``include_canards``. The cylinder adds nothing
    at α = 0 (its crossflow lift grows as sin²α).
    """
    zero = np.zeros_like(np.asarray(mach, dtype=float))
    cn, cp = _area_step_cp(geometry, 0.0, geometry.nose.length_m, lambda x: body_radius_m(geometry, x))
    components = [Component("nose", cn + zero, cp)]
    for i, section in enumerate(geometry.sections()):
        is_tail = geometry.boat_tail is not None and section.position_m == geometry.boat_tail.position_m
        cn, cp = _section_cp(geometry, section)
        components.append(Component("boat_tail" if is_tail else f"transition{i + 1}", cn + zero, cp))
    sets = [(f"fins{i + 1}", f) for i, f in enumerate(geometry.fins)]
    if include_canards and geometry.canards is not None:
        sets.append(("canards", geometry.canards))
    for name, fins in sets:
        factors = slender_body_factors(fins.count, round(_fin_tau(geometry, fins), 12))
        cn = factors.lift * fins.count / 2 * fin_panel_cn_alpha(geometry, fins, mach)
        components.append(Component(name, cn, _fin_cp_m(fins)))
    return components


def normal_force_slope(geometry: RocketGeometry, mach) -> tuple[np.ndarray, np.ndarray]:
    """Whole-rocket CNα [1/rad] (canards at zero deflection included) and its centre of pressure
    from the nose tip [m] at ``mach``. For N ≤ 2 panels the roll-averaged value is used."""
    components = normal_force_components(geometry, mach)
    cn = sum(c.cn_alpha for c in components)
    return cn, sum(c.cn_alpha * c.cp_m for c in components) / cn


# --- non-linear body table ----------------------------------------------------------------------------


def _panel_normal_force(cn_alpha_panel, panel_area_ratio, local_angle):
    """Smooth attached-to-stalled normal force of a panel at ``local_angle`` [rad] (ref S)."""
    at_zero = 1 / (1 + math.exp(FIN_STALL_RAD / FIN_STALL_WIDTH_RAD))
    logistic = 1 / (1 + np.exp(-(np.abs(local_angle) - FIN_STALL_RAD) / FIN_STALL_WIDTH_RAD))
    stalled = (logistic - at_zero) / (1 - at_zero)  # 0 at zero angle, → 1 well past the stall
    sin_a = np.sin(local_angle)
    plate = FLAT_PLATE_CD90 * panel_area_ratio
    attached = cn_alpha_panel * sin_a * np.cos(local_angle) + plate * sin_a * np.abs(sin_a)
    return (1 - stalled) * attached + stalled * plate * sin_a


def _rate_derivatives(geometry, components, mach, moment_reference_m):
    """CNq and Cmq [per q·d/(2V)]: slender-body body terms plus the lifting surfaces."""
    d, s_ref = geometry.body_diameter_m, geometry.reference_area_m2
    x = np.linspace(0.0, geometry.length_m, 4001)
    area = np.pi * body_radius_m(geometry, x) ** 2
    arm_base = geometry.length_m - moment_reference_m
    area_base = np.pi * float(body_radius_m(geometry, np.array(geometry.length_m))) ** 2
    # dN/dx = ρV d(A w)/dx with w = q (x − x_ref): the force and moment are set by the base section.
    zero = np.zeros_like(mach)
    cn_q = zero + 4 * area_base * arm_base / (s_ref * d)
    cm_q = zero - 4 / (s_ref * d**2) * (area_base * arm_base**2 - _integrate(area * (x - moment_reference_m), x))
    for c in components:
        if c.name.startswith("fins"):
            arm = (c.cp_m - moment_reference_m) / d
            cn_q = cn_q + 2 * c.cn_alpha * arm
            cm_q = cm_q - 2 * c.cn_alpha * arm**2
    return cn_q, cm_q


def body_coefficients(geometry: RocketGeometry, alpha_rad, beta_rad, mach, moment_reference_m: float) -> dict[str, np.ndarray]:
    """CY, CN, Cl, Cm, Cn and the damping derivatives of the rocket without its movable canards.

    alpha_rad, beta_rad [rad], mach [-] broadcast together; moments about ``moment_reference_m``
    from the nose tip [m]. One total normal force per component, from the total angle α_t
    (cos α_t = cos α cos β), acts against the crossflow (sin β, cos β sin α); the fin sets are summed
    panel by panel at their own local angles. Cl is the fins' cant; CNq = CYr, Cmq = Cnr, Clp < 0.
    """
    alpha, beta, mach = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (alpha_rad, beta_rad, mach)))
    d, s_ref = geometry.body_diameter_m, geometry.reference_area_m2
    u = np.cos(alpha) * np.cos(beta)
    v, w = np.sin(beta), np.cos(beta) * np.sin(alpha)  # crossflow / V
    sin_t = np.sqrt(v**2 + w**2)
    components = normal_force_components(geometry, mach, include_canards=False)
    cy = np.zeros_like(alpha)
    cn = np.zeros_like(alpha)
    cm = np.zeros_like(alpha)
    cn_yaw = np.zeros_like(alpha)

    def add(force_y, force_n, x_m):  # force coefficients along +y and along −z, acting at x_m
        nonlocal cy, cn, cm, cn_yaw
        arm = (moment_reference_m - x_m) / d
        cy, cn = cy + force_y, cn + force_n
        cm, cn_yaw = cm + force_n * arm, cn_yaw + force_y * arm

    # Potential (Jorgensen) terms: CNα/2 · sin 2α_t cos(α_t/2), divided by sin α_t to resolve.
    potential = u * np.sqrt((1 + u) / 2)  # sin 2α_t cos(α_t/2) / (2 sin α_t)
    for c in components:
        if not c.name.startswith(("fins", "canards")):  # nose, transitions, boat-tail
            add(-c.cn_alpha * potential * v, c.cn_alpha * potential * w, c.cp_m)
    # Viscous crossflow: η C_dc (A_p/S) sin²α_t at the planform centroid.
    planform_area, planform_x = _planform(geometry)
    eta = np.interp(geometry.length_m / d, _ETA_FINENESS, _ETA)
    cdc = np.interp(np.minimum(mach, 1.3) * sin_t, _CDC_MACH, _CDC)
    viscous = eta * cdc * planform_area / s_ref * sin_t
    add(-viscous * v, viscous * w, planform_x)
    # Fin sets, panel by panel: local angle from the crossflow through the panel.
    cl = np.zeros_like(alpha)
    cl_p = np.zeros_like(alpha)
    for fins, comp in zip(geometry.fins, (c for c in components if c.name.startswith("fins"))):
        factors = slender_body_factors(fins.count, round(_fin_tau(geometry, fins), 12))
        cn1 = fin_panel_cn_alpha(geometry, fins, mach)
        area_ratio = fins.panel_area_m2 / s_ref
        for phi in fins.panel_roll_angles():
            n_y, n_z = -math.cos(phi), -math.sin(phi)
            local = np.arctan2(n_y * v + n_z * w, u)
            force = -factors.lift * _panel_normal_force(cn1, area_ratio, local)  # along the normal
            add(force * n_y, -force * n_z, comp.cp_m)
        arm = _fin_cp_radius_m(geometry, fins) / d
        roll_slope = fins.count * factors.roll * cn1 * arm  # rolling moment per rad of cant (negative)
        cl = cl - roll_slope * math.radians(fins.cant_deg)
        cl_p = cl_p - 2 * roll_slope * arm  # local incidence p·r/V = 2 p̂ r/d
    cn_q, cm_q = _rate_derivatives(geometry, components, mach, moment_reference_m)
    return {"CY": cy, "CN": cn, "Cl": cl, "Cm": cm, "Cn": cn_yaw, "CNq": cn_q, "Cmq": cm_q, "CYr": cn_q, "Cnr": cm_q, "Clp": cl_p}


# --- canard panels ------------------------------------------------------------------------------------


def canard_panel_table(geometry: RocketGeometry, moment_reference_m: float, incidence_rad, deflection_rad, mach) -> CanardPanels:
    """Per-panel CN, CA, CR of ``geometry.canards`` on the grid incidence × deflection × Mach.

    A panel at local incidence i and deflection δ [rad] sees α_l = i + δ (positive both pushing it
    along its normal). Linear: CN = (CNα)₁ [K·i + k·δ] with K the slender-body incidence factor
    (panels + carry-over, K_W(B) + K_B(W) for two) and k the one-panel deflection factor
    (k_W(B) + k_B(W)); the lift falls off with α_l as a tail fin's does. CA = CN_panel sin δ, the
    panel's own normal force (not the body carry-over) tilted with the panel. CR = (CNα)₁ k_R (i + δ)
    · r_cp/d, the panel's lift times its spanwise centre with the slender-body roll interference k_R
    (the carry-over onto the body makes no rolling moment). ``moment_reference_m`` is not needed:
    the panels carry their own point of action (``cp_m``); it is accepted for symmetry with the body.
    """
    del moment_reference_m
    canards = geometry.canards
    if canards is None:
        raise ValueError("geometry has no canards")
    axes = tuple(np.asarray(a, dtype=float) for a in (incidence_rad, deflection_rad, mach))
    inc, dfl, m = np.meshgrid(*axes, indexing="ij")
    factors = slender_body_factors(canards.count, round(_fin_tau(geometry, canards), 12))
    cn1 = fin_panel_cn_alpha(geometry, canards, m)
    local = inc + dfl
    # Non-linear falloff: the panel's normal force at α_l relative to its linear value (1 at α_l → 0).
    safe = np.where(np.abs(local) < 1e-9, 1e-9, local)
    falloff = _panel_normal_force(cn1, canards.panel_area_m2 / geometry.reference_area_m2, safe) / (cn1 * safe)
    cn = cn1 * (factors.lift * inc + factors.deflection * dfl) * falloff
    cn_panel = cn1 * (factors.lift_panels * inc + factors.deflection_panel * dfl) * falloff
    ca = cn_panel * np.sin(dfl)
    cp_radius = _fin_cp_radius_m(geometry, canards)
    cr = cn1 * factors.roll * local * falloff * cp_radius / geometry.body_diameter_m
    table = GriddedCoefficients(PANEL_AXES, axes, PANEL_COEFFS, np.stack([cn, ca, cr], axis=-1))
    return CanardPanels(table, canards.panel_roll_angles(), _fin_cp_m(canards), cp_radius)
