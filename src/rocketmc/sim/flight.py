"""One flight, from the rail to the ground: the right-hand side, the control-period step, events.

Single-vehicle and pure: ``jit`` and ``vmap`` are applied by its callers (``campaign.runner`` for campaigns; the
others in docs/architecture.md, "Where jit and vmap sit").
Phases are masks, not branches: on the rail, under canopy and on the ground all run the same
code. Event times are ``inf`` until the event happens.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp

from ..aero import AirData, aero_coefficients, aero_wrench, air_data
from ..dynamics import RigidBodyState, open_fraction, parachute_drag_n, propellant_mass, rigid_body_derivatives, thrust
from ..dynamics.propulsion import grain_inertia
from ..dynamics.rigid_body import MassProperties, combine_on_axis, normalize_attitude
from ..dynamics.servo import deflection_at, end_of_period
from ..env import (
    G0, TurbulenceState, advance_turbulence, gust_n, initial_turbulence, turbulence_noise, turbulence_scales,
)  # fmt: skip
from ..env.atmosphere import MAX_ALTITUDE_M
from ..gnc.control import GncState, control_summary, gnc_step, initial_gnc, sensed_triggers, truth
from ..gnc.guidance import guidance_active
from ..gnc.navigation import (
    DIVERGED_MEANING, bus_measurements, dead_reckoning, filter_step, liftoff_sensed, navigation_summary, track_errors,
)  # fmt: skip
from ..math import Quat, Vec3, rk4_step
from ..sensors.avionics import (
    AvionicsState, avionics_noise, gyroscope_bias_b, initial_avionics, sense, sense_acceleration, specific_force_b,
)  # fmt: skip
from ..pytree import pytree_dataclass, tree_where
from .faults import faulty_servos, faulty_sensors
from .params import FlightParams, SimSettings

OUTSIDE_TABLES_QBAR_FRACTION = 0.1
"""A flight is flagged when it leaves the aero tables at a dynamic pressure above this fraction of its
maximum: near apogee or on the rail the angles are large but the loads are not."""


class Status(enum.IntEnum):
    """Outcome of one realization; the value is stored in ``/outputs/status``."""

    OK = 0
    NON_FINITE = 1
    MAX_TIME = 2
    OUTSIDE_AERO_TABLES = 3
    OUTSIDE_ATMOSPHERE = 4
    NAVIGATION_FAILED = 5

    @property
    def message(self) -> str:
        return {
            Status.OK: "ok",
            Status.NON_FINITE: "the state became NaN or infinite; the flight was stopped there",
            Status.MAX_TIME: "not on the ground at the maximum simulated time (raise max_time_s?)",
            Status.OUTSIDE_AERO_TABLES: (
                "flew outside the aerodynamic tables' range (values clamped at their edge) at more than "
                f"{OUTSIDE_TABLES_QBAR_FRACTION:.0%} of its maximum dynamic pressure"
            ),
            Status.OUTSIDE_ATMOSPHERE: (
                f"climbed above the standard atmosphere's top ({MAX_ALTITUDE_M / 1000:.1f} km above sea level), "
                "where the air was held at its value there"
            ),
            Status.NAVIGATION_FAILED: (
                "a navigation filter's covariance became non-finite or non-positive; its last good estimate was held"
            ),
        }[self]


@pytree_dataclass
class Events:
    """Event times [s] (``inf`` until they happen) and the values interpolated at them (SI, NED)."""

    rail_exit_time: jnp.ndarray
    rail_exit_speed: jnp.ndarray
    burnout_time: jnp.ndarray
    burnout_altitude: jnp.ndarray
    burnout_speed: jnp.ndarray
    apogee_time: jnp.ndarray
    apogee_altitude: jnp.ndarray
    apogee_north: jnp.ndarray
    apogee_east: jnp.ndarray
    chute_trigger_times: tuple
    impact_time: jnp.ndarray
    impact_north: jnp.ndarray
    impact_east: jnp.ndarray
    impact_speed: jnp.ndarray
    max_mach: jnp.ndarray
    max_qbar: jnp.ndarray
    max_qbar_outside_tables: jnp.ndarray
    non_finite: jnp.ndarray


@pytree_dataclass
class FlightState:
    """Time [s], the control-period counter, rigid-body state, the event record, the squared pendulum
    rate of the body swinging under its canopies, ω² = Σ|F_chute|·|arm|/I [1/s²], which bounds the
    descent step, the turbulence filters (None without turbulence), the closed loop's state (None
    without a controller) and the avionics' (None without sensors).

    tick: control periods flown (int32, +1 per ``control_step``, after landing too, as ``t``). A long period of
    steady descent (``steady_descent``: up to ``settings.descent_dt_s``, the GNC idle) counts one too, so
    ``t = tick·control_dt_s`` (up to the rounding of the summed periods) only until the first of them."""

    t: jnp.ndarray
    tick: jnp.ndarray
    body: RigidBodyState
    events: Events
    canopy_stiffness: jnp.ndarray
    turbulence: TurbulenceState | None
    gnc: GncState | None = None
    avionics: AvionicsState | None = None


class Diagnostics(NamedTuple):
    """By-products of the right-hand side: Mach [-], dynamic pressure [Pa], canopy ω² [1/s²], and
    the dynamic pressure if the aerodynamic tables were left (not under a canopy), else 0 [Pa]."""

    mach: jnp.ndarray
    qbar: jnp.ndarray
    canopy_stiffness: jnp.ndarray
    qbar_outside_tables: jnp.ndarray


def mass_properties(p: FlightParams, t) -> MassProperties:
    """Mass, CG and inertia of the rocket with the propellant left at time ``t``."""
    r, motor = p.rocket, p.rocket.motor
    m_prop = propellant_mass(motor, t)
    grain_ixx, grain_iyy = grain_inertia(motor, m_prop)
    return combine_on_axis(
        [
            (r.dry_mass_kg, r.dry_cg_x_m, r.dry_ixx_kgm2, r.dry_iyy_kgm2),
            (m_prop, motor.grain_center_x_m, grain_ixx, grain_iyy),
        ]
    )


class Loads(NamedTuple):
    """What acts on the rocket at one instant (``loads``): its mass properties, the air data, the thrust
    along body x [N], the aerodynamic force at the moment reference [N, FRD], the parachutes' force [N, NED],
    the moment of everything about the CG [N·m, FRD], whether a canopy is open (bool), the canopy ω²
    [1/s²] and whether the aerodynamic tables were left (bool)."""

    mass: MassProperties
    air: AirData
    thrust: jnp.ndarray
    aero_force_b: Vec3
    chute_force_n: Vec3
    moment_b: Vec3
    under_canopy: jnp.ndarray
    canopy_stiffness: jnp.ndarray
    outside_tables: jnp.ndarray


def loads(t, body: RigidBodyState, p: FlightParams, deflections, gust_n: Vec3, events: Events) -> Loads:
    """The ``Loads`` at ``t`` [s] on ``body`` with canard deflections δ1..δn [rad] and a turbulent gust
    ``gust_n`` [m/s, NED] on top of the mean wind (``derivatives``' forces, also read by ``analysis``)."""
    rocket, env = p.rocket, p.environment
    mass = mass_properties(p, t)
    altitude = -body.r_n.z
    altitude_msl = env.site_altitude_m + altitude
    atmosphere = env.air(altitude_msl)
    wind_n = env.wind.velocity_n(altitude) + gust_n
    q_nb, omega_b = body.q_nb, body.omega_b
    air = air_data(q_nb.rotate_inverse(body.v_n - wind_n), atmosphere, altitude_msl)

    force_n = Vec3.zeros(t)
    moment_b = Vec3.zeros(t)
    under_canopy = jnp.zeros_like(t, dtype=bool)
    stiffness = jnp.zeros_like(t)
    for chute, trigger_time in zip(rocket.parachutes, events.chute_trigger_times):
        fraction = open_fraction(chute, trigger_time, t)
        arm_b = Vec3(chute.attach_x_m - mass.cg_x, 0.0, 0.0)
        v_air_n = body.v_n + q_nb.rotate(omega_b.cross(arm_b)) - wind_n
        drag_n = parachute_drag_n(chute, fraction, v_air_n, atmosphere.density)
        force_n = force_n + drag_n
        moment_b = moment_b + arm_b.cross(q_nb.rotate_inverse(drag_n))
        under_canopy = under_canopy | (fraction > 0.0)
        stiffness = stiffness + drag_n.norm() * jnp.abs(arm_b.x) / mass.iyy

    thrust_n = thrust(rocket.motor, t)
    coefficients, outside_tables = aero_coefficients(rocket.aero, air, omega_b, mass.cg_x, deflections, thrust_n > 0.0)
    if rocket.airbrake_time_s is not None:
        since_ignition = t - rocket.motor.ignition_time_s
        delta_ca = jnp.interp(since_ignition, rocket.airbrake_time_s, rocket.airbrake_delta_ca, left=0.0, right=0.0)
        coefficients = coefficients._replace(ca=coefficients.ca + delta_ca)
    aero_force_b, aero_moment_b = aero_wrench(rocket.aero, coefficients, air, omega_b, rocket.canopy_cl_p, under_canopy)
    aero_arm_b = Vec3(rocket.aero.moment_ref_x_m - mass.cg_x, 0.0, 0.0)
    moment_b = moment_b + aero_moment_b + aero_arm_b.cross(aero_force_b)
    return Loads(mass, air, thrust_n, aero_force_b, force_n, moment_b, under_canopy, stiffness, outside_tables)


def derivatives(t, body: RigidBodyState, p: FlightParams, deflections, gust_n: Vec3, events: Events):
    """State derivative and ``Diagnostics`` at ``t`` with canard deflections δ1..δn [rad] and a
    turbulent gust ``gust_n`` [m/s, NED] on top of the mean wind."""
    f = loads(t, body, p, deflections, gust_n, events)
    force_b = f.aero_force_b + Vec3(f.thrust, 0.0, 0.0)
    free = rigid_body_derivatives(body, f.mass, force_b, f.chute_force_n, f.moment_b, G0)

    # On the rail: motion along it only, no rotation, no sliding back down before liftoff.
    rail = p.launch.rail_direction_n
    accel_along = free.v_n.dot(rail)
    accel_along = jnp.where((body.v_n.dot(rail) > 0.0) | (accel_along > 0.0), accel_along, 0.0)
    zero = jnp.zeros_like(accel_along)
    on_rail = RigidBodyState(body.v_n, rail * accel_along, Quat(zero, zero, zero, zero), Vec3(zero, zero, zero))
    d_body = tree_where(jnp.isinf(events.rail_exit_time), on_rail, free)
    qbar_outside = jnp.where(f.outside_tables & ~f.under_canopy, f.air.qbar, 0.0)
    return d_body, Diagnostics(f.air.mach, f.air.qbar, f.canopy_stiffness, qbar_outside)


def _crossing_fraction(g0, g1):
    """Fraction of a step at which g (linear in the step) reaches 0 from above; 0 if already there."""
    dg = g0 - g1
    return jnp.clip(jnp.where(g0 > 0.0, g0 / jnp.where(dg != 0.0, dg, 1.0), 0.0), 0.0, 1.0)


def _lerp(a, b, s):
    return a + s * (b - a)


def _record(event_time, hit, t0, h, s):
    return jnp.where(hit, t0 + s * h, event_time)


def rail_start_n(p: FlightParams) -> Vec3:
    """CG position at rest on the rail, the nozzle exit at the pad [m, NED]."""
    return p.launch.rail_direction_n * (mass_properties(p, 0.0).cg_x - p.rocket.motor.nozzle_x_m)


def update_events(
    p: FlightParams, start_n: Vec3, ev: Events, t0, h, b0: RigidBodyState, b1: RigidBodyState, diag: Diagnostics,
    sensed=None,
) -> Events:
    """Detect the events inside the step ``[t0, t0 + h]`` from ``b0`` to ``b1`` and interpolate them.

    start_n: ``rail_start_n(p)``, passed in so that it is computed once per flight; sensed: with
    ``sensed_recovery(p)``, (the navigation's held height error [m], whether it has sensed apogee (bool)) from
    ``gnc.control.Recovery``, else None (the true apogee and height trigger the parachutes).
    """
    rail = p.launch.rail_direction_n
    motor = p.rocket.motor
    speed0, speed1 = b0.v_n.norm(), b1.v_n.norm()
    alt0, alt1 = -b0.r_n.z, -b1.r_n.z

    # Rail exit: the rear lug passes the top of the rail (the nozzle started at its foot); the CG
    # shift while on the rail (< 1 cm for Lynx) is neglected.
    travel_to_exit = p.launch.rail_length_m - (p.rocket.rear_lug_x_m - motor.nozzle_x_m)
    g0 = travel_to_exit - (b0.r_n - start_n).dot(rail)
    g1 = travel_to_exit - (b1.r_n - start_n).dot(rail)
    hit = jnp.isinf(ev.rail_exit_time) & (g1 <= 0.0)
    s = _crossing_fraction(g0, g1)
    rail_exit_time = _record(ev.rail_exit_time, hit, t0, h, s)
    rail_exit_speed = jnp.where(hit, _lerp(speed0, speed1, s), ev.rail_exit_speed)

    # Burnout: the end of the thrust curve, a known time.
    t_bo = motor.ignition_time_s + motor.burn_time_s
    hit = jnp.isinf(ev.burnout_time) & (t0 + h >= t_bo)
    s = jnp.clip((t_bo - t0) / h, 0.0, 1.0)
    burnout_time = _record(ev.burnout_time, hit, t0, h, s)
    burnout_altitude = jnp.where(hit, _lerp(alt0, alt1, s), ev.burnout_altitude)
    burnout_speed = jnp.where(hit, _lerp(speed0, speed1, s), ev.burnout_speed)

    # Apogee: the vertical velocity changes sign; altitude from the cubic Hermite interpolant.
    climb0, climb1 = -b0.v_n.z, -b1.v_n.z
    hit = jnp.isfinite(rail_exit_time) & jnp.isinf(ev.apogee_time) & (climb1 <= 0.0)
    s = _crossing_fraction(climb0, climb1)
    hermite_alt = (
        (2 * s**3 - 3 * s**2 + 1) * alt0
        + (s**3 - 2 * s**2 + s) * h * climb0
        + (-2 * s**3 + 3 * s**2) * alt1
        + (s**3 - s**2) * h * climb1
    )
    apogee_time = _record(ev.apogee_time, hit, t0, h, s)
    apogee_altitude = jnp.where(hit, hermite_alt, ev.apogee_altitude)
    apogee_north = jnp.where(hit, _lerp(b0.r_n.x, b1.r_n.x, s), ev.apogee_north)
    apogee_east = jnp.where(hit, _lerp(b0.r_n.y, b1.r_n.y, s), ev.apogee_east)
    past_apogee = jnp.isfinite(apogee_time)

    # Parachute triggers: after apogee, at or below the trigger altitude (inf: at apogee). Navigating from the
    # sensors (``sensed``: the navigation's held height error [m] and whether it has sensed apogee), the altitude
    # triggers fire where the true height plus that error crosses their altitude after the sensed apogee, and those
    # at apogee at the sensed apogee's GNC tick (``step``).
    triggers = []
    for chute, trigger_time in zip(p.rocket.parachutes, ev.chute_trigger_times):
        altitude = chute.trigger_altitude_agl_m
        if sensed is None:
            g0, g1 = alt0 - altitude, alt1 - altitude
            hit = past_apogee & jnp.isinf(trigger_time) & (g1 <= 0.0)
            crossing_time = jnp.maximum(t0 + _crossing_fraction(g0, g1) * h, apogee_time)
        else:
            height_error, apogee_sensed = sensed
            g0, g1 = alt0 + height_error - altitude, alt1 + height_error - altitude
            hit = apogee_sensed & jnp.isfinite(altitude) & jnp.isinf(trigger_time) & (g1 <= 0.0)
            crossing_time = t0 + _crossing_fraction(g0, g1) * h
        triggers.append(jnp.where(hit, crossing_time, trigger_time))

    # Impact: the CG reaches the ground after apogee.
    hit = past_apogee & jnp.isinf(ev.impact_time) & (alt1 <= 0.0)
    s = _crossing_fraction(alt0, alt1)
    impact_time = _record(ev.impact_time, hit, t0, h, s)
    impact_north = jnp.where(hit, _lerp(b0.r_n.x, b1.r_n.x, s), ev.impact_north)
    impact_east = jnp.where(hit, _lerp(b0.r_n.y, b1.r_n.y, s), ev.impact_east)
    impact_speed = jnp.where(hit, _lerp(speed0, speed1, s), ev.impact_speed)

    return Events(
        rail_exit_time, rail_exit_speed, burnout_time, burnout_altitude, burnout_speed,
        apogee_time, apogee_altitude, apogee_north, apogee_east, tuple(triggers),
        impact_time, impact_north, impact_east, impact_speed,
        jnp.maximum(ev.max_mach, diag.mach), jnp.maximum(ev.max_qbar, diag.qbar),
        jnp.maximum(ev.max_qbar_outside_tables, diag.qbar_outside_tables), ev.non_finite,
    )  # fmt: skip


def sensed_recovery(p: FlightParams) -> bool:
    """Whether the parachutes are triggered by the navigation at the GNC ticks (``gnc.control.sensed_triggers``): a
    controller navigating from the sensors; else by the true apogee and height (``update_events``). Static."""
    return p.gnc is not None and p.gnc.navigation != "truth"


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
    return FlightState(zero, jnp.zeros_like(zero, dtype=jnp.int32), body, events, zero, filters, gnc, avionics)


def done(state: FlightState):
    """True once the flight has landed or stopped on a non-finite state."""
    return jnp.isfinite(state.events.impact_time) | state.events.non_finite


def steady_descent(p: FlightParams, settings: SimSettings, state: FlightState):
    """True under a fully open canopy once every triggered opening has settled, unless a wind-layer
    boundary is within one descent step (its wind jump is a transient too)."""
    t, events = state.t, state.events
    any_open, transient = False, False
    for chute, trigger_time in zip(p.rocket.parachutes, events.chute_trigger_times):
        settled = trigger_time + chute.delay_s + chute.opening_time_s + settings.settle_s
        any_open = any_open | (t >= settled)
        transient = transient | (jnp.isfinite(trigger_time) & (t < settled))
    altitude = -state.body.r_n.z
    reach = jnp.abs(state.body.v_n.z) * settings.descent_dt_s + 1.0
    for jump_altitude in p.environment.wind.jump_altitudes_m():
        transient = transient | (jnp.abs(altitude - jump_altitude) < reach)
    return any_open & ~transient


def control_period(p: FlightParams, settings: SimSettings, state: FlightState):
    """The period starting at ``state`` [s]: ``settings.control_dt_s``; in steady descent under canopy
    it grows up to ``settings.descent_dt_s`` while the body's pendulum rate ω allows RK4 steps with
    h·ω ≤ ``settings.descent_h_omega``. Each realization keeps its own clock."""
    stable_period = settings.substeps * settings.descent_h_omega / jnp.sqrt(jnp.maximum(state.canopy_stiffness, 1e-12))
    descent_period = jnp.clip(stable_period, settings.control_dt_s, settings.descent_dt_s)
    return jnp.where(steady_descent(p, settings, state), descent_period, settings.control_dt_s)


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
    first_stage: bool = False,
) -> tuple[FlightState, jnp.ndarray | None]:  # fmt: skip
    """One control period of ``period`` [s] (``control_period``) with the turbulent gust held: RK4 substeps
    of the rigid body with events, then the turbulence filters advanced over the period with ``noise``,
    the period's row of turbulence noise (None without turbulence); ``tick`` + 1. Returns the new state and,
    with ``first_stage``, the CG's acceleration [m/s², NED], the body's angular acceleration [rad/s², FRD], the
    dynamic pressure [Pa] and the CG's position x [m, body] at the period start (the first RK4 stage's), as one
    (8,) array, else None.

    deflections: the canard deflections δ1..δn [rad] as a function of the time t [s] inside the
    period (held, or the servos' response evaluated at each RK4 stage).
    """
    h = period / settings.substeps
    turbulence = p.environment.turbulence
    mean_wind_n, scales, gust = period_gust(p, state)
    recovery = state.gnc.recovery if sensed_recovery(p) else None
    sensed = None if recovery is None else (recovery.height_error_m, jnp.isfinite(recovery.apogee_time))

    def rhs(t, y, events):
        d_body, diag = derivatives(t, y, p, deflections(t), gust, events)
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
        return (t0 + h, body1, events, diag.canopy_stiffness), derivative

    carry = (state.t, state.body, state.events, state.canopy_stiffness)
    (t, body, events, stiffness), derivatives_at_start = jax.lax.scan(substep, carry, None, settings.substeps)
    first = None if derivatives_at_start is None else jax.tree_util.tree_map(lambda x: x[0], derivatives_at_start)
    finite = functools.reduce(jnp.logical_and, [jnp.isfinite(x) for x in jax.tree_util.tree_leaves(body)])
    body = tree_where(done(state) | ~finite, state.body, body)
    events = tree_where(done(state), state.events, events)
    events = dataclasses.replace(events, non_finite=events.non_finite | ~finite)
    filters = state.turbulence
    if turbulence is not None:
        airspeed = (state.body.v_n - mean_wind_n - gust).norm()
        filters = advance_turbulence(filters, scales, airspeed, period, noise)
    return FlightState(state.t + period, state.tick + 1, body, events, stiffness, filters, state.gnc, state.avionics), first


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
    LQI reads the canard feedback and the parachutes trigger on the navigation, ``sensed_recovery``)."""
    period = control_period(p, settings, state)
    sensing = period <= settings.control_dt_s  # the sensors sample in GNC periods only, not in long descent ones
    if p.gnc is None:
        held = jnp.zeros(p.rocket.aero.n_canards) if canard_command is None else canard_command(state.t)
        held = jnp.asarray(held, dtype=float)
        start = _sensed(p, state, held, sensing, noise)
        state, first = control_step(p, settings, start_n, start, period, lambda t: held, noise.turbulence,
                                    p.avionics is not None)  # fmt: skip
        return _accelerometer(p, start, state, first, sensing, noise)
    if canard_command is not None:
        raise ValueError("canard_command flies open loop: it needs a flight without a controller (p.gnc None)")
    servo_params, t0 = p.gnc.servo, state.t
    state = start = _sensed(p, state, state.gnc.servo.deflection_rad, sensing, noise)
    canopy = functools.reduce(jnp.logical_or, [jnp.isfinite(t) for t in state.events.chute_trigger_times], False)
    feedback = None
    if p.gnc.navigation == "truth":
        nav, moving = truth(state.body)
    else:
        bus = state.avionics.bus
        # liftoff latched: after burnout the accelerometer reads less than the 2 g that sensed it
        moving = liftoff_sensed(p.avionics, bus) | jnp.isfinite(state.gnc.liftoff_time)
        if p.gnc.navigation == "sensors":
            nav, navigation = dead_reckoning(p.avionics, state.gnc.navigation, bus, t0)
        else:
            measured = bus_measurements(p.avionics, bus)
            nav, navigation = filter_step(p.gnc.filters, state.gnc.navigation, measured, t0, moving, canopy)
        recovery, triggers = sensed_triggers(state.gnc.recovery, nav, -state.body.r_n.z, moving, canopy, t0,
                                             [chute.trigger_altitude_agl_m for chute in p.rocket.parachutes],
                                             state.events.chute_trigger_times)  # fmt: skip
        canopy = functools.reduce(jnp.logical_or, [jnp.isfinite(t) for t in triggers], False)
        events = dataclasses.replace(state.events, chute_trigger_times=triggers)
        gnc = dataclasses.replace(state.gnc, navigation=navigation, recovery=recovery)
        state = dataclasses.replace(state, gnc=gnc, events=tree_where(done(state), state.events, events))
        feedback = jnp.where(bus.canard_feedback.valid, bus.canard_feedback.value, 0.0)  # the servos' sensed positions
    altitude_msl = p.environment.site_altitude_m - nav.r_n.z
    gnc = gnc_step(p.gnc, state.gnc, nav, moving, t0, settings.control_dt_s, altitude_msl, canopy, feedback)
    if p.gnc.navigation == "filters":
        gnc = dataclasses.replace(gnc, navigation=_tracked(p, settings, state, gnc, canopy))
    held = gnc.servo
    if p.faults is not None and p.faults.servos:
        servo_params, held = faulty_servos(p.faults, servo_params, held, t0)
    servo = end_of_period(servo_params, held, period)
    state, first = control_step(p, settings, start_n, state, period,
                                lambda t: deflection_at(servo_params, held, t - t0), noise.turbulence,
                                p.avionics is not None)  # fmt: skip
    state = dataclasses.replace(state, gnc=dataclasses.replace(gnc, servo=servo))
    return _accelerometer(p, start, state, first, sensing, noise)


def _tracked(p: FlightParams, settings: SimSettings, state: FlightState, gnc: GncState, canopy):
    """The filters' state of ``gnc`` with its errors against the truth of ``state`` at the period start
    (``track_errors``): the window is the controller's active time (the guidance window from the sensed liftoff, no
    parachute), the ascent from the true first motion to apogee."""
    body, events, dt = state.body, state.events, settings.control_dt_s
    window = guidance_active(p.gnc.guidance, state.t - gnc.liftoff_time) & ~canopy
    ascent = (body.v_n.dot(body.v_n) > 0.0) & jnp.isinf(events.apogee_time)
    return track_errors(gnc.navigation, body.q_nb, body.r_n, body.v_n,
                        gyroscope_bias_b(_avionics_at(p, state.t), state.avionics),
                        jnp.where(window, dt, 0.0), jnp.where(ascent, dt, 0.0), state.t >= events.burnout_time,
                        state.t >= events.apogee_time)  # fmt: skip


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
    force = specific_force_b(tree_where(landed, zero, acceleration_n), body.q_nb, body.omega_b,
                             tree_where(landed, zero, omega_dot_b), arm_b)  # fmt: skip
    qbar = jnp.where(landed, 0.0, qbar)
    avionics = sense_acceleration(_avionics_at(p, start.t), state.avionics, start.tick, force, qbar, sensing,
                                  noise.avionics)  # fmt: skip
    return dataclasses.replace(state, avionics=avionics)


def simulate_one(p: FlightParams, settings: SimSettings) -> tuple[dict, jnp.ndarray]:
    """Fly until landed, stopped or ``settings.max_time_s``; return (summary dict, status code).

    The loop runs in blocks of ``settings.block_steps`` control periods (``fly_block``).
    """

    def block(carry):
        state, index = carry
        return fly_block(p, settings, state, index), index + 1

    final, _ = jax.lax.while_loop(
        lambda carry: ~flight_done(settings, carry[0]), block, (initial_state(p), jnp.zeros((), jnp.uint32))
    )
    return flight_summary(p, final)


def flight_done(settings: SimSettings, state: FlightState):
    """True once the flight has landed, stopped on a non-finite state or reached ``settings.max_time_s``."""
    return done(state) | (state.t >= settings.max_time_s)


def fly_block(p: FlightParams, settings: SimSettings, state: FlightState, index) -> FlightState:
    """The flight ``settings.block_steps`` control periods (block ``index`` of its flight) later,
    canards neutral."""
    start_n = rail_start_n(p)
    noise = block_noise(p, index, settings.block_steps)
    return jax.lax.scan(lambda s, n: (step(p, settings, start_n, s, n), None), state, noise, settings.block_steps)[0]


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


class Metric(NamedTuple):
    """An output of a flight: its unit and what it means (stored with each ``/outputs`` dataset)."""

    unit: str
    meaning: str


METRICS: dict[str, Metric] = {
    "apogee_agl_m": Metric("m", "altitude of the CG above the pad at apogee"),
    "apogee_time_s": Metric("s", "time of apogee (t = 0 at rest on the rail, before ignition)"),
    "apogee_north_m": Metric("m", "CG north of the pad at apogee"),
    "apogee_east_m": Metric("m", "CG east of the pad at apogee"),
    "max_mach": Metric("1", "largest Mach number of the flight"),
    "max_dynamic_pressure_pa": Metric("Pa", "largest dynamic pressure of the flight"),
    "max_dynamic_pressure_outside_aero_tables_pa": Metric(
        "Pa", "largest dynamic pressure outside the aerodynamic tables' range, not under a canopy (0: never outside)"
    ),
    "rail_exit_time_s": Metric("s", "time the rear lug leaves the top of the rail"),
    "rail_exit_speed_mps": Metric("m/s", "speed at rail exit"),
    "burnout_time_s": Metric("s", "time the thrust curve ends"),
    "burnout_altitude_agl_m": Metric("m", "altitude of the CG above the pad at burnout"),
    "burnout_speed_mps": Metric("m/s", "speed at burnout"),
    "impact_north_m": Metric("m", "CG north of the pad at impact (the CG back at the pad's altitude)"),
    "impact_east_m": Metric("m", "CG east of the pad at impact"),
    "impact_time_s": Metric("s", "time of impact"),
    "impact_speed_mps": Metric("m/s", "speed at impact"),
    "status": Metric("1", "outcome of the flight, a code of attrs['codes'] (0: ok)"),
}
"""The outputs of ``flight_summary`` by name, its status included, but the parachutes' deploy times
(see ``metric``). Times from t = 0 at rest on the rail; speeds over ground; NaN: the event did not
happen."""

CONTROL_METRICS: dict[str, Metric] = {
    "control_active_time_s": Metric("s", "time the controller was active: inside the guidance window, no parachute triggered"),
    "tracking_error_rms_rad": Metric("rad", "RMS over the active time of χ, the angle from the velocity to the reference direction"),
    "canard_deflection_rms_rad": Metric("rad", "RMS over the active time and the fins of the canard deflections"),
    "canard_deflection_max_rad": Metric("rad", "largest canard deflection of any fin in the flight"),
    "canard_saturated_fraction": Metric("1", "fraction of the active time with a fin command clipped at the servo limit"),
}
"""The outputs a flight with a controller adds (``gnc.control.control_summary``); NaN where it never acted."""

NAVIGATION_METRICS: dict[str, Metric] = {
    "attitude_error_rms_window_rad": Metric("rad", "RMS over the controller's active time of the attitude estimate's error angle"),
    "attitude_error_max_window_rad": Metric("rad", "largest attitude estimation error over the controller's active time"),
    "attitude_error_rms_ascent_rad": Metric("rad", "RMS of the attitude estimation error from the first motion to apogee"),
    "attitude_error_max_ascent_rad": Metric("rad", "largest attitude estimation error from the first motion to apogee"),
    "gyro_bias_error_window_end_rad_s": Metric("rad/s", "norm of the gyro-bias estimate's error at the controller's last active tick"),
    "position_error_burnout_m": Metric("m", "norm of the position estimate's error at the first GNC tick after burnout"),
    "velocity_error_burnout_mps": Metric("m/s", "norm of the velocity estimate's error at the first GNC tick after burnout"),
    "position_error_apogee_m": Metric("m", "norm of the position estimate's error at the first GNC tick after apogee"),
    "velocity_error_apogee_mps": Metric("m/s", "norm of the velocity estimate's error at the first GNC tick after apogee"),
    "attitude_nees_window": Metric("1", "mean over the controller's active time of the MEKF's normalised estimation error squared (6 dof)"),
    "position_nees_window": Metric("1", "mean over the controller's active time of the position/velocity filter's NEES (6 dof)"),
    "navigation_diverged": Metric("1", DIVERGED_MEANING),
}  # fmt: skip
"""The outputs a flight on the navigation filters adds (``gnc.navigation.navigation_summary``); NaN where their span
never came."""

DEPLOY_TIME_SUFFIX = "_deploy_time_s"


def metric(name: str) -> Metric:
    """The ``Metric`` of output ``name``: from ``METRICS`` or a parachute's ``<name>_deploy_time_s``."""
    every = {**METRICS, **CONTROL_METRICS, **NAVIGATION_METRICS}
    if name in every:
        return every[name]
    if not name.endswith(DEPLOY_TIME_SUFFIX):
        raise KeyError(name)
    chute = name.removesuffix(DEPLOY_TIME_SUFFIX)
    return Metric("s", f"time the {chute} parachute deploys: its trigger (apogee or its altitude) plus its delay")


def flight_summary(p: FlightParams, state: FlightState) -> tuple[dict, jnp.ndarray]:
    """Summary metrics (NaN for events that did not happen) and the status code."""
    ev = state.events
    landed = jnp.isfinite(ev.impact_time)

    def when(time, value):
        return jnp.where(jnp.isfinite(time), value, jnp.nan)

    summary = {
        "apogee_agl_m": when(ev.apogee_time, ev.apogee_altitude),
        "apogee_time_s": when(ev.apogee_time, ev.apogee_time),
        "apogee_north_m": when(ev.apogee_time, ev.apogee_north),
        "apogee_east_m": when(ev.apogee_time, ev.apogee_east),
        "max_mach": ev.max_mach,
        "max_dynamic_pressure_pa": ev.max_qbar,
        "max_dynamic_pressure_outside_aero_tables_pa": ev.max_qbar_outside_tables,
        "rail_exit_time_s": when(ev.rail_exit_time, ev.rail_exit_time),
        "rail_exit_speed_mps": when(ev.rail_exit_time, ev.rail_exit_speed),
        "burnout_time_s": when(ev.burnout_time, ev.burnout_time),
        "burnout_altitude_agl_m": when(ev.burnout_time, ev.burnout_altitude),
        "burnout_speed_mps": when(ev.burnout_time, ev.burnout_speed),
        "impact_north_m": when(ev.impact_time, ev.impact_north),
        "impact_east_m": when(ev.impact_time, ev.impact_east),
        "impact_time_s": when(ev.impact_time, ev.impact_time),
        "impact_speed_mps": when(ev.impact_time, ev.impact_speed),
    }
    for chute, trigger_time in zip(p.rocket.parachutes, ev.chute_trigger_times):
        summary[chute.name + DEPLOY_TIME_SUFFIX] = when(trigger_time, trigger_time + chute.delay_s)
    failed = []
    if state.gnc is not None:
        summary.update(control_summary(state.gnc))
    if p.gnc is not None and p.gnc.navigation == "filters":
        summary.update(navigation_summary(state.gnc.navigation, summary["burnout_speed_mps"]))
        failed = [state.gnc.navigation.failed]
    outside = ev.max_qbar_outside_tables > OUTSIDE_TABLES_QBAR_FRACTION * ev.max_qbar
    too_high = p.environment.site_altitude_m + ev.apogee_altitude > MAX_ALTITUDE_M
    status = jnp.select(
        [*failed, ev.non_finite, ~landed, too_high, outside],
        [*[Status.NAVIGATION_FAILED] * len(failed), Status.NON_FINITE, Status.MAX_TIME, Status.OUTSIDE_ATMOSPHERE,
         Status.OUTSIDE_AERO_TABLES],
        Status.OK,
    )  # fmt: skip
    return summary, status.astype(jnp.int32)
