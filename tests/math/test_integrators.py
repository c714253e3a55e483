"""RK4 convergence order and table interpolation."""

import jax
import jax.numpy as jnp
import numpy as np

from rocketmc.math import interp1d, rk4_step


def oscillator_error(n_steps: int) -> float:
    # x'' = -x as a pytree (dict) state; exact x(T) = cos T.
    f = lambda t, y: ({"x": y["v"], "v": -y["x"]}, None)  # noqa: E731
    T, h = 3.0, 3.0 / n_steps

    def body(y, _):
        return rk4_step(f, 0.0, y, h)[0], None

    y, _ = jax.lax.scan(body, {"x": jnp.asarray(1.0), "v": jnp.asarray(0.0)}, None, n_steps)
    return abs(float(y["x"]) - np.cos(T))


def test_rk4_is_fourth_order():
    steps = np.array([40, 80, 160, 320])
    errors = np.array([oscillator_error(n) for n in steps])
    slope = np.polyfit(np.log(3.0 / steps), np.log(errors), 1)[0]
    assert 3.8 < slope < 4.2, slope  # asymptotic order 4; ±0.2 for the pre-asymptotic range


def test_aux_is_first_stage():
    f = lambda t, y: (-y, t + y)  # noqa: E731
    _, aux = rk4_step(f, 1.5, 2.0, 0.1)
    assert aux == 3.5


def test_interp1d_matches_numpy():
    xp = np.array([0.0, 0.2, 0.5, 0.7, 0.85, 1.0])
    fp = np.array([0.42, 0.42, 0.378, 0.362, 0.383, 0.605])
    x = np.concatenate([np.linspace(-0.5, 1.5, 201), xp])
    got = jax.jit(jax.vmap(lambda v: interp1d(v, xp, fp)))(x)
    np.testing.assert_allclose(got, np.interp(x, xp, fp), rtol=0, atol=1e-15)  # clamped outside, like numpy
