"""interp1d against numpy.interp: inside, at the breakpoints, clamped outside, under vmap."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.math import interp1d

# Two different but exact-in-real-arithmetic formulas (numpy: slope·(x − x0) + f0; ours:
# f0 + s·(f1 − f0)): they differ by a few roundings of the values (|f| ≤ ~1500 here), so
# 1e-12 relative plus 1e-12·max|f| absolute.
RTOL = 1e-12


def tables():
    rng = np.random.default_rng(7)
    xp_random = np.sort(rng.uniform(-3.0, 5.0, 12))
    return {
        "ca0_mach": (np.array([0.0, 0.2, 0.5, 0.7, 0.85, 1.0]), np.array([0.420, 0.420, 0.378, 0.362, 0.383, 0.605])),
        "random": (xp_random, rng.normal(size=12) * 100.0),
        "two_points": (np.array([1.0, 2.0]), np.array([-4.0, 6.0])),
        "l1350_head": (np.array([0.0, 0.016, 0.034, 0.049, 0.081]), np.array([0.0, 1421.724, 1345.218, 1502.479, 1415.348])),
    }


batched = jax.jit(jax.vmap(interp1d, in_axes=(0, None, None)))


@pytest.mark.parametrize("name", list(tables()))
def test_matches_numpy_interp_under_vmap(name):
    xp, fp = tables()[name]
    span = xp[-1] - xp[0]
    mids = 0.5 * (xp[1:] + xp[:-1])
    x = np.concatenate(
        [
            np.linspace(xp[0] - 0.5 * span, xp[-1] + 0.5 * span, 301),  # inside and both sides outside
            xp,  # exactly at every breakpoint
            mids,
            [xp[0] - 1e6, xp[-1] + 1e6, np.nextafter(xp[0], -np.inf), np.nextafter(xp[-1], np.inf)],
        ]
    )
    got = np.asarray(batched(jnp.asarray(x), jnp.asarray(xp), jnp.asarray(fp)))
    scale = np.max(np.abs(fp))
    np.testing.assert_allclose(got, np.interp(x, xp, fp), rtol=RTOL, atol=RTOL * scale)
    # clamping: constant end values outside the table
    below, above = got[x < xp[0]], got[x > xp[-1]]
    np.testing.assert_allclose(below, fp[0], rtol=RTOL, atol=RTOL * scale)
    np.testing.assert_allclose(above, fp[-1], rtol=RTOL, atol=RTOL * scale)
    # interior breakpoints: s = 0 selects f0 with no arithmetic, so they are exact
    np.testing.assert_array_equal(got[301 : 301 + len(xp) - 1], fp[:-1])


def test_scalar_and_vmap_agree_and_jit():
    xp, fp = tables()["random"]
    x = np.linspace(-4.0, 6.0, 37)
    single = jax.jit(interp1d)
    loop = np.array([float(single(xi, xp, fp)) for xi in x])
    np.testing.assert_array_equal(np.asarray(batched(jnp.asarray(x), xp, fp)), loop)  # same ops: bit-identical


def test_piecewise_linear_slope_and_continuity():
    """The derivative inside a segment is the segment's slope (jax.grad through the search)."""
    xp, fp = tables()["ca0_mach"]
    grad = jax.grad(interp1d)
    for i in range(len(xp) - 1):
        x = 0.3 * xp[i] + 0.7 * xp[i + 1]
        slope = (fp[i + 1] - fp[i]) / (xp[i + 1] - xp[i])
        np.testing.assert_allclose(float(grad(x, xp, fp)), slope, rtol=1e-12, atol=1e-15)  # rounding of one quotient
    assert float(grad(-1.0, xp, fp)) == 0.0  # clamped: flat outside
    assert float(grad(2.0, xp, fp)) == 0.0
