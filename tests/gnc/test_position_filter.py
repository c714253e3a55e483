"""The position/velocity Kalman filter (docs/gnc.md §3) against independent references: a plain 6-state numpy Kalman
filter (the decoupled per-axis form is exact), the closed form of the prediction with a constant acceleration,
the discrete algebraic Riccati equation (scipy) for the steady state, and a Monte Carlo in which the truth follows
the filter's own model, whose NEES must be chi-square distributed. Then grad and vmap.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.linalg
import scipy.stats

from rocketmc.campaign.model import position_tuning
from rocketmc.campaign.schema import PositionFilterConfig
from rocketmc.gnc.position_filter import (
    PositionEstimate,
    PositionTuning,
    altitude_nis,
    altitude_update,
    gnss_nis,
    gnss_update,
    initial_position,
    position_nees,
    propagate_position,
)
from rocketmc.math.vectors import Vec3
from rocketmc.pytree import tree_where

T = 0.02  # the thesis's period [s] (50 Hz)
# Strong updates (GNSS of a few metres, a barometer of 2 m) so that gains are far from 0 and 1 and every term of
# the update matters; the thesis's tuning de-weights GNSS ~100× and leaves K ~ 1e-3.
SHARP = PositionTuning(
    position_noise=0.7,
    velocity_noise=0.3,
    gnss_position_std=Vec3(3.0, 4.0, 6.0),
    gnss_velocity_std=Vec3(0.5, 0.6, 0.9),
    altitude_std=2.0,
    initial_position_std=5.0,
    initial_velocity_std=2.0,
)
THESIS = position_tuning(PositionFilterConfig())
"""The thesis's tuning (docs/gnc.md §3): the schema's defaults."""

propagate_jit = jax.jit(propagate_position)
gnss_jit = jax.jit(gnss_update, static_argnames="horizontal_only")
altitude_jit = jax.jit(altitude_update)


def vec(a) -> Vec3:
    return Vec3(*(jnp.asarray(float(x)) for x in a))


def to_dense(est: PositionEstimate) -> tuple[np.ndarray, np.ndarray]:
    """The 6-state (r_N, r_E, r_D, v_N, v_E, v_D) mean and covariance of a decoupled estimate (host, tests only)."""
    x = np.concatenate([np.asarray(est.r_n.to_array()), np.asarray(est.v_n.to_array())])
    p = np.zeros((6, 6))
    for i in range(3):
        p[i, i], p[i, i + 3], p[i + 3, i], p[i + 3, i + 3] = est.p_rr[i], est.p_rv[i], est.p_rv[i], est.p_vv[i]
    return x, p


# --- the plain 6-state Kalman filter, the reference ---------------------------------------------------------------


def ref_propagate(x, p, u, dt, tuning):
    i3, z3 = np.eye(3), np.zeros((3, 3))
    f = np.block([[i3, dt * i3], [z3, i3]])
    g = np.vstack([0.5 * dt**2 * i3, dt * i3])
    q = dt * np.diag([float(tuning.position_noise) ** 2] * 3 + [float(tuning.velocity_noise) ** 2] * 3)
    return f @ x + g @ u, f @ p @ f.T + q


def ref_update(x, p, z, h, r):
    s = h @ p @ h.T + r
    k = p @ h.T @ np.linalg.inv(s)
    m = np.eye(6) - k @ h
    return x + k @ (z - h @ x), m @ p @ m.T + k @ r @ k.T


def gnss_model(tuning, horizontal_only):
    rows = [0, 1, 3, 4] if horizontal_only else list(range(6))
    var = np.concatenate([np.asarray(tuning.gnss_position_std, float), np.asarray(tuning.gnss_velocity_std, float)])
    return np.eye(6)[rows], np.diag(var[rows] ** 2), rows


def ref_nees(x, p, truth):
    e = x - truth
    return float(e @ np.linalg.solve(p, e))


@pytest.mark.parametrize("tuning", [SHARP, THESIS], ids=["sharp", "thesis"])
def test_decoupled_filter_equals_the_6_state_filter(tuning):
    """Random inputs, periods and a random sequence of no update, full GNSS, horizontal GNSS, altitude, or GNSS and
    altitude together: means, covariances and NEES equal numpy's 6-state filter step by step."""
    rng = np.random.default_rng(7)
    r0 = np.array([1.0, -2.0, -1.6])
    est = initial_position(vec(r0), tuning)
    x = np.concatenate([r0, np.zeros(3)])
    p = np.diag([float(tuning.initial_position_std) ** 2] * 3 + [float(tuning.initial_velocity_std) ** 2] * 3)
    h_alt, r_alt = -np.eye(6)[[2]], np.array([[float(tuning.altitude_std) ** 2]])
    kinds = set()
    for _ in range(300):
        u, dt = rng.normal(0.0, 20.0, 3), rng.uniform(0.005, 0.05)
        est = propagate_jit(est, vec(u), dt, tuning)
        x, p = ref_propagate(x, p, u, dt, tuning)
        kind = rng.integers(5)
        kinds.add(int(kind))
        if kind in (1, 2, 4):
            horizontal = kind == 2
            z = x + rng.normal(0.0, 5.0, 6)
            est = gnss_jit(est, vec(z[:3]), vec(z[3:]), tuning, horizontal_only=horizontal)
            h, r, rows = gnss_model(tuning, horizontal)
            x, p = ref_update(x, p, z[rows], h, r)
        if kind in (3, 4):
            altitude = -x[2] + rng.normal(0.0, 3.0)
            est = altitude_jit(est, altitude, tuning)
            x, p = ref_update(x, p, np.array([altitude]), h_alt, r_alt)
        got_x, got_p = to_dense(est)
        # 1e-10 of each quantity's scale: both filters round differently (closed-form 2×2 inverse against LU) at a
        # few ulps per step, and 300 steps of a stable filter do not amplify that beyond ~1e-13 relative.
        np.testing.assert_allclose(got_x, x, rtol=0, atol=1e-10 * max(1.0, np.abs(x).max()))
        np.testing.assert_allclose(got_p, p, rtol=0, atol=1e-10 * np.abs(p).max())
        truth = x + rng.normal(0.0, 1.0, 6)
        nees = float(position_nees(est, vec(truth[:3]), vec(truth[3:])))
        assert nees == pytest.approx(ref_nees(x, p, truth), rel=1e-10)  # the same ~1e-13 rounding, through P⁻¹
    assert kinds == {0, 1, 2, 3, 4}


def test_horizontal_gnss_leaves_the_down_axis_untouched():
    est = propagate_jit(initial_position(vec([0.0, 0.0, -1.6]), SHARP), vec([1.0, 2.0, -30.0]), T, SHARP)
    new = gnss_jit(est, vec([5.0, 5.0, -50.0]), vec([1.0, 1.0, -9.0]), SHARP, horizontal_only=True)
    for name in ("r_n", "v_n", "p_rr", "p_rv", "p_vv"):
        assert float(getattr(new, name).z) == float(getattr(est, name).z)  # passed through, bit for bit
        assert float(getattr(new, name).x) != float(getattr(est, name).x)


# --- closed forms -------------------------------------------------------------------------------------------------


def test_prediction_matches_its_closed_form():
    """No updates, constant acceleration a, n steps of T, t = nT. Mean: the exact kinematics v = v0 + a t,
    r = r0 + v0 t + ½ a t² (G = [½T² I; T I] is exact for a held acceleration; the thesis's [0; T I] lags ½ a t T).

    Covariance: summing P⁻ = F P Fᵀ + T·diag(σ_r², σ_v²) per axis,
      p_vv(t) = c0 + σ_v² t,
      p_rv(t) = b0 + c0 t + σ_v² t (t − T)/2,
      p_rr(t) = a0 + 2 b0 t + c0 t² + σ_r² t + σ_v² t (t − T)(2t − T)/6.
    The continuous white-noise-acceleration model with P0 (Ṗ = A P + P Aᵀ + diag(σ_r², σ_v²)) gives
    c0 + σ_v² t, b0 + c0 t + σ_v² t²/2 and a0 + 2 b0 t + c0 t² + σ_r² t + σ_v² t³/3: its exact discretization has
    Q_d = σ_v² [[T³/3, T²/2], [T²/2, T]] + diag(σ_r² T, 0), and the thesis's diagonal Q drops the off-diagonal and
    T³ terms. So p_vv is compared with the continuous form itself, p_rv and p_rr with the continuous form less
    σ_v² t T/2 and σ_v² (t² T/2 − t T²/6)."""
    n = 500
    t = n * T
    r0, v0, a = np.array([3.0, -4.0, -1.6]), np.array([0.5, 1.0, -2.0]), np.array([0.3, -0.7, -60.0])
    a0, b0, c0 = np.array([2.0, 3.0, 4.0]), np.array([0.3, -0.2, 0.5]), np.array([1.5, 0.8, 2.5])
    est = PositionEstimate(vec(r0), vec(v0), vec(a0), vec(b0), vec(c0))
    tuning = SHARP

    def body(e, _):
        return propagate_position(e, vec(a), T, tuning), None

    est, _ = jax.lax.scan(body, est, None, length=n)
    sr2, sv2 = float(tuning.position_noise) ** 2, float(tuning.velocity_noise) ** 2
    # n = 500 accumulated additions round at ~n·eps ≈ 1e-13 relative; 1e-11 leaves room and is far below the
    # O(T) terms distinguishing the forms (~1e-3 relative here).
    tol = dict(rtol=1e-11, atol=1e-11)
    np.testing.assert_allclose(est.v_n.to_array(), v0 + a * t, **tol)
    np.testing.assert_allclose(est.r_n.to_array(), r0 + v0 * t + 0.5 * a * t**2, **tol)
    np.testing.assert_allclose(est.p_vv.to_array(), c0 + sv2 * t, **tol)
    continuous_rv = b0 + c0 * t + sv2 * t**2 / 2
    continuous_rr = a0 + 2 * b0 * t + c0 * t**2 + sr2 * t + sv2 * t**3 / 3
    np.testing.assert_allclose(est.p_rv.to_array(), continuous_rv - sv2 * t * T / 2, **tol)
    np.testing.assert_allclose(est.p_rr.to_array(), continuous_rr - sv2 * (t**2 * T / 2 - t * T**2 / 6), **tol)
    # the O(T) terms are not roundoff: the discrete filter really differs from the continuous form
    assert abs(float(est.p_rr.z) - continuous_rr[2]) > 1e4 * 1e-11 * continuous_rr[2]


# --- steady state -------------------------------------------------------------------------------------------------


def steady_state(tuning, steps, gnss=True, altitude=False):
    def body(e, _):
        e = propagate_position(e, Vec3(0.0, 0.0, 0.0), T, tuning)
        if gnss:
            e = gnss_update(e, Vec3(0.0, 0.0, 0.0), Vec3(0.0, 0.0, 0.0), tuning)
        if altitude:
            e = altitude_update(e, 0.0, tuning)
        return e, None

    est, _ = jax.lax.scan(body, initial_position(Vec3(0.0, 0.0, 0.0), tuning), None, length=steps)
    prior = propagate_position(est, Vec3(0.0, 0.0, 0.0), T, tuning)
    return prior, est


def dare_axis(tuning, h, r):
    """A priori and a posteriori steady covariance of one axis from scipy's DARE (the filter's dual: A = Fᵀ,
    B = Hᵀ)."""
    f = np.array([[1.0, T], [0.0, 1.0]])
    q = T * np.diag([float(tuning.position_noise) ** 2, float(tuning.velocity_noise) ** 2])
    prior = scipy.linalg.solve_discrete_are(f.T, h.T, q, r)
    post = prior - prior @ h.T @ np.linalg.solve(h @ prior @ h.T + r, h @ prior)
    return prior, post


def elements(est, i):
    return np.array([[est.p_rr[i], est.p_rv[i]], [est.p_rv[i], est.p_vv[i]]], dtype=float)


@pytest.mark.parametrize("tuning, steps", [(SHARP, 3000), (THESIS, 20000)], ids=["sharp", "thesis"])
def test_gnss_steady_state_solves_the_riccati_equation(tuning, steps):
    """Repeated propagate + GNSS update converge, per axis, to scipy's DARE solution (a priori) and its update (a
    posteriori). The slowest steady closed-loop pole, |eig((I − K) F)|, is 0.9833 per step for SHARP (τ = 1.2 s)
    and 0.9982 for the thesis's de-weighted GNSS (τ = 11 s); the Riccati iteration's error shrinks as its square,
    so 3000 and 20000 steps are ~50 and ~35 time constants: converged to roundoff."""
    prior, post = steady_state(tuning, steps)
    for i in range(3):
        r = np.diag([float(tuning.gnss_position_std[i]) ** 2, float(tuning.gnss_velocity_std[i]) ** 2])
        want_prior, want_post = dare_axis(tuning, np.eye(2), r)
        # 1e-9 relative: the iteration is then a fixed point of the Riccati map to an ulp; scipy's Schur solution
        # leaves a residual of ~1e-12 relative, which the thesis's slow pole (1/(1 − ρ²) ~ 300) turns into an
        # error of 2e-10 (measured).
        np.testing.assert_allclose(elements(post, i), want_post, rtol=1e-9)
        np.testing.assert_allclose(elements(prior, i), want_prior, rtol=1e-9)


def test_altitude_steady_state_solves_the_riccati_equation():
    """The down axis under altitude updates alone (H = [1, 0] on (r_D, v_D); the sign of H does not enter P)."""
    prior, post = steady_state(SHARP, 6000, gnss=False, altitude=True)
    want_prior, want_post = dare_axis(SHARP, np.array([[1.0, 0.0]]), np.array([[float(SHARP.altitude_std) ** 2]]))
    np.testing.assert_allclose(elements(post, 2), want_post, rtol=1e-9)  # as for GNSS above
    np.testing.assert_allclose(elements(prior, 2), want_prior, rtol=1e-9)


# --- consistency --------------------------------------------------------------------------------------------------


def test_nees_is_chi_square_when_the_truth_follows_the_model():
    """300 runs of 400 ticks (8 s at 50 Hz): the truth starts from N(x̂0, P0) and follows x⁺ = F x + G u + w,
    w ~ N(0, Q), G = [½T² I; T I], with a known acceleration profile; each tick has an altitude, every 5th a horizontal GNSS fix and
    every 25th a full one, each with the filter's own R. Then M·NEES averaged over M runs is chi-square with 6M
    dof at every tick: its 95 % band must hold the average at ≥ 90 % of ticks (95 % expected; the averages of
    neighbouring ticks are strongly correlated, so excursions come in runs and the fraction scatters more than
    a binomial's), and the average over all ticks must be 6 within 5 %."""
    tuning = SHARP
    m, n = 300, 400
    rng = np.random.default_rng(2024)
    sr, sv = float(tuning.position_noise), float(tuning.velocity_noise)
    gp, gv = np.asarray(tuning.gnss_position_std, float), np.asarray(tuning.gnss_velocity_std, float)
    sh = float(tuning.altitude_std)
    r0_hat = np.array([0.0, 0.0, -1.6])
    tk = T * np.arange(n)
    accel = np.stack([2.0 * np.sin(tk), np.full(n, -1.0), -30.0 * (tk < 3.0) + 9.80665 * (tk >= 3.0) - 5.0], -1)
    r = r0_hat + rng.normal(0.0, float(tuning.initial_position_std), (m, 3))
    v = rng.normal(0.0, float(tuning.initial_velocity_std), (m, 3))
    r_true, v_true, z_gnss, z_alt = [], [], [], []
    for k in range(n):
        w_r, w_v = rng.normal(0.0, sr * np.sqrt(T), (m, 3)), rng.normal(0.0, sv * np.sqrt(T), (m, 3))  # Q
        r, v = r + T * (v + 0.5 * T * accel[k]) + w_r, v + T * accel[k] + w_v
        r_true.append(r)
        v_true.append(v)
        z_gnss.append(np.concatenate([r + rng.normal(0.0, 1.0, (m, 3)) * gp, v + rng.normal(0.0, 1.0, (m, 3)) * gv],
                                     -1))
        z_alt.append(-r[:, 2] + rng.normal(0.0, sh, m))
    r_true, v_true, z_gnss, z_alt = (np.stack(a, 1) for a in (r_true, v_true, z_gnss, z_alt))  # (m, n, ...)
    accel = jnp.asarray(accel)
    full = np.arange(n) % 25 == 24
    horizontal = jnp.asarray((np.arange(n) % 5 == 4) & ~full)  # one fix, one update: never the same fix twice
    full = jnp.asarray(full)

    def run(r_t, v_t, zg, za):
        def body(est, k):
            est = propagate_position(est, Vec3.from_array(accel[k]), T, tuning)
            zp, zv = Vec3.from_array(zg[k, :3]), Vec3.from_array(zg[k, 3:])
            est = tree_where(horizontal[k], gnss_update(est, zp, zv, tuning, horizontal_only=True), est)
            est = tree_where(full[k], gnss_update(est, zp, zv, tuning), est)
            est = altitude_update(est, za[k], tuning)
            return est, position_nees(est, Vec3.from_array(r_t[k]), Vec3.from_array(v_t[k]))

        return jax.lax.scan(body, initial_position(Vec3.from_array(jnp.asarray(r0_hat)), tuning), jnp.arange(n))[1]

    nees = np.asarray(jax.jit(jax.vmap(run))(r_true, v_true, z_gnss, z_alt))
    average = nees.mean(0)
    low, high = scipy.stats.chi2.ppf([0.025, 0.975], 6 * m) / m
    inside = np.mean((average > low) & (average < high))
    assert inside >= 0.90, inside
    assert average.mean() == pytest.approx(6.0, rel=0.05), average.mean()  # its sd here is ~1 %: 5 % is 5 sd


# --- transformations ----------------------------------------------------------------------------------------------


def few_steps(tuning, accel_down):
    est = initial_position(Vec3(0.0, 0.0, -1.6), tuning)
    for k in range(4):
        est = propagate_position(est, Vec3(0.1, -0.2, accel_down), T, tuning)
        est = altitude_update(est, 1.6 + 0.05 * k, tuning)
    est = gnss_update(est, Vec3(1.0, 2.0, -3.0), Vec3(0.1, 0.2, -0.3), tuning)
    est = gnss_update(est, Vec3(1.0, 2.0, -3.0), Vec3(0.1, 0.2, -0.3), tuning, horizontal_only=True)
    return est


def test_grad_is_finite_and_matches_finite_differences():
    def loss(tuning, accel_down):
        est = few_steps(tuning, accel_down)
        return est.r_n.z + est.v_n.z + est.p_rr.z + est.p_rv.x + position_nees(est, Vec3(0.0, 0.0, -1.0),
                                                                               Vec3(0.0, 0.0, 0.0))

    tuning = SHARP
    g_tuning, g_accel = jax.grad(loss, argnums=(0, 1))(tuning, -20.0)
    leaves = jax.tree_util.tree_leaves(g_tuning) + [g_accel]
    assert all(np.isfinite(float(x)) for x in leaves)
    assert any(float(x) != 0.0 for x in leaves)
    h = 1e-5
    fd = (loss(tuning, -20.0 + h) - loss(tuning, -20.0 - h)) / (2 * h)
    # central difference on a loss of ~0.5 with a slope of ~6e-3: rounding eps·|f|/h ~ 5e-12 (~1e-9 relative,
    # 3e-9 measured) dominates the truncation h² f'''/6
    assert float(g_accel) == pytest.approx(float(fd), rel=1e-6)


def test_vmap_equals_single_runs():
    downs = jnp.array([-30.0, -10.0, 0.0, 9.8])
    batched = jax.vmap(lambda a: few_steps(SHARP, a))(downs)
    for i, a in enumerate(downs):
        one = few_steps(SHARP, a)
        for got, want in zip(jax.tree_util.tree_leaves(batched), jax.tree_util.tree_leaves(one)):
            # the same operations per lane; vectorized and scalar code may contract or order them differently
            assert float(got[i]) == pytest.approx(float(want), rel=1e-14, abs=1e-14)


@pytest.mark.parametrize("horizontal_only", [False, True], ids=["all", "horizontal"])
def test_innovation_squares_equal_the_6_state_filters(horizontal_only):
    """``gnss_nis`` and ``altitude_nis`` against the dense 6-state filter's eᵀ (H P Hᵀ + R)⁻¹ e, on a random
    propagated estimate (correlated r and v per axis) and random measurements. 1e-12 relative: roundoff of a
    2×2 (or scalar) inverse against numpy's 6×6 solve."""
    rng = np.random.default_rng(18)
    est = initial_position(vec(rng.normal(size=3)), SHARP)
    for _ in range(20):
        est = propagate_position(est, vec(rng.normal(size=3)), T, SHARP)
    x, p = to_dense(est)
    z = x + rng.normal(size=6) * 4.0
    h, r, rows = gnss_model(SHARP, horizontal_only)
    e = z[rows] - x[rows]
    expected = e @ np.linalg.solve(h @ p @ h.T + r, e)
    nis = gnss_nis(est, vec(z[:3]), vec(z[3:]), SHARP, horizontal_only)
    assert float(nis) == pytest.approx(expected, rel=1e-12)
    height = -x[2] + 7.0
    h_alt = np.zeros((1, 6))
    h_alt[0, 2] = -1.0
    e_alt = np.array([height - h_alt[0] @ x])
    expected = e_alt @ np.linalg.solve(h_alt @ p @ h_alt.T + float(SHARP.altitude_std) ** 2, e_alt)
    assert float(altitude_nis(est, jnp.asarray(height), SHARP)) == pytest.approx(float(expected), rel=1e-12)
