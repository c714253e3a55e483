"""Campaign files (TOML): schema, validation and loading, on the host.

Errors are ``ConfigError`` with one line that names the field (dotted path), what was expected and
what was found; the CLI prints it and exits with code 2.
"""

from __future__ import annotations

import copy
import dataclasses
import tomllib
from importlib import resources
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from ..aero.geometry import NOSE_KINDS, BoatTail, FinSet, Nose, RocketGeometry
from ..aero.io import load_aero
from ..aero.model import LinearAero, TableAero, simplify
from ..aero.sources import BUILTIN_TABLES, build_up_tables, power_on_axial_increment, with_axial_curve, with_canards
from ..aero.tables import AeroTables
from ..dynamics.propulsion import ThrustCurveError, cumulative_impulse, read_thrust_curve
from ..env.atmosphere import G0
from ..env.wind import read_wind_profile
from ..math.table import Table

DISPERSIBLE_SECTIONS = ("rocket", "launch", "environment")
FIXED_PER_CAMPAIGN = ("rocket.reference_point_m", "rocket.nose_position_m", "rocket.geometry.", "rocket.aero.")
"""Numbers that define the body frame or build the aerodynamic tables once per campaign: not
dispersible, except those of ``DISPERSIBLE_AERO``."""
DISPERSIBLE_AERO = ("rocket.aero.drag_scale", "rocket.aero.cl0", "rocket.aero.linear.")
ISP_TOLERANCE = 0.02  # relative mismatch allowed between isp_s and the curve's impulse per propellant mass


class ConfigError(ValueError):
    """A campaign that cannot be flown; the message is one line naming the field."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]


class MotorConfig(_Strict):
    """Solid motor; positions in the rocket's coordinates [m]."""

    thrust_curve: str = Field(description="RASP .eng or CSV (time s, thrust N); built-in name or path")
    propellant_mass_kg: Positive
    isp_s: Positive | None = Field(None, description="checked against the curve's impulse / propellant")
    ignition_delay_s: NonNegative = 0.0
    thrust_scale: Positive = 1.0
    nozzle_m: float
    grain_outer_diameter_m: Positive
    grain_inner_diameter_m: NonNegative
    grain_length_m: Positive
    grain_center_m: float | None = Field(None, description="default: the grain ends at the nozzle exit")
    dry_mass_kg: NonNegative = Field(0.0, description="casing, nozzle, closures: 0 if the rocket's dry mass has them")
    dry_inertia_kgm2: list[NonNegative] = Field([0.0, 0.0], min_length=2, max_length=2,
                                                description="[axial, transverse] about the motor's dry CG")
    dry_cg_m: float | None = Field(None, description="default: the grain centre")

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

    reference_area_m2: Positive
    reference_length_m: Positive
    ca0_mach: list[NonNegative] = Field(min_length=2)
    ca0: list[NonNegative] = Field(min_length=2)
    ca_u: list[float] = Field([0.0, 0.0, 0.0, 0.0], min_length=4, max_length=4)
    cn_alpha: float
    cn_delta: float = 0.0
    cm_alpha: float
    cm_delta: float = 0.0
    cl_delta: float = 0.0
    cy_r: float = 0.0
    cn_q: float = 0.0
    cl_p: float = Field(0.0, le=0)
    cm_q: float = Field(0.0, le=0)

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
    reference_area_m2: Positive | None = Field(None, description="for table files that do not state it")
    reference_length_m: Positive | None = None
    moment_reference_m: float | None = Field(None, description="in the rocket's coordinates; for files that do not state it")
    cd_mach: list[NonNegative] | None = Field(None, description="Cd-vs-Mach curve replacing the zero-lift axial force")
    cd: list[NonNegative] | None = None
    cd_power_on: list[NonNegative] | None = Field(None, description="Cd at cd_mach while the motor burns")
    drag_scale: Positive = 1.0
    cl0: float = Field(0.0, description="rolling-moment offset (fin misalignment)")
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
    kind: Literal[NOSE_KINDS]
    length_m: Positive


class FinSetConfig(_Strict):
    """Trapezoidal panels (aero/geometry.py ``FinSet``); position_m: the root's leading edge."""

    count: int = Field(ge=1, le=8)
    root_chord_m: Positive
    tip_chord_m: NonNegative
    span_m: Positive
    sweep_m: float = 0.0
    position_m: float
    thickness_m: Positive = 0.005
    cant_deg: float = Field(0.0, ge=-15, le=15)
    first_panel_deg: float = 0.0


class BoatTailConfig(_Strict):
    length_m: Positive
    aft_diameter_m: Positive
    position_m: float


class GeometryConfig(_Strict):
    """External shape for the aerodynamic build-up; positions in the rocket's coordinates [m]."""

    body_diameter_m: Positive
    length_m: Positive
    nose: NoseConfig
    fins: list[FinSetConfig] = []
    canards: FinSetConfig | None = None
    boat_tail: BoatTailConfig | None = None

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

    name: str = Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*$")
    cd: Positive
    area_m2: Positive
    deploy_altitude_m: NonNegative | None = None
    delay_s: NonNegative = 0.0
    opening_time_s: NonNegative = 0.0
    attach_m: float


class AirbrakesConfig(_Strict):
    """Extra axial-force coefficient ΔCA (on the aerodynamic reference area) of deployed airbrakes as a
    schedule of time since motor ignition [s], linear in between, 0 outside."""

    time_s: list[float] = Field(min_length=2)
    delta_ca: list[NonNegative] = Field(min_length=2)

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

    coordinate_system: Literal["nose_to_tail", "tail_to_nose"] = "nose_to_tail"
    nose_position_m: float = 0.0
    reference_point_m: float = Field(description="origin of the body frame and, by default, the moment reference")
    dry_mass_kg: Positive
    dry_cg_m: float
    dry_inertia_kgm2: list[Positive] = Field(min_length=2, max_length=2, description="[axial, transverse]")
    rear_lug_m: float
    canopy_roll_damping: float = Field(-5.0, le=0)
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
    name: str = ""
    latitude_deg: float = Field(ge=-90, le=90)
    longitude_deg: float = Field(ge=-180, le=360)
    altitude_m: float = Field(ge=-400, le=30000, description="pad altitude above mean sea level")


class LaunchConfig(_Strict):
    rail_length_m: Positive
    elevation_deg: float = Field(gt=0, le=90, description="rail angle above the horizon")
    azimuth_deg: float = Field(ge=-360, le=720, description="clockwise from north")


class WindLayerConfig(_Strict):
    speed_mps: NonNegative
    from_deg: float = Field(ge=-360, le=720, description="direction the wind blows from, clockwise from north")
    thickness_m: Positive | None = Field(None, description="not needed for the top layer")


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

    model: Literal["layers", "constant", "power_law", "profile"] = "layers"
    layers: list[WindLayerConfig] | None = Field(None, min_length=1)
    speed_mps: NonNegative | None = Field(None, description="constant wind, or power law at reference_height_m")
    from_deg: float | None = Field(None, ge=-360, le=720, description="direction the wind blows from")
    reference_height_m: Positive | None = None
    exponent: float | None = Field(None, ge=0, le=1, description="power-law exponent (1/7 over open terrain)")
    file: str | None = Field(None, description="CSV: altitude_agl_m (or altitude_msl_m), speed_mps, from_deg")
    speed_scale: NonNegative | None = None

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

    severity: float = Field(ge=0, le=3)
    w20_mps: NonNegative | None = None


class EnvironmentConfig(_Strict):
    wind: WindConfig = WindConfig()
    turbulence: TurbulenceConfig | None = None


class Dispersion(_Strict):
    """How one parameter is drawn: normal (mean defaults to the nominal value; optional low/high
    clip the draw), uniform [low, high], or a choice among values (optional weights)."""

    dist: Literal["normal", "uniform", "choice"]
    mean: float | None = None
    std: NonNegative | None = None
    low: float | None = None
    high: float | None = None
    values: list[float] | None = Field(None, min_length=1)
    weights: list[NonNegative] | None = None

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
    control_dt_s: float = Field(0.02, gt=0, le=0.1, description="GNC period")
    substeps: int = Field(1, ge=1, le=100, description="RK4 steps per control period")
    descent_dt_s: float = Field(0.25, gt=0, le=1.0, description="longest period in steady descent under canopy")
    descent_h_omega: float = Field(
        1.0, gt=0, le=2.0, description="largest RK4 step times the body's pendulum rate under canopy (RK4 is stable to 2.8)"
    )
    max_time_s: Positive = 300.0
    chunk_size: int = Field(1000, ge=1, description="realizations per compiled batch")


class CampaignConfig(_Strict):
    name: str
    description: str = ""
    n_realizations: int = Field(ge=1)
    seed: int = Field(ge=0, lt=2**32)
    rocket: RocketConfig
    site: SiteConfig
    launch: LaunchConfig
    environment: EnvironmentConfig = EnvironmentConfig()
    dispersions: dict[str, Dispersion] = {}
    simulation: SimulationConfig = SimulationConfig()


@dataclasses.dataclass(frozen=True)
class Campaign:
    """A validated campaign: the config, its TOML text, the thrust curve, the nominal values of
    every dispersible number, keyed by dotted path (``"rocket.dry_mass_kg"``, ``"rocket.aero.ca0.2"``),
    the aerodynamic model with its tables (None for ``model = "linear"``, built per flight), the
    folder its relative file names are resolved from, and the measured wind profile (altitude above
    ground [m], speed [m/s], from-direction [rad]) when the wind model is ``profile``."""

    config: CampaignConfig
    text: str
    thrust_time_s: np.ndarray
    thrust_n: np.ndarray
    nominal: dict[str, float]
    aero: TableAero | LinearAero | None
    base_dir: Path
    wind_profile: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def with_overrides(
        self, n_realizations: int | None = None, seed: int | None = None, aero_model: str | None = None
    ) -> Campaign:
        """The same campaign with N, the seed and/or the aerodynamic model replaced (CLI options)."""
        data = self.config.model_dump()
        data.update({k: v for k, v in (("n_realizations", n_realizations), ("seed", seed)) if v is not None})
        if aero_model is None or aero_model == self.config.rocket.aero.model:
            return dataclasses.replace(self, config=_validate(data))
        data["rocket"]["aero"]["model"] = aero_model
        config = _validate(data)
        return dataclasses.replace(self, config=config, aero=_aero_model(config.rocket, self.base_dir))


def _format_error(error: ValidationError) -> str:
    first = error.errors()[0]
    path = ".".join(str(p) for p in first["loc"]) or "(top level)"
    if first["type"] == "extra_forbidden":
        return f"{path}: unknown key"
    if first["type"] == "missing":
        return f"{path}: missing (required)"
    message = first["msg"].removeprefix("Value error, ")
    found = first.get("input")
    shown = "" if isinstance(found, dict | list) else f" (got {found!r})"
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
    resource = resources.files("rocketmc") / "data" / "rockets" / f"{name}.toml"
    if not resource.is_file():
        available = sorted(p.name.removesuffix(".toml") for p in resource.parent.iterdir())
        raise ConfigError(f"rocket.preset: unknown preset {name!r} (available: {', '.join(available)})")
    return tomllib.loads(resource.read_text())


def _resolve_data_file(name: str, base_dir: Path, folder: str, field: str) -> Path:
    """``name`` beside the campaign, else in the package's ``data/<folder>``."""
    candidate = base_dir / name
    if candidate.is_file():
        return candidate
    builtin = resources.files("rocketmc") / "data" / folder / name
    if builtin.is_file():
        return Path(str(builtin))
    raise ConfigError(f"{field}: file not found: {name!r} (neither beside the campaign nor built in)")


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


def _check_dispersions(config: CampaignConfig, nominal: dict[str, float]) -> None:
    """Each dispersion names a dispersible number and every value it can draw passes validation."""
    data = config.model_dump(exclude={"dispersions"})
    for path, d in config.dispersions.items():
        field = f"dispersions.{path}"
        if path.startswith(FIXED_PER_CAMPAIGN) and not path.startswith(DISPERSIBLE_AERO):
            raise ConfigError(f"{field}: fixed for the whole campaign (it defines the body frame or builds the "
                              "aerodynamic tables); disperse rocket.aero.drag_scale or rocket.aero.cl0 instead")  # fmt: skip
        if path not in nominal:
            raise ConfigError(f"{field}: not a dispersible number (expected a numeric field of "
                              f"{'/'.join(DISPERSIBLE_SECTIONS)}, e.g. 'rocket.dry_mass_kg')")  # fmt: skip
        for value in [d.mean, d.low, d.high, *(d.values or [])]:
            if value is None:
                continue
            try:
                CampaignConfig.model_validate(_set_path(data, path, value))
            except ValidationError as e:
                raise ConfigError(f"{field}: draws a value {value!r} that is out of range: {_format_error(e)}") from None


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

    path = _resolve_data_file(config.rocket.motor.thrust_curve, base_dir, "motors", "rocket.motor.thrust_curve")
    try:
        time_s, thrust_n = read_thrust_curve(path)
    except ThrustCurveError as e:
        raise ConfigError(f"rocket.motor.thrust_curve: {e}") from None
    motor = config.rocket.motor
    if motor.isp_s is not None:
        curve_isp = cumulative_impulse(time_s, thrust_n)[-1] / (G0 * motor.propellant_mass_kg)
        if abs(curve_isp / motor.isp_s - 1.0) > ISP_TOLERANCE:
            raise ConfigError(f"rocket.motor.isp_s: {motor.isp_s} s disagrees with the curve's impulse per "
                              f"propellant mass ({curve_isp:.1f} s) by more than {ISP_TOLERANCE:.0%}")  # fmt: skip

    dump = config.model_dump()
    nominal = {k: v for s in DISPERSIBLE_SECTIONS for k, v in flatten_numbers(dump[s], s).items()}
    _check_dispersions(config, nominal)
    aero = _aero_model(config.rocket, base_dir)
    return Campaign(config, text, time_s, thrust_n, nominal, aero, base_dir, _wind_profile(config, base_dir))


def _wind_profile(config: CampaignConfig, base_dir: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    wind = config.environment.wind
    if wind.model != "profile":
        return None
    path = _resolve_data_file(wind.file, base_dir, "wind", "environment.wind.file")
    try:
        return read_wind_profile(path, config.site.altitude_m)
    except (ValueError, OSError) as err:
        raise ConfigError(f"environment.wind.file: {err}") from None


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
    return parse_campaign(path.read_text(), path.parent)
