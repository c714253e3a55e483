"""The closed loop's step at each control period (docs/gnc.md §4-5): navigation → guidance → LQI → canard servos.

At the start of each period t_k the controller reads the navigation solution, computes the body-rate command
(``guidance.rate_command``), integrates the rate errors, interpolates the LQI gains designed on the host
(``gnc.design``, carried as a ``Table`` over speed and altitude), forms the three virtual commands u = −K x,
allocates them to the four fins (``aero.canards.allocate``) and holds them for the servos over the period
(``dynamics.servo``). Outside the guidance window, before liftoff and once a parachute is triggered the fins
are commanded to zero.

Pure, single-vehicle, scalar components (no small-array algebra inside the flight loop, see
docs/sharp-bits.md).
"""

from __future__ import annotations

import dataclasses
import functools
from typing import NamedTuple

import jax.numpy as jnp

from ..aero.canards import allocate, mix
from ..dynamics.rigid_body import RigidBodyState
from ..dynamics.servo import ServoParams, ServoState, hold_command
from ..math import Quat, Vec3
from ..math.table import Table, interpolate
from ..pytree import pytree_dataclass, static_field
from ..sensors.avionics import Avionics, AvionicsState, gyroscope_bias_b
from .design import N_INPUT, N_PLANT, N_STATE
from .navigation import (
    DeadReckoning, FilterParams, FilterState, NavigationMode, bus_measurements, dead_reckoning, filter_step,
    initial_dead_reckoning, initial_filters, liftoff_sensed, navigation_summary, track_errors,
)  # fmt: skip
from .guidance import GuidanceParams, Navigation, filtered_wind, guidance_active, integrate_errors, rate_command

GAIN_NAMES = tuple(f"K{i}{j}" for i in range(N_INPUT) for j in range(N_STATE))
"""Outputs of the gain table: K (3, 11) row by row; rows (yaw, pitch, roll), columns docs/gnc.md §5's state
[v, w, p, q, r, u_y, u_p, u_r, e_p, e_q, e_r]."""


@pytree_dataclass
class GncParams:
    """servo: the canard servos; guidance: the reference and the rate command (these and the gains None: navigation
    alone, no canard controller, ``gnc.canards = false``); gains: ``Table`` of K over
    ``speed`` (axial body speed u [m/s]) and, when the design grid has several, ``altitude`` (above mean sea
    level [m]), outputs ``GAIN_NAMES`` (clamped at the grid's edges); anti_windup: conditional integration
    (``gnc_step``; static); navigation: what the controller reads (``NavigationMode``; static); filters: the
    navigation filters' parameters (None unless FILTERS); rail_q_nb, rail_r_n: what the avionics know of the
    launch, the campaign's nominal rail: its attitude (body → NED) and the CG's position at rest on it [m, NED],
    where navigation from the sensors starts (None with TRUTH)."""

    servo: ServoParams | None
    guidance: GuidanceParams | None
    gains: Table | None
    anti_windup: bool = static_field()
    navigation: NavigationMode = static_field()
    filters: FilterParams | None = None
    rail_q_nb: Quat | None = None
    rail_r_n: Vec3 | None = None


@pytree_dataclass
class GncState:
    """servo: the servos' state; integrators: (e_p, e_q, e_r) [rad]; liftoff_time: the period start at which
    the rocket was first seen moving [s] (inf before), the guidance clock's zero; command: the last virtual
    commands (yaw, pitch, roll) [rad]; saturated: they clipped a fin at its limit (bool). Flight totals for the outputs: active_time [s] with the controller
    active; tracking_sq, ∫χ² dt [rad²·s], and deflection_sq, ∫ mean over the fins of δ² dt [rad²·s], over that
    time; saturated_time [s] active with a fin saturated; max_deflection, the largest |δ| of any fin at a
    period start [rad]. navigation: the navigation's state (``gnc.navigation``: ``DeadReckoning`` with SENSORS,
    ``FilterState`` with FILTERS, None with TRUTH); recovery: the parachutes' triggers from that navigation
    (``Recovery``; None with TRUTH); wind_n: the upwind aim's wind [m/s, NED] (``guidance.filtered_wind``; None
    without the aim)."""

    servo: ServoState
    integrators: Vec3
    liftoff_time: jnp.ndarray
    command: Vec3
    saturated: jnp.ndarray
    active_time: jnp.ndarray
    tracking_sq: jnp.ndarray
    deflection_sq: jnp.ndarray
    saturated_time: jnp.ndarray
    max_deflection: jnp.ndarray
    navigation: DeadReckoning | FilterState | None = None
    recovery: Recovery | None = None
    wind_n: Vec3 | None = None


APOGEE_DESCENDING_TICKS = 5
"""Apogee is sensed at the fifth consecutive GNC tick (0.1 s at 50 Hz) after the sensed liftoff whose estimated
vertical velocity points down: the flight software's guard against a noisy estimate crossing zero."""


@pytree_dataclass
class Recovery:
    """The parachutes' triggers from the navigation (``sensed_triggers``): descending_ticks, the consecutive GNC
    ticks with the estimated vertical velocity downward (int32); apogee_time, the tick apogee was sensed at [s]
    (inf before); height_error_m, the navigation's height above the pad less the true one at its last tick before a
    canopy [m] (held after: the filters idle under canopy), which the altitude triggers fly with."""

    descending_ticks: jnp.ndarray
    apogee_time: jnp.ndarray
    height_error_m: jnp.ndarray


def sensed_triggers(state: Recovery, nav: Navigation, true_height_m, moving, canopy, t, trigger_altitudes_m,
                    trigger_times) -> tuple[Recovery, tuple]:  # fmt: skip
    """The flight software's parachute triggers at the GNC tick t [s] from the navigation solution ``nav``: apogee
    once the estimated vertical velocity has pointed down for ``APOGEE_DESCENDING_TICKS`` ticks after the sensed
    liftoff (``moving``), when the parachutes triggered at apogee (``trigger_altitudes_m`` inf) trigger, at t; the
    navigation's height error against ``true_height_m`` [m] kept while no canopy is out (bool ``canopy``). The
    altitude triggers fire inside the integration (``sim.events.update_events``) where the true height plus that
    error crosses their altitude. Returns the new state and the trigger times [s] (``trigger_times``, inf before)."""
    descending = moving & (nav.v_n.z > 0.0)
    ticks = jnp.where(descending, state.descending_ticks + 1, 0)
    sensed = jnp.isinf(state.apogee_time) & (ticks >= APOGEE_DESCENDING_TICKS)
    apogee_time = jnp.where(sensed, t, state.apogee_time)
    triggers = tuple(jnp.where(sensed & jnp.isinf(altitude) & jnp.isinf(trigger), t, trigger)
                     for altitude, trigger in zip(trigger_altitudes_m, trigger_times))  # fmt: skip
    height_error = jnp.where(canopy, state.height_error_m, -nav.r_n.z - true_height_m)
    return Recovery(ticks, apogee_time, height_error), triggers


def initial_gnc(params: GncParams, like) -> GncState:
    """At rest on the rail: servos at their zero, integrators empty, no liftoff yet, navigation from the sensors
    (``params.navigation`` SENSORS or FILTERS) at the nominal rail (``params.rail_q_nb``, ``rail_r_n``); ``like``
    a scalar of the flight's dtype."""
    zero = jnp.zeros_like(like)
    fins = jnp.zeros(0) if params.servo is None else jnp.zeros_like(params.servo.offset_rad)
    q_nb0, r_n0 = params.rail_q_nb, params.rail_r_n
    navigation = {NavigationMode.TRUTH: lambda: None,
                  NavigationMode.SENSORS: lambda: initial_dead_reckoning(q_nb0),
                  NavigationMode.FILTERS: lambda: initial_filters(params.filters, q_nb0, r_n0)}[params.navigation]()  # fmt: skip
    recovery = (None if params.navigation is NavigationMode.TRUTH
                else Recovery(jnp.zeros_like(zero, dtype=jnp.int32), zero + jnp.inf, zero))  # fmt: skip
    wind_n = None if params.guidance is None or params.guidance.wind_gain is None else Vec3(zero, zero, zero)
    return GncState(
        ServoState(fins, fins), Vec3(zero, zero, zero), zero + jnp.inf, Vec3(zero, zero, zero),
        jnp.zeros_like(zero, dtype=bool),
        zero, zero, zero, zero, zero, navigation, recovery, wind_n,
    )  # fmt: skip


def gains_at(gains: Table, speed, altitude_msl):
    """K (flat, ``GAIN_NAMES``) at axial speed [m/s] and altitude [m MSL], clamped to the grid."""
    point = {"speed": speed, "altitude": altitude_msl}
    return interpolate(gains, tuple(point[name] for name in gains.axis_names))[0]


def lqi_command(k, state: tuple) -> tuple:
    """Virtual commands (yaw, pitch, roll) = −K x [rad] for the 11 state components ``state``; K flat
    (``GAIN_NAMES``), written out as sums (a vmapped small matrix product is a slow library call on CPU)."""
    return tuple(-sum(k[i * N_STATE + j] * x for j, x in enumerate(state)) for i in range(N_INPUT))


def unwinding_only(k, state: GncState, stepped: Vec3) -> Vec3:
    """The integrators ``stepped`` (e_p, e_q, e_r) [rad], except, when ``state``'s command saturated a fin,
    those whose step would move their own virtual command (roll, pitch, yaw: rows 2, 1, 0 of K, flat) further
    from zero: they keep ``state``'s value."""
    old, last = state.integrators, state.command
    kept = []
    for axis, (row, new, before, command) in enumerate(((2, stepped.x, old.x, last.z), (1, stepped.y, old.y, last.y),
                                                        (0, stepped.z, old.z, last.x))):  # fmt: skip
        effect = -k[row * N_STATE + N_PLANT + axis] * (new - before)  # its step's change of the command
        kept.append(jnp.where(state.saturated & (effect * command > 0.0), before, new))
    return Vec3(*kept)


def gnc_step(params: GncParams, state: GncState, nav: Navigation, moving, t, dt, altitude_msl, canopy,
             feedback_rad=None) -> GncState:  # fmt: skip
    """The GNC at a period start t [s] (simulation clock): liftoff detection, guidance, integrators, LQI,
    allocation, the command held by the servos, and the totals of the period dt [s] (the GNC period: the
    controller is never active in the longer descent periods). nav: the navigation solution; moving: the
    navigation sees the rocket off the pad (bool; the first such period start is liftoff); altitude_msl: its
    altitude [m]; canopy: a parachute has been triggered (bool); feedback_rad: the servo positions δ1..δ4 [rad]
    the LQI reads for its actuator states (the canard-feedback sensor's; None: the servos' true deflections).

    Anti-windup (``params.anti_windup``), conditional integration per axis: while the last command saturated
    a fin, an integrator steps only if its step moves its own virtual command (roll for e_p, pitch for e_q,
    yaw for e_r) back toward zero. Holding every integrator instead latches: an integrator whose own value
    saturates the fins could never unwind."""
    liftoff_time = jnp.where(jnp.isinf(state.liftoff_time) & moving, t, state.liftoff_time)
    since_liftoff = t - liftoff_time  # −inf before liftoff: outside any window
    active = guidance_active(params.guidance, since_liftoff) & ~jnp.asarray(canopy)  # canopy: False without parachutes
    g = params.guidance
    wind_n = None if state.wind_n is None else filtered_wind(state.wind_n, nav, dt, g.wind_time_constant_s)
    rates_cmd, chi = rate_command(g, nav, since_liftoff, wind_n)
    v_b = nav.q_nb.rotate_inverse(nav.v_n)
    k = gains_at(params.gains, v_b.x, altitude_msl)
    errors = integrate_errors(state.integrators, rates_cmd, nav.omega_b, dt, active, params.guidance.integrator_gain)
    if params.anti_windup:
        errors = unwinding_only(k, state, errors)
    feedback = state.servo.deflection_rad if feedback_rad is None else feedback_rad
    u_yaw, u_pitch, u_roll, _ = mix(*(feedback[i] for i in range(4)))
    omega = nav.omega_b
    x = (v_b.y, v_b.z, omega.x, omega.y, omega.z, u_yaw, u_pitch, u_roll, errors.x, errors.y, errors.z)
    command = Vec3(*(jnp.where(active, u, 0.0) for u in lqi_command(k, x)))  # (yaw, pitch, roll)
    fins = allocate(*command)
    saturated = functools.reduce(jnp.logical_or, [jnp.abs(f) > params.servo.limit_rad for f in fins])
    servo = hold_command(params.servo, state.servo, jnp.stack(fins))

    deflection = state.servo.deflection_rad + params.servo.offset_rad
    deflections = [deflection[i] for i in range(deflection.shape[0])]
    active_dt = jnp.where(active, dt, 0.0)
    return GncState(
        servo,
        errors,
        liftoff_time,
        command,
        saturated,
        state.active_time + active_dt,
        state.tracking_sq + chi * chi * active_dt,
        # a reduction, not a chain of additions: XLA fused the chain differently with the batch size (1 ulp)
        state.deflection_sq + jnp.mean(deflection * deflection) * active_dt,
        state.saturated_time + jnp.where(saturated, active_dt, 0.0),
        functools.reduce(jnp.maximum, [jnp.abs(d) for d in deflections], state.max_deflection),
        state.navigation,
        state.recovery,
        wind_n,
    )


def truth(body: RigidBodyState) -> tuple[Navigation, jnp.ndarray]:
    """Perfect navigation (``NavigationMode.TRUTH``): the vehicle's true state, and whether it moves."""
    return Navigation(body.r_n, body.v_n, body.q_nb, body.omega_b), body.v_n.dot(body.v_n) > 0.0


class Navigated(NamedTuple):
    """What the navigation gives the controller at a GNC tick (``navigate``): solution, the navigation solution;
    moving, whether it sees the rocket off the pad (bool); state, the GNC's state with its navigation and recovery
    advanced; trigger_times, the parachutes' trigger times [s] (inf before) from the navigation (``sensed_triggers``),
    or None: the true apogee and height trigger them (``sim.events.update_events``); feedback_rad, the servo
    positions δ1..δn [rad] the LQI reads (the canard-feedback sensor's), or None: the servos' true deflections."""

    solution: Navigation
    moving: jnp.ndarray
    state: GncState
    trigger_times: tuple | None
    feedback_rad: jnp.ndarray | None


def navigate(params: GncParams, av: Avionics | None, state: GncState, body: RigidBodyState,
             sensed: AvionicsState | None, t, canopy, trigger_altitudes_m, trigger_times) -> Navigated:  # fmt: skip
    """The navigation of ``params.navigation`` at the GNC tick t [s]: TRUTH, the true ``body``;
    SENSORS, the raw sensors on the bus of ``sensed`` (the avionics' state; ``av``: the sensors as the
    flight software knows them), and FILTERS, the filters on it, both with liftoff from the accelerometer and the
    parachutes' triggers (``sensed_triggers``, with ``trigger_altitudes_m`` [m above the pad] and the trigger times
    so far ``trigger_times`` [s]). canopy: a parachute has been triggered (bool)."""
    if params.navigation is NavigationMode.TRUTH:
        return Navigated(*truth(body), state, None, None)
    bus = sensed.bus
    # liftoff latched: after burnout the accelerometer reads less than the 2 g that sensed it
    moving = liftoff_sensed(av, bus) | jnp.isfinite(state.liftoff_time)
    if params.navigation is NavigationMode.SENSORS:
        nav, navigation = dead_reckoning(av, state.navigation, bus, t)
    else:
        nav, navigation = filter_step(params.filters, state.navigation, bus_measurements(av, bus), t, moving, canopy)
    recovery, triggers = sensed_triggers(state.recovery, nav, -body.r_n.z, moving, canopy, t, trigger_altitudes_m,
                                         trigger_times)  # fmt: skip
    state = dataclasses.replace(state, navigation=navigation, recovery=recovery)
    feedback = jnp.where(bus.canard_feedback.valid, bus.canard_feedback.value, 0.0)  # the servos' sensed positions
    return Navigated(nav, moving, state, triggers, feedback)


def track_navigation(params: GncParams, state: GncState, t, dt, canopy, body: RigidBodyState, av: Avionics | None,
                     sensed: AvionicsState | None, ascent, burnt, past_apogee) -> GncState:  # fmt: skip
    """``state`` (after ``gnc_step`` at the period start t [s]) with, on the FILTERS, their errors against the truth
    accumulated (``track_errors``): the true ``body`` and gyroscope bias (of ``av``, the sensors as they sample at t,
    and their state ``sensed``); over the GNC period dt [s] while the controller is active (the guidance window
    from the sensed liftoff, no parachute: bool ``canopy``) and while ``ascent`` (the true first motion to apogee,
    bool), and at the first tick ``burnt`` and ``past_apogee`` (bool). Other navigation: ``state`` itself."""
    if params.navigation is not NavigationMode.FILTERS:
        return state
    if params.guidance is None:  # no controller, no window
        window = jnp.zeros_like(t, dtype=bool)
    else:
        window = guidance_active(params.guidance, t - state.liftoff_time) & ~jnp.asarray(canopy)  # canopy: False without parachutes
    navigation = track_errors(state.navigation, body.q_nb, body.r_n, body.v_n, gyroscope_bias_b(av, sensed),
                              jnp.where(window, dt, 0.0), jnp.where(ascent, dt, 0.0), burnt, past_apogee)  # fmt: skip
    return dataclasses.replace(state, navigation=navigation)


def gnc_summary(params: GncParams, state: GncState, burnout_speed_mps) -> tuple[dict, jnp.ndarray | None]:
    """The closed loop's per-flight outputs: the controller's (``control_summary``) and, on the FILTERS, theirs
    (``navigation.navigation_summary``, with the burnout speed [m/s]); and whether the filters failed (bool; None
    on other navigation). Navigation alone (no gains) has no controller's outputs."""
    summary = {} if params.gains is None else control_summary(state)
    if params.navigation is not NavigationMode.FILTERS:
        return summary, None
    return {**summary, **navigation_summary(state.navigation, burnout_speed_mps)}, state.navigation.failed


def control_summary(state: GncState) -> dict:
    """The controller's per-flight outputs (``sim.outputs.CONTROL_METRICS``); NaN where it never acted."""
    acted = state.active_time > 0.0
    per_active = 1.0 / jnp.where(acted, state.active_time, 1.0)
    return {
        "control_active_time_s": state.active_time,
        "tracking_error_rms_rad": jnp.where(acted, jnp.sqrt(state.tracking_sq * per_active), jnp.nan),
        "canard_deflection_rms_rad": jnp.where(acted, jnp.sqrt(state.deflection_sq * per_active), jnp.nan),
        "canard_deflection_max_rad": state.max_deflection,
        "canard_saturated_fraction": jnp.where(acted, state.saturated_time * per_active, jnp.nan),
    }
