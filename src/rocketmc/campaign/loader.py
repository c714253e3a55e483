"""Campaign files (TOML) to a ``Campaign``, on the host: the one builder (``campaign_from_dict``), which validates
the tables against the schema, runs the checks across tables and files, reads the data files and designs the gains.

Errors are ``ConfigError`` with one line that names the field (dotted path), what was expected and
what was found; the CLI prints it and exits with code 2.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import hashlib
import math
import tomllib
from collections.abc import Mapping
from datetime import datetime
from importlib import resources
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from ..aero.geometry import BoatTail, FinSet, LaunchLug, Nose, RailButton, RocketGeometry, Transition
from ..aero.io import load_aero
from ..aero.model import LinearAero, TableAero, simplify
from ..aero.sources import BUILTIN_TABLES, build_up_tables, power_on_axial_increment, with_axial_curve, with_canards
from ..aero.tables import AeroTables
from ..dynamics.motor_library import MotorLibraryError, casing_inertia_kgm2, eng_header, estimated_grain, find_motor
from ..dynamics.propulsion import ThrustCurveError, cumulative_impulse, read_thrust_curve
from ..env.atmosphere import G0
from ..env.weather import Weather, WeatherError, read_weather
from ..env.wind import read_wind_profile
from ..math.table import Table
from .errors import ConfigError, shown
from .airbrakes import design_airbrakes
from .gains import design_inputs, design_schedule
from .limits import (
    DISPERSIBLE_SECTIONS,
    GEOMETRY_TOLERANCE_M,
    ISP_TOLERANCE,
    MAX_WIND_MPS,
    NORMAL_REACH_STD,
    SOLID_ISP_S,
    fixed_reason,
)
from .model import airframe_params, sample_period_ticks, sensor_ticks
from .record import Campaign
from .schema import (
    FAULT_SECTIONS,
    SENSOR_CONFIGS,
    SPREAD_ELEMENTS,
    SPREADS,
    CampaignConfig,
    Dispersion,
    FinSetConfig,
    RocketConfig,
)


def with_overrides(
    campaign: Campaign, n_realizations: int | None = None, seed: int | None = None, aero_model: str | None = None,
    controller: bool | None = None, sensors: bool | None = None, navigation: str | None = None,
    values: Mapping[str, object] | None = None, airbrakes: bool | None = None,
) -> Campaign:  # fmt: skip
    """``campaign`` loaded again by the one builder (``campaign_from_dict``: every check run, the gains designed
    again) from its validated tables with the overrides applied: N, the seed and/or the aerodynamic model replaced
    (CLI options); controller: True adds a [gnc] section of defaults if there is none, False removes it and its
    servo dispersions and its faults (the same flights with the canards neutral); sensors: True adds an [avionics]
    section of defaults (the thesis's parts) if there is none and flies the controller on raw sensors (or on its
    filters, if the campaign's navigation is "filters"), False removes it and its dispersions and flies the
    controller on perfect navigation (their faults removed too); navigation: the controller's ("truth", "sensors"
    or "filters"), with sensors to match; airbrakes: False removes the [airbrakes] (True is refused: they have no
    defaults); values: fields set by dotted path (``{"avionics.gyroscope.truth_only":
    True}``), after the options above, and dispersions by their parameter's path after ``dispersions.``: a table
    sets one, None removes it. The result file's campaign text stays the file's; the overrides given (N and the seed
    apart) are added to ``Campaign.overrides``."""
    switched = {name: value for name, value in (("aero_model", aero_model), ("controller", controller),
                ("sensors", sensors), ("navigation", navigation), ("airbrakes", airbrakes)) if value is not None}  # fmt: skip
    if airbrakes:
        raise ConfigError("airbrakes: there are no default air brakes to add; write an [airbrakes] section")
    if navigation is not None:
        sensors = navigation != "truth"
    data = campaign.config.model_dump()
    spreads = sensor_spreads(campaign.config)  # drawn by the sensors' spreads, not the file: redrawn from the new ones
    data["dispersions"] = {k: d for k, d in data["dispersions"].items()
                           if k not in spreads or campaign.config.dispersions[k] != spreads[k]}  # fmt: skip
    data.update({k: v for k, v in (("n_realizations", n_realizations), ("seed", seed)) if v is not None})
    if aero_model is not None:
        data["rocket"]["aero"]["model"] = aero_model
    if airbrakes is False:
        data["airbrakes"] = None
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
    built = campaign_from_dict(data, campaign.base_dir, campaign.text)
    return dataclasses.replace(built, overrides={**campaign.overrides, **switched, **(values or {})})


def _misspelt(errors: list[dict]) -> tuple[dict, str] | None:
    """The first unknown key that looks like a required key missing beside it (``rocket.dry_mas_kg`` for
    ``rocket.dry_mass_kg``), with that key's name; None if there is none."""
    missing = [e["loc"] for e in errors if e["type"] == "missing"]
    for error in errors:
        if error["type"] != "extra_forbidden":
            continue
        *table, key = error["loc"]
        names = [str(loc[-1]) for loc in missing if list(loc[:-1]) == table]
        if close := difflib.get_close_matches(str(key), names, n=1):
            return error, close[0]
    return None


def _format_error(error: ValidationError) -> str:
    """One line for the first of pydantic's errors, the dotted path first; an unknown key that misspells a missing
    required one is reported first, as the misspelling."""
    errors = error.errors()
    first, meant = _misspelt(errors) or (errors[0], None)
    path = ".".join(str(p) for p in first["loc"]) or "(top level)"
    if first["type"] == "extra_forbidden":
        return f"{path}: unknown key" + ("" if meant is None else f" (did you mean '{meant}'?)")
    if first["type"] == "missing":
        return f"{path}: missing (required)"
    message = first["msg"].removeprefix("Value error, ")
    found = first.get("input")
    got = "" if isinstance(found, dict | list) else f" (got {shown(found)})"
    return f"{path}: {message}{got}"


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


def preset_rocket(name: str, base_dir: Path = Path(".")) -> dict:
    """The rocket table of a preset: a built-in one by name (``data/rockets/<name>.toml``), or a file of the user's
    (a name ending in ``.toml``, beside the campaign) holding the keys of a ``[rocket]`` table."""
    if name.endswith(".toml"):
        return _toml_file(name, base_dir, "rockets", "rocket.preset")[1]
    folder = resources.files("rocketmc") / "data" / "rockets"
    available = sorted(p.name.removesuffix(".toml") for p in folder.iterdir() if p.name.endswith(".toml"))
    if name not in available:
        raise ConfigError(f"rocket.preset: unknown preset {shown(name)} (available: {', '.join(available)}, "
                          "or a file name ending in .toml)")  # fmt: skip
    return tomllib.loads((folder / f"{name}.toml").read_text())


def _toml_file(name: str, base_dir: Path, folder: str, field: str) -> tuple[Path, dict]:
    """The TOML file ``name`` (beside the campaign, else built in ``data/<folder>``) and its tables."""
    path = _resolve_data_file(name, base_dir, folder, field)
    try:
        return path, tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ConfigError(f"{field}: {shown(name)} is not valid TOML ({e})") from None


def _extended(raw: dict, base_dir: Path, seen: tuple[Path, ...] = ()) -> dict:
    """The campaign's tables laid over those of the campaign it ``extends`` (a file beside it, else a built-in
    campaign), which may itself extend another (named from its own folder): tables merge key by key, every other
    value (an array of tables too) replaces the base's. The data files they name are looked up beside the campaign
    loaded."""
    if "extends" not in raw:
        return raw
    name = raw.pop("extends")
    if not isinstance(name, str):
        raise ConfigError(f"extends: expected a campaign file name (got {shown(name)})")
    path, base = _toml_file(name, base_dir, "campaigns", "extends")
    chain = (*seen, path.resolve())
    if path.resolve() in seen:
        raise ConfigError(f"extends: {' → '.join(shown(p.name) for p in chain)} is a circle")
    return _deep_merge(_extended(base, path.parent, chain), raw)


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
        raise ConfigError(f"{field}: cannot look up {shown(name)} ({err.strerror})") from None
    if exists:
        raise ConfigError(f"{field}: {shown(name)} is not a file (a folder?)")
    raise ConfigError(f"{field}: file not found: {shown(name)} (neither beside the campaign nor built in)")


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


def read_campaign_tables(path: str | Path) -> dict:
    """The tables of a campaign file with the campaigns it ``extends`` laid under them: what to edit and hand to
    ``campaign_from_dict(tables, path.parent)``."""
    path = Path(path)
    return _extended(_toml_file(path.name, path.parent, "campaigns", "campaign file")[1], path.parent, (path.resolve(),))


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
    raw = _extended(copy.deepcopy(raw), base_dir)
    rocket = raw.get("rocket")
    if isinstance(rocket, dict) and "preset" in rocket:
        overrides = {k: v for k, v in rocket.items() if k != "preset"}
        if not isinstance(rocket["preset"], str):
            raise ConfigError(f"rocket.preset: expected a string (got {rocket['preset']!r})")
        preset = preset_rocket(rocket["preset"], base_dir)
        if "designation" in (overrides.get("motor") or {}) and "thrust_curve" in (preset.get("motor") or {}):
            raise ConfigError(f"rocket.motor.designation: the preset {shown(rocket['preset'])} has its motor by "
                              "thrust_curve and its dry mass includes that motor's casing; to fly another motor, "
                              "write the rocket out without the preset")  # fmt: skip
        raw["rocket"] = _deep_merge(preset, overrides)
    if isinstance(raw.get("rocket"), dict):
        raw["rocket"] = _with_library_motor(raw["rocket"])
    config = _validate(raw)
    _check_geometry(config.rocket)
    _check_elevation_unit(config.launch.elevation_deg)

    field, path = _motor_file(config, base_dir)
    try:
        time_s, thrust_n = read_thrust_curve(path)
    except ThrustCurveError as e:
        raise ConfigError(f"{field}: {e}") from None
    _check_specific_impulse(config, cumulative_impulse(time_s, thrust_n)[-1])

    config = _with_sensor_spreads(config)
    nominal = _nominal_values(config)
    _check_dispersions(config, nominal)
    aero = _aero_model(config.rocket, base_dir)
    wind_profile, files, weather = _wind_profile(config, base_dir), _file_digests(config, base_dir), _weather(config, base_dir)
    schedule, inputs = None, None
    if config.gnc is not None and config.gnc.canards:
        inputs = design_inputs(config, airframe_params(config, time_s, thrust_n, aero, wind_profile, weather, nominal))
        schedule = design_schedule(config, inputs)
    airbrakes, airbrake_design = None, None
    if config.airbrakes is not None:
        airframe = airframe_params(config, time_s, thrust_n, aero, wind_profile, weather, nominal)
        airbrakes, airbrake_design = design_airbrakes(config, airframe)
    return Campaign(config, text, time_s, thrust_n, nominal, aero, base_dir, wind_profile, files, schedule, inputs,
                    weather, motor=eng_header(path), airbrakes=airbrakes, airbrake_design=airbrake_design)  # fmt: skip


def _with_library_motor(rocket: dict) -> dict:
    """The rocket table with a motor named by ``designation`` completed from the library where the table leaves a
    value out (the one place these defaults are made): the .eng header's propellant mass, the grain
    ``estimated_grain`` gives, the casing (total less propellant) as the motor's dry mass, and its inertia as a thin
    tube of the casing's size (``casing_inertia_kgm2``) of that dry mass. So ``rocket.dry_mass_kg`` is the rocket
    without its motor, unless the table sets ``dry_mass_kg = 0`` (its dry mass then includes the casing)."""
    motor = rocket.get("motor")
    if not (isinstance(motor, dict) and isinstance(motor.get("designation"), str)):
        return rocket  # the schema says what is wrong (and refuses a thrust_curve beside a designation)
    try:
        entry = find_motor(motor["designation"])
    except MotorLibraryError as e:
        raise ConfigError(f"rocket.motor.designation: {e}") from None
    outer, core, length = estimated_grain(entry)
    dry_mass_kg = motor.get("dry_mass_kg", entry.casing_mass_kg)
    defaults = {"propellant_mass_kg": entry.propellant_mass_kg, "grain_outer_diameter_m": outer,
                "grain_inner_diameter_m": core, "grain_length_m": length, "dry_mass_kg": dry_mass_kg}  # fmt: skip
    if isinstance(dry_mass_kg, int | float):  # else the schema refuses it
        defaults["dry_inertia_kgm2"] = list(casing_inertia_kgm2(entry, dry_mass_kg))
    return {**rocket, "motor": {**defaults, **motor}}


def _motor_file(config: CampaignConfig, base_dir: Path) -> tuple[str, Path]:
    """The field naming the motor's thrust curve and the file: the library's for a designation, else
    ``thrust_curve`` beside the campaign or built in."""
    motor = config.rocket.motor
    if motor.designation is not None:
        return "rocket.motor.designation", find_motor(motor.designation).path
    return "rocket.motor.thrust_curve", _resolve_data_file(motor.thrust_curve, base_dir, "motors",
                                                            "rocket.motor.thrust_curve")  # fmt: skip


def _check_specific_impulse(config: CampaignConfig, total_impulse_ns: float) -> None:
    """ConfigError unless the curve's impulse per propellant weight is a solid motor's (``SOLID_ISP_S``), and
    within ``ISP_TOLERANCE`` of ``isp_s`` where that is given."""
    motor = config.rocket.motor
    curve_isp = total_impulse_ns / (G0 * motor.propellant_mass_kg)
    if not SOLID_ISP_S[0] <= curve_isp <= SOLID_ISP_S[1]:
        raise ConfigError(f"rocket.motor.propellant_mass_kg: {motor.propellant_mass_kg:g} kg burnt over the curve's "
                          f"{total_impulse_ns:.0f} N·s is a specific impulse of {curve_isp:.0f} s, outside the "
                          f"{SOLID_ISP_S[0]:g}-{SOLID_ISP_S[1]:g} s of solid motors")  # fmt: skip
    if motor.isp_s is not None and abs(curve_isp - motor.isp_s) > ISP_TOLERANCE * motor.isp_s:
        raise ConfigError(f"rocket.motor.isp_s: {motor.isp_s} s disagrees with the curve's impulse per "
                          f"propellant mass ({curve_isp:.1f} s) by more than {ISP_TOLERANCE:.0%}")  # fmt: skip


def _check_elevation_unit(elevation_deg: float) -> None:
    """ConfigError if the rail's elevation is at most π/2: radians in a field of degrees (no rail is set 1.6° above
    the horizon)."""
    if elevation_deg <= math.pi / 2:
        raise ConfigError(f"launch.elevation_deg: {elevation_deg:g} looks like radians ({math.degrees(elevation_deg):.1f}°); "
                          "the rail's elevation is in degrees above the horizon")  # fmt: skip


def _check_geometry(rocket: RocketConfig) -> None:
    """The build-up's shape can be built: every fin set's and the canards' root chord on the body (from the
    nose tip to the aft end), the canards clear of every fin set, a boat-tail behind the nose and ending at
    or before the aft end, narrowing; the transitions between the nose's end and the aft end (the
    boat-tail's front), one after the other without overlapping; lugs and buttons on the body; one line
    naming the field."""
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
    end = length if tail is None else rocket.from_nose(tail.position_m)
    previous_end, previous = g.nose.length_m, "the nose"
    for i, t in sorted(enumerate(g.transitions), key=lambda item: rocket.from_nose(item[1].position_m)):
        start = rocket.from_nose(t.position_m)
        if start < previous_end - eps or start + t.length_m > end + eps:
            raise ConfigError(f"rocket.geometry.transitions.{i}.position_m: the transition spans {start:g} to "
                              f"{start + t.length_m:g} m from the nose tip, overlapping {previous} (ending at "
                              f"{previous_end:g} m) or past {'the boat-tail' if tail else 'the aft end'} ({end:g} m)")  # fmt: skip
        previous_end, previous = start + t.length_m, f"transitions.{i}"
    for path, parts in (("launch_lugs", g.launch_lugs), ("rail_buttons", g.rail_buttons)):
        for i, part in enumerate(parts):
            start = rocket.from_nose(part.position_m)
            if not -eps <= start <= length + eps:
                raise ConfigError(f"rocket.geometry.{path}.{i}.position_m: {start:g} m from the nose tip, off the body "
                                  f"(0 to length_m = {length:g} m)")  # fmt: skip


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
        if getattr(config, section) is None or (section == "gnc" and not config.gnc.canards):
            acts_on = {"gnc": "the canard servos", "airbrakes": "the air brakes"}.get(section, "the sensors")
            raise ConfigError(f"faults.{name}: needs [{section}] ({acts_on} it acts on)"
                              + ("; gnc.canards is false" if getattr(config, section) is not None else ""))
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
    """SHA-256 of each file the campaign reads, by the field naming it (built-in files too; a library motor's by
    ``rocket.motor.designation``)."""
    motor_field, motor_path = _motor_file(config, base_dir)
    named = {}
    aero, wind = config.rocket.aero, config.environment.wind
    if aero.model != "linear" and aero.tables != "buildup" and aero.tables not in BUILTIN_TABLES:
        named["rocket.aero.tables"] = (aero.tables, "aero")
    if wind.model == "profile":
        named["environment.wind.file"] = (wind.file, "wind")
    if config.environment.atmosphere is not None:
        named["environment.atmosphere.file"] = (config.environment.atmosphere.file, "weather")
    paths = {motor_field: motor_path, **{field: _resolve_data_file(name, base_dir, folder, field)
                                        for field, (name, folder) in named.items()}}  # fmt: skip
    return {field: hashlib.sha256(path.read_bytes()).hexdigest() for field, path in paths.items()}


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


def rocket_geometry(rocket: RocketConfig) -> RocketGeometry:
    """The build-up's ``RocketGeometry`` of ``rocket.geometry``, its positions from the nose tip [m]."""
    g, from_nose = rocket.geometry, rocket.from_nose

    def fin_set(f: FinSetConfig) -> FinSet:
        return FinSet(**{**f.model_dump(), "position_m": from_nose(f.position_m)})

    def placed(kind, item):  # a part whose position_m is its front or axis: from the nose tip
        return kind(**{**item.model_dump(), "position_m": from_nose(item.position_m)})

    return RocketGeometry(
        g.body_diameter_m,
        g.length_m,
        Nose(**g.nose.model_dump()),
        tuple(fin_set(f) for f in g.fins),
        None if g.canards is None else fin_set(g.canards),
        None if g.boat_tail is None else placed(BoatTail, g.boat_tail),
        tuple(placed(Transition, t) for t in g.transitions),
        tuple(placed(LaunchLug, lug) for lug in g.launch_lugs),
        tuple(placed(RailButton, b) for b in g.rail_buttons),
        g.surface_roughness_m,
    )


def _aero_tables(rocket: RocketConfig, base_dir: Path) -> AeroTables:
    aero = rocket.aero
    geometry = None if rocket.geometry is None else rocket_geometry(rocket)
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
        geometry = rocket_geometry(rocket)
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
