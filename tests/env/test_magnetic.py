"""IGRF-13 dipole against a closed-form dipole, the full IGRF-13 at the launch sites, secular
variation, validity range, jit/vmap, the geomagnetic pole and the (a/r)³ fall-off.

References
- The dipole written a second way, in ECEF (x to 0° E on the equator, z north): the degree-1
  potential a³ g·r/r³ with g = (g11, h11, g10) is the potential of the moment
  m = (4π a³/μ0) g, whose field B = μ0/(4π r³)[3(m·r̂)r̂ − m] = (a/r)³[3(g·r̂)r̂ − g] is rotated
  to NED with numpy.
- igrf-model 1.1.4 (PyPI; a Python port of NOAA's igrf13syn with the IGRF-13 table), run in a
  throwaway venv at 2021.7 (the flights: Roccaraso 18 Sept 2021, EuRoC 13 Oct 2021):
  - full field, geodetic (WGS84) input: ``IGRFModel.get(13).evaluate(lat, lon, alt_m, date=2021.7)``
    -> (north, east, down). ppigrf 1.1.0
    ``ppigrf.igrf(lon, lat, alt_km, datetime(2021, 9, 13, 12))`` agrees within 1.2 nT (it
    interpolates its .shc file's 2025 column instead of applying the SV).
  - degree 1 only: ``igrf13syn(2021.7, InputType.GEOCENTRIC, 6371.2 + alt_km, lat, lon, gh=...)``
    with every coefficient of degree ≥ 2 set to zero: the same sphere, latitude and radius as
    ``dipole_field_ned``, with the secular variation applied by igrf-model.
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.env.magnetic import DipoleCoefficients, dipole_field_ned, igrf_dipole, site_field_gradient, site_field_ned

SITES = {  # geodetic latitude [deg], longitude [deg], altitude above sea level [m]
    "roccaraso": (41.8087, 14.0543, 1416.0),
    "santa_margarida": (39.3903, -8.2892, 160.0),
}
YEAR = 2021.7
IGRF13_FULL_NT = {  # igrf-model 1.1.4, full field, north/east/down
    "roccaraso": (24545.243573948545, 1665.0383416182028, 39756.744704650235),
    "santa_margarida": (26276.084976299415, -649.317192347869, 35621.13441623007),
}
IGRF13_DEGREE1_NT = {  # igrf-model 1.1.4 igrf13syn, degree 1 only, geocentric input
    "roccaraso": (21711.80775917403, -4816.5915330265725, 39577.50375846686),
    "santa_margarida": (21391.284279346055, -4352.635169255036, 40532.11463588648),
}
# Dipole minus full IGRF-13 at 2021.7, measured: |ΔB|, ΔF [nT], Δdeclination, Δinclination [deg].
# Roccaraso: dipole D −12.51° I 60.67° F 45398 nT, IGRF D +3.88° I 58.25° F 46753 nT.
# Santa Margarida: dipole D −11.50° I 61.69° F 46037 nT, IGRF D −1.42° I 53.58° F 44269 nT.
DIFFERENCES = {
    "roccaraso": (7076.16, -1354.94, -16.389, 2.417),
    "santa_margarida": (7854.53, 1768.06, -10.086, 8.117),
}
# The dipole misses the non-dipole field (degrees 2–13). Its global RMS at the surface,
# sqrt(Σ_{n=2..13} (n+1) Σ_m (g_nm² + h_nm²)) (Lowes–Mauersberger spectrum of IGRF-13 at 2021.7),
# is 11 582 nT (against 42 128 nT for the dipole). A single site can lie above its RMS, so this is
# the scale, not a hard bound; these sites sit at 0.61 and 0.68 of it. Add ~330 nT for taking the
# geodetic latitude as geocentric on the sphere (the full IGRF evaluated both ways at the sites).
NON_DIPOLE_BOUND_NT = 11582.0 + 400.0


def closed_form_ned(c: DipoleCoefficients, lat, lon, alt):
    """Field of the moment (4π a³/μ0)(g11, h11, g10) at the point, in NED [nT]."""
    a = float(c.radius_m)
    g = np.array([float(c.g11_nt), float(c.h11_nt), float(c.g10_nt)])
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    r_hat = np.array([cl * co, cl * so, sl])
    b_ecef = (a / (a + alt)) ** 3 * (3.0 * (g @ r_hat) * r_hat - g)
    ecef_to_ned = np.array([[-sl * co, -sl * so, cl], [-so, co, 0.0], [-cl * co, -cl * so, -sl]])
    return ecef_to_ned @ b_ecef


def ned(b) -> np.ndarray:
    """(3,) or, batched, (3, n) array of a Vec3."""
    return np.stack([np.asarray(b.x), np.asarray(b.y), np.asarray(b.z)])


def declination_inclination_deg(b):
    declination, inclination = math.atan2(b[1], b[0]), math.atan2(b[2], math.hypot(b[0], b[1]))
    return math.degrees(declination), math.degrees(inclination)


def site_points():
    rng = np.random.default_rng(7)
    points = [(math.radians(lat), math.radians(lon), alt) for lat, lon, alt in SITES.values()]
    lat = np.arcsin(rng.uniform(-1.0, 1.0, 6))
    lon = rng.uniform(-math.pi, math.pi, 6)
    alt = rng.uniform(-500.0, 100e3, 6)
    return points + list(zip(lat, lon, alt))


@pytest.mark.parametrize("year", [None, YEAR, 2025.0])
@pytest.mark.parametrize("point", site_points())
def test_matches_closed_form_dipole(point, year):
    # A handful of float64 trig and power operations on each side, ~1e-16 each, can only drift a few
    # 1e-15 apart; 1e-9 of |B| leaves room without hiding any formula error (those are ≥ 1e-3).
    c = igrf_dipole(year)
    b = ned(dipole_field_ned(c, *point))
    ref = closed_form_ned(c, *point)
    np.testing.assert_allclose(b, ref, rtol=0, atol=1e-9 * np.linalg.norm(ref))


@pytest.mark.parametrize("site", SITES)
def test_matches_igrf13syn_degree_one(site):
    lat, lon, alt = SITES[site]
    b = site_field_ned(lat, lon, alt, YEAR)
    ref = np.array(IGRF13_DEGREE1_NT[site])
    np.testing.assert_allclose(b, ref, rtol=0, atol=1e-9 * np.linalg.norm(ref))


@pytest.mark.parametrize("site", SITES)
def test_against_full_igrf13_within_non_dipole_field(site):
    lat, lon, alt = SITES[site]
    dipole, full = site_field_ned(lat, lon, alt, YEAR), np.array(IGRF13_FULL_NT[site])
    delta = np.linalg.norm(dipole - full)
    assert delta < NON_DIPOLE_BOUND_NT

    (d_dip, i_dip), (d_full, i_full) = map(declination_inclination_deg, (dipole, full))
    delta_f = np.linalg.norm(dipole) - np.linalg.norm(full)
    measured = (delta, delta_f, d_dip - d_full, i_dip - i_full)
    np.testing.assert_allclose(measured, DIFFERENCES[site], rtol=0, atol=0.01)


def test_secular_variation_and_epoch():
    epoch = igrf_dipole()
    np.testing.assert_array_equal(
        [epoch.g10_nt, epoch.g11_nt, epoch.h11_nt, epoch.radius_m],
        [-29404.8, -1450.9, 4652.5, 6371200.0],
    )
    c = igrf_dipole(YEAR)
    np.testing.assert_allclose(
        [c.g10_nt, c.g11_nt, c.h11_nt],
        [-29404.8 + 1.7 * 5.7, -1450.9 + 1.7 * 7.4, 4652.5 - 1.7 * 25.9],
        rtol=1e-14,
    )
    assert c.g10_nt.dtype == jnp.float64


@pytest.mark.parametrize("year", [2019.99, 2025.01, 1990.0])
def test_refuses_years_outside_validity(year):
    with pytest.raises(ValueError, match=rf"{year}.*2020\.0–2025\.0"):
        igrf_dipole(year)


def test_jit_and_vmap():
    c = igrf_dipole(YEAR)
    points = np.array(site_points())
    lat, lon, alt = (jnp.asarray(points[:, k]) for k in range(3))
    batched = jax.jit(jax.vmap(dipole_field_ned, in_axes=(None, 0, 0, 0)))(c, lat, lon, alt)
    assert batched.x.dtype == jnp.float64
    for k, point in enumerate(points):
        np.testing.assert_allclose(ned(batched)[:, k], ned(dipole_field_ned(c, *point)), rtol=1e-13)

    dated = [igrf_dipole(year) for year in (2020.0, YEAR, 2025.0)]
    stacked = jax.tree_util.tree_map(lambda *x: jnp.stack(x), *dated)
    per_year = jax.vmap(dipole_field_ned, in_axes=(0, None, None, None))(stacked, *points[0])
    for k, coefficients in enumerate(dated):
        expected = ned(dipole_field_ned(coefficients, *points[0]))
        np.testing.assert_allclose(ned(per_year)[:, k], expected, rtol=1e-13)


@pytest.mark.parametrize("altitude_m", [0.0, 5e3, 400e3])
def test_vertical_at_geomagnetic_poles(altitude_m):
    # The centred dipole's axis is g = (g11, h11, g10); the north geomagnetic pole lies along −g
    # (80.7° N, 72.7° W at 2021.7), where the field points straight down with 2|g|(a/r)³.
    c = igrf_dipole(YEAR)
    g = np.array([float(c.g11_nt), float(c.h11_nt), float(c.g10_nt)])
    scale = 2.0 * np.linalg.norm(g) * (float(c.radius_m) / (float(c.radius_m) + altitude_m)) ** 3
    for sign in (1.0, -1.0):  # north pole: down; south pole: up
        axis = -sign * g / np.linalg.norm(g)
        lat, lon = math.asin(axis[2]), math.atan2(axis[1], axis[0])
        b = ned(dipole_field_ned(c, lat, lon, altitude_m))
        np.testing.assert_allclose(b, [0.0, 0.0, sign * scale], rtol=0, atol=1e-9 * scale)


def test_falls_as_inverse_cube_of_radius():
    c = igrf_dipole(YEAR)
    lat, lon, _ = site_points()[0]
    altitudes = jnp.array([0.0, 1416.0, 5e3, 100e3, 1000e3])
    b = ned(jax.vmap(dipole_field_ned, in_axes=(None, None, None, 0))(c, lat, lon, altitudes))
    ratio = (6371200.0 / (6371200.0 + np.asarray(altitudes))) ** 3
    np.testing.assert_allclose(b / b[:, :1], np.broadcast_to(ratio, b.shape), rtol=1e-13)


@pytest.mark.parametrize("site", SITES)
def test_gradient_in_the_sites_axes(site):
    # The field at a point offset from the site, in the site's NED axes (the flat Earth's), by central differences
    # of the ECEF closed form (a second formulation: no latitudes, no local axes at the offset point). Steps of 10 m
    # against a field that changes on the Earth's scale (a/3 ≈ 2000 km): truncation ~(10/2e6)² ~ 3e-11 of the
    # gradient, roundoff ~1e-16·|B|/10 m; 1e-7 of the gradient's size leaves room for both.
    lat, lon, alt = SITES[site]
    field, gradient = site_field_gradient(lat, lon, alt)
    c = igrf_dipole()
    a = float(c.radius_m)
    g = 1e-9 * np.array([float(c.g11_nt), float(c.h11_nt), float(c.g10_nt)])
    sl, cl, so, co = (f(math.radians(x)) for f, x in ((np.sin, lat), (np.cos, lat), (np.sin, lon), (np.cos, lon)))
    ecef_to_ned = np.array([[-sl * co, -sl * so, cl], [-so, co, 0.0], [-cl * co, -cl * so, -sl]])
    centre = (a + alt) * np.array([cl * co, cl * so, sl])

    def at(offset_n):
        r = centre + ecef_to_ned.T @ offset_n
        r_hat = r / np.linalg.norm(r)
        return ecef_to_ned @ ((a / np.linalg.norm(r)) ** 3 * (3.0 * (g @ r_hat) * r_hat - g))

    step = 10.0
    reference = np.stack([(at(step * e) - at(-step * e)) / (2 * step) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(field, at(np.zeros(3)), rtol=1e-12)
    np.testing.assert_allclose(gradient, reference, rtol=0, atol=1e-7 * np.abs(reference).max())
    # A field with a potential in free space: the gradient is symmetric (curl-free) and traceless (divergence-free)
    np.testing.assert_allclose(gradient, gradient.T, rtol=0, atol=1e-12 * np.abs(gradient).max())
    assert abs(np.trace(gradient)) < 1e-12 * np.abs(gradient).max()
