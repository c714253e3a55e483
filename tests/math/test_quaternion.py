"""Quaternions and vectors against scipy's Rotation (independent implementation)."""

import jax
import jax.numpy as jnp
import numpy as np
from scipy.spatial.transform import Rotation

from rocketmc.math import Quat, Vec3, rk4_step

RNG = np.random.default_rng(42)
QUATS = RNG.normal(size=(50, 4))
QUATS /= np.linalg.norm(QUATS, axis=1, keepdims=True)
VECS = RNG.normal(size=(50, 3))


def scipy_rotation(q):  # scipy stores quaternions scalar last
    return Rotation.from_quat([q[1], q[2], q[3], q[0]])


def test_rotate_matches_scipy():
    for q, v in zip(QUATS, VECS):
        expected = scipy_rotation(q).apply(v)
        np.testing.assert_allclose(Quat(*q).rotate(Vec3(*v)).to_array(), expected, atol=1e-12)  # rounding
        np.testing.assert_allclose(Quat(*q).rotate_inverse(Vec3(*expected)).to_array(), v, atol=1e-12)


def test_product_matches_scipy_composition():
    for a, b in zip(QUATS[:25], QUATS[25:]):
        product = (Quat(*a) * Quat(*b)).to_array()
        expected = (scipy_rotation(a) * scipy_rotation(b)).as_quat()  # scalar last, sign ambiguous
        expected = np.roll(expected, 1) * np.sign(np.roll(expected, 1)[0] * product[0])
        np.testing.assert_allclose(product, expected, atol=1e-12)
        assert abs(float((Quat(*a) * Quat(*b)).norm()) - 1.0) < 1e-14  # |ab| = |a||b|
    identity = (Quat(*QUATS[0]) * Quat(*QUATS[0]).conj()).to_array()
    np.testing.assert_allclose(identity, [1, 0, 0, 0], atol=1e-15)


def test_euler_matches_scipy_and_inverts():
    for yaw, pitch, roll in RNG.uniform([-3, -1.4, -3], [3, 1.4, 3], size=(20, 3)):
        q = Quat.from_euler(yaw, pitch, roll)
        expected = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_quat()  # intrinsic 3-2-1
        np.testing.assert_allclose(np.abs(np.dot(q.to_array(), np.roll(expected, 1))), 1.0, atol=1e-12)
        np.testing.assert_allclose(q.to_euler(), (yaw, pitch, roll), atol=1e-10)  # arcsin near ±1.4 rad


def test_cross_and_dot():
    for a, b in zip(VECS[:25], VECS[25:]):
        np.testing.assert_allclose(Vec3(*a).cross(Vec3(*b)).to_array(), np.cross(a, b), atol=1e-14)
        np.testing.assert_allclose(Vec3(*a).dot(Vec3(*b)), np.dot(a, b), atol=1e-14)


def test_kinematics_constant_rate_closed_form():
    # dq/dt = ½ q ⊗ ω with constant ω: q(T) = q0 ⊗ exp(ωT/2) = q0 ⊗ [cos(|ω|T/2), sin(|ω|T/2) ω/|ω|].
    omega = np.array([0.3, -1.2, 2.0])
    q0, T, n = Quat(*QUATS[0]), 2.0, 400
    f = lambda t, q: (q.derivative(Vec3(*omega)), None)  # noqa: E731
    step = jax.jit(lambda q: rk4_step(f, 0.0, q, T / n)[0])
    q = q0
    for _ in range(n):
        q = step(q)
    w = np.linalg.norm(omega)
    expected = q0 * Quat(np.cos(w * T / 2), *(np.sin(w * T / 2) * omega / w))
    np.testing.assert_allclose(q.to_array(), expected.to_array(), atol=1e-9)  # RK4 error ~ (hw)^4 T w ≈ 1e-10
    assert abs(float(q.norm()) - 1.0) < 1e-9


def test_vmap_over_components():
    qs = Quat.from_array(jnp.asarray(QUATS))
    vs = Vec3.from_array(jnp.asarray(VECS))
    rotated = jax.vmap(lambda q, v: q.rotate(v))(qs, vs).to_array()
    np.testing.assert_allclose(rotated, np.array([scipy_rotation(q).apply(v) for q, v in zip(QUATS, VECS)]), atol=1e-12)
