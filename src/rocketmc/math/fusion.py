"""Values that XLA's CPU fusion should compute once.

XLA's CPU backend fuses an elementwise producer into each kernel that consumes it, so a value read by many
kernels is computed again in every one of them: a sine or cosine read by a dozen leaves of the flight state is a
dozen sines a period (docs/performance.md, "Transcendentals computed once"). A reduction over a stacked axis is
not fused into its consumers: its result is computed once and read back.
"""

from __future__ import annotations

import jax.numpy as jnp


def computed_once(x):
    """``x``, bit for bit, computed once however many kernels read it: the maximum of ``x`` and −∞ (a reduction
    over a stacked axis, which XLA's CPU fusion does not copy into its consumers; NaN stays NaN, −0 stays −0)."""
    return jnp.max(jnp.stack([x, jnp.full_like(x, -jnp.inf)]), axis=0)
