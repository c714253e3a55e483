"""The thesis's linear Kalman filter for position and velocity (docs/gnc.md §3), NED from the pad, as three exact
2-state filters.

Model (period T [s]): x = [r_n, v_n], x⁻ = F x + G u, F = [I, T I; 0, I], G = [½T² I; T I], u the acceleration
[m/s², NED] held over the period: the accelerometer's specific force rotated into NED plus gravity
(A(q̂)ᵀ f + [0, 0, g], formed by the caller). P⁻ = F P Fᵀ + Q, Q = T·diag(σ_r² I, σ_v² I) (the thesis's
σ_r = 2 m/√s, σ_v = 1 m/s/√s). The thesis's G = [0; T I] integrates the acceleration into the velocity only:
its position trails the exact r0 + v0 t + ½ u t² by ½ u t T (½ T Δv ≈ 3 m after a 300 m/s burn at 50 Hz), a
slip this G, exact for a held u, does not make.
Updates, each by the Kalman gain K = P Hᵀ (H P Hᵀ + R)⁻¹ and the Joseph form
P⁺ = (I − K H) P (I − K H)ᵀ + K R Kᵀ: GNSS position and velocity (H = I6, R diagonal; the thesis's
R = diag(500², 500², 700² m², 50², 50², 70² m²/s²), de-weighted about 100×), or its north and east
axes only (Skyward's avionics, 2021); barometric altitude above the pad, h = −r_D (H = [0, 0, −1, 0, 0, 0]).

Decoupling: order the state axis by axis, (r_N, v_N, r_E, v_E, r_D, v_D). Then F, G, Q are block diagonal with
one 2×2 block per axis (F₁ = [1, T; 0, 1], G₁ = [0; T], Q₁ = T·diag(σ_r², σ_v²)), and so are P0 (diagonal), the
GNSS H and R (each axis measures its own r and v, with its own variances) and the altitude H (the down block
alone). If P is block diagonal, so are F P Fᵀ + Q, S = H P Hᵀ + R, K and the Joseph update, and the block of an
axis depends on that axis's block, inputs and measurements only: by induction the 6-state filter is exactly
three independent filters of (r, v) with covariance [[p_rr, p_rv], [p_rv, p_vv]]. They are held here as one
``Vec3`` per covariance element (one scalar per axis) and updated in closed form (2×2 S inverted explicitly),
which is cheap under ``vmap`` (docs/sharp-bits.md: scalar components, no small-matrix algebra). This needs R
without cross-axis correlations and P0 without cross-axis covariances, as the thesis's and Skyward's are.

Pure single-vehicle JAX, no branches on traced values: jit, vmap and grad as they are.
"""

from __future__ import annotations

import jax.numpy as jnp

from ..math.vectors import Vec3
from ..pytree import pytree_dataclass


@pytree_dataclass
class PositionTuning:
    """The filter's noise model (docs/gnc.md §3), from the campaign's [gnc.filters.position]
    (``campaign.model.position_tuning``).

    position_noise: σ_r, process-noise density on the position [m/√s] (Q_r = T σ_r²); velocity_noise: σ_v, on the
    velocity [m/s/√s] (Q_v = T σ_v²); gnss_position_std, gnss_velocity_std: GNSS measurement noise per axis N, E,
    D [m], [m/s]; altitude_std: barometric altitude noise [m]; initial_position_std,
    initial_velocity_std: the square roots of P0's diagonal [m], [m/s].
    """

    position_noise: jnp.ndarray
    velocity_noise: jnp.ndarray
    gnss_position_std: Vec3
    gnss_velocity_std: Vec3
    altitude_std: jnp.ndarray
    initial_position_std: jnp.ndarray
    initial_velocity_std: jnp.ndarray


@pytree_dataclass
class PositionEstimate:
    """The filter's state: r_n, v_n, position [m] and velocity [m/s], NED from the pad; p_rr, p_rv, p_vv, each
    axis's covariance [[p_rr, p_rv], [p_rv, p_vv]] [m²], [m²/s], [m²/s²] (no cross-axis covariance)."""

    r_n: Vec3
    v_n: Vec3
    p_rr: Vec3
    p_rv: Vec3
    p_vv: Vec3


def _by_axis(axis_update, est: PositionEstimate, *per_axis: Vec3, axes=(0, 1, 2)) -> PositionEstimate:
    """``axis_update(r, v, p_rr, p_rv, p_vv, *others)`` → the same five, applied to each axis in ``axes`` (the
    others' i-th components passed along); the other axes are kept."""
    fields = (est.r_n, est.v_n, est.p_rr, est.p_rv, est.p_vv)
    out = [
        axis_update(*(f[i] for f in fields), *(v[i] for v in per_axis)) if i in axes else tuple(f[i] for f in fields)
        for i in range(3)
    ]
    return PositionEstimate(*(Vec3(*(o[k] for o in out)) for k in range(5)))


def _congruence(m11, m12, m21, m22, a, b, c):
    """M P Mᵀ of P = [[a, b], [b, c]], as its elements (11, 12, 22)."""
    n11, n12 = m11 * a + m12 * b, m11 * b + m12 * c
    n21, n22 = m21 * a + m22 * b, m21 * b + m22 * c
    return n11 * m11 + n12 * m12, n11 * m21 + n12 * m22, n21 * m21 + n22 * m22


def initial_position(r_n0: Vec3, tuning: PositionTuning) -> PositionEstimate:
    """At r_n0 [m] (NED from the pad; the thesis's (0, 0, −1.6 m)) at rest, P0 = diag(σ_r0² I, σ_v0² I)."""
    zero = jnp.zeros_like(r_n0.x)
    var_r = zero + tuning.initial_position_std**2
    var_v = zero + tuning.initial_velocity_std**2
    return PositionEstimate(r_n0, Vec3(zero, zero, zero), Vec3(var_r, var_r, var_r), Vec3(zero, zero, zero),
                            Vec3(var_v, var_v, var_v))


def propagate_position(est: PositionEstimate, acceleration_n: Vec3, dt, tuning: PositionTuning) -> PositionEstimate:
    """One step of dt [s] with the acceleration u [m/s², NED, gravity included] held: r⁻ = r + T v + ½ T² u,
    v⁻ = v + T u, P⁻ = F P Fᵀ + T·diag(σ_r², σ_v²) per axis."""
    q_r = dt * tuning.position_noise**2
    q_v = dt * tuning.velocity_noise**2

    def axis(r, v, a, b, c, u):
        return r + dt * (v + 0.5 * dt * u), v + dt * u, a + dt * (2.0 * b + dt * c) + q_r, b + dt * c, c + q_v

    return _by_axis(axis, est, acceleration_n)


def gnss_update(est: PositionEstimate, position_n: Vec3, velocity_n: Vec3, tuning: PositionTuning,
                horizontal_only: bool = False) -> PositionEstimate:
    """Correct with a GNSS fix: position [m] and velocity [m/s], NED from the pad, noise ``gnss_position_std``,
    ``gnss_velocity_std``. horizontal_only (static): the N and E axes only, the down axis kept (Skyward's
    avionics). Per axis H = I2, R = diag(ρ_r², ρ_v²): S = P + R, I − K = R S⁻¹, K = P S⁻¹, Joseph form."""
    var_r = Vec3(*(s * s for s in tuning.gnss_position_std))
    var_v = Vec3(*(s * s for s in tuning.gnss_velocity_std))

    def axis(r, v, a, b, c, z_r, z_v, rr, rv):
        s11, s22 = a + rr, c + rv
        inv_det = 1.0 / (s11 * s22 - b * b)
        k11, k12 = (a * s22 - b * b) * inv_det, b * rr * inv_det
        k21, k22 = b * rv * inv_det, (c * s11 - b * b) * inv_det
        e_r, e_v = z_r - r, z_v - v
        m11, m12 = rr * s22 * inv_det, -rr * b * inv_det
        m21, m22 = -rv * b * inv_det, rv * s11 * inv_det
        j11, j12, j22 = _congruence(m11, m12, m21, m22, a, b, c)
        return (
            r + k11 * e_r + k12 * e_v,
            v + k21 * e_r + k22 * e_v,
            j11 + rr * k11 * k11 + rv * k12 * k12,
            j12 + rr * k11 * k21 + rv * k12 * k22,
            j22 + rr * k21 * k21 + rv * k22 * k22,
        )

    return _by_axis(axis, est, position_n, velocity_n, var_r, var_v, axes=(0, 1) if horizontal_only else (0, 1, 2))


def altitude_update(est: PositionEstimate, altitude_m, tuning: PositionTuning) -> PositionEstimate:
    """Correct with a barometric altitude above the pad h [m] (= −r_D), noise ``altitude_std``: a scalar update
    of the down axis (equivalently a measurement −h of r_D, H = [1, 0]), S = p_rr + σ_h², Joseph form."""
    var_h = tuning.altitude_std**2
    r, v, a, b, c = est.r_n.z, est.v_n.z, est.p_rr.z, est.p_rv.z, est.p_vv.z
    inv_s = 1.0 / (a + var_h)
    k1, k2 = a * inv_s, b * inv_s
    e = -altitude_m - r
    j11, j12, j22 = _congruence(var_h * inv_s, 0.0, -k2, 1.0, a, b, c)
    return PositionEstimate(
        est.r_n._replace(z=r + k1 * e),
        est.v_n._replace(z=v + k2 * e),
        est.p_rr._replace(z=j11 + var_h * k1 * k1),
        est.p_rv._replace(z=j12 + var_h * k1 * k2),
        est.p_vv._replace(z=j22 + var_h * k2 * k2),
    )


def gnss_nis(est: PositionEstimate, position_n: Vec3, velocity_n: Vec3, tuning: PositionTuning,
             horizontal_only: bool = False) -> jnp.ndarray:
    """``gnss_update``'s normalised innovation squared [-]: the sum over its axes of eᵀ S⁻¹ e, e = (z_r − r, z_v − v),
    S = P + R per axis, i.e. (s22 e_r² − 2 p_rv e_r e_v + s11 e_v²)/det S (χ² with 2 degrees of freedom per axis)."""
    total = 0.0
    for i in (0, 1) if horizontal_only else (0, 1, 2):
        e_r, e_v = position_n[i] - est.r_n[i], velocity_n[i] - est.v_n[i]
        s11, b = est.p_rr[i] + tuning.gnss_position_std[i] ** 2, est.p_rv[i]
        s22 = est.p_vv[i] + tuning.gnss_velocity_std[i] ** 2
        total = total + (s22 * e_r * e_r - 2.0 * b * e_r * e_v + s11 * e_v * e_v) / (s11 * s22 - b * b)
    return total


def altitude_nis(est: PositionEstimate, altitude_m, tuning: PositionTuning) -> jnp.ndarray:
    """``altitude_update``'s normalised innovation squared e²/S [-], e = −h − r_D, S = p_rr + σ_h² (χ², 1 degree
    of freedom)."""
    e = -altitude_m - est.r_n.z
    return e * e / (est.p_rr.z + tuning.altitude_std**2)


def position_nees(est: PositionEstimate, r_true: Vec3, v_true: Vec3) -> jnp.ndarray:
    """Normalized estimation error squared eᵀ P⁻¹ e, e = estimate − truth (6 degrees of freedom): the sum over
    the axes of (p_vv e_r² − 2 p_rv e_r e_v + p_rr e_v²)/(p_rr p_vv − p_rv²) [-]."""
    total = 0.0
    for i in range(3):
        e_r, e_v = est.r_n[i] - r_true[i], est.v_n[i] - v_true[i]
        a, b, c = est.p_rr[i], est.p_rv[i], est.p_vv[i]
        total = total + (c * e_r * e_r - 2.0 * b * e_r * e_v + a * e_v * e_v) / (a * c - b * b)
    return total
