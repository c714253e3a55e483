"""Vec3 and Hamilton quaternions against closed forms and scipy.spatial.transform.Rotation.

Quaternions are scalar-first [w, x, y, z] here; scipy's default is scalar-last, so every call to
scipy passes ``scalar_first=True``. Components are (N,) arrays, which the NamedTuple methods
handle elementwise, so one call tests N random cases.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rocketmc.math import Quat, Vec3, rk4_step

N = 200
# Products and sums of O(1) float64 numbers: a handful of roundings of 1.1e-16 each. 1e-13
# leaves a wide margin over that and is still ~1e13 times smaller than any sign or index error.
ROUND = 1e-13


@pytest.fixture(scope="module")
def rng():
    return np.random.default_rng(20240611)


def random_quats(rng, n=N, unit=True):
    a = rng.normal(size=(n, 4))
    if unit:
        a /= np.linalg.norm(a, axis=1, keepdims=True)
    else:
        a *= rng.uniform(0.2, 3.0, size=(n, 1))
    return a


def random_vecs(rng, n=N, scale=10.0):
    return rng.normal(size=(n, 3)) * scale


def qarr(q: Quat) -> np.ndarray:
    return np.asarray(q.to_array())


def varr(v: Vec3) -> np.ndarray:
    return np.asarray(v.to_array())


def same_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """b with the sign of each row flipped to match a (q and -q are the same rotation)."""
    return b * np.sign(np.sum(a * b, axis=-1, keepdims=True))


# ---------------------------------------------------------------------------------------- Vec3


def test_vec3_arithmetic_matches_numpy(rng):
    a, b, s = random_vecs(rng), random_vecs(rng), rng.normal(size=N)
    va, vb = Vec3.from_array(a), Vec3.from_array(b)
    np.testing.assert_array_equal(varr(va + vb), a + b)  # one rounding each, same as numpy: exact
    np.testing.assert_array_equal(varr(va - vb), a - b)
    np.testing.assert_array_equal(varr(-va), -a)
    np.testing.assert_array_equal(varr(va * s), a * s[:, None])
    # Python scalar on the left goes through __rmul__ (a NumPy array on the left would broadcast
    # over the tuple instead, so the code base always writes the Vec3 first).
    np.testing.assert_array_equal(varr(2.5 * va), a * 2.5)
    np.testing.assert_allclose(np.asarray(va.dot(vb)), np.einsum("ij,ij->i", a, b), rtol=0, atol=ROUND * 100)
    # |a|,|b| ~ 17: the dot product of magnitude ~300 carries ~1e-13 rounding; 1e-11 absolute.
    np.testing.assert_allclose(varr(va.cross(vb)), np.cross(a, b), rtol=0, atol=1e-11)
    np.testing.assert_allclose(np.asarray(va.norm()), np.linalg.norm(a, axis=1), rtol=ROUND)


def test_cross_and_dot_identities(rng):
    a, b, c = (Vec3.from_array(random_vecs(rng, scale=1.0)) for _ in range(3))
    axb = a.cross(b)
    # All quantities O(1): ROUND (1e-13) covers the roundings of a few products.
    np.testing.assert_allclose(np.asarray(axb.dot(a)), 0.0, atol=ROUND)  # a×b ⟂ a
    np.testing.assert_allclose(np.asarray(axb.dot(b)), 0.0, atol=ROUND)  # a×b ⟂ b
    np.testing.assert_allclose(varr(b.cross(a)), -varr(axb), atol=ROUND)  # anticommutative
    np.testing.assert_allclose(varr(a.cross(a)), 0.0, atol=0)  # exactly zero: x*y - y*x
    # Lagrange: |a×b|² + (a·b)² = |a|²|b|²
    np.testing.assert_allclose(
        np.asarray(axb.dot(axb) + a.dot(b) ** 2), np.asarray(a.dot(a) * b.dot(b)), rtol=ROUND, atol=ROUND
    )
    # scalar triple product is cyclic and equals det[a, b, c]
    det = np.linalg.det(np.stack([varr(a), varr(b), varr(c)], axis=1))
    np.testing.assert_allclose(np.asarray(axb.dot(c)), det, atol=ROUND)
    np.testing.assert_allclose(np.asarray(b.cross(c).dot(a)), det, atol=ROUND)
    # BAC-CAB: a×(b×c) = b(a·c) − c(a·b)
    np.testing.assert_allclose(varr(a.cross(b.cross(c))), varr(b * a.dot(c) - c * a.dot(b)), atol=ROUND)
    # right-handed basis
    x, y, z = Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0), Vec3(0.0, 0.0, 1.0)
    np.testing.assert_array_equal(varr(x.cross(y)), [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(varr(y.cross(z)), [1.0, 0.0, 0.0])


def test_vec3_array_round_trip_and_zeros(rng):
    a = random_vecs(rng)
    np.testing.assert_array_equal(varr(Vec3.from_array(a)), a)
    z = Vec3.zeros(jnp.ones(5))
    assert all(c.shape == (5,) and c.dtype == jnp.float64 for c in z)
    np.testing.assert_array_equal(varr(z), np.zeros((5, 3)))


# ---------------------------------------------------------------------------------- quaternion


def test_hamilton_product_basis():
    """i j = k, j k = i, k i = j, i² = j² = k² = ijk = −1 (Hamilton's rules)."""
    one, i, j, k = (Quat.from_array(np.eye(4)[n]) for n in range(4))
    np.testing.assert_array_equal(qarr(i * j), qarr(k))
    np.testing.assert_array_equal(qarr(j * k), qarr(i))
    np.testing.assert_array_equal(qarr(k * i), qarr(j))
    np.testing.assert_array_equal(qarr(j * i), -qarr(k))
    for u in (i, j, k):
        np.testing.assert_array_equal(qarr(u * u), -qarr(one))
    np.testing.assert_array_equal(qarr(i * j * k), -qarr(one))


def test_product_associative(rng):
    a, b, c = (Quat.from_array(random_quats(rng, unit=False)) for _ in range(3))
    # Non-unit factors up to 3 in norm: products up to ~30, a few roundings each: 1e-12 absolute.
    np.testing.assert_allclose(qarr((a * b) * c), qarr(a * (b * c)), rtol=0, atol=1e-12)


def test_norm_multiplicative(rng):
    a, b = (Quat.from_array(random_quats(rng, unit=False)) for _ in range(2))
    np.testing.assert_allclose(np.asarray((a * b).norm()), np.asarray(a.norm() * b.norm()), rtol=ROUND)


def test_product_matches_scipy_composition(rng):
    """Rotation(a ⊗ b) = Rotation(a) ∘ Rotation(b): apply b first, then a."""
    a, b = random_quats(rng), random_quats(rng)
    ref = (Rotation.from_quat(a, scalar_first=True) * Rotation.from_quat(b, scalar_first=True)).as_quat(
        scalar_first=True
    )
    got = qarr(Quat.from_array(a) * Quat.from_array(b))
    np.testing.assert_allclose(same_rotation(got, ref), got, atol=ROUND)


def test_conjugate_is_inverse(rng):
    q = Quat.from_array(random_quats(rng, unit=False))
    n2 = np.asarray(q.norm()) ** 2
    expected = np.stack([n2, 0 * n2, 0 * n2, 0 * n2], axis=1)  # q ⊗ q* = |q|² (1, 0, 0, 0)
    np.testing.assert_allclose(qarr(q * q.conj()), expected, rtol=ROUND, atol=ROUND * 10)
    np.testing.assert_allclose(qarr(q.conj() * q), expected, rtol=ROUND, atol=ROUND * 10)
    u = q.normalized()
    np.testing.assert_allclose(np.asarray(u.norm()), 1.0, rtol=ROUND)
    np.testing.assert_allclose(qarr(u * u.conj()), np.tile([1.0, 0, 0, 0], (N, 1)), atol=ROUND)


def test_rotate_matches_scipy(rng):
    q, v = random_quats(rng), random_vecs(rng)
    rot = Rotation.from_quat(q, scalar_first=True)
    qq, vv = Quat.from_array(q), Vec3.from_array(v)
    # |v| ~ 17: scipy builds a matrix, we use the Rodrigues form; both round at ~1e-15 |v|.
    np.testing.assert_allclose(varr(qq.rotate(vv)), rot.apply(v), rtol=0, atol=1e-12)
    np.testing.assert_allclose(varr(qq.rotate_inverse(vv)), rot.apply(v, inverse=True), rtol=0, atol=1e-12)


def test_rotate_equals_sandwich_product(rng):
    """rotate(v) is q ⊗ (0, v) ⊗ q* (the definition) for unit q."""
    q, v = Quat.from_array(random_quats(rng)), random_vecs(rng)
    pure = Quat.from_array(np.concatenate([np.zeros((N, 1)), v], axis=1))
    sandwich = qarr(q * pure * q.conj())
    np.testing.assert_allclose(sandwich[:, 0], 0.0, atol=1e-12)  # |v| ~ 17, see above
    np.testing.assert_allclose(varr(q.rotate(Vec3.from_array(v))), sandwich[:, 1:], atol=1e-12)


def test_rotation_preserves_norm_and_inverts(rng):
    q, v = Quat.from_array(random_quats(rng)), Vec3.from_array(random_vecs(rng))
    w = q.rotate(v)
    np.testing.assert_allclose(np.asarray(w.norm()), np.asarray(v.norm()), rtol=ROUND)
    np.testing.assert_allclose(varr(q.rotate_inverse(w)), varr(v), atol=1e-12)  # |v| ~ 17
    # composition: rotating by a ⊗ b is rotating by b then by a
    a, b = Quat.from_array(random_quats(rng)), Quat.from_array(random_quats(rng))
    np.testing.assert_allclose(varr((a * b).rotate(v)), varr(a.rotate(b.rotate(v))), atol=1e-12)


def test_from_euler_matches_scipy(rng):
    yaw = rng.uniform(-np.pi, np.pi, N)
    pitch = rng.uniform(-np.pi / 2, np.pi / 2, N)
    roll = rng.uniform(-np.pi, np.pi, N)
    # Intrinsic z-y'-x'' (scipy upper case) is the aerospace 3-2-1 sequence.
    ref = Rotation.from_euler("ZYX", np.stack([yaw, pitch, roll], axis=1)).as_quat(scalar_first=True)
    got = qarr(Quat.from_euler(yaw, pitch, roll))
    np.testing.assert_allclose(got, same_rotation(got, ref), atol=ROUND)
    np.testing.assert_allclose(np.linalg.norm(got, axis=1), 1.0, rtol=ROUND)


@pytest.mark.parametrize(
    "yaw_deg, pitch_deg, roll_deg, body, ned",
    [
        (90.0, 0.0, 0.0, (1, 0, 0), (0, 1, 0)),  # yaw 90°: the nose points east
        (0.0, 90.0, 0.0, (1, 0, 0), (0, 0, -1)),  # pitch +90°: the nose points up (−z in NED)
        (0.0, 0.0, 90.0, (0, 1, 0), (0, 0, 1)),  # roll +90°: the right wing points down
        (130.0, 84.0, 0.0, (1, 0, 0), None),  # the Lynx rail (checked against the closed form)
    ],
)
def test_from_euler_frame_conventions(yaw_deg, pitch_deg, roll_deg, body, ned):
    """q_nb rotates body vectors into NED with the aerospace sign conventions."""
    y, p, r = np.deg2rad([yaw_deg, pitch_deg, roll_deg])
    if ned is None:  # nose direction (cosθ cosψ, cosθ sinψ, −sinθ)
        ned = (np.cos(p) * np.cos(y), np.cos(p) * np.sin(y), -np.sin(p))
    got = varr(Quat.from_euler(y, p, r).rotate(Vec3(*map(float, body))))
    np.testing.assert_allclose(got, ned, atol=ROUND)


def test_to_euler_inverts_from_euler(rng):
    yaw = rng.uniform(-np.pi, np.pi, N)
    pitch = rng.uniform(-np.deg2rad(89.0), np.deg2rad(89.0), N)  # away from the ±90° singularity
    roll = rng.uniform(-np.pi, np.pi, N)
    y, p, r = Quat.from_euler(yaw, pitch, roll).to_euler()
    # arcsin near ±89° amplifies rounding by 1/cos(89°) ≈ 57: 1e-11 rad covers it.
    np.testing.assert_allclose(np.asarray(y), yaw, atol=1e-11)
    np.testing.assert_allclose(np.asarray(p), pitch, atol=1e-11)
    np.testing.assert_allclose(np.asarray(r), roll, atol=1e-11)
    # and agrees with scipy's decomposition of a random rotation
    q = random_quats(rng)
    ref = Rotation.from_quat(q, scalar_first=True).as_euler("ZYX")
    got = np.stack([np.asarray(a) for a in Quat.from_array(q).to_euler()], axis=1)
    np.testing.assert_allclose(got, ref, atol=1e-9)  # random pitches can come within ~0.1° of ±90°


def quat_exp(half_angle_vec: np.ndarray) -> np.ndarray:
    """exp of the pure quaternion (0, u): (cos|u|, û sin|u|)."""
    a = np.linalg.norm(half_angle_vec, axis=-1, keepdims=True)
    return np.concatenate([np.cos(a), np.sinc(a / np.pi) * half_angle_vec], axis=-1)


@pytest.fixture(scope="module")
def integrate_constant_rate():
    """Integrates dq/dt = ½ q ⊗ (0, ω) with RK4 (jit once, reused)."""

    def run(q0, omega, t_end, n_steps):
        h = t_end / n_steps

        def f(t, q):
            return q.derivative(omega), None

        def body(i, q):
            return rk4_step(f, i * h, q, h)[0]

        return jax.lax.fori_loop(0, n_steps, body, q0)

    return jax.jit(run, static_argnums=3)


def test_quaternion_derivative_constant_rate_closed_form(rng, integrate_constant_rate):
    """Constant body rate ω for time T: q(T) = q0 ⊗ exp(ω T / 2)."""
    n = 20
    q0 = random_quats(rng, n)
    omega = rng.normal(size=(n, 3)) * 2.0  # |ω| up to ~6 rad/s
    t_end, steps = 1.0, 200
    q_t = qarr(integrate_constant_rate(Quat.from_array(q0), Vec3.from_array(omega), t_end, steps))
    expected = qarr(Quat.from_array(q0) * Quat.from_array(quat_exp(omega * t_end / 2)))
    # RK4 on the linear ODE with rate |ω|/2 ≤ 3/s: global error ≈ T (|ω|h/2)⁴ |ω|/2 / 120 ≲ 3e-10.
    np.testing.assert_allclose(q_t, expected, atol=1e-9)
    # The unnormalised RK4 solution stays on the unit sphere to the same order.
    np.testing.assert_allclose(np.linalg.norm(q_t, axis=1), 1.0, atol=1e-9)
    # The closed form is not trivially satisfied: the attitude moved by O(1).
    assert np.min(np.linalg.norm(q_t - q0, axis=1)) > 0.05


def test_quaternion_derivative_is_body_rate():
    """A body rate about body z (yaw) turns the nose from north toward east."""
    q = Quat(1.0, 0.0, 0.0, 0.0)
    d = qarr(q.derivative(Vec3(0.0, 0.0, 2.0)))
    np.testing.assert_array_equal(d, [0.0, 0.0, 0.0, 1.0])  # ½ (1,0,0,0) ⊗ (0,0,0,2), exact


def test_methods_under_vmap_match_unbatched(rng):
    """jax.vmap over NamedTuple components gives the per-element results (the batched flight code)."""
    q, v = random_quats(rng, 16), random_vecs(rng, 16)
    qs, vs = Quat.from_array(jnp.asarray(q)), Vec3.from_array(jnp.asarray(v))
    fn = jax.jit(jax.vmap(lambda a, b: (a.rotate(b), a.derivative(b), a * a.conj(), a.to_euler())))
    rot, der, ident, eul = fn(qs, vs)
    for i in range(16):
        qi, vi = Quat(*q[i]), Vec3(*v[i])
        # same float64 operations batched or not; vectorised transcendental functions (to_euler's
        # atan2/asin) may differ in the last ulp: 1e-14 absolute on O(1..20) values.
        np.testing.assert_allclose(np.asarray(rot.to_array())[i], varr(qi.rotate(vi)), rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(np.asarray(der.to_array())[i], qarr(qi.derivative(vi)), rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(np.asarray(ident.to_array())[i], [1.0, 0, 0, 0], atol=ROUND)
        np.testing.assert_allclose([float(e[i]) for e in eul], [float(e) for e in qi.to_euler()], atol=1e-14)
