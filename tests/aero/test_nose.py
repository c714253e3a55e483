"""The nose profile shared by the build-up and the drag (``aero.geometry.nose_radius_m``) against
closed forms written out independently, and the two quantities computed from it: the build-up's
nose centre of pressure (Barrowman: L − V/A) and the drag's wetted area."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad

from rocketmc.aero.buildup import normal_force_components
from rocketmc.aero.drag import nose_wetted_area_m2
from rocketmc.aero.geometry import LYNX_AS_FLOWN, NOSE_KINDS, Nose, nose_radius_m

NOSES = ((0.26, 0.075), (0.55829, 0.0635))  # (length, base radius) [m]: the Lynx's and custom_rocket's


def _ogive_rho(length, r):
    return (r**2 + length**2) / (2 * r)


def closed_form_volume_m3(kind, length, r):
    """Volume of the nose [m³]. Haack series, x = L(1 − cos θ)/2:
    V = (R²L/2)∫₀^π (θ − sin 2θ/2 + C sin³θ) sin θ dθ = πR²L(1/2 + 3C/16).
    Tangent ogive: π∫₀^L (√(ρ² − u²) − (ρ − R))² du."""
    rho = _ogive_rho(length, r)
    return {
        "conical": math.pi * r**2 * length / 3,
        "ogive": math.pi * (length * rho**2 - length**3 / 3 - (rho - r) * rho**2 * math.asin(length / rho)),
        "elliptical": 2 * math.pi * r**2 * length / 3,  # half prolate spheroid
        "parabolic": 8 * math.pi * r**2 * length / 15,  # πR²L ∫₀¹ (2ξ − ξ²)² dξ
        "von_karman": math.pi * r**2 * length / 2,
        "haack_lv": 9 * math.pi * r**2 * length / 16,
    }[kind]


def closed_form_wetted_area_m2(kind, length, r):
    """Lateral surface [m²] where it has a closed form (the elliptical nose for length > radius)."""
    rho = _ogive_rho(length, r)
    e = math.sqrt(1 - (r / length) ** 2)
    return {
        "conical": math.pi * r * math.hypot(r, length),
        "ogive": 2 * math.pi * (rho * length - (rho - r) * rho * math.asin(length / rho)),
        "elliptical": math.pi * r**2 * (1 + length * math.asin(e) / (r * e)),
    }[kind]


@pytest.mark.parametrize("length, r", NOSES)
@pytest.mark.parametrize("kind", NOSE_KINDS)
def test_profile_volume_closed_forms(kind, length, r):
    # quad of the profile is good to ~1e-13 even at the infinite slope of the elliptical and Haack tips;
    # 1e-10 leaves margin and still catches any error in a formula (a wrong C or ρ moves V by > 1e-3).
    area = lambda x: math.pi * float(nose_radius_m(kind, length, r, x)) ** 2  # noqa: E731
    volume, _ = quad(area, 0, length, epsabs=0, epsrel=1e-13, limit=200)
    assert volume == pytest.approx(closed_form_volume_m3(kind, length, r), rel=1e-10)


@pytest.mark.parametrize("kind", NOSE_KINDS)
def test_profile_ends_and_held_values(kind):
    length, r = NOSES[0]
    # Tip and base exact to rounding (ogive: R − ρ + ρ, Haack: arccos(−1) = π rounded).
    assert nose_radius_m(kind, length, r, 0.0) == pytest.approx(0.0, abs=1e-15)
    assert nose_radius_m(kind, length, r, length) == pytest.approx(r, rel=1e-14)
    np.testing.assert_array_equal(
        nose_radius_m(kind, length, r, [-1.0, 2 * length]), nose_radius_m(kind, length, r, [0.0, length])
    )
    # Every shape but the cone is tangent to the body at its base: its mean slope over the last ppm of the length
    # is < 1e-3 (the Haack series' slope vanishes only as √(L − x): 2.4e-4 there; the others' < 1e-6; the cone's R/L).
    h = 1e-6 * length
    slope = (r - float(nose_radius_m(kind, length, r, length - h))) / h
    if kind == "conical":
        assert slope == pytest.approx(r / length, rel=1e-9)
    else:
        assert slope < 1e-3


def test_profile_points():
    length, r = NOSES[0]
    # Haack series at mid-length, θ = π/2: r = R √((π/2 + C)/π); cone and parabola at ξ = 1/2; exact to rounding.
    assert nose_radius_m("von_karman", length, r, length / 2) == pytest.approx(r / math.sqrt(2), rel=1e-14)
    haack_mid = r * math.sqrt((math.pi / 2 + 1 / 3) / math.pi)
    assert nose_radius_m("haack_lv", length, r, length / 2) == pytest.approx(haack_mid, rel=1e-14)
    assert nose_radius_m("conical", length, r, length / 2) == pytest.approx(r / 2, rel=1e-15)
    assert nose_radius_m("parabolic", length, r, length / 2) == pytest.approx(0.75 * r, rel=1e-15)
    # Tangent ogive: on the circle of radius ρ centred (L, R − ρ).
    x = np.linspace(0, length, 7)
    rho = _ogive_rho(length, r)
    np.testing.assert_allclose(np.hypot(x - length, nose_radius_m("ogive", length, r, x) - (r - rho)), rho, rtol=1e-14)


@pytest.mark.parametrize("length, r", NOSES)
@pytest.mark.parametrize("kind", ("conical", "ogive", "elliptical"))
def test_drag_wetted_area_closed_forms(kind, length, r):
    # 4000 frusta: exact for the cone; chords under-run a curved meridian by O(h²): measured 1.6e-8 (ogive),
    # 3.5e-7 (elliptical, its tip's curvature); 1e-6 bounds both.
    rel = 1e-12 if kind == "conical" else 1e-6
    assert nose_wetted_area_m2(kind, length, r) == pytest.approx(closed_form_wetted_area_m2(kind, length, r), rel=rel)


@pytest.mark.parametrize("length, r", NOSES)
@pytest.mark.parametrize("kind", NOSE_KINDS)
def test_buildup_nose_centre_of_pressure(kind, length, r):
    # Barrowman: CNα = 2 at x = L − V/A. The build-up integrates the area over 2001 points (trapezoid, O(h²)):
    # measured ≤ 2.4e-8 m (cone, ellipse), 1e-7 m bounds it (0.2 ppm of the nose length).
    geometry = dataclasses.replace(LYNX_AS_FLOWN, body_diameter_m=2 * r, nose=Nose(kind, length))
    nose = normal_force_components(geometry, 0.3)[0]
    assert nose.name == "nose"
    assert float(nose.cn_alpha) == pytest.approx(2.0, rel=1e-12)
    assert nose.cp_m == pytest.approx(length - closed_form_volume_m3(kind, length, r) / (math.pi * r**2), abs=1e-7)
