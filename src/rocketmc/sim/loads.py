"""What acts on the rocket at one instant: its mass properties with the propellant left, the thrust, the
aerodynamic and parachute forces (``loads``), and the flight's right-hand side built on them (``derivatives``),
on the rail constrained to move along it."""

from __future__ import annotations

from typing import NamedTuple

import jax.numpy as jnp

from ..aero import AirData, aero_coefficients, aero_wrench, air_data
from ..dynamics import RigidBodyState, open_fraction, parachute_drag_n, propellant_mass, rigid_body_derivatives, thrust
from ..dynamics.propulsion import grain_inertia
from ..dynamics.rigid_body import MassProperties, combine_on_axis
from ..gnc.airbrakes import delta_ca as airbrake_delta_ca
from ..math import Quat, Vec3
from ..pytree import tree_where
from .params import FlightParams
from .state import Canopy, Diagnostics, Events

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
    the moment of everything about the CG [N·m, FRD], whether a canopy is open (bool), the ``Canopy`` rates and
    whether the aerodynamic tables were left (bool)."""

    mass: MassProperties
    air: AirData
    thrust_n: jnp.ndarray
    aero_force_b: Vec3
    chute_force_n: Vec3
    moment_b: Vec3
    under_canopy: jnp.ndarray
    canopy: Canopy
    outside_tables: jnp.ndarray


def loads(t, body: RigidBodyState, p: FlightParams, deflections, gust_n: Vec3, events: Events,
          deployment=None) -> Loads:  # fmt: skip
    """The ``Loads`` at ``t`` [s] on ``body`` with canard deflections δ1..δn [rad], a turbulent gust
    ``gust_n`` [m/s, NED] on top of the mean wind and the air brakes' ``deployment`` (0 … 1; with ``p.airbrakes``)
    (``derivatives``' forces, also read by ``analysis``)."""
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
    stiffness, drag_per_m = jnp.zeros_like(t), jnp.zeros_like(t)
    for chute, trigger_time in zip(rocket.parachutes, events.chute_trigger_times):
        fraction = open_fraction(chute, trigger_time, t)
        if chute.released_by is not None:  # cut away once the canopy that releases it starts opening
            releaser = rocket.parachutes[chute.released_by]
            cut_time = events.chute_trigger_times[chute.released_by] + releaser.delay_s
            fraction = jnp.where(t >= cut_time, 0.0, fraction)
        arm_b = Vec3(chute.attach_x_m - mass.cg_x, 0.0, 0.0)
        v_air_n = body.v_n + q_nb.rotate(omega_b.cross(arm_b)) - wind_n
        drag_n = parachute_drag_n(chute, fraction, v_air_n, atmosphere.density)
        force_n = force_n + drag_n
        moment_b = moment_b + arm_b.cross(q_nb.rotate_inverse(drag_n))
        under_canopy = under_canopy | (fraction > 0.0)
        stiffness = stiffness + drag_n.norm() * jnp.abs(arm_b.x) / mass.iyy
        drag_per_m = drag_per_m + drag_n.norm() / (mass.mass * jnp.maximum(v_air_n.dot(v_air_n), 1e-12))

    thrust_n = thrust(rocket.motor, t)
    coefficients, outside_tables = aero_coefficients(rocket.aero, air, omega_b, mass.cg_x, deflections, thrust_n > 0.0)
    if rocket.airbrake_time_s is not None:
        since_ignition = t - rocket.motor.ignition_time_s
        delta_ca = jnp.interp(since_ignition, rocket.airbrake_time_s, rocket.airbrake_delta_ca, left=0.0, right=0.0)
        coefficients = coefficients._replace(ca=coefficients.ca + delta_ca)
    if p.airbrakes is not None:
        coefficients = coefficients._replace(ca=coefficients.ca + airbrake_delta_ca(p.airbrakes, deployment, air.mach))
    aero_force_b, aero_moment_b = aero_wrench(rocket.aero, coefficients, air, omega_b, rocket.canopy_cl_p, under_canopy)
    aero_arm_b = Vec3(rocket.aero.moment_ref_x_m - mass.cg_x, 0.0, 0.0)
    moment_b = moment_b + aero_moment_b + aero_arm_b.cross(aero_force_b)
    canopy = Canopy(stiffness, drag_per_m)
    return Loads(mass, air, thrust_n, aero_force_b, force_n, moment_b, under_canopy, canopy, outside_tables)


def derivatives(t, body: RigidBodyState, p: FlightParams, deflections, gust_n: Vec3, events: Events,
                point_mass=False, deployment=None):  # fmt: skip
    """State derivative and ``Diagnostics`` at ``t`` with canard deflections δ1..δn [rad], a
    turbulent gust ``gust_n`` [m/s, NED] on top of the mean wind and the air brakes' ``deployment`` (``loads``);
    point_mass (bool): the body's attitude and rates held, its CG moved by every force (steady descent:
    ``sim.flight.steady_descent``)."""
    f = loads(t, body, p, deflections, gust_n, events, deployment)
    force_b = f.aero_force_b + Vec3(f.thrust_n, 0.0, 0.0)
    gravity = p.environment.gravity_mps2(p.environment.site_altitude_m - body.r_n.z)
    free = rigid_body_derivatives(body, f.mass, force_b, f.chute_force_n, f.moment_b, gravity)

    # On the rail: motion along it only, no rotation, no sliding back down before liftoff.
    rail = p.launch.rail_direction_n
    accel_along = free.v_n.dot(rail)
    accel_along = jnp.where((body.v_n.dot(rail) > 0.0) | (accel_along > 0.0), accel_along, 0.0)
    zero = jnp.zeros_like(accel_along)
    still_q, still_omega = Quat(zero, zero, zero, zero), Vec3(zero, zero, zero)  # attitude and rates held
    on_rail = RigidBodyState(body.v_n, rail * accel_along, still_q, still_omega)
    d_body = tree_where(jnp.isinf(events.rail_exit_time), on_rail, free)
    if point_mass is not False:
        d_body = tree_where(point_mass, RigidBodyState(free.r_n, free.v_n, still_q, still_omega), d_body)
    qbar_outside = jnp.where(f.outside_tables & ~f.under_canopy, f.air.qbar, 0.0)
    return d_body, Diagnostics(f.air.mach, f.air.qbar, f.canopy, qbar_outside)
