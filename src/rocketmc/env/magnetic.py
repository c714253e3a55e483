"""Geomagnetic field for the magnetometer model: the full IGRF-14 (degrees 1–13) on the WGS84 ellipsoid, and the
IGRF-13 dipole (degree 1) on a spherical Earth.

The IGRF-14 coefficients are ppigrf's table (``ppigrf.shc_fn_igrf14``; data/igrf/SOURCE.md); the dipole's live in
``data/igrf/igrf13_dipole.toml``. Leaving out the non-dipole field (degrees 2–13) costs about 7 000–8 000 nT
(15–18 % of the field, 10–16° of declination) at the Roccaraso and Santa Margarida pads: tests/env/test_magnetic.py.
"""

from __future__ import annotations

import datetime
import functools
import math
import tomllib
from importlib import resources

import jax
import jax.numpy as jnp
import numpy as np
from ppigrf.ppigrf import RE, WGS84_a, WGS84_e2, read_shc, shc_fn_igrf14

from ..math import Vec3
from ..pytree import pytree_dataclass, static_field

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


def _ned_axes(lat, lon):
    """(3, 3) rows: north, east, down at a latitude and longitude [rad], in Earth-centred axes."""
    sin_lat, cos_lat, sin_lon, cos_lon = jnp.sin(lat), jnp.cos(lat), jnp.sin(lon), jnp.cos(lon)
    return jnp.array([[-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat], [-sin_lon, cos_lon, 0.0 * lat],
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


IGRF14_TABLE = shc_fn_igrf14
"""ppigrf's IGRF-14 coefficient table (.shc): main-field models every 5 years 1900.0–2025.0 and 2030.0, the 2025.0
model moved by the predictive secular variation (data/igrf/SOURCE.md)."""
IGRF_REFERENCE_RADIUS_M = 1e3 * RE
WGS84_A_M, WGS84_E2 = 1e3 * WGS84_a, WGS84_e2
"""The WGS84 ellipsoid's equatorial radius [m] and first eccentricity squared (ppigrf's, which it converts geodetic
coordinates with)."""


@pytree_dataclass
class IgrfCoefficients:
    """Gauss coefficients g_nm, h_nm [nT] of one date, in ppigrf's order of (degree, order) (``degree``, ``order``)."""

    g_nt: jnp.ndarray
    h_nt: jnp.ndarray
    degree: tuple = static_field()
    order: tuple = static_field()


@functools.cache
def igrf_validity(table: str = IGRF14_TABLE) -> tuple[datetime.date, datetime.date]:
    """The first and last dates of a coefficient table (IGRF-14: 1900-01-01 to 2030-01-01)."""
    g, _ = read_shc(table)
    return g.index[0].date(), g.index[-1].date()


def igrf_coefficients(date: datetime.date, table: str = IGRF14_TABLE) -> IgrfCoefficients:
    """The coefficients at 0 h UTC of ``date``, linear in time between the table's models (as ppigrf interpolates
    them); ValueError outside the table's dates."""
    g, h = read_shc(table)
    first, last = igrf_validity(table)
    if not first <= date <= last:
        raise ValueError(f"IGRF: the date {date.isoformat()} is outside the model's {first.isoformat()} to {last.isoformat()}")
    days = lambda t: (t - datetime.datetime(1900, 1, 1)).total_seconds() / 86400.0  # noqa: E731
    at, models = days(datetime.datetime(date.year, date.month, date.day)), [days(t) for t in g.index.to_pydatetime()]
    g_nt, h_nt = (np.array([np.interp(at, models, c[key].to_numpy(float)) for key in g.columns]) for c in (g, h))
    degree, order = zip(*g.columns)
    return IgrfCoefficients(jnp.asarray(g_nt), jnp.asarray(h_nt), degree, order)


def _igrf_potential(c: IgrfCoefficients, point_m):
    """The IGRF's scalar potential V [nT·m] at an Earth-centred point [m] (x to 0° E on the equator, z north):
    V = a Σ_n (a/r)^(n+1) Σ_m (g_nm cos mφ + h_nm sin mφ) P_nm(cos θ), P_nm Schmidt semi-normalised."""
    radius = jnp.linalg.norm(point_m)
    cos_t, sin_t = point_m[2] / radius, jnp.hypot(point_m[0], point_m[1]) / radius
    phi = jnp.arctan2(point_m[1], point_m[0])
    n_max = max(c.degree)
    p = {(0, 0): jnp.ones_like(cos_t)}
    for n in range(1, n_max + 1):  # Schmidt semi-normalised associated Legendre functions by recursion
        p[n, n] = sin_t * p[n - 1, n - 1] * (1.0 if n == 1 else math.sqrt((2 * n - 1) / (2 * n)))
        for m in range(n):
            below = p[n - 2, m] * math.sqrt((n - 1) ** 2 - m**2) if n - 2 >= m else 0.0
            p[n, m] = ((2 * n - 1) * cos_t * p[n - 1, m] - below) / math.sqrt(n**2 - m**2)
    ratio = IGRF_REFERENCE_RADIUS_M / radius
    terms = [ratio ** (n + 1) * (c.g_nt[k] * jnp.cos(m * phi) + c.h_nt[k] * jnp.sin(m * phi)) * p[n, m]
             for k, (n, m) in enumerate(zip(c.degree, c.order))]  # fmt: skip
    return IGRF_REFERENCE_RADIUS_M * sum(terms)


def geodetic_to_ecef_m(latitude_rad, longitude_rad, height_m):
    """The Earth-centred point [m] of a geodetic latitude, longitude [rad] and height above the WGS84 ellipsoid [m]."""
    sin_lat = jnp.sin(latitude_rad)
    normal = WGS84_A_M / jnp.sqrt(1.0 - WGS84_E2 * sin_lat**2)
    across = (normal + height_m) * jnp.cos(latitude_rad)
    return jnp.stack([across * jnp.cos(longitude_rad), across * jnp.sin(longitude_rad),
                      (normal * (1.0 - WGS84_E2) + height_m) * sin_lat])  # fmt: skip


@functools.lru_cache(maxsize=16)
def igrf_site_field_gradient(latitude_deg, longitude_deg, altitude_m, date: datetime.date, table: str = IGRF14_TABLE):
    """(the IGRF-14 field (or ``table``'s) [T] at a site given in degrees at 0 h UTC of ``date``, its derivative along
    an offset from there [T/m] (3, 3)), both in the site's NED axes (geodetic: down along the ellipsoid's normal; the
    flat Earth's), as numpy arrays: B = −∇V at the offset point, by automatic differentiation (the gradient is −V's
    Hessian: symmetric and traceless). The altitude is taken above the ellipsoid (the geoid is within ~100 m of it:
    ~2 nT). Evaluated eagerly (~2 s; compiled, XLA takes minutes over the unrolled degree-13 sums) and cached
    (read-only arrays)."""
    with jax.ensure_compile_time_eval():  # the site's numbers: computed once on the host, even under jit
        coefficients = igrf_coefficients(date, table)
        lat, lon = np.radians(latitude_deg), np.radians(longitude_deg)
        site, centre = _ned_axes(lat, lon), geodetic_to_ecef_m(lat, lon, altitude_m)

        def field_t(offset_n):
            return -1e-9 * site @ jax.grad(_igrf_potential, argnums=1)(coefficients, centre + site.T @ offset_n)

        origin = jnp.zeros(3)
        field, gradient = np.array(field_t(origin), dtype=float), np.array(jax.jacfwd(field_t)(origin), dtype=float)
    for cached in (field, gradient):  # shared by every caller: read-only
        cached.setflags(write=False)
    return field, gradient


def first_order_field(field_n, gradient, r_n: Vec3) -> Vec3:
    """A field [T, NED] at ``r_n`` [m, NED from the pad] to first order from its value field_n (3,) [T] and its
    gradient (3, 3) [T/m] at the pad."""
    r = (r_n.x, r_n.y, r_n.z)
    return Vec3(*(field_n[i] + sum(gradient[i, j] * r[j] for j in range(3)) for i in range(3)))
