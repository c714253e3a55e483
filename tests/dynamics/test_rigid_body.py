"""Rigid body: torque-free conservation laws, the closed-form axisymmetric motion, force routing.

The model supports axisymmetric inertia (I_yy = I_zz); "asymmetric-ish" here means I_xx ≠ I_yy,
which already makes the torque-free motion non-trivial (precession and body-cone rotation).
References are computed in NumPy from the definitions, not with the module's helpers (those are
checked against the same references).
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rocketmc.dynamics import MassProperties, RigidBodyState, rigid_body_derivatives
from rocketmc.dynamics.rigid_body import angular_momentum_n, combine_on_axis, kinetic_energy
from rocketmc.math import Quat, Vec3, rk4_step

ZERO = Vec3(0.0, 0.0, 0.0)


@functools.partial(jax.jit, static_argnums=(3, 4))
def integrate(state: RigidBodyState, mass: MassProperties, h, n: int, gravity: float = 0.0):
    """n RK4 steps of the force- and torque-free body (no renormalisation of q); the trajectory."""

    def f(t, y):
        return rigid_body_derivatives(y, mass, ZERO, ZERO, ZERO, gravity), None

    def body(y, _):
        y = rk4_step(f, 0.0, y, h)[0]
        return y, y

    return jax.lax.scan(body, state, None, n)


def np_energy(state: RigidBodyState, m: MassProperties) -> float:
    v = np.asarray(state.v_n.to_array())
    w = np.asarray(state.omega_b.to_array())
    return 0.5 * m.mass * v @ v + 0.5 * (m.ixx * w[0] ** 2 + m.iyy * (w[1] ** 2 + w[2] ** 2))


def np_momentum_n(state: RigidBodyState, m: MassProperties) -> np.ndarray:
    q = np.asarray(state.q_nb.to_array())
    w = np.asarray(state.omega_b.to_array())
    return Rotation.from_quat(q, scalar_first=True).apply(np.array([m.ixx, m.iyy, m.iyy]) * w)


def quat_exp(half_angle_vec) -> np.ndarray:
    a = np.linalg.norm(half_angle_vec)
    return np.concatenate([[np.cos(a)], np.sinc(a / np.pi) * np.asarray(half_angle_vec)])


# I_xx ≠ I_yy with a large ratio (a slender rocket is ~1:100; 2:5 keeps the body-cone rate high)
MASS = MassProperties(20.0, 0.1, 2.0, 5.0)
STATE0 = RigidBodyState(
    Vec3(1.0, -2.0, -30.0), Vec3(3.0, -1.0, 2.0), Quat.from_euler(0.3, 1.0, -0.2), Vec3(3.0, 1.5, -2.0)
)
T_END = 10.0


def test_helpers_match_independent_formulas():
    np.testing.assert_allclose(float(kinetic_energy(STATE0, MASS)), np_energy(STATE0, MASS), rtol=1e-15)
    np.testing.assert_allclose(
        np.asarray(angular_momentum_n(STATE0, MASS).to_array()), np_momentum_n(STATE0, MASS), atol=1e-13
    )  # |H| ~ 15: rounding only


@pytest.fixture(scope="module")
def torque_free_runs():
    """The same 10 s with h = 10 ms and 5 ms (|ω| ≈ 4 rad/s: h·|ω| = 0.04 and 0.02)."""
    coarse = integrate(STATE0, MASS, T_END / 1000, 1000)
    fine = integrate(STATE0, MASS, T_END / 2000, 2000)
    return coarse, fine


def test_torque_free_conserves_energy_momentum_and_unit_quaternion(torque_free_runs):
    (final, traj), (final_fine, _) = torque_free_runs
    e0, h0 = np_energy(STATE0, MASS), np_momentum_n(STATE0, MASS)
    e, hn = np_energy(final, MASS), np_momentum_n(final, MASS)
    # Bound from RK4's truncation: N·(h|ω|)⁵/120 = 1000·0.039⁵/120 ≈ 8e-7 relative after 1000 steps
    # of h|ω| = 0.039. Measured: |H_n| drift 8e-9, energy 4.5e-11 (an invariant of ω alone, whose
    # errors partly cancel), |q| − 1 6e-10. The bound is the tolerance for H_n and q; energy gets
    # 1e-8, still 200× its measured drift.
    assert abs(e / e0 - 1.0) < 1e-8
    np.testing.assert_allclose(hn, h0, rtol=0, atol=1e-6 * np.linalg.norm(h0))
    # Unit norm is an invariant of dq/dt = ½ q ⊗ ω that RK4 keeps to its own truncation order.
    q_norm = np.linalg.norm(np.asarray(traj.q_nb.to_array()), axis=1)
    assert np.max(np.abs(q_norm - 1.0)) < 1e-6
    # The errors are RK4 truncation: halving h divides them by ~2⁴ (> 8 leaves room for rounding).
    drift_coarse = np.linalg.norm(hn - h0)
    drift_fine = np.linalg.norm(np_momentum_n(final_fine, MASS) - h0)
    assert drift_fine < drift_coarse / 8
    # Translation is unaffected by the rotation: uniform motion, exactly linear in t (RK4 exact).
    np.testing.assert_allclose(
        np.asarray(final.r_n.to_array()),
        np.asarray(STATE0.r_n.to_array()) + np.asarray(STATE0.v_n.to_array()) * T_END,
        rtol=0,
        atol=1e-11,  # 1000 additions of O(1) increments to O(30) positions: rounding only
    )
    # The motion is non-trivial: the body rates and the attitude did change.
    assert np.linalg.norm(np.asarray(final.omega_b.to_array()) - np.asarray(STATE0.omega_b.to_array())) > 1.0


def test_axisymmetric_body_rates_closed_form(torque_free_runs):
    """Euler's equations with I_yy = I_zz: ω_x constant, (ω_y, ω_z) rotate at λ = (I_xx − I_yy)/I_yy·ω_x."""
    (_, traj), _ = torque_free_runs
    wx, wy0, wz0 = (float(c) for c in STATE0.omega_b)
    lam = (MASS.ixx - MASS.iyy) / MASS.iyy * wx
    t = T_END / 1000 * np.arange(1, 1001)
    # RK4 on a rotation at |λ| = 1.8 rad/s, h = 10 ms: local error (h|λ|)⁵/120 ≈ 1.6e-11 per step,
    # × 1000 steps × amplitude |ω_yz| = 2.5 rad/s ≈ 4e-8 rad/s (measured 3.6e-8): 1e-7.
    np.testing.assert_allclose(np.asarray(traj.omega_b.x), wx, rtol=1e-13)  # exactly constant up to rounding
    np.testing.assert_allclose(np.asarray(traj.omega_b.y), wy0 * np.cos(lam * t) - wz0 * np.sin(lam * t), atol=1e-7)
    np.testing.assert_allclose(np.asarray(traj.omega_b.z), wz0 * np.cos(lam * t) + wy0 * np.sin(lam * t), atol=1e-7)


def test_axisymmetric_attitude_closed_form(torque_free_runs):
    """Torque-free axisymmetric attitude: q(t) = exp(½ Ω t ĥ_n) ⊗ q0 ⊗ exp(½ σ t x̂_b), with the
    precession rate Ω = |H|/I_yy about the fixed H and the body-cone rate σ = ω_x (1 − I_xx/I_yy)."""
    (final, _), _ = torque_free_runs
    h0 = np_momentum_n(STATE0, MASS)
    big_omega = np.linalg.norm(h0) / MASS.iyy
    sigma = float(STATE0.omega_b.x) * (1.0 - MASS.ixx / MASS.iyy)
    space = Quat(*quat_exp(0.5 * big_omega * T_END * h0 / np.linalg.norm(h0)))
    spin = Quat(*quat_exp([0.5 * sigma * T_END, 0.0, 0.0]))
    expected = np.asarray((space * STATE0.q_nb * spin).to_array())
    got = np.asarray(final.q_nb.to_array())
    # The truncation bound ~8e-7 of the conservation test (measured 2.9e-8): 1e-6.
    np.testing.assert_allclose(got, expected * np.sign(got @ expected), atol=1e-6)
    assert np.linalg.norm(expected - np.asarray(STATE0.q_nb.to_array())) > 0.5  # it moved by O(1)


def test_force_and_moment_routing():
    """Body forces are rotated into NED, NED forces are not, gravity is +z (down); Euler's equation."""
    mass = MassProperties(4.0, 0.0, 0.5, 2.0)
    q_east = Quat.from_euler(jnp.pi / 2, 0.0, 0.0)  # nose east
    state = RigidBodyState(ZERO, Vec3(1.0, 2.0, 3.0), q_east, ZERO)
    d = rigid_body_derivatives(state, mass, Vec3(8.0, 0.0, 0.0), Vec3(0.0, 0.0, -4.0), Vec3(1.0, -6.0, 4.0), 9.80665)
    # a = (8 N east + 4 N up)/4 kg + g down
    np.testing.assert_allclose(np.asarray(d.v_n.to_array()), [0.0, 2.0, -1.0 + 9.80665], atol=1e-15)
    np.testing.assert_array_equal(np.asarray(d.r_n.to_array()), [1.0, 2.0, 3.0])  # dr/dt = v
    np.testing.assert_allclose(np.asarray(d.omega_b.to_array()), [2.0, -3.0, 2.0], rtol=1e-15)  # M/I, ω = 0
    np.testing.assert_array_equal(np.asarray(d.q_nb.to_array()), 0.0)  # no rate, no attitude change
    # the gyroscopic term: I ω̇ = −ω × (I ω), against NumPy
    spin = state._replace(omega_b=Vec3(3.0, 1.0, 0.0))
    d = rigid_body_derivatives(spin, mass, ZERO, ZERO, ZERO, 0.0)
    wdot = np.asarray(d.omega_b.to_array())
    w = np.array([3.0, 1.0, 0.0])
    inertia = np.diag([0.5, 2.0, 2.0])
    np.testing.assert_allclose(wdot, np.linalg.solve(inertia, -np.cross(w, inertia @ w)), atol=1e-15)


def test_uniform_gravity_parabola_is_exact():
    """With only gravity, RK4 integrates r = r0 + v0 t + ½ g t² exactly (the ODE solution is a polynomial)."""
    state = STATE0._replace(omega_b=Vec3(0.4, -0.3, 0.2))
    final, _ = integrate(state, MASS, 0.01, 700, 9.80665)
    t = 7.0
    expected = np.asarray(state.r_n.to_array()) + np.asarray(state.v_n.to_array()) * t + 0.5 * np.array([0, 0, 9.80665]) * t**2
    np.testing.assert_allclose(np.asarray(final.r_n.to_array()), expected, rtol=0, atol=1e-9)  # rounding of 700 steps
    np.testing.assert_allclose(
        np.asarray(final.v_n.to_array()), np.asarray(state.v_n.to_array()) + np.array([0, 0, 9.80665]) * t, atol=1e-11
    )


def test_combine_on_axis_parallel_axis_theorem():
    # a 2 kg part at x = 1 and a 6 kg part at x = −1/3: CG at 0 by construction
    parts = [(2.0, 1.0, 0.1, 0.5), (6.0, -1.0 / 3.0, 0.3, 0.7)]
    m = combine_on_axis(parts)
    assert m.mass == 8.0
    assert m.cg_x == pytest.approx(0.0, abs=1e-15)
    assert m.ixx == pytest.approx(0.4, rel=1e-15)  # axial inertias add (all on the axis)
    assert m.iyy == pytest.approx(0.5 + 0.7 + 2.0 * 1.0 + 6.0 / 9.0, rel=1e-14)  # + Σ m d²
    # independent check with point masses: two equal masses at ±a have I_yy = 2 m a² about the middle
    m2 = combine_on_axis([(1.5, 0.2 + 0.4, 0.0, 0.0), (1.5, 0.2 - 0.4, 0.0, 0.0)])
    assert (m2.cg_x, m2.iyy) == (pytest.approx(0.2, rel=1e-15), pytest.approx(2 * 1.5 * 0.16, rel=1e-14))
