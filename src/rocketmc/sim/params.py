"""The parameter aggregate of one flight and the static simulation settings."""

from __future__ import annotations

import dataclasses

import jax.numpy as jnp

from ..aero import LinearAero, TableAero
from ..dynamics import Motor, Parachute
from ..gnc.airbrakes import AirbrakeParams
from ..gnc.control import GncParams
from ..sensors.avionics import Avionics
from ..env import PowerLawWind, Turbulence, WindLayers, WindProfile
from ..env.atmosphere import G0, AtmosphereProfile, AtmosphereState, air, inverse_square_gravity
from ..math import Quat, Vec3
from ..pytree import pytree_dataclass, static_field
from .faults import Faults


@pytree_dataclass
class Rocket:
    """Airframe without propellant, motor, aerodynamics and recovery.

    dry_mass_kg: mass without propellant [kg]; dry_cg_x_m: its CG on the body x axis from the
    reference point [m]; dry_ixx_kgm2, dry_iyy_kgm2: its inertia about that CG [kg·m²];
    exit_lug_x_m: body-frame x of the launch lug (or rail button) whose passing the rail's top frees the rocket: the
    upper of two, else the only one [m]; aero: the aerodynamic model, linear or interpolated
    from tables (``aero.model``); canopy_cl_p: roll damping under canopy;
    airbrake_time_s, airbrake_delta_ca: the airbrakes' extra axial-force coefficient against time since
    ignition [s] (linear in between, 0 outside), or None without airbrakes.
    """

    dry_mass_kg: jnp.ndarray
    dry_cg_x_m: jnp.ndarray
    dry_ixx_kgm2: jnp.ndarray
    dry_iyy_kgm2: jnp.ndarray
    exit_lug_x_m: jnp.ndarray
    motor: Motor
    aero: LinearAero | TableAero
    parachutes: tuple[Parachute, ...]
    canopy_cl_p: jnp.ndarray
    airbrake_time_s: jnp.ndarray | None = None
    airbrake_delta_ca: jnp.ndarray | None = None


@pytree_dataclass
class Launch:
    """rail_length_m [m]; rail_direction_n: unit vector up the rail in NED; q_nb0: attitude on the
    rail (body x along the rail, no roll)."""

    rail_length_m: jnp.ndarray
    rail_direction_n: Vec3
    q_nb0: Quat

    @classmethod
    def from_angles(cls, rail_length_m, elevation_rad, azimuth_rad) -> Launch:
        """Rail of given length, elevation above the horizon and azimuth clockwise from north."""
        ce = jnp.cos(elevation_rad)
        direction = Vec3(ce * jnp.cos(azimuth_rad), ce * jnp.sin(azimuth_rad), -jnp.sin(elevation_rad))
        return cls(jnp.asarray(rail_length_m), direction, Quat.from_euler(azimuth_rad, elevation_rad, 0.0))


@pytree_dataclass
class Environment:
    """site_altitude_m: pad altitude above mean sea level [m]; wind: the mean wind; turbulence:
    Dryden gusts added to it (None: no turbulence, and no cost); atmosphere: the day's (None: the ISA, and
    no cost); gravity: "constant" (G0 everywhere) or "inverse_square" (falling with altitude, static)."""

    site_altitude_m: jnp.ndarray
    wind: WindLayers | WindProfile | PowerLawWind
    turbulence: Turbulence | None = None
    atmosphere: AtmosphereProfile | None = None
    gravity: str = static_field(default="constant")

    def air(self, altitude_msl) -> AtmosphereState:
        """The air at a geometric altitude above mean sea level [m]."""
        return air(self.atmosphere, altitude_msl)

    def gravity_mps2(self, altitude_msl):
        """Gravity [m/s², down] at a geometric altitude above mean sea level [m]: G0, or with
        ``gravity = "inverse_square"`` G0·(r0/(r0 + z))² (``env.atmosphere.inverse_square_gravity``)."""
        return inverse_square_gravity(altitude_msl) if self.gravity == "inverse_square" else G0


@pytree_dataclass
class FlightParams:
    """Everything one realization needs (all leaves dynamic: they can be dispersed); gnc: the closed
    loop (None: canards neutral, and no cost); avionics: the sensors (None: none simulated, and no cost); faults:
    the servos' and sensors' faults (``sim.faults``; None: none, and no cost); airbrakes: the air brakes and their
    flight software (``gnc.airbrakes``; None: none, and no cost)."""

    rocket: Rocket
    launch: Launch
    environment: Environment
    gnc: GncParams | None = None
    avionics: Avionics | None = None
    faults: Faults | None = None
    airbrakes: AirbrakeParams | None = None


@dataclasses.dataclass(frozen=True)
class SimSettings:
    """Static settings (hashable; changing one recompiles).

    control_dt_s: control period, the GNC rate [s]; substeps: RK4 steps per control period;
    descent_dt_s: the longer period used under a fully open canopy, once opening transients have
    settled (``settle_s`` after full opening); the GNC is idle then [s]; ``descent_h_omega``: the
    largest RK4 step h times the body's pendulum rate ω under its canopies there; point_mass_descent: once the body's
    swing has died out there (``swing_settle_s`` [s] after the last opening settled and the last wind-layer boundary
    crossed), fly it as a point mass in longer periods (``sim.flight.steady_descent``);
    event_periods: without a controller and sensors, fly periods of ``open_loop_dt_s`` [s] (``control_dt_s`` unless the
    campaign sets a longer one) that end at the rail exit, a wind-layer boundary and a thrust-curve point
    (``sim.flight.event_period``); False: the GNC grid's periods, as with a controller;
    max_time_s: a flight not on the ground by then gets the status MAX_TIME;
    block_steps: control periods per chunk of work between checks that the whole batch has landed.
    """

    control_dt_s: float = 0.02
    substeps: int = 1
    descent_dt_s: float = 0.25
    descent_h_omega: float = 1.0
    settle_s: float = 1.0
    point_mass_descent: bool = True
    swing_settle_s: float = 5.0
    event_periods: bool = True
    open_loop_dt_s: float = 0.02
    max_time_s: float = 300.0
    block_steps: int = 100
