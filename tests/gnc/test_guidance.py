"""Guidance (docs/gnc.md §4) against closed forms: the parabolic reference, the tracking error χ and rotation axis
of a velocity turned by a known angle about a known axis, the rate limit, the roll law, the window, the
rate-error integrators, and jit/vmap against eager bit for bit.

Attitudes come from ``Quat.from_euler`` (3-2-1, q_nb body→NED); the velocity is put along the body x axis,
so a rotation axis in the body's y-z plane is the one the command must return.
"""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign.gains import GuidanceReference
from rocketmc.campaign.model import guidance_params
from rocketmc.campaign.schema import GuidanceConfig
from rocketmc.env.atmosphere import G0
from rocketmc.gnc.guidance import (
    Navigation,
    filtered_wind,
    guidance_active,
    integrate_errors,
    rate_command,
    reference_direction,
    wind_estimate,
)
from rocketmc.math.vectors import Quat, Vec3

DEG = math.pi / 180.0
THESIS = guidance_params(GuidanceConfig(), GuidanceReference(apogee_m=1614.0, t0_s=GuidanceConfig().t0_s,
                                                             flight_path_angle_deg=84.0, heading_deg=130.0,
                                                             roll_heading_deg=90.0, derived=()))  # fmt: skip
"""The thesis's guidance (docs/gnc.md §4): the schema's defaults, and the thesis's reference (H 1614 m, γ0 84°,
heading 130°, roll heading 90°)."""
# Unit vectors and angles rebuilt through a few trig functions and quaternion rotations round at a few ulps
# (~1e-16); 1e-13 leaves room for that and is far below anything a controller could notice.
ROUND = 1e-13


def nav(v_n: Vec3, q_nb: Quat, omega_b: Vec3 = Vec3(0.0, 0.0, 0.0)) -> Navigation:
    return Navigation(r_n=Vec3(0.0, 0.0, -100.0), v_n=v_n, q_nb=q_nb, omega_b=omega_b)


def axis_angle(axis: Vec3, angle: float) -> Quat:
    """Rotation by ``angle`` [rad] about the unit ``axis``, right-handed."""
    s = math.sin(angle / 2.0)
    return Quat(math.cos(angle / 2.0), axis.x * s, axis.y * s, axis.z * s)


def test_reference_is_the_thesis_parabola():
    """d_ref at t0 has flight-path angle γ0 and heading ψ; it is level at the apex t0 + √(2H/g0) and is the
    direction of the point mass with v_x = √(2 g0 H)/tan γ0 and vertical speed √(2 g0 H) − g0 (t − t0)."""
    p = THESIS
    assert float(p.apogee_m) == 1614.0 and float(p.t0_s) == 1.5 and float(p.gain) == 5.0
    assert math.isclose(math.sqrt(2 * G0 * 1614.0), 177.92, abs_tol=5e-3)  # docs/gnc.md's c1 [m/s], to its digits
    assert math.isclose(math.sqrt(2 * G0 * 1614.0) / math.tan(84 * DEG), 18.70, abs_tol=5e-3)  # v_x [m/s]
    d0 = reference_direction(p, None, p.t0_s)
    assert math.isclose(float(-d0.z), math.sin(84 * DEG), abs_tol=ROUND)
    assert math.isclose(math.atan2(float(d0.y), float(d0.x)), 130 * DEG, abs_tol=ROUND)
    apex = reference_direction(p, None, 1.5 + math.sqrt(2 * 1614.0 / G0))
    np.testing.assert_allclose(apex.to_array(), [math.cos(130 * DEG), math.sin(130 * DEG), 0.0], atol=ROUND)
    c1 = math.sqrt(2 * G0 * 1614.0)
    v_x = c1 / math.tan(84 * DEG)
    for t in (0.0, 1.5, 4.0, 9.9, 25.0):
        v = np.array([v_x * math.cos(130 * DEG), v_x * math.sin(130 * DEG), -(c1 - G0 * (t - 1.5))])
        got = reference_direction(p, None, t).to_array()
        np.testing.assert_allclose(got, v / np.linalg.norm(v), atol=ROUND)
        assert math.isclose(float(jnp.linalg.norm(got)), 1.0, abs_tol=ROUND)


@pytest.mark.parametrize("t", [1.0, 1.5, 4.0, 9.98])
def test_on_the_reference_the_command_is_zero(t):
    """Velocity along the parabola, body x along it with the body z axis toward the roll heading: χ = 0 and
    ω_cmd = 0 (to the rounding of V×d, ~1e-16 per unit vector)."""
    p = dataclasses.replace(THESIS, roll_heading_rad=130 * DEG)
    c1 = math.sqrt(2 * G0 * 1614.0)
    v_x = c1 / math.tan(84 * DEG)
    vz = c1 - G0 * (t - 1.5)
    v = Vec3(v_x * math.cos(130 * DEG), v_x * math.sin(130 * DEG), -vz)
    q_nb = Quat.from_euler(130 * DEG, math.atan2(vz, v_x), 0.0)  # body x along v, no roll
    cmd, chi = rate_command(p, nav(v, q_nb), t)
    assert abs(float(chi)) < ROUND
    np.testing.assert_allclose(cmd.to_array(), 0.0, atol=5.0 * ROUND)  # k = 5 times χ's rounding


ATTITUDES = [  # (yaw, pitch, roll) [deg]: rail-like, rolled, upside-down roll, a shallow climb
    (130.0, 84.0, 0.0),
    (130.0, 84.0, 37.0),
    (-20.0, 70.0, -120.0),
    (250.0, 60.0, 180.0),
    (10.0, 45.0, 90.0),
]


def turned_velocity(yaw, pitch, roll, beta, theta):
    """A body at (yaw, pitch, roll) flying along its x axis, and the reference that lies θ away from its
    velocity about the body axis (0, cos β, sin β): returns (nav, params at t = t0, t0)."""
    q_nb = Quat.from_euler(yaw * DEG, pitch * DEG, roll * DEG)
    v_n = q_nb.rotate(Vec3(1.0, 0.0, 0.0)) * 150.0
    axis_n = q_nb.rotate(Vec3(0.0, math.cos(beta * DEG), math.sin(beta * DEG)))
    d = axis_angle(axis_n, theta * DEG).rotate(v_n) * (1.0 / 150.0)
    params = dataclasses.replace(
        THESIS, flight_path_angle_rad=jnp.arcsin(-d.z), heading_rad=jnp.arctan2(d.y, d.x), roll_heading_rad=yaw * DEG
    )
    return nav(v_n, q_nb), params, params.t0_s


@pytest.mark.parametrize("attitude", ATTITUDES)
@pytest.mark.parametrize("beta", [0.0, 90.0, 215.0])
def test_chi_and_axis_of_a_turned_velocity_below_the_limit(attitude, beta):
    """θ = 2°: χ = θ, (q, r) = k θ (cos β, sin β), below the 20 °/s limit (k θ = 10 °/s)."""
    n, params, t = turned_velocity(*attitude, beta, 2.0)
    cmd, chi = rate_command(params, n, t)
    assert math.isclose(float(chi), 2.0 * DEG, abs_tol=ROUND)
    k_theta = 5.0 * 2.0 * DEG
    np.testing.assert_allclose(
        [cmd.y, cmd.z], [k_theta * math.cos(beta * DEG), k_theta * math.sin(beta * DEG)], atol=ROUND
    )


@pytest.mark.parametrize("attitude", ATTITUDES)
@pytest.mark.parametrize("beta", [30.0, 300.0])
def test_the_rate_limit_holds_the_direction(attitude, beta):
    """θ = 10°: k θ = 50 °/s > 20 °/s, so ‖(q, r)‖ is the limit (to 2 ulps, the rescaling's rounding) along
    the same axis (cos β, sin β)."""
    n, params, t = turned_velocity(*attitude, beta, 10.0)
    cmd, chi = rate_command(params, n, t)
    assert math.isclose(float(chi), 10.0 * DEG, abs_tol=ROUND)
    norm = math.hypot(float(cmd.y), float(cmd.z))
    assert math.isclose(norm, 20.0 * DEG, rel_tol=4.5e-16)
    np.testing.assert_allclose(
        [float(cmd.y) / norm, float(cmd.z) / norm], [math.cos(beta * DEG), math.sin(beta * DEG)], atol=ROUND
    )


@pytest.mark.parametrize(
    "yaw, pitch, roll, p_expected",
    [
        (90.0, 84.0, 0.0, 0.0),  # body z toward East already
        (90.0, 84.0, 10.0, -10.0),  # rolled +10°: roll back at 1 1/s
        (90.0, 84.0, -5.0, 5.0),
        (90.0, 84.0, 30.0, -20.0),  # 30 °/s clipped to the 20 °/s limit
        (90.0, 60.0, -170.0, 20.0),
        (130.0, 84.0, 12.0, -12.0),  # roll heading set to the body's yaw (below)
    ],
)
def test_roll_command_steers_body_z_toward_the_heading(yaw, pitch, roll, p_expected):
    """With the roll heading equal to the body's 3-2-1 yaw, the body z axis points at it when the roll is 0,
    so the roll error is −roll and p = clip(−roll_gain·roll, ±20 °/s) (roll_gain 1 1/s)."""
    params = dataclasses.replace(THESIS, roll_heading_rad=yaw * DEG)
    q_nb = Quat.from_euler(yaw * DEG, pitch * DEG, roll * DEG)
    cmd, _ = rate_command(params, nav(q_nb.rotate(Vec3(100.0, 0.0, 0.0)), q_nb), 5.0)
    assert math.isclose(float(cmd.x), p_expected * DEG, abs_tol=ROUND)


def test_outside_the_window_the_command_is_zero_and_integrators_hold():
    """Before 1 s and from 10 s on (the window is [1, 10) s): ω_cmd = 0 exactly, χ still reported; the
    integrators keep their value bit for bit. Below 1 m/s the pitch and yaw command is zero, roll is not."""
    n, params, _ = turned_velocity(130.0, 84.0, 25.0, 40.0, 3.0)
    params = dataclasses.replace(
        THESIS, flight_path_angle_rad=params.flight_path_angle_rad, heading_rad=params.heading_rad, t0_s=5.0
    )
    _, chi_in = rate_command(params, n, 5.0)
    errors = Vec3(0.1, -0.2, 0.3)
    for t in (0.0, 0.999, 10.0, 30.0):
        assert not bool(guidance_active(params, t))
        cmd, chi = rate_command(params, n, t)
        assert cmd.to_array().tolist() == [0.0, 0.0, 0.0]
        assert float(chi) > 0.0
        held = integrate_errors(errors, Vec3(1.0, 1.0, 1.0), n.omega_b, 0.02, guidance_active(params, t))
        assert held.to_array().tolist() == errors.to_array().tolist()
    assert math.isclose(float(chi_in), 3.0 * DEG, abs_tol=ROUND)
    cmd, _ = rate_command(params, nav(n.v_n * (0.5 / 150.0), n.q_nb), 5.0)  # 0.5 m/s
    assert float(cmd.y) == 0.0 and float(cmd.z) == 0.0 and float(cmd.x) != 0.0


def test_integrators_integrate_a_constant_error_exactly():
    """e += k_int (ω_cmd − ω) dt. With dyadic dt = 2⁻⁶ s, rates, commands and gains every partial sum is a
    float exactly, so 640 steps give N k_int (ω_cmd − ω) dt with no rounding; steps not active add nothing.
    The default gain is 1 (gnc/design.py's ė = ω_cmd − ω)."""
    command, rates = Vec3(0.75, 0.5, -0.375), Vec3(0.25, -0.5, 0.125)
    gain = THESIS.integrator_gain
    dt = 2.0**-6
    active = jnp.arange(800) % 5 != 0  # 640 of 800 steps active

    def step(e, a):
        return integrate_errors(e, command, rates, dt, a, gain), None

    e, _ = jax.lax.scan(step, Vec3(0.0, 0.0, 0.0), active)
    assert e.to_array().tolist() == [640 * 1.0 * 0.5 * dt, 640 * 12.0 * 1.0 * dt, 640 * 12.0 * -0.5 * dt]
    one = integrate_errors(Vec3(0.0, 0.0, 0.0), command, rates, dt, True)
    assert one.to_array().tolist() == [0.5 * dt, 1.0 * dt, -0.5 * dt]


def test_vmap_matches_jit_bit_for_bit_and_eager_to_rounding():
    """Random navigation solutions and times (some outside the window, two below 1 m/s) and dispersed
    parameters. The compiled batch (jit of vmap, what a flight runs) equals each compiled member to the bit.
    Eager differs from compiled by a few ulps (measured 2.2e-15 relative): XLA's CPU compiler contracts
    a·b + c into fused multiply-adds inside a fused kernel, op-by-op eager cannot; 1e-14 bounds that."""
    rng = np.random.default_rng(16)
    m = 12
    quats = rng.normal(size=(m, 4))
    quats /= np.linalg.norm(quats, axis=1, keepdims=True)
    batch = Navigation(
        r_n=Vec3.from_array(rng.normal(size=(m, 3)) * 100.0),
        v_n=Vec3.from_array(rng.normal(size=(m, 3)) * np.array([50.0] * 10 + [0.3] * 2)[:, None]),
        q_nb=Quat.from_array(quats),
        omega_b=Vec3.from_array(rng.normal(size=(m, 3))),
    )
    params = dataclasses.replace(THESIS, apogee_m=jnp.asarray(rng.uniform(1000.0, 2000.0, m)))
    params = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(jnp.asarray(x, float), (m,)), params)
    times = jnp.asarray(rng.uniform(0.0, 12.0, m))
    errors = Vec3.from_array(rng.normal(size=(m, 3)))

    def step(params, n, t, e):
        cmd, chi = rate_command(params, n, t)
        active = guidance_active(params, t)
        return cmd, chi, integrate_errors(e, cmd, n.omega_b, 0.02, active, params.integrator_gain)

    batched = jax.tree_util.tree_leaves(jax.jit(jax.vmap(step))(params, batch, times, errors))
    jitted = jax.jit(step)
    for i in range(m):
        one = jax.tree_util.tree_map(lambda x, i=i: x[i], (params, batch, times, errors))
        compiled = [float(x) for x in jax.tree_util.tree_leaves(jitted(*one))]
        assert [float(x[i]) for x in batched] == compiled
        eager = [float(x) for x in jax.tree_util.tree_leaves(step(*one))]
        np.testing.assert_allclose(eager, compiled, rtol=1e-14, atol=1e-14)


def test_wind_estimate_recovers_the_wind_at_zero_angle_of_attack():
    """An airframe whose axis lies along its air velocity v − w (zero angle of attack) gives back the horizontal
    wind w exactly (to rounding); an axis shallower than 30° gives 0 (the estimate would divide by its climb)."""
    wind = Vec3(-4.0, 7.0, 0.0)
    v = Vec3(20.0, -5.0, -150.0)
    air = v - wind
    pitch = math.atan2(-air.z, math.hypot(air.x, air.y))
    yaw = math.atan2(air.y, air.x)
    got = wind_estimate(nav(v, Quat.from_euler(yaw, pitch, 0.3)))
    np.testing.assert_allclose([float(got.x), float(got.y), float(got.z)], [wind.x, wind.y, 0.0], atol=ROUND * 150)
    shallow = wind_estimate(nav(Vec3(100.0, 0.0, -10.0), Quat.from_euler(0.0, 20 * DEG, 0.0)))
    assert [float(c) for c in shallow] == [0.0, 0.0, 0.0]


def test_filtered_wind_is_the_first_order_lag_of_the_estimate():
    """A constant estimate ŵ through n periods dt of the low-pass τ from 0: ŵ (1 − e^(−n dt/τ)), the closed form."""
    wind = Vec3(-4.0, 7.0, 0.0)
    v = Vec3(20.0, -5.0, -150.0)
    air = v - wind
    attitude = Quat.from_euler(math.atan2(air.y, air.x), math.atan2(-air.z, math.hypot(air.x, air.y)), 0.0)
    filtered = Vec3(0.0, 0.0, 0.0)
    for _ in range(37):
        filtered = filtered_wind(filtered, nav(v, attitude), 0.02, 2.0)
    expected = np.array([wind.x, wind.y]) * -math.expm1(-37 * 0.02 / 2.0)
    np.testing.assert_allclose([float(filtered.x), float(filtered.y)], expected, rtol=1e-12)  # 37 steps' rounding


def test_upwind_aim_moves_the_reference_against_the_wind():
    """wind_gain k_w: d_ref is the direction of (v_x cos ψ − k_w w_n, v_x sin ψ − k_w w_e, −(c1 − g0 (t − t0)));
    k_w = 0 is the thesis's reference to rounding (its own formula, not its bits); before liftoff (t = −inf) the
    aimed reference is its direction at t = 0, the thesis's straight up, both with finite derivatives."""
    wind = Vec3(6.0, -3.0, 0.0)
    k_w, t = 2.0, 4.0
    aimed = dataclasses.replace(THESIS, wind_gain=jnp.asarray(k_w), wind_time_constant_s=jnp.asarray(2.0))
    c1 = math.sqrt(2 * G0 * 1614.0)
    v_x, climb = c1 / math.tan(84 * DEG), c1 - G0 * (t - 1.5)
    expected = np.array([v_x * math.cos(130 * DEG) - k_w * wind.x, v_x * math.sin(130 * DEG) - k_w * wind.y, -climb])
    got = reference_direction(aimed, None, jnp.asarray(t), wind).to_array()
    np.testing.assert_allclose(got, expected / np.linalg.norm(expected), atol=ROUND)
    calm = dataclasses.replace(aimed, wind_gain=jnp.asarray(0.0))
    np.testing.assert_allclose(reference_direction(calm, None, jnp.asarray(t), wind).to_array(),
                               reference_direction(THESIS, None, jnp.asarray(t)).to_array(), atol=ROUND)  # fmt: skip
    before = reference_direction(aimed, None, jnp.asarray(-jnp.inf), wind).to_array()
    np.testing.assert_array_equal(before, reference_direction(aimed, None, jnp.asarray(0.0), wind).to_array())
    for guidance in (aimed, THESIS):  # the thesis's points straight up then, with a derivative of 0
        angle = lambda p: reference_direction(dataclasses.replace(guidance, flight_path_angle_rad=p), None,  # noqa: E731
                                              jnp.asarray(-jnp.inf), wind).z  # fmt: skip
        assert np.isfinite(float(jax.grad(angle)(jnp.asarray(84 * DEG))))
    assert float(reference_direction(THESIS, None, jnp.asarray(-jnp.inf)).z) == -1.0
