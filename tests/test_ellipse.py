"""Confidence ellipses against closed forms and a large known 2-D normal sample."""

import math

import numpy as np
import pytest

from rocketmc.analysis import Ellipse, chi2_scale, confidence_ellipse
from rocketmc.ellipse import bootstrap_intervals, ellipse_area_m2

N_BIG = 200_000
# True impact distribution (north, east) [m]: std 250 m along azimuth 30 deg, 80 m across.
MEAN = np.array([1200.0, -400.0])
_AZ = np.deg2rad(30.0)
_R = np.array([[np.cos(_AZ), -np.sin(_AZ)], [np.sin(_AZ), np.cos(_AZ)]])
COV = _R @ np.diag([250.0**2, 80.0**2]) @ _R.T


@pytest.fixture(scope="module")
def big_sample():
    rng = np.random.default_rng(20240611)
    pts = rng.multivariate_normal(MEAN, COV, size=N_BIG)
    return pts[:, 0], pts[:, 1]


def _axis_distance_deg(a, b):
    """Distance between two axis directions [deg] (modulo 180)."""
    d = (a - b) % 180.0
    return min(d, 180.0 - d)


@pytest.mark.parametrize("level", [0.5, 0.9, 0.95, 0.99, 0.999])
def test_chi2_scale_closed_form(level):
    # chi-square with 2 dof is exponential(1/2): ppf(p) = -2 ln(1-p); 1e-12 covers the
    # round-off of scipy's ppf evaluation (values are O(1..14)).
    assert chi2_scale(level) == pytest.approx(-2.0 * math.log1p(-level), rel=0, abs=1e-12)


@pytest.mark.parametrize("level", [0.0, 1.0, -0.1, 1.5])
def test_invalid_level_rejected(level):
    with pytest.raises(ValueError, match="level"):
        chi2_scale(level)


@pytest.mark.parametrize("level", [0.5, 0.95, 0.99])
def test_coverage_of_large_normal_sample(big_sample, level):
    north, east = big_sample
    e = confidence_ellipse(north, east, level)
    frac = e.contains(north, east).mean()
    # Binomial 5-sigma bound on the empirical fraction; the ellipse being estimated from the
    # same sample adds only O(1/N) to the spread.
    sigma = math.sqrt(level * (1.0 - level) / N_BIG)
    assert abs(frac - level) < 5.0 * sigma


def test_axes_and_orientation_match_true_covariance(big_sample):
    north, east = big_sample
    e = confidence_ellipse(north, east, 0.95)
    # Closed form for the 2x2 covariance [[snn, sne], [sne, see]].
    snn, see, sne = COV[0, 0], COV[1, 1], COV[0, 1]
    half_sum, root = 0.5 * (snn + see), math.hypot(0.5 * (snn - see), sne)
    k2 = -2.0 * math.log(1.0 - 0.95)
    a_true, b_true = math.sqrt(k2 * (half_sum + root)), math.sqrt(k2 * (half_sum - root))
    az_true = math.degrees(0.5 * math.atan2(2.0 * sne, snn - see)) % 180.0
    assert az_true == pytest.approx(30.0)
    # Sample eigenvalues have relative std sqrt(2/N) = 0.32 %, semi-axes half that (0.16 %):
    # 1 % is over 5 sigma.
    assert e.semi_major_m == pytest.approx(a_true, rel=1e-2)
    assert e.semi_minor_m == pytest.approx(b_true, rel=1e-2)
    # Eigenvector angle std ~ sqrt(l1*l2 / (N (l1-l2)^2)) = 0.05 deg: 0.25 deg is 5 sigma.
    assert _axis_distance_deg(e.orientation_deg, az_true) < 0.25
    # Mean std = sigma / sqrt(N) <= 250 / 447 = 0.56 m: 3 m is over 5 sigma.
    assert e.center_north_m == pytest.approx(MEAN[0], abs=3.0)
    assert e.center_east_m == pytest.approx(MEAN[1], abs=3.0)
    assert e.n == N_BIG


def _cross(a, b, azimuth_deg):
    """Points +-a along azimuth (clockwise from north) and +-b across it, about (10, 20)."""
    az = np.deg2rad(azimuth_deg)
    major = np.array([np.cos(az), np.sin(az)])
    minor = np.array([-np.sin(az), np.cos(az)])
    pts = np.array([a * major, -a * major, b * minor, -b * minor]) + np.array([10.0, 20.0])
    return pts[:, 0], pts[:, 1]


@pytest.mark.parametrize("azimuth", [0.0, 45.0, 90.0, 135.0, 170.0])
def test_orientation_of_rotated_cross(azimuth):
    north, east = _cross(30.0, 10.0, azimuth)
    e = confidence_ellipse(north, east, 0.95)
    # Exact construction: only floating-point round-off in eigh.
    assert _axis_distance_deg(e.orientation_deg, azimuth) < 1e-9
    assert 0.0 <= e.orientation_deg < 180.0
    # Sample covariance (ddof=1) of the cross: 2 a^2 / 3 along, 2 b^2 / 3 across.
    k2 = chi2_scale(0.95)
    assert e.semi_major_m == pytest.approx(math.sqrt(k2 * 2 * 30.0**2 / 3), rel=1e-12)
    assert e.semi_minor_m == pytest.approx(math.sqrt(k2 * 2 * 10.0**2 / 3), rel=1e-12)
    assert (e.center_north_m, e.center_east_m) == pytest.approx((10.0, 20.0), abs=1e-12)


def test_major_axis_along_east_is_90_and_north_east_is_45():
    e = confidence_ellipse([0.0, 0.0, 1.0, -1.0], [5.0, -5.0, 0.0, 0.0])
    assert e.orientation_deg == pytest.approx(90.0, abs=1e-9)  # round-off only
    e = confidence_ellipse([3.0, -3.0, 1.0, -1.0], [3.0, -3.0, -1.0, 1.0])
    assert e.orientation_deg == pytest.approx(45.0, abs=1e-9)  # round-off only


def test_area_is_pi_a_b():
    e = confidence_ellipse(*_cross(30.0, 10.0, 20.0), level=0.99)
    assert e.area_m2 == pytest.approx(math.pi * e.semi_major_m * e.semi_minor_m, rel=1e-15)
    # The drawn boundary encloses the same area (shoelace on 20 000 points: O(1/n^2) error).
    n, east = e.boundary(20_000)
    shoelace = 0.5 * abs(np.dot(east, np.roll(n, 1)) - np.dot(n, np.roll(east, 1)))
    assert shoelace == pytest.approx(e.area_m2, rel=1e-6)


def test_boundary_lies_on_the_ellipse():
    e = confidence_ellipse(*_cross(30.0, 10.0, 60.0))
    north, east = e.boundary(n_points=50)
    assert north.shape == east.shape == (50,)
    assert (north[0], east[0]) == pytest.approx((north[-1], east[-1]))  # closed
    # Boundary points are inside when shrunk slightly toward the centre, outside when grown
    # (1e-9 relative: far above round-off, far below any real error).
    for scale, inside in [(1 - 1e-9, True), (1 + 1e-9, False)]:
        pn = e.center_north_m + scale * (north - e.center_north_m)
        pe = e.center_east_m + scale * (east - e.center_east_m)
        assert np.all(e.contains(pn, pe) == inside)


def test_nan_rows_ignored():
    north, east = _cross(30.0, 10.0, 20.0)
    clean = confidence_ellipse(north, east)
    north_bad = np.concatenate([north, [np.nan, 5.0, np.inf]])
    east_bad = np.concatenate([east, [1.0, np.nan, 2.0]])
    dirty = confidence_ellipse(north_bad, east_bad)
    assert dirty == clean
    assert dirty.n == 4


def test_too_few_points_raises():
    with pytest.raises(ValueError, match="at least 3 finite"):
        confidence_ellipse([1.0, 2.0, np.nan], [1.0, 2.0, 3.0])


def test_length_mismatch_raises():
    with pytest.raises(ValueError, match="differ in length"):
        confidence_ellipse([1.0, 2.0, 3.0], [1.0, 2.0])


def test_degenerate_ellipse_of_identical_points():
    e = confidence_ellipse([5.0] * 4, [7.0] * 4)
    assert (e.semi_major_m, e.semi_minor_m, e.area_m2) == (0.0, 0.0, 0.0)
    assert e.contains([5.0, 5.1], [7.0, 7.0]).tolist() == [True, False]


def test_to_dict_fields():
    e = confidence_ellipse(*_cross(30.0, 10.0, 20.0), level=0.5)
    d = e.to_dict()
    assert set(d) == {
        "level", "center_north_m", "center_east_m", "semi_major_m", "semi_minor_m",
        "orientation_deg", "area_m2", "n",
    }
    assert d["area_m2"] == e.area_m2 and d["level"] == 0.5
    assert isinstance(e, Ellipse)


def test_bootstrap_area_formula_and_interval_coverage():
    """The vectorised area equals the ellipse's; the 95 % percentile-bootstrap interval of the area and
    centre holds the true values (π·k²·sqrt(det Σ), the mean) in 95 % of 200 independent samples of
    N = 300 correlated normal points: within 4 binomial standard errors (1.5 % each) of 95 %."""
    rng = np.random.default_rng(11)
    cov = np.array([[500.0**2, 0.6 * 500 * 300], [0.6 * 500 * 300, 300.0**2]])
    true_area = np.pi * chi2_scale(0.95) * np.sqrt(np.linalg.det(cov))
    points = rng.multivariate_normal([100.0, -50.0], cov, size=(200, 300))
    assert ellipse_area_m2(points[0, :, 0], points[0, :, 1]) == pytest.approx(
        confidence_ellipse(points[0, :, 0], points[0, :, 1]).area_m2, rel=1e-12
    )
    hits = {"area_m2": 0, "center_north_m": 0, "center_east_m": 0}
    truth = {"area_m2": true_area, "center_north_m": 100.0, "center_east_m": -50.0}
    for sample in points:
        intervals = bootstrap_intervals(sample[:, 0], sample[:, 1], n_resamples=1000, seed=1)
        for name, (low, high) in intervals.items():
            hits[name] += low <= truth[name] <= high
    for name, count in hits.items():
        assert abs(count / 200 - 0.95) < 4 * np.sqrt(0.95 * 0.05 / 200), (name, count)
