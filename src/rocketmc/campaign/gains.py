"""The LQI gain schedule of a campaign with a ``[gnc]`` section (docs/gnc.md §5), designed once on the host
when the campaign loads (``loader.campaign_from_dict``), from its validated config and its nominal airframe
(``model.airframe_params``: the rocket, its rail and the air, without the closed loop).

Each grid point (axial speed u [m/s], altitude) is ``gnc.design``'s linear plant built from the
campaign's own aerodynamic model at α = β = δ = 0 (its simplified form: the linear model as given,
the simplified table, or ``simplify`` of the interpolated tables) and from the nominal rocket at
burnout: the coast, where most of the guidance window lies. Before the design, the grid is checked
against a point-mass estimate of the nominal flight inside the guidance window; the same estimate gives the
guidance reference's climb when the campaign leaves it out (``guidance_reference``).
"""

from __future__ import annotations

import itertools
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from threadpoolctl import threadpool_limits

from ..aero.model import LinearAero, linear_derivatives, simplify
from ..dynamics.propulsion import propellant_mass, thrust
from ..dynamics.rigid_body import MassProperties
from ..env.atmosphere import G0, AtmosphereProfile, air
from ..gnc.design import FlownLoopUnstable, PlantPoint, Schedule, gain_schedule
from ..math.vectors import Vec3
from ..sim.events import rail_travel_m
from ..sim.loads import mass_properties
from ..sim.params import FlightParams, Launch
from .errors import ConfigError
from .schema import CampaignConfig

ESTIMATE_DT_S = 0.01
"""Step of the point-mass estimate [s]: Lynx's window speeds are within 0.3 % of a step ten times smaller."""
ESTIMATE_HEIGHTS_M = np.linspace(0.0, 50_000.0, 1001)
"""Heights above the pad [m] the estimate tabulates the air on: every 50 m to 50 km (the ISA ends at 47 km)."""
MAX_DERIVED_FLIGHT_PATH_ANGLE_DEG = 89.0
"""The derived reference's angle at t0 is the rail's elevation, at most this [deg]: on a vertical rail the parabola's
horizontal speed c1/tan γ0 is 0, its γ_ref jumps from +90° to −90° at its apogee and its heading is void; at 89° it
is 1.7 % of the climb rate c1 (3 m/s for a 1600 m climb)."""


class GuidanceReference(NamedTuple):
    """The reference guidance steers to (``gnc.guidance.GuidanceParams``): apogee_m, its climb H after t0_s [m];
    t0_s [s since liftoff]; flight_path_angle_deg, γ0 above the horizon at t0; heading_deg, its azimuth; roll_heading_deg,
    the azimuth the body z axis is steered toward [deg, clockwise from north]. derived: the names of those derived
    from the campaign (left out of gnc.guidance)."""

    apogee_m: float
    t0_s: float
    flight_path_angle_deg: float
    heading_deg: float
    roll_heading_deg: float
    derived: tuple[str, ...]


class DesignInputs(NamedTuple):
    """What the gains are designed from: aero, the campaign's model in its simplified form; mass, the
    nominal rocket at burnout (mass [kg], CG body x [m], inertia [kg·m²]); omega_a, the servo bandwidth
    1/τ [rad/s]; speeds [m/s] and altitudes_agl [m above the pad], the nominal flight's range inside the
    guidance window (point-mass estimate, ``nominal_estimate``); atmosphere: the day's air (None: the ISA);
    reference: what guidance steers to (``guidance_reference``)."""

    aero: LinearAero
    mass: MassProperties
    omega_a: float
    speeds: tuple[float, float]
    altitudes_agl: tuple[float, float]
    atmosphere: AtmosphereProfile | None = None
    reference: GuidanceReference | None = None


def design_inputs(config: CampaignConfig, airframe: FlightParams) -> DesignInputs:
    """The ``DesignInputs`` of a campaign with a ``[gnc]`` section from its config and its nominal ``airframe``
    (``campaign.model.airframe_params``); ConfigError if its rocket has no four canards or its nominal flight is not
    in the air during the guidance window."""
    aero = airframe.rocket.aero
    aero = aero if isinstance(aero, LinearAero) else simplify(aero)
    if aero.n_canards != 4:
        raise ConfigError(f"gnc: the controller steers four canards; this rocket's aerodynamic model has "
                          f"{aero.n_canards} (rocket.geometry.canards)")  # fmt: skip
    motor = airframe.rocket.motor
    times = jnp.arange(0.0, float(motor.ignition_time_s + motor.burn_time_s), ESTIMATE_DT_S)
    mass, *arrays = nominal_arrays(airframe, times, jnp.asarray(ESTIMATE_HEIGHTS_M))
    guidance = config.gnc.guidance
    speeds, altitudes, climb = nominal_estimate(airframe, aero, *map(np.asarray, arrays), guidance.window_start_s,
                                                guidance.window_end_s, guidance.t0_s)  # fmt: skip
    return DesignInputs(aero, mass, 1.0 / config.gnc.servo.time_constant_s, speeds, altitudes,
                        airframe.environment.atmosphere, guidance_reference(config, airframe.launch, climb))  # fmt: skip


def guidance_reference(config: CampaignConfig, launch: Launch, climb_m: float) -> GuidanceReference:
    """The reference of the campaign's gnc.guidance, those of its fields left out derived from the nominal flight:
    heading, the launch azimuth; flight-path angle, the rail's elevation (at most MAX_DERIVED_FLIGHT_PATH_ANGLE_DEG);
    roll heading, the azimuth of the horizontal direction that the nominal rail's attitude ``launch.q_nb0`` already
    steers to (perpendicular to the body y axis, on the body z axis's side: no roll error there, so no roll manoeuvre
    at the window's start); apogee, ``climb_m`` [m], the nominal flight's climb after t0_s (``nominal_estimate``).
    ConfigError naming gnc.guidance.apogee_m if that climb is not positive."""
    g = config.gnc.guidance
    y_b = launch.q_nb0.rotate(Vec3(0.0, 1.0, 0.0))
    z_b = launch.q_nb0.rotate(Vec3(0.0, 0.0, 1.0))
    north, east = -float(y_b.y), float(y_b.x)  # ⟂ y_b and horizontal: D × y_b
    side = math.copysign(1.0, north * float(z_b.x) + east * float(z_b.y))
    derived = {
        "apogee_m": climb_m,
        "flight_path_angle_deg": min(config.launch.elevation_deg, MAX_DERIVED_FLIGHT_PATH_ANGLE_DEG),
        "heading_deg": config.launch.azimuth_deg,
        "roll_heading_deg": math.degrees(math.atan2(side * east, side * north)) % 360.0,
    }
    if g.apogee_m is None and not climb_m > 0.0:
        raise ConfigError(f"gnc.guidance.apogee_m: the nominal flight (a point-mass estimate) does not climb after "
                          f"t0_s = {g.t0_s:g} s; set apogee_m or an earlier t0_s")  # fmt: skip
    values = {name: float(derived[name]) if getattr(g, name) is None else getattr(g, name) for name in derived}
    return GuidanceReference(t0_s=g.t0_s, derived=tuple(name for name in derived if getattr(g, name) is None), **values)


@jax.jit
def nominal_arrays(params: FlightParams, times, heights):
    """The nominal rocket's mass properties at burnout; thrust [N] and propellant mass [kg] at simulation
    ``times`` [s]; the air's density [kg/m³] and speed of sound [m/s] at ``heights`` above the pad [m]. One
    compilation (eagerly, XLA compiles each operation apart: seconds in a fresh process)."""
    motor = params.rocket.motor
    air = params.environment.air(params.environment.site_altitude_m + heights)
    return (mass_properties(params, motor.ignition_time_s + motor.burn_time_s), thrust(motor, times),
            propellant_mass(motor, times), air.density, air.speed_of_sound)  # fmt: skip


def plant_point(
    aero: LinearAero, mass: MassProperties, speed: float, altitude_msl: float, omega_a: float,
    atmosphere: AtmosphereProfile | None = None,
) -> PlantPoint:  # fmt: skip
    """docs/gnc.md §5's plant at axial speed ``speed`` [m/s] and ``altitude_msl`` [m]: the coefficients of
    ``aero`` at that Mach number and altitude (in ``atmosphere``, the ISA if None), the moments moved from
    its reference to the CG of ``mass``, the force damping halved to PlantPoint's per ω·d/V."""
    air_there = air(atmosphere, altitude_msl)
    c = linear_derivatives(aero, speed / float(air_there.speed_of_sound), altitude_msl)
    d = float(aero.reference_length_m)
    # About the CG: M_cg = M_ref + (a, 0, 0) × q̄S(−CA, CY, −CN), a = x_ref − x_cg (forward), so
    # Cm gains (a/d)·CN and Cn gains (a/d)·CY, term by term.
    arm = (float(aero.moment_ref_x_m) - float(mass.cg_x)) / d
    return PlantPoint(
        cy_beta=-c["CNa"], cy_r=0.5 * c["CYr"], cy_delta=c["CY_yaw"],
        cn_alpha=c["CNa"], cn_q=0.5 * c["CNq"], cn_delta=c["CN_pitch"],
        cl_p=c["Clp"], cl_delta=c["Cl_roll"],
        cm_alpha=c["Cma"] + arm * c["CNa"], cm_q=c["Cmq"] + arm * c["CNq"],
        cm_delta=c["Cm_pitch"] + arm * c["CN_pitch"],
        cn_yaw_beta=-c["Cma"] - arm * c["CNa"], cn_r=c["Cnr"] + arm * c["CYr"],
        cn_yaw_delta=c["Cn_yaw"] + arm * c["CY_yaw"],
        mass=float(mass.mass), ixx=float(mass.ixx), iyy=float(mass.iyy), area=float(aero.reference_area_m2),
        diameter=d, speed=float(speed), density=float(air_there.density), omega_a=omega_a,
    )  # fmt: skip


def nominal_estimate(params: FlightParams, aero: LinearAero, thrust_n, propellant_kg, density, sound, start_s, end_s,
                     t0_s):  # fmt: skip
    """((min, max) speed [m/s], (min, max) altitude above the pad [m]) of the nominal flight off the
    rail (on it the rocket cannot turn) from ``start_s`` to ``end_s`` after liftoff (first motion), and its
    climb from ``t0_s`` after liftoff to its apogee [m] (≤ 0 if it is past its apogee then, −inf if landed), from
    ``point_mass_flight``. ConfigError if the flight is not in the air in the window."""
    flight = point_mass_flight(params, aero, thrust_n, propellant_kg, density, sound, max(end_s, t0_s))
    window = [(speed, z) for since, z, speed, on_rail in zip(flight.since_liftoff_s, flight.height_m, flight.speed_mps,
                                                             flight.on_rail) if start_s <= since <= end_s and not on_rail]  # fmt: skip
    if not window:
        raise ConfigError(f"gnc.guidance.window_start_s: the nominal flight (a point-mass estimate) is not in the air "
                          f"from {start_s:g} to {end_s:g} s after liftoff")  # fmt: skip
    speeds, altitudes = zip(*window)
    heights = flight.height_m
    climb = max(heights) - float(np.interp(t0_s, flight.since_liftoff_s, heights, right=np.inf))  # −inf: landed by t0
    return (float(min(speeds)), float(max(speeds))), (float(min(altitudes)), float(max(altitudes))), climb


class PointMassFlight(NamedTuple):
    """The nominal flight's point-mass estimate (``point_mass_flight``) every ESTIMATE_DT_S from liftoff: time since
    liftoff [s]; height above the pad [m]; climb and horizontal speed [m/s]; speed [m/s]; on the rail (bool)."""

    since_liftoff_s: list
    height_m: list
    climb_mps: list
    horizontal_mps: list
    speed_mps: list
    on_rail: list


def point_mass_flight(params: FlightParams, aero: LinearAero, thrust_n, propellant_kg, density, sound,
                      until_s) -> PointMassFlight:  # fmt: skip
    """The nominal flight estimated as a point mass up the rail, then turning under gravity (thrust and drag along
    the velocity), with the thrust [N] and propellant [kg] every ESTIMATE_DT_S from t = 0 to burnout, the zero-lift
    drag drag_scale·CA0(Mach) at the pad's altitude (no power-on change, no airbrakes) and the air's density and
    speed of sound at ESTIMATE_HEIGHTS_M; no wind; from liftoff until past ``until_s`` after it and past its apogee,
    or landed. A host loop, ~30 ms for Lynx's guidance window (~60 ms to its apogee)."""
    site = float(params.environment.site_altitude_m)
    heights = ESTIMATE_HEIGHTS_M
    mach_axis = np.asarray(aero.table.axes[aero.table.axis_names.index("mach")])
    ca0 = float(aero.drag_scale) * np.array([linear_derivatives(aero, m, site)["CA0"] for m in mach_axis])
    area, dry_kg = float(aero.reference_area_m2), float(params.rocket.dry_mass_kg)
    sin_e = -float(params.launch.rail_direction_n.z)
    cos_e = math.sqrt(1.0 - sin_e**2)
    travel = float(rail_travel_m(params))

    dt = ESTIMATE_DT_S
    x = z = vx = vz = 0.0  # along the azimuth and up from the start [m], velocity [m/s]
    liftoff, flown = None, PointMassFlight([], [], [], [], [], [])
    for k in itertools.count():
        burning = k < thrust_n.size
        if liftoff is None and not burning:
            break  # burnt out on the pad
        force, mass = (thrust_n[k], dry_kg + propellant_kg[k]) if burning else (0.0, dry_kg)
        speed = math.hypot(vx, vz)
        mach = speed / np.interp(z, heights, sound)
        drag = 0.5 * np.interp(z, heights, density) * speed**2 * area * np.interp(mach, mach_axis, ca0)
        accel = (force - drag) / mass
        on_rail = x * cos_e + z * sin_e < travel
        if on_rail:  # along it, not sliding back from rest
            along = accel - G0 * sin_e if speed > 0.0 else max(accel - G0 * sin_e, 0.0)
            ax, az = along * cos_e, along * sin_e
        else:
            ax, az = accel * vx / speed, accel * vz / speed - G0
        if liftoff is None and (ax != 0.0 or az != 0.0):
            liftoff = k * dt
        if liftoff is not None:
            since = k * dt - liftoff
            if (since > until_s and vz < 0.0 and not on_rail) or (z < 0.0 and vz < 0.0):
                break  # past until_s and the apogee, or back on the ground
            for values, value in zip(flown, (since, z, vz, vx, speed, on_rail)):
                values.append(value)
        x, z = x + (vx + 0.5 * ax * dt) * dt, z + (vz + 0.5 * az * dt) * dt
        vx, vz = vx + ax * dt, vz + az * dt
    return flown


def describe_reference(reference: GuidanceReference) -> str:
    """One line: the reference guidance steers to, each value marked (derived) or (set)."""
    mark = lambda name: "derived" if name in reference.derived else "set"  # noqa: E731
    return (f"guidance reference: climb H {reference.apogee_m:.0f} m ({mark('apogee_m')}) after t0 {reference.t0_s:g} s, "
            f"γ0 {reference.flight_path_angle_deg:g}° ({mark('flight_path_angle_deg')}), heading "
            f"{reference.heading_deg:g}° ({mark('heading_deg')}), roll heading {reference.roll_heading_deg:.4g}° "
            f"({mark('roll_heading_deg')})")  # fmt: skip


GRID_STEPS = {"speeds_mps": 50.0, "altitudes_m": 1000.0}
"""The steps [m/s, m] by which a default design grid grows past its last point to cover a rocket's nominal flight."""


def design_grid(config: CampaignConfig, inputs: DesignInputs) -> dict[str, list[float]]:
    """gnc.control's speeds_mps [m/s] and altitudes_m [m above the pad] as designed on: each as set in the campaign,
    or, left at its default, the default grown by ``GRID_STEPS`` (and a speed point below it, the window's lowest
    speed rounded down) until it covers the nominal flight's window, so that another rocket gets a grid around its
    own flight; the Lynx's window lies inside the defaults. ConfigError if a grid set in the campaign does not cover
    the window (an altitude grid of one point designs gains for every altitude)."""
    control = config.gnc.control
    window = {"speeds_mps": (inputs.speeds, "m/s"), "altitudes_m": (inputs.altitudes_agl, "m above the pad")}
    grids = {}
    for name, ((low, high), unit) in window.items():
        grid = list(getattr(control, name))
        if name not in control.model_fields_set:
            if low < grid[0]:
                grid.insert(0, max(math.floor(low), 1.0))
            while grid[-1] < high:
                grid.append(grid[-1] + GRID_STEPS[name])
        elif (name == "speeds_mps" or len(grid) > 1) and not (grid[0] <= low and high <= grid[-1]):
            guidance = config.gnc.guidance
            raise ConfigError(
                f"gnc.control.{name}: the grid spans {grid[0]:g} to {grid[-1]:g} {unit}, the nominal flight "
                f"{low:.0f} to {high:.0f} {unit} in the guidance window ({guidance.window_start_s:g} to "
                f"{guidance.window_end_s:g} s after liftoff; a point-mass estimate): extend the grid"
            )
        grids[name] = grid
    return grids


MIN_TRIM_ANGLE_DEG = 0.5
"""The least angle of attack the canards must hold the nominal rocket at with full deflection, everywhere in the
guidance window, for a controller to be designed: the rail's setting error (0.5°, an inclinometer on a rail that
sags), below which the canards correct less than the launch itself disperses. The Lynx trims 5.9° (its thesis's
linear model), another team's 4-inch rocket with canards behind the nose (campaigns/custom_canards.toml) 3.5°."""


def trim_angles_deg(config: CampaignConfig, inputs: DesignInputs) -> np.ndarray:
    """The angle of attack [deg] the canards hold the nominal rocket at burnout at with full deflection
    (gnc.servo.limit_deg), |Cm_δ·δ_max / Cmα| about its CG, at the corners of the nominal flight's speeds and
    altitudes inside the guidance window."""
    limit_rad = math.radians(config.gnc.servo.limit_deg)
    points = [plant_point(inputs.aero, inputs.mass, speed, config.site.altitude_m + altitude, inputs.omega_a,
                          inputs.atmosphere) for speed in inputs.speeds for altitude in inputs.altitudes_agl]  # fmt: skip
    return np.degrees([abs(p.cm_delta * limit_rad / p.cm_alpha) for p in points])


def check_authority(config: CampaignConfig, inputs: DesignInputs) -> None:
    """ConfigError naming gnc.servo.limit_deg if the canards trim the rocket less than ``MIN_TRIM_ANGLE_DEG``
    somewhere in the guidance window (``trim_angles_deg``)."""
    weakest = float(np.min(trim_angles_deg(config, inputs)))
    if weakest < MIN_TRIM_ANGLE_DEG:
        raise ConfigError(f"gnc.servo.limit_deg: the canards at {config.gnc.servo.limit_deg:g}° trim the rocket to "
                          f"{weakest:.2g}° of angle of attack where they are weakest in the guidance window, under the "
                          f"{MIN_TRIM_ANGLE_DEG:g}° a controller needs: too little authority (larger canards, "
                          "rocket.geometry.canards, or a larger deflection)")  # fmt: skip


def design_schedule(config: CampaignConfig, inputs: DesignInputs) -> Schedule:
    """The campaign's gain schedule from its config and ``design_inputs``: speeds [m/s], altitudes [m above mean sea
    level] (the grid's altitudes_m plus site.altitude_m), gains (speed, altitude, 3, 11). ConfigError naming
    the field if a grid set in the campaign does not cover the flight (``design_grid``), the canards lack authority (``check_authority``), a point has no
    stabilising design or its loop as flown (the integrators stepped with gnc.guidance.integrator_gain) is not
    stable."""
    grid = design_grid(config, inputs)
    check_authority(config, inputs)
    control = config.gnc.control
    try:
        # One BLAS thread: on 11×11 matrices more only contend (measured 2.5 ms a point against 7-25 ms
        # on 2 busy cores), and the gains (in the set-up's fingerprint) are the same bits on any machine.
        with threadpool_limits(1):
            return gain_schedule(
                lambda speed, altitude: plant_point(inputs.aero, inputs.mass, speed, altitude, inputs.omega_a,
                                                    inputs.atmosphere),
                grid["speeds_mps"],
                config.site.altitude_m + np.asarray(grid["altitudes_m"]),
                dt=config.simulation.control_dt_s,
                q=np.diag(control.q_weights),
                r=np.diag(control.r_weights),
                method=control.discretisation,
                integrator_gain=config.gnc.guidance.integrator_gain,
            )
    except FlownLoopUnstable as err:
        raise ConfigError(f"gnc.guidance.integrator_gain: {err} (lower the integrator gains or change the design's "
                          f"gnc.control)") from None  # fmt: skip
    except ValueError as err:
        raise ConfigError(f"gnc.control: {err}") from None


STATE = ("v", "w", "p", "q", "r", "u_y", "u_p", "u_r", "e_p", "e_q", "e_r")
"""The columns of K: the augmented state of docs/gnc.md §5 (``gnc.design``); its rows are (yaw, pitch, roll)."""
MAIN_GAINS = {"pitch": {"K_w": (1, 1), "K_q": (1, 3), "K_up": (1, 6), "K_eq": (1, 9)},
              "roll": {"K_p": (2, 2), "K_ur": (2, 7), "K_ep": (2, 8)}}  # fmt: skip
"""The gains that act in the pitch and roll channels, by (row, column) of K; the yaw row mirrors pitch."""


def schedule_summary(config: CampaignConfig, schedule: Schedule, inputs: DesignInputs) -> dict:
    """A campaign's gain schedule and what it was designed from (``Campaign.gnc_schedule``, ``gnc_inputs``),
    JSON-able (``rocketmc gnc design``):
    per grid point speed [m/s], altitude above the pad and above sea level [m], the designed closed loop's
    spectral radius and the loop's as flown (``gnc.design.flown_loop``), relative Riccati residual, K (3, 11)
    and its ``MAIN_GAINS``; the guidance reference, each value with whether it was derived (t0_s is always set)."""
    control = config.gnc.control
    altitudes_agl = design_grid(config, inputs)["altitudes_m"]
    points = [
        {
            "speed_mps": float(speed), "altitude_agl_m": altitudes_agl[j],
            "altitude_msl_m": float(altitude), "spectral_radius": float(schedule.spectral_radius[i, j]),
            "flown_spectral_radius": float(schedule.flown_radius[i, j]),
            "riccati_residual": float(schedule.residual[i, j]), "gain": schedule.gains[i, j].tolist(),
            **{row: {name: float(schedule.gains[i, j][index]) for name, index in gains.items()}
               for row, gains in MAIN_GAINS.items()},
        }
        for i, speed in enumerate(schedule.speeds)
        for j, altitude in enumerate(schedule.altitudes)
    ]  # fmt: skip
    mass = inputs.mass
    return {
        "campaign": config.name,
        "aero_model": config.rocket.aero.model,
        "dt_s": config.simulation.control_dt_s,
        "discretisation": control.discretisation,
        "integrator_gain": config.gnc.guidance.integrator_gain,
        "q_weights": control.q_weights,
        "r_weights": control.r_weights,
        "state": STATE,
        "servo_bandwidth_rad_s": inputs.omega_a,
        "burnout": {"mass_kg": float(mass.mass), "cg_x_m": float(mass.cg_x), "ixx_kgm2": float(mass.ixx),
                    "iyy_kgm2": float(mass.iyy)},  # fmt: skip
        "window_estimate": {"speed_mps": list(inputs.speeds), "altitude_agl_m": list(inputs.altitudes_agl)},
        "reference": {name: {"value": getattr(inputs.reference, name), "derived": name in inputs.reference.derived}
                      for name in GuidanceReference._fields if name != "derived"},
        "points": points,
    }


def format_schedule(summary: dict, reference: GuidanceReference) -> str:
    """``schedule_summary``'s result as text: the design's inputs, then one row of main gains per grid point."""
    mass, window = summary["burnout"], summary["window_estimate"]
    names = [name for row in ("pitch", "roll") for name in summary["points"][0][row]]
    flown = max(p["flown_spectral_radius"] for p in summary["points"])
    designed = max(p["spectral_radius"] for p in summary["points"])
    lines = [
        f"{summary['campaign']}: LQI gains ({summary['aero_model']} aerodynamics), {summary['discretisation']} "
        f"over dt {summary['dt_s']:g} s, Q = diag{tuple(summary['q_weights'])}, R = diag{tuple(summary['r_weights'])}, "
        f"integrator gains {tuple(summary['integrator_gain'])}",
        f"  plant at burnout: mass {mass['mass_kg']:.3f} kg, CG x {mass['cg_x_m']:+.3f} m (body, from the "
        f"reference point), Ixx {mass['ixx_kgm2']:.4g}, Iyy {mass['iyy_kgm2']:.4g} kg·m²; "
        f"servo {summary['servo_bandwidth_rad_s']:.2f} rad/s",
        f"  guidance window (nominal flight, point-mass estimate): {window['speed_mps'][0]:.0f} to "
        f"{window['speed_mps'][1]:.0f} m/s, {window['altitude_agl_m'][0]:.0f} to {window['altitude_agl_m'][1]:.0f} m above the pad",
        f"  {describe_reference(reference)}",
        f"  spectral radius of the loop as flown: at most {flown:.5f} over the grid (designed loop: {designed:.5f})",
        f"  {'speed':>7}{'altitude':>10}{'flown':>10}{'designed':>10}{'residual':>10}" + "".join(f"{n:>9}" for n in names),
        f"  {'[m/s]':>7}{'[m AGL]':>10}{'radius':>10}{'radius':>10}",
    ]  # fmt: skip
    for p in summary["points"]:
        gains = [p[row][name] for row in ("pitch", "roll") for name in p[row]]
        lines.append(f"  {p['speed_mps']:>7g}{p['altitude_agl_m']:>10g}{p['flown_spectral_radius']:>10.5f}"
                     f"{p['spectral_radius']:>10.5f}{p['riccati_residual']:>10.1e}" + "".join(f"{k:>9.4f}" for k in gains))  # fmt: skip
    return "\n".join(lines)
