"""Dryden turbulence against the analytic spectra and intensities of MIL-F-8785C.

The spectra are written here independently of the implementation, one-sided in frequency f [Hz]
(∫₀^∞ S df = σ²), τ = L/V:

    S_u(f) = 4τσ² / (1 + (2πfτ)²)
    S_v(f) = S_w(f) = 2τσ² (1 + 3(2πfτ)²) / (1 + (2πfτ)²)²

The series are generated at the flight's own 50 Hz. Samples of a continuous process carry its
spectrum folded about the Nyquist frequency, S(f) + Σ_k [S(k·fs − f) + S(k·fs + f)]; that folded
Dryden spectrum is the reference (at 10 Hz it lies 12 % above the unfolded S_u, 3 % above S_v).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.signal

from rocketmc.env import Turbulence, advance_turbulence, gust_n, initial_turbulence, turbulence_noise, turbulence_scales
from rocketmc.env.turbulence import FT, KNOT, high_altitude_scales, low_altitude_scales
from rocketmc.math import Quat, Vec3

FS_HZ = 50.0  # the flight's control rate
N_STEPS = 2**17  # 2621 s per series
N_SERIES = 32  # independent flights per case
NORTHWARD = Vec3(jnp.asarray(1.0), 0.0, 0.0)  # mean wind toward north: low-altitude axes = NED
LEVEL = Quat(1.0, 0.0, 0.0, 0.0)  # body axes = NED


@jax.jit
def gust_series(severity, height_m, speed_mps, key):
    """(N_SERIES, N_STEPS, 3) gusts [m/s] at a fixed height and speed, one series per key split."""

    def one(k):
        turbulence = Turbulence.from_severity(severity, k)

        scales = turbulence_scales(turbulence, height_m)

        def step(state, noise):
            g = gust_n(state, scales, NORTHWARD, LEVEL)
            return advance_turbulence(state, scales, speed_mps, 1.0 / FS_HZ, noise), g.to_array()

        noise = turbulence_noise(turbulence, 0, N_STEPS)  # one block: the block length does not matter here
        return jax.lax.scan(step, initial_turbulence(turbulence), noise)[1]

    return jax.vmap(one)(jax.random.split(key, N_SERIES))


def analytic_psd(f, sigma, length_m, speed_mps, longitudinal):
    tau = length_m / speed_mps
    x = (2 * np.pi * f * tau) ** 2
    return 4 * tau * sigma**2 / (1 + x) if longitudinal else 2 * tau * sigma**2 * (1 + 3 * x) / (1 + x) ** 2


def folded_psd(f, *args, **kwargs):
    """``analytic_psd`` of the series sampled at FS_HZ (aliases up to 10⁴·fs: the rest is < 1e-6 of it)."""
    k = np.arange(1, 10_001)[:, None] * FS_HZ
    return analytic_psd(f, *args, **kwargs) + (analytic_psd(k - f, *args, **kwargs) + analytic_psd(k + f, *args, **kwargs)).sum(0)


# Octave bands over 0.05–10 Hz. The spectra fall 10³-fold across them; the estimate in the lowest
# band has ~2 % relative standard error (bandwidth 0.05 Hz × 84 000 s of turbulence per case).
BAND_EDGES_HZ = np.array([0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4, 10.0])

CASES = {
    "low altitude, light": (1.0, 100.0, 100.0),  # 328 ft, W20 = 15 kt
    "low altitude, moderate": (2.0, 250.0, 60.0),  # 820 ft, W20 = 30 kt
    "high altitude, light": (1.0, 1500.0, 200.0),  # 4921 ft
    "high altitude, severe": (3.0, 3000.0, 150.0),  # 9843 ft
}


@pytest.mark.parametrize("case", CASES)
def test_spectra_and_variances_match_the_standard(case):
    severity, height, speed = CASES[case]
    gusts = np.asarray(gust_series(severity, height, speed, jax.random.key(list(CASES).index(case))))
    low = height < 1000 * FT
    scales = low_altitude_scales(severity * 15 * KNOT, height) if low else high_altitude_scales(severity, height)
    sigmas = np.array([float(s) for s in scales[:3]])
    lengths = np.array([float(s) for s in scales[3:]])

    # Sample variances within 5 % of σ²: the estimator's own relative error is about sqrt(τ/T) ≤ 0.7 %
    # for τ = L/V up to 3.6 s over T = 84 000 s of flight.
    np.testing.assert_allclose(gusts.var(axis=(0, 1)), sigmas**2, rtol=0.05)

    f, psd = scipy.signal.welch(gusts, fs=FS_HZ, nperseg=2**13, axis=1)
    psd = psd.mean(axis=0)
    for component in range(3):
        reference = folded_psd(f, sigmas[component], lengths[component], speed, longitudinal=component == 0)
        for lo, hi in zip(BAND_EDGES_HZ[:-1], BAND_EDGES_HZ[1:]):
            band = (f >= lo) & (f < hi)
            ratio = psd[band, component].sum() / reference[band].sum()
            assert ratio == pytest.approx(1.0, abs=0.10), f"{'uvw'[component]} {lo}-{hi} Hz: {ratio:.3f}"


def test_intensities_and_scale_lengths():
    # low altitude, MIL-F-8785C with h in ft: at 500 ft, W20 = 30 kt
    s = low_altitude_scales(30 * KNOT, 500 * FT)
    k = 0.177 + 0.000823 * 500
    assert float(s.sigma_w) == pytest.approx(0.1 * 30 * KNOT, rel=1e-15)
    assert float(s.sigma_u) == pytest.approx(0.1 * 30 * KNOT / k**0.4, rel=1e-14)
    assert float(s.length_u) == pytest.approx(500 / k**1.2 * FT, rel=1e-14)
    assert float(s.length_w) == pytest.approx(500 * FT, rel=1e-14)
    # clamped to [10, 1000] ft
    assert float(low_altitude_scales(1.0, 0.0).length_w) == pytest.approx(10 * FT, rel=1e-15)
    assert float(low_altitude_scales(1.0, 5000.0).length_w) == pytest.approx(1000 * FT, rel=1e-15)
    # high altitude: the table's nodes (ft/s) and L = 1750 ft, not below 2000 ft
    assert float(high_altitude_scales(3.0, 7500 * FT).sigma_u) == pytest.approx(23.6 * FT, rel=1e-14)
    assert float(high_altitude_scales(2.0, 15000 * FT).sigma_w) == pytest.approx(8.0 * FT, rel=1e-14)
    assert float(high_altitude_scales(1.0, 0.0).sigma_v) == pytest.approx(float(high_altitude_scales(1.0, 2000 * FT).sigma_v))
    assert float(high_altitude_scales(0.0, 3000.0).sigma_u) == 0.0
    assert float(high_altitude_scales(2.0, 3000.0).length_v) == pytest.approx(1750 * FT, rel=1e-15)


def test_frames_and_blend():
    turbulence = Turbulence.from_severity(2.0, jax.random.key(3))
    state = initial_turbulence(turbulence)
    eastward = Vec3(jnp.asarray(0.0), jnp.asarray(5.0), 0.0)
    # low altitude: u along the mean wind (east here), v to its right (south), w down
    def gust(height, wind, q_nb):
        return gust_n(state, turbulence_scales(turbulence, height), wind, q_nb)

    at_north, at_east = gust(100.0, NORTHWARD, LEVEL), gust(100.0, eastward, LEVEL)
    np.testing.assert_allclose(at_east.to_array(), [-at_north.y, at_north.x, at_north.z], atol=1e-12)
    # high altitude: body axes; a body yawed 90° right turns body x into east
    yawed = Quat.from_euler(np.pi / 2, 0.0, 0.0)
    level, turned = gust(3000.0, NORTHWARD, LEVEL), gust(3000.0, NORTHWARD, yawed)
    np.testing.assert_allclose(turned.to_array(), [-level.y, level.x, level.z], atol=1e-12)
    # 1500 ft: √½ of each regime's gust, so the variance is the mean of the two
    mid = 1500 * FT
    low, high = gust(1000 * FT, NORTHWARD, LEVEL).to_array(), gust(2000 * FT, NORTHWARD, LEVEL).to_array()
    np.testing.assert_allclose(gust(mid, NORTHWARD, LEVEL).to_array(), (low + high) * np.sqrt(0.5), rtol=1e-12)


def test_frozen_field_at_rest_and_finite_for_tiny_steps():
    turbulence = Turbulence.from_severity(3.0, jax.random.key(5))
    state = initial_turbulence(turbulence)
    scales = turbulence_scales(turbulence, 100.0)
    noise = turbulence_noise(turbulence, 0, 1)[0]
    still = advance_turbulence(state, scales, 0.0, 0.02, noise)  # V = 0: Taylor's field does not move
    for a, b in zip(jax.tree_util.tree_leaves(state.low), jax.tree_util.tree_leaves(still.low)):
        assert float(a) == float(b)
    crawl = advance_turbulence(state, scales, 1e-6, 1e-4, noise)
    assert all(np.isfinite(float(x)) for x in jax.tree_util.tree_leaves(crawl))


def test_reproducible_per_key_and_independent_between_keys():
    severity, height, speed = CASES["low altitude, light"]
    a = np.asarray(gust_series(severity, height, speed, jax.random.key(11)))
    b = np.asarray(gust_series(severity, height, speed, jax.random.key(11)))
    np.testing.assert_array_equal(a, b)  # same key, same gusts, to the bit
    # 32 flights: the zero-lag correlation of every pair of their u series. For independent
    # Ornstein–Uhlenbeck series its standard error is sqrt(τ/T) (τ = L_u/V = 2.6 s, T = 2621 s): 0.03.
    u = a[:, :, 0]
    correlation = np.corrcoef(u)[np.triu_indices(N_SERIES, 1)]
    tau = float(low_altitude_scales(15 * KNOT, height).length_u) / speed
    standard_error = np.sqrt(tau / (N_STEPS / FS_HZ))
    assert np.abs(correlation).max() < 5 * standard_error
    assert abs(correlation.mean()) < 5 * standard_error / np.sqrt(correlation.size)


if __name__ == "__main__":  # the figures quoted in docs/validation.md
    for name, (severity, height, speed) in CASES.items():
        gusts = np.asarray(gust_series(severity, height, speed, jax.random.key(list(CASES).index(name))))
        scales = low_altitude_scales(severity * 15 * KNOT, height) if height < 1000 * FT else high_altitude_scales(severity, height)
        sigma, length = np.array([float(x) for x in scales[:3]]), np.array([float(x) for x in scales[3:]])
        f, psd = scipy.signal.welch(gusts, fs=FS_HZ, nperseg=2**13, axis=1)
        worst = []
        for c in range(3):
            reference = folded_psd(f, sigma[c], length[c], speed, longitudinal=c == 0)
            bands = [(f >= lo) & (f < hi) for lo, hi in zip(BAND_EDGES_HZ[:-1], BAND_EDGES_HZ[1:])]
            worst.append(max(abs(psd.mean(0)[b, c].sum() / reference[b].sum() - 1) for b in bands))
        print(f"{name}: σ u,v,w {np.round(sigma, 2)} m/s, L {np.round(length)} m, V {speed} m/s; variance error "
              f"{np.round(100 * (gusts.var(axis=(0, 1)) / sigma**2 - 1), 1)} %, worst octave-band PSD error "
              f"{np.round(100 * np.array(worst), 1)} %")  # fmt: skip
