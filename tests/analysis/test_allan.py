"""Allan deviation against a direct implementation and the closed forms of white noise, a rate random
walk and a ramp; the noise-term fit on synthetic records of known N and K.

Sampling bands: the overlapping Allan variance of a noise record is σ² · χ²_ν/ν with ν its equivalent
degrees of freedom (Howe, Allan & Barnes 1981; Riley, NIST SP 1065, Table 5), ν ≈ 1.5·n/m for white
noise and ≈ n/m for a rate random walk at m ≪ n; a Monte Carlo of 400 records of 20 000 samples
reproduced both formulas within its own ±10 % (m = 1 … 2000). Each estimate must lie within the
χ²_ν quantiles 1e-6 and 1 − 1e-6.
"""

import numpy as np
import pytest
from scipy.stats import chi2

from rocketmc.analysis.allan import allan_deviation, noise_terms, plot_allan

RATE_HZ = 50.0


def _direct_adev(y, m):
    """Half the mean square difference of adjacent overlapping m-sample averages, square-rooted, by loops."""
    means = np.array([y[i : i + m].mean(axis=0) for i in range(len(y) - m + 1)])
    return np.sqrt(np.mean((means[m:] - means[:-m]) ** 2, axis=0) / 2.0)


def _assert_in_chi2_band(avar, expected, edf):
    low, high = chi2.ppf(1e-6, edf) / edf, chi2.ppf(1.0 - 1e-6, edf) / edf
    ratio = avar / expected
    assert np.all((ratio > low) & (ratio < high)), (ratio, low, high)


def test_matches_the_direct_implementation():
    # 300 samples, two columns with offsets and a trend; 1e-12 relative: float64 rounding of the sums.
    rng = np.random.default_rng(17)
    y = rng.standard_normal((300, 2)) * [0.02, 3.0] + [9.81, -40.0] + np.linspace(0.0, 0.5, 300)[:, None]
    taus, adev = allan_deviation(y, RATE_HZ)
    m = np.rint(taus * RATE_HZ).astype(int)
    assert m[0] == 1 and m[-1] == 30 and np.all(np.diff(m) > 0)  # 1 … n // 10, unique
    assert 10 <= len(m) <= 16  # ~10 per decade over 1.5 decades, fewer where rounding merges them
    assert adev.shape == (len(m), 2)
    np.testing.assert_allclose(adev, [_direct_adev(y, k) for k in m], rtol=1e-12)
    taus_1, adev_1 = allan_deviation(y[:, 1], RATE_HZ, [0.02, 0.5, 3.0])  # one column, explicit taus
    np.testing.assert_array_equal(taus_1, [0.02, 0.5, 3.0])
    np.testing.assert_allclose(adev_1, [_direct_adev(y[:, 1], k) for k in (1, 25, 150)], rtol=1e-12)


@pytest.mark.parametrize("taus", [[0.0], [0.01 / RATE_HZ], [3.02], [[0.1, 0.2]]])
def test_taus_outside_the_record_rejected(taus):
    with pytest.raises(ValueError, match="taus"):
        allan_deviation(np.zeros(300), RATE_HZ, taus)  # 151 samples is more than half of 300


def test_white_noise_closed_form():
    n, sigma = 200_000, 0.05
    y = np.random.default_rng(1).normal(3.0, sigma, n)
    taus, adev = allan_deviation(y, RATE_HZ)
    m, phase_points = taus * RATE_HZ, n + 1
    edf = (3.0 * (phase_points - 1) / (2.0 * m) - 2.0 * (phase_points - 2) / phase_points) * 4 * m**2 / (4 * m**2 + 5)
    _assert_in_chi2_band(adev**2, sigma**2 / (RATE_HZ * taus), edf)  # σ / √(f·τ)


def test_rate_random_walk_closed_form():
    # y_i = Σ K·√(1/f)·w_j: the m-sample averages' difference weighs the increments 1, 2, … m … 2, 1
    # (over m²), so E[σ²] = K²τ0·(2m² + 1)/(6m) = K²τ/3 + K²τ0²/(6τ) exactly (τ0 = 1/f; the second
    # term, 1/(2m²) of the first, vanishes for m ≫ 1).
    n, k_walk = 200_000, 0.01
    y = 2.0 + np.cumsum(k_walk * np.sqrt(1.0 / RATE_HZ) * np.random.default_rng(2).standard_normal(n))
    taus, adev = allan_deviation(y, RATE_HZ)
    m, phase_points, tau0 = taus * RATE_HZ, n + 1, 1.0 / RATE_HZ
    big = phase_points - 1
    edf = (phase_points - 2) / m * (big**2 - 3 * m * big + 4 * m**2) / (phase_points - 3) ** 2
    _assert_in_chi2_band(adev**2, k_walk**2 * (taus / 3.0 + tau0**2 / (6.0 * taus)), edf)


def test_ramp_closed_form():
    # y = R·t: adjacent m-sample averages differ by exactly R·τ, σ = R·τ/√2; 1e-9: rounding of sums of 72 000.
    t = np.arange(72_000) / RATE_HZ
    taus, adev = allan_deviation(0.3 + 2e-3 * t, RATE_HZ)
    np.testing.assert_allclose(adev, 2e-3 * taus / np.sqrt(2.0), rtol=1e-9)


@pytest.fixture(scope="module")
def white_plus_walk():
    """2 h at 50 Hz of white noise N = 2e-3 plus a rate random walk K = 1e-2 (crossover √3·N/K = 0.35 s:
    the white region τ ≤ 0.11 s, 5 taus; the walk region 1.1 s to 720 s, 26 taus)."""
    n, n_white, k_walk = 360_000, 2e-3, 1e-2
    w = np.random.default_rng(2021).standard_normal((n, 2))
    y = n_white * np.sqrt(RATE_HZ) * w[:, 0] + np.cumsum(k_walk * np.sqrt(1.0 / RATE_HZ) * w[:, 1])
    return allan_deviation(y, RATE_HZ), n_white, k_walk


def test_noise_terms_recover_n_and_k(white_plus_walk):
    # Over 200 seeds of this record the errors' standard deviations were: N 0.13 %, K 0.95 %, white
    # slope 0.0016, walk slope 0.014 (the largest of 200: 0.43 %, 3.1 %, 0.005, 0.041). So 10 % is ≥ 10σ
    # for N and K and 0.05 is 30σ and 3.5σ for the slopes. K and the walk slope scatter most: they rest
    # on the long taus (ν ≈ n/m = 10 at τ = 720 s).
    (taus, adev), n_white, k_walk = white_plus_walk
    terms = noise_terms(taus, adev)
    assert terms["N"] == pytest.approx(n_white, rel=0.10)
    assert terms["K"] == pytest.approx(k_walk, rel=0.10)
    assert terms["crossover_s"] == pytest.approx(np.sqrt(3.0) * terms["N"] / terms["K"], rel=1e-12)
    assert terms["white_slope"] == pytest.approx(-0.5, abs=0.05)
    assert terms["walk_slope"] == pytest.approx(0.5, abs=0.05)


def test_noise_terms_of_pure_white_noise():
    # No walk: K fits to nearly 0. A walk equal to the white part at the longest τ (400 s) would be
    # K = √3·N/400 = 0.0043·N; the upward scatter of the long taus (ν ≈ 15 at 400 s) fitted up to
    # 0.006·N over 40 seeds. The bound 0.01·N puts the crossover beyond 173 s and the walk region
    # (τ ≥ √10 × crossover) beyond the record, so the walk slope is NaN.
    n_white = 2e-3
    y = np.random.default_rng(3).normal(0.0, n_white * np.sqrt(RATE_HZ), 200_000)
    terms = noise_terms(*allan_deviation(y, RATE_HZ))
    assert terms["N"] == pytest.approx(n_white, rel=0.01)  # ν ≈ 3·10⁵ at τ = 0.02 s: 0.13 % per point
    assert terms["K"] < 0.01 * n_white
    assert np.isnan(terms["walk_slope"])
    assert terms["white_slope"] == pytest.approx(-0.5, abs=0.02)


def test_plot_allan(tmp_path, white_plus_walk):
    (taus, adev), _, _ = white_plus_walk
    path = tmp_path / "allan.png"
    fig = plot_allan({"gyro x": (taus, adev), "gyro x, first hour": (taus[:-3], adev[:-3])}, path, "rad/s")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (ax,) = fig.axes
    assert ax.get_xscale() == ax.get_yscale() == "log" and "rad/s" in ax.get_ylabel()
    lines = ax.get_lines()
    assert len(lines) == 4  # two series, two reference lines
    for line, slope in zip(lines[2:], (-0.5, 0.5)):  # the reference lines' log-log slopes
        x, y = line.get_data()
        np.testing.assert_allclose(np.diff(np.log(y)) / np.diff(np.log(x)), slope, rtol=1e-9)
    assert lines[2].get_data()[1][0] == pytest.approx(adev[0], rel=1e-12)  # through the first point
