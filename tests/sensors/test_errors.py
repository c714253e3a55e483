"""The error primitives (sensors/errors.py) against their definitions: quantisation and saturation exact at
the LSB and range edges, sample-and-hold on its ticks with its latency, the walk stepping only at samples,
the gain matrix against numpy, the noise conversions against the Allan deviation's closed forms."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.sensors.errors import (
    Channel, corrupt, initial_channel, noise_per_sample, quantize, sample, saturate, walk_per_sample,
)  # fmt: skip

LSB = 0.25  # a power of two: every multiple and half-multiple below is exact in binary


def channel(n=3, **kwargs) -> Channel:
    fields = dict(gain=None, bias=jnp.zeros(n), noise_std=jnp.asarray(0.0), walk_std=jnp.asarray(0.0),
                  low=jnp.asarray(-10.0), high=jnp.asarray(10.0), lsb=jnp.asarray(LSB))  # fmt: skip
    return Channel(**(fields | kwargs))


def test_quantize_rounds_half_away_from_zero_to_the_lsb():
    x = jnp.array([0.0, 0.124, 0.125, 0.126, -0.125, -0.124, 0.375, -0.375, 2.5, -2.5, 1.0])
    expected = [0.0, 0.0, 0.25, 0.25, -0.25, 0.0, 0.5, -0.5, 2.5, -2.5, 1.0]
    np.testing.assert_array_equal(quantize(x, LSB), expected)
    np.testing.assert_array_equal(quantize(x, 0.0), x)  # lsb 0: no quantisation


def test_saturate_holds_the_range_edges_exactly():
    x = jnp.array([-10.5, -10.0, -9.999, 0.0, 9.999, 10.0, 1e9])
    np.testing.assert_array_equal(saturate(x, -10.0, 10.0), [-10.0, -10.0, -9.999, 0.0, 9.999, 10.0, 10.0])


def test_a_measurement_saturates_then_quantises():
    # 9.99 + bias 0.2 saturates at 10, a multiple of the LSB; -10.1 saturates at -10; 3.3 rounds to 3.25
    c = channel(bias=jnp.array([0.2, 0.0, 0.0]))
    y, _ = corrupt(c, jnp.array([9.99, -10.1, 3.3]), jnp.zeros(3), jnp.zeros(6))
    np.testing.assert_array_equal(y, [10.0, -10.0, 3.25])


def test_gain_bias_walk_and_noise_add_as_defined():
    rng = np.random.default_rng(1)
    gain, truth, bias, walk, noise = rng.normal(size=(3, 3)), rng.normal(size=3), rng.normal(size=3), rng.normal(size=3), rng.normal(size=6)
    c = channel(gain=jnp.asarray(gain), bias=jnp.asarray(bias), noise_std=jnp.asarray(0.3), walk_std=jnp.asarray(0.05),
                lsb=jnp.asarray(0.0), low=jnp.asarray(-np.inf), high=jnp.asarray(np.inf))  # fmt: skip
    y, new_walk = corrupt(c, jnp.asarray(truth), jnp.asarray(walk), jnp.asarray(noise))
    expected_walk = walk + 0.05 * noise[3:]
    np.testing.assert_allclose(new_walk, expected_walk, rtol=0, atol=1e-15)
    # against numpy's matrix product: sums of three O(1) products, a few ulps
    np.testing.assert_allclose(y, gain @ truth + bias + expected_walk + 0.3 * noise[:3], rtol=0, atol=1e-14)


def test_an_ideal_channel_returns_the_truth():
    c = channel(bias=jnp.ones(3), noise_std=jnp.asarray(1.0), ideal=True)
    y, walk = corrupt(c, jnp.array([0.1, 0.2, 0.3]), jnp.zeros(3), jnp.zeros(0))
    np.testing.assert_array_equal(y, [0.1, 0.2, 0.3])
    assert c.noise_per_tick == 0


def run_ticks(c: Channel, n_ticks: int, truth_at=lambda k: jnp.full(3, float(k))):
    """Deliveries (value, fresh) and walks of ``c`` over ``n_ticks`` ticks (truth k at tick k), noise ones."""
    state, out = initial_channel(c, jnp.asarray(0.0)), []
    for k in range(n_ticks):
        value, fresh, state = sample(c, state, jnp.int32(k), truth_at(k), jnp.ones(c.noise_per_tick))
        out.append((np.asarray(value), bool(fresh), np.asarray(state.walk)))
    return out


def test_sample_and_hold_takes_every_nth_tick_and_walks_only_then():
    c = channel(every=5, walk_std=jnp.asarray(0.25), lsb=jnp.asarray(0.0))
    out = run_ticks(c, 16)
    assert [k for k, (_, fresh, _) in enumerate(out) if fresh] == [0, 5, 10, 15]
    # each sample's walk took one step (noise 1 × 0.25) more than the last: 0.25, 0.5, 0.75, 1.0
    np.testing.assert_array_equal([out[k][2][0] for k in (0, 4, 5, 9, 10, 15)], [0.25, 0.25, 0.5, 0.5, 0.75, 1.0])
    np.testing.assert_array_equal(out[5][0], np.full(3, 5.0 + 0.5))  # truth + walk (noise std 0)


def test_latency_delivers_each_sample_delay_ticks_late():
    c = channel(every=2, delay=3, lsb=jnp.asarray(0.0))
    out = run_ticks(c, 12)
    assert [k for k, (_, fresh, _) in enumerate(out) if fresh] == [3, 5, 7, 9, 11]
    assert [float(out[k][0][0]) for k in (3, 5, 7, 9, 11)] == [0.0, 2.0, 4.0, 6.0, 8.0]


def test_noise_conversions_give_the_allan_levels():
    # white noise of density N sampled at f: per-sample σ = N√f, whose Allan deviation σ/√(fτ) is N at τ = 1 s;
    # a rate random walk of density K steps K/√f per sample
    assert noise_per_sample(0.01, 50.0) == pytest.approx(0.01 * np.sqrt(50.0), rel=1e-15)
    assert walk_per_sample(0.002, 25.0) == pytest.approx(0.002 / 5.0, rel=1e-15)


def test_sample_is_jit_and_vmap_bitwise():
    c = channel(gain=jnp.eye(3) * 1.01, walk_std=jnp.asarray(0.1), noise_std=jnp.asarray(0.2), every=2, delay=1)
    truths = jax.random.normal(jax.random.key(0), (8, 3))
    noises = jax.random.normal(jax.random.key(1), (8, 6))
    state = initial_channel(c, jnp.asarray(0.0))
    one = lambda x, n: sample(c, state, jnp.int32(2), x, n)  # noqa: E731
    batched = jax.jit(jax.vmap(one))(truths, noises)
    for i in range(8):
        single = jax.jit(one)(truths[i], noises[i])
        for a, b in zip(jax.tree_util.tree_leaves(single), jax.tree_util.tree_leaves(batched)):
            np.testing.assert_array_equal(a, b[i])


def test_vibration_adds_its_variance_to_the_sensors_white_noise():
    # σ² = σ_0² + (v·q̄)²: 0.3 and 0.4 make 0.5 (a 3-4-5 triangle, exact in floating point) on the same normals
    c = channel(noise_std=jnp.asarray(0.3), walk_std=None, lsb=jnp.asarray(0.0), vibration=jnp.full(3, 0.004))
    noise = jnp.array([1.0, -2.0, 0.5])
    y, _ = corrupt(c, jnp.zeros(3), jnp.zeros(3), noise, qbar=100.0)
    np.testing.assert_allclose(y, 0.5 * noise, rtol=1e-15)
    assert c.noise_per_tick == 3  # one normal per axis: the vibration draws none of its own
    y, _ = corrupt(c, jnp.zeros(3), jnp.zeros(3), noise, qbar=0.0)  # on the ground: the sensor's own noise
    np.testing.assert_allclose(y, 0.3 * noise, rtol=1e-15)
