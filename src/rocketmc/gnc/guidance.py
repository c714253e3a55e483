"""Guidance (docs/gnc.md §4): the thesis's parabolic reference, the body-rate command that turns the velocity
onto it, the roll command to a heading and the rate-error integrators the LQI follows (docs/gnc.md §5).

Pure JAX on scalar components (``Vec3``, ``Quat``), no branches on traced values: jit and vmap as they are.
Frames: NED world from the pad, FRD body; ``q_nb`` rotates body vectors into NED, so docs/gnc.md's
A(q) (NED into body) is ``q_nb.rotate_inverse``. Time ``t`` is the time since liftoff [s] (liftoff = first
motion on the rail): the reference and the window share that clock.
"""

from __future__ import annotations


import jax
import jax.numpy as jnp

from ..env.atmosphere import G0
from ..math import safe_arctan2, safe_sqrt
from ..math.vectors import Quat, Vec3
from ..pytree import pytree_dataclass


@pytree_dataclass
class Navigation:
    """The navigation solution guidance reads, its one interface (for now the true state).

    r_n: position of the centre of mass from the pad, NED [m]; v_n: inertial velocity, NED [m/s];
    q_nb: attitude, rotates body vectors into NED; omega_b: body rates (p, q, r), FRD [rad/s].
    """

    r_n: Vec3
    v_n: Vec3
    q_nb: Quat
    omega_b: Vec3


@pytree_dataclass
class GuidanceParams:
    """Guidance parameters (docs/gnc.md §4), from the campaign's [gnc.guidance] (``campaign.model.guidance_params``).

    Reference parabola: apogee_m, the height H [m] the reference climbs after t0_s [s]; flight_path_angle_rad,
    γ0, the reference's flight-path angle at t0 (above the horizon) [rad]; heading_rad, ψ, its azimuth
    clockwise from north [rad] (the launch azimuth). gain: k [1/s]; rate_limit_rad_s: the 2-norm limit of the
    pitch and yaw rate command [rad/s]; min_speed_mps: below this inertial speed [m/s] the pitch and yaw command
    is zero. Roll: roll_gain [1/s], roll_heading_rad the azimuth [rad] the body z axis is steered toward,
    roll_rate_limit_rad_s [rad/s]. integrator_gain: k_int of e_p, e_q, e_r [-]. window_start_s, window_end_s:
    guidance acts for window_start_s ≤ t < window_end_s [s since liftoff]. wind_gain: k_w [-] of the upwind aim
    (``reference_direction``), wind_time_constant_s: τ [s] of the low-pass on its wind (``filtered_wind``); None:
    no upwind aim (the thesis's reference, nothing computed).
    """

    apogee_m: jnp.ndarray
    t0_s: jnp.ndarray
    flight_path_angle_rad: jnp.ndarray
    heading_rad: jnp.ndarray
    gain: jnp.ndarray
    rate_limit_rad_s: jnp.ndarray
    min_speed_mps: jnp.ndarray
    roll_gain: jnp.ndarray
    roll_heading_rad: jnp.ndarray
    roll_rate_limit_rad_s: jnp.ndarray
    integrator_gain: Vec3
    window_start_s: jnp.ndarray
    window_end_s: jnp.ndarray
    wind_gain: jnp.ndarray | None = None
    wind_time_constant_s: jnp.ndarray | None = None


MIN_WIND_AXIS_CLIMB = 0.5
"""The wind is estimated from the attitude (``wind_estimate``) only while the body axis climbs at least this steeply
(its down component ≤ −0.5: 30° above the horizon); below, the estimate divides by a vanishing climb and is 0."""


def wind_estimate(nav: Navigation) -> Vec3:
    """The horizontal wind [m/s, NED] the rocket's weathercocking reveals: a statically stable airframe flies close to
    zero angle of attack, its air velocity v − w along its axis x_b; with no vertical wind, v − w = s x_b with
    s = v_d / x_b,d, hence w = v − s x_b (down component 0). Exact at zero angle of attack; an angle of attack α
    (a gust, a manoeuvre) adds ~‖v‖·α."""
    axis_n = nav.q_nb.rotate(Vec3(jnp.ones_like(nav.v_n.x), jnp.zeros_like(nav.v_n.x), jnp.zeros_like(nav.v_n.x)))
    climbing = axis_n.z <= -MIN_WIND_AXIS_CLIMB
    along = nav.v_n.z / jnp.where(climbing, axis_n.z, -1.0)
    zero = jnp.zeros_like(nav.v_n.x)
    return Vec3(jnp.where(climbing, nav.v_n.x - along * axis_n.x, zero),
                jnp.where(climbing, nav.v_n.y - along * axis_n.y, zero), zero)  # fmt: skip


def filtered_wind(previous: Vec3, nav: Navigation, dt, time_constant_s) -> Vec3:
    """The upwind aim's wind [m/s, NED]: ``wind_estimate`` through a first-order low-pass of time constant τ [s],
    one GNC period dt [s] on (exact for an estimate held over the period: w += (1 − e^(−dt/τ)) (ŵ − w)). The
    estimate also reads the angle of attack of the rocket's own manoeuvres, which the aim would feed back (measured
    on lynx_nominal_ctrl_1s: aimed on the raw estimate, the canards saturated 50-70 % of the window, and the landing
    point jumped by ~100 m for a change of 0.05 in k_w); the turn lasts a fraction of a second, the wind it crosses
    changes over seconds."""
    blend = 1.0 - jnp.exp(-dt / time_constant_s)
    raw = wind_estimate(nav)
    return Vec3(previous.x + blend * (raw.x - previous.x), previous.y + blend * (raw.y - previous.y), previous.z)


def guidance_active(params: GuidanceParams, t) -> jnp.ndarray:
    """True inside the window, window_start_s ≤ t < window_end_s, t the time since liftoff [s]."""
    return (t >= params.window_start_s) & (t < params.window_end_s)


@jax.custom_jvp
def _climb_angle(climb, v_x):
    """γ = arctan(climb / v_x) [rad] of a climb and a horizontal speed v_x > 0 [m/s]. Its derivative is 0 at an
    infinite climb (the reference before liftoff, t = −inf), where the textbook one is inf·0: reverse mode would carry
    NaN into every derivative of the reference's numbers. The forward value is numpy's, bit for bit."""
    return jnp.arctan(climb / v_x)


@_climb_angle.defjvp
def _climb_angle_jvp(primals, tangents):
    (climb, v_x), (d_climb, d_v_x) = primals, tangents
    finite = jnp.isfinite(climb)
    c = jnp.where(finite, climb, 0.0)
    slope = (v_x * d_climb - c * d_v_x) / (v_x * v_x + c * c)
    return jnp.arctan(climb / v_x), jnp.where(finite, slope, 0.0)


def reference_direction(params: GuidanceParams, nav: Navigation, t, wind_n: Vec3 | None = None) -> Vec3:
    """Desired velocity direction d_ref (unit, NED) of the parabolic reference at t [s since liftoff].

    docs/gnc.md §4: c1 = √(2 g0 H), v_x = c1/tan γ0, γ_ref = atan((c1 − g0 (t − t0))/v_x),
    d_ref = (cos ψ cos γ_ref, sin ψ cos γ_ref, −sin γ_ref): a point mass climbing at c1 at t0 with horizontal
    speed v_x along ψ, which rises H after t0. The thesis's reference depends on time only (``nav`` is not read; it
    is in the signature so that a reference of the position can replace this one). With ``wind_gain`` k_w set, the
    reference's horizontal velocity v_x (cos ψ, sin ψ) is aimed upwind by k_w times ``wind_n``, the wind the
    navigation reveals (``filtered_wind``), d_ref the direction of
    (v_x cos ψ − k_w w_n, v_x sin ψ − k_w w_e, −(c1 − g0 (t − t0))): a rocket that climbs into the wind lands closer
    to where the same rocket lands in calm air after drifting downwind under its canopies. Before liftoff (t = −inf)
    the thesis's reference points straight up (``_climb_angle``), the aimed one is its direction at liftoff, t = 0.
    """
    c1 = jnp.sqrt(2.0 * G0 * params.apogee_m)
    v_x = c1 / jnp.tan(params.flight_path_angle_rad)
    if params.wind_gain is None:
        gamma = _climb_angle(c1 - G0 * (t - params.t0_s), v_x)
        cg = jnp.cos(gamma)
        return Vec3(jnp.cos(params.heading_rad) * cg, jnp.sin(params.heading_rad) * cg, -jnp.sin(gamma))
    climb = c1 - G0 * (jnp.where(jnp.isfinite(t), t, 0.0) - params.t0_s)
    aim = Vec3(v_x * jnp.cos(params.heading_rad) - params.wind_gain * wind_n.x,
               v_x * jnp.sin(params.heading_rad) - params.wind_gain * wind_n.y, -climb)  # fmt: skip
    return aim * (1.0 / aim.norm())


def _clip_norm2(y, z, limit):
    """(y, z) scaled down to a 2-norm of at most ``limit``, direction kept."""
    norm = safe_sqrt(y * y + z * z)
    scale = jnp.where(norm > limit, limit / jnp.where(norm > 0.0, norm, 1.0), 1.0)
    return y * scale, z * scale


def rate_command(params: GuidanceParams, nav: Navigation, t, wind_n: Vec3 | None = None) -> tuple[Vec3, jnp.ndarray]:
    """Body-rate command ω_cmd = (p, q, r), FRD [rad/s], and the tracking error χ [rad] at t [s since liftoff].

    docs/gnc.md §4, V = nav.v_n: χ = ∠(V, d_ref) ∈ [0, π], computed as atan2(‖V×d‖, V·d) (the thesis's
    acos(V·d/‖V‖) loses digits near 0); n = V×d/‖V×d‖ (NED, 0 when V ∥ d), the axis about which a rotation by
    +χ turns V onto d (right-handed); ω_b = k χ A(q) n. Pitch and yaw: (q, r) = ω_b's y, z components, scaled
    together to a 2-norm of at most ``rate_limit_rad_s``, zero when ‖V‖ ≤ ``min_speed_mps`` (ω_b's x component is
    dropped). Roll: t_b = A(q) (cos ψ_roll, sin ψ_roll, 0), the roll error φ_e = atan2(−t_b,y, t_b,z) ∈ (−π, π] is the
    rotation about +x_b that takes the body z axis onto t_b's lateral (y, z) part (positive p turns z_b toward
    −y_b); p = clip(roll_gain φ_e, ±roll_rate_limit_rad_s). All three are zero outside the window; χ is returned
    at every t (the reference is defined at every t). wind_n: the upwind aim's wind (``reference_direction``).
    """
    v = nav.v_n
    d = reference_direction(params, nav, t, wind_n)
    cross = v.cross(d)
    sin_part = cross.norm()
    chi = safe_arctan2(sin_part, v.dot(d))
    axis_n = cross * (1.0 / jnp.where(sin_part > 0.0, sin_part, 1.0))
    axis_b = nav.q_nb.rotate_inverse(axis_n)
    fly = guidance_active(params, t)
    steer = fly & (v.norm() > params.min_speed_mps)
    q_cmd, r_cmd = _clip_norm2(params.gain * chi * axis_b.y, params.gain * chi * axis_b.z, params.rate_limit_rad_s)
    ch, sh = jnp.cos(params.roll_heading_rad), jnp.sin(params.roll_heading_rad)
    target_b = nav.q_nb.rotate_inverse(Vec3(ch, sh, jnp.zeros_like(ch)))
    roll_error = safe_arctan2(-target_b.y, target_b.z)
    p_cmd = jnp.clip(params.roll_gain * roll_error, -params.roll_rate_limit_rad_s, params.roll_rate_limit_rad_s)
    command = Vec3(jnp.where(fly, p_cmd, 0.0), jnp.where(steer, q_cmd, 0.0), jnp.where(steer, r_cmd, 0.0))
    return command, chi


def integrate_errors(
    errors: Vec3, rate_command: Vec3, rates: Vec3, dt, active, gain: Vec3 = Vec3(1.0, 1.0, 1.0)
) -> Vec3:
    """Rate-error integrators (e_p, e_q, e_r) [rad] one step dt [s] on: e += k_int (ω_cmd − ω) dt while active.

    docs/gnc.md §4's e_k = e_{k−1} + k_int T (ref − ω̂), with rates ω = (p, q, r) FRD [rad/s]. The sign is
    gnc/design.py's augmentation ė = −C x (C picks p, q, r) with the command added, ė = ω_cmd − ω, for which
    its gains u = −K x are designed; ``gain`` is k_int per axis (design.py assumes 1; the thesis flew
    ``GuidanceParams.integrator_gain``, 1, 12, 12). Not active: held bit for bit (the thesis resets them while
    inactive; the same for a single window entered with e = 0, the canards commanded to zero after it).
    """
    step = Vec3(
        errors.x + gain.x * (rate_command.x - rates.x) * dt,
        errors.y + gain.y * (rate_command.y - rates.y) * dt,
        errors.z + gain.z * (rate_command.z - rates.z) * dt,
    )
    return Vec3(*(jnp.where(active, s, e) for s, e in zip(step, errors)))
