"""Campaign files (TOML): schema, validation and loading, on the host.

Errors are ``ConfigError`` with one line that names the field (dotted path), what was expected and
what was found; the CLI prints it and exits with code 2.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import tomllib
from collections.abc import Mapping
from datetime import date, datetime, timezone
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, ValidationInfo, field_validator, model_validator

from ..aero.geometry import NOSE_KINDS, BoatTail, FinSet, Nose, RocketGeometry
from ..aero.io import load_aero
from ..aero.model import LinearAero, TableAero, simplify
from ..aero.sources import BUILTIN_TABLES, build_up_tables, power_on_axial_increment, with_axial_curve, with_canards
from ..aero.tables import AeroTables
from ..dynamics.propulsion import ThrustCurveError, cumulative_impulse, read_thrust_curve
from ..env.atmosphere import G0
from ..env.magnetic import igrf_validity
from ..errors import RocketmcError
from ..gnc.design import Schedule
from ..env.weather import Weather, WeatherError, read_weather
from ..env.wind import POWER_LAW_FLOOR_M, read_wind_profile
from ..math.table import Table
from ..sensors.parts import load_part, part_names
from ..sim.params import SimSettings

if TYPE_CHECKING:
    from .gains import DesignInputs

DISPERSIBLE_SECTIONS = ("rocket", "launch", "environment", "gnc", "avionics")
FIXED_PER_CAMPAIGN = ("rocket.reference_point_m", "rocket.nose_position_m", "rocket.geometry.", "rocket.aero.")
"""Numbers that define the body frame or build the aerodynamic tables once per campaign: not
dispersible, except those of ``DISPERSIBLE_AERO``."""
DISPERSIBLE_AERO = ("rocket.aero.drag_scale", "rocket.aero.cl0", "rocket.aero.linear.")
FIXED_GNC = ("gnc.guidance.", "gnc.control.", "gnc.filters.")
"""Guidance, the gain design and the navigation filters' tuning, set once per campaign (the gains are designed
when it loads): not dispersible; the servos (``gnc.servo``) are."""
FIXED_AVIONICS = ("rate_hz", "latency_s", *("_std", "_std_deg"))
"""Ends of the avionics' numbers that are not dispersible: the schedule (rate, latency) is set per campaign,
and the per-flight spreads are dispersions themselves."""
ISP_TOLERANCE = 0.02  # relative mismatch allowed between isp_s and the curve's impulse per propellant mass

# Physical ranges (docs/conventions.md, Campaign validation): every number is finite and within these, generous
# for any student or amateur rocket, so that a typo or a unit slip is refused here instead of flying a campaign
# of failed flights.
MIN_MASS_KG = 1e-3  # 1 g, below any model rocket: the mass divides every force
MAX_MASS_KG = 5000.0  # a few tonnes: the heaviest amateur rockets weigh under 2 t
MIN_LENGTH_M = 1e-4  # 0.1 mm, thinner than any fin
MAX_LENGTH_M = 100.0  # lengths and positions: amateur rockets are under 20 m long
MAX_DIAMETER_M = 10.0  # diameters: amateur rockets are under 1 m across
MAX_AREA_M2 = 1000.0  # canopy and reference areas: the largest cargo canopies have ~700 m²
MIN_INERTIA_KGM2 = 1e-9  # a 1 g rod 5 mm across has an axial inertia of 3·10⁻⁹ kg·m²; it divides every moment
MAX_INERTIA_KGM2 = 1e7  # a 5 t, 100 m rod about its middle has m·L²/12 ≈ 4·10⁶ kg·m²
MAX_ISP_S = 500.0  # above any chemical motor (hydrogen-oxygen in vacuum: ~450 s)
MAX_SCALE = 10.0  # multipliers of a measured curve (thrust, drag, wind): ×10 is a unit slip, not a dispersion
MAX_DELAY_S = 60.0  # ignition delay, parachute delay and opening time: longer is a flight without that event
MAX_FLIGHT_TIME_S = 3600.0  # a descent under a main canopy from 10 km takes under ~2000 s
MAX_ALTITUDE_M = 100_000.0  # heights above ground: the standard atmosphere ends at 47 km (status 4 above)
MAX_WIND_MPS = 150.0  # above the strongest jet-stream winds measured (~110 m/s)
MAX_MACH = 25.0  # Mach axes: beyond any sounding rocket
MAX_DRAG_COEFFICIENT = 10.0  # axial-force and canopy coefficients: a flat plate's is 1.2, a canopy's 0.8-2.2
MAX_COEFFICIENT = 1000.0  # static derivatives and offsets [per rad]: 40 × Lynx's CNα (24 per rad)
MAX_DAMPING_COEFFICIENT = 1e5  # damping derivatives [per ω·d/(2V)]: 50 × Lynx's Cmq (−1813)
MIN_CONTROL_DT_S = 1e-3  # 1 kHz, the fastest flight-computer loops; a flight is max_time_s/control_dt_s periods
MAX_REALIZATIONS = 10**8  # ~20 float64 outputs per flight: 10⁸ flights fill ~16 GB
MAX_NAME_LENGTH = 128  # a campaign's name is a label, printed and stored in result files
MAX_SPEED_MPS = 10_000.0  # speeds: Mach 25 (MAX_MACH) is ~8.5 km/s
MAX_SERVO_TIME_CONSTANT_S = 1.0  # a servo slower than 1 s cannot follow a ~10 s guidance window (Lynx: 0.077 s)
MAX_CANARD_LIMIT_DEG = 45.0  # canards stall beyond ~20°: 45° is a unit slip, not a servo
MAX_SERVO_RATE_DEG_S = 10_000.0  # servos slew 60-1000 °/s
MAX_RATE_DEG_S = 3600.0  # commanded body rates: ten turns a second is no guidance
MAX_GUIDANCE_GAIN = 1000.0  # guidance [1/s] and integrator [-] gains: 200 × the thesis's; k·T ≫ 1 oscillates
MAX_SENSOR_VALUE = 1e7  # any sensor's unit (m/s², deg/s, µT, Pa, deg): 1e7 Pa is 100 atmospheres
MAX_SENSOR_LATENCY_S = 1.0  # a sensor later than a second is a logger, not a GNC input
MAX_MISALIGNMENT_DEG = 10.0  # a sensor more than 10° off its mount is mounted elsewhere
MAX_ANOMALY_NT = 100_000.0  # twice the main field: the strongest crustal anomalies (iron ores) reach ~tens of µT
MAX_SOFT_IRON_STD = 0.5  # a soft-iron matrix half off the identity per flight is no calibration
MAX_LENGTH_KM = 100.0  # GNSS errors: 100 km is no fix
MAX_LQ_WEIGHT = 1e12  # LQI weights: only their ratios matter, and the DARE loses accuracy beyond 1e12 apart
DEFAULT_SPEEDS_MPS = [20.0, 30.0, 40.0, 60.0, 80.0, 100.0, 150.0, 200.0, 250.0, 300.0]
DEFAULT_ALTITUDES_M = [0.0, 1000.0, 2000.0]
"""The default design grid [m/s] × [m above the pad]. Lynx's guidance window (1-10 s after liftoff, at
Roccaraso) flies 62-183 m/s and 30-1220 m (``campaign/gains.py``' estimate), from its rail exit at 21 m/s
when it opens at liftoff; the grid adds room for dispersions and winds. Interpolated linearly, these
points give the main gains of Lynx's designs in between within 5 % (closer where the gains vary less
than the ~1/u of K_p below 40 m/s), and within 0.1 % between these altitudes."""
NORMAL_REACH_STD = 6.0
"""An unclipped side of a normal dispersion is checked at mean ± 6·std: a draw beyond has a
probability of ~1e-9."""


class ConfigError(RocketmcError, ValueError):
    """A campaign that cannot be flown; the message is one line naming the field."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)


NonNegative = Annotated[float, Field(ge=0)]
Mass = Annotated[float, Field(ge=MIN_MASS_KG, le=MAX_MASS_KG)]
Position = Annotated[float, Field(ge=-MAX_LENGTH_M, le=MAX_LENGTH_M, description="in the rocket's coordinates [m]")]
Length = Annotated[float, Field(ge=MIN_LENGTH_M, le=MAX_LENGTH_M)]
Diameter = Annotated[float, Field(ge=MIN_LENGTH_M, le=MAX_DIAMETER_M)]
Area = Annotated[float, Field(gt=0, le=MAX_AREA_M2)]
Inertia = Annotated[float, Field(ge=MIN_INERTIA_KGM2, le=MAX_INERTIA_KGM2)]
Scale = Annotated[float, Field(gt=0, le=MAX_SCALE)]
Delay = Annotated[float, Field(ge=0, le=MAX_DELAY_S)]
Height = Annotated[float, Field(gt=0, le=MAX_ALTITUDE_M)]
WindSpeed = Annotated[float, Field(ge=0, le=MAX_WIND_MPS)]
Direction = Annotated[float, Field(ge=-360, le=720, description="[deg], clockwise; −360 to 720 accepted")]
Mach = Annotated[float, Field(ge=0, le=MAX_MACH)]
DragCoefficient = Annotated[float, Field(ge=0, le=MAX_DRAG_COEFFICIENT)]
Coefficient = Annotated[float, Field(ge=-MAX_COEFFICIENT, le=MAX_COEFFICIENT)]
DampingCoefficient = Annotated[float, Field(ge=-MAX_DAMPING_COEFFICIENT, le=MAX_DAMPING_COEFFICIENT)]
Damping = Annotated[float, Field(ge=-MAX_DAMPING_COEFFICIENT, le=0)]


class MotorConfig(_Strict):
    """Solid motor; positions in the rocket's coordinates [m]."""

    thrust_curve: str = Field(description="RASP .eng or CSV (time s, thrust N); built-in name or path")
    propellant_mass_kg: Mass = Field(description="propellant mass at ignition, all of it burnt by the curve's end")
    isp_s: float | None = Field(
        None, gt=0, le=MAX_ISP_S, description="checked against the curve's impulse / propellant"
    )
    ignition_delay_s: Delay = Field(0.0, description="ignition after the start of the simulation, on the rail")
    thrust_scale: Scale = Field(1.0, description="multiplies the thrust curve (the burn time unchanged)")
    nozzle_m: Position = Field(description="the nozzle exit, in the rocket's coordinates [m]")
    grain_outer_diameter_m: Diameter = Field(description="the propellant grain's outer diameter (burning outward)")
    grain_inner_diameter_m: float = Field(ge=0, le=MAX_DIAMETER_M, description="the grain's initial core diameter")
    grain_length_m: Length = Field(description="the grain's length along the axis")
    grain_center_m: Position | None = Field(None, description="default: the grain ends at the nozzle exit")
    dry_mass_kg: float = Field(0.0, ge=0, le=MAX_MASS_KG,
                               description="casing, nozzle, closures: 0 if the rocket's dry mass has them")
    dry_inertia_kgm2: list[Annotated[float, Field(ge=0, le=MAX_INERTIA_KGM2)]] = Field(
        [0.0, 0.0], min_length=2, max_length=2, description="[axial, transverse] about the motor's dry CG"
    )
    dry_cg_m: Position | None = Field(None, description="default: the grain centre")

    @model_validator(mode="after")
    def _core_inside_grain(self):
        if self.grain_inner_diameter_m >= self.grain_outer_diameter_m:
            raise ValueError("grain_inner_diameter_m must be smaller than grain_outer_diameter_m")
        return self


def _mach_curve(mach: list[float], values: list[float], names: str) -> None:
    if len(mach) != len(values):
        raise ValueError(f"{names} must have the same length")
    if np.any(np.diff(mach) <= 0):
        raise ValueError(f"{names.split(' and ')[-1]} must be strictly increasing")


class LinearCoefficientsConfig(_Strict):
    """Linear coefficients per rad about the reference point, per virtual canard command
    u = (yaw, pitch, roll, squeeze) as in the thesis (aero/model.py, ``from_virtual_commands``);
    damping per ω·d/(2V)."""

    reference_area_m2: Area = Field(description="S of the coefficients")
    reference_length_m: Length = Field(description="d of the coefficients (moments, rates)")
    ca0_mach: list[Mach] = Field(min_length=2, description="Mach numbers of ca0, increasing")
    ca0: list[DragCoefficient] = Field(min_length=2, description="zero-lift axial force at ca0_mach")
    ca_u: list[Coefficient] = Field([0.0, 0.0, 0.0, 0.0], min_length=4, max_length=4,
                                    description="axial force per command squared (yaw, pitch, roll, squeeze) [per rad²]")
    cn_alpha: Coefficient = Field(description="normal-force slope CNα [per rad]")
    cn_delta: Coefficient = Field(0.0, description="normal force per pitch (and yaw) command [per rad]")
    cm_alpha: Coefficient = Field(description="pitching-moment slope Cmα about the reference point [per rad]")
    cm_delta: Coefficient = Field(0.0, description="pitching moment per pitch (and yaw) command [per rad]")
    cl_delta: Coefficient = Field(0.0, description="rolling moment per roll command [per rad]")
    cy_r: DampingCoefficient = Field(0.0, description="side force per yaw rate ω·d/(2V)")
    cn_q: DampingCoefficient = Field(0.0, description="normal force per pitch rate ω·d/(2V)")
    cl_p: Damping = Field(0.0, description="roll damping per roll rate ω·d/(2V)")
    cm_q: Damping = Field(0.0, description="pitch damping per pitch rate ω·d/(2V)")

    @model_validator(mode="after")
    def _mach_table(self):
        _mach_curve(self.ca0_mach, self.ca0, "ca0 and ca0_mach")
        return self


class AeroConfig(_Strict):
    """Aerodynamics: which model flies and where its tables come from."""

    model: Literal["interpolated", "simplified", "linear"] = Field(
        "interpolated",
        description="interpolated: the tables; simplified: their linearisation at zero angles; "
        "linear: the coefficients of [aero.linear]",
    )
    tables: str = Field(
        "buildup",
        description="'buildup' (from [rocket.geometry]), a built-in table name, or a .h5/.csv/.mat file",
    )
    reference_area_m2: Area | None = Field(None, description="for table files that do not state it")
    reference_length_m: Length | None = Field(None, description="d, for table files that do not state it")
    moment_reference_m: Position | None = Field(None, description="for table files that do not state it")
    cd_mach: list[Mach] | None = Field(None, description="Cd-vs-Mach curve replacing the zero-lift axial force")
    cd: list[DragCoefficient] | None = Field(None, description="Cd at cd_mach (with the motor off)")
    cd_power_on: list[DragCoefficient] | None = Field(None, description="Cd at cd_mach while the motor burns")
    drag_scale: Scale = Field(1.0, description="multiplies the axial force (dispersible)")
    cl0: Coefficient = Field(0.0, description="rolling-moment offset (fin misalignment)")
    linear: LinearCoefficientsConfig | None = None

    @model_validator(mode="after")
    def _consistent(self):
        if (self.cd_mach is None) != (self.cd is None):
            raise ValueError("cd and cd_mach go together")
        if self.cd is not None:
            _mach_curve(self.cd_mach, self.cd, "cd and cd_mach")
        if self.cd_power_on is not None and (self.cd is None or len(self.cd_power_on) != len(self.cd)):
            raise ValueError("cd_power_on needs cd and cd_mach of the same length")
        if self.model == "linear" and self.linear is None:
            raise ValueError("model = 'linear' needs the coefficients in [rocket.aero.linear]")
        return self


class NoseConfig(_Strict):
    """The nose cone."""

    kind: Literal[NOSE_KINDS] = Field(description="the nose cone's profile")
    length_m: Length = Field(description="from the tip to the shoulder")


class FinSetConfig(_Strict):
    """Trapezoidal panels (aero/geometry.py ``FinSet``); position_m: the root's leading edge."""

    count: int = Field(ge=1, le=8, description="panels, evenly spaced in roll")
    root_chord_m: Length = Field(description="chord along the body")
    tip_chord_m: float = Field(ge=0, le=MAX_LENGTH_M, description="chord at the tip (0: a delta)")
    span_m: Length = Field(description="from the body to the tip")
    sweep_m: Position = Field(0.0, description="the tip's leading edge aft of the root's [m]")
    position_m: Position = Field(description="the root's leading edge, in the rocket's coordinates [m]")
    thickness_m: Length = Field(0.005, description="panel thickness")
    cant_deg: float = Field(0.0, ge=-15, le=15, description="cant angle, positive as a positive deflection")
    first_panel_deg: Direction = Field(0.0, description="roll position of panel 1, 0 up, 90 starboard")


class BoatTailConfig(_Strict):
    length_m: Length = Field(description="along the axis")
    aft_diameter_m: Diameter = Field(description="the diameter at its aft end, below the body's")
    position_m: Position = Field(description="its forward end, in the rocket's coordinates [m]")


class GeometryConfig(_Strict):
    """External shape for the aerodynamic build-up; positions in the rocket's coordinates [m]."""

    body_diameter_m: Diameter = Field(description="the body tube's diameter (the reference length d)")
    length_m: Length = Field(description="from the nose tip to the aft end")
    nose: NoseConfig
    fins: list[FinSetConfig] = []
    canards: FinSetConfig | None = None
    boat_tail: BoatTailConfig | None = None

    @model_validator(mode="after")
    def _nose_on_the_body(self):
        if self.nose.length_m > self.length_m:
            raise ValueError(f"nose.length_m ({self.nose.length_m}) exceeds length_m ({self.length_m}), "
                             "the length from the nose tip to the aft end")  # fmt: skip
        return self

    def to_geometry(self, from_nose=lambda position_m: position_m) -> RocketGeometry:
        """The ``RocketGeometry``; ``from_nose`` maps a position to the distance from the nose tip."""

        def fin_set(f: FinSetConfig) -> FinSet:
            return FinSet(**{**f.model_dump(), "position_m": from_nose(f.position_m)})

        return RocketGeometry(
            self.body_diameter_m,
            self.length_m,
            Nose(**self.nose.model_dump()),
            tuple(fin_set(f) for f in self.fins),
            None if self.canards is None else fin_set(self.canards),
            None if self.boat_tail is None
            else BoatTail(**{**self.boat_tail.model_dump(), "position_m": from_nose(self.boat_tail.position_m)}),
        )


class ParachuteConfig(_Strict):
    """A canopy: opens at apogee, or at deploy_altitude_m above ground after apogee."""

    name: str = Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*$", description="an identifier; names /outputs/<name>_deploy_time_s")
    cd: float = Field(gt=0, le=MAX_DRAG_COEFFICIENT, description="drag coefficient on area_m2")
    area_m2: Area = Field(description="reference area of cd")
    deploy_altitude_m: float | None = Field(None, ge=0, le=MAX_ALTITUDE_M,
                                            description="above the pad, after apogee (none: at apogee)")
    delay_s: Delay = Field(0.0, description="from the trigger to the start of opening")
    opening_time_s: Delay = Field(0.0, description="the drag area grows linearly over it")
    attach_m: Position


class AirbrakesConfig(_Strict):
    """Extra axial-force coefficient ΔCA (on the aerodynamic reference area) of deployed airbrakes as a
    schedule of time since motor ignition [s], linear in between, 0 outside."""

    time_s: list[Annotated[float, Field(ge=0, le=MAX_FLIGHT_TIME_S)]] = Field(
        min_length=2, description="schedule times since motor ignition, increasing"
    )
    delta_ca: list[DragCoefficient] = Field(min_length=2, description="ΔCA at time_s")

    @model_validator(mode="after")
    def _schedule(self):
        if len(self.time_s) != len(self.delta_ca):
            raise ValueError(f"time_s and delta_ca need the same length, got {len(self.time_s)} and {len(self.delta_ca)}")
        if not np.all(np.diff(self.time_s) > 0):
            raise ValueError("time_s must be strictly increasing")
        return self


class RocketConfig(_Strict):
    """The rocket. Positions [m] are coordinates along the axis in ``coordinate_system``:
    ``nose_to_tail`` (positive aft) or ``tail_to_nose`` (positive forward, RocketPy's default),
    from an origin of the user's choice where the nose tip is at ``nose_position_m``."""

    coordinate_system: Literal["nose_to_tail", "tail_to_nose"] = Field(
        "nose_to_tail", description="the direction positions grow in: aft, or toward the nose (RocketPy's)"
    )
    nose_position_m: Position = 0.0
    reference_point_m: Position = Field(description="origin of the body frame and, by default, the moment reference")
    dry_mass_kg: Mass = Field(
        description="the rocket without propellant; the motor's casing included unless rocket.motor.dry_mass_kg gives it apart"
    )
    dry_cg_m: Position
    dry_inertia_kgm2: list[Inertia] = Field(min_length=2, max_length=2, description="[axial, transverse]")
    rear_lug_m: Position
    canopy_roll_damping: Damping = Field(-5.0, description="roll damping Clp under an open canopy, per ω·d/(2V)")
    motor: MotorConfig
    aero: AeroConfig = AeroConfig()
    geometry: GeometryConfig | None = None
    parachutes: list[ParachuteConfig] = []
    airbrakes: AirbrakesConfig | None = None

    @property
    def position_sign(self) -> float:
        """+1 if positions grow aft, −1 if they grow toward the nose."""
        return 1.0 if self.coordinate_system == "nose_to_tail" else -1.0

    def from_nose(self, position_m: float) -> float:
        """Distance from the nose tip, positive aft, of a position in the rocket's coordinates [m]."""
        return self.position_sign * (position_m - self.nose_position_m)

    @model_validator(mode="after")
    def _unique_names(self):
        names = [p.name for p in self.parachutes]
        if len(set(names)) != len(names):
            raise ValueError(f"parachute names must be unique, got {names}")
        if self.aero.model != "linear" and self.aero.tables == "buildup" and self.geometry is None:
            raise ValueError("aero.tables = 'buildup' needs the rocket's [rocket.geometry]")
        return self


class SiteConfig(_Strict):
    """The launch site: the pad's position (the NED origin)."""

    name: str = Field("", description="a label")
    latitude_deg: float = Field(ge=-90, le=90, description="the pad's geodetic latitude, north positive")
    longitude_deg: float = Field(ge=-180, le=360, description="the pad's longitude, east positive")
    altitude_m: float = Field(ge=-400, le=30000, description="pad altitude above mean sea level")


class LaunchConfig(_Strict):
    """The launch rail."""

    rail_length_m: Length = Field(description="the rail's length; the rocket leaves when its rear lug passes the end")
    elevation_deg: float = Field(gt=0, le=90, description="rail angle above the horizon")
    azimuth_deg: Direction = Field(description="clockwise from north")


class WindLayerConfig(_Strict):
    """One layer of piecewise constant wind, from the layer below's top (the pad for the first)."""

    speed_mps: WindSpeed = Field(description="horizontal wind speed in the layer")
    from_deg: Direction = Field(description="direction the wind blows from, clockwise from north")
    thickness_m: Height | None = Field(None, description="not needed for the top layer")


WIND_MODEL_FIELDS = {
    "layers": ("layers",),
    "constant": ("speed_mps", "from_deg"),
    "power_law": ("speed_mps", "from_deg", "reference_height_m", "exponent"),
    "profile": ("file", "speed_scale"),
}
"""The keys each wind model reads."""
WIND_DEFAULTS = {"layers": [{"speed_mps": 0.0, "from_deg": 0.0}], "reference_height_m": 10.0, "exponent": 1.0 / 7.0,
                 "speed_scale": 1.0}  # fmt: skip


class WindConfig(_Strict):
    """The mean wind: ``layers`` (piecewise constant, the default), ``constant``, ``power_law``
    (speed at a reference height, V ∝ h^exponent) or ``profile`` (a CSV file of altitude, speed and
    direction, linear in between; ``speed_scale`` multiplies it and can be dispersed)."""

    model: Literal["layers", "constant", "power_law", "profile"] = Field("layers", description="how the mean wind is given")
    layers: list[WindLayerConfig] | None = Field(None, min_length=1, description="the layers, from the pad up")
    speed_mps: WindSpeed | None = Field(None, description="constant wind, or power law at reference_height_m")
    from_deg: Direction | None = Field(None, description="direction the wind blows from")
    reference_height_m: float | None = Field(
        None, ge=POWER_LAW_FLOOR_M, le=MAX_ALTITUDE_M, description="not below the height the law is held at"
    )
    exponent: float | None = Field(None, ge=0, le=1, description="power-law exponent (1/7 over open terrain)")
    file: str | None = Field(None, description="CSV: altitude_agl_m (or altitude_msl_m), speed_mps, from_deg")
    speed_scale: float | None = Field(None, ge=0, le=MAX_SCALE, description="multiplies the profile's speeds")

    @model_validator(mode="before")
    @classmethod
    def _defaults_of_model(cls, data):
        if isinstance(data, dict):
            used = WIND_MODEL_FIELDS.get(data.get("model", "layers"), ())
            data = {**{k: v for k, v in WIND_DEFAULTS.items() if k in used}, **data}
        return data

    @model_validator(mode="after")
    def _fields_of_model(self):
        used = WIND_MODEL_FIELDS[self.model]
        for name in {f for fields in WIND_MODEL_FIELDS.values() for f in fields} - set(used):
            if getattr(self, name) is not None:
                raise ValueError(
                    f"'{name}' does not apply to the {self.model!r} wind model (it reads {', '.join(used)})"
                )
        for name in used:
            if getattr(self, name) is None:
                raise ValueError(f"the {self.model!r} wind model needs '{name}'")
        for i, layer in enumerate((self.layers or [])[:-1]):
            if layer.thickness_m is None:
                raise ValueError(f"layers.{i}.thickness_m is required below the top layer")
        return self


class TurbulenceConfig(_Strict):
    """Dryden turbulence (MIL-F-8785C): severity 0 none, 1 light, 2 moderate, 3 severe (the high-altitude
    exceedance curves 10⁻², 10⁻³, 10⁻⁵); w20_mps the wind at 20 ft for the low-altitude intensities,
    by default 15/30/45 kt from the severity."""

    severity: float = Field(ge=0, le=3, description="0 none, 1 light, 2 moderate, 3 severe")
    w20_mps: WindSpeed | None = Field(None, description="wind at 20 ft for the low-altitude intensities")


class AtmosphereConfig(_Strict):
    """The day's atmosphere from a file (docs/weather.md): its temperature, pressure and wind against height give
    every flight's density, speed of sound, pressure and mean wind, in place of the standard atmosphere and of
    [environment.wind]; the day's wind profile can be turned and scaled (both dispersible)."""

    file: str = Field(description="a sounding (University of Wyoming text list, or CSV) or an ERA5/GFS netCDF file "
                                  "on pressure levels, beside the campaign or in the package's data/weather")  # fmt: skip
    time_utc: str | None = Field(None, description="netCDF only, required there: the launch time in UTC, ISO 8601 "
                                                   "('2023-10-13T12:00:00Z'); the file's nearest time is used")  # fmt: skip
    grid: Literal["bilinear", "nearest"] | None = Field(
        None, description="netCDF only: interpolate between the four grid points around the site (the default) or "
                          "take the nearest one")  # fmt: skip
    wind_rotation_deg: float = Field(0.0, ge=-360, le=360, description="turns the day's wind clockwise: added to "
                                                                       "every level's from-direction [deg]")  # fmt: skip
    wind_scale: float = Field(1.0, ge=0, le=MAX_SCALE, description="multiplies every level's wind speed")

    @field_validator("time_utc")
    @classmethod
    def _utc(cls, text: str | None) -> str | None:
        if text is None:
            return None
        try:
            time = datetime.fromisoformat(text)
        except ValueError:
            raise ValueError("expected an ISO 8601 date and time, e.g. '2023-10-13T12:00:00Z'") from None
        if time.utcoffset() != timezone.utc.utcoffset(None):
            raise ValueError("expected a time in UTC, ending in 'Z' (or '+00:00')")
        return text


class MagneticFieldConfig(_Strict):
    """The geomagnetic field the magnetometer flies in (docs/sensors.md): the full IGRF-14 at 0 h UTC of ``date``,
    with its gradient over the flight ("igrf"), or the IGRF-13 dipole at its 2020.0 epoch, constant at the pad's
    value ("dipole", the thesis's); plus a constant local anomaly (the site's crustal field and the day's
    variation, which the filters do not know), dispersible per axis."""

    model: Literal["igrf", "dipole"] = Field("igrf", description="the full IGRF-14, or the thesis's IGRF-13 dipole")
    date: str = Field("2025-01-01", description="the flight's date for the IGRF-14, ISO 8601 ('2025-09-18'), "
                                                "1900-01-01 to 2030-01-01")  # fmt: skip
    anomaly_nt: list[Annotated[float, Field(ge=-MAX_ANOMALY_NT, le=MAX_ANOMALY_NT)]] = Field(
        [0.0, 0.0, 0.0], min_length=3, max_length=3, description="a constant field added to the model's, N, E, D [nT]"
    )

    @field_validator("date", mode="before")
    @classmethod
    def _iso_date(cls, value):
        """A TOML date (``date = 2025-09-18``) as its ISO text."""
        return value.isoformat() if isinstance(value, date) else value

    @field_validator("date")
    @classmethod
    def _igrf_dates(cls, text: str) -> str:
        try:
            day = date.fromisoformat(text)
        except ValueError:
            raise ValueError("expected an ISO 8601 date, e.g. '2025-09-18'") from None
        first, last = igrf_validity()
        if not first <= day <= last:
            raise ValueError(f"the IGRF-14 covers {first.isoformat()} to {last.isoformat()}, got {text}")
        return text


class EnvironmentConfig(_Strict):
    """The air the rocket flies through: mean wind and turbulence; the geomagnetic field."""

    wind: WindConfig = WindConfig()
    turbulence: TurbulenceConfig | None = None
    atmosphere: AtmosphereConfig | None = Field(
        None, description="the day's atmosphere and wind from a file; None: the standard atmosphere and "
                          "[environment.wind]")  # fmt: skip
    magnetic_field: MagneticFieldConfig = MagneticFieldConfig()

    @model_validator(mode="after")
    def _one_wind(self):
        if self.atmosphere is not None and self.wind != WindConfig():
            raise ValueError("[environment.wind] and [environment.atmosphere] both give the wind: the atmosphere's "
                             "file brings its own (turn it with wind_rotation_deg, scale it with wind_scale); "
                             "remove [environment.wind]")  # fmt: skip
        return self


class Dispersion(_Strict):
    """How one parameter is drawn: normal (mean defaults to the nominal value; optional low/high
    clip the draw), uniform [low, high], or a choice among values (optional weights)."""

    dist: Literal["normal", "uniform", "choice"] = Field(description="the distribution")
    mean: float | None = Field(None, description="normal: its mean (none: the nominal value), in the parameter's unit")
    std: NonNegative | None = Field(None, description="normal: its standard deviation, in the parameter's unit")
    low: float | None = Field(None, description="uniform: the lower end; normal: the clip below")
    high: float | None = Field(None, description="uniform: the upper end; normal: the clip above")
    values: list[float] | None = Field(None, min_length=1, description="choice: the values drawn among")
    weights: list[NonNegative] | None = Field(None, description="choice: relative weights of values (none: equal)")

    @model_validator(mode="after")
    def _parameters(self):
        need = {"normal": ("std",), "uniform": ("low", "high"), "choice": ("values",)}[self.dist]
        allowed = {"normal": {"mean", "std", "low", "high"}, "uniform": {"low", "high"},
                   "choice": {"values", "weights"}}[self.dist]  # fmt: skip
        for name in need:
            if getattr(self, name) is None:
                raise ValueError(f"a {self.dist} dispersion needs '{name}'")
        for name in {"mean", "std", "low", "high", "values", "weights"} - allowed:
            if getattr(self, name) is not None:
                raise ValueError(f"'{name}' does not apply to a {self.dist} dispersion")
        if self.low is not None and self.high is not None and not self.low < self.high:
            raise ValueError(f"low must be below high, got {self.low} and {self.high}")
        if self.weights is not None and (len(self.weights) != len(self.values) or sum(self.weights) <= 0):
            raise ValueError("weights must match values in length and have a positive sum")
        return self


class SimulationConfig(_Strict):
    control_dt_s: float = Field(0.02, ge=MIN_CONTROL_DT_S, le=0.1, description="GNC period")
    substeps: int = Field(1, ge=1, le=100, description="RK4 steps per control period")
    descent_dt_s: float = Field(0.25, gt=0, le=1.0, description="longest period in steady descent under canopy")
    descent_h_omega: float = Field(
        1.0, gt=0, le=2.0, description="largest RK4 step times the body's pendulum rate under canopy (RK4 is stable to 2.8)"
    )
    max_time_s: float = Field(300.0, gt=0, le=MAX_FLIGHT_TIME_S, description="a flight still up by then stops")
    chunk_size: int = Field(1000, ge=1, le=MAX_REALIZATIONS, description="realizations per compiled batch")


class ServoConfig(_Strict):
    """The canard servos (dispersible): first order 1/(τs + 1), output clipped to ±limit_deg, optional
    slew-rate limit, a constant offset per fin δ1..δ4 (mounting error) [deg]."""

    time_constant_s: float = Field(0.0769, gt=0, le=MAX_SERVO_TIME_CONSTANT_S, description="τ [s]")
    limit_deg: float = Field(10.0, gt=0, le=MAX_CANARD_LIMIT_DEG, description="deflection limit [deg]")
    rate_limit_deg_s: float | None = Field(None, gt=0, le=MAX_SERVO_RATE_DEG_S, description="None: no slew limit")
    offset_deg: list[Annotated[float, Field(ge=-MAX_CANARD_LIMIT_DEG, le=MAX_CANARD_LIMIT_DEG)]] = Field(
        [0.0, 0.0, 0.0, 0.0], min_length=4, max_length=4, description="per fin δ1..δ4 [deg]"
    )

    @field_validator("offset_deg")
    @classmethod
    def _inside_limit(cls, offsets: list[float], info: ValidationInfo) -> list[float]:
        limit = info.data.get("limit_deg")  # absent if itself invalid
        if limit is not None and max(abs(x) for x in offsets) >= limit:
            raise ValueError(f"each offset must be smaller in magnitude than limit_deg ({limit}), got {offsets}")
        return offsets


class GuidanceConfig(_Strict):
    """Guidance (the thesis's, docs/conventions.md), its gains as defaults; fixed per campaign. The reference parabola
    climbs apogee_m [m] after t0_s [s] from a flight-path angle flight_path_angle_deg above the horizon,
    toward heading_deg (clockwise from north); the roll steers the body z axis toward roll_heading_deg.
    Each of the four left out (None) is derived from the campaign at set-up (``campaign.gains.guidance_reference``):
    the launch azimuth, the nominal rail's elevation (at most 89°), the rail's roll, the nominal flight's climb
    after t0_s (a point-mass estimate). The thesis flew H 1614 m, 84°, roll heading 90°."""

    apogee_m: Height | None = Field(None, description="the reference parabola's climb after t0_s (none: the nominal flight's)")
    t0_s: float = Field(1.5, ge=0, le=MAX_FLIGHT_TIME_S, description="[s since liftoff]")
    flight_path_angle_deg: float | None = Field(
        None, gt=0, lt=90, description="the parabola's angle above the horizon at t0_s (none: the rail's, at most 89)"
    )
    heading_deg: Direction | None = Field(None, description="clockwise from north (none: launch.azimuth_deg)")
    gain: float = Field(5.0, ge=0, le=MAX_GUIDANCE_GAIN, description="k [1/s]")
    rate_limit_deg_s: float = Field(20.0, gt=0, le=MAX_RATE_DEG_S, description="pitch/yaw command, 2-norm")
    min_speed_mps: float = Field(1.0, ge=0, le=MAX_SPEED_MPS, description="no pitch/yaw command below")
    roll_gain: float = Field(1.0, ge=0, le=MAX_GUIDANCE_GAIN, description="[1/s]")
    roll_heading_deg: Direction | None = Field(
        None, description="azimuth the body z axis is steered toward (none: its azimuth on the rail, no roll manoeuvre)"
    )
    roll_rate_limit_deg_s: float = Field(20.0, gt=0, le=MAX_RATE_DEG_S, description="largest commanded roll rate [deg/s]")
    integrator_gain: list[Annotated[float, Field(ge=0, le=MAX_GUIDANCE_GAIN)]] = Field(
        [1.0, 12.0, 12.0], min_length=3, max_length=3, description="k_int of e_p, e_q, e_r [-]"
    )
    window_start_s: float = Field(1.0, ge=0, le=MAX_FLIGHT_TIME_S, description="[s since liftoff]")
    window_end_s: float = Field(10.0, ge=0, le=MAX_FLIGHT_TIME_S, description="[s since liftoff]")

    @field_validator("window_end_s")
    @classmethod
    def _after_start(cls, end: float, info: ValidationInfo) -> float:
        start = info.data.get("window_start_s")
        if start is not None and not start < end:
            raise ValueError(f"the window must end after it starts (window_start_s = {start})")
        return end


class ControlConfig(_Strict):
    """The LQI design (docs/gnc.md §5); fixed per campaign. Weights on the augmented state
    [v, w, p, q, r, u_y, u_p, u_r, e_p, e_q, e_r] and on the three virtual commands; the grid of axial
    speed [m/s] and altitude above the pad [m] the gains are designed on (interpolated in flight)."""

    q_weights: list[Annotated[float, Field(ge=0, le=MAX_LQ_WEIGHT)]] = Field(
        [0.0, 0.0, 0.0, 5.0, 5.0, 0.0, 0.0, 0.0, 10.0, 10.0, 10.0], min_length=11, max_length=11,
        description="Q's diagonal on (v, w, p, q, r, u_y, u_p, u_r, e_p, e_q, e_r)",
    )
    r_weights: list[Annotated[float, Field(gt=0, le=MAX_LQ_WEIGHT)]] = Field(
        [100.0, 100.0, 100.0], min_length=3, max_length=3, description="R's diagonal on the (yaw, pitch, roll) commands"
    )
    speeds_mps: list[Annotated[float, Field(gt=0, le=MAX_SPEED_MPS)]] = Field(
        DEFAULT_SPEEDS_MPS, min_length=2, description="axial speeds of the design grid, increasing"
    )
    altitudes_m: list[Annotated[float, Field(ge=0, le=MAX_ALTITUDE_M)]] = Field(
        DEFAULT_ALTITUDES_M, min_length=1, description="heights above the pad of the design grid, increasing"
    )
    discretisation: Literal["zoh", "euler"] = Field("zoh", description="how the plant is discretised over control_dt_s")
    anti_windup: bool = Field(True, description="conditional integration after a clipped command")

    @field_validator("speeds_mps", "altitudes_m")
    @classmethod
    def _increasing(cls, grid: list[float]) -> list[float]:
        if np.any(np.diff(grid) <= 0):
            raise ValueError(f"the grid must be strictly increasing, got {grid}")
        return grid


ONE_RAD_DEG = math.degrees(1.0)
"""The thesis's initial covariances are identities: 1 rad and 1 rad/s, in the campaign's degrees."""
StdDeviation = Annotated[float, Field(gt=0, le=MAX_SENSOR_VALUE)]
MAX_GATE = 1e4  # a χ² gate of 1e4 on the normalised innovation squared is a 100σ gate: none at all
Gate = Annotated[float | None, Field(gt=0, le=MAX_GATE)]
"""An update's χ² innovation gate [-]: fresh samples whose normalised innovation squared eᵀ S⁻¹ e exceeds it are
rejected (``gnc.navigation.innovation_gate``); None (the default): no gate. E.g. the 99.7 % (3σ) quantiles: 8.8
for 1 degree of freedom, 11.8 for 2, 16.3 for 4, 20.1 for 6."""


class AttitudeFilterConfig(_Strict):
    """The MEKF's tuning (docs/gnc.md §2, ``gnc.attitude_filter``), the thesis's values as defaults: the gyro's white
    noise σ_v [deg/s/√s] and its bias's random walk σ_u [deg/s²/√s] (knobs about 10³ above the thesis gyro's own:
    the filter follows the magnetometer within ~0.3 s), the measured field direction's standard deviation [-] (a
    unit vector; the thesis's R = 4 I), the initial standard deviations of the attitude [deg] and gyro bias
    [deg/s] per axis (the thesis's P0 = I); the magnetometer update's innovation gate (``Gate``, ~2 degrees of
    freedom; the thesis has none)."""

    gyro_noise_deg_s: StdDeviation = Field(60.0, description="σ_v, the gyro's white-noise density the filter assumes")
    bias_walk_deg_s2: StdDeviation = Field(10.0, description="σ_u, the gyro bias's random-walk density assumed")
    field_direction_std: StdDeviation = Field(2.0, description="the measured unit field direction's std (R = σ² I)")
    initial_attitude_std_deg: StdDeviation = Field(ONE_RAD_DEG, description="initial attitude std per axis (P0)")
    initial_bias_std_deg_s: StdDeviation = Field(ONE_RAD_DEG, description="initial gyro-bias std per axis (P0)")
    field_gate: Gate = Field(None, description="the magnetometer update's χ² innovation gate (none: off)")
    field_model: Literal["igrf", "dipole"] | None = Field(
        None, description="the reference field the MEKF carries: the IGRF-14 at environment.magnetic_field.date, or "
                          "the IGRF-13 dipole (the thesis's); none: environment.magnetic_field.model")  # fmt: skip


class PositionFilterConfig(_Strict):
    """The position/velocity Kalman filter's tuning (docs/gnc.md §3, ``gnc.position_filter``), the thesis's values as
    defaults: process noise on position [m/√s] and velocity [m/s/√s]; the GNSS fixes used from ``gnss_after_s``
    (simulation time [s]), on every axis ("all") or north and east only ("horizontal", Skyward's avionics),
    with their standard deviations N, E, D (the thesis's, de-weighted ~100×); the barometric height update (off in
    the thesis) and its standard deviation [m]; the initial standard deviations (the thesis's P0 = I); the GNSS's
    and the barometer's innovation gates (``Gate``; 2 degrees of freedom per GNSS axis, 1 for the barometer; the
    thesis has none)."""

    position_noise_m: StdDeviation = Field(2.0, description="σ_r, process-noise density on the position, per √s")
    velocity_noise_mps: StdDeviation = Field(1.0, description="σ_v, process-noise density on the velocity, per √s")
    gnss: Literal["all", "horizontal"] = Field("all", description="the GNSS axes used: all, or north and east only")
    gnss_after_s: float = Field(10.5, ge=0, le=MAX_FLIGHT_TIME_S, description="GNSS fixes used from this time on")
    gnss_position_std_m: list[StdDeviation] = Field([500.0, 500.0, 700.0], min_length=3, max_length=3,
                                                    description="the GNSS position's std the filter assumes, N, E, D")
    gnss_velocity_std_mps: list[StdDeviation] = Field([50.0, 50.0, 70.0], min_length=3, max_length=3,
                                                      description="the GNSS velocity's std the filter assumes, N, E, D")
    barometer: bool = Field(False, description="the barometric height update")
    # docs/gnc.md's MS5803-class 50 Pa per sample over ρ·g: 4.2 m at sea level, 4.8 m at Lynx's 1.4 km pads (the thesis
    # has no barometer update)
    altitude_std_m: StdDeviation = Field(5.0, description="the barometric height's std")
    initial_position_std_m: StdDeviation = Field(1.0, description="initial position std per axis (P0)")
    initial_velocity_std_mps: StdDeviation = Field(1.0, description="initial velocity std per axis (P0)")
    gnss_gate: Gate = Field(None, description="the GNSS update's χ² innovation gate (none: off)")
    altitude_gate: Gate = Field(None, description="the barometer update's χ² innovation gate (none: off)")


class FiltersConfig(_Strict):
    """The navigation filters of ``navigation = "filters"``: initialised from the launch rail's nominal elevation,
    azimuth and the rocket's roll on it, the gyro bias zero ("rail"); from the mean of ``pad_samples`` accelerometer
    and magnetometer samples on the pad (TRIAD) and the gyroscope's mean rate there as its bias ("pad"); or from the
    nominal rail's attitude levelled by the accelerometer's pad mean (its tilt measured, its azimuth and roll the
    rail's) and the gyroscope's pad mean as its bias ("level"). "pad" and "level" need the motor to light after the
    pad samples (``rocket.motor.ignition_delay_s``). Their tunings."""

    initialisation: Literal["rail", "pad", "level"] = Field(
        "rail", description="the nominal rail's attitude; TRIAD and the gyro's mean (its bias) on the pad; or the "
                            "nominal rail's levelled by the pad's accelerometer, and the gyro's pad mean")  # fmt: skip
    pad_samples: int = Field(500, ge=1, le=100_000, description="GNC ticks on the pad averaged for TRIAD and the "
                                                                 "gyro bias (\"pad\", \"level\")")  # fmt: skip
    rail_tilt_std_deg: float | None = Field(
        None, ge=0, le=MAX_MISALIGNMENT_DEG, description="how far the avionics believe the rail's tilt can be off the "
        "nominal, per axis (\"level\"): the levelling turns the nominal's tilt toward the accelerometer's by "
        "σ_rail²/(σ_rail² + σ_accel²), σ_accel the accelerometer's spread of bias over g0 and of misalignment; none: "
        "all the way")  # fmt: skip
    attitude: AttitudeFilterConfig = AttitudeFilterConfig()
    position: PositionFilterConfig = PositionFilterConfig()


class GncConfig(_Strict):
    """The closed loop: canard servos, guidance, LQI control; navigation "truth" (the true state), "sensors"
    (raw sensors from the avionics bus: gyro rates, GNSS fixes held between fixes, the launch attitude
    propagated by the gyro; needs [avionics]) or "filters" (the MEKF and the position/velocity Kalman filter
    on the bus, ``filters``; needs [avionics])."""

    navigation: Literal["truth", "sensors", "filters"] = Field("truth", description="what the controller reads")
    servo: ServoConfig = ServoConfig()
    guidance: GuidanceConfig = GuidanceConfig()
    control: ControlConfig = ControlConfig()
    filters: FiltersConfig = FiltersConfig()


DEFAULT_PART = "thesis"
"""The part of a sensor no part is named for: the thesis's set provides every sensor (docs/gnc.md §1)."""
SensorValue = Annotated[float, Field(ge=-MAX_SENSOR_VALUE, le=MAX_SENSOR_VALUE)]
SensorSpread = Annotated[float, Field(ge=0, le=MAX_SENSOR_VALUE)]


class _SensorConfig(_Strict):
    """What every sensor has: its part (data/sensors/<part>.toml, whose values the other fields override),
    its sampling rate [Hz] (dividing the GNC rate), its latency [s] (a multiple of the GNC period) and a
    switch to turn its errors off (the truth at each sample, on the same schedule)."""

    part: str = Field(description="data/sensors/<part>.toml, whose values the other keys override")
    truth_only: bool = Field(False, description="no errors: the truth at each sample, on the same schedule")
    rate_hz: float = Field(gt=0, le=1.0 / MIN_CONTROL_DT_S, description="sampling rate, dividing the GNC rate")
    latency_s: float = Field(0.0, ge=0, le=MAX_SENSOR_LATENCY_S, description="a whole number of GNC periods")


class ChannelConfig(_SensorConfig):
    """A channel of ``AXES`` axes in the sensor's unit (docs/sensors.md): range [low, high], LSB (0: no
    quantisation), white noise as a density [unit/√Hz] or per sample [unit] (one of the two), the constant
    bias and the standard deviation of its per-flight draw [unit] per axis, the bias instability as a rate
    random walk [unit/√s], the airframe's vibration per axis (white noise per sample that grows with the
    dynamic pressure [unit per kPa], its variance added to the sensor's own), the scale-factor error [-] per
    axis and its per-flight spread."""

    AXES: ClassVar[int] = 3
    VECTORS: ClassVar[tuple[str, ...]] = ("bias", "bias_std", "scale_factor", "vibration_per_kpa")

    range: list[SensorValue] = Field(min_length=2, max_length=2, description="[low, high], the sensor's unit")
    lsb: SensorSpread = Field(description="quantisation step, the sensor's unit (0: none)")
    noise_density: SensorSpread | None = Field(None, description="white noise density [unit/√Hz] (or noise_std)")
    noise_std: SensorSpread | None = Field(None, description="white noise per sample [unit] (or noise_density)")
    bias: list[SensorValue] = Field(description="constant bias per axis [unit]")
    bias_std: list[SensorSpread] = Field(description="the bias's per-flight spread per axis [unit]")
    bias_walk: SensorSpread = Field(0.0, description="bias instability as a rate random walk [unit/√s]")
    vibration_per_kpa: list[SensorSpread] = Field(
        description="airframe vibration per axis: white noise per sample per kPa of dynamic pressure [unit/kPa]"
    )
    scale_factor: list[Annotated[float, Field(ge=-0.5, le=0.5)]] = Field(description="scale-factor error per axis [-]")
    scale_factor_std: Annotated[float, Field(ge=0, le=0.1)] = Field(0.0, description="its per-flight spread [-]")

    @model_validator(mode="before")
    @classmethod
    def _zero_vectors(cls, data):
        """The per-axis fields default to zeros of the channel's size."""
        if isinstance(data, dict):
            data = {**{name: [0.0] * cls._size(name) for name in cls.VECTORS}, **data}
        return data

    @classmethod
    def _size(cls, name: str) -> int:
        return cls.AXES

    @model_validator(mode="after")
    def _shape(self):
        for name in self.VECTORS:
            if len(getattr(self, name)) != self._size(name):
                raise ValueError(f"{name} must have {self._size(name)} values, got {len(getattr(self, name))}")
        if (self.noise_density is None) == (self.noise_std is None):
            raise ValueError("give the white noise either as noise_density [unit/√Hz] or as noise_std [unit per sample]")
        low, high = self.range
        if not low < high:
            raise ValueError(f"range must be [low, high] with low < high, got {self.range}")
        return self


class RateChannelConfig(ChannelConfig):
    """A channel that measures a signed quantity: its range contains zero."""

    @model_validator(mode="after")
    def _contains_zero(self):
        if not self.range[0] <= 0.0 <= self.range[1]:
            raise ValueError(f"range must contain zero, got {self.range}")
        return self


class InertialConfig(RateChannelConfig):
    """A 3-axis sensor on the airframe: its cross-axis couplings (xy, xz, yx, yz, zx, zy) [-] and their
    per-flight spread, its misalignment (3-2-1 angles about z, y, x [deg], unknown to the avionics) and its
    spread, its mounting (3-2-1 angles from the body frame to the sensor's [deg], known to the avionics), and
    where it sits: [x along the rocket's axis in the rocket's coordinates, y, z across it in the body frame] [m]
    (None: at the reference point)."""

    VECTORS: ClassVar[tuple[str, ...]] = (*ChannelConfig.VECTORS, "cross_axis", "misalignment_deg", "mounting_deg")

    cross_axis: list[Annotated[float, Field(ge=-0.5, le=0.5)]] = Field(
        description="cross-axis couplings xy, xz, yx, yz, zx, zy [-]"
    )
    cross_axis_std: Annotated[float, Field(ge=0, le=0.1)] = Field(0.0, description="their per-flight spread [-]")
    misalignment_deg: list[Annotated[float, Field(ge=-MAX_MISALIGNMENT_DEG, le=MAX_MISALIGNMENT_DEG)]] = Field(
        description="3-2-1 angles about z, y, x, unknown to the avionics"
    )
    misalignment_std_deg: Annotated[float, Field(ge=0, le=MAX_MISALIGNMENT_DEG)] = Field(
        0.0, description="the misalignment's per-flight spread"
    )
    mounting_deg: list[Direction] = Field(description="3-2-1 angles from the body frame to the sensor's, known to the avionics")
    position_m: list[Position] | None = Field(
        None, min_length=3, max_length=3,
        description="x in the rocket's coordinates, y, z in the body frame [m] (none: the reference point)",
    )

    @classmethod
    def _size(cls, name: str) -> int:
        return 6 if name == "cross_axis" else 3


class MagnetometerConfig(InertialConfig):
    """A magnetometer [µT]: also the airframe's hard-iron offset [µT] and its per-flight spread, and its
    soft-iron matrix (row by row, 9 values [-])."""

    VECTORS: ClassVar[tuple[str, ...]] = (*InertialConfig.VECTORS, "hard_iron", "soft_iron")

    hard_iron: list[SensorValue] = Field(description="the airframe's hard-iron offset per axis [µT]")
    hard_iron_std: SensorSpread = Field(0.0, description="its per-flight spread [µT]")
    soft_iron: list[Annotated[float, Field(ge=-10, le=10)]] = Field(description="soft-iron matrix, row by row [-]")
    soft_iron_std: Annotated[float, Field(ge=0, le=MAX_SOFT_IRON_STD)] = Field(
        0.0, description="its per-flight spread, symmetric: the diagonal and upper elements drawn, the lower follow [-]"
    )

    @model_validator(mode="before")
    @classmethod
    def _identity(cls, data):
        if isinstance(data, dict) and "soft_iron" not in data:
            data = {**data, "soft_iron": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]}
        return data

    @classmethod
    def _size(cls, name: str) -> int:
        return 9 if name == "soft_iron" else super()._size(name)


class BarometerConfig(ChannelConfig):
    """A barometer [Pa], one axis: the static pressure at the rocket's altitude."""

    AXES: ClassVar[int] = 1


class CanardFeedbackConfig(RateChannelConfig):
    """The canard servos' position sensors [deg], one per fin."""

    AXES: ClassVar[int] = 4


class GnssConfig(_SensorConfig):
    """A GNSS receiver: NED position and velocity fixes with white noise per fix (N, E, D) [m], [m/s], the slow
    sinusoidal position bias A·sin(2πft + φ) [m], [Hz], [deg] (its derivative on the velocity), and the time of
    the first fix [s from t = 0, the rocket on the pad]."""

    position_noise_m: list[Annotated[float, Field(ge=0, le=MAX_LENGTH_KM * 1000)]] = Field(
        min_length=3, max_length=3, description="white noise per fix, north, east, down"
    )
    velocity_noise_mps: list[Annotated[float, Field(ge=0, le=MAX_SPEED_MPS)]] = Field(
        min_length=3, max_length=3, description="white noise per fix, north, east, down"
    )
    sinusoid_amplitude_m: list[Annotated[float, Field(ge=0, le=MAX_LENGTH_KM * 1000)]] = Field(
        [0.0] * 3, min_length=3, max_length=3, description="A of the slow position bias A·sin(2πft + φ), N, E, D"
    )
    sinusoid_frequency_hz: float = Field(0.0, ge=0, le=1.0, description="f of the slow position bias")
    sinusoid_phase_deg: list[Direction] = Field([0.0] * 3, min_length=3, max_length=3, description="φ of the slow position bias, N, E, D")
    first_fix_s: float = Field(0.0, ge=0, le=MAX_FLIGHT_TIME_S, description="time of the first fix from t = 0, on the pad")


SENSOR_CONFIGS: dict[str, type[_SensorConfig]] = {
    "accelerometer": InertialConfig, "gyroscope": InertialConfig, "magnetometer": MagnetometerConfig,
    "barometer": BarometerConfig, "gnss": GnssConfig, "canard_feedback": CanardFeedbackConfig,
}  # fmt: skip
"""Each sensor of the avionics and its schema, in the bus's order."""
SPREADS = {"bias_std": "bias", "scale_factor_std": "scale_factor", "cross_axis_std": "cross_axis",
           "misalignment_std_deg": "misalignment_deg", "hard_iron_std": "hard_iron", "soft_iron_std": "soft_iron"}  # fmt: skip
"""A sensor's per-flight spreads and the values they disperse (normal draws about the nominal value)."""
SPREAD_ELEMENTS = {"soft_iron": (0, 1, 2, 4, 5, 8)}
"""The elements a spread draws where not all: the soft-iron matrix's diagonal and upper triangle (row by row; the
lower triangle follows their draws, ``campaign.model``: a symmetric perturbation)."""


class AvionicsConfig(_Strict):
    """The sensors (docs/sensors.md): each from a part (``part``: the default of every sensor it provides, the
    others the thesis's; a sensor's own ``part`` picks another), with any field overridden in its own table;
    ``truth_only``: every sensor's errors off."""

    part: str = Field(DEFAULT_PART, description="the part every sensor defaults to (data/sensors/<part>.toml)")
    truth_only: bool = Field(False, description="every sensor's errors off")
    accelerometer: InertialConfig = Field(default_factory=dict, validate_default=True)
    gyroscope: InertialConfig = Field(default_factory=dict, validate_default=True)
    magnetometer: MagnetometerConfig = Field(default_factory=dict, validate_default=True)
    barometer: BarometerConfig = Field(default_factory=dict, validate_default=True)
    gnss: GnssConfig = Field(default_factory=dict, validate_default=True)
    canard_feedback: CanardFeedbackConfig = Field(default_factory=dict, validate_default=True)

    @field_validator(*SENSOR_CONFIGS, mode="before")
    @classmethod
    def _from_part(cls, own, info: ValidationInfo):
        """The part's values under the sensor's own."""
        if not isinstance(own, dict):
            return own
        default = info.data.get("part", DEFAULT_PART)
        if default in part_names() and info.field_name not in load_part(default):
            default = DEFAULT_PART  # the section's part provides other sensors: this one is the thesis's
        name = own.get("part", default)
        if not isinstance(name, str):
            raise ValueError(f"part: expected a part name, got {_shown(name)}")
        try:
            part = load_part(name)
        except KeyError:
            raise ValueError(f"unknown part {_shown(name)} (known: {', '.join(part_names(info.field_name))})") from None
        if info.field_name not in part:
            raise ValueError(f"part {name!r} has no {info.field_name} (parts with one: "
                             f"{', '.join(part_names(info.field_name))})")  # fmt: skip
        values = dict(part[info.field_name])
        for given, other in (("noise_density", "noise_std"), ("noise_std", "noise_density")):
            if given in own:  # the table's own kind of white noise replaces the part's
                values.pop(other, None)
        return {"truth_only": info.data.get("truth_only", False), **values, **own, "part": name}

    @field_validator("part")
    @classmethod
    def _known(cls, name: str) -> str:
        if name not in part_names():
            raise ValueError(f"not a known part (known: {', '.join(part_names())})")
        return name


MAX_SLOW_FACTOR = 100.0  # a servo 100× slower than Lynx's (0.077 s → 7.7 s) no longer moves in the window: stuck
MAX_FIELD_STEP_UT = 10_000.0  # 200 × the geomagnetic field: a motor's current (~100 A at ~10 cm) makes ~200 µT
FaultTime = Annotated[float, Field(ge=0, le=MAX_FLIGHT_TIME_S)]


class _Fault(_Strict):
    """A fault that a flight has with ``probability``, drawn per flight from its own random stream."""

    probability: float = Field(ge=0, le=1, description="chance that a flight has it (0: off, nothing drawn or flown)")

    @staticmethod
    def _window(window: list[float]) -> list[float]:
        if not window[0] <= window[1]:
            raise ValueError(f"must be [earliest, latest] with earliest ≤ latest, got {window}")
        return window


TimeWindow = Annotated[list[FaultTime], Field(min_length=2, max_length=2)]


class _TimedFault(_Fault):
    """A fault from a time drawn uniformly in ``time_s`` = [earliest, latest] [s from t = 0, on the pad] (equal: fixed)."""

    time_s: TimeWindow = Field(description="[earliest, latest] time of the fault, drawn uniformly [s from t = 0]")

    @field_validator("time_s")
    @classmethod
    def _ordered(cls, window: list[float]) -> list[float]:
        return cls._window(window)


class _CanardFault(_TimedFault):
    """A fault of one canard servo: fin δ1..δ4 (none: drawn uniformly per flight)."""

    fin: int | None = Field(None, ge=1, le=4, description="the faulty fin, 1..4 (none: drawn per flight)")


class StuckCanardConfig(_CanardFault):
    """A canard servo that stops moving at the fault time: frozen at its deflection then, or at ``angle_deg``."""

    angle_deg: float | None = Field(None, ge=-MAX_CANARD_LIMIT_DEG, le=MAX_CANARD_LIMIT_DEG,
                                    description="the deflection it is stuck at (none: where it was at the fault) [deg]")


class SlowCanardConfig(_CanardFault):
    """A canard servo whose time constant is multiplied by ``factor`` from the fault time."""

    factor: float = Field(ge=1, le=MAX_SLOW_FACTOR, description="its time constant's multiplier [-]")


class GnssOutageConfig(_Fault):
    """No GNSS fix from a start drawn in ``start_s`` for a duration drawn in ``duration_s`` (uniform)."""

    start_s: TimeWindow = Field(description="[earliest, latest] start of the outage [s from t = 0]")
    duration_s: TimeWindow = Field(description="[shortest, longest] duration of the outage [s]")

    @field_validator("start_s", "duration_s")
    @classmethod
    def _ordered(cls, window: list[float]) -> list[float]:
        return cls._window(window)


class MagnetometerStepConfig(_TimedFault):
    """A body-fixed magnetic field of ``magnitude_ut`` in a direction drawn uniformly from the fault time on (the
    motor's or an ignition current's signature), seen by the magnetometer as a hard-iron step."""

    magnitude_ut: float = Field(gt=0, le=MAX_FIELD_STEP_UT, description="the field step's magnitude [µT]")


class GyroscopeBiasJumpConfig(_TimedFault):
    """The gyroscope's bias jumps by ``magnitude_deg_s`` in a direction drawn uniformly (sensor frame)."""

    magnitude_deg_s: float = Field(gt=0, le=MAX_RATE_DEG_S, description="the jump's magnitude [deg/s]")


class AccelerometerBiasJumpConfig(_TimedFault):
    """The accelerometer's bias jumps by ``magnitude_mps2`` in a direction drawn uniformly (sensor frame)."""

    magnitude_mps2: float = Field(gt=0, le=MAX_SENSOR_VALUE, description="the jump's magnitude [m/s²]")


class FaultsConfig(_Strict):
    """Faults a campaign disperses (docs/faults.md), each absent (none) or with its probability per flight."""

    stuck_canard: StuckCanardConfig | None = None
    slow_canard: SlowCanardConfig | None = None
    gnss_outage: GnssOutageConfig | None = None
    magnetometer_step: MagnetometerStepConfig | None = None
    gyroscope_bias_jump: GyroscopeBiasJumpConfig | None = None
    accelerometer_bias_jump: AccelerometerBiasJumpConfig | None = None

    def active(self) -> dict[str, _Fault]:
        """The faults some flight can have (given, probability above 0), by name in the table's order."""
        return {name: f for name in type(self).model_fields if (f := getattr(self, name)) is not None
                and f.probability > 0.0}  # fmt: skip


FAULT_SECTIONS = {"stuck_canard": "gnc", "slow_canard": "gnc", "gnss_outage": "avionics",
                  "magnetometer_step": "avionics", "gyroscope_bias_jump": "avionics",
                  "accelerometer_bias_jump": "avionics"}  # fmt: skip
"""The section each fault acts on: the canard servos of [gnc], the sensors of [avionics]."""


class CampaignConfig(_Strict):
    name: str = Field(description=f"a label of 1 to {MAX_NAME_LENGTH} printable characters on one line")
    description: str = Field("", description="free text")
    n_realizations: int = Field(ge=1, le=MAX_REALIZATIONS, description="flights in the campaign (-n overrides)")
    seed: int = Field(ge=0, lt=2**32, description="master seed; realization i draws from fold_in(key(seed), i)")
    rocket: RocketConfig
    site: SiteConfig
    launch: LaunchConfig
    environment: EnvironmentConfig = EnvironmentConfig()
    dispersions: dict[str, Dispersion] = {}
    simulation: SimulationConfig = SimulationConfig()
    gnc: GncConfig | None = Field(None, description="the closed loop; None: no controller, canards neutral")
    avionics: AvionicsConfig | None = Field(None, description="the sensors; None: no sensors simulated")
    faults: FaultsConfig | None = Field(None, description="faults drawn per flight (docs/faults.md); None: none")

    @field_validator("name")
    @classmethod
    def _label(cls, name: str) -> str:
        if not (name.strip() and len(name) <= MAX_NAME_LENGTH and name.isprintable()):
            raise ValueError(f"expected a label: 1 to {MAX_NAME_LENGTH} printable characters on one line, not blank")
        return name


@dataclasses.dataclass(frozen=True)
class Campaign:
    """A validated campaign: the config, its TOML text, the thrust curve, the nominal values of
    every dispersible number, keyed by dotted path (``"rocket.dry_mass_kg"``, ``"rocket.aero.ca0.2"``),
    the aerodynamic model with its tables (None for ``model = "linear"``, built per flight), the
    folder its relative file names are resolved from, the measured wind profile (altitude above
    ground [m], speed [m/s], from-direction [rad]) when the wind model is ``profile``, and with a
    [gnc] section the LQI gain schedule (``campaign/gains.py``): gains over speeds [m/s] × altitudes
    [m above mean sea level: the grid's altitudes_m plus site.altitude_m], and what it was designed from
    (``gains.DesignInputs``: the linearised aerodynamics, the rocket at burnout, the window estimate)."""

    config: CampaignConfig
    text: str
    thrust_time_s: np.ndarray
    thrust_n: np.ndarray
    nominal: dict[str, float]
    aero: TableAero | LinearAero | None
    base_dir: Path
    wind_profile: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    files: dict[str, str] = dataclasses.field(default_factory=dict)
    gnc_schedule: Schedule | None = None
    gnc_inputs: DesignInputs | None = None
    weather: Weather | None = None

    def with_overrides(
        self, n_realizations: int | None = None, seed: int | None = None, aero_model: str | None = None,
        controller: bool | None = None, sensors: bool | None = None, navigation: str | None = None,
        values: Mapping[str, object] | None = None,
    ) -> Campaign:  # fmt: skip
        """The same campaign with N, the seed and/or the aerodynamic model replaced (CLI options); controller:
        True adds a [gnc] section of defaults if there is none, False removes it and its servo dispersions
        and its faults (the same flights with the canards neutral); sensors: True adds an [avionics] section of defaults
        (the thesis's parts) if there is none and flies the controller on raw sensors (or on its filters, if the
        campaign's navigation is "filters"), False removes it and its dispersions and flies the controller on
        perfect navigation (their faults removed too); navigation: the controller's ("truth", "sensors" or "filters"), with sensors to match;
        values: fields set by dotted path (``{"avionics.gyroscope.truth_only": True}``), after the options above, and
        dispersions by their parameter's path after ``dispersions.``: a table sets one, None removes it."""
        if navigation is not None:
            sensors = navigation != "truth"
        data = self.config.model_dump()
        spreads = sensor_spreads(self.config)  # drawn by the sensors' spreads, not the file: redrawn from the new ones
        data["dispersions"] = {k: d for k, d in data["dispersions"].items()
                               if k not in spreads or self.config.dispersions[k] != spreads[k]}  # fmt: skip
        data.update({k: v for k, v in (("n_realizations", n_realizations), ("seed", seed)) if v is not None})
        if aero_model is not None:
            data["rocket"]["aero"]["model"] = aero_model
        for section, on in (("gnc", controller), ("avionics", sensors)):
            if on is not None and on != (data[section] is not None):
                data[section] = {} if on else None
                data["dispersions"] = {k: d for k, d in data["dispersions"].items() if on or not k.startswith(section + ".")}
                if not on and data["faults"] is not None:  # its faults go with it
                    data["faults"].update({name: None for name, s in FAULT_SECTIONS.items() if s == section})
        if sensors is not None and data["gnc"] is not None:
            current = data["gnc"].get("navigation", "truth")  # a [gnc] just added is empty: the schema's default
            kept = current if current != "truth" else "sensors"
            data["gnc"]["navigation"] = (navigation or kept) if sensors else "truth"
        for path, value in (values or {}).items():
            if path.startswith("dispersions."):  # a key of the dispersions' table is itself a dotted path
                key = path.removeprefix("dispersions.")
                if value is None and key not in data["dispersions"]:
                    raise ConfigError(f"{path}: not a dispersion of this campaign")
                data["dispersions"] = {k: d for k, d in data["dispersions"].items() if k != key}
                data["dispersions"].update({} if value is None else {key: value})
                continue
            try:
                data = _set_path(data, path, value)
            except (KeyError, IndexError, TypeError, ValueError):
                raise ConfigError(f"{path}: not a field of this campaign") from None
        config = _validate(data)
        config = _with_sensor_spreads(config)
        campaign = dataclasses.replace(self, config=config, nominal=_nominal_values(config))
        new_aero = config.rocket.aero.model != self.config.rocket.aero.model
        if new_aero:
            campaign = dataclasses.replace(campaign, aero=_aero_model(config.rocket, self.base_dir),
                                           files=_file_digests(config, self.base_dir))  # fmt: skip
        design = lambda c: None if c.gnc is None else c.gnc.model_dump(exclude={"navigation"})  # noqa: E731
        if new_aero or design(config) != design(self.config):
            campaign = _with_gains(campaign)
        return campaign


def _with_gains(campaign: Campaign) -> Campaign:
    """``campaign`` with its LQI gain schedule and what it was designed from (``campaign/gains.py``), both
    None without a [gnc] section."""
    if campaign.config.gnc is None:
        return dataclasses.replace(campaign, gnc_schedule=None, gnc_inputs=None)
    from .gains import design_inputs, design_schedule  # gains imports campaign.model, which imports this module

    inputs = design_inputs(campaign)
    return dataclasses.replace(campaign, gnc_schedule=design_schedule(campaign, inputs), gnc_inputs=inputs)


SHOWN_INPUT_LENGTH = 60
"""Characters of a refused value that an error message shows (a 10 000-character name is not repeated)."""


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= SHOWN_INPUT_LENGTH else f"{text[:SHOWN_INPUT_LENGTH]}... ({len(text)} characters)"


def _format_error(error: ValidationError) -> str:
    first = error.errors()[0]
    path = ".".join(str(p) for p in first["loc"]) or "(top level)"
    if first["type"] == "extra_forbidden":
        return f"{path}: unknown key"
    if first["type"] == "missing":
        return f"{path}: missing (required)"
    message = first["msg"].removeprefix("Value error, ")
    found = first.get("input")
    shown = "" if isinstance(found, dict | list) else f" (got {_shown(found)})"
    return f"{path}: {message}{shown}"


def _validate(data: dict) -> CampaignConfig:
    try:
        return CampaignConfig.model_validate(data)
    except ValidationError as e:
        raise ConfigError(_format_error(e)) from None


def _deep_merge(base: dict, override: dict) -> dict:
    merged = copy.deepcopy(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = _deep_merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def preset_rocket(name: str) -> dict:
    """The rocket table of a built-in preset (``data/rockets/<name>.toml``)."""
    folder = resources.files("rocketmc") / "data" / "rockets"
    available = sorted(p.name.removesuffix(".toml") for p in folder.iterdir() if p.name.endswith(".toml"))
    if name not in available:  # a name, not a path
        raise ConfigError(f"rocket.preset: unknown preset {_shown(name)} (available: {', '.join(available)})")
    return tomllib.loads((folder / f"{name}.toml").read_text())


def _resolve_data_file(name: str, base_dir: Path, folder: str, field: str) -> Path:
    """``name`` beside the campaign, else in the package's ``data/<folder>``."""
    candidate = base_dir / name
    builtin = resources.files("rocketmc") / "data" / folder / name
    try:
        if candidate.is_file():
            return candidate
        if builtin.is_file():
            return Path(str(builtin))
        exists = candidate.exists()
    except OSError as err:  # e.g. a name too long for the file system
        raise ConfigError(f"{field}: cannot look up {_shown(name)} ({err.strerror})") from None
    if exists:
        raise ConfigError(f"{field}: {_shown(name)} is not a file (a folder?)")
    raise ConfigError(f"{field}: file not found: {_shown(name)} (neither beside the campaign nor built in)")


def flatten_numbers(tree, prefix: str = "") -> dict[str, float]:
    """Numeric leaves (not bools) of nested dicts/lists, keyed by dotted path."""
    items = tree.items() if isinstance(tree, dict) else enumerate(tree) if isinstance(tree, list) else None
    if items is None:
        return {prefix: float(tree)} if isinstance(tree, int | float) and not isinstance(tree, bool) else {}
    out = {}
    for key, value in items:
        out.update(flatten_numbers(value, f"{prefix}.{key}" if prefix else str(key)))
    return out


def _set_path(data: dict, path: str, value: float) -> dict:
    data = copy.deepcopy(data)
    *parents, last = path.split(".")
    node = data
    for p in parents:
        node = node[int(p)] if isinstance(node, list) else node[p]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return data


def _drawable_values(d: Dispersion, nominal_value: float, field: str) -> list[tuple[float, str]]:
    """The values that bound what ``d`` draws (every valid range is an interval, so they are enough), each
    with a hint for the error message. ConfigError if a normal's clip range excludes its mean."""
    if d.dist == "choice":
        return [(value, "") for value in d.values]
    if d.dist == "uniform":
        return [(d.low, ""), (d.high, "")]
    mean = nominal_value if d.mean is None else d.mean
    if not ((d.low is None or d.low <= mean) and (d.high is None or mean <= d.high)):
        of = " (the nominal value, as no mean is given)" if d.mean is None else ""
        raise ConfigError(f"{field}: the clip range [{d.low}, {d.high}] excludes the mean {mean!r}{of}")
    reach = NORMAL_REACH_STD * d.std
    sides = [(d.low, mean - reach, "−", "low"), (d.high, mean + reach, "+", "high")]
    return [(mean, "")] + [
        (clip, "") if clip is not None else (unclipped, f" (mean {sign} {NORMAL_REACH_STD:g}·std; clip it with {key})")
        for clip, unclipped, sign, key in sides
    ]


def fixed_reason(path: str) -> str | None:
    """Why the number at dotted ``path`` is fixed for the whole campaign (not dispersible), or None."""
    if path.startswith(FIXED_PER_CAMPAIGN) and not path.startswith(DISPERSIBLE_AERO):
        return ("fixed for the whole campaign (it defines the body frame or builds the aerodynamic tables); "
                "disperse rocket.aero.drag_scale or rocket.aero.cl0 instead")  # fmt: skip
    if path.startswith("avionics.") and path.rstrip("0123456789.").endswith(FIXED_AVIONICS):
        return "fixed for the whole campaign (a sensor's schedule is set once, and its per-flight spreads are dispersions already)"
    if path.startswith(FIXED_GNC):
        return ("fixed for the whole campaign (guidance, the LQI gains and the navigation filters are set once, "
                "when it loads); only the servos, gnc.servo.*, can be dispersed")  # fmt: skip
    return None


def _check_dispersions(config: CampaignConfig, nominal: dict[str, float]) -> None:
    """Each dispersion names a dispersible number and every value it can draw passes validation; one a sensor's
    per-flight spread implies (``sensor_spreads``) is named by that spread, the field the file gives."""
    data = config.model_dump(exclude={"dispersions"})
    implied = sensor_spreads(config)
    for path, d in config.dispersions.items():
        field = f"dispersions.{path}"
        if implied.get(path) == d:
            _check_spread_draws(data, path, d, nominal[path])
            continue
        if (reason := fixed_reason(path)) is not None:
            raise ConfigError(f"{field}: {reason}")
        if path.startswith("environment.wind.") and config.environment.atmosphere is not None:
            raise ConfigError(f"{field}: the wind is environment.atmosphere's; disperse "
                              "environment.atmosphere.wind_rotation_deg or wind_scale instead")  # fmt: skip
        if path not in nominal:
            raise ConfigError(f"{field}: not a dispersible number (expected a numeric field of "
                              f"{'/'.join(DISPERSIBLE_SECTIONS)}, e.g. 'rocket.dry_mass_kg')")  # fmt: skip
        for value, hint in _drawable_values(d, nominal[path], field):
            try:
                CampaignConfig.model_validate(_set_path(data, path, value))
            except ValidationError as e:
                raise ConfigError(f"{field}: draws a value {value!r}{hint} that is out of range: "
                                  f"{_format_error(e)}") from None  # fmt: skip


def _check_spread_draws(data: dict, path: str, d: Dispersion, nominal_value: float) -> None:
    """ConfigError naming the spread (``avionics.<sensor>.<spread>``) if the draws it implies at ``path``
    (``avionics.<sensor>.<value>.<i>``, normal about the nominal value, unclipped) can leave the value's range."""
    sensor, target = path.split(".")[1:3]
    spread = f"avionics.{sensor}.{next(name for name, value in SPREADS.items() if value == target)}"
    reach = NORMAL_REACH_STD * d.std
    for sign, value in (("−", nominal_value - reach), ("+", nominal_value + reach)):
        try:
            CampaignConfig.model_validate(_set_path(data, path, value))
        except ValidationError as e:
            raise ConfigError(f"{spread}: draws {value!r} (the nominal {sign} {NORMAL_REACH_STD:g}·std), out of "
                              f"range: {_format_error(e)}; lower it, or clip the draws with a dispersion of that "
                              "path (low, high)") from None  # fmt: skip


def parse_campaign(text: str, base_dir: Path = Path(".")) -> Campaign:
    """Validate a campaign from its TOML text; relative files are looked up from ``base_dir``."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"not valid TOML: {e}") from None
    return campaign_from_dict(raw, base_dir, text)


def campaign_from_dict(raw: dict, base_dir: Path = Path("."), text: str = "") -> Campaign:
    """Validate a campaign from the tables of a campaign file (e.g. one read with ``tomllib`` and
    edited); ``text`` is what result files record as the campaign's source."""
    raw = copy.deepcopy(raw)
    rocket = raw.get("rocket")
    if isinstance(rocket, dict) and "preset" in rocket:
        overrides = {k: v for k, v in rocket.items() if k != "preset"}
        if not isinstance(rocket["preset"], str):
            raise ConfigError(f"rocket.preset: expected a string (got {rocket['preset']!r})")
        raw["rocket"] = _deep_merge(preset_rocket(rocket["preset"]), overrides)
    config = _validate(raw)
    _check_geometry(config.rocket)

    path = _resolve_data_file(config.rocket.motor.thrust_curve, base_dir, "motors", "rocket.motor.thrust_curve")
    try:
        time_s, thrust_n = read_thrust_curve(path)
    except ThrustCurveError as e:
        raise ConfigError(f"rocket.motor.thrust_curve: {e}") from None
    motor = config.rocket.motor
    if motor.isp_s is not None:
        curve_isp = cumulative_impulse(time_s, thrust_n)[-1] / (G0 * motor.propellant_mass_kg)
        if abs(curve_isp - motor.isp_s) > ISP_TOLERANCE * motor.isp_s:
            raise ConfigError(f"rocket.motor.isp_s: {motor.isp_s} s disagrees with the curve's impulse per "
                              f"propellant mass ({curve_isp:.1f} s) by more than {ISP_TOLERANCE:.0%}")  # fmt: skip

    config = _with_sensor_spreads(config)
    nominal = _nominal_values(config)
    _check_dispersions(config, nominal)
    aero = _aero_model(config.rocket, base_dir)
    return _with_gains(Campaign(config, text, time_s, thrust_n, nominal, aero, base_dir,
                                _wind_profile(config, base_dir), _file_digests(config, base_dir),
                                weather=_weather(config, base_dir)))  # fmt: skip


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


GEOMETRY_TOLERANCE_M = 1e-9
"""Slack on the geometry's fits [m]: a fin whose trailing edge is the aft end, computed from positions in
another origin, may land a rounding error past it."""


def _check_geometry(rocket: RocketConfig) -> None:
    """The build-up's shape can be built: every fin set's and the canards' root chord on the body (from the
    nose tip to the aft end), the canards clear of every fin set, a boat-tail behind the nose and ending at
    or before the aft end, narrowing; one line naming the field."""
    g = rocket.geometry
    if g is None:
        return
    length, eps = g.length_m, GEOMETRY_TOLERANCE_M

    def root(path: str, f: FinSetConfig) -> tuple[float, float]:
        start = rocket.from_nose(f.position_m)
        end = start + f.root_chord_m
        if start < -eps or end > length + eps:
            raise ConfigError(f"rocket.geometry.{path}.position_m: the root chord spans {start:g} to {end:g} m from "
                              f"the nose tip, outside the body (0 to length_m = {length:g} m)")  # fmt: skip
        return start, end

    fins = [(f"fins.{i}", root(f"fins.{i}", f)) for i, f in enumerate(g.fins)]
    if g.canards is not None:
        start, end = root("canards", g.canards)
        for path, (fin_start, fin_end) in fins:
            if start < fin_end - eps and fin_start < end - eps:
                raise ConfigError(f"rocket.geometry.canards.position_m: the canards' root chord ({start:g} to {end:g} m "
                                  f"from the nose tip) overlaps {path}'s ({fin_start:g} to {fin_end:g} m)")  # fmt: skip
    if (tail := g.boat_tail) is not None:
        start = rocket.from_nose(tail.position_m)
        if start < g.nose.length_m - eps or start + tail.length_m > length + eps:
            raise ConfigError(f"rocket.geometry.boat_tail.position_m: the boat-tail spans {start:g} to "
                              f"{start + tail.length_m:g} m from the nose tip, not between the nose's end "
                              f"({g.nose.length_m:g} m) and the aft end ({length:g} m)")  # fmt: skip
        if tail.aft_diameter_m > g.body_diameter_m:
            raise ConfigError(f"rocket.geometry.boat_tail.aft_diameter_m: {tail.aft_diameter_m:g} m exceeds the body's "
                              f"diameter ({g.body_diameter_m:g} m); a boat-tail narrows")  # fmt: skip


def _check_avionics(config: CampaignConfig) -> None:
    """Sensor rates divide the GNC rate, latencies are whole GNC periods, raw-sensor navigation has sensors."""
    gnc = config.gnc
    if gnc is not None and gnc.navigation != "truth" and config.avionics is None:
        raise ConfigError(f"gnc.navigation: '{gnc.navigation}' needs an [avionics] section (the sensors it reads)")
    if gnc is not None and gnc.navigation == "filters" and gnc.filters.initialisation != "rail":
        _check_pad_samples(config)
    for sensor in SENSOR_CONFIGS if config.avionics is not None else ():
        sample_period_ticks(config, sensor)
        sensor_ticks(config, getattr(config.avionics, sensor).latency_s, f"avionics.{sensor}.latency_s")


def _check_pad_samples(config: CampaignConfig) -> None:
    """ConfigError unless the motor lights after the filters' pad samples in every flight (the samples at the
    GNC ticks before ignition)."""
    pad = config.gnc.filters.pad_samples * config.simulation.control_dt_s
    path = "rocket.motor.ignition_delay_s"
    nominal, d = config.rocket.motor.ignition_delay_s, config.dispersions.get(path)
    earliest = min([nominal] + ([] if d is None else [value for value, _ in _drawable_values(d, nominal, path)]))
    if earliest < pad:
        raise ConfigError(f"gnc.filters.initialisation: '{config.gnc.filters.initialisation}' needs "
                          f"{config.gnc.filters.pad_samples} samples on the "
                          f"pad ({pad:g} s) before ignition, but {path} can be {earliest:g} s (raise it, lower "
                          "gnc.filters.pad_samples, or initialise from the 'rail')")  # fmt: skip


def _check_faults(config: CampaignConfig) -> None:
    """Each fault some flight can have acts on a section the campaign has (the servos of [gnc], the sensors of
    [avionics]), and a bias jump on a sensor with errors (a truth-only sensor has no bias)."""
    for name in ({} if config.faults is None else config.faults.active()):
        section = FAULT_SECTIONS[name]
        if getattr(config, section) is None:
            acts_on = "the canard servos" if section == "gnc" else "the sensors"
            raise ConfigError(f"faults.{name}: needs [{section}] ({acts_on} it acts on)")
        sensor = name.removesuffix("_bias_jump")
        if sensor != name and getattr(config.avionics, sensor).truth_only:
            raise ConfigError(f"faults.{name}: avionics.{sensor} is truth_only (no errors, so no bias to jump)")


def _with_sensor_spreads(config: CampaignConfig) -> CampaignConfig:
    """``config`` checked (``_check_avionics``, ``_check_faults``) with its sensors' spreads among its dispersions,
    the file's own dispersions kept where both name a value."""
    _check_avionics(config)
    _check_faults(config)
    return config.model_copy(update={"dispersions": {**sensor_spreads(config), **config.dispersions}})


def sensor_spreads(config: CampaignConfig) -> dict[str, Dispersion]:
    """The normal dispersions the sensors' per-flight spreads (``SPREADS``) imply, by dotted path: each axis
    of a value about its nominal value."""
    spreads = {}
    for sensor in SENSOR_CONFIGS if config.avionics is not None else ():
        values = getattr(config.avionics, sensor)
        for spread, target in SPREADS.items():
            stds = getattr(values, spread, None)
            if stds is None:
                continue
            nominal = getattr(values, target)
            for i, std in enumerate(stds if isinstance(stds, list) else [stds] * len(nominal)):
                if std > 0.0 and i in SPREAD_ELEMENTS.get(target, range(len(nominal))):
                    spreads[f"avionics.{sensor}.{target}.{i}"] = Dispersion(dist="normal", std=std)
    return spreads


def _nominal_values(config: CampaignConfig) -> dict[str, float]:
    """Every number of the dispersible sections by dotted path (``Campaign.nominal``); with an
    [environment.atmosphere], none of [environment.wind]'s (its file brings the wind)."""
    dump = config.model_dump()
    if config.environment.atmosphere is not None:
        del dump["environment"]["wind"]
    return {k: v for s in DISPERSIBLE_SECTIONS for k, v in flatten_numbers(dump[s], s).items()}


def _file_digests(config: CampaignConfig, base_dir: Path) -> dict[str, str]:
    """SHA-256 of each file the campaign reads, by the field naming it (built-in files too)."""
    named = {"rocket.motor.thrust_curve": (config.rocket.motor.thrust_curve, "motors")}
    aero, wind = config.rocket.aero, config.environment.wind
    if aero.model != "linear" and aero.tables != "buildup" and aero.tables not in BUILTIN_TABLES:
        named["rocket.aero.tables"] = (aero.tables, "aero")
    if wind.model == "profile":
        named["environment.wind.file"] = (wind.file, "wind")
    if config.environment.atmosphere is not None:
        named["environment.atmosphere.file"] = (config.environment.atmosphere.file, "weather")
    return {
        field: hashlib.sha256(_resolve_data_file(name, base_dir, folder, field).read_bytes()).hexdigest()
        for field, (name, folder) in named.items()
    }


def _wind_profile(config: CampaignConfig, base_dir: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    wind = config.environment.wind
    if wind.model != "profile":
        return None
    path = _resolve_data_file(wind.file, base_dir, "wind", "environment.wind.file")
    try:
        altitude, speed, from_rad = read_wind_profile(path, config.site.altitude_m)
    except (ValueError, OSError) as err:
        raise ConfigError(f"environment.wind.file: {err}") from None
    if speed.max() > MAX_WIND_MPS:
        raise ConfigError(f"environment.wind.file: {path}: speed_mps reaches {speed.max():g}, "
                          f"above {MAX_WIND_MPS:g} m/s")  # fmt: skip
    return altitude, speed, from_rad


def _weather(config: CampaignConfig, base_dir: Path) -> Weather | None:
    """The day's atmosphere at the site (``env.weather.read_weather``), None without [environment.atmosphere]."""
    atmosphere, field = config.environment.atmosphere, "environment.atmosphere"
    if atmosphere is None:
        return None
    path = _resolve_data_file(atmosphere.file, base_dir, "weather", f"{field}.file")
    time = None if atmosphere.time_utc is None else datetime.fromisoformat(atmosphere.time_utc)
    try:
        weather = read_weather(path, config.site.latitude_deg, config.site.longitude_deg, time, atmosphere.grid)
    except WeatherError as err:
        raise ConfigError(f"{field}.{err.field}: {err}") from None
    if weather.speed_mps.max() > MAX_WIND_MPS:
        raise ConfigError(f"{field}.file: {path}: the wind reaches {weather.speed_mps.max():g} m/s, "
                          f"above {MAX_WIND_MPS:g} m/s")  # fmt: skip
    return weather


def _aero_tables(rocket: RocketConfig, base_dir: Path) -> AeroTables:
    aero = rocket.aero
    geometry = None if rocket.geometry is None else rocket.geometry.to_geometry(rocket.from_nose)
    try:
        if aero.tables == "buildup":
            tables = build_up_tables(geometry, rocket.from_nose(rocket.reference_point_m))
        else:
            references = {
                k: v for k in ("reference_area_m2", "reference_length_m") if (v := getattr(aero, k)) is not None
            }  # fmt: skip
            if aero.moment_reference_m is not None:
                references["moment_reference_m"] = rocket.from_nose(aero.moment_reference_m)
            tables = BUILTIN_TABLES[aero.tables]() if aero.tables in BUILTIN_TABLES else load_aero(
                _resolve_data_file(aero.tables, base_dir, "aero", "rocket.aero.tables"), **references
            )
            if geometry is not None:
                tables = with_canards(tables, geometry)
        if aero.cd is not None:
            tables = with_axial_curve(tables, aero.cd_mach, aero.cd)
    except (ValueError, OSError) as err:
        raise ConfigError(f"rocket.aero.tables: {err}") from None
    return tables


def _power_on_table(rocket: RocketConfig) -> Table | None:
    """ΔCA(Mach) while the motor burns: ``cd_power_on − cd`` if given, else the build-up's (the
    exhaust area taken as the nominal grain's outer diameter) when the tables are built up and no
    Cd curve replaces them, else None (no power-on effect)."""
    aero = rocket.aero
    if aero.cd_power_on is not None:
        mach, increment = aero.cd_mach, np.subtract(aero.cd_power_on, aero.cd)
    elif aero.tables == "buildup" and aero.cd is None:
        geometry = rocket.geometry.to_geometry(rocket.from_nose)
        mach, increment = power_on_axial_increment(geometry, rocket.motor.grain_outer_diameter_m)
    else:
        return None
    return Table.from_numpy((mach,), np.asarray(increment)[:, None], ("mach",), ("dCA",))


def _aero_model(rocket: RocketConfig, base_dir: Path) -> TableAero | LinearAero | None:
    """The campaign's aerodynamic model with its nominal scalars (``campaign.model`` replaces the
    dispersible ones per flight), or None for ``model = 'linear'`` (built per flight)."""
    if rocket.aero.model == "linear":
        return None
    table_aero = TableAero.from_tables(_aero_tables(rocket, base_dir), rocket.from_nose(rocket.reference_point_m))
    table_aero = dataclasses.replace(table_aero, power_on_ca=_power_on_table(rocket))
    return simplify(table_aero) if rocket.aero.model == "simplified" else table_aero


def load_campaign(path: str | Path) -> Campaign:
    """Read and validate a campaign file."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"campaign file not found: {path}")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ConfigError("not valid TOML: not UTF-8 text (a binary file?)") from None
    return parse_campaign(text, path.parent)
