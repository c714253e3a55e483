"""The launch site's local frame: north/east metres on the flat tangent plane at the pad (the
simulation's NED origin) against WGS84 latitude/longitude, on the host.

The plane uses the WGS84 radii of curvature at the pad: over the few km of a landing ellipse the
flat-Earth error is below a metre (it grows as distance³/R², 0.1 m at 10 km).
"""

from __future__ import annotations

import numpy as np

WGS84_A = 6378137.0  # semi-major axis [m]
WGS84_E2 = 6.69437999014e-3  # first eccentricity squared


def _radii(latitude_deg) -> tuple[float, float]:
    """Meridian and prime-vertical radii of curvature [m] at a latitude."""
    w = 1.0 - WGS84_E2 * np.sin(np.radians(latitude_deg)) ** 2
    return WGS84_A * (1.0 - WGS84_E2) / w**1.5, WGS84_A / np.sqrt(w)


def north_east_m(latitude_deg, longitude_deg, site_latitude_deg: float, site_longitude_deg: float):
    """North, east [m] from the site of positions given in degrees."""
    meridian, prime = _radii(site_latitude_deg)
    north = np.radians(np.asarray(latitude_deg) - site_latitude_deg) * meridian
    east = np.radians(np.asarray(longitude_deg) - site_longitude_deg) * prime * np.cos(np.radians(site_latitude_deg))
    return north, east


def latitude_longitude_deg(north_m, east_m, site_latitude_deg: float, site_longitude_deg: float):
    """Latitude, longitude [deg] of positions north/east [m] of the site (inverse of ``north_east_m``)."""
    meridian, prime = _radii(site_latitude_deg)
    latitude = site_latitude_deg + np.degrees(np.asarray(north_m) / meridian)
    longitude = site_longitude_deg + np.degrees(np.asarray(east_m) / (prime * np.cos(np.radians(site_latitude_deg))))
    return latitude, longitude
