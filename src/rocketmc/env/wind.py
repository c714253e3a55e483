"""Mean wind: piecewise-constant layers, a measured profile, or a power-law shear.

Each model is a pytree with ``velocity_n(altitude_agl)`` (the air's velocity [m/s, NED], horizontal)
and ``jump_altitudes_m()`` (altitudes [m] where the wind jumps, which the descent step must not
straddle).
"""

from __future__ import annotations

import csv
from pathlib import Path

import jax.numpy as jnp
import numpy as np

from ..math import Vec3
from ..pytree import pytree_dataclass


def _north_east(speed_mps, from_rad):
    """Velocity components of a wind of ``speed_mps`` blowing *from* ``from_rad`` (clockwise from north)."""
    return -speed_mps * jnp.cos(from_rad), -speed_mps * jnp.sin(from_rad)


@pytree_dataclass
class WindLayers:
    """Horizontal wind per layer, in NED.

    ``bottom_m[k]`` is the lower edge of layer k above ground [m] (``bottom_m[0] = 0``, increasing);
    ``north_mps[k]``, ``east_mps[k]`` the velocity of the air (the direction it blows *to*) [m/s].
    The top layer extends upward without limit; below ground the first layer applies. A constant
    wind is one layer.
    """

    bottom_m: jnp.ndarray
    north_mps: jnp.ndarray
    east_mps: jnp.ndarray

    @classmethod
    def from_speed_direction(cls, bottom_m, speed_mps, from_rad) -> WindLayers:
        """Layers from speeds [m/s] and meteorological directions (where the wind comes *from*,
        clockwise from north) [rad]."""
        north, east = _north_east(jnp.asarray(speed_mps), from_rad)
        return cls(jnp.asarray(bottom_m), north, east)

    def velocity_n(self, altitude_agl) -> Vec3:
        north, east = self.north_mps[0], self.east_mps[0]
        for k in range(1, self.bottom_m.shape[0]):
            above = altitude_agl >= self.bottom_m[k]
            north = jnp.where(above, self.north_mps[k], north)
            east = jnp.where(above, self.east_mps[k], east)
        return Vec3(north, east, jnp.zeros_like(north))

    def jump_altitudes_m(self) -> list:
        return [self.bottom_m[k] for k in range(1, self.bottom_m.shape[0])]


@pytree_dataclass
class WindProfile:
    """A measured profile: velocity components [m/s] at increasing altitudes above ground [m],
    linear in between, constant beyond both ends."""

    altitude_m: jnp.ndarray
    north_mps: jnp.ndarray
    east_mps: jnp.ndarray

    @classmethod
    def from_speed_direction(cls, altitude_m, speed_mps, from_rad) -> WindProfile:
        north, east = _north_east(jnp.asarray(speed_mps), from_rad)
        return cls(jnp.asarray(altitude_m), north, east)

    def velocity_n(self, altitude_agl) -> Vec3:
        north = jnp.interp(altitude_agl, self.altitude_m, self.north_mps)
        east = jnp.interp(altitude_agl, self.altitude_m, self.east_mps)
        return Vec3(north, east, jnp.zeros_like(north))

    def jump_altitudes_m(self) -> list:
        return []


POWER_LAW_FLOOR_M = 1.0
"""Below this height [m] the power-law wind is held at its value there (the law is meant for the
surface layer above the roughness elements, not at z → 0)."""


@pytree_dataclass
class PowerLawWind:
    """Shear V(h) = V_ref·(h/h_ref)^exponent from one direction: speed_mps at reference_height_m [m]
    above ground, exponent (1/7 over open terrain), from_rad where it blows from."""

    speed_mps: jnp.ndarray
    reference_height_m: jnp.ndarray
    exponent: jnp.ndarray
    from_rad: jnp.ndarray

    def velocity_n(self, altitude_agl) -> Vec3:
        height = jnp.maximum(altitude_agl, POWER_LAW_FLOOR_M)
        north, east = _north_east(self.speed_mps * (height / self.reference_height_m) ** self.exponent, self.from_rad)
        return Vec3(north, east, jnp.zeros_like(north))

    def jump_altitudes_m(self) -> list:
        return []


def read_csv_columns(path, columns: tuple[tuple[str, ...], ...]) -> tuple[list[str], np.ndarray]:
    """The columns of a CSV file (``#`` comments allowed) as floats, on the host: ``columns`` lists, for each
    column read, the header names it may have (exactly one present). Returns the names found and an array
    (rows, columns) of at least 2 rows of finite numbers. ``ValueError`` naming the file and what is wrong,
    also for a file that is not text."""
    try:
        with Path(path).open(newline="", encoding="utf-8-sig") as f:  # -sig: spreadsheets often start with a BOM
            reader = csv.DictReader(line for line in f if line.strip() and not line.lstrip().startswith("#"))
            rows = list(reader)
            header = reader.fieldnames or []
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a UTF-8 text file") from None
    except csv.Error as err:  # e.g. a NUL byte
        raise ValueError(f"{path}: not a readable CSV file ({err})") from None
    found = [[c for c in names if c in header] for names in columns]
    if any(len(names) != 1 for names in found):
        wanted = [names[0] + "".join(f" (or {c})" for c in names[1:]) for names in columns]
        raise ValueError(f"{path}: expected columns {', '.join(wanted[:-1])} and {wanted[-1]}, "
                         f"found {', '.join(header) or 'none'}")  # fmt: skip
    names = [c for c, in found]
    try:
        values = np.array([[float(row[c]) for c in names] for row in rows])
    except (TypeError, ValueError):
        raise ValueError(f"{path}: every row needs numbers in {', '.join(names)}") from None
    if len(values) < 2 or not np.all(np.isfinite(values)):
        raise ValueError(f"{path}: needs at least 2 rows of finite numbers in {', '.join(names)}")
    return names, values


def read_wind_profile(path, site_altitude_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(altitude above ground [m], speed [m/s], from-direction [rad]) of a measured profile, on the host.

    The CSV (``#`` comments allowed) has a header naming ``altitude_agl_m`` or ``altitude_msl_m``
    (the latter made relative to ``site_altitude_m``), ``speed_mps`` and ``from_deg``; altitudes strictly
    increasing. ``ValueError`` naming the file and what is wrong, also for a file that is not text.
    """
    names, values = read_csv_columns(path, (("altitude_agl_m", "altitude_msl_m"), ("speed_mps",), ("from_deg",)))
    altitude, speed, from_deg = values.T
    if names[0] == "altitude_msl_m":
        altitude = altitude - site_altitude_m
    if not np.all(np.diff(altitude) > 0):
        raise ValueError(f"{path}: {names[0]} must be strictly increasing")
    if np.any(speed < 0):
        raise ValueError(f"{path}: speed_mps must not be negative")
    return altitude, speed, np.deg2rad(from_deg)
