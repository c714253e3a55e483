"""Geomagnetic field for the magnetometer model: the IGRF-13 dipole (degree 1) on a spherical Earth.

The coefficients live in ``data/igrf/igrf13_dipole.toml`` (see SOURCE.md there). Leaving out the
non-dipole field (degrees 2–13) costs about 7 000–8 000 nT (15–18 % of the field, 10–16° of
declination) at the Roccaraso and Santa Margarida pads: tests/env/test_magnetic.py.
"""

from __future__ import annotations

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


def site_field_gradient(latitude_deg, longitude_deg, altitude_m, decimal_year: float | None = None):
    """(the dipole field [T] at a site given in degrees, its derivative along an offset from there [T/m] (3, 3)),
    both in the site's NED axes (a flat Earth's), as numpy arrays: the field at the offset point of the sphere of
    ``dipole_field_ned``, turned from that point's north, east, down into the site's."""
    coefficients = igrf_dipole(decimal_year)

    def ned_axes(lat, lon):  # rows: north, east, down in Earth-centred axes
        sin_lat, cos_lat, sin_lon, cos_lon = jnp.sin(lat), jnp.cos(lat), jnp.sin(lon), jnp.cos(lon)
        return jnp.array([[-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat], [-sin_lon, cos_lon, 0.0 * lat],
                          [-cos_lat * cos_lon, -cos_lat * sin_lon, -sin_lat]])  # fmt: skip

    site = ned_axes(np.radians(latitude_deg), np.radians(longitude_deg))
    centre = -(coefficients.radius_m + altitude_m) * site[2]  # the site in Earth-centred axes

    def field_t(offset_n):
        point = centre + site.T @ offset_n
        radius = jnp.linalg.norm(point)
        lat, lon = jnp.arcsin(point[2] / radius), jnp.arctan2(point[1], point[0])
        b = dipole_field_ned(coefficients, lat, lon, radius - coefficients.radius_m)
        return 1e-9 * site @ (ned_axes(lat, lon).T @ jnp.stack([b.x, b.y, b.z]))

    origin = jnp.zeros(3)
    return np.asarray(field_t(origin), dtype=float), np.asarray(jax.jacfwd(field_t)(origin), dtype=float)
