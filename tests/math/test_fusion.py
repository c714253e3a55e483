"""``math.fusion.computed_once``: the same bits, one computation however many kernels read it."""

import re

import jax
import jax.numpy as jnp
import numpy as np

from rocketmc.math.fusion import computed_once


def test_the_same_bits():
    """NaN, ±0, ±∞, the smallest subnormal and an ordinary value come back bit for bit, and its gradient is 1."""
    x = jnp.array([np.nan, -0.0, 0.0, -np.inf, np.inf, -5e-324, 1e-308, 3.0])
    y = jax.jit(computed_once)(x)
    assert np.asarray(x).dtype == np.float64 and np.asarray(x).tobytes() == np.asarray(y).tobytes()
    assert jax.grad(lambda v: computed_once(v))(0.7) == 1.0


def _sines(f, *args) -> int:
    return len(re.findall(r" sine\(", jax.jit(f).lower(*args).compile().as_text()))


def test_one_sine_for_thirty_readers():
    """Thirty selects that read sin(x), vmapped: XLA's CPU fusion computes the sine in each of their kernels (the
    count that makes this test meaningful), once through ``computed_once``; the outputs are the same bits."""

    def readers(once):
        def one(x, ys):
            s = jnp.sin(1.1 * x)
            s = computed_once(s) if once else s
            return [jnp.where(ys[k] > 0.0, ys[k] * s + k, ys[k] - k * s) for k in range(30)]

        return jax.vmap(one)

    x, ys = jnp.linspace(-3.0, 3.0, 128), jax.random.normal(jax.random.key(0), (128, 30))
    assert _sines(readers(False), x, ys) == 30 and _sines(readers(True), x, ys) == 1
    for a, b in zip(jax.jit(readers(False))(x, ys), jax.jit(readers(True))(x, ys)):
        assert np.array_equal(np.asarray(a), np.asarray(b))
