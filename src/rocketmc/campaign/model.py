"""From the numbers of a campaign (nominal or drawn) to the ``FlightParams`` of one flight.

Pure and jittable: ``values`` maps dotted paths to scalars (Python floats for the nominal ones,
traced arrays for the dispersed ones), so every unit conversion below happens per realization.
"""

from __future__ import annotations

import dataclasses
import datetime
import math
from collections.abc import Mapping

import jax
import jax.numpy as jnp

from ..aero.model import TableAero, from_virtual_commands
from ..dynamics import Motor, Parachute
from ..dynamics.propulsion import cumulative_impulse
from ..dynamics.rigid_body import combine_on_axis
from ..dynamics.servo import ServoParams
from ..env import PowerLawWind, Turbulence, WindLayers, WindProfile
from ..env.atmosphere import G0, AtmosphereProfile
from ..env.weather import geometric_altitude
from ..gnc.control import GAIN_NAMES, GncParams
from ..gnc.attitude_filter import AttitudeTuning
from ..gnc.guidance import GuidanceParams
from ..gnc.navigation import FilterParams, NavigationMode
from ..gnc.position_filter import PositionTuning
from ..math import Quat, Vec3
from ..math.table import Table
from ..env.magnetic import igrf_site_field_gradient, site_field_gradient, site_field_ned
from ..sensors.avionics import Avionics, Gnss, Magnetometer, Mounted
from ..sensors.errors import Channel, noise_per_sample, walk_per_sample
from ..sensors.parts import SENSORS
from ..sim.faults import Faults, GnssOutage, SensorStep, SlowCanard, StuckAirbrakes, StuckCanard
from ..env.weather import Weather
from ..sim.events import rail_start_n
from ..sim.params import Environment, FlightParams, Launch, Rocket, SimSettings
from .errors import ConfigError
from .gains import GuidanceReference
from .record import Campaign
from .sampling import UNIT_FIELDS, realization_key, stream_key
from .schema import AttitudeFilterConfig, CampaignConfig, FiltersConfig, GuidanceConfig, PositionFilterConfig


def _vector(values: Mapping, path: str, n: int, suffix: str = ""):
    """The n values at ``path.0<suffix>`` .. ``path.<n-1><suffix>`` as one array."""
    return jnp.stack([jnp.asarray(values[f"{path}.{i}{suffix}"], dtype=float) for i in range(n)])


def _configured(config: CampaignConfig, path: str) -> float:
    """The number the config holds at a dotted path: a host float, also where the flight's values are traced (what
    is switched off by a zero is decided from it; ``program.structure_fingerprint`` keeps its sign)."""
    node = config
    for part in path.split("."):
        node = node[int(part)] if part.isdigit() else getattr(node, part)
    return float(node)


def _arrays(values: Mapping) -> dict:
    return {k: jnp.asarray(x, dtype=float) for k, x in values.items()}


def _body_x(config: CampaignConfig, v: Mapping):
    """A position in the rocket's coordinates (dotted path of ``v``) -> body-frame x (forward) from the reference [m]."""
    ref, sign = v["rocket.reference_point_m"], config.rocket.position_sign
    return lambda path: sign * (ref - v[path])


def flight_params(campaign: Campaign, values: Mapping, key) -> FlightParams:
    """FlightParams from ``values`` (dotted path -> scalar), the realization's ``key`` (the turbulence's
    noise) and the campaign's static structure."""
    cfg = campaign.config
    airframe = airframe_params(cfg, campaign.thrust_time_s, campaign.thrust_n, campaign.aero, campaign.wind_profile,
                               campaign.weather, values)  # fmt: skip
    v = _arrays(values)
    environment = dataclasses.replace(airframe.environment, turbulence=_turbulence(cfg, v, key))
    avionics = _avionics(campaign, v, key, _body_x(cfg, v), airframe.rocket.aero.n_canards)
    return dataclasses.replace(airframe, environment=environment, gnc=_gnc(campaign, v), avionics=avionics,
                               faults=_faults(campaign, v, avionics), airbrakes=campaign.airbrakes)  # fmt: skip


def airframe_params(
    config: CampaignConfig, thrust_time_s, thrust_n, aero: TableAero | None, wind_profile, weather: Weather | None,
    values: Mapping,
) -> FlightParams:  # fmt: skip
    """The flight of ``values`` (dotted path -> scalar) without turbulence, closed loop, sensors or faults: the rocket
    with its thrust curve (``thrust_time_s`` [s], ``thrust_n`` [N]) and aerodynamic model (``aero``; None: the linear
    one of ``values``), its rail, the mean wind (``wind_profile``: the measured one of ``model = "profile"``) and the
    air (``weather``: the day's, None: the ISA). What the gains are designed for (``campaign.gains``) and what the
    avionics know of the launch (``nominal_rail``)."""
    v = _arrays(values)
    rocket = _rocket(config, thrust_time_s, thrust_n, aero, v)
    launch = Launch.from_angles(
        v["launch.rail_length_m"], jnp.deg2rad(v["launch.elevation_deg"]), jnp.deg2rad(v["launch.azimuth_deg"])
    )
    environment = Environment(
        site_altitude_m=jnp.asarray(config.site.altitude_m, dtype=float),
        wind=_wind(config, wind_profile, weather, v),
        atmosphere=_atmosphere(weather),
        gravity=config.environment.gravity,
    )
    return FlightParams(rocket, launch, environment)


def _rocket(cfg: CampaignConfig, thrust_time_s, thrust_n, table_aero: TableAero | None, v: Mapping) -> Rocket:
    """The rocket from the values ``v``, its thrust curve [s], [N] and aerodynamic model (None: the linear one of
    ``v``)."""
    body_x = _body_x(cfg, v)
    ref = v["rocket.reference_point_m"]
    m = "rocket.motor"
    grain_center = (
        body_x(f"{m}.grain_center_m")
        if cfg.rocket.motor.grain_center_m is not None
        else body_x(f"{m}.nozzle_m") + 0.5 * v[f"{m}.grain_length_m"]
    )
    motor_dry_x = grain_center if cfg.rocket.motor.dry_cg_m is None else body_x(f"{m}.dry_cg_m")
    time_s, scaled_thrust_n = jnp.asarray(thrust_time_s), jnp.asarray(thrust_n) * v[f"{m}.thrust_scale"]
    if cfg.rocket.motor.burn_time_s is not None:  # the curve reshaped to the burn time, each segment's impulse kept
        stretch = v[f"{m}.burn_time_s"] / time_s[-1]
        time_s, scaled_thrust_n = time_s * stretch, scaled_thrust_n / stretch
    motor = Motor(
        time_s=time_s,
        thrust_n=scaled_thrust_n,
        impulse_ns=jnp.asarray(cumulative_impulse(thrust_time_s, thrust_n)) * v[f"{m}.thrust_scale"],
        ignition_time_s=v[f"{m}.ignition_delay_s"],
        propellant_mass_kg=v[f"{m}.propellant_mass_kg"],
        grain_outer_diameter_m=v[f"{m}.grain_outer_diameter_m"],
        grain_inner_diameter_m=v[f"{m}.grain_inner_diameter_m"],
        grain_length_m=v[f"{m}.grain_length_m"],
        grain_center_x_m=grain_center,
        nozzle_x_m=body_x(f"{m}.nozzle_m"),
    )

    a = "rocket.aero"
    if table_aero is None:  # model = "linear": the coefficients may be dispersed
        lin = f"{a}.linear"
        n_mach = len(cfg.rocket.aero.linear.ca0_mach)
        aero = from_virtual_commands(
            reference_area_m2=v[f"{lin}.reference_area_m2"],
            reference_length_m=v[f"{lin}.reference_length_m"],
            moment_ref_x_m=jnp.zeros_like(ref),
            ca0_mach=_vector(v, f"{lin}.ca0_mach", n_mach),
            ca0=_vector(v, f"{lin}.ca0", n_mach),
            ca_u=_vector(v, f"{lin}.ca_u", 4),
            drag_scale=v[f"{a}.drag_scale"],
            cl0=v[f"{a}.cl0"],
            **{k: v[f"{lin}.{k}"] for k in ("cn_alpha", "cn_delta", "cm_alpha", "cm_delta", "cl_delta",
                                             "cy_r", "cn_q", "cl_p", "cm_q")},
        )  # fmt: skip
    else:
        aero = dataclasses.replace(table_aero, drag_scale=v[f"{a}.drag_scale"], cl0=v[f"{a}.cl0"])

    parachutes = []
    for i, chute in enumerate(cfg.rocket.parachutes):
        c = f"rocket.parachutes.{i}"
        altitude = v[f"{c}.deploy_altitude_m"] if chute.deploy_altitude_m is not None else jnp.inf
        parachutes.append(
            Parachute(
                cd_s_m2=v[f"{c}.cd"] * v[f"{c}.area_m2"],
                trigger_altitude_agl_m=jnp.asarray(altitude, dtype=float),
                delay_s=v[f"{c}.delay_s"],
                opening_time_s=v[f"{c}.opening_time_s"],
                attach_x_m=body_x(f"{c}.attach_m"),
                name=chute.name,
                released_by=next((j for j, other in enumerate(cfg.rocket.parachutes) if other.releases == chute.name),
                                 None),
            )
        )

    dry = combine_on_axis([
        (v["rocket.dry_mass_kg"], body_x("rocket.dry_cg_m"), v["rocket.dry_inertia_kgm2.0"], v["rocket.dry_inertia_kgm2.1"]),
        (v[f"{m}.dry_mass_kg"], motor_dry_x, v[f"{m}.dry_inertia_kgm2.0"], v[f"{m}.dry_inertia_kgm2.1"]),
    ])  # fmt: skip
    rocket = Rocket(
        dry_mass_kg=dry.mass,
        dry_cg_x_m=dry.cg_x,
        dry_ixx_kgm2=dry.ixx,
        dry_iyy_kgm2=dry.iyy,
        exit_lug_x_m=body_x("rocket.rear_lug_m" if cfg.rocket.upper_lug_m is None else "rocket.upper_lug_m"),
        motor=motor,
        aero=aero,
        parachutes=tuple(parachutes),
        canopy_cl_p=v["rocket.canopy_roll_damping"],
    )
    if cfg.rocket.airbrakes is not None:
        n = len(cfg.rocket.airbrakes.time_s)
        rocket = dataclasses.replace(
            rocket,
            airbrake_time_s=_vector(v, "rocket.airbrakes.time_s", n),
            airbrake_delta_ca=_vector(v, "rocket.airbrakes.delta_ca", n),
        )
    return rocket


def _faults(campaign: Campaign, v: Mapping, avionics: Avionics | None) -> Faults | None:
    """The faults the campaign can fly (``FaultsConfig.active``) from their draws in ``v`` (``sample_faults``), in SI
    and the sensors' frames (the magnetometer's step through its mounting); None without any, or without their draws
    (the nominal flight)."""
    faults = campaign.config.faults
    active = {} if faults is None else faults.active()
    if not active or f"faults.{next(iter(active))}.happened" not in v:
        return None

    def at(name: str, what: str = "time_s"):  # the fault's time [s], inf where it did not happen
        return jnp.where(v[f"faults.{name}.happened"] > 0.5, v[f"faults.{name}.{what}"], jnp.inf)

    def fin(name: str):  # (4,) bool, the faulty fin (none where it did not happen: NaN)
        return jnp.arange(1.0, 5.0) == v[f"faults.{name}.fin"]

    def vector(name: str, unit: float):  # the drawn vector in SI, zeros where it did not happen
        path = f"faults.{name}.{UNIT_FIELDS[name][1]}"
        return jnp.where(v[f"faults.{name}.happened"] > 0.5, _vector(v, path, 3) * unit, 0.0)

    built = {}
    if "stuck_canard" in active:
        angle = active["stuck_canard"].angle_deg
        built["stuck_canard"] = StuckCanard(at("stuck_canard"), fin("stuck_canard"),
                                            None if angle is None else jnp.asarray(math.radians(angle)))  # fmt: skip
    if "slow_canard" in active:
        built["slow_canard"] = SlowCanard(at("slow_canard"), fin("slow_canard"),
                                          jnp.asarray(active["slow_canard"].factor))  # fmt: skip
    if "stuck_airbrakes" in active:
        jammed = active["stuck_airbrakes"].deployment
        built["stuck_airbrakes"] = StuckAirbrakes(at("stuck_airbrakes"), None if jammed is None else jnp.asarray(jammed))
    if "gnss_outage" in active:
        built["gnss_outage"] = GnssOutage(at("gnss_outage", "start_s"), at("gnss_outage", "end_s"))
    if "magnetometer_step" in active:
        step_b = vector("magnetometer_step", SENSOR_UNITS["magnetometer"])
        rotation = avionics.magnetometer.sensor.rotation  # body → sensor
        step_s = jnp.stack([sum(rotation[i, j] * step_b[j] for j in range(3)) for i in range(3)])
        built["magnetometer_step"] = SensorStep(at("magnetometer_step"), step_s)
    for sensor in ("gyroscope", "accelerometer"):
        if (name := f"{sensor}_bias_jump") in active:
            built[name] = SensorStep(at(name), vector(name, SENSOR_UNITS[sensor]))
    return Faults(**built)


def _gnc(campaign: Campaign, v: Mapping) -> GncParams | None:
    """The closed loop from the campaign's [gnc] (None without it): the servos from the (possibly drawn)
    values ``v``, guidance from the config and its reference from ``campaign.gnc_inputs.reference`` (set or derived
    at set-up), the gains of ``campaign.gnc_schedule``."""
    gnc = campaign.config.gnc
    if gnc is None:
        return None
    navigation = NavigationMode(gnc.navigation)
    filters = filter_params(campaign) if navigation is NavigationMode.FILTERS else None
    rail = (None, None) if navigation is NavigationMode.TRUTH else nominal_rail(campaign)
    if not gnc.canards:
        return GncParams(None, None, None, False, navigation, filters, *rail)
    s = "gnc.servo"
    rate_limit = gnc.servo.rate_limit_deg_s
    servo = ServoParams(
        time_constant_s=v[f"{s}.time_constant_s"],
        limit_rad=jnp.deg2rad(v[f"{s}.limit_deg"]),
        offset_rad=jnp.deg2rad(_vector(v, f"{s}.offset_deg", len(gnc.servo.offset_deg))),
        rate_limit_rad_s=None if rate_limit is None else jnp.deg2rad(v[f"{s}.rate_limit_deg_s"]),
    )
    guidance = guidance_params(gnc.guidance, campaign.gnc_inputs.reference)  # the reference: set, or derived
    schedule = campaign.gnc_schedule
    gains = schedule.gains.reshape(*schedule.gains.shape[:2], -1)  # (speed, altitude, 33)
    if schedule.altitudes.size > 1:  # the design's grid, checked when it was designed (traced in a program)
        table = Table((jnp.asarray(schedule.speeds), jnp.asarray(schedule.altitudes)), jnp.asarray(gains),
                      ("speed", "altitude"), GAIN_NAMES)  # fmt: skip
    else:
        table = Table((jnp.asarray(schedule.speeds),), jnp.asarray(gains[:, 0]), ("speed",), GAIN_NAMES)
    return GncParams(servo, guidance, table, gnc.control.anti_windup, navigation, filters, *rail)


def guidance_params(g: GuidanceConfig, reference: GuidanceReference) -> GuidanceParams:
    """Guidance from [gnc.guidance] and the reference it steers to (``campaign.gains.guidance_reference``), in SI."""
    rad = lambda deg: jnp.deg2rad(jnp.asarray(deg, dtype=float))  # noqa: E731
    return GuidanceParams(
        apogee_m=jnp.asarray(reference.apogee_m), t0_s=jnp.asarray(g.t0_s),
        flight_path_angle_rad=rad(reference.flight_path_angle_deg), heading_rad=rad(reference.heading_deg),
        gain=jnp.asarray(g.gain), rate_limit_rad_s=rad(g.rate_limit_deg_s), min_speed_mps=jnp.asarray(g.min_speed_mps),
        roll_gain=jnp.asarray(g.roll_gain), roll_heading_rad=rad(reference.roll_heading_deg),
        roll_rate_limit_rad_s=rad(g.roll_rate_limit_deg_s), integrator_gain=Vec3(*(jnp.asarray(k) for k in g.integrator_gain)),
        window_start_s=jnp.asarray(g.window_start_s), window_end_s=jnp.asarray(g.window_end_s),
        wind_gain=None if g.wind_gain is None else jnp.asarray(g.wind_gain),
        wind_time_constant_s=None if g.wind_gain is None else jnp.asarray(g.wind_time_constant_s),
    )  # fmt: skip


DEG = math.pi / 180.0  # [rad/deg]
GUIDANCE_NUMBERS = {
    "gnc.guidance.apogee_m": ("apogee_m", 1.0),
    "gnc.guidance.t0_s": ("t0_s", 1.0),
    "gnc.guidance.flight_path_angle_deg": ("flight_path_angle_rad", DEG),
    "gnc.guidance.heading_deg": ("heading_rad", DEG),
    "gnc.guidance.gain": ("gain", 1.0),
    "gnc.guidance.rate_limit_deg_s": ("rate_limit_rad_s", DEG),
    "gnc.guidance.roll_gain": ("roll_gain", 1.0),
    "gnc.guidance.roll_rate_limit_deg_s": ("roll_rate_limit_rad_s", DEG),
    "gnc.guidance.integrator_gain.0": ("integrator_gain.x", 1.0),
    "gnc.guidance.integrator_gain.1": ("integrator_gain.y", 1.0),
    "gnc.guidance.integrator_gain.2": ("integrator_gain.z", 1.0),
    "gnc.guidance.wind_gain": ("wind_gain", 1.0),
    "gnc.guidance.wind_time_constant_s": ("wind_time_constant_s", 1.0),
}
"""[gnc.guidance]'s continuous numbers a flight can take as values (``with_guidance``): path -> (the
``GuidanceParams`` field, a Vec3's component after a dot; the factor from the config's unit to SI)."""


def with_guidance(params: FlightParams, values: Mapping) -> FlightParams:
    """``params`` with the guidance numbers of ``values`` (``GUIDANCE_NUMBERS``' paths -> values in the config's
    units, traced or not) in place of the campaign's: what ``rocketmc tune`` adjusts and ``sensitivities --wrt``
    differentiates. The campaign's own flights read them as constants (``guidance_params``)."""
    changes: dict = {}
    for path, value in values.items():
        field, factor = GUIDANCE_NUMBERS[path]
        name, _, component = field.partition(".")
        scaled = value * factor
        if component:
            vector = changes.get(name, getattr(params.gnc.guidance, name))
            changes[name] = vector._replace(**{component: scaled})
        else:
            changes[name] = scaled
    guidance = dataclasses.replace(params.gnc.guidance, **changes)
    return dataclasses.replace(params, gnc=dataclasses.replace(params.gnc, guidance=guidance))


AIRBRAKE_NUMBERS = {
    "airbrakes.gain_per_m_s": ("gain_per_m_s", "prediction"),
    "airbrakes.reference.kp_n_s_per_m": ("kp_n_s_per_m", "reference_pi"),
    "airbrakes.reference.ki_n_per_m": ("ki_n_per_m", "reference_pi"),
}
"""[airbrakes]' controller gains a flight can take as values (``with_airbrakes``): path -> (the field of
``AirbrakeParams``, or of its ``ReferencePI`` for the reference-trajectory PI; the law that has it), in SI."""


def airbrake_numbers(campaign: Campaign) -> dict[str, float]:
    """The gains the campaign's air brakes fly (designed or given) by ``AIRBRAKE_NUMBERS``' path, those of its law; none
    without brakes."""
    brakes = campaign.airbrakes
    if brakes is None:
        return {}
    law = campaign.config.airbrakes.controller
    holder = brakes if brakes.reference is None else brakes.reference
    return {path: float(getattr(holder, field)) for path, (field, of) in AIRBRAKE_NUMBERS.items() if of == law}


def with_airbrakes(params: FlightParams, values: Mapping) -> FlightParams:
    """``params`` with the brakes' gains of ``values`` (``airbrake_numbers``' paths -> values, traced or not) in place
    of the campaign's: what ``rocketmc tune`` adjusts and ``sensitivities --wrt`` differentiates."""
    brakes = params.airbrakes
    changes = {AIRBRAKE_NUMBERS[path][0]: value for path, value in values.items()}
    brakes = (dataclasses.replace(brakes, **changes) if brakes.reference is None else
              dataclasses.replace(brakes, reference=dataclasses.replace(brakes.reference, **changes)))  # fmt: skip
    return dataclasses.replace(params, airbrakes=brakes)


def nominal_rail(campaign: Campaign) -> tuple[Quat, Vec3]:
    """What the avionics know of the launch: the campaign's nominal rail (its configured elevation and azimuth, not a
    realization's draw), its attitude (body → NED) and the nominal rocket's CG at rest on it [m, NED]."""
    airframe = airframe_params(campaign.config, campaign.thrust_time_s, campaign.thrust_n, campaign.aero,
                               campaign.wind_profile, campaign.weather, campaign.nominal)  # fmt: skip
    return airframe.launch.q_nb0, rail_start_n(airframe)


def filter_params(campaign: Campaign) -> FilterParams:
    """The navigation filters from the campaign's [gnc.filters] (fixed per campaign; its defaults without a [gnc]
    section), in SI; the reference field of the site's geomagnetic model (``field_model``, by default the
    environment's) and its gradient along NED [T, T/m]."""
    config = campaign.config
    f, site = (FiltersConfig() if config.gnc is None else config.gnc.filters), config.site
    a, p = f.attitude, f.position
    model = a.field_model or config.environment.magnetic_field.model
    with jax.ensure_compile_time_eval():  # the site's numbers: constants of the flight, even under jit
        field_t, gradient = (site_field_gradient(site.latitude_deg, site.longitude_deg, site.altitude_m)
                             if model == "dipole" else _igrf(config))  # fmt: skip
    return FilterParams(attitude_tuning(a), position_tuning(p), jnp.asarray(field_t), jnp.asarray(gradient), jnp.asarray(p.gnss_after_s),
                        jnp.asarray(level_fraction(config)), 0 if f.initialisation == "rail" else f.pad_samples,
                        f.initialisation == "pad", p.gnss == "horizontal", p.barometer, a.field_gate, p.gnss_gate,
                        p.altitude_gate)  # fmt: skip


def attitude_tuning(a: AttitudeFilterConfig) -> AttitudeTuning:
    """The MEKF's tuning from [gnc.filters.attitude], in SI."""
    rad = lambda deg: jnp.asarray(math.radians(deg))  # noqa: E731
    return AttitudeTuning(rad(a.gyro_noise_deg_s), rad(a.bias_walk_deg_s2), jnp.asarray(a.field_direction_std),
                          rad(a.initial_attitude_std_deg), rad(a.initial_bias_std_deg_s))  # fmt: skip


def position_tuning(p: PositionFilterConfig) -> PositionTuning:
    """The position/velocity filter's tuning from [gnc.filters.position], in SI."""
    return PositionTuning(
        jnp.asarray(p.position_noise_m), jnp.asarray(p.velocity_noise_mps), Vec3(*map(jnp.asarray, p.gnss_position_std_m)),
        Vec3(*map(jnp.asarray, p.gnss_velocity_std_mps)), jnp.asarray(p.altitude_std_m),
        jnp.asarray(p.initial_position_std_m), jnp.asarray(p.initial_velocity_std_mps),
    )  # fmt: skip


def level_fraction(config) -> float:
    """How far the pad's levelling turns the nominal rail's tilt toward the accelerometer's [-]: the minimum-variance
    weight σ_rail²/(σ_rail² + σ_accel²) of ``gnc.filters.rail_tilt_std_deg`` against the accelerometer's tilt error,
    its bias spread over g0 and its misalignment spread (RSS of the largest axis's; 0 for a truth-only one); 1
    without a rail std or without [avionics]."""
    rail_deg = None if config.gnc is None else config.gnc.filters.rail_tilt_std_deg
    if rail_deg is None or config.avionics is None:
        return 1.0
    accel = config.avionics.accelerometer
    accel_deg = 0.0 if accel.truth_only else math.hypot(math.degrees(max(accel.bias_std) / G0), accel.misalignment_std_deg)
    total = rail_deg**2 + accel_deg**2
    return 1.0 if total == 0.0 else rail_deg**2 / total


SENSOR_UNITS = {"accelerometer": 1.0, "gyroscope": math.pi / 180.0, "magnetometer": 1e-6, "barometer": 1.0,
                "canard_feedback": math.pi / 180.0}  # fmt: skip
"""Each channel's config unit in SI: m/s², deg/s → rad/s, µT → T, Pa, deg → rad (docs/sensors.md)."""


def _rotation(yaw, pitch, roll):
    """The (3, 3) matrix from a frame to one turned by the 3-2-1 angles [rad] about z, y, x (vectors' new
    components: the rows are the new axes in the old frame)."""
    q = Quat.from_euler(yaw, pitch, roll)
    return jnp.stack([q.rotate_inverse(Vec3(*e)).to_array() for e in jnp.eye(3)], axis=1)


def _channel(campaign: Campaign, v: Mapping, sensor: str) -> Channel:
    """The error model of ``sensor``'s channel from the (possibly drawn) values ``v``, in SI."""
    config = campaign.config
    c = getattr(config.avionics, sensor)
    path, unit, n = f"avionics.{sensor}", SENSOR_UNITS[sensor], len(c.bias)

    def drawn(field: str) -> bool:  # not zero in some flight: an error that is zero in all costs nothing (None)
        return _configured(config, f"{path}.{field}") != 0.0 or f"{path}.{field}" in config.dispersions

    rate, density = c.rate_hz, c.noise_density is not None
    white = noise_per_sample(v[f"{path}.noise_density"], rate) if density else v[f"{path}.noise_std"]
    mounted = hasattr(c, "cross_axis")
    errors = [f"scale_factor.{i}" for i in range(n)] + (
        [f"cross_axis.{i}" for i in range(6)] + [f"misalignment_deg.{i}" for i in range(3)] if mounted else [])
    gain = jnp.diag(1.0 + _vector(v, f"{path}.scale_factor", n)) if any(map(drawn, errors)) else None
    shaking = [f"vibration_per_kpa.{i}" for i in range(n)]
    if mounted and gain is not None:
        xy, xz, yx, yz, zx, zy = (v[f"{path}.cross_axis.{i}"] for i in range(6))
        one = jnp.ones_like(xy)
        coupling = jnp.stack([jnp.stack([one, xy, xz]), jnp.stack([yx, one, yz]), jnp.stack([zx, zy, one])])
        gain = gain @ coupling @ _rotation(*jnp.deg2rad(_vector(v, f"{path}.misalignment_deg", 3)))
    return Channel(
        gain=gain,
        bias=_vector(v, f"{path}.bias", n) * unit,
        noise_std=white * unit if drawn("noise_density" if density else "noise_std") else None,
        walk_std=walk_per_sample(v[f"{path}.bias_walk"], rate) * unit if drawn("bias_walk") else None,
        low=v[f"{path}.range.0"] * unit,
        high=v[f"{path}.range.1"] * unit,
        lsb=v[f"{path}.lsb"] * unit,
        vibration=_vector(v, f"{path}.vibration_per_kpa", n) * unit / 1000.0 if any(map(drawn, shaking)) else None,
        every=sample_period_ticks(config, sensor),
        delay=sensor_ticks(config, c.latency_s, f"{path}.latency_s"),
        ideal=c.truth_only,
    )


def _avionics(campaign: Campaign, v: Mapping, key, body_x, n_canards: int) -> Avionics | None:
    """The sensors from the campaign's [avionics] (None without it), from the (possibly drawn) values ``v``; the
    keys of their noise streams ``avionics.<sensor>`` from the realization's ``key``; ``body_x``: a position
    in the rocket's coordinates (dotted path) to body-frame x [m]; no canard feedback without canards."""
    config = campaign.config.avionics
    if config is None:
        return None

    def mounted(sensor: str) -> Mounted:
        path = f"avionics.{sensor}"
        rotation = _rotation(*jnp.deg2rad(_vector(v, f"{path}.mounting_deg", 3)))
        position = jnp.zeros(3)
        if getattr(config, sensor).position_m is not None:
            position = jnp.stack([body_x(f"{path}.position_m.0"), v[f"{path}.position_m.1"], v[f"{path}.position_m.2"]])
        return Mounted(_channel(campaign, v, sensor), rotation, position)

    m, g = "avionics.magnetometer", "avionics.gnss"
    magnetometer = Magnetometer(mounted("magnetometer"), *_true_field(campaign, v), _soft_iron(campaign, v),
                                1e-6 * _vector(v, f"{m}.hard_iron", 3))  # fmt: skip
    fix_noise = jnp.concatenate([_vector(v, f"{g}.position_noise_m", 3), _vector(v, f"{g}.velocity_noise_mps", 3)])
    receiver = Channel(
        gain=None, bias=jnp.zeros(6), noise_std=fix_noise, walk_std=None, low=jnp.asarray(-jnp.inf),
        high=jnp.asarray(jnp.inf), lsb=jnp.asarray(0.0), every=sample_period_ticks(campaign.config, "gnss"),
        delay=sensor_ticks(campaign.config, config.gnss.latency_s, f"{g}.latency_s"), ideal=config.gnss.truth_only,
    )  # fmt: skip
    gnss = Gnss(receiver, _vector(v, f"{g}.sinusoid_amplitude_m", 3), v[f"{g}.sinusoid_frequency_hz"],
                jnp.deg2rad(_vector(v, f"{g}.sinusoid_phase_deg", 3)), v[f"{g}.first_fix_s"])  # fmt: skip
    keys = {name: stream_key(key, f"avionics.{name}") for name in SENSORS}
    return Avionics(mounted("accelerometer"), mounted("gyroscope"), magnetometer, _channel(campaign, v, "barometer"),
                    gnss, _channel(campaign, v, "canard_feedback") if n_canards else None, keys)  # fmt: skip


def _igrf(config) -> tuple:
    """The IGRF-14 field at the site on the campaign's date and its gradient along NED [T, T/m] (numpy)."""
    site, date = config.site, datetime.date.fromisoformat(config.environment.magnetic_field.date)
    return igrf_site_field_gradient(site.latitude_deg, site.longitude_deg, site.altitude_m, date)


def _true_field(campaign: Campaign, v: Mapping) -> tuple:
    """The flight's geomagnetic field at the pad [T, NED] and its gradient along NED [T/m] (None: constant, the
    dipole's) from [environment.magnetic_field], its anomaly from the (possibly drawn) values ``v``."""
    config, f = campaign.config, "environment.magnetic_field.anomaly_nt"
    site = config.site
    with jax.ensure_compile_time_eval():  # the site's numbers: constants of the flight, even under jit
        if config.environment.magnetic_field.model == "dipole":
            field_t, gradient = 1e-9 * site_field_ned(site.latitude_deg, site.longitude_deg, site.altitude_m), None
        else:
            field_t, gradient = _igrf(config)
    field_t = jnp.asarray(field_t)
    if any(_configured(config, f"{f}.{i}") != 0.0 or f"{f}.{i}" in config.dispersions for i in range(3)):
        field_t = field_t + 1e-9 * _vector(v, f, 3)
    return field_t, None if gradient is None else jnp.asarray(gradient)


def _soft_iron(campaign: Campaign, v: Mapping):
    """The magnetometer's soft-iron matrix (3, 3) [-] from the (possibly drawn) values ``v``; with a per-flight
    spread, the lower triangle follows the upper's draws (``schema.SPREAD_ELEMENTS``): a symmetric perturbation of
    the configured matrix."""
    path = "avionics.magnetometer.soft_iron"
    matrix = _vector(v, path, 9).reshape(3, 3)
    if campaign.config.avionics.magnetometer.soft_iron_std == 0.0:
        return matrix
    nominal = jnp.asarray([campaign.nominal[f"{path}.{i}"] for i in range(9)]).reshape(3, 3)
    return matrix + jnp.triu(matrix - nominal, 1).T


def _atmosphere(weather: Weather | None) -> AtmosphereProfile | None:
    """The day's atmosphere of [environment.atmosphere] (None without: the ISA)."""
    if weather is None:
        return None
    return AtmosphereProfile(jnp.asarray(weather.geopotential_height_m), jnp.asarray(weather.temperature_k),
                             jnp.log(jnp.asarray(weather.pressure_pa)))  # fmt: skip


def _wind(cfg: CampaignConfig, wind_profile, weather: Weather | None, v: Mapping):
    """The mean wind of the campaign's model from the (possibly drawn) values ``v``: the day's ``weather``
    ([environment.atmosphere]) when there is one (its levels' geometric heights above the pad, turned by
    wind_rotation_deg and scaled by wind_scale), else [environment.wind]'s (``wind_profile``: its measured profile)."""
    a = "environment.atmosphere"
    if weather is not None:
        height = geometric_altitude(weather.geopotential_height_m) - cfg.site.altitude_m
        return WindProfile.from_speed_direction(height, jnp.asarray(weather.speed_mps) * v[f"{a}.wind_scale"],
                                                weather.from_rad + jnp.deg2rad(v[f"{a}.wind_rotation_deg"]))  # fmt: skip
    config, w = cfg.environment.wind, "environment.wind"
    if config.model == "layers":
        n = len(config.layers)
        bottoms = [jnp.zeros(())]
        for i in range(n - 1):
            bottoms.append(bottoms[-1] + v[f"{w}.layers.{i}.thickness_m"])
        speeds, directions = _vector(v, f"{w}.layers", n, ".speed_mps"), _vector(v, f"{w}.layers", n, ".from_deg")
        return WindLayers.from_speed_direction(jnp.stack(bottoms), speeds, jnp.deg2rad(directions))
    if config.model == "constant":
        speed, direction = v[f"{w}.speed_mps"][None], jnp.deg2rad(v[f"{w}.from_deg"])[None]
        return WindLayers.from_speed_direction(jnp.zeros(1), speed, direction)
    if config.model == "power_law":
        return PowerLawWind(
            v[f"{w}.speed_mps"], v[f"{w}.reference_height_m"], v[f"{w}.exponent"], jnp.deg2rad(v[f"{w}.from_deg"])
        )
    altitude, speed, from_rad = wind_profile
    return WindProfile.from_speed_direction(altitude, jnp.asarray(speed) * v[f"{w}.speed_scale"], from_rad)


def _turbulence(cfg: CampaignConfig, v: Mapping, key) -> Turbulence | None:
    if cfg.environment.turbulence is None:
        return None
    t = "environment.turbulence"
    return Turbulence.from_severity(v[f"{t}.severity"], stream_key(key, t), v.get(f"{t}.w20_mps"))


def nominal_params(campaign: Campaign) -> FlightParams:
    """FlightParams of the nominal (undispersed) flight; its turbulence noise is realization 0's."""
    return flight_params(campaign, campaign.nominal, realization_key(jax.random.key(campaign.config.seed), 0))


def sensor_ticks(config: CampaignConfig, seconds: float, field: str) -> int:
    """``seconds`` as a whole number of GNC periods (``simulation.control_dt_s``); ConfigError naming
    ``field`` if it is not one."""
    dt = config.simulation.control_dt_s
    ticks = round(seconds / dt)
    if abs(ticks * dt - seconds) > 1e-9 * max(seconds, dt):
        raise ConfigError(f"{field}: {seconds:g} s is not a whole number of GNC periods "
                          f"(simulation.control_dt_s = {dt:g} s)")  # fmt: skip
    return ticks


def sample_period_ticks(config: CampaignConfig, sensor: str) -> int:
    """The GNC periods between two samples of ``sensor``; ConfigError unless its rate divides the GNC rate into a
    divisor of ``SimSettings.block_steps`` (a sensor's noise is drawn a block at a time, for its samples only)."""
    dt, rate = config.simulation.control_dt_s, getattr(config.avionics, sensor).rate_hz
    every = round(1.0 / (rate * dt))
    if every < 1 or abs(every * rate * dt - 1.0) > 1e-9 or SimSettings.block_steps % every:
        rates = ", ".join(f"{1 / (k * dt):g}" for k in (1, 2, 5, 10))
        raise ConfigError(f"avionics.{sensor}.rate_hz: {rate:g} Hz does not divide the GNC rate ({1 / dt:g} Hz, "
                          f"simulation.control_dt_s = {dt:g} s) into a divisor of {SimSettings.block_steps} GNC "
                          f"periods (the noise blocks): e.g. {rates} Hz")  # fmt: skip
    return every
