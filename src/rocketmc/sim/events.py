"""The flight's events inside an integration step (``update_events``): rail exit, burnout, apogee, the parachutes'
triggers, impact, each located in the step and its values interpolated there, and the start on the rail they are
measured from (``rail_start_n``)."""

from __future__ import annotations

import jax
import jax.numpy as jnp

from ..dynamics import RigidBodyState
from ..math import Vec3
from .loads import mass_properties
from .params import FlightParams
from .state import Diagnostics, Events


@jax.custom_jvp
def _crossing_fraction(g0, g1):
    """Fraction s = g0/(g0 − g1) of a step at which g (linear in the step) reaches 0 from above, in [0, 1]; 0 if
    already there. Its derivative is taken inside (0, 1) only, where g0 and g1 are finite (``_crossing_jvp``): a
    trigger at an infinite altitude makes g infinite in the branch not taken, and reverse mode multiplies that
    branch's derivative by 0 (0·inf is NaN)."""
    dg = g0 - g1
    return jnp.clip(jnp.where(g0 > 0.0, g0 / jnp.where(dg != 0.0, dg, 1.0), 0.0), 0.0, 1.0)


@_crossing_fraction.defjvp
def _crossing_jvp(primals, tangents):
    (g0, g1), (dg0, dg1) = primals, tangents
    s = _crossing_fraction(g0, g1)
    inside = (s > 0.0) & (s < 1.0) & (g1 < 0.0)  # g0 > 0 > g1, both finite
    a, b = jnp.where(inside, g0, 1.0), jnp.where(inside, g1, -1.0)
    return s, jnp.where(inside, (a * dg1 - b * dg0) / (a - b) ** 2, 0.0)  # ds = (g0·dg1 − g1·dg0) / (g0 − g1)²


def _lerp(a, b, s):
    return a + s * (b - a)


def _record(event_time, hit, t0, h, s):
    return jnp.where(hit, t0 + s * h, event_time)


def rail_start_n(p: FlightParams) -> Vec3:
    """CG position at rest on the rail, the nozzle exit at the pad [m, NED]."""
    return p.launch.rail_direction_n * (mass_properties(p, 0.0).cg_x - p.rocket.motor.nozzle_x_m)


def rail_travel_m(p: FlightParams):
    """How far the rocket slides up the rail before it is free [m]: until its exit lug (``Rocket.exit_lug_x_m``)
    passes the rail's top, the nozzle exit starting at its foot."""
    return p.launch.rail_length_m - (p.rocket.exit_lug_x_m - p.rocket.motor.nozzle_x_m)


def update_events(
    p: FlightParams, start_n: Vec3, ev: Events, t0, h, b0: RigidBodyState, b1: RigidBodyState, diag: Diagnostics,
    sensed=None,
) -> Events:
    """Detect the events inside the step ``[t0, t0 + h]`` from ``b0`` to ``b1`` and interpolate them.

    start_n: ``rail_start_n(p)``, passed in so that it is computed once per flight; sensed: navigating from the
    sensors (the GNC state's ``gnc.control.Recovery``), the navigation's held height error [m] and whether it has
    sensed apogee (bool), else None (the true apogee and height trigger the parachutes).
    """
    rail = p.launch.rail_direction_n
    motor = p.rocket.motor
    speed0, speed1 = b0.v_n.norm(), b1.v_n.norm()
    alt0, alt1 = -b0.r_n.z, -b1.r_n.z

    # Rail exit: the exit lug passes the top of the rail (the nozzle started at its foot); the CG
    # shift while on the rail (< 1 cm for Lynx) is neglected.
    travel_to_exit = rail_travel_m(p)
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
