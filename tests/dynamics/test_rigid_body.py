"""Torque-free rigid body: conservation laws and the closed-form axisymmetric precession."""

import jax
import numpy as np
import pytest

from rocketmc.dynamics import MassProperties, RigidBodyState, rigid_body_derivatives
from rocketmc.dynamics.rigid_body import angular_momentum_n, kinetic_energy, normalize_attitude
from rocketmc.math import Quat, Vec3, rk4_step

MASS = MassProperties(20.0, 0.0, 0.06, 6.4)
ZERO = Vec3(0.0, 0.0, 0.0)


def integrate(state, h, n):
    f = lambda t, y: (rigid_body_derivatives(y, MASS, ZERO, ZERO, ZERO, 0.0), None)  # noqa: E731

    def body(y, _):
        y = normalize_attitude(rk4_step(f, 0.0, y, h)[0])
        return y, y

    return jax.jit(lambda s: jax.lax.scan(body, s, None, n))(state)


def test_conserves_energy_and_momentum():
    state = RigidBodyState(ZERO, Vec3(3.0, -1.0, 2.0), Quat.from_euler(0.3, 1.0, -0.2), Vec3(20.0, 0.5, -0.3))
    final, _ = integrate(state, 1e-3, 5000)
    e0, e1 = kinetic_energy(state, MASS), kinetic_energy(final, MASS)
    assert float(e1) == pytest.approx(float(e0), rel=1e-10)  # RK4 drift at h·ω = 0.02 over 5000 steps
    # The attitude carries RK4's local error (h·ω)^5/120 ≈ 3e-11 per step, ≈ 1.3e-7 after 5000 steps.
    np.testing.assert_allclose(angular_momentum_n(final, MASS).to_array(), angular_momentum_n(state, MASS).to_array(), rtol=1e-6)
    np.testing.assert_allclose(final.r_n.to_array(), np.array([3.0, -1.0, 2.0]) * 5.0, rtol=1e-12)  # uniform motion


def test_axisymmetric_precession_closed_form():
    # Euler's equations with I_yy = I_zz: p constant, (q, r) rotate at λ = (I_yy − I_xx)/I_yy · p.
    p, q0, r0, h, n = 20.0, 0.5, -0.3, 1e-3, 3000
    state = RigidBodyState(ZERO, ZERO, Quat(1.0, 0.0, 0.0, 0.0), Vec3(p, q0, r0))
    _, traj = integrate(state, h, n)
    t = h * np.arange(1, n + 1)
    lam = (MASS.iyy - MASS.ixx) / MASS.iyy * p
    # Tolerance: RK4 phase error (h·λ)^5/120 ≈ 2.5e-11 per step, ≈ 8e-8 after 3000 steps.
    np.testing.assert_allclose(np.asarray(traj.omega_b.y), q0 * np.cos(lam * t) + r0 * np.sin(lam * t), atol=2e-7)
    np.testing.assert_allclose(np.asarray(traj.omega_b.z), r0 * np.cos(lam * t) - q0 * np.sin(lam * t), atol=2e-7)
    np.testing.assert_allclose(np.asarray(traj.omega_b.x), p, rtol=1e-14)
