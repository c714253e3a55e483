"""Fixed-step explicit integrators on pytree states."""

from __future__ import annotations

from typing import Callable

import jax
import jax.numpy as jnp

from ..pytree import tree_where


def _axpy(y, h, k):
    return jax.tree_util.tree_map(lambda a, b: a + h * b, y, k)


def rk4_step(f: Callable, t, y, h):
    """One classical Runge–Kutta step of ``dy/dt = f(t, y) -> (dy, aux)``.

    Returns ``(y_next, aux)`` where ``aux`` is the auxiliary output of the first stage,
    i.e. evaluated at ``(t, y)`` (diagnostics such as Mach number cost no extra evaluation).

    The four stages run as a loop, not unrolled: unrolled, XLA fuses each output's whole chain
    of stages into its own kernel and so recomputes the right-hand side once per state
    component (12× the arithmetic, 2.2× the time and 4× the compile time of a Lynx step on
    CPU, measured). The weighted sum is accumulated in the textbook order, k1 + 2k2 + 2k3 + k4.
    """
    nodes, weights = jnp.array([0.0, 0.5, 0.5, 1.0]), jnp.array([1.0, 2.0, 2.0, 1.0])
    k0, aux0 = jax.tree_util.tree_map(jnp.zeros_like, jax.eval_shape(f, t, y))

    def stage(i, carry):
        k, total, aux = carry
        first = i == 0
        k, aux_i = f(t + nodes[i] * h, tree_where(first, y, _axpy(y, nodes[i] * h, k)))
        aux = tree_where(first, aux_i, aux)
        return k, _axpy(total, weights[i], k), aux

    _, total, aux = jax.lax.fori_loop(0, 4, stage, (k0, k0, aux0))
    return _axpy(y, h, jax.tree_util.tree_map(lambda s: s / 6.0, total)), aux
