"""Functions whose forward values are numpy's but whose derivatives stay finite where the textbook one is not.

A flight meets these points as a matter of course: a speed of exactly zero on the rail, a blend weight clipped to
exactly 0 or 1, a variance that is zero over a zero step. There the forward value is exact, and the derivative
chosen is the one of the continuous side (zero), not inf or NaN, which a jvp or a grad would otherwise carry to every
output of the flight. The forward computation is unchanged, bit for bit: ``custom_jvp`` changes only the derivative.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp


@jax.custom_jvp
def safe_sqrt(x):
    """√x for x ≥ 0, with derivative 1/(2√x) where x > 0 and 0 at x = 0 (where the textbook one is infinite)."""
    return jnp.sqrt(x)


@safe_sqrt.defjvp
def _safe_sqrt_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    y = jnp.sqrt(x)
    positive = x > 0.0
    return y, jnp.where(positive, dx / (2.0 * jnp.where(positive, y, 1.0)), 0.0)


@jax.custom_jvp
def safe_arctan2(y, x):
    """arctan2(y, x), with derivative 0 at y = x = 0 (where the textbook one is 0/0)."""
    return jnp.arctan2(y, x)


@safe_arctan2.defjvp
def _safe_arctan2_jvp(primals, tangents):
    (y, x), (dy, dx) = primals, tangents
    r2 = x * x + y * y
    nonzero = r2 > 0.0
    return jnp.arctan2(y, x), jnp.where(nonzero, (x * dy - y * dx) / jnp.where(nonzero, r2, 1.0), 0.0)
