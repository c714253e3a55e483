"""Geomagnetic field for the magnetometer model: the full IGRF-14 (degrees 1–13) on the WGS84 ellipsoid, and the
IGRF-13 dipole (degree 1) on a spherical Earth.

The IGRF-14 is ppigrf's: its table (``ppigrf.shc_fn_igrf14``; data/igrf/SOURCE.md) and its evaluation; the dipole's
coefficients live in ``data/igrf/igrf13_dipole.toml``. Leaving out the non-dipole field (degrees 2–13) costs about
7 000–8 000 nT (15–18 % of the field, 10–16° of declination) at the Roccaraso and Santa Margarida pads:
tests/env/test_magnetic.py.
"""

from __future__ import annotations

import datetime
import functools
import importlib.util
import os
import tomllib
from importlib import resources

import jax
import jax.numpy as jnp
import numpy as np

from ..math import Vec3
from ..pytree import pytree_dataclass

IGRF13_DIPOLE = resources.files("rocketmc") / "data" / "igrf" / "igrf13_dipole.toml"


@pytree_dataclass
class DipoleCoefficients:
    """Degree-1 Gauss coefficients g10, g11, h11 [nT] and the reference radius a [m]."""

    g10_nt: jnp.ndarray
    g11_nt: jnp.ndarray
    h11_nt: jnp.ndarray
    radius_m: jnp.ndarray


def igrf_dipole(decimal_year: float | None = None) -> DipoleCoefficients:
    """IGRF-13 dipole at ``decimal_year`` (default: the 2020.0 epoch), moved by the linear secular
    variation; ValueError outside the model's validity (2020.0–2025.0)."""
    data = tomllib.loads(IGRF13_DIPOLE.read_text())
    year = data["epoch"] if decimal_year is None else float(decimal_year)
    if not data["valid_from"] <= year <= data["valid_until"]:
        raise ValueError(
            f"IGRF-13 dipole: year {year} is outside the model's validity "
            f"{data['valid_from']}–{data['valid_until']}"
        )
    value, rate = data["coefficients_nt"], data["secular_variation_nt_per_year"]
    g10, g11, h11 = (
        jnp.asarray(value[k] + rate[k] * (year - data["epoch"])) for k in ("g10", "g11", "h11")
    )
    return DipoleCoefficients(g10, g11, h11, jnp.asarray(data["reference_radius_m"]))


def dipole_field_ned(
    coefficients: DipoleCoefficients, latitude_rad, longitude_rad, altitude_m
) -> Vec3:
    """Dipole field [nT] in north, east, down at a latitude, longitude [rad] and altitude [m].

    B = −∇V with V = a Σ_m (a/r)² (g1m cos mφ + h1m sin mφ) P1m(cos θ), Schmidt semi-normalised
    (P10 = cos θ, P11 = sin θ), on a sphere of radius a: r = a + altitude, and the geodetic
    latitude is taken as the geocentric one (θ = 90° − latitude).
    """
    # Geodetic latitude exceeds geocentric by up to 0.19° (at 45°; 0.19° at both launch sites),
    # and there the WGS84 surface lies 1.6–2.5 km inside the sphere. The full IGRF evaluated both
    # ways differs by 320–330 nT (0.7 % of the field) at the two sites, small next to the
    # 7 000–8 000 nT non-dipole part left out.
    c = coefficients
    k = (c.radius_m / (c.radius_m + altitude_m)) ** 3
    sin_lat, cos_lat = jnp.sin(latitude_rad), jnp.cos(latitude_rad)
    sin_lon, cos_lon = jnp.sin(longitude_rad), jnp.cos(longitude_rad)
    equatorial = c.g11_nt * cos_lon + c.h11_nt * sin_lon
    return Vec3(
        k * (equatorial * sin_lat - c.g10_nt * cos_lat),
        k * (c.g11_nt * sin_lon - c.h11_nt * cos_lon),
        -2.0 * k * (c.g10_nt * sin_lat + equatorial * cos_lat),
    )


def site_field_ned(
    latitude_deg, longitude_deg, altitude_m, decimal_year: float | None = None
) -> np.ndarray:
    """Dipole field [nT] (north, east, down) at a site given in degrees, as a numpy (3,) array."""
    lat, lon = np.radians(latitude_deg), np.radians(longitude_deg)
    b = dipole_field_ned(igrf_dipole(decimal_year), lat, lon, altitude_m)
    return np.array([b.x, b.y, b.z], dtype=float)


def _ned_axes(lat, lon, xp=jnp):
    """(3, 3) rows: north, east, down at a latitude and longitude [rad], in Earth-centred axes (``xp``: jax.numpy,
    or numpy for the host's)."""
    sin_lat, cos_lat, sin_lon, cos_lon = xp.sin(lat), xp.cos(lat), xp.sin(lon), xp.cos(lon)
    return xp.array([[-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat], [-sin_lon, cos_lon, 0.0 * lat],
                     [-cos_lat * cos_lon, -cos_lat * sin_lon, -sin_lat]])  # fmt: skip


def site_field_gradient(latitude_deg, longitude_deg, altitude_m, decimal_year: float | None = None):
    """(the dipole field [T] at a site given in degrees, its derivative along an offset from there [T/m] (3, 3)),
    both in the site's NED axes (a flat Earth's), as numpy arrays: the field at the offset point of the sphere of
    ``dipole_field_ned``, turned from that point's north, east, down into the site's."""
    coefficients = igrf_dipole(decimal_year)
    site = _ned_axes(np.radians(latitude_deg), np.radians(longitude_deg))
    centre = -(coefficients.radius_m + altitude_m) * site[2]  # the site in Earth-centred axes

    def field_t(offset_n):
        point = centre + site.T @ offset_n
        radius = jnp.linalg.norm(point)
        lat, lon = jnp.arcsin(point[2] / radius), jnp.arctan2(point[1], point[0])
        b = dipole_field_ned(coefficients, lat, lon, radius - coefficients.radius_m)
        return 1e-9 * site @ (_ned_axes(lat, lon).T @ jnp.stack([b.x, b.y, b.z]))

    origin = jnp.zeros(3)
    return np.asarray(field_t(origin), dtype=float), np.asarray(jax.jacfwd(field_t)(origin), dtype=float)


IGRF14_TABLE = os.path.join(importlib.util.find_spec("ppigrf").submodule_search_locations[0], "IGRF14.shc")
"""ppigrf's IGRF-14 coefficient table (.shc; its ``shc_fn_igrf14``, found without importing ppigrf, which imports
pandas: ~0.2 s before a run's first flight, needed only with a magnetometer): main-field models every 5 years
1900.0–2025.0 and 2030.0, the 2025.0 model moved by the predictive secular variation (data/igrf/SOURCE.md)."""
IGRF14_VALIDITY = (datetime.date(1900, 1, 1), datetime.date(2030, 1, 1))
"""``igrf_validity`` of ``IGRF14_TABLE``, known without reading it (tests/env/test_magnetic.py reads it): the campaign's
date check needs no ppigrf."""
GRADIENT_STEP_M = 25.0
"""The half step [m] of the gradient's central differences. Their truncation, h²/6 of the field's third derivative,
is ≈ 3.3 (h/r)² of the gradient for the dominant dipole (B ∝ r⁻³): 8e-14 h² [m⁻²]; ppigrf's rounding, ~1e-15 of |B|
(~50 µT) over 2h against a gradient of ~0.02 nT/m, is ~2.5e-9 m / h of it (both measured against the exact gradient
of a dipole table, tests/env/test_magnetic.py). Their sum is least, ~1e-10 of the gradient, near h = 25 m."""


@functools.cache
def igrf_validity(table: str = IGRF14_TABLE) -> tuple[datetime.date, datetime.date]:
    """The first and last dates of a coefficient table (IGRF-14: 1900-01-01 to 2030-01-01)."""
    from ppigrf.ppigrf import read_shc
    g, _ = read_shc(table)
    return g.index[0].date(), g.index[-1].date()


def _igrf_in_axes(points_m: np.ndarray, date: datetime.date, table: str, axes: np.ndarray) -> np.ndarray:
    """ppigrf's field [nT] (n, 3) at Earth-centred points [m] (n, 3) (x to 0° E on the equator, z north) at 0 h UTC
    of ``date``, in the axes whose rows (in Earth-centred axes) are ``axes`` (3, 3)."""
    from ppigrf.ppigrf import igrf_gc
    radius = np.linalg.norm(points_m, axis=1)
    theta, phi = np.arccos(points_m[:, 2] / radius), np.arctan2(points_m[:, 1], points_m[:, 0])
    at = datetime.datetime(date.year, date.month, date.day)
    radial, south, east = (b[0] for b in igrf_gc(radius / 1e3, np.degrees(theta), np.degrees(phi), at, coeff_fn=table))
    sin_t, cos_t, sin_p, cos_p = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    spherical = np.stack([np.stack([sin_t * cos_p, sin_t * sin_p, cos_t], axis=1),  # radial, south, east unit vectors
                          np.stack([cos_t * cos_p, cos_t * sin_p, -sin_t], axis=1),
                          np.stack([-sin_p, cos_p, np.zeros_like(sin_p)], axis=1)], axis=1)  # fmt: skip
    return np.einsum("nk,nkj,ij->ni", np.stack([radial, south, east], axis=1), spherical, axes)


@functools.lru_cache(maxsize=16)
def igrf_site_field_gradient(latitude_deg, longitude_deg, altitude_m, date: datetime.date, table: str = IGRF14_TABLE):
    """(the IGRF-14 field (or ``table``'s) [T] at a site given in degrees at 0 h UTC of ``date``, its derivative along
    an offset from there [T/m] (3, 3)), both in the site's NED axes (geodetic: down along the ellipsoid's normal; the
    flat Earth's), as numpy arrays, from ppigrf's own evaluation (``igrf_gc``; the coefficients linear in time
    between the table's models): the field at the site, and the gradient by central differences over
    ±``GRADIENT_STEP_M`` along the site's axes, each point's field turned into them. The site goes onto Earth-centred
    axes by ppigrf's ``geod2geoc``, its altitude taken above the ellipsoid (the geoid is within ~100 m of it: ~2 nT).
    ValueError outside the table's dates. ~0.03 s; cached (read-only arrays)."""
    from ppigrf.ppigrf import geod2geoc

    first, last = igrf_validity(table)
    if not first <= date <= last:
        raise ValueError(f"IGRF: the date {date.isoformat()} is outside the model's {first.isoformat()} to "
                         f"{last.isoformat()}")  # fmt: skip
    colatitude_deg, radius_km, _, _ = geod2geoc(np.array([latitude_deg]), np.array([altitude_m / 1e3]), 0.0, 0.0)
    theta, lon = np.radians(colatitude_deg.item()), np.radians(longitude_deg)
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    centre_m = 1e3 * radius_km.item() * np.array([sin_t * np.cos(lon), sin_t * np.sin(lon), cos_t])
    site = _ned_axes(np.radians(latitude_deg), lon, np)
    offsets = GRADIENT_STEP_M * np.concatenate([np.zeros((1, 3)), np.eye(3), -np.eye(3)])  # the site, then ±h per axis
    b = 1e-9 * _igrf_in_axes(centre_m + offsets @ site, date, table, site)
    field, gradient = b[0], (b[1:4] - b[4:7]).T / (2.0 * GRADIENT_STEP_M)
    for cached in (field, gradient):  # shared by every caller: read-only
        cached.setflags(write=False)
    return field, gradient


def first_order_field(field_n, gradient, r_n: Vec3) -> Vec3:
    """A field [T, NED] at ``r_n`` [m, NED from the pad] to first order from its value field_n (3,) [T] and its
    gradient (3, 3) [T/m] at the pad."""
    r = (r_n.x, r_n.y, r_n.z)
    return Vec3(*(field_n[i] + sum(gradient[i, j] * r[j] for j in range(3)) for i in range(3)))
