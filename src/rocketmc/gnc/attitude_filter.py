"""Attitude and gyro-bias estimation: the thesis's multiplicative extended Kalman filter (docs/gnc.md §2; Markley &
Crassidis 2014, ch. 6), one vehicle, pure JAX (jit, vmap and grad as they are; no branches on traced values).

State: the attitude q̂ = q̂_nb (body FRD → NED) and the gyro bias β̂_b [rad/s]. Error state δx = [δϑ, Δβ]
with covariance P (6×6):
- **error convention**: q_true = q̂ ⊗ δq(δϑ), δq(δϑ) ≈ (1, δϑ/2), so δϑ [rad] is a small rotation of the
  estimated body frame, in body axes; Δβ = β_true − β̂ [rad/s]. ``attitude_error_b`` returns that δϑ (as
  the rotation vector of q̂* ⊗ q_true, which is the filter's δϑ to second order).
- gyro model: ω_meas = ω + β + η_v, β̇ = η_u, white densities σ_v [rad/s/√s], σ_u [rad/s²/√s].
- propagation over T at ω̂ = ω_meas − β̂ (held over T): δϑ̇ = −[ω̂×] δϑ − Δβ − η_v, Δβ̇ = η_u, i.e.
  F = [[−W, −I], [0, 0]], G = diag(−I, I), W = [ω̂×]. Closed forms (x = ‖ω̂‖T, exact for constant
  ω̂):
  Φ11 = exp(−WT) = I − T S1 W + T² S2 W², Φ12 = −T I + T² S2 W − T³ S3 W², Φ21 = 0, Φ22 = I;
  Q11 = σ_v² T I + σ_u² (T³/3 I + 2 T⁵ S5 W²), Q12 = −σ_u² (T²/2 I − T³ S3 W + T⁴ S4 W²),
  Q22 = σ_u² T I,
  with S_m(x) = Σ_n (−x²)ⁿ/(2n + m)!: S1 = sin x/x, S2 = (1 − cos x)/x², S3 = (x − sin x)/x³,
  S4 = (x²/2 + cos x − 1)/x⁴, 2 S5 = (x³/3 + 2 sin x − 2x)/x⁵ (docs/gnc.md §2's expressions divided out). The
  closed forms cancel catastrophically at small x (the last two lose ~ε/x⁴), so below x = 1 the series
  (ten terms, truncation < 1e-17) are used: smooth in ω̂ down to 0, and ~1e-14 relative everywhere, where
  the thesis switched to first order below ‖ω̂‖ = 1e-5 rad/s. q̂⁻ = q̂⁺ ⊗ exp(ω̂T)
  (``rotation_step``), P⁻ = Φ P⁺ Φᵀ + Q.
- magnetometer update, b and r normalised (b the measured field direction in body axes, r the
  reference in NED): h = A(q̂) r (A(q) = rotate_inverse: NED into body); b ≈ h + [h×] δϑ, so H = [[h×], 0];
  S = H P Hᵀ + σ_b² I, K = P Hᵀ S⁻¹, δx = K (b − h); Joseph form P⁺ = (I − KH) P (I − KH)ᵀ + σ_b² K Kᵀ
  (symmetric and positive definite by construction); reset q̂⁺ = (q̂ ⊗ (1, δϑ/2))/‖·‖ (docs/gnc.md's
  q⁻ + ½ Ξ(q⁻) δϑ, normalised), β̂⁺ = β̂ + Δβ. The radial part of b − h does nothing (K h = 0): a unit
  vector carries two directions of information. The rotation about the field line (fixed in NED) is never
  observed by the magnetometer alone; the rotation of the body makes the gyro bias observable.

Unlike the thesis (docs/gnc.md §2, its slips), the a-posteriori estimate is fed forward and output, and the
update uses the Joseph form. The tuning knobs are the thesis's (σ_b = 2 on a unit vector: R = 4 I).

Performance: this runs once per 20 ms control period inside a vmapped scan on CPU. 3×3 blocks are tuples
of rows of scalars (no tiny-array products or library inverses under vmap; Φ21 = 0, Φ22 = I and H's zero
bias columns are used); the 6×6 covariance enters and leaves as one (6, 6) array. Measured at 1024 vehicles
per call: ~2× faster per tick than the same algebra on (3, 3) arrays, but ~2× longer to compile.
"""

from __future__ import annotations

import functools
import math
import operator

import jax.numpy as jnp

from ..math.fusion import computed_once
from ..math.vectors import Quat, Vec3
from ..pytree import pytree_dataclass

SERIES_BELOW = 1.0
"""Below x = ‖ω̂‖T = 1 rad the propagation coefficients S_m come from their series (ten terms: the next is
below 1e-17 relative there), above from the closed forms (whose cancellation costs ≤ ~3e-14 relative there)."""

_SERIES_TERMS = 10
_SERIES = {m: [(-1.0) ** n / math.factorial(2 * n + m) for n in range(_SERIES_TERMS)] for m in range(1, 6)}


@pytree_dataclass
class AttitudeTuning:
    """The filter's noise model (docs/gnc.md §2), from the campaign's [gnc.filters.attitude]
    (``campaign.model.attitude_tuning``).

    gyro_noise: σ_v, gyro white-noise density [rad/s/√s]; bias_walk: σ_u, gyro-bias random-walk density
    [rad/s²/√s]; field_direction_std: σ_b, per-axis std of the measured unit field direction [-] (R = σ_b² I);
    initial_attitude_std [rad] and initial_bias_std [rad/s]: per axis, P0 = diag(σ_ϑ² I, σ_β² I).
    """

    gyro_noise: jnp.ndarray
    bias_walk: jnp.ndarray
    field_direction_std: jnp.ndarray
    initial_attitude_std: jnp.ndarray
    initial_bias_std: jnp.ndarray


@pytree_dataclass
class AttitudeEstimate:
    """q_nb: the estimated attitude (body FRD → NED); bias_b: the estimated gyro bias, body frame [rad/s];
    cov: (6, 6) covariance of the error [δϑ (rad, body frame), Δβ (rad/s)] (module docstring)."""

    q_nb: Quat
    bias_b: Vec3
    cov: jnp.ndarray


# 3×3 matrices as tuples of rows of scalars; a Python 0.0 is a structural zero (the diagonal of [v×], the
# off-diagonal of a scaled identity) that products and sums skip.


def _nonzero(x) -> bool:
    return not (isinstance(x, float) and x == 0.0)


def _sum(terms):
    terms = [t for t in terms if _nonzero(t)]
    return functools.reduce(operator.add, terms) if terms else 0.0


def _eye(scale=1.0):
    return ((scale, 0.0, 0.0), (0.0, scale, 0.0), (0.0, 0.0, scale))


def _mm(a, b):
    return tuple(
        tuple(_sum(a[i][k] * b[k][j] for k in range(3) if _nonzero(a[i][k]) and _nonzero(b[k][j])) for j in range(3))
        for i in range(3)
    )


def _mt(a):
    return tuple(tuple(a[j][i] for j in range(3)) for i in range(3))


def _add(*ms):
    return tuple(tuple(_sum(m[i][j] for m in ms) for j in range(3)) for i in range(3))


def _scale(a, s):
    return tuple(tuple(x * s if _nonzero(x) else 0.0 for x in row) for row in a)


def _mv(a, v: Vec3) -> Vec3:
    return Vec3(*(_sum(a[i][j] * v[j] for j in range(3) if _nonzero(a[i][j])) for i in range(3)))


def _cross_matrix(v: Vec3):
    """[v×], so that [v×] u = v × u."""
    return ((0.0, -v.z, v.y), (v.z, 0.0, -v.x), (-v.y, v.x, 0.0))


def _sym_inverse(s):
    """Inverse of a symmetric positive definite 3×3 by its adjugate (upper triangle read)."""
    a, b, c, d, e, f = s[0][0], s[0][1], s[0][2], s[1][1], s[1][2], s[2][2]
    ca, cb, cc = d * f - e * e, c * e - b * f, b * e - c * d
    cd, ce, cf = a * f - c * c, b * c - a * e, a * d - b * b
    inv_det = 1.0 / (a * ca + b * cb + c * cc)
    return tuple(tuple(x * inv_det for x in row) for row in ((ca, cb, cc), (cb, cd, ce), (cc, ce, cf)))


def _blocks(cov):
    """(P11, P12, P22) of a symmetric (6, 6) covariance (upper triangle read)."""
    def entry(i, j):
        return cov[min(i, j), max(i, j)]

    return tuple(
        tuple(tuple(entry(3 * r + i, 3 * c + j) for j in range(3)) for i in range(3))
        for r, c in ((0, 0), (0, 1), (1, 1))
    )


def _covariance(p11, p12, p22) -> jnp.ndarray:
    """The (6, 6) covariance [[P11, P12], [P12ᵀ, P22]], exactly symmetric: the diagonal blocks' upper triangles
    are read (the lower ones are left to XLA's dead-code elimination), and the result averaged with its
    transpose, because XLA may compute an entry twice in two fusions that round differently (an ulp)."""
    top = tuple(p11[i] + p12[i] for i in range(3))
    full = top + tuple(tuple(p12[j][i] for j in range(3)) + p22[i] for i in range(3))
    rows = [[full[min(i, j)][max(i, j)] for j in range(6)] for i in range(6)]
    cov = jnp.stack([jnp.stack(jnp.broadcast_arrays(*row), axis=-1) for row in rows], axis=-2)
    return 0.5 * (cov + jnp.swapaxes(cov, -1, -2))


def _unit(v: Vec3) -> Vec3:
    return v * (1.0 / v.norm())


def _coefficients(x2):
    """S1..S5 at x² = (‖ω̂‖T)² (module docstring): series below SERIES_BELOW, closed forms above."""
    series = x2 < SERIES_BELOW**2
    out = []
    for m in range(1, 6):
        acc = _SERIES[m][-1]
        for c in reversed(_SERIES[m][:-1]):
            acc = c + x2 * acc
        out.append(acc)
    x = jnp.sqrt(jnp.where(series, 1.0, x2))  # never 0 in the closed branch (finite gradients)
    s, c = computed_once(jnp.stack([jnp.sin(x), jnp.cos(x)]))  # read by ~50 kernels
    closed = (
        s / x,
        (1.0 - c) / x**2,
        (x - s) / x**3,
        (0.5 * x**2 + c - 1.0) / x**4,
        0.5 * (x**3 / 3.0 + 2.0 * s - 2.0 * x) / x**5,
    )
    return [jnp.where(series, a, b) for a, b in zip(out, closed)]


def _error_model(omega_b: Vec3, dt, tuning: AttitudeTuning):
    """Blocks (Φ11, Φ12, Q11, Q12, Q22) of the discrete error model over dt [s] at constant ω̂ [rad/s]."""
    w2 = omega_b.dot(omega_b)
    s1, s2, s3, s4, s5 = _coefficients(w2 * dt * dt)
    wx = _cross_matrix(omega_b)
    wx2 = tuple(tuple(omega_b[i] * omega_b[j] - (w2 if i == j else 0.0) for j in range(3)) for i in range(3))
    eye = _eye()
    var_v, var_u = tuning.gyro_noise**2, tuning.bias_walk**2
    phi11 = _add(eye, _scale(wx, -dt * s1), _scale(wx2, dt**2 * s2))
    phi12 = _add(_eye(-dt), _scale(wx, dt**2 * s2), _scale(wx2, -(dt**3) * s3))
    q11 = _add(_eye(var_v * dt + var_u * dt**3 / 3.0), _scale(wx2, var_u * 2.0 * dt**5 * s5))
    q12 = _add(_eye(-0.5 * var_u * dt**2), _scale(wx, var_u * dt**3 * s3), _scale(wx2, -var_u * dt**4 * s4))
    q22 = _eye(var_u * dt)
    return phi11, phi12, q11, q12, q22


def error_transition(omega_b: Vec3, dt, tuning: AttitudeTuning) -> tuple[jnp.ndarray, jnp.ndarray]:
    """(Φ, Q), each (6, 6): the discrete error-state transition and process noise over dt [s] at the constant
    bias-corrected rate ω̂ [rad/s, body frame] (module docstring). For tests and analysis; the filter uses
    the blocks."""
    phi11, phi12, q11, q12, q22 = _error_model(omega_b, dt, tuning)
    zero, eye = _eye(0.0), _eye()
    phi = jnp.block([[jnp.array(phi11), jnp.array(phi12)], [jnp.array(zero), jnp.array(eye)]])
    return phi, _covariance(q11, q12, q22)


def rotation_step(omega_b: Vec3, dt) -> Quat:
    """The quaternion of a rotation at constant body rates ω [rad/s] over dt [s]: (cos(θ/2), sin(θ/2)·ω/|ω|),
    θ = |ω|·dt (exact for constant rates; smooth at ω = 0)."""
    angle = omega_b.norm() * dt
    half_cos, half_sinc = computed_once(jnp.stack([jnp.cos(0.5 * angle), jnp.sinc(0.5 * angle / jnp.pi)]))
    half_sinc = 0.5 * dt * half_sinc  # sin(θ/2)/|ω|
    return Quat(half_cos, omega_b.x * half_sinc, omega_b.y * half_sinc, omega_b.z * half_sinc)


def initial_attitude(q_nb0: Quat, tuning: AttitudeTuning) -> AttitudeEstimate:
    """The estimate on the pad: attitude q_nb0 (body → NED), zero bias, P0 = diag(σ_ϑ² I, σ_β² I)."""
    zero = jnp.zeros_like(q_nb0.w)
    var_a = tuning.initial_attitude_std**2 + zero
    var_b = tuning.initial_bias_std**2 + zero
    cov = jnp.diag(jnp.stack([var_a, var_a, var_a, var_b, var_b, var_b], axis=-1))
    return AttitudeEstimate(q_nb0, Vec3(zero, zero, zero), cov)


def propagate_attitude(
    est: AttitudeEstimate, omega_measured_b: Vec3, dt, tuning: AttitudeTuning
) -> AttitudeEstimate:
    """The estimate dt [s] later, the gyro's body rates ω_meas [rad/s] held over dt: ω̂ = ω_meas − β̂,
    q̂ ⊗ exp(ω̂ dt) (normalised), bias held, P = Φ P Φᵀ + Q (symmetric)."""

    omega = omega_measured_b - est.bias_b
    phi11, phi12, q11, q12, q22 = _error_model(omega, dt, tuning)
    p11, p12, p22 = _blocks(est.cov)
    m1 = _add(_mm(phi11, p11), _mm(phi12, _mt(p12)))  # rows 1-3 of Φ P
    m2 = _add(_mm(phi11, p12), _mm(phi12, p22))
    new11 = _add(_mm(m1, _mt(phi11)), _mm(m2, _mt(phi12)), q11)
    q_nb = (est.q_nb * rotation_step(omega, dt)).normalized()
    return AttitudeEstimate(q_nb, est.bias_b, _covariance(new11, _add(m2, q12), _add(p22, q22)))


def magnetometer_update(
    est: AttitudeEstimate, field_measured_b: Vec3, reference_n: Vec3, tuning: AttitudeTuning
) -> AttitudeEstimate:
    """The estimate after one magnetometer sample: field_measured_b, the field in body axes, and reference_n,
    the model field in NED (any units: both are normalised). Kalman gain, Joseph-form covariance and the
    multiplicative reset (module docstring)."""
    b, r = _unit(field_measured_b), _unit(reference_n)
    h = est.q_nb.rotate_inverse(r)
    hx = _cross_matrix(h)
    p11, p12, p22 = _blocks(est.cov)
    p21 = _mt(p12)
    u1 = _scale(_mm(p11, hx), -1.0)  # P Hᵀ = [P11 [h×]ᵀ; P21 [h×]ᵀ], [h×]ᵀ = −[h×]
    u2 = _scale(_mm(p21, hx), -1.0)
    var_b = tuning.field_direction_std**2
    s_inv = _sym_inverse(_add(_mm(hx, u1), _eye(var_b)))
    k1, k2 = _mm(u1, s_inv), _mm(u2, s_inv)
    innovation = b - h
    dtheta, dbeta = _mv(k1, innovation), _mv(k2, innovation)
    # Joseph form with L = I − K H = [[I − K1 [h×], 0], [−K2 [h×], I]].
    l11 = _add(_eye(), _scale(_mm(k1, hx), -1.0))
    l21 = _scale(_mm(k2, hx), -1.0)
    l11p11 = _mm(l11, p11)
    l21p11_p21 = _add(_mm(l21, p11), p21)
    new11 = _add(_mm(l11p11, _mt(l11)), _scale(_mm(k1, _mt(k1)), var_b))
    new12 = _add(_mm(l11p11, _mt(l21)), _mm(l11, p12), _scale(_mm(k1, _mt(k2)), var_b))
    new22 = _add(_mm(l21p11_p21, _mt(l21)), _mm(l21, p12), p22, _scale(_mm(k2, _mt(k2)), var_b))
    half = dtheta * 0.5
    q_nb = (est.q_nb * Quat(jnp.ones_like(half.x), half.x, half.y, half.z)).normalized()
    return AttitudeEstimate(q_nb, est.bias_b + dbeta, _covariance(new11, new12, new22))


def magnetometer_nis(
    est: AttitudeEstimate, field_measured_b: Vec3, reference_n: Vec3, tuning: AttitudeTuning
) -> jnp.ndarray:
    """``magnetometer_update``'s normalised innovation squared eᵀ S⁻¹ e [-], e = b − h, S = [h×] P11 [h×]ᵀ + σ_b² I
    (b, h unit vectors: e is tangential to first order, so ~χ² with 2 degrees of freedom)."""
    b, r = _unit(field_measured_b), _unit(reference_n)
    h = est.q_nb.rotate_inverse(r)
    hx = _cross_matrix(h)
    p11 = _blocks(est.cov)[0]
    innovation = b - h
    s = _add(_scale(_mm(_mm(hx, p11), hx), -1.0), _eye(tuning.field_direction_std**2))  # [h×]ᵀ = −[h×]
    return innovation.dot(_mv(_sym_inverse(s), innovation))


def _quat_from_matrix(m) -> Quat:
    """The unit quaternion (w ≥ 0) of a rotation matrix (rows of scalars; body → NED), Shepperd's method:
    the candidate built on the largest of 4w², 4x², 4y², 4z²."""
    tr = m[0][0] + m[1][1] + m[2][2]
    candidates = (
        (1.0 + tr, m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]),
        (m[2][1] - m[1][2], 1.0 + m[0][0] - m[1][1] - m[2][2], m[0][1] + m[1][0], m[0][2] + m[2][0]),
        (m[0][2] - m[2][0], m[0][1] + m[1][0], 1.0 - m[0][0] + m[1][1] - m[2][2], m[1][2] + m[2][1]),
        (m[1][0] - m[0][1], m[0][2] + m[2][0], m[1][2] + m[2][1], 1.0 - m[0][0] - m[1][1] + m[2][2]),
    )
    best, best_size = candidates[0], candidates[0][0]
    for i in range(1, 4):
        better = candidates[i][i] > best_size
        best = tuple(jnp.where(better, a, b) for a, b in zip(candidates[i], best))
        best_size = jnp.where(better, candidates[i][i], best_size)
    q = Quat(*best).normalized()
    sign = jnp.where(q.w < 0.0, -1.0, 1.0)
    return Quat(q.w * sign, q.x * sign, q.y * sign, q.z * sign)


def triad(specific_force_b: Vec3, field_b: Vec3, field_n: Vec3) -> Quat:
    """q_nb (body → NED) from two pad measurements by TRIAD: the specific force f_b (at rest the
    accelerometer reads −g, i.e. "up", (0, 0, −g0) in NED) as the primary, exact direction, and the field
    b_b (reference field_n, NED) as the secondary, which fixes the rotation about the vertical. Units of
    each pair are free (directions only); f and the field must not be parallel."""
    up_n = Vec3(jnp.zeros_like(field_n.x), jnp.zeros_like(field_n.x), -jnp.ones_like(field_n.x))
    t1_b, t1_n = _unit(specific_force_b), up_n
    t2_b, t2_n = _unit(t1_b.cross(field_b)), _unit(t1_n.cross(field_n))
    t3_b, t3_n = t1_b.cross(t2_b), t1_n.cross(t2_n)
    pairs = ((t1_n, t1_b), (t2_n, t2_b), (t3_n, t3_b))
    rotation = tuple(tuple(sum(tn[i] * tb[j] for tn, tb in pairs) for j in range(3)) for i in range(3))
    return _quat_from_matrix(rotation)


def level(q_nb: Quat, specific_force_b: Vec3, fraction=1.0) -> Quat:
    """q_nb turned by ``fraction`` [-] of the least rotation that makes the specific force f_b (at rest on the pad:
    "up", (0, 0, −g0) in NED) point up: at 1 the attitude's tilt is the accelerometer's, its rotation about the
    vertical (for a rocket on its rail: the rail's azimuth and the rocket's roll on it) kept as given to first order;
    below 1 the tilt is a weighted mean of the two. The rotation is about the body axis f_b × q_nb's own up, by
    ``fraction`` of the angle between them; f_b must not point down in q_nb."""
    up_n = Vec3(jnp.zeros_like(q_nb.w), jnp.zeros_like(q_nb.w), -jnp.ones_like(q_nb.w))
    measured_b, predicted_b = _unit(specific_force_b), q_nb.rotate_inverse(up_n)
    axis_b = measured_b.cross(predicted_b)
    sine = axis_b.norm()
    half_angle = 0.5 * fraction * jnp.arctan2(sine, measured_b.dot(predicted_b))
    scale = jnp.where(sine > 1e-300, jnp.sin(half_angle) / jnp.where(sine > 1e-300, sine, 1.0), 0.5 * fraction)
    return q_nb * Quat(jnp.cos(half_angle), axis_b.x * scale, axis_b.y * scale, axis_b.z * scale)


def attitude_error_b(q_estimate: Quat, q_true: Quat) -> Vec3:
    """The filter's attitude error δϑ [rad], body frame: q_true = q̂ ⊗ δq(δϑ) (module docstring), given as the
    rotation vector (angle ≤ π times unit axis) of δq = q̂* ⊗ q_true; equal to the filter's 2·vec(δq)/w
    (what its reset inverts) to second order."""
    dq = q_estimate.conj() * q_true
    sign = jnp.where(dq.w < 0.0, -1.0, 1.0)
    vec = Vec3(dq.x, dq.y, dq.z) * sign
    c = dq.w * sign
    n2 = vec.dot(vec)
    tiny = n2 < 1e-30  # atan2(n, c)/n = (1 − n²/3c² …)/c: 2/c is exact below n = 1e-15
    n = jnp.sqrt(jnp.where(tiny, 1.0, n2))
    return vec * jnp.where(tiny, 2.0 / c, 2.0 * jnp.arctan2(n, c) / n)


def attitude_nees(est: AttitudeEstimate, q_true: Quat, bias_true_b: Vec3) -> jnp.ndarray:
    """Normalised estimation error squared eᵀ P⁻¹ e, e = [δϑ, β_true − β̂] (6 degrees of freedom), by the
    block inverse of P (P11's and its Schur complement's 3×3 inverses)."""
    e1 = attitude_error_b(est.q_nb, q_true)
    e2 = bias_true_b - est.bias_b
    p11, p12, p22 = _blocks(est.cov)
    p11_inv = _sym_inverse(p11)
    y = _mv(p11_inv, e1)
    schur = _add(p22, _scale(_mm(_mt(p12), _mm(p11_inv, p12)), -1.0))
    d = e2 - _mv(_mt(p12), y)
    return e1.dot(y) + d.dot(_mv(_sym_inverse(schur), d))
