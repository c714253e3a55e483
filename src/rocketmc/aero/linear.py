"""The simplified (linearised) aerodynamic model of the thesis (see ../docs/conventions.md).

Coefficients per radian, forces and moments at the moment reference point, body frame FRD.
With q̄ = ½ρV², q_v = ½ρV and virtual canard deflections u = (yaw, pitch, roll, squeeze) [rad]:

    CA = s_D·CA0(M) + Σ CA_u,i u_i²,   CN = CNα α + CN_δ u_pitch,   CY = −CNα β + CN_δ u_yaw,
    Cl = Cl0 + Cl_δ u_roll,   Cm = Cmα α + Cm_δ u_pitch,   Cn = −Cmα β + Cm_δ u_yaw,
    F_b = [−q̄S CA,  q̄S CY + q_v S d CY_r r,  −q̄S CN − q_v S d CN_q q],
    M_b = q̄Sd [Cl, Cm, Cn] + q_v S d (d/2) [Cl_p p, Cm_q q, Cm_q r].

Under an open parachute only the damping moments remain, with the canopy's roll damping.
"""

from __future__ import annotations

import jax.numpy as jnp

from ..math import Vec3, interp1d
from ..pytree import pytree_dataclass
from .airdata import AirData


@pytree_dataclass
class LinearAero:
    """Linear aerodynamic coefficients (per rad) of an axisymmetric rocket with four canards.

    reference_area_m2, reference_length_m: S [m²] and d [m]; moment_ref_x_m: body-frame x of the
    moment reference point [m]; ca0_mach, ca0: (K,) zero-lift axial force vs Mach; drag_scale:
    multiplier on CA0; ca_u: (4,) quadratic axial-force terms of (yaw, pitch, roll, squeeze).
    """

    reference_area_m2: jnp.ndarray
    reference_length_m: jnp.ndarray
    moment_ref_x_m: jnp.ndarray
    ca0_mach: jnp.ndarray
    ca0: jnp.ndarray
    drag_scale: jnp.ndarray
    ca_u: jnp.ndarray
    cn_alpha: jnp.ndarray
    cn_delta: jnp.ndarray
    cm_alpha: jnp.ndarray
    cm_delta: jnp.ndarray
    cl0: jnp.ndarray
    cl_delta: jnp.ndarray
    cy_r: jnp.ndarray
    cn_q: jnp.ndarray
    cl_p: jnp.ndarray
    cm_q: jnp.ndarray


def linear_aero_wrench(aero: LinearAero, air: AirData, omega_b: Vec3, u, canopy_cl_p, under_canopy):
    """Aerodynamic force and moment (body frame) at the moment reference point [N, N·m].

    u: (yaw, pitch, roll, squeeze) virtual canard deflections [rad]; canopy_cl_p: roll damping
    coefficient that replaces Cl_p under an open parachute; under_canopy: bool.
    """
    u_yaw, u_pitch, u_roll, u_squeeze = u
    s, d = aero.reference_area_m2, aero.reference_length_m
    qs = air.qbar * s
    qvs = 0.5 * air.density * air.airspeed * s * d
    ca_u = aero.ca_u
    ca = aero.drag_scale * interp1d(air.mach, aero.ca0_mach, aero.ca0) + (
        ca_u[0] * u_yaw**2 + ca_u[1] * u_pitch**2 + ca_u[2] * u_roll**2 + ca_u[3] * u_squeeze**2
    )
    cn = aero.cn_alpha * air.alpha + aero.cn_delta * u_pitch
    cy = -aero.cn_alpha * air.beta + aero.cn_delta * u_yaw
    cl = aero.cl0 + aero.cl_delta * u_roll
    cm = aero.cm_alpha * air.alpha + aero.cm_delta * u_pitch
    cn_yaw = -aero.cm_alpha * air.beta + aero.cm_delta * u_yaw
    flying = jnp.where(under_canopy, 0.0, 1.0)
    force = Vec3(
        -qs * ca,
        qs * cy + qvs * aero.cy_r * omega_b.z,
        -qs * cn - qvs * aero.cn_q * omega_b.y,
    ) * flying
    cl_p = jnp.where(under_canopy, canopy_cl_p, aero.cl_p)
    damping = 0.5 * d * qvs
    moment = Vec3(
        qs * d * cl * flying + damping * cl_p * omega_b.x,
        qs * d * cm * flying + damping * aero.cm_q * omega_b.y,
        qs * d * cn_yaw * flying + damping * aero.cm_q * omega_b.z,
    )
    return force, moment
