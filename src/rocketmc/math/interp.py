"""Linear interpolation in short 1-D tables, written for cheap evaluation under ``vmap``."""

from __future__ import annotations

import jax.numpy as jnp


def interp1d(x, xp, fp):
    """Piecewise-linear ``f(x)`` from breakpoints ``xp`` (increasing, (K,)) and values ``fp`` (K,).

    Clamps to the end values outside ``[xp[0], xp[-1]]`` (like ``numpy.interp``). The segment is
    found by comparing ``x`` with all breakpoints, which beats a binary search for the short
    tables of thrust curves and Mach schedules.
    """
    fp = jnp.asarray(fp)
    i, s = segment(x, xp)
    f0, f1 = fp[i], fp[i + 1]
    return f0 + s * (f1 - f0)


def segment(x, xp):
    """The segment ``i`` of breakpoints ``xp`` (increasing, (K,), K ≥ 2) holding ``x`` and the fraction
    ``s`` in [0, 1] of the way from ``xp[i]`` to ``xp[i + 1]`` (clamped to the end segments outside)."""
    xp = jnp.asarray(xp)
    i = jnp.clip(jnp.searchsorted(xp, x, side="right", method="compare_all") - 1, 0, xp.shape[0] - 2)
    x0, x1 = xp[i], xp[i + 1]
    return i, jnp.clip((x - x0) / (x1 - x0), 0.0, 1.0)
