"""Six-degree-of-freedom rigid body with time-varying mass properties, flat non-rotating Earth.

Translation of the centre of mass in NED and rotation about it in the body frame (FRD):

    dr_n/dt = v_n,   m dv_n/dt = q_nb ⊗ f_b ⊗ q_nb* + m g_n,
    dq_nb/dt = ½ q_nb ⊗ ω_b,   I dω_b/dt = m_b − ω_b × (I ω_b).

The mass properties are those of the instant (quasi-rigid body): the jet-damping and
CG-migration terms of the variable-mass equations are neglected (they are below 1 % of the
aerodynamic damping for a rocket like Lynx; see docs/conventions.md).
"""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp

from ..math import Quat, Vec3


class RigidBodyState(NamedTuple):
    """r_n: CG position in NED from the pad [m]; v_n: CG velocity in NED [m/s];
    q_nb: attitude, body to NED; omega_b: body rate in the body frame [rad/s]."""

    r_n: Vec3
    v_n: Vec3
    q_nb: Quat
    omega_b: Vec3


class MassProperties(NamedTuple):
    """Axisymmetric mass properties: mass [kg], body-frame x of the CG [m], inertia about the CG
    along the body axis and across it [kg·m²]."""

    mass: jnp.ndarray
    cg_x: jnp.ndarray
    ixx: jnp.ndarray
    iyy: jnp.ndarray


def combine_on_axis(parts) -> MassProperties:
    """Mass properties of point-axisymmetric parts on the body axis, given as
    (mass, cg_x, ixx_own, iyy_own) about each part's own CG; parallel-axis theorem."""
    mass = sum(p[0] for p in parts)
    cg_x = sum(p[0] * p[1] for p in parts) / mass
    ixx = sum(p[2] for p in parts)
    iyy = sum(p[3] + p[0] * (p[1] - cg_x) ** 2 for p in parts)
    return MassProperties(mass, cg_x, ixx, iyy)


def rigid_body_derivatives(
    state: RigidBodyState, mass: MassProperties, force_b: Vec3, force_n: Vec3, moment_b: Vec3, gravity
) -> RigidBodyState:
    """Time derivative of the state.

    force_b: forces in the body frame [N]; force_n: forces in NED [N] (both at the CG);
    moment_b: moments about the CG in the body frame [N·m]; gravity: downward acceleration [m/s²].
    """
    inv_m = 1.0 / mass.mass
    accel_n = (state.q_nb.rotate(force_b) + force_n) * inv_m + Vec3(0.0, 0.0, gravity)
    w = state.omega_b
    i_w = Vec3(mass.ixx * w.x, mass.iyy * w.y, mass.iyy * w.z)
    rhs = moment_b - w.cross(i_w)
    omega_dot = Vec3(rhs.x / mass.ixx, rhs.y / mass.iyy, rhs.z / mass.iyy)
    return RigidBodyState(state.v_n, accel_n, state.q_nb.derivative(w), omega_dot)


def kinetic_energy(state: RigidBodyState, mass: MassProperties):
    """Translational plus rotational kinetic energy [J]."""
    w = state.omega_b
    return 0.5 * mass.mass * state.v_n.dot(state.v_n) + 0.5 * (
        mass.ixx * w.x**2 + mass.iyy * (w.y**2 + w.z**2)
    )


def angular_momentum_n(state: RigidBodyState, mass: MassProperties) -> Vec3:
    """Angular momentum about the CG in NED [kg·m²/s]."""
    w = state.omega_b
    return state.q_nb.rotate(Vec3(mass.ixx * w.x, mass.iyy * w.y, mass.iyy * w.z))


def normalize_attitude(state: RigidBodyState) -> RigidBodyState:
    return state._replace(q_nb=state.q_nb.normalized())

