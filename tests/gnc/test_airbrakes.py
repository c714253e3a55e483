"""The air brakes: their drag against Hoerner's plate and NACA 1135's impact pressure, the apogee prediction against
closed forms and scipy, the controller's rules and the servo's exact response."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rocketmc.aero.airbrakes import HOERNER_SQUARE_PLATE_CD, panel_delta_ca, stagnation_pressure_ratio
from rocketmc.dynamics.servo import ServoState, end_of_period
from rocketmc.env.atmosphere import G0, isa
from rocketmc.gnc.airbrakes import airbrake_step, delta_ca, initial_airbrakes, predicted_apogee_m
from rocketmc.gnc.guidance import Navigation
from rocketmc.math import Quat, Vec3

from ..conftest import CAMPAIGNS


@pytest.fixture(scope="module")
def brakes():
    from rocketmc.campaign import load_campaign

    return load_campaign(CAMPAIGNS / "lynx_euroc_airbrakes.toml").airbrakes


@pytest.mark.parametrize("mach, naca_p_over_p0", [(0.5, 0.8430), (0.8, 0.6560), (0.9, 0.5913)])
def test_impact_pressure_against_naca_1135(mach, naca_p_over_p0):
    # NACA Report 1135, Table I (γ = 1.4), p/p0 to 4 digits: q_c/q = (p0/p − 1)/(0.7 M²), good to ~1e-4 relative
    expected = (1.0 / naca_p_over_p0 - 1.0) / (0.7 * mach**2)
    assert float(stagnation_pressure_ratio(mach)) == pytest.approx(expected, rel=3e-4)


def test_impact_pressure_at_low_mach_is_the_series():
    mach = 0.2  # 1 + M²/4 + M⁴/40 + M⁶/1600; the next term is below 1e-8 there
    assert float(stagnation_pressure_ratio(mach)) == pytest.approx(1 + mach**2 / 4 + mach**4 / 40 + mach**6 / 1600, rel=1e-8)
    assert float(stagnation_pressure_ratio(0.0)) == 1.0


def test_panels_are_hoerners_plates():
    area = 3 * 0.05 * 0.02  # three 50 × 20 mm plates, on a 0.01767 m² reference
    assert float(panel_delta_ca(1.0, 0.0, 3, 0.05, 0.02, 0.01767)) == pytest.approx(HOERNER_SQUARE_PLATE_CD * area / 0.01767, rel=1e-15)
    assert float(panel_delta_ca(0.5, 0.0, 3, 0.05, 0.02, 0.01767)) == pytest.approx(0.5 * HOERNER_SQUARE_PLATE_CD * area / 0.01767, rel=1e-15)
    assert float(panel_delta_ca(0.0, 0.7, 3, 0.05, 0.02, 0.01767)) == 0.0


def _without_drag(params):
    zero = lambda table: dataclasses.replace(table, values=jnp.zeros_like(table.values))  # noqa: E731
    return dataclasses.replace(params, known_ca=zero(params.known_ca), drag=zero(params.drag))


@pytest.mark.parametrize("height, climb, horizontal", [(900.0, 290.0, 40.0), (2000.0, 120.0, 10.0), (10.0, 3.0, 0.0)])
def test_prediction_without_drag_is_the_parabola(brakes, height, climb, horizontal):
    predicted = float(jax.jit(predicted_apogee_m)(_without_drag(brakes), height, climb, horizontal, 0.3))
    # RK4 is exact on the drag-free coast and the crossing's interpolation on a linear climb rate: round-off only
    assert predicted == pytest.approx(height + climb**2 / (2 * G0), rel=1e-12)


def test_prediction_of_a_falling_rocket_is_where_it_is(brakes):
    assert float(predicted_apogee_m(brakes, 1500.0, -5.0, 20.0, 0.0)) == 1500.0


def _scipy_coast(brakes, deployment):
    """The flight software's point-mass coast (``coast_rates``) in numpy for scipy: (t, [h, w, u]) -> rates."""
    site, area, mass = float(brakes.site_altitude_m), float(brakes.reference_area_m2), float(brakes.coast_mass_kg)
    machs, ca = np.asarray(brakes.known_ca.axes[0]), np.asarray(brakes.known_ca.values[:, 0])
    d_axes = [np.asarray(a) for a in brakes.drag.axes]
    d_values = np.asarray(brakes.drag.values[..., 0])

    def delta_ca(mach):
        along = [np.interp(mach, d_axes[1], row) for row in d_values]
        return np.interp(deployment, d_axes[0], along)

    def rates(_, y):
        h, w, u = y
        air = isa(site + h)
        speed = np.hypot(w, u)
        mach = speed / float(air.speed_of_sound)
        k = 0.5 * float(air.density) * speed * area * (np.interp(mach, machs, ca) + delta_ca(mach)) / mass
        return [w, -G0 - k * w, -k * u]

    return rates


@pytest.mark.parametrize("deployment", [0.0, 0.4, 1.0])
def test_prediction_against_scipy(brakes, deployment):
    """The same point mass integrated by scipy's RK45 to 1e-11 with an event at the apogee."""
    apogee = lambda _, y: y[1]  # noqa: E731
    apogee.terminal, apogee.direction = True, -1
    height, climb, horizontal = 949.0, 291.0, 44.0
    reference = solve_ivp(_scipy_coast(brakes, deployment), (0.0, 60.0), [height, climb, horizontal], events=apogee,
                          rtol=1e-11, atol=1e-9)  # fmt: skip
    predicted = float(jax.jit(predicted_apogee_m)(brakes, height, climb, horizontal, deployment))
    # PREDICTION_STEPS RK4 steps and a linear crossing: measured within 1.6 m of these 2.4 km climbs (its docstring)
    assert predicted == pytest.approx(reference.y_events[0][0][0], abs=2.0)


def _nav(height, climb, horizontal=0.0):
    zero = jnp.zeros(())
    return Navigation(Vec3(zero, zero, zero - height), Vec3(zero + horizontal, zero, zero - climb),
                      Quat(zero + 1.0, zero, zero, zero), Vec3(zero, zero, zero))  # fmt: skip


def test_the_brakes_stay_in_until_allowed(brakes):
    state = initial_airbrakes(brakes, jnp.zeros(()))
    lifted = airbrake_step(brakes, state, _nav(0.1, 1.0), True, 0.52, 0.02, False)
    assert float(lifted.liftoff_time) == 0.52 and float(lifted.servo.command_rad) == 0.0
    early = float(brakes.allowed_after_s) - 0.02  # still burning: in, whatever the prediction
    assert float(airbrake_step(brakes, lifted, _nav(900.0, 200.0), True, 0.52 + early, 0.02, False).servo.command_rad) == 0.0
    later = 0.52 + float(brakes.allowed_after_s) + 1.0
    fast = airbrake_step(brakes, lifted, _nav(900.0, 300.0), True, later, 0.02, False)  # Mach 0.9 > max_mach
    assert float(fast.servo.command_rad) == 0.0 and np.isnan(float(fast.predicted_apogee_m))
    under_canopy = airbrake_step(brakes, lifted, _nav(900.0, 200.0), True, later, 0.02, True)
    assert float(under_canopy.servo.command_rad) == 0.0


def test_the_command_integrates_the_predicted_error(brakes):
    state = dataclasses.replace(initial_airbrakes(brakes, jnp.zeros(())), liftoff_time=jnp.asarray(0.5))
    t, dt = 0.5 + float(brakes.allowed_after_s) + 1.0, 0.02
    stepped = airbrake_step(brakes, state, _nav(1500.0, 220.0, 30.0), True, t, dt, False)
    predicted = float(predicted_apogee_m(brakes, 1500.0, 220.0, 30.0, 0.0))
    expected = np.clip(float(brakes.gain_per_m_s) * dt * (predicted - float(brakes.target_apogee_m)), 0.0, 1.0)
    assert float(stepped.servo.command_rad) == pytest.approx(expected, rel=1e-12)
    assert float(stepped.predicted_apogee_m) == pytest.approx(predicted, rel=1e-12)


@pytest.fixture(scope="module")
def pi_brakes():
    from rocketmc.campaign import load_campaign, with_overrides

    campaign = with_overrides(load_campaign(CAMPAIGNS / "lynx_euroc_airbrakes.toml"),
                              values={"airbrakes.controller": "reference_pi"})  # fmt: skip
    return campaign.airbrakes, campaign.airbrake_design


@pytest.mark.parametrize("level", [0, 4, 8])
def test_references_are_the_backward_coast_of_scipy(pi_brakes, level):
    """Each reference against scipy's RK45 (rtol 1e-11) integrating the same coast backward from the target apogee
    with the brakes held at its level, at the reference's own heights."""
    brakes, design = pi_brakes
    r = brakes.reference
    target = float(brakes.target_apogee_m)
    ground = lambda _, y: y[0]  # noqa: E731
    ground.terminal = True
    back = solve_ivp(_scipy_coast(brakes, float(r.levels[level])), (0.0, -60.0), [target, 0.0, design.apogee_horizontal_mps],
                     events=ground, rtol=1e-11, atol=1e-9, dense_output=True)  # fmt: skip
    heights, climbs = np.asarray(r.heights_m), np.asarray(r.climb_mps[level])
    times = np.linspace(back.t[-1], 0.0, 20001)
    h, w = back.sol(times)[:2]
    below = heights < target
    expected = np.interp(heights[below], h, w)
    # RK4 at 0.02 s and the linear interpolation in height between its steps (h sampled 20 001 times here): measured
    # within 0.002 m/s over the nine levels, the largest at the most braked, fastest near the pad
    assert np.max(np.abs(climbs[below] - expected)) < 0.005
    assert climbs[-1] == 0.0  # at the target apogee itself


def _pi_tick(brakes, height, climb, horizontal=30.0, state=None, t=None):
    state = state or dataclasses.replace(initial_airbrakes(brakes, jnp.zeros(())), liftoff_time=jnp.asarray(0.5))
    t = 0.5 + float(brakes.allowed_after_s) + 1.0 if t is None else t
    return airbrake_step(brakes, state, _nav(height, climb, horizontal), True, t, 0.02, False)


def _reference_climb(brakes, level, height):
    r = brakes.reference
    return float(np.interp(height, np.asarray(r.heights_m), np.asarray(r.climb_mps[level])))


def test_the_pi_on_a_reference_commands_its_level(pi_brakes):
    brakes, _ = pi_brakes
    stepped = _pi_tick(brakes, 1500.0, _reference_climb(brakes, 4, 1500.0))
    assert int(stepped.reference.trajectory) == 4  # the nearest reference: this one
    # no error, no integral: the reference's own ΔCA, inverted on the piecewise-linear table: its level to round-off
    assert float(stepped.servo.command_rad) == pytest.approx(float(brakes.reference.levels[4]), rel=1e-12)
    assert float(stepped.reference.integral_n) == 0.0


def test_the_pi_adds_the_drag_of_its_proportional_and_integral_terms(pi_brakes):
    brakes, _ = pi_brakes
    first = _pi_tick(brakes, 1500.0, _reference_climb(brakes, 4, 1500.0))
    height, excess, horizontal = 1600.0, 0.5, 30.0  # within the brakes' reach: no saturation
    climb = _reference_climb(brakes, 4, height) + excess
    later = _pi_tick(brakes, height, climb, horizontal, first, 0.5 + float(brakes.allowed_after_s) + 1.02)
    assert int(later.reference.trajectory) == 4  # kept, though another reference is nearer now
    r, air = brakes.reference, isa(float(brakes.site_altitude_m) + height)
    speed = np.hypot(climb, horizontal)
    mach = speed / float(air.speed_of_sound)
    integral = float(r.ki_n_per_m) * 0.02 * excess
    force = float(r.kp_n_s_per_m) * excess + integral  # [N] of vertical drag beyond the reference's
    expected = float(delta_ca(brakes, r.levels[4], mach)) + force / (0.5 * float(air.density) * float(brakes.reference_area_m2) * climb * speed)
    assert float(delta_ca(brakes, later.servo.command_rad, mach)) == pytest.approx(expected, rel=1e-9)
    assert float(later.reference.integral_n) == pytest.approx(integral, rel=1e-12)


def test_the_pi_holds_its_integral_while_saturated(pi_brakes):
    brakes, _ = pi_brakes
    first = _pi_tick(brakes, 1500.0, _reference_climb(brakes, 4, 1500.0))
    too_fast = _pi_tick(brakes, 1600.0, _reference_climb(brakes, 4, 1600.0) + 60.0, 30.0, first,
                        0.5 + float(brakes.allowed_after_s) + 1.02)  # fmt: skip
    assert float(too_fast.servo.command_rad) == 1.0 and float(too_fast.saturated_time) == pytest.approx(0.02)
    assert float(too_fast.reference.integral_n) == float(first.reference.integral_n)
    assert np.isnan(float(too_fast.predicted_apogee_m))  # no prediction in this law


def test_the_servo_follows_its_exact_first_order_response(brakes):
    tau, period = float(brakes.servo.time_constant_s), 0.02
    servo = ServoState(jnp.asarray(0.0), jnp.asarray(1.0))  # a full command held from retracted
    for k in range(1, 11):
        servo = end_of_period(brakes.servo, servo, period)
        assert float(servo.deflection_rad) == pytest.approx(1.0 - np.exp(-k * period / tau), rel=1e-14)
