"""A campaign file written from an OpenRocket design (host side): ``import_openrocket`` reads the .ork
(``campaign.openrocket``), chooses a simulation, takes the motor from its stored flight (or a thrust file), and writes
a commented campaign whose every value says where it came from, with the thrust curve beside it. The campaign is
loaded before anything is written: a design rocketmc refuses leaves no file.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import tempfile
from pathlib import Path

import numpy as np

from ..aero.geometry import LaunchLug, RailButton
from ..dynamics.motor_library import MotorEntry, MotorLibraryError, eng_header, find_motor
from ..dynamics.propulsion import ThrustCurveError, read_thrust_curve
from ..dynamics.rigid_body import MassProperties
from ..files import replacing
from . import openrocket_mass as om
from .errors import ConfigError
from .loader import parse_campaign
from .openrocket import Design, MotorMount, OpenRocketError, Simulation, read_design, read_simulation, stored_dry_mass

N_REALIZATIONS = 100
"""Realizations of the written campaign (a first look; raise it with ``run -n``)."""
DRYDEN_SIGMA_PER_W20 = 0.1 / (0.177 + 0.000823 * 20.0) ** 0.4
"""Dryden's horizontal gust intensity at 20 ft per unit W20 (MIL-F-8785C: σ_w = 0.1·W20, σ_u = σ_w/(0.177 +
0.000823 h)^0.4 with h in ft): 0.193. OpenRocket's turbulence intensity I gives its horizontal σ = I × the average
wind; W20 = σ / 0.193 gives Dryden the same σ at 20 ft."""
DEFAULT_MAX_TIME_S = 300.0
"""rocketmc's default ``simulation.max_time_s``; a stored flight longer than 80 % of it raises it to twice that."""
MAX_TIME_S = 3600.0
COMMENT_COLUMN = 37
"""Where the comments start, as in campaigns/custom_rocket.toml."""


@dataclasses.dataclass
class ImportResult:
    """What ``import_openrocket`` wrote: the campaign and thrust files (None: a motor of the library), what it read (``lines``: one per part, for the
    CLI), its warnings, and the mass check: the computed dry rocket and the stored one (None without stored data)."""

    campaign: Path
    thrust_curve: Path | None
    lines: list[str]
    warnings: list[str]
    computed: MassProperties
    stored: MassProperties | None


def _float(value: float) -> str:
    """A TOML float with 7 significant digits."""
    return repr(float(f"{value:.7g}"))


def _string(text: str) -> str:
    return json.dumps(text, ensure_ascii=False)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


class _Toml:
    """The campaign text: ``key = value  # where it came from`` lines under tables."""

    def __init__(self):
        self.lines: list[str] = []

    def comment(self, *texts: str) -> None:
        self.lines.extend(f"# {_one_line(t)}" for t in texts)

    def table(self, name: str, array: bool = False) -> None:
        self.lines.extend(["", f"[[{name}]]" if array else f"[{name}]"])

    def key(self, key: str, value, source: str = "") -> None:
        text = value if isinstance(value, str) else _float(value) if isinstance(value, float) else \
            "[" + ", ".join(_float(v) for v in value) + "]" if isinstance(value, list) else str(value)  # fmt: skip
        line = f"{key} = {text}"
        self.lines.append(f"{line:<{COMMENT_COLUMN - 1}} # {_one_line(source)}" if source else line)

    def text(self) -> str:
        return "\n".join(self.lines).lstrip("\n") + "\n"


def import_openrocket(source: str | Path, out: str | Path, motor: str | Path | None = None,
                      simulation: int | None = None, force: bool = False) -> ImportResult:
    """Write the campaign ``out`` from the OpenRocket design ``source``, flying simulation ``simulation`` (1-based;
    None: the first) with its motor: ``motor`` by designation from the library (``rocketmc motors``) or as a thrust
    file (RASP .eng, RockSim .rse, CSV: copied beside the campaign); without it, the design's motor if the library
    has it, else the thrust curve the simulation stored (``<out stem>_thrust.csv``). Existing files are replaced
    only with ``force``. An ``OpenRocketError`` (one line naming the file and the component) writes nothing."""
    source, out = Path(source), Path(out)
    design = read_design(source)
    sim = read_simulation(design, simulation)
    mount = _mount(design, sim, source)
    entry = _library_motor(motor, mount)
    flown = sim is not None and "Thrust" in sim.columns and "Time" in sim.columns
    if entry is None and motor is None and not flown:
        without = ("the design has no simulation" if sim is None else
                   f"{sim.label} holds no flight data (run it in OpenRocket and save the file)")  # fmt: skip
        raise OpenRocketError(f"{source}: {without} and its motor {mount.designation!r} is not in rocketmc's library, "
                              "so no thrust curve: give --motor NAME|FILE")  # fmt: skip
    thrust_name = None if entry else f"{out.stem}_thrust{Path(motor).suffix.lower() if motor else '.csv'}"
    thrust_path = None if entry else out.with_name(thrust_name)
    for path in (out, thrust_path):
        if path is not None and path.exists() and not force:
            raise OpenRocketError(f"{path}: the file exists; use --force to replace it")
    warnings = list(design.warnings)
    engine, thrust_text = None, None
    if entry is None and motor is None:
        curve, engine = _stored_curve(sim, warnings), _stored_masses(sim)
        thrust_text = "time_s,thrust_n\n" + "".join(f"{t:.6g},{f:.6g}\n" for t, f in zip(*curve))
    elif entry is None:
        engine, thrust_text = _motor_file(Path(motor), sim, source)
    text = _campaign_text(source, design, sim, mount, entry or engine, thrust_name, warnings)
    with tempfile.TemporaryDirectory() as folder:  # the campaign must load before anything is written
        if thrust_name is not None:
            (Path(folder) / thrust_name).write_text(thrust_text, encoding="utf-8")
        try:
            parse_campaign(text, Path(folder))
        except ConfigError as e:
            raise OpenRocketError(f"{source}: rocketmc refuses the campaign made of it: {e}") from None
    for path, content in ((thrust_path, thrust_text), (out, text)):
        if path is not None:
            with replacing(path) as partial:
                partial.write_text(content, encoding="utf-8")
    stored = stored_dry_mass(sim, mount) if flown else None
    motor_line = f"motor {entry.designation} from the library" if entry else f"motor {mount.designation}"
    lines = [f"{design.name} (OpenRocket {design.version}): {design.parts} components, "
             f"{sim.label if sim else 'no simulation'}, {motor_line}",
             f"dry mass {design.dry.mass:.4g} kg, CG {design.dry.cg_x:.4g} m from the nose tip, inertia "
             f"[{design.dry.ixx:.4g}, {design.dry.iyy:.4g}] kg·m²" + ("" if stored is None else
             f" (stored at t = 0 less the motor: {stored.mass:.4g} kg, {stored.cg_x:.4g} m, [{stored.ixx:.4g}, "
             f"{stored.iyy:.4g}] kg·m²)"), f"wrote {out}" + ("" if thrust_path is None else f" and {thrust_path}")]  # fmt: skip
    return ImportResult(out, thrust_path, lines, warnings, design.dry, stored)


THRUST_FILE_SUFFIXES = (".eng", ".rse", ".csv")
"""What ``--motor`` names as a thrust file; anything else is a designation in the library."""


def _library_motor(motor: str | Path | None, mount: MotorMount) -> MotorEntry | None:
    """The library's motor to fly: ``motor`` when it is a designation (not a thrust file), else (no ``motor``) the
    design's own motor if the library has it; None: a thrust file or the stored curve."""
    if motor is not None and Path(motor).suffix.lower() in THRUST_FILE_SUFFIXES:
        return None
    try:
        return find_motor(str(motor if motor is not None else mount.designation))
    except MotorLibraryError as e:
        if motor is None:
            return None
        raise OpenRocketError(f"--motor {motor}: {e}") from None


def _mount(design: Design, sim: Simulation | None, source: Path) -> MotorMount:
    """The motor mount of the simulation's configuration (without a simulation: the first one holding a motor)."""
    configs = [sim.config_id] if sim else [m.get("configid") for _, e, _, _ in design.mounts for m in e.findall("motor")]
    for config in configs:
        mount = design.motor_mount(config)
        if mount is not None:
            return mount
    which = f"{sim.label}'s motor configuration" if sim else "any configuration"
    raise OpenRocketError(f"{source}: no motor mount holds a motor in {which}")


def _stored_curve(sim: Simulation, warnings: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The thrust curve [s, N] from ignition to burnout as the simulation stored it (Time and Thrust columns)."""
    time, thrust = sim.columns["Time"], sim.columns["Thrust"]
    ignition = min(sim.events.get("ignition", [0.0]))
    burnout = min(sim.events.get("burnout", [time[np.nonzero(thrust > 0)[0][-1]] if np.any(thrust > 0) else 0.0]))
    keep = (time >= ignition) & (time <= burnout) & np.isfinite(thrust)
    t, f = time[keep] - ignition, np.maximum(thrust[keep], 0.0)
    t, first = np.unique(t, return_index=True)
    f = f[first]
    if t[-1] < burnout - ignition:
        t, f = np.append(t, burnout - ignition), np.append(f, 0.0)
    if ignition > 0:
        warnings.append(f"{sim.label}: its motor ignites {ignition:g} s after launch; rocketmc's ignites at once")
    warnings.append(f"the thrust curve is the Thrust column of {sim.label}, sampled at OpenRocket's time steps "
                    f"({len(t)} points to burnout at {burnout - ignition:.3g} s), not the motor's own data")  # fmt: skip
    return t, f


def _stored_masses(sim: Simulation) -> tuple[float, float, str]:
    """(propellant, casing) masses [kg] from the simulation's Motor mass (else Mass) column: at t = 0 less after
    burnout, and after burnout; with where they came from."""
    burnout = min(sim.events.get("burnout", [float(sim.columns["Time"][-1])]))
    column = "Motor mass" if "Motor mass" in sim.columns else "Mass"
    values = sim.columns[column]
    after = float(np.interp(burnout, sim.columns["Time"], values))
    casing = after if column == "Motor mass" else 0.0
    return float(values[0]) - after, casing, f"{sim.label}: {column} at t = 0 less at burnout ({burnout:g} s)"


def _motor_file(path: Path, sim: Simulation | None, source: Path) -> tuple[tuple[float, float, str], str]:
    """((propellant, casing) masses [kg] with their source, the file's text) of a ``--motor`` thrust file: a RASP
    header's propellant and total masses, else the stored simulation's."""
    try:
        read_thrust_curve(path)
        text = path.read_text(encoding="utf-8-sig")
    except (ThrustCurveError, OSError, UnicodeDecodeError) as e:
        raise OpenRocketError(f"--motor {path}: {e}") from None
    if (header := eng_header(path)) is not None:
        return (header.propellant_mass_kg, header.casing_mass_kg, f"{path.name}'s RASP header"), text
    if sim is not None and "Time" in sim.columns:
        return _stored_masses(sim), text
    raise OpenRocketError(f"--motor {path}: no propellant mass (neither a RASP header with it nor a stored "
                          f"simulation in {source.name})")  # fmt: skip


def _campaign_text(source: Path, design: Design, sim: Simulation | None, mount: MotorMount,
                   engine: MotorEntry | tuple[float, float, str], thrust_name: str | None, warnings: list[str]) -> str:
    """The campaign file's text; ``engine``: a motor of the library, or the (propellant, casing) masses [kg] with
    their source of the curve ``thrust_name``."""
    toml = _Toml()
    dry = design.dry
    computed = f"computed from {design.parts} components"
    toml.comment(f"Imported by `rocketmc import` from the OpenRocket design {source.name!r} ('{design.name}', file "
                 f"version {design.version}); {sim.label if sim else 'no simulation'}.",
                 "Positions are from the nose tip, growing aft [m], as in OpenRocket.")  # fmt: skip
    if sim is not None and (stored := stored_dry_mass(sim, mount)) is not None:
        toml.comment(f"Check: {sim.label} stored at t = 0, less the motor: {stored.mass:.4g} kg, CG {stored.cg_x:.4g} "
                     f"m, inertia [{stored.ixx:.3g}, {stored.iyy:.3g}] kg·m² (rounded in the file); computed here: "
                     f"{dry.mass:.4g} kg, {dry.cg_x:.4g} m, [{dry.ixx:.3g}, {dry.iyy:.3g}] kg·m².")  # fmt: skip
    for warning in warnings:
        toml.comment(f"Note: {warning}.")
    toml.key("name", _string(_one_line(design.name)[:128]))
    toml.key("description", _string(f"imported from OpenRocket ({source.name}, {sim.label if sim else 'no simulation'})"))
    toml.key("n_realizations", N_REALIZATIONS)
    toml.key("seed", 1)

    toml.table("rocket")
    toml.key("coordinate_system", '"nose_to_tail"', "OpenRocket's: from the nose tip, growing aft")
    toml.key("nose_position_m", 0.0)
    toml.key("reference_point_m", dry.cg_x, "body-frame origin: the dry CG")
    toml.key("dry_mass_kg", dry.mass, f"without the motor, {computed}")
    toml.key("dry_cg_m", dry.cg_x, computed)
    toml.key("dry_inertia_kgm2", [dry.ixx, dry.iyy], f"[axial, transverse] about the dry CG, {computed}")
    _lugs(toml, design, mount, warnings)

    toml.table("rocket.motor")
    if isinstance(engine, MotorEntry):
        toml.comment("The library's motor (`rocketmc motors`): its curve, its header's propellant, the grain estimated "
                     "from its casing and the casing as the motor's dry mass.")  # fmt: skip
        toml.key("designation", _string(engine.designation), f"{engine.manufacturer}, in the design: {mount.designation}")
        toml.key("nozzle_m", mount.nozzle_m, f"aft end of {mount.name!r} plus its overhang")
        return _rest_of_campaign(toml, design, sim, mount, warnings)
    propellant, casing, masses_from = engine
    toml.key("thrust_curve", _string(thrust_name), f"{mount.manufacturer} {mount.designation}".strip())
    toml.key("propellant_mass_kg", propellant, masses_from)
    toml.key("nozzle_m", mount.nozzle_m, f"aft end of {mount.name!r} plus its overhang")
    toml.comment("The grain fills the motor's case: a solid cylinder of its diameter and length, centred in it, as "
                 "OpenRocket models a motor's mass (the file gives no grain).")  # fmt: skip
    toml.key("grain_outer_diameter_m", mount.diameter_m, f"the motor's diameter ({mount.designation})")
    toml.key("grain_inner_diameter_m", 0.0)
    toml.key("grain_length_m", mount.length_m, "the motor's length")
    if casing > 0:
        case = om.solid_cylinder(casing, mount.diameter_m / 2, mount.length_m)
        toml.key("dry_mass_kg", casing, "the casing: the motor's mass after burnout")
        toml.key("dry_inertia_kgm2", [case.ixx, case.iyy], "a solid cylinder, as OpenRocket takes it")
        toml.key("dry_cg_m", mount.top_m + mount.length_m / 2, "the motor's centre")
    return _rest_of_campaign(toml, design, sim, mount, warnings)


def _rest_of_campaign(toml: _Toml, design: Design, sim: Simulation | None, mount: MotorMount,
                      warnings: list[str]) -> str:
    """The campaign's text from its aerodynamics on: the build-up, the geometry, recovery, site, rail and wind."""
    toml.table("rocket.aero")
    toml.key("model", '"interpolated"')
    toml.key("tables", '"buildup"', "built from [rocket.geometry]")
    _geometry(toml, design)
    _recovery(toml, design, sim, mount, warnings)
    _conditions(toml, sim, warnings)
    return toml.text()


def _lugs(toml: _Toml, design: Design, mount: MotorMount, warnings: list[str]) -> None:
    """``rear_lug_m``: the rearmost launch lug or rail button, and ``upper_lug_m``: the foremost when it is forward of
    that (the rocket leaves the rail when the upper one passes the rail's top, the rear one alone when there is no
    other); each a button's centre or a lug's aft end. The nozzle when there is none."""
    if not design.lugs:
        warnings.append("no launch lug or rail button: the rear lug is put at the nozzle, the rocket leaving the rail "
                        "after travelling its whole length (OpenRocket's own rule)")  # fmt: skip
        toml.key("rear_lug_m", mount.nozzle_m, "no lug or rail button: the nozzle")
        return
    rear, upper = max(design.lugs, key=lambda lug: lug[1]), min(design.lugs, key=lambda lug: lug[1])
    toml.key("rear_lug_m", rear[1], f"{rear[0]!r}, the rearmost (a button: its centre; a lug: its aft end)")
    if upper[1] < rear[1]:
        toml.key("upper_lug_m", upper[1], f"{upper[0]!r}, the foremost: the rocket leaves the rail when it passes "
                                          "the top")  # fmt: skip


def _inline(**values: float) -> str:
    """A TOML inline table of floats."""
    return "{ " + ", ".join(f"{key} = {_float(value)}" for key, value in values.items()) + " }"


def _geometry(toml: _Toml, design: Design) -> None:
    toml.table("rocket.geometry")
    body = ", ".join(repr(n) for n in design.body_names) or "the nose cone's base"
    toml.key("body_diameter_m", design.body_diameter_m, body)
    toml.key("length_m", design.length_m, "nose tip to the aft end")
    toml.key("nose", f'{{ kind = "{design.nose_kind}", length_m = {_float(design.nose_length_m)} }}', repr(design.nose_name))
    toml.key("surface_roughness_m", design.surface_roughness_m, "the body's finish (OpenRocket's roughness height)")
    if design.boat_tail is not None:
        name, length, aft, top = design.boat_tail
        toml.key("boat_tail", _inline(length_m=length, aft_diameter_m=aft, position_m=top), repr(name))
    if design.transitions:
        toml.key("transitions", "[", "conical sections: OpenRocket's transitions and tubes of another diameter")
        for name, t in design.transitions:
            override = {} if t.cd_override is None else {"cd_override": t.cd_override}
            toml.lines.append(f"    {_inline(position_m=t.position_m, length_m=t.length_m, fore_diameter_m=t.fore_diameter_m, aft_diameter_m=t.aft_diameter_m, **override)},  # {_one_line(repr(name))}"
                              + (" (its drag overridden in OpenRocket)" if override else ""))
        toml.lines.append("]")
    for key, kind in (("launch_lugs", LaunchLug), ("rail_buttons", RailButton)):
        parts = [(name, part) for name, part in design.lug_shapes if isinstance(part, kind)]
        if parts:
            toml.key(key, "[", "one per instance; position_m: a lug's front end, a button's axis")
            for name, part in parts:
                toml.lines.append(f"    {_inline(**dataclasses.asdict(part))},  # {_one_line(repr(name))}")
            toml.lines.append("]")
    for fins in design.fins:
        toml.table("rocket.geometry.fins", array=True)
        if fins.note:
            toml.comment(f"{fins.name!r}: {fins.note}.")
        shape = fins.shape
        toml.key("count", shape.count, repr(fins.name))
        for key in ("root_chord_m", "tip_chord_m", "span_m", "sweep_m"):
            toml.key(key, getattr(shape, key))
        toml.key("position_m", shape.position_m, "the root's leading edge")
        toml.key("thickness_m", shape.thickness_m)
        toml.key("profile", _string(shape.profile), "OpenRocket's cross-section")
        if shape.surface_roughness_m != design.surface_roughness_m:
            toml.key("surface_roughness_m", shape.surface_roughness_m, "the fins' own finish")
        if shape.cant_deg:
            toml.key("cant_deg", shape.cant_deg)


def _identifier(name: str, taken: set[str]) -> str:
    """A parachute name rocketmc accepts (letters, digits, underscores) made of OpenRocket's, unique."""
    base = re.sub(r"\W+", "_", name.lower()).strip("_")[:40].rstrip("_") or "parachute"
    base = base if not base[0].isdigit() else f"p_{base}"
    ident, i = base, 2
    while ident in taken:
        ident, i = f"{base}_{i}", i + 1
    taken.add(ident)
    return ident


def _recovery(toml: _Toml, design: Design, sim: Simulation | None, mount: MotorMount, warnings: list[str]) -> None:
    """The parachutes and streamers: OpenRocket's deployment at apogee, at an altitude after apogee, or at the motor's
    ejection charge (flown at apogee, delayed by the stored flight's ejection less its apogee)."""
    taken: set[str] = set()
    apogee = min(sim.events.get("apogee", [math.nan])) if sim else math.nan
    burnout = min(sim.events.get("burnout", [math.nan])) if sim else math.nan
    for chute in design.recovery:
        delay, altitude, why = chute.delay_s, None, f"OpenRocket's deploy event {chute.event!r}"
        if chute.event == "altitude":
            altitude = chute.altitude_m
        elif chute.event == "ejection":
            ejection = burnout + mount.delay_s if mount.delay_s is not None else math.nan
            if not math.isfinite(ejection - apogee):
                warnings.append(f"{chute.kind} {chute.name!r}: deployed by the ejection charge, whose time the file "
                                "does not give (a plugged motor or no stored flight): flown at apogee")  # fmt: skip
            else:
                delay += max(ejection - apogee, 0.0)
                why = (f"the ejection charge: burnout {burnout:g} s + delay {mount.delay_s:g} s, {ejection - apogee:+.3g} "
                       f"s from the stored apogee; flown at apogee + {delay:.3g} s")  # fmt: skip
                if ejection < apogee:
                    warnings.append(f"{chute.kind} {chute.name!r}: its ejection charge fires {apogee - ejection:.3g} s "
                                    "before the stored apogee; rocketmc opens it at apogee")  # fmt: skip
        elif chute.event != "apogee":
            warnings.append(f"{chute.kind} {chute.name!r}: deploy event {chute.event!r} is not flown, the {chute.kind} "
                            "is left out (its mass stays)")  # fmt: skip
            continue
        toml.table("rocket.parachutes", array=True)
        toml.key("name", _string(_identifier(chute.name, taken)), f"{chute.kind} {chute.name!r}")
        toml.key("cd", chute.cd)
        toml.key("area_m2", chute.area_m2, "canopy area π d²/4" if chute.kind == "parachute" else "strip length × width")
        if altitude is not None:
            toml.key("deploy_altitude_m", altitude, "above the pad, after apogee")
        toml.key("delay_s", delay, why)
        toml.key("attach_m", chute.attach_m, "its packed centre")


def _conditions(toml: _Toml, sim: Simulation | None, warnings: list[str]) -> None:
    """Site, launch rail, wind and turbulence from the simulation's conditions (OpenRocket's defaults without one)."""
    label = sim.label if sim else "OpenRocket's defaults (no simulation)"
    value = (lambda tag, default: sim.condition(tag, default)) if sim else (lambda tag, default: default)
    toml.table("site")
    site_altitude = value("launchaltitude", 0.0)
    toml.key("latitude_deg", value("launchlatitude", 28.61), label)
    toml.key("longitude_deg", value("launchlongitude", -80.6))
    toml.key("altitude_m", site_altitude)

    wind_speed, wind_from = value("windaverage", 0.0), math.degrees(value("winddirection", math.pi / 2)) % 360
    into_wind = sim is not None and sim.conditions.get("launchintowind", "false") == "true"
    angle = value("launchrodangle", 0.0)
    azimuth = wind_from if into_wind else value("launchroddirection", 0.0)
    toml.table("launch")
    toml.key("rail_length_m", value("launchrodlength", 1.0), f"{label}: the launch rod")
    toml.key("elevation_deg", 90.0 - abs(angle), "90° less the rod angle")
    toml.key("azimuth_deg", (azimuth + (180.0 if angle < 0 else 0.0)) % 360,
             "into the wind, as OpenRocket launches" if into_wind else "the rod direction")  # fmt: skip

    sigma = value("windturbulence", 0.0) * wind_speed
    levels = sim.wind_levels if sim and sim.conditions.get("windmodeltype", "").lower() == "multilevel" else []
    if levels:
        sigma = _wind_levels(toml, levels, sim, site_altitude, warnings)
    else:
        toml.table("environment.wind.layers", array=True)
        toml.key("speed_mps", wind_speed, f"{label}: the average wind")
        toml.key("from_deg", wind_from, "the direction it blows from")
    if sigma > 0:
        toml.table("environment.turbulence")
        toml.key("severity", 1.0, "light above 2000 ft")
        toml.key("w20_mps", sigma / DRYDEN_SIGMA_PER_W20,
                 f"Dryden's horizontal σ at 20 ft = OpenRocket's turbulence σ {sigma:.3g} m/s")  # fmt: skip

    atmosphere = sim.atmosphere if sim else None
    if atmosphere is not None and atmosphere.get("model", "isa") != "isa":
        warnings.append(f"{label}: its atmosphere ({atmosphere.get('model')}, base temperature "
                        f"{atmosphere.findtext('basetemperature')} K, pressure {atmosphere.findtext('basepressure')} "
                        "Pa) cannot be written in a campaign; the standard atmosphere flies")  # fmt: skip
    flight_time = sim.summary.get("flighttime", 0.0) if sim else 0.0
    if flight_time > 0.8 * DEFAULT_MAX_TIME_S:
        toml.table("simulation")
        toml.key("max_time_s", min(2 * flight_time, MAX_TIME_S), f"twice the stored flight's {flight_time:g} s")


def _wind_levels(toml: _Toml, levels: list[dict[str, str]], sim: Simulation, site_altitude_m: float,
                 warnings: list[str]) -> float:
    """OpenRocket's multi-level wind as rocketmc layers, each level's wind held from the midpoint below it to the one
    above (OpenRocket interpolates); returns the lowest level's turbulence σ [m/s]."""
    rows = sorted((float(lv["altitude"]), float(lv["speed"]), float(lv["direction"]), float(lv.get("standarddeviation", 0)))
                  for lv in levels)  # fmt: skip
    msl = levels[0].get("altituderef", "msl") == "msl"
    heights = [h - (site_altitude_m if msl else 0.0) for h, *_ in rows]
    bounds = [(a + b) / 2 for a, b in zip(heights, heights[1:])]
    bottom = 0.0
    for i, (_, speed, direction, _) in enumerate(rows):
        toml.table("environment.wind.layers", array=True)
        toml.key("speed_mps", speed, f"{sim.label}: wind level {i + 1}" if i else f"{sim.label}: wind level 1")
        toml.key("from_deg", math.degrees(direction) % 360)
        if i < len(bounds):
            toml.key("thickness_m", max(bounds[i] - bottom, 1.0), "to the midpoint with the next level")
            bottom = max(bounds[i], bottom + 1.0)
    warnings.append(f"{sim.label}: its multi-level wind is held constant between the levels' midpoints (OpenRocket "
                    "interpolates between them)")  # fmt: skip
    return rows[0][3]
