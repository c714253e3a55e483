"""The campaign file's schema (pydantic): every table and key, its type, range, default and description, and the
checks that belong to one table; loading, the checks across tables and files are ``campaign/loader.py``'s."""

from __future__ import annotations

import math
from datetime import date, datetime, timezone
from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator

from ..aero.airbrakes import HOERNER_SQUARE_PLATE_CD
from ..aero.geometry import DEFAULT_ROUGHNESS_M, FIN_PROFILES, NOSE_KINDS
from ..env.magnetic import IGRF14_VALIDITY
from ..env.wind import POWER_LAW_FLOOR_M
from ..sensors.parts import load_part, part_names
from .errors import shown
from .limits import (
    DEFAULT_ALTITUDES_M,
    DEFAULT_SPEEDS_MPS,
    MAX_AIRBRAKE_DAMPING,
    MAX_AIRBRAKE_GAIN,
    MAX_AIRBRAKE_MACH,
    MAX_AIRBRAKE_NATURAL_FREQUENCY_RAD_S,
    MAX_AIRBRAKE_PI_GAIN,
    MAX_AIRBRAKE_REFERENCES,
    MAX_AIRBRAKE_PANELS,
    MAX_AIRBRAKE_RATE_PER_S,
    MAX_ALTITUDE_M,
    MAX_ANOMALY_NT,
    MAX_BURN_TIME_S,
    MAX_AREA_M2,
    MAX_CANARD_LIMIT_DEG,
    MAX_COEFFICIENT,
    MAX_DAMPING_COEFFICIENT,
    MAX_DELAY_S,
    MAX_DIAMETER_M,
    MAX_DRAG_COEFFICIENT,
    MAX_FIELD_STEP_UT,
    MAX_FLIGHT_TIME_S,
    MAX_GATE,
    MAX_GUIDANCE_GAIN,
    MAX_WIND_GAIN,
    MAX_INERTIA_KGM2,
    MAX_ISP_S,
    MAX_LENGTH_KM,
    MAX_LENGTH_M,
    MAX_LQ_WEIGHT,
    MAX_MACH,
    MAX_MASS_KG,
    MAX_MISALIGNMENT_DEG,
    MAX_NAME_LENGTH,
    MAX_RATE_DEG_S,
    MAX_REALIZATIONS,
    MAX_ROUGHNESS_M,
    MAX_SCALE,
    MAX_SENSOR_LATENCY_S,
    MAX_SENSOR_VALUE,
    MAX_SERVO_RATE_DEG_S,
    MAX_SERVO_TIME_CONSTANT_S,
    MAX_SLOW_FACTOR,
    MAX_SOFT_IRON_STD,
    MAX_SPEED_MPS,
    MAX_WIND_MPS,
    MIN_CONTROL_DT_S,
    MIN_INERTIA_KGM2,
    MIN_LENGTH_M,
    MIN_MASS_KG,
)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)


NonNegative = Annotated[float, Field(ge=0)]
Mass = Annotated[float, Field(ge=MIN_MASS_KG, le=MAX_MASS_KG)]
Position = Annotated[float, Field(ge=-MAX_LENGTH_M, le=MAX_LENGTH_M, description="in the rocket's coordinates [m]")]
Length = Annotated[float, Field(ge=MIN_LENGTH_M, le=MAX_LENGTH_M)]
Diameter = Annotated[float, Field(ge=MIN_LENGTH_M, le=MAX_DIAMETER_M)]
Area = Annotated[float, Field(gt=0, le=MAX_AREA_M2)]
Roughness = Annotated[float, Field(ge=0, le=MAX_ROUGHNESS_M)]
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


def _added(default, description: str, **constraints):
    """A field added after campaigns were stored, left out of the dump at its ``default``: a campaign that does not
    write it keeps its configuration and set-up fingerprint bit for bit."""
    return Field(default, exclude_if=lambda value: value == default, description=description, **constraints)


class MotorConfig(_Strict):
    """Solid motor; positions in the rocket's coordinates [m]."""

    thrust_curve: str | None = Field(
        None, description="RASP .eng, RockSim .rse or CSV (time s, thrust N); built-in name or path; this or designation"
    )
    designation: str | None = _added(
        None, "a motor of the built-in library instead of thrust_curve ('L1350', 'Cesaroni_4263L1350-P'; "
        "`rocketmc motors` lists them): its curve, and where not given its propellant mass, a grain estimated from "
        "its casing, and its casing as dry_mass_kg (so rocket.dry_mass_kg is then the rocket without its motor)",
    )
    propellant_mass_kg: Mass = Field(description="propellant mass at ignition, all of it burnt by the curve's end "
                                     "(a designation gives the .eng header's)")  # fmt: skip
    isp_s: float | None = Field(
        None, gt=0, le=MAX_ISP_S, description="checked against the curve's impulse / propellant"
    )
    ignition_delay_s: Delay = Field(0.0, description="ignition after the start of the simulation, on the rail")
    thrust_scale: Scale = Field(1.0, description="multiplies the thrust curve (the burn time unchanged)")
    burn_time_s: float | None = _added(
        None, "reshapes the curve to this burn time keeping its total impulse: its times scaled to end at "
        "burn_time_s, its thrusts by the inverse ratio (RocketPy's reshape_thrust_curve); dispersible (none: the "
        "curve's own)", gt=0, le=MAX_BURN_TIME_S,
    )
    nozzle_m: Position = Field(description="the nozzle exit, in the rocket's coordinates [m]")
    grain_outer_diameter_m: Diameter = Field(description="the propellant grain's outer diameter (burning outward); "
                                             "a designation estimates the grain from its casing")  # fmt: skip
    grain_inner_diameter_m: float = Field(ge=0, le=MAX_DIAMETER_M, description="the grain's initial core diameter")
    grain_length_m: Length = Field(description="the grain's length along the axis")
    grain_center_m: Position | None = Field(None, description="default: the grain ends at the nozzle exit")
    dry_mass_kg: float = Field(0.0, ge=0, le=MAX_MASS_KG,
                               description="casing, nozzle, closures: 0 if the rocket's dry mass has them; a "
                               "designation's default is the library's total less propellant")  # fmt: skip
    dry_inertia_kgm2: list[Annotated[float, Field(ge=0, le=MAX_INERTIA_KGM2)]] = Field(
        [0.0, 0.0], min_length=2, max_length=2, description="[axial, transverse] about the motor's dry CG; a "
        "designation's default is a thin tube of the casing's size and dry_mass_kg"
    )
    dry_cg_m: Position | None = Field(None, description="default: the grain centre")

    @model_validator(mode="after")
    def _one_motor(self):
        if (self.thrust_curve is None) == (self.designation is None):
            raise ValueError("thrust_curve and designation both name the motor; keep one" if self.thrust_curve else
                             "name the motor by thrust_curve (a file) or by designation (a motor of the built-in "
                             "library, `rocketmc motors`)")  # fmt: skip
        return self

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
    profile: Literal[FIN_PROFILES] = _added("rounded", "edges: rounded (or bevelled), square or airfoil")
    surface_roughness_m: Roughness | None = _added(None, "roughness height of the panels (none: the body's)")


class BoatTailConfig(_Strict):
    length_m: Length = Field(description="along the axis")
    aft_diameter_m: Diameter = Field(description="the diameter at its aft end, below the body's")
    position_m: Position = Field(description="its forward end, in the rocket's coordinates [m]")


class TransitionConfig(_Strict):
    """A conical section of the body, narrowing or widening; the body behind it keeps its aft diameter."""

    position_m: Position = Field(description="its forward end, in the rocket's coordinates [m]")
    length_m: Length = Field(description="along the axis")
    fore_diameter_m: float = Field(ge=0, le=MAX_DIAMETER_M, description="at its forward end")
    aft_diameter_m: float = Field(ge=0, le=MAX_DIAMETER_M, description="at its aft end")
    cd_override: DragCoefficient | None = _added(
        None, "a drag coefficient on the reference area flown instead of the section's friction and pressure drag "
        "(and its base drag if it ends the body): OpenRocket's drag override; none: from its shape",
    )


class LaunchLugConfig(_Strict):
    """A launch lug, a tube along the body (one entry per lug)."""

    position_m: Position = Field(description="its forward end, in the rocket's coordinates [m]")
    length_m: Length
    outer_diameter_m: Diameter
    inner_diameter_m: float = Field(0.0, ge=0, le=MAX_DIAMETER_M, description="its bore (0: solid)")


class RailButtonConfig(_Strict):
    """A rail button (one entry per button)."""

    position_m: Position = Field(description="its axis, in the rocket's coordinates [m]")
    height_m: Length = Field(description="how far it stands off the body")
    outer_diameter_m: Diameter = Field(description="the flanges' diameter")
    inner_diameter_m: float = Field(0.0, ge=0, le=MAX_DIAMETER_M, description="the waist's diameter (0: no waist)")
    inner_height_m: float = Field(0.0, ge=0, le=MAX_LENGTH_M, description="the waist's height")


class GeometryConfig(_Strict):
    """External shape for the aerodynamic build-up; positions in the rocket's coordinates [m]."""

    body_diameter_m: Diameter = Field(description="the nose's base diameter (the reference length d)")
    length_m: Length = Field(description="from the nose tip to the aft end")
    nose: NoseConfig
    fins: list[FinSetConfig] = []
    canards: FinSetConfig | None = None
    boat_tail: BoatTailConfig | None = None
    transitions: list[TransitionConfig] = _added([], "conical sections of the body, narrowing or widening, anywhere")
    launch_lugs: list[LaunchLugConfig] = _added([], "launch lugs (their drag)")
    rail_buttons: list[RailButtonConfig] = _added([], "rail buttons (their drag)")
    surface_roughness_m: Roughness = _added(
        DEFAULT_ROUGHNESS_M,
        "roughness height of the body's surface; OpenRocket's finishes: rough 5e-4, unfinished 1.5e-4, "
        "regular paint 6e-5, smooth paint 2e-5, polished 2e-6",
    )

    @model_validator(mode="after")
    def _nose_on_the_body(self):
        if self.nose.length_m > self.length_m:
            raise ValueError(f"nose.length_m ({self.nose.length_m}) exceeds length_m ({self.length_m}), "
                             "the length from the nose tip to the aft end")  # fmt: skip
        return self



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
    releases: str | None = _added(
        None, "the name of another parachute cut away when this one starts opening (delay_s after its "
        "trigger), its drag gone from then: a drogue released by the main (none: every canopy stays attached)",
    )


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
        description="the rocket without propellant; the motor's casing included unless rocket.motor.dry_mass_kg gives it apart "
        "(a motor named by rocket.motor.designation gives it apart unless its dry_mass_kg is set to 0)"
    )
    dry_cg_m: Position
    dry_inertia_kgm2: list[Inertia] = Field(min_length=2, max_length=2, description="[axial, transverse]")
    rear_lug_m: Position = Field(description="the rear launch lug's aft end or rail button, in the rocket's coordinates "
                                 "[m]; alone, the rocket leaves the rail when it passes the rail's top")
    upper_lug_m: Position | None = _added(
        None, "the upper (forward) of two rail buttons or lugs, in the rocket's coordinates [m]: the rocket leaves "
        "the rail when it passes the rail's top, the pivot on the rear one until that leaves too not modelled (none: "
        "one lug, rear_lug_m)",
    )
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
        released = [p.releases for p in self.parachutes if p.releases is not None]
        for i, chute in enumerate(self.parachutes):
            if chute.releases is not None and (chute.releases not in names or chute.releases == chute.name):
                raise ValueError(f"parachutes.{i}.releases: {chute.releases!r} is not another parachute of the "
                                 f"rocket ({', '.join(names)})")  # fmt: skip
            if released.count(chute.name) > 1:
                raise ValueError(f"parachute {chute.name!r} is released by more than one parachute")
        if self.aero.model != "linear" and self.aero.tables == "buildup" and self.geometry is None:
            raise ValueError("aero.tables = 'buildup' needs the rocket's [rocket.geometry]")
        return self

    @model_validator(mode="after")
    def _upper_lug_forward(self):
        if self.upper_lug_m is not None and not self.from_nose(self.upper_lug_m) < self.from_nose(self.rear_lug_m):
            raise ValueError(f"upper_lug_m ({self.upper_lug_m:g} m) must be forward of rear_lug_m "
                             f"({self.rear_lug_m:g} m), nearer the nose")  # fmt: skip
        return self


class SiteConfig(_Strict):
    """The launch site: the pad's position (the NED origin)."""

    name: str = Field("", description="a label")
    latitude_deg: float = Field(ge=-90, le=90, description="the pad's geodetic latitude, north positive")
    longitude_deg: float = Field(ge=-180, le=360, description="the pad's longitude, east positive")
    altitude_m: float = Field(ge=-400, le=30000, description="pad altitude above mean sea level")


class LaunchConfig(_Strict):
    """The launch rail."""

    rail_length_m: Length = Field(description="the rail's length; the rocket leaves when its upper lug (rocket.upper_lug_m, "
                                  "else rear_lug_m) passes the end")
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
        first, last = IGRF14_VALIDITY
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
    gravity: Literal["constant", "inverse_square"] = _added(
        "constant", "'constant': standard gravity 9.80665 m/s² everywhere; 'inverse_square': 9.80665·(r0/(r0 + z))² "
        "at the altitude z above mean sea level, r0 = 6356766 m (US Standard Atmosphere 1976)",
    )

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
    point_mass_descent: bool = Field(
        True, description="in steady descent, once the body's swing has died out (swing_settle_s), fly it as a point "
                          "mass in periods of up to 5 s (docs/validation.md, 'Step size')"
    )  # fmt: skip
    swing_settle_s: float = Field(
        5.0, ge=0, le=60.0, description="seconds flown with 6 degrees of freedom after a canopy has settled or a "
                                        "wind-layer boundary was crossed, before a point mass"
    )  # fmt: skip
    event_periods: bool = Field(
        True, description="without [gnc] and [avionics], fly periods of open_loop_dt_s that end at the rail exit, a "
                          "wind-layer boundary and a thrust-curve point (docs/validation.md, 'Step size'); false: every "
                          "period control_dt_s until steady descent, as with a controller (pairs flights with a "
                          "controller's)"
    )  # fmt: skip
    open_loop_dt_s: float | None = Field(
        None, ge=MIN_CONTROL_DT_S, le=0.1, description="period without [gnc] and [avionics] when event_periods is true "
                                                       "(default control_dt_s; measure a longer one with "
                                                       "benchmarks/step_accuracy.py: docs/validation.md, 'Step size')"
    )  # fmt: skip
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
    wind_gain: float | None = Field(
        None, ge=0, le=MAX_WIND_GAIN,
        description="k_w: the reference aimed upwind by k_w times the wind the attitude reveals (none: not aimed, the thesis's)",
    )
    wind_time_constant_s: float = Field(
        2.0, gt=0, le=MAX_FLIGHT_TIME_S, description="the low-pass on the upwind aim's wind (with wind_gain) [s]"
    )

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
        DEFAULT_SPEEDS_MPS, min_length=2, description="axial speeds of the design grid, increasing (left out: these, grown to cover the nominal flight)"
    )
    altitudes_m: list[Annotated[float, Field(ge=0, le=MAX_ALTITUDE_M)]] = Field(
        DEFAULT_ALTITUDES_M, min_length=1, description="heights above the pad of the design grid, increasing (left out: these, grown to cover the nominal flight)"
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
    canards: bool = _added(
        True, "false: the flight software's navigation alone, no canard controller (the canards neutral): what the air "
        "brakes and the parachutes' triggers read on a rocket flown without steering"
    )
    servo: ServoConfig = ServoConfig()
    guidance: GuidanceConfig = GuidanceConfig()
    control: ControlConfig = ControlConfig()
    filters: FiltersConfig = FiltersConfig()


class AirbrakePanelsConfig(_Strict):
    """Air-brake panels sliding out of the body: each a flat plate normal to the flow, ``count`` of them ``width_m``
    wide and ``max_extension_m`` out at full deployment; ΔCA from Hoerner's plate drag and the stagnation pressure's
    rise with Mach (``aero.airbrakes``)."""

    count: int = Field(ge=1, le=MAX_AIRBRAKE_PANELS, description="number of panels")
    width_m: Length = Field(description="each panel's width across the flow")
    max_extension_m: Length = Field(description="how far each panel stands out of the body at full deployment")
    cd: float = Field(HOERNER_SQUARE_PLATE_CD, gt=0, le=MAX_DRAG_COEFFICIENT,
                      description="a panel's drag coefficient on its area at low Mach (Hoerner's square plate)")


class AirbrakeTableConfig(_Strict):
    """A team's own ΔCA (on the aerodynamic reference area) against deployment (0 … 1) and Mach: ``delta_ca[i][j]`` at
    ``deployments[i]`` and ``machs[j]``, interpolated, clamped at the edges."""

    deployments: list[Annotated[float, Field(ge=0, le=1)]] = Field(min_length=2, description="from 0 to 1, increasing")
    machs: list[Mach] = Field(min_length=2, description="increasing")
    delta_ca: list[list[DragCoefficient]] = Field(min_length=2, description="one row per deployment, one value per Mach")

    @model_validator(mode="after")
    def _grid(self):
        if self.deployments[0] != 0.0 or self.deployments[-1] != 1.0 or np.any(np.diff(self.deployments) <= 0):
            raise ValueError(f"deployments must increase from 0 to 1, got {self.deployments}")
        if np.any(np.diff(self.machs) <= 0):
            raise ValueError(f"machs must be strictly increasing, got {self.machs}")
        if len(self.delta_ca) != len(self.deployments) or any(len(row) != len(self.machs) for row in self.delta_ca):
            raise ValueError(f"delta_ca needs {len(self.deployments)} rows (deployments) of {len(self.machs)} values (machs)")
        return self


class AirbrakeServoConfig(_Strict):
    """The deployment servo: first order 1/(τs + 1) from retracted (0) to fully out (1), optional slew-rate limit."""

    time_constant_s: float = Field(0.1, gt=0, le=MAX_SERVO_TIME_CONSTANT_S, description="τ [s]")
    rate_limit_per_s: float | None = Field(None, gt=0, le=MAX_AIRBRAKE_RATE_PER_S,
                                           description="largest deployment rate [1/s] (none: no slew limit)")


class AirbrakeReferenceConfig(_Strict):
    """The reference-trajectory PI of Skyward's flight software (docs/airbrakes.md): reference coasts to the target
    apogee with the brakes held at ``levels``, a PI on the climb rate's excess over the nearest one, its gains designed
    for the vertical motion's second-order response (K_p = 2ζω·m, K_i = ω²·m on the coast mass m) unless given."""

    levels: list[Annotated[float, Field(gt=0, lt=1)]] = Field(
        [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9], min_length=2, max_length=MAX_AIRBRAKE_REFERENCES,
        description="the deployments the reference coasts are computed with, increasing (Skyward's: 10 % … 90 %)")
    natural_frequency_rad_s: float = Field(1.5, gt=0, le=MAX_AIRBRAKE_NATURAL_FREQUENCY_RAD_S,
                                           description="ω [rad/s] of the designed response (Skyward's gains: ~1.5)")
    damping: float = Field(0.8, gt=0, le=MAX_AIRBRAKE_DAMPING, description="ζ [-] of the designed response (Skyward's: ~0.8)")
    kp_n_s_per_m: float | None = Field(None, ge=0, le=MAX_AIRBRAKE_PI_GAIN, description="K_p [N/(m/s)] (none: designed)")
    ki_n_per_m: float | None = Field(None, ge=0, le=MAX_AIRBRAKE_PI_GAIN, description="K_i [N/m] (none: designed)")

    @model_validator(mode="after")
    def _increasing(self):
        if np.any(np.diff(self.levels) <= 0):
            raise ValueError(f"levels must be strictly increasing, got {self.levels}")
        return self


class AirbrakesControlConfig(_Strict):
    """Air brakes and the flight software that flies them to a target apogee (docs/airbrakes.md): the drag they add
    (``panels`` or ``table``), their servo, when they may open, and the controller: a ballistic prediction of the
    apogee from the navigation ([gnc]'s, else the true state) with integral feedback on its error, its gain designed at
    set-up for ``response_time_s`` unless ``gain_per_m_s`` is given (``rocketmc airbrakes design``). Fixed per
    campaign."""

    target_apogee_m: Height = Field(description="the apogee to reach, above the pad [m]")
    panels: AirbrakePanelsConfig | None = Field(None, description="the drag from the panels' geometry")
    table: AirbrakeTableConfig | None = Field(None, description="the drag from a team's own table")
    servo: AirbrakeServoConfig = AirbrakeServoConfig()
    max_mach: float = Field(0.8, gt=0, le=MAX_AIRBRAKE_MACH, description="the brakes stay in at or above this Mach")
    after_burnout_s: float = Field(0.5, ge=0, le=MAX_FLIGHT_TIME_S,
                                   description="the brakes may open this long after the nominal burnout [s]")
    response_time_s: float = Field(1.0, gt=0, le=MAX_FLIGHT_TIME_S,
                                   description="the time constant the gain is designed for at the nominal window's start [s]")
    gain_per_m_s: float | None = Field(None, ge=0, le=MAX_AIRBRAKE_GAIN,
                                       description="K_i [1/(m·s)] (none: designed for response_time_s)")
    controller: Literal["prediction", "reference_pi"] = _added(
        "prediction", "the law: the apogee prediction with integral feedback, or Skyward's reference-trajectory PI")
    reference: AirbrakeReferenceConfig | None = _added(
        None, "the reference-trajectory PI's numbers (controller = 'reference_pi'; none: its defaults)")

    @model_validator(mode="after")
    def _one_drag(self):
        if (self.panels is None) == (self.table is None):
            raise ValueError("give the brakes' drag as exactly one of panels or table")
        return self

    @model_validator(mode="after")
    def _one_law(self):
        if self.controller == "prediction" and self.reference is not None:
            raise ValueError("reference: read only by controller = 'reference_pi' (this campaign flies 'prediction')")
        if self.controller == "reference_pi" and self.gain_per_m_s is not None:
            raise ValueError("gain_per_m_s: the prediction law's gain; controller = 'reference_pi' takes "
                             "reference.kp_n_s_per_m and reference.ki_n_per_m")  # fmt: skip
        return self

    @property
    def reference_pi(self) -> AirbrakeReferenceConfig | None:
        """The reference-trajectory PI's numbers, its defaults if not given; None with the prediction law."""
        return None if self.controller == "prediction" else self.reference or AirbrakeReferenceConfig()


DEFAULT_PART = "thesis"
"""The part of a sensor no part is named for: the thesis's set provides every sensor (docs/gnc.md §1)."""
SensorValue = Annotated[float, Field(ge=-MAX_SENSOR_VALUE, le=MAX_SENSOR_VALUE)]
SensorSpread = Annotated[float, Field(ge=0, le=MAX_SENSOR_VALUE)]


class SensorConfig(_Strict):
    """What every sensor has: its part (data/sensors/<part>.toml, whose values the other fields override),
    its sampling rate [Hz] (dividing the GNC rate), its latency [s] (a multiple of the GNC period) and a
    switch to turn its errors off (the truth at each sample, on the same schedule)."""

    part: str = Field(description="data/sensors/<part>.toml, whose values the other keys override")
    truth_only: bool = Field(False, description="no errors: the truth at each sample, on the same schedule")
    rate_hz: float = Field(gt=0, le=1.0 / MIN_CONTROL_DT_S, description="sampling rate, dividing the GNC rate")
    latency_s: float = Field(0.0, ge=0, le=MAX_SENSOR_LATENCY_S, description="a whole number of GNC periods")


class ChannelConfig(SensorConfig):
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


class GnssConfig(SensorConfig):
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


SENSOR_CONFIGS: dict[str, type[SensorConfig]] = {
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
            raise ValueError(f"part: expected a part name, got {shown(name)}")
        try:
            part = load_part(name)
        except KeyError:
            raise ValueError(f"unknown part {shown(name)} (known: {', '.join(part_names(info.field_name))})") from None
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


class StuckAirbrakesConfig(_TimedFault):
    """Air brakes that stop moving at the fault time: frozen at their deployment then, or jammed at ``deployment``
    (0: stuck retracted, 1: stuck fully out)."""

    deployment: float | None = Field(None, ge=0, le=1, description="where they are stuck, 0 … 1 (none: where they were)")


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
    stuck_airbrakes: StuckAirbrakesConfig | None = _added(None, "the air brakes stuck from a time on (none: never)")

    def active(self) -> dict[str, _Fault]:
        """The faults some flight can have (given, probability above 0), by name in the table's order."""
        return {name: f for name in type(self).model_fields if (f := getattr(self, name)) is not None
                and f.probability > 0.0}  # fmt: skip


FAULT_SECTIONS = {"stuck_canard": "gnc", "slow_canard": "gnc", "stuck_airbrakes": "airbrakes", "gnss_outage": "avionics",
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
    airbrakes: AirbrakesControlConfig | None = _added(
        None, "air brakes flown to a target apogee by their flight software (docs/airbrakes.md); none: none"
    )

    @field_validator("name")
    @classmethod
    def _label(cls, name: str) -> str:
        if not (name.strip() and len(name) <= MAX_NAME_LENGTH and name.isprintable()):
            raise ValueError(f"expected a label: 1 to {MAX_NAME_LENGTH} printable characters on one line, not blank")
        return name


    @model_validator(mode="after")
    def _one_kind_of_airbrakes(self):
        if self.airbrakes is not None and self.rocket.airbrakes is not None:
            raise ValueError("airbrakes: the rocket has a drag schedule already (rocket.airbrakes): fly one or the other")
        return self
