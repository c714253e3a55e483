"""One flight, from the rail to the ground: the control-period step (``step``: sensors, GNC, RK4 substeps with
events) and its drivers (``simulate_one``, ``fly_block``, ``fly``).

Single-vehicle and pure: ``jit`` and ``vmap`` are applied by its callers (``campaign.runner`` for campaigns; the
others in docs/architecture.md, "Where jit and vmap sit").
Phases are masks, not branches: on the rail, under canopy and on the ground all run the same
code. Event times are ``inf`` until the event happens.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from typing import NamedTuple

import jax
import jax.numpy as jnp

from ..dynamics import RigidBodyState
from ..dynamics.rigid_body import normalize_attitude
from ..dynamics.servo import deflection_at, end_of_period
from ..env import advance_turbulence, gust_n, initial_turbulence, turbulence_noise, turbulence_scales
from ..gnc.airbrakes import AirbrakeState, airbrake_step, initial_airbrakes
from ..gnc.control import gnc_step, initial_gnc, navigate, track_navigation, truth
from ..math import Vec3, rk4_step, safe_sqrt
from ..sensors.avionics import avionics_noise, initial_avionics, sense, sense_acceleration, specific_force_b
from ..pytree import tree_where
from .events import rail_start_n, rail_travel_m, update_events
from .faults import faulty_servos, faulty_sensors, stuck_airbrakes
from .loads import derivatives, mass_properties
from .outputs import flight_summary
from .params import FlightParams, SimSettings
from .state import Canopy, Events, FlightState, done


def initial_state(p: FlightParams) -> FlightState:
    """At rest on the rail, the nozzle exit at the pad, t = 0."""
    zero = jnp.zeros_like(p.rocket.dry_mass_kg)
    inf = zero + jnp.inf
    body = RigidBodyState(rail_start_n(p), Vec3(zero, zero, zero), p.launch.q_nb0, Vec3(zero, zero, zero))
    events = Events(
        inf, zero, inf, zero, zero, inf, zero, zero, zero,
        tuple(inf for _ in p.rocket.parachutes), inf, zero, zero, zero, zero, zero, zero,
        jnp.zeros_like(zero, dtype=bool),
    )  # fmt: skip
    turbulence = p.environment.turbulence
    filters = None if turbulence is None else initial_turbulence(turbulence)
    gnc = None if p.gnc is None else initial_gnc(p.gnc, zero)
    avionics = None if p.avionics is None else initial_avionics(p.avionics, zero)
    airbrakes = None if p.airbrakes is None else initial_airbrakes(p.airbrakes, zero)
    return FlightState(zero, jnp.zeros_like(zero, dtype=jnp.int32), body, events, Canopy(zero, zero), filters, gnc,
                       avionics, airbrakes)  # fmt: skip


def steady_descent(p: FlightParams, settings: SimSettings, state: FlightState):
    """Whether the period starting at ``state`` is one of steady descent and whether the body flies it as a point
    mass (bools). Steady: under a fully open canopy once every triggered opening has settled (``settings.settle_s``
    after full opening), unless a wind-layer boundary is within ``_reach_m`` (its wind jump is a transient too). A
    point mass (with ``settings.point_mass_descent``): steady, ``settings.swing_settle_s`` after the last opening
    settled and after the last wind-layer boundary crossed, when the body's swing under its canopies has died out,
    and not within ``_reach_m`` of a trigger altitude still to come (False without it)."""
    t, events = state.t, state.events
    any_open = transient = swinging = jnp.zeros_like(t, dtype=bool)
    for chute, trigger_time in zip(p.rocket.parachutes, events.chute_trigger_times):
        settled = trigger_time + chute.delay_s + chute.opening_time_s + settings.settle_s
        any_open = any_open | (t >= settled)
        transient = transient | (jnp.isfinite(trigger_time) & (t < settled))
        swinging = swinging | (jnp.isfinite(trigger_time) & (t < settled + settings.swing_settle_s))
    altitude, reach = -state.body.r_n.z, _reach_m(settings, state)
    swung = reach + jnp.abs(state.body.v_n.z) * settings.swing_settle_s
    for jump_altitude in p.environment.wind.jump_altitudes_m():
        transient = transient | (jnp.abs(altitude - jump_altitude) < reach)
        swinging = swinging | ((altitude < jump_altitude) & (jump_altitude - altitude < swung))
    steady = any_open & ~transient
    if not settings.point_mass_descent:
        return steady, False
    for trigger_gap in _trigger_gaps_m(p, state):
        swinging = swinging | (jnp.abs(trigger_gap) < reach)
    return steady, steady & ~swinging


def _reach_m(settings: SimSettings, state: FlightState):
    """How near a wind-layer boundary [m] a descent is a transient, and how near one or a trigger altitude a point mass
    stops: one longest 6-DOF descent period's sink + 1 m."""
    return jnp.abs(state.body.v_n.z) * settings.descent_dt_s + 1.0


def _trigger_gaps_m(p: FlightParams, state: FlightState) -> list:
    """Each parachute still to be triggered at an altitude: its trigger altitude minus the altitude [m] (with the
    navigation's held height error when it triggers them), inf for the others."""
    altitude = -state.body.r_n.z
    sensed_error = 0.0 if state.gnc is None or state.gnc.recovery is None else state.gnc.recovery.height_error_m
    pending = jnp.isfinite(state.events.apogee_time)
    chutes = zip(p.rocket.parachutes, state.events.chute_trigger_times)
    return [jnp.where(pending & jnp.isinf(trigger), chute.trigger_altitude_agl_m - altitude - sensed_error, jnp.inf)
            for chute, trigger in chutes]  # fmt: skip


def control_period(p: FlightParams, settings: SimSettings, start_n: Vec3, state: FlightState):
    """The period starting at ``state`` [s] and whether the body flies it as a point mass (bool, ``steady_descent``).

    ``regular_period_s``; in steady descent under canopy it grows up to ``settings.descent_dt_s`` while the body's
    pendulum rate ω allows RK4 steps with h·ω ≤ ``settings.descent_h_omega``; as a point mass up to
    ``POINT_MASS_MAX_S`` while h·λ ≤ ``POINT_MASS_H_RATE``, λ the rate at which the canopies' quadratic drag
    settles the air-relative velocity (``Canopy``), and ending where the point mass ends (``point_mass_period``). Without a
    controller and sensors, a period in which the forces switch ends there (``event_period``). Each realization
    keeps its own clock."""
    regular = regular_period_s(p, settings)
    steady, point_mass = steady_descent(p, settings, state)
    stable_period = settings.substeps * settings.descent_h_omega / jnp.sqrt(jnp.maximum(state.canopy.stiffness, 1e-12))
    descent_period = jnp.clip(stable_period, regular, max(settings.descent_dt_s, regular))
    period = jnp.where(steady, descent_period, regular)
    if point_mass is not False:
        period = jnp.where(point_mass, point_mass_period(p, settings, state, descent_period), period)
    if _events_end_periods(p, settings):
        period = event_period(p, start_n, state, period)
    return period, point_mass


def point_mass_period(p: FlightParams, settings: SimSettings, state: FlightState, shortest):
    """A point-mass period [s] (``control_period``), at least ``shortest`` [s] unless it ends first just inside
    ``_reach_m`` of a wind-layer boundary or a trigger altitude, or just below the ground (each predicted at the
    start's sink, overshot by ``EVENT_OVERSHOOT``): a long RK4 step must not reach across the wind's jump or the
    opening, nor its stages far below the ground (where the low-altitude turbulence scales vanish)."""
    altitude, climb = -state.body.r_n.z, -state.body.v_n.z
    mean_wind_n, _, gust = period_gust(p, state)
    drag_per_m, airspeed = state.canopy.drag_per_m, (state.body.v_n - mean_wind_n - gust).norm()
    gravity = p.environment.gravity_mps2(p.environment.site_altitude_m + altitude)
    rate = 2.0 * jnp.maximum(drag_per_m * airspeed, safe_sqrt(gravity * drag_per_m))  # now, or at the terminal speed
    period = jnp.clip(settings.substeps * POINT_MASS_H_RATE / jnp.maximum(rate, 1e-12), shortest, POINT_MASS_MAX_S)
    reach = _reach_m(settings, state)
    gaps = [jump - altitude + reach for jump in p.environment.wind.jump_altitudes_m()]
    gaps += [gap + reach for gap in _trigger_gaps_m(p, state)] + [-altitude]
    to_edge = functools.reduce(jnp.minimum, [_time_to(gap, climb) for gap in gaps], jnp.inf)
    return jnp.minimum(to_edge + EVENT_OVERSHOOT * period, period)


POINT_MASS_H_RATE = 2.0
"""The largest RK4 step h of a point-mass period times the rate λ [1/s] at which quadratic drag settles the
air-relative velocity v_air (gust included): 2κ|v_air| with κ = ``Canopy.drag_per_m``, or 2κ·v_t = 2√(gκ) at the
terminal speed v_t = √(g/κ) if larger (a gust can leave the canopy nearly still in the air, and the period must stay
stable as it falls back to v_t). RK4 is stable to h·λ = 2.8 on decaying modes."""
POINT_MASS_MAX_S = 5.0
"""The longest point-mass period [s]."""


def regular_period_s(p: FlightParams, settings: SimSettings) -> float:
    """A period's length outside steady descent [s], unless an event ends it first: ``settings.open_loop_dt_s``
    without a controller and sensors when events end periods (``settings.event_periods``), else the GNC's
    ``settings.control_dt_s``."""
    return settings.open_loop_dt_s if _events_end_periods(p, settings) else settings.control_dt_s


def _events_end_periods(p: FlightParams, settings: SimSettings) -> bool:
    # with them, each period is a GNC tick
    return settings.event_periods and p.gnc is None and p.avionics is None and p.airbrakes is None


EVENT_OVERSHOOT = 0.01
"""How far past the predicted switch ``event_period`` ends its period, as a fraction of the regular period (0.2 ms
at 20 ms): a climb that slows reaches a wind-layer boundary a little later than at the start's speed (3e-5 s for
Lynx at 200 m/s and 30 m/s² in a 20 ms period, 1.2e-4 s at 50 m/s); it is also the shortest period taken, so a
prediction that keeps falling short (a climb that stops just below a boundary) costs a few periods, not ever shorter
ones."""
CLOCK_RESOLUTION_S = 1e-9
"""A kink less than this ahead of the clock [s] is where the clock is (a period that ended there)."""


def event_period(p: FlightParams, start_n: Vec3, state: FlightState, period):
    """``period`` [s], or shorter: ending where the right-hand side switches or kinks, if that is within the period.
    Switches, predicted at the period start's velocity and overshot by ``EVENT_OVERSHOOT``: the rocket on the rail
    reaching its exit (``rail_travel_m``), crossing a wind-layer boundary (a jump of the layered wind). Kinks, at known
    times: the thrust curve's points (a canopy's opening ramp is one too, but ending periods there measured no gain).
    A switch acts from the step after the one it happens in (the rail's constraint holds through each RK4 step it
    starts, as the events are the step start's) or jumps inside it (a stage past a boundary sees the other layer's
    wind), so a step across one integrates its far side with the near side's forces, an error of the order of the
    step; a kink inside a step costs RK4 its order. Ending the period there keeps both out (lynx_nominal without
    turbulence, N = 1 000, against RK4 steps ten times finer: the impact point's worst error went from 10.7 m to
    2.0 m; with 40 ms periods, the thrust curve's points took the apogee's median error from 0.24 % to 0.004 %:
    docs/validation.md, "Step size")."""
    rail = p.launch.rail_direction_n
    travel = rail_travel_m(p) - (state.body.r_n - start_n).dot(rail)
    to_switch = jnp.where(jnp.isinf(state.events.rail_exit_time), _time_to(travel, state.body.v_n.dot(rail)), jnp.inf)
    altitude, climb = -state.body.r_n.z, -state.body.v_n.z
    for boundary in p.environment.wind.jump_altitudes_m():
        to_switch = jnp.minimum(to_switch, _time_to(boundary - altitude, climb))
    to_kink = p.rocket.motor.ignition_time_s + p.rocket.motor.time_s - state.t
    to_kink = jnp.min(jnp.where(to_kink > CLOCK_RESOLUTION_S, to_kink, jnp.inf))
    return jnp.minimum(jnp.minimum(to_switch + EVENT_OVERSHOOT * period, to_kink), period)


def _time_to(gap, speed):
    """Time [s] to close ``gap`` [m] at ``speed`` [m/s] along it; inf when moving away or still, or for an infinite
    gap (kept out of the division, whose derivative there would be inf: reverse mode's 0·inf)."""
    closing = (gap * speed > 0.0) & jnp.isfinite(gap)
    return jnp.where(closing, jnp.where(closing, gap, 0.0) / jnp.where(closing, speed, 1.0), jnp.inf)


def period_gust(p: FlightParams, state: FlightState):
    """The mean wind at the period start's height [m/s, NED], the turbulence's ``turbulence_scales`` there (None
    without turbulence) and the gust held over the period starting at ``state`` [m/s, NED]."""
    altitude = -state.body.r_n.z
    mean_wind_n = p.environment.wind.velocity_n(altitude)
    if p.environment.turbulence is None:
        return mean_wind_n, None, Vec3.zeros(state.t)
    scales = turbulence_scales(p.environment.turbulence, altitude)
    return mean_wind_n, scales, gust_n(state.turbulence, scales, mean_wind_n, state.body.q_nb)


def control_step(
    p: FlightParams, settings: SimSettings, start_n: Vec3, state: FlightState, period, deflections, noise=None,
    first_stage: bool = False, point_mass=False, deployment=None,
) -> tuple[FlightState, jnp.ndarray | None]:  # fmt: skip
    """One control period of ``period`` [s] (``control_period``) with the turbulent gust held: RK4 substeps
    of the rigid body with events, then the turbulence filters advanced over the period with ``noise``,
    the period's row of turbulence noise (None without turbulence); ``tick`` + 1. point_mass (bool,
    ``steady_descent``'s): the body's rates set to zero and its attitude held over the period. Returns the new state and,
    with ``first_stage``, the CG's acceleration [m/s², NED], the body's angular acceleration [rad/s², FRD], the
    dynamic pressure [Pa] and the CG's position x [m, body] at the period start (the first RK4 stage's), as one
    (8,) array, else None.

    deflections: the canard deflections δ1..δn [rad] as a function of the time t [s] inside the
    period (held, or the servos' response evaluated at each RK4 stage); deployment: the air brakes' (0 … 1), a
    function of t too (None without air brakes).
    """
    h = period / settings.substeps
    turbulence = p.environment.turbulence
    mean_wind_n, scales, gust = period_gust(p, state)
    recovery = None if state.gnc is None else state.gnc.recovery
    sensed = None if recovery is None else (recovery.height_error_m, jnp.isfinite(recovery.apogee_time))

    def rhs(t, y, events):
        brakes = None if deployment is None else deployment(t)
        d_body, diag = derivatives(t, y, p, deflections(t), gust, events, point_mass, brakes)
        if not first_stage:
            return d_body, (diag, None)
        # one array, not a pytree: RK4 keeps its first stage's by-products with a select per leaf and stage; the CG
        # is the stage's own (``loads``'): the same operations at the same time, computed once by XLA
        cg_x = mass_properties(p, t).cg_x
        return d_body, (diag, jnp.stack([*d_body.v_n, *d_body.omega_b, diag.qbar, cg_x]))

    def substep(carry, _):
        t0, body0, events, _ = carry
        body1, (diag, derivative) = rk4_step(lambda t, y: rhs(t, y, events), t0, body0, h)
        body1 = normalize_attitude(body1)
        events = update_events(p, start_n, events, t0, h, body0, body1, diag, sensed)
        return (t0 + h, body1, events, diag.canopy), derivative

    body = state.body
    if point_mass is not False:
        body = tree_where(point_mass, body._replace(omega_b=Vec3.zeros(state.t)), body)
    carry = (state.t, body, state.events, state.canopy)
    (t, body, events, canopy), derivatives_at_start = jax.lax.scan(substep, carry, None, settings.substeps)
    first = None if derivatives_at_start is None else jax.tree_util.tree_map(lambda x: x[0], derivatives_at_start)
    finite = functools.reduce(jnp.logical_and, [jnp.isfinite(x) for x in jax.tree_util.tree_leaves(body)])
    body = tree_where(done(state) | ~finite, state.body, body)
    events = tree_where(done(state), state.events, events)
    events = dataclasses.replace(events, non_finite=events.non_finite | ~finite)
    filters = state.turbulence
    if turbulence is not None:
        airspeed = (state.body.v_n - mean_wind_n - gust).norm()
        filters = advance_turbulence(filters, scales, airspeed, period, noise)
    return FlightState(state.t + period, state.tick + 1, body, events, canopy, filters, state.gnc, state.avionics,
                       state.airbrakes), first  # fmt: skip


class StepNoise(NamedTuple):
    """A control period's random numbers: the turbulence's row (None without turbulence) and each sensor's
    (``sensors.avionics.avionics_noise``; None without sensors)."""

    turbulence: jnp.ndarray | None
    avionics: dict | None


def step(p: FlightParams, settings: SimSettings, start_n: Vec3, state: FlightState, noise: StepNoise,
         canard_command=None):  # fmt: skip
    """The step of every driver (``fly_block``, ``fly``): the sensors at the period start, the canard
    deflections of the period, ``control_step``, then the accelerometer. start_n: ``rail_start_n(p)``;
    noise: the period's ``StepNoise``; canard_command: open-loop deflections, a function of time [s]
    returning δ1..δn [rad] held over the period (None: neutral, or the closed loop's when ``p.gnc`` is set:
    guidance and control at the period start, the servos' response inside it; navigating from the sensors, the
    LQI reads the canard feedback and the parachutes trigger on the navigation: ``gnc.control.navigate``). The air
    brakes (``p.airbrakes``) read the closed loop's navigation, or the truth without one (``_airbrakes``)."""
    period, point_mass = control_period(p, settings, start_n, state)
    sensing = (period <= settings.control_dt_s) & ~jnp.asarray(point_mass)  # GNC periods only, not long or point-mass ones
    if p.gnc is None:
        held = jnp.zeros(p.rocket.aero.n_canards) if canard_command is None else canard_command(state.t)
        held = jnp.asarray(held, dtype=float)
        start = _sensed(p, state, held, sensing, noise)
        brakes, deployment = _airbrakes(p, settings, start, *truth(start.body), _canopy(start.events.chute_trigger_times))
        state, first = control_step(p, settings, start_n, start, period, lambda t: held, noise.turbulence,
                                    p.avionics is not None, point_mass, deployment)  # fmt: skip
        return _accelerometer(p, start, _with_airbrakes(p, state, brakes, period), first, sensing, noise)
    if canard_command is not None:
        raise ValueError("canard_command flies open loop: it needs a flight without a controller (p.gnc None)")
    servo_params, t0 = p.gnc.servo, state.t
    steering = p.gnc.gains is not None  # else the navigation alone (gnc.canards false), the canards neutral
    neutral = jnp.zeros(p.rocket.aero.n_canards)
    state = start = _sensed(p, state, state.gnc.servo.deflection_rad if steering else neutral, sensing, noise)
    canopy = _canopy(state.events.chute_trigger_times)
    navigated = navigate(p.gnc, p.avionics, state.gnc, state.body, state.avionics, t0, canopy,
                         [chute.trigger_altitude_agl_m for chute in p.rocket.parachutes],
                         state.events.chute_trigger_times)  # fmt: skip
    nav, events = navigated.solution, state.events
    if navigated.trigger_times is not None:
        canopy = _canopy(navigated.trigger_times)
        triggered = dataclasses.replace(events, chute_trigger_times=navigated.trigger_times)
        events = tree_where(done(state), events, triggered)
    state = dataclasses.replace(state, gnc=navigated.state, events=events)
    gnc = state.gnc
    if steering:
        altitude_msl = p.environment.site_altitude_m - nav.r_n.z
        gnc = gnc_step(p.gnc, gnc, nav, navigated.moving, t0, settings.control_dt_s, altitude_msl, canopy,
                       navigated.feedback_rad)  # fmt: skip
    body = state.body
    ascent = (body.v_n.dot(body.v_n) > 0.0) & jnp.isinf(events.apogee_time)
    gnc = track_navigation(p.gnc, gnc, t0, settings.control_dt_s, canopy, body, _avionics_at(p, t0), state.avionics,
                           ascent, t0 >= events.burnout_time, t0 >= events.apogee_time)  # fmt: skip
    brakes, deployment = _airbrakes(p, settings, state, nav, navigated.moving, canopy)
    deflections = lambda t: neutral  # noqa: E731
    if steering:
        held = gnc.servo
        if p.faults is not None and p.faults.servos:
            servo_params, held = faulty_servos(p.faults, servo_params, held, t0)
        gnc = dataclasses.replace(gnc, servo=end_of_period(servo_params, held, period))
        deflections = lambda t: deflection_at(servo_params, held, t - t0)  # noqa: E731
    state, first = control_step(p, settings, start_n, state, period, deflections, noise.turbulence,
                                p.avionics is not None, point_mass, deployment)  # fmt: skip
    state = dataclasses.replace(state, gnc=gnc)
    return _accelerometer(p, start, _with_airbrakes(p, state, brakes, period), first, sensing, noise)


def _airbrakes(p: FlightParams, settings: SimSettings, state: FlightState, nav, moving, canopy):
    """The air brakes at the period start ``state`` (``gnc.airbrakes.airbrake_step`` on the navigation solution
    ``nav``, ``moving`` and ``canopy`` as it sees them; stuck once their fault happened: ``sim.faults``) and their
    deployment over the period, a function of the time [s]; (None, None) without air brakes."""
    if p.airbrakes is None:
        return None, None
    brakes = airbrake_step(p.airbrakes, state.airbrakes, nav, moving, state.t, settings.control_dt_s, canopy)
    if p.faults is not None and p.faults.stuck_airbrakes is not None:
        brakes = dataclasses.replace(brakes, servo=stuck_airbrakes(p.faults.stuck_airbrakes, brakes.servo, state.t))
    return brakes, lambda t: deflection_at(p.airbrakes.servo, brakes.servo, t - state.t)


def _with_airbrakes(p: FlightParams, state: FlightState, brakes: AirbrakeState | None, period) -> FlightState:
    """``state``, the period's end, with the air brakes' servo ``period`` [s] after ``brakes`` (no change without)."""
    if brakes is None:
        return state
    servo = end_of_period(p.airbrakes.servo, brakes.servo, period)
    return dataclasses.replace(state, airbrakes=dataclasses.replace(brakes, servo=servo))


def _canopy(trigger_times):
    """Whether a parachute has been triggered by now (bool): one of ``trigger_times`` [s] finite."""
    return functools.reduce(jnp.logical_or, [jnp.isfinite(t) for t in trigger_times], False)


def _avionics_at(p: FlightParams, t):
    """The sensors as they sample at ``t`` [s]: with the faults that happened by then (``sim.faults``)."""
    return faulty_sensors(p.faults, p.avionics, t) if p.faults is not None and p.faults.sensors else p.avionics


def _at_rest_once_landed(state: FlightState) -> RigidBodyState:
    """The body the sensors see: once landed (or stopped) at rest where it came down."""
    body, landed = state.body, done(state)
    zero = Vec3.zeros(state.t)
    return body._replace(v_n=tree_where(landed, zero, body.v_n), omega_b=tree_where(landed, zero, body.omega_b))


def _sensed(p: FlightParams, state: FlightState, deflections, sensing, noise: StepNoise) -> FlightState:
    """``state`` with every sensor but the accelerometer sampled at its time (no change without sensors)."""
    if p.avionics is None:
        return state
    body = _at_rest_once_landed(state)
    avionics = sense(_avionics_at(p, state.t), state.avionics, state.tick, state.t, body.r_n, body.v_n, body.q_nb, body.omega_b,
                     deflections, p.environment, sensing, noise.avionics)  # fmt: skip
    return dataclasses.replace(state, avionics=avionics)


def _accelerometer(p: FlightParams, start: FlightState, state: FlightState, first, sensing,
                   noise: StepNoise) -> FlightState:  # fmt: skip
    """``state``, the period's end, with the accelerometer's sample of the period start ``start`` (from the
    accelerations, dynamic pressure and CG ``first`` there, ``control_step``'s, at rest once landed); ``state``
    itself without sensors."""
    if p.avionics is None:
        return state
    acceleration_n, omega_dot_b, qbar, cg_x = Vec3(*first[:3]), Vec3(*first[3:6]), first[6], first[7]
    body, landed = _at_rest_once_landed(start), done(start)
    zero = Vec3.zeros(start.t)
    position = p.avionics.accelerometer.position_b
    arm_b = Vec3(position[0] - cg_x, position[1], position[2])
    gravity = p.environment.gravity_mps2(p.environment.site_altitude_m - body.r_n.z)
    force = specific_force_b(tree_where(landed, zero, acceleration_n), body.q_nb, body.omega_b,
                             tree_where(landed, zero, omega_dot_b), arm_b, gravity)  # fmt: skip
    qbar = jnp.where(landed, 0.0, qbar)
    avionics = sense_acceleration(_avionics_at(p, start.t), state.avionics, start.tick, force, qbar, sensing,
                                  noise.avionics)  # fmt: skip
    return dataclasses.replace(state, avionics=avionics)


def simulate_one(p: FlightParams, settings: SimSettings) -> tuple[dict, jnp.ndarray]:
    """Fly until landed, stopped or ``settings.max_time_s``; return (summary dict, status code).

    The loop runs in blocks of ``settings.block_steps`` control periods (``fly_block``), as many as the flight
    needs: a ``while_loop``, which forward-mode derivatives (``jax.jvp``) go through and reverse mode does not
    (``simulate_bounded``).
    """

    def block(carry):
        state, index = carry
        return fly_block(p, settings, state, index), index + 1

    final, _ = jax.lax.while_loop(
        lambda carry: ~flight_done(settings, carry[0]), block, (initial_state(p), jnp.zeros((), jnp.uint32))
    )
    return flight_summary(p, final)


def simulate_bounded(params_of: Callable[..., FlightParams], inputs, settings: SimSettings,
                     n_blocks: int) -> tuple[dict, jnp.ndarray]:  # fmt: skip
    """``simulate_one``'s flights of ``params_of(input)`` for a batch of inputs (a pytree with a leading flight axis),
    in at most ``n_blocks`` blocks: a ``scan`` with a fixed number of steps, through which reverse-mode derivatives
    (``jax.grad``, ``jax.vjp``) go, each block skipped once every flight of the batch is done (``lax.cond`` on the
    whole batch). A flight done keeps its state, so with enough blocks (``max_blocks``) the summaries are
    ``simulate_one``'s, to round-off (too few: the flights still up are cut, status MAX_TIME). Each block and each period in it
    are rematerialised in the backward pass (``jax.checkpoint``): a gradient holds one state per block, one per
    period of the block being differentiated and one period's intermediates, for each flight, as diffrax's
    checkpointed loops do. The parameters are made per flight inside each block, so that what the flights share
    (tables, thrust curve) stays one array, and no derivative is taken with respect to it."""
    fly_all = jax.vmap(lambda i, state, index: fly_block(params_of(i), settings, state, index, True),
                       in_axes=(0, 0, None))  # fmt: skip
    done_all = jax.vmap(lambda state: flight_done(settings, state))

    def block(states, index):
        done = done_all(states)
        flown = lambda states: jax.vmap(tree_where)(done, states, fly_all(inputs, states, index))  # noqa: E731
        return jax.lax.cond(jnp.all(done), lambda states: states, flown, states), None

    blocks = jnp.arange(n_blocks, dtype=jnp.uint32)
    final, _ = jax.lax.scan(jax.checkpoint(block), jax.vmap(lambda i: initial_state(params_of(i)))(inputs), blocks)
    return jax.vmap(lambda i, state: flight_summary(params_of(i), state))(inputs, final)


def max_blocks(settings: SimSettings) -> int:
    """Blocks enough for any flight to reach ``settings.max_time_s`` (``simulate_bounded``): its regular periods (the
    shortest there are, but the few an event ends early) and two blocks' margin for those."""
    shortest = min(settings.control_dt_s, settings.open_loop_dt_s)
    return math.ceil(settings.max_time_s / shortest / settings.block_steps) + 2


def flight_done(settings: SimSettings, state: FlightState):
    """True once the flight has landed, stopped on a non-finite state or reached ``settings.max_time_s``."""
    return done(state) | (state.t >= settings.max_time_s)


def fly_block(p: FlightParams, settings: SimSettings, state: FlightState, index, remat: bool = False) -> FlightState:
    """The flight ``settings.block_steps`` control periods (block ``index`` of its flight) later,
    canards neutral; remat: each period rematerialised in a backward pass (``jax.checkpoint``: one state kept
    per period, not its intermediates)."""
    start_n = rail_start_n(p)
    noise = block_noise(p, index, settings.block_steps)
    period = lambda s, n: (step(p, settings, start_n, s, n), None)  # noqa: E731
    return jax.lax.scan(jax.checkpoint(period) if remat else period, state, noise, settings.block_steps)[0]


def block_noise(p: FlightParams, index, n_periods: int) -> StepNoise:
    """The random numbers of block ``index`` of ``n_periods`` control periods, each with a leading axis
    ``n_periods``: the turbulence's white noise (n_periods, 10) and each sensor's (None without them). Blocks
    are ``settings.block_steps`` long in ``fly_block`` and ``fly`` alike, so both fly the same gusts and
    sensor errors."""
    turbulence = p.environment.turbulence
    return StepNoise(None if turbulence is None else turbulence_noise(turbulence, index, n_periods),
                     None if p.avionics is None else avionics_noise(p.avionics, index, n_periods))  # fmt: skip


def fly(p: FlightParams, settings: SimSettings, n_periods: int, canard_command=None, record=None):
    """Fly ``n_periods`` control periods and return (final state, trajectory): the trajectory is the
    ``FlightState`` after each period, stacked along a leading axis (``trajectory.t`` holds the
    times, since periods grow in steady descent).

    canard_command: open-loop deflections, a function of time [s] returning δ1..δn [rad] held over
    each control period (default: neutral); record: what the trajectory keeps of each period's state, a
    function of the ``FlightState`` returning a pytree (default: all of it).
    """
    start_n = rail_start_n(p)

    def period(s, noise):
        s = step(p, settings, start_n, s, noise, canard_command)
        return s, s if record is None else record(s)

    def block(s, index, length):  # the first ``length`` periods of block ``index``
        noise = jax.tree_util.tree_map(lambda x: x[:length], block_noise(p, index, settings.block_steps))
        return jax.lax.scan(period, s, noise, length)

    full, rest = divmod(n_periods, settings.block_steps)
    blocks = jnp.arange(full, dtype=jnp.uint32)
    state, trajectory = jax.lax.scan(lambda s, i: block(s, i, settings.block_steps), initial_state(p), blocks)
    trajectory = jax.tree_util.tree_map(lambda x: x.reshape(x.shape[0] * x.shape[1], *x.shape[2:]), trajectory)
    if rest:
        state, tail = block(state, jnp.uint32(full), rest)
        trajectory = jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a, b]), trajectory, tail)
    return state, trajectory
