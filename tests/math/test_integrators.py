"""Classical RK4 on pytree states: convergence order, exactness, auxiliary output."""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.math import rk4_step


class Oscillator(NamedTuple):
    x: jnp.ndarray
    v: jnp.ndarray


def forced_decay(t, y):
    """y' = −y + sin t; closed form y = 3/2 e^{−t} + (sin t − cos t)/2 for y(0) = 1."""
    return -y + jnp.sin(t), None


def forced_decay_exact(t):
    return 1.5 * np.exp(-t) + 0.5 * (np.sin(t) - np.cos(t))


def oscillator(t, s: Oscillator):
    """x'' = −x as a NamedTuple state; x = cos t, v = −sin t from (1, 0)."""
    return Oscillator(s.v, -s.x), {"energy": 0.5 * (s.x**2 + s.v**2), "t": t}


def _integrate(f, y0, t_end, n):
    h = t_end / n.astype(float)

    def body(i, y):
        return rk4_step(f, i.astype(float) * h, y, h)[0]

    return jax.lax.fori_loop(0, n, body, y0)  # n is traced: one compilation for every n


integrate_decay = jax.jit(lambda y0, t_end, n: _integrate(forced_decay, y0, t_end, n))
integrate_oscillator = jax.jit(lambda y0, t_end, n: _integrate(oscillator, y0, t_end, n))

STEPS = np.array([20, 40, 80, 160, 320])


def fitted_order(errors, steps):
    slope = np.polyfit(np.log(1.0 / steps), np.log(errors), 1)[0]
    return slope


def test_rk4_order_four_scalar():
    # T = 5 s: at T ≈ 2 s the leading error terms of the forcing and of the decay nearly cancel and
    # the fit is pre-asymptotic down to h = 0.05 s (slope 3.75 measured).
    t_end = 5.0
    errors = np.array([abs(float(integrate_decay(1.0, t_end, n)) - forced_decay_exact(t_end)) for n in STEPS])
    # The smallest error (~5e-12) stays far above float64 rounding (~1e-16), so the fit is clean.
    assert errors[-1] > 1e-13
    order = fitted_order(errors, STEPS)
    assert 3.8 <= order <= 4.2, (order, errors)  # classical RK4: global error O(h⁴)


def test_rk4_order_four_pytree_state():
    t_end = 3.0
    errors = []
    for n in STEPS:
        s = integrate_oscillator(Oscillator(jnp.float64(1.0), jnp.float64(0.0)), t_end, n)
        assert isinstance(s, Oscillator)  # the NamedTuple structure survives the step
        errors.append(np.hypot(float(s.x) - np.cos(t_end), float(s.v) + np.sin(t_end)))
    order = fitted_order(np.array(errors), STEPS)
    assert 3.8 <= order <= 4.2, (order, errors)
    # With 320 steps of 3/320 s the bound T h⁴/120 ≈ 2e-10: 1e-9 absolute.
    assert errors[-1] < 1e-9


def test_rk4_exact_for_cubic_quadrature():
    """For y' = f(t) RK4 is Simpson's rule, exact for cubic f: ∫₀² (4t³ − 3t² + 1) dt = 10."""

    def f(t, y):
        return 4 * t**3 - 3 * t**2 + 1.0, None

    y, _ = rk4_step(f, 0.0, jnp.float64(0.0), 2.0)
    np.testing.assert_allclose(float(y), 10.0, rtol=1e-15)  # one rounding of each stage sum
    # a quartic is not integrated exactly (the error is −h⁵ f⁗/2880 = −2⁵·24·5/2880 ≈ −1.33)
    y4, _ = rk4_step(lambda t, y: (5 * t**4, None), 0.0, jnp.float64(0.0), 2.0)
    np.testing.assert_allclose(float(y4) - 32.0, 2.0**5 * 120 / 2880, rtol=1e-12)


def test_rk4_nested_pytree_and_aux_from_first_stage():
    """Dicts of NamedTuples work; aux is the first stage's, evaluated at (t, y)."""

    def f(t, y):
        d, aux = oscillator(t, y["osc"])
        return {"osc": d, "clock": jnp.ones_like(y["clock"])}, aux

    y0 = {"osc": Oscillator(jnp.float64(0.6), jnp.float64(0.8)), "clock": jnp.float64(5.0)}
    y1, aux = rk4_step(f, 5.0, y0, 0.1)
    assert jax.tree_util.tree_structure(y1) == jax.tree_util.tree_structure(y0)
    np.testing.assert_allclose(float(y1["clock"]), 5.1, rtol=1e-15)  # dy/dt = 1 is integrated exactly
    assert float(aux["t"]) == 5.0  # aux from the first stage: at t, not t + h
    np.testing.assert_allclose(float(aux["energy"]), 0.5, rtol=1e-15)  # energy of y0, not y1
    # one step of the rotation x'' = −x: matches cos/sin to the local error h⁵/120 ≈ 1e-7
    phase = np.arctan2(-0.8, 0.6)  # x = cos(t + φ) with x0 = 0.6, v0 = −sin φ = 0.8
    np.testing.assert_allclose(float(y1["osc"].x), np.cos(0.1 + phase), atol=2e-7)


@pytest.mark.parametrize("h", [0.05, 0.2])
def test_rk4_vmap_equals_loop(h):
    y0 = jnp.linspace(-1.0, 2.0, 7)
    step = jax.jit(lambda y: rk4_step(forced_decay, 0.3, y, h)[0])
    batched = jax.vmap(step)(y0)
    single = np.array([float(step(y)) for y in y0])
    np.testing.assert_allclose(np.asarray(batched), single, rtol=1e-15, atol=0)  # same arithmetic
