"""Ready-made sensor parts: ``data/sensors/<name>.toml``, each with its datasheet values per sensor
(see SOURCE.md there and docs/sensors.md)."""

from __future__ import annotations

import copy
import functools
import tomllib
from importlib import resources

PARTS = resources.files("rocketmc") / "data" / "sensors"
SENSORS = ("accelerometer", "gyroscope", "magnetometer", "barometer", "gnss", "canard_feedback")
"""The sensors of the avionics, in the order of the bus."""


def part_names(sensor: str | None = None) -> list[str]:
    """The built-in parts (that provide ``sensor``, when given), sorted."""
    names = sorted(p.name.removesuffix(".toml") for p in PARTS.iterdir() if p.name.endswith(".toml"))
    return [n for n in names if sensor is None or sensor in load_part(n)]


def load_part(name: str) -> dict:
    """The tables of part ``name``: its ``name``, ``description``, ``source`` and one table per sensor it
    provides (a copy: the caller may change it). KeyError (listing the known parts) if there is no such part."""
    return copy.deepcopy(_parsed(name))


@functools.cache
def _parsed(name: str) -> dict:
    """Part ``name``'s file, read once: a campaign validates its [avionics] once per value its dispersions can
    draw, each time reading every sensor's part."""
    path = PARTS / f"{name}.toml"
    if not (name.replace("_", "").isalnum() and path.is_file()):
        raise KeyError(f"unknown part {name!r} (known: {', '.join(part_names())})")
    return tomllib.loads(path.read_text())
