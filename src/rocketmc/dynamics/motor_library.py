"""The built-in library of commercial motors (RASP ``.eng`` files in ``data/motors/library``), by designation.

Host-side numpy, never traced: ``motor_library()`` reads each file's header (``NAME DIAMETER_mm LENGTH_mm DELAYS
PROPELLANT_MASS_kg TOTAL_MASS_kg MANUFACTURER``) and its curve into a ``MotorEntry``; ``find_motor`` finds one by
name; ``estimated_grain`` estimates the grain the file does not give; ``matching_motors`` are those ``rocketmc motors``
lists.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import math
import re
from importlib import resources
from pathlib import Path

import numpy as np

from .propulsion import cumulative_impulse, read_thrust_curve

LIBRARY_FOLDER = "library"
"""The library's folder inside the package's ``data/motors`` (a campaign's ``thrust_curve`` may name a file there as
``library/<file>.eng``)."""
BURN_THRESHOLD = 0.05
"""The burn time is the time the thrust is at or above this fraction of its maximum, the threshold of the
certification data's average thrust (thrustcurve.org, "Motor Statistics": "dividing the total [impulse] over the
normalized burn time, within the 5 % threshold")."""
CLASS_BASE_NS = 2.5
"""The upper end of the NAR's A class [N·s]; each letter after it doubles (K: 1280.01 to 2560 N·s)."""

# The grain estimate: RocketPy's Cesaroni Pro75 M1670 (its getting-started example, data/motors/cesaroni/
# Cesaroni_M1670.eng: a 75 mm × 757 mm motor) has five grains 120 mm long, 5 mm apart, outer radius 33 mm,
# core radius 15 mm, density 1815 kg/m³.
GRAIN_OUTER_FRACTION = 66.0 / 75.0
"""Grain outer diameter per motor diameter: the casing wall and the liner take 4.5 mm a side of the 75 mm motor."""
CLOSURE_CALIBERS = (757.0 - (5 * 120.0 + 4 * 5.0)) / 75.0
"""The motor's length not filled by the grain stack (closures, nozzle), in motor diameters: 137 mm of the
757 mm motor, 1.83 calibers."""
PROPELLANT_DENSITY_KG_M3 = 1815.0
"""Ammonium perchlorate composite propellant, the example's value (APCP is 1700 to 1850 kg/m³)."""


class MotorLibraryError(ValueError):
    """A name that is not one motor of the library, or an ``.eng`` header that cannot be read."""


@dataclasses.dataclass(frozen=True)
class MotorEntry:
    """A motor of a RASP ``.eng`` file: its header and what its curve gives.

    designation: the header's name (``4263-L1350-CS-P``); manufacturer: the header's (``CTI``);
    diameter_m, length_m: the casing [m]; propellant_mass_kg, total_mass_kg: at ignition [kg];
    path: the file; total_impulse_ns: the curve's [N·s]; burn_time_s: the time the thrust is at or above
    ``BURN_THRESHOLD`` of its maximum [s] (the curve itself lasts longer).
    """

    designation: str
    manufacturer: str
    diameter_m: float
    length_m: float
    propellant_mass_kg: float
    total_mass_kg: float
    path: Path
    total_impulse_ns: float
    burn_time_s: float

    @property
    def name(self) -> str:
        """The file's stem, with the manufacturer's prefix (``Cesaroni_4263L1350-P``)."""
        return self.path.stem

    @property
    def casing_mass_kg(self) -> float:
        """Casing, closures and nozzle: total less propellant [kg]."""
        return self.total_mass_kg - self.propellant_mass_kg

    @property
    def average_thrust_n(self) -> float:
        """Total impulse over the burn time [N] (the number of the designation: L1350 is ~1350 N)."""
        return self.total_impulse_ns / self.burn_time_s

    @property
    def impulse_class(self) -> str:
        """The NAR impulse class letter of the curve's total impulse (1.26-2.5 N·s: A; 1280.01-2560 N·s: K)."""
        return impulse_class(self.total_impulse_ns)


def impulse_class(total_impulse_ns: float) -> str:
    """The NAR class of a total impulse [N·s]: A for (1.25, 2.5], each letter doubling; 1/2A, 1/4A, ... below."""
    k = math.ceil(math.log2(total_impulse_ns / CLASS_BASE_NS))
    return chr(ord("A") + k) if k >= 0 else f"1/{2 ** -k}A"


def burn_time_s(time_s: np.ndarray, thrust_n: np.ndarray) -> float:
    """The time from the thrust's first rise through ``BURN_THRESHOLD`` of its maximum to its last fall through it,
    on the piecewise-linear curve [s]."""
    level = BURN_THRESHOLD * thrust_n.max()
    above = np.flatnonzero(thrust_n >= level)
    first, last = above[0], above[-1]
    start = time_s[0] if first == 0 else np.interp(level, thrust_n[first - 1:first + 1], time_s[first - 1:first + 1])
    end = time_s[-1] if last == len(time_s) - 1 else np.interp(
        level, thrust_n[last:last + 2][::-1], time_s[last:last + 2][::-1])
    return float(end - start)


def read_eng_entry(path: str | Path) -> MotorEntry:
    """The ``MotorEntry`` of a RASP ``.eng`` file; ``MotorLibraryError`` naming the file if its header is not
    ``NAME DIAMETER_mm LENGTH_mm DELAYS PROPELLANT_MASS_kg TOTAL_MASS_kg MANUFACTURER``, ``ThrustCurveError`` if its
    curve cannot be read."""
    path = Path(path)
    time_s, thrust_n = read_thrust_curve(path)
    lines = (line.split(";")[0].split() for line in path.read_bytes().decode("utf-8-sig").splitlines())
    header = next(words for words in lines if words)
    try:
        name, diameter_mm, length_mm, _delays, propellant_kg, total_kg, manufacturer = header
        numbers = [float(x) for x in (diameter_mm, length_mm, propellant_kg, total_kg)]
    except ValueError:
        raise MotorLibraryError(f"{path}: the first line is not a RASP header (name, diameter mm, length mm, "
                                f"delays, propellant kg, total kg, manufacturer): {' '.join(header)!r}") from None  # fmt: skip
    if not (all(math.isfinite(x) and x > 0 for x in numbers) and numbers[2] < numbers[3]):
        raise MotorLibraryError(f"{path}: the header's sizes and masses must be positive, the propellant less than "
                                f"the total: {' '.join(header)!r}")  # fmt: skip
    return MotorEntry(name, manufacturer, numbers[0] / 1000.0, numbers[1] / 1000.0, numbers[2], numbers[3], path,
                      float(cumulative_impulse(time_s, thrust_n)[-1]), burn_time_s(time_s, thrust_n))  # fmt: skip


def eng_header(path: Path) -> MotorEntry | None:
    """The motor a thrust file's RASP header describes (``read_eng_entry``); None for another kind of file, or an
    ``.eng`` whose first line is not a RASP header (its curve alone is read then)."""
    if path.suffix.lower() != ".eng":
        return None
    try:
        return read_eng_entry(path)
    except MotorLibraryError:
        return None


@functools.cache
def motor_library() -> tuple[MotorEntry, ...]:
    """Every motor of the built-in library, by file name."""
    folder = resources.files("rocketmc") / "data" / "motors" / LIBRARY_FOLDER
    return tuple(read_eng_entry(Path(str(p))) for p in sorted(folder.iterdir(), key=lambda p: p.name)
                 if p.name.endswith(".eng"))  # fmt: skip


def _key(text: str) -> str:
    """``text`` lower-cased without punctuation (``4263-L1350-CS-P`` → ``4263l1350csp``)."""
    return re.sub(r"[^0-9a-z]", "", text.lower())


def _names(entry: MotorEntry) -> set[str]:
    """The keys a name matches ``entry`` by: its designation, its file's stem with and without the manufacturer's
    prefix, and from its class letter on (``L1350-P``, ``L1350-CS-P``), and the class letter with the average
    thrust alone (``L1350``)."""
    stem = entry.name.split("_", 1)[-1]
    names = {entry.designation, entry.name, stem}
    for text in (stem, entry.designation):
        if code := re.search(r"[A-O]\d+.*", text):
            names |= {code.group(), re.match(r"[A-O]\d+", code.group()).group()}
    return {_key(name) for name in names}


def find_motor(name: str, library: tuple[MotorEntry, ...] | None = None) -> MotorEntry:
    """The motor of ``library`` (the built-in one by default) that ``name`` designates, case-insensitive: its
    designation or file name exactly (``4263-L1350-CS-P``, ``Cesaroni_4263L1350-P``), else the one motor matching it
    without punctuation (``L1350``, ``l1350-p``). ``MotorLibraryError``, one line: the candidates of an ambiguous
    name, the close matches of an unknown one."""
    library = motor_library() if library is None else library
    exact = [e for e in library if name.lower() in (e.designation.lower(), e.name.lower())]
    found = exact or [e for e in library if _key(name) in _names(e)]
    if len(found) == 1:
        return found[0]
    if found:
        raise MotorLibraryError(f"{name!r} is ambiguous: {', '.join(e.name for e in found)}")
    close = difflib.get_close_matches(_key(name), {k: e for e in library for k in _names(e)}, n=5, cutoff=0.6)
    matches = sorted({e.name for e in library if _names(e) & set(close)})
    hint = f"close: {', '.join(matches)}" if matches else "`rocketmc motors` lists them"
    raise MotorLibraryError(f"{name!r} is not a motor of the library ({hint})")


def estimated_grain(entry: MotorEntry) -> tuple[float, float, float]:
    """(outer diameter, core diameter, length) [m] of a hollow-cylinder grain for ``entry``, which the ``.eng`` file
    does not give, scaled from RocketPy's Pro75 M1670 (``GRAIN_OUTER_FRACTION``, ``CLOSURE_CALIBERS``,
    ``PROPELLANT_DENSITY_KG_M3``): the outer diameter a fixed fraction of the motor's, the length the motor's less
    its closures, and the core what holds the header's propellant mass at that density; a solid grain (core 0)
    where the mass does not fit (its density then above the assumed one). Only the grain's inertia and the
    power-on drag's exhaust area read it; for the Cesaroni L1350 it gives 66, 16.9 and 349 mm, against the
    75, 20 and 532 mm the Lynx thesis models (tests/dynamics/test_motor_library.py)."""
    outer = GRAIN_OUTER_FRACTION * entry.diameter_m
    length = entry.length_m - CLOSURE_CALIBERS * entry.diameter_m
    core_sq = outer**2 - 4.0 * entry.propellant_mass_kg / (math.pi * PROPELLANT_DENSITY_KG_M3 * length)
    return outer, math.sqrt(max(core_sq, 0.0)), length


def casing_inertia_kgm2(entry: MotorEntry, mass_kg: float) -> tuple[float, float]:
    """[axial, transverse] inertia [kg·m²] of a thin-walled tube of ``mass_kg`` with ``entry``'s diameter and length
    about its centre: the casing, closures and nozzle as one tube (m r², m (r²/2 + L²/12))."""
    r_sq = (0.5 * entry.diameter_m) ** 2
    return mass_kg * r_sq, mass_kg * (0.5 * r_sq + entry.length_m**2 / 12.0)


def matching_motors(search: str | None = None) -> list[MotorEntry]:
    """The library's motors whose file name, designation or manufacturer contains ``search`` (case-insensitive,
    punctuation ignored); all of them without one."""
    key = _key(search or "")
    return [e for e in motor_library() if key in _key(e.name) or key in _key(e.designation)
            or key in _key(e.manufacturer)]  # fmt: skip
