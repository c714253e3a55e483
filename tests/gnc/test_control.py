"""The online LQI step (gnc/control.py) against independent references: u = −K x against numpy's matrix
product, the gain table at its nodes and clamped outside, the window, liftoff and canopy gates, the
anti-windup, the allocation through the airframe's mixing, the per-flight totals, and jit/vmap bitwise."""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.aero.canards import mix
from rocketmc.campaign.runner import LANES
from rocketmc.dynamics.servo import ServoParams, ServoState
from rocketmc.gnc import design
from rocketmc.gnc import control
from rocketmc.gnc.control import GAIN_NAMES, GncParams, GncState, control_summary, gains_at, initial_gnc, lqi_command
from rocketmc.gnc.guidance import Navigation
from rocketmc.gnc.navigation import NavigationMode
from rocketmc.math import Quat, Vec3
from rocketmc.math.table import Table

from .test_guidance import THESIS

DT = 0.02
LIMIT = math.radians(10.0)
# Sums of 11 products of O(1) numbers against numpy's dot: a few ulps of the largest term.
ROUND = 1e-14


def thesis_point(speed, altitude_msl):
    """docs/gnc.md §5's thesis plant (m 22 kg, the linear coefficients of docs/lynx.md) at one design point."""
    return design.PlantPoint(
        -24.0744, 154.0, 3.4045, 24.0744, 154.0, 3.4045, -19.0, 2.3963, -37.2959, -1813.0, 21.8445,
        37.2959, -1813.0, 21.8445, 22.0, 0.06, 6.437, math.pi * 0.15**2 / 4, 0.15, speed, design.density(altitude_msl),
    )  # fmt: skip


def gnc_step(params, state, nav: Navigation, *rest):
    """``control.gnc_step`` with perfect navigation's liftoff test: the rocket moves once its velocity is not zero."""
    return control.gnc_step(params, state, nav, nav.v_n.dot(nav.v_n) > 0.0, *rest)


SPEEDS = np.array([50.0, 100.0, 200.0, 300.0])
ALTITUDES = np.array([1000.0, 3000.0])


@pytest.fixture(scope="module")
def schedule():
    return design.gain_schedule(thesis_point, SPEEDS, ALTITUDES)


@pytest.fixture(scope="module")
def params(schedule):
    table = Table.from_numpy((SPEEDS, ALTITUDES), schedule.gains.reshape(4, 2, -1), ("speed", "altitude"), GAIN_NAMES)
    servo = ServoParams(jnp.asarray(0.0769), jnp.asarray(LIMIT), jnp.zeros(4))
    guidance = THESIS
    return GncParams(servo, guidance, table, anti_windup=True, navigation=NavigationMode.TRUTH)


def flying(speed=100.0, pitch_deg=80.0, omega=Vec3(0.0, 0.0, 0.0)) -> Navigation:
    """Climbing along the body x axis at ``speed`` [m/s], 130° heading, ``pitch_deg`` above the horizon."""
    q = Quat.from_euler(math.radians(130.0), math.radians(pitch_deg), 0.0)
    v = q.rotate(Vec3(speed, 0.0, 0.0))
    return Navigation(Vec3(0.0, 0.0, -500.0), Vec3(*(jnp.asarray(c) for c in v)), q, omega)


def after_liftoff(params, liftoff=0.6, **changes) -> GncState:
    state = initial_gnc(params, jnp.asarray(0.0))
    fields = {**vars(state), "liftoff_time": jnp.asarray(liftoff), **changes}
    return GncState(**fields)


def test_lqi_command_is_minus_k_x():
    rng = np.random.default_rng(1)
    k, x = rng.normal(size=(3, 11)), rng.normal(size=11)
    np.testing.assert_allclose(np.array(lqi_command(k.ravel(), tuple(x))), -k @ x, rtol=0, atol=ROUND * 11)


def test_gains_at_the_nodes_and_clamped(params, schedule):
    """At a node the table returns the DARE's gain exactly (multilinear interpolation is exact there); below
    and above the grid it holds the edge's."""
    for i, j in ((0, 0), (1, 1), (3, 0)):
        k = np.asarray(gains_at(params.gains, SPEEDS[i], ALTITUDES[j]))
        np.testing.assert_array_equal(k.reshape(3, 11), schedule.gains[i, j])
    np.testing.assert_array_equal(gains_at(params.gains, 10.0, 0.0), gains_at(params.gains, SPEEDS[0], ALTITUDES[0]))
    np.testing.assert_array_equal(gains_at(params.gains, 900.0, 9e3), gains_at(params.gains, SPEEDS[-1], ALTITUDES[-1]))
    halfway = (schedule.gains[1, 0] + schedule.gains[2, 0]) / 2  # linear in speed between nodes
    np.testing.assert_allclose(np.asarray(gains_at(params.gains, 150.0, 1000.0)).reshape(3, 11), halfway, atol=ROUND)


def test_command_inside_the_window_is_the_allocated_lqi(params, schedule):
    """1.5 s after liftoff at a node of the grid: the fins hold allocate(−K x) with x from the navigation
    solution, the servo state and the integrators just updated; mixing it back gives −K x (squeeze 0)."""
    nav = flying(100.0, omega=Vec3(0.01, -0.02, 0.03))
    servo = ServoState(jnp.array([0.01, -0.02, 0.005, 0.0]), jnp.zeros(4))
    state = after_liftoff(params, servo=servo, integrators=Vec3(0.001, -0.002, 0.003))
    new = gnc_step(params, state, nav, 0.6 + 1.5, DT, 1000.0, False)
    v_b = nav.q_nb.rotate_inverse(nav.v_n)
    u_y, u_p, u_r, _ = mix(*np.asarray(servo.deflection_rad))
    e = new.integrators
    x = np.array([v_b.y, v_b.z, 0.01, -0.02, 0.03, u_y, u_p, u_r, e.x, e.y, e.z], dtype=float)
    expected = -schedule.gains[1, 0] @ x
    yaw, pitch, roll, squeeze = mix(*np.asarray(new.servo.command_rad))
    np.testing.assert_allclose([yaw, pitch, roll], expected, atol=ROUND)
    assert abs(squeeze) < ROUND
    assert bool(new.saturated) == (np.abs(np.asarray(new.servo.command_rad)).max() >= LIMIT)
    assert float(new.active_time) == DT


@pytest.mark.parametrize(
    "t, canopy, liftoff, why",
    [(0.6 + 0.5, False, 0.6, "before the window"), (0.6 + 10.0, False, 0.6, "at its end (half-open)"),
     (0.6 + 2.0, True, 0.6, "a parachute triggered"), (5.0, False, math.inf, "never lifted off")],
)  # fmt: skip
def test_idle_gates_command_zero_and_hold_the_integrators(params, t, canopy, liftoff, why):
    nav = flying(100.0, omega=Vec3(0.01, -0.02, 0.03))
    nav = nav if math.isfinite(liftoff) else Navigation(nav.r_n, Vec3(0.0, 0.0, 0.0), nav.q_nb, nav.omega_b)
    e = Vec3(*(jnp.asarray(x) for x in (0.001, -0.002, 0.003)))
    new = gnc_step(params, after_liftoff(params, liftoff, integrators=e), nav, t, DT, 1000.0, canopy)
    np.testing.assert_array_equal(new.servo.command_rad, np.zeros(4), err_msg=why)
    assert tuple(map(float, new.integrators)) == tuple(map(float, e)), why
    assert float(new.active_time) == 0.0 and not bool(new.saturated), why


def test_liftoff_is_the_first_period_start_in_motion(params):
    state = initial_gnc(params, jnp.asarray(0.0))
    still = flying(0.0)
    state = gnc_step(params, state, still, 0.5, DT, 1000.0, False)
    assert math.isinf(float(state.liftoff_time))
    state = gnc_step(params, state, flying(0.3), 0.52, DT, 1000.0, False)
    state = gnc_step(params, state, flying(0.6), 0.54, DT, 1000.0, False)
    assert float(state.liftoff_time) == 0.52


def test_anti_windup_holds_only_the_integrators_that_would_wind_further(params):
    """e_q = −2 rad saturates the fins with a negative pitch command. Next step: with q above its command the
    e_q step is negative (further into saturation): held; with q below it, the step unwinds: taken. Without
    anti-windup both are taken."""
    e = Vec3(*(jnp.asarray(x) for x in (0.0, -2.0, 0.0)))
    first = gnc_step(params, after_liftoff(params, integrators=e), flying(100.0, 60.0), 2.0, DT, 1000.0, False)
    assert bool(first.saturated) and float(first.command.y) < -LIMIT
    np.testing.assert_array_equal(np.abs(np.asarray(first.servo.command_rad)).max(), LIMIT)
    free = dataclasses.replace(params, anti_windup=False)
    for q, held in ((0.5, True), (-0.5, False)):
        nav = flying(100.0, 60.0, Vec3(0.0, q, 0.0))
        new, moved = (gnc_step(g, first, nav, 2.02, DT, 1000.0, False).integrators for g in (params, free))
        assert float(moved.y) != float(first.integrators.y) and np.sign(float(moved.y - first.integrators.y)) == -np.sign(q)
        assert float(new.y) == (float(first.integrators.y) if held else float(moved.y)), q


def test_totals_and_summary(params):
    """Two active steps: time 2·dt, χ RMS the RMS of the two χ, deflections from the servo state at each
    period start; a flight that never acted gives NaN rates and zero times."""
    nav = flying(100.0, pitch_deg=70.0)  # χ ≈ 14° from the reference, steady
    servo = ServoState(jnp.array([0.1, -0.1, 0.0, 0.0]), jnp.zeros(4))
    s1 = gnc_step(params, after_liftoff(params, servo=servo), nav, 2.0, DT, 1000.0, False)
    s2 = gnc_step(params, s1, nav, 2.02, DT, 1000.0, False)
    out = {k: float(v) for k, v in control_summary(s2).items()}
    assert math.isclose(out["control_active_time_s"], 2 * DT, rel_tol=1e-15)
    mean_sq = (0.02 / 4 + float(jnp.mean(s1.servo.deflection_rad**2))) / 2  # (0.1² + 0.1²)/4 then the held state's
    assert math.isclose(out["canard_deflection_rms_rad"], math.sqrt(mean_sq), rel_tol=1e-12)
    assert out["canard_deflection_max_rad"] == 0.1
    assert 0.2 < out["tracking_error_rms_rad"] < 0.3  # 84° − 70° = 14° = 0.244 rad, give or take the parabola
    idle = control_summary(initial_gnc(params, jnp.asarray(0.0)))
    assert float(idle["control_active_time_s"]) == 0.0 and math.isnan(float(idle["tracking_error_rms_rad"]))


def test_lanes_bitwise_whatever_the_batch(params):
    """A flight's step gives the same bits in any lane of any batch of whole SIMD vectors (``runner.LANES``
    per core; leftover lanes run a scalar loop whose math may differ by an ulp): what makes campaign results
    independent of the chunk size."""
    cases = [(40.0 + 30.0 * i, 70.0 + 2.0 * i, Vec3(0.01 * i, -0.02, 0.01)) for i in range(LANES)]
    rng = np.random.default_rng(3)
    lanes = [(flying(*c), after_liftoff(params, servo=ServoState(*jnp.asarray(rng.uniform(-0.1, 0.1, (2, 4))))))
             for c in cases]  # fmt: skip
    step = jax.jit(jax.vmap(lambda n, s: gnc_step(params, s, n, 2.0, DT, 1500.0, False)))
    stack = lambda items: jax.tree_util.tree_map(lambda *x: jnp.stack(x), *items)  # noqa: E731
    small = step(*stack(lanes))
    large = step(*stack(lanes[::-1] * 2))  # reversed, two vectors
    for i in range(LANES):
        a = jax.tree_util.tree_leaves(jax.tree_util.tree_map(lambda x: x[i], small))
        b = jax.tree_util.tree_leaves(jax.tree_util.tree_map(lambda x: x[LANES - 1 - i], large))
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)


def test_parachutes_trigger_on_the_navigation_solution():
    """``sensed_triggers``: apogee once the estimated vertical velocity has pointed down for
    APOGEE_DESCENDING_TICKS consecutive ticks after liftoff (a shorter run of downward noise resets the count;
    no apogee before liftoff), the drogue (trigger altitude inf) at that tick; the main (an altitude) is left to the
    integration (``sim.events.update_events``); the navigation's height error is kept until a canopy is out, then
    held."""
    altitudes = (jnp.asarray(jnp.inf), jnp.asarray(350.0))
    state = control.Recovery(jnp.asarray(0, jnp.int32), jnp.asarray(jnp.inf), jnp.asarray(0.0))
    triggers = (jnp.asarray(jnp.inf), jnp.asarray(jnp.inf))

    def tick(state, triggers, t, height, down_mps, moving=True, canopy=False, true_height=None):
        still = Vec3(0.0, 0.0, 0.0)
        nav = Navigation(Vec3(0.0, 0.0, -height), Vec3(0.0, 0.0, down_mps), Quat(1.0, 0.0, 0.0, 0.0), still)
        truth = height - 7.0 if true_height is None else true_height  # the estimate 7 m high
        return control.sensed_triggers(state, nav, jnp.asarray(truth), jnp.asarray(moving), jnp.asarray(canopy),
                                       jnp.asarray(t), altitudes, triggers)  # fmt: skip

    n = control.APOGEE_DESCENDING_TICKS
    for k in range(2 * n):  # on the pad, a falling estimate: not an apogee before liftoff
        state, triggers = tick(state, triggers, 0.02 * k, 1.0, 3.0, moving=False)
    assert int(state.descending_ticks) == 0 and np.isinf(triggers).all()
    t = 1.0
    for down in [-50.0] + [1.0] * (n - 1) + [-0.5] + [1.0] * (n - 1):  # climbing, then n − 1 down, a blip up
        state, triggers = tick(state, triggers, t, 1600.0, down)
        t += DT
    assert np.isinf(float(state.apogee_time)) and np.isinf(triggers).all()
    state, triggers = tick(state, triggers, t, 1600.0, 1.0)  # the n-th consecutive tick down
    assert float(state.apogee_time) == t and float(triggers[0]) == t and np.isinf(float(triggers[1]))
    assert float(state.height_error_m) == 7.0
    state, triggers = tick(state, triggers, t + DT, 300.0, 20.0, canopy=True, true_height=250.0)  # under the drogue
    assert np.isinf(float(triggers[1])) and float(triggers[0]) == t
    assert float(state.height_error_m) == 7.0  # held: the filters idle under canopy
