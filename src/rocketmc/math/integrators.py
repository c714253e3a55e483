"""Fixed-step explicit integrators on pytree states."""

from __future__ import annotations

from typing import Callable

import jax


def _axpy(y, h, k):
    return jax.tree_util.tree_map(lambda a, b: a + h * b, y, k)


def rk4_step(f: Callable, t, y, h):
    """One classical Runge–Kutta step of ``dy/dt = f(t, y) -> (dy, aux)``.

    Returns ``(y_next, aux)`` where ``aux`` is the auxiliary output of the first stage,
    i.e. evaluated at ``(t, y)`` (diagnostics such as Mach number cost no extra evaluation).
    """
    k1, aux = f(t, y)
    k2, _ = f(t + 0.5 * h, _axpy(y, 0.5 * h, k1))
    k3, _ = f(t + 0.5 * h, _axpy(y, 0.5 * h, k2))
    k4, _ = f(t + h, _axpy(y, h, k3))
    slope = jax.tree_util.tree_map(lambda a, b, c, d: (a + 2.0 * b + 2.0 * c + d) / 6.0, k1, k2, k3, k4)
    return _axpy(y, h, slope), aux
