"""Derivatives through the flight (``campaign.derivatives``): forward mode against central finite differences,
reverse mode against forward mode, the bounded driver against ``simulate_one``'s bits, and the functions whose
derivatives are chosen where the textbook one is infinite (``math.safe``, ``sensors.errors.quantize``)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign import load_campaign, with_overrides
from rocketmc import ellipse
from rocketmc.campaign.derivatives import (DIFFERENTIATED_OUTPUTS, check_inputs, ellipse_area_m2, jacobians,
                                          realization_function)
from rocketmc.campaign.errors import ConfigError
from rocketmc.campaign.runner import realization_params, sim_settings
from rocketmc.math import safe_arctan2, safe_sqrt
from rocketmc.sensors.errors import quantize
from rocketmc.sim.flight import max_blocks, simulate_bounded, simulate_one

from ..conftest import CAMPAIGNS

WRT = ("rocket.motor.thrust_scale", "rocket.dry_mass_kg", "environment.wind.layers.1.speed_mps",
       "environment.wind.layers.0.thickness_m", "launch.elevation_deg")  # fmt: skip
"""Continuous inputs of every kind: the motor, the mass, a wind layer's speed and a boundary's height, the rail."""
CLOSED_LOOP_WRT = WRT + ("gnc.guidance.gain", "gnc.guidance.flight_path_angle_deg", "gnc.guidance.wind_gain")
"""With the guidance's numbers ``rocketmc tune`` adjusts: its gain, its reference and its upwind aim."""

FD_STEP = 1e-6
"""Central differences' step, relative to max(1, |x|). The flights are smooth only piecewise: a step of 1e-3 moves
events across period ends and the ballistic descent's tumbling amplifies it (thrust scale on lynx_ballistic's
realization 0: impact north −261 m at a step of 1e-2, +131 at 1e-3, −578 at 1e-4, −477 at 1e-5, −483 at 1e-6,
the derivative −482.3); at 1e-6 the differences have converged and round-off is ~1e-8 relative."""


def _forward_and_differences(campaign, index: int, wrt=WRT, step: float = FD_STEP):
    """(derivatives (outputs, len(wrt)), central differences (same)) of realization ``index``: the jvp at the
    realization's values and the flights at x ± h for each input, one compiled program."""
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    x0, f = realization_function(campaign, settings, master, jnp.uint32(index), wrt)
    h = step * np.maximum(1.0, np.abs(np.asarray(x0)))
    basis = np.eye(len(wrt))
    x0 = np.asarray(x0)[None, :]
    points = np.concatenate([np.tile(x0, (len(wrt), 1)), x0 + basis * h, x0 - basis * h])
    tangents = np.concatenate([basis, np.zeros_like(basis), np.zeros_like(basis)])
    y, dy = jax.jit(jax.vmap(lambda x, dx: jax.jvp(lambda z: f(z)[0], (x,), (dx,))))(points, tangents)
    n = len(wrt)
    return np.asarray(dy[:n]).T, np.asarray((y[n : 2 * n] - y[2 * n :]) / (2 * h[:, None])).T


@pytest.fixture(scope="module")
def ballistic():
    return load_campaign(CAMPAIGNS / "lynx_ballistic.toml")


@pytest.fixture(scope="module")
def closed_loop():
    """LQI and canards, drogue + main, turbulence; guidance aimed upwind (``gnc.guidance.wind_gain``)."""
    return with_overrides(load_campaign(CAMPAIGNS / "lynx_nominal_ctrl_1s.toml"), values={"gnc.guidance.wind_gain": 1.0})


def _errors(derivatives, differences):
    """Each output's largest difference between derivative and central difference, relative to the output's largest
    derivative (the scale a variance share or a gradient step sees)."""
    return np.abs(derivatives - differences).max(axis=1) / np.abs(differences).max(axis=1)


@pytest.mark.parametrize("index", [0, 1])
def test_forward_derivatives_match_central_differences_with_turbulence(ballistic, index):
    derivatives, differences = _forward_and_differences(ballistic, index)
    assert np.all(np.isfinite(derivatives))
    errors = dict(zip(DIFFERENTIATED_OUTPUTS, _errors(derivatives, differences)))
    # apogee: smooth in every input (measured 6e-8 and 1.3e-7: the differences' own round-off and truncation)
    assert errors["apogee_agl_m"] < 1e-6
    # the landing point after a ballistic (tumbling) descent, which amplifies every change: differences at 1e-5 and
    # 1e-6 still differ by ~1 % (FD_STEP); measured 1.2e-3 and 4.6e-3 from the derivatives
    assert max(errors.values()) < 1e-2


def test_closed_loop_forward_derivatives_match_central_differences(closed_loop):
    errors = _errors(*_forward_and_differences(closed_loop, 0, CLOSED_LOOP_WRT, step=1e-7))
    # under canopies the descent is damped, not tumbling: measured 1.8e-7 at a step of 1e-7 (the landing speed by
    # thrust scale: the upwind aim curves the flight in its thrust, the differences' truncation was 2.5e-5 at 1e-6,
    # 2.5e-3 at 1e-5; 3.2e-9 at 1e-6 without the aim)
    assert max(errors) < 1e-6


def test_reverse_mode_through_the_bounded_flights_equals_forward_mode(closed_loop):
    # the closed loop under parachutes: the canopies' triggers at an infinite altitude and the point mass's periods
    # to an infinite gap, whose derivatives reverse mode multiplies by 0 (NaN until kept out of the divisions), and
    # the guidance's reference before liftoff (an infinite climb)
    campaign = closed_loop
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    indices = jnp.arange(2, dtype=jnp.uint32)

    def forward(index):
        x0, f = realization_function(campaign, settings, master, index, CLOSED_LOOP_WRT)
        return jax.jacfwd(lambda x: f(x)[0])(x0)

    expected = jax.jit(jax.vmap(forward))(indices)
    summary, status, reverse = jax.jit(lambda i: jacobians(campaign, settings, master, i, CLOSED_LOOP_WRT))(indices)
    assert np.all(np.asarray(status) == 0)
    # the same derivatives summed in another order: round-off only
    np.testing.assert_allclose(reverse, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


def test_bounded_flights_fly_simulate_ones_flights(ballistic):
    settings, master = sim_settings(ballistic), jax.random.key(ballistic.config.seed)
    params = lambda i: realization_params(ballistic, master, i)[0]  # noqa: E731
    indices = jnp.arange(8, dtype=jnp.uint32)
    one = jax.jit(jax.vmap(lambda i: simulate_one(params(i), settings)))(indices)
    bounded = jax.jit(lambda i: simulate_bounded(params, i, settings, max_blocks(settings)))(indices)
    for name, value in one[0].items():
        # round-off: the two programs compile the events' interpolation differently since the crossing's custom
        # derivative (measured: 3 apogees of 8 one ulp apart, another output 18 ulp of a value smaller than its
        # largest); 1e-13 of each output's largest value is 1e-10 m on a 1 km apogee
        got, want = np.asarray(bounded[0][name]), np.asarray(value)
        np.testing.assert_array_equal(np.isnan(got), np.isnan(want), err_msg=name)
        scale = np.nanmax(np.abs(want)) if np.isfinite(want).any() else 0.0
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * scale, equal_nan=True, err_msg=name)
    np.testing.assert_array_equal(np.asarray(bounded[1]), np.asarray(one[1]))
    cut = jax.jit(lambda i: simulate_bounded(params, i, settings, 2))(indices)
    assert np.all(np.asarray(cut[1]) != 0)  # too few blocks: cut short, not landed


def test_inputs_checked(ballistic):
    check_inputs(ballistic, WRT)
    with pytest.raises(ConfigError, match="rocket.geometry.fins.span_m: fixed for the whole campaign"):
        check_inputs(ballistic, ["rocket.geometry.fins.span_m"])
    with pytest.raises(ConfigError, match="rocket.no_such: not a number"):
        check_inputs(ballistic, ["rocket.no_such"])


def test_safe_functions_keep_values_and_give_finite_derivatives():
    x = jnp.array([0.0, 1e-300, 0.25, 4.0])
    np.testing.assert_array_equal(safe_sqrt(x), jnp.sqrt(x))
    np.testing.assert_array_equal(jax.vmap(jax.grad(safe_sqrt))(x)[1:], jax.vmap(jax.grad(jnp.sqrt))(x)[1:])
    assert jax.grad(safe_sqrt)(0.0) == 0.0  # the textbook derivative is inf
    y, z = jnp.array([0.0, 1.0, -2.0]), jnp.array([0.0, 1.0, 0.5])
    np.testing.assert_array_equal(safe_arctan2(y, z), jnp.arctan2(y, z))
    for argnum in (0, 1):
        got = jax.vmap(jax.grad(safe_arctan2, argnum))(y, z)
        assert got[0] == 0.0  # 0/0 in the textbook derivative
        np.testing.assert_allclose(got[1:], jax.vmap(jax.grad(jnp.arctan2, argnum))(y[1:], z[1:]), rtol=1e-15)


def test_quantizer_is_straight_through():
    x, lsb = jnp.array([-0.26, 0.0, 0.24, 0.26]), 0.5
    np.testing.assert_array_equal(quantize(x, lsb), jnp.array([-0.5, 0.0, 0.0, 0.5]))
    np.testing.assert_array_equal(jax.vmap(jax.grad(quantize), (0, None))(x, lsb), jnp.ones(4))


def test_ellipse_area_weights_failed_flights_out_and_matches_the_reports():
    rng = np.random.default_rng(4)
    points = rng.normal(size=(50, 4)) * np.array([300.0, 120.0, 1.0, 1.0])
    status = np.zeros(50, dtype=np.int32)
    status[[3, 7]] = 3
    points[7, :2] = np.nan  # a failed flight without an impact point
    ok = status == 0
    expected = ellipse.ellipse_area_m2(points[ok, 0], points[ok, 1])
    got = ellipse_area_m2(jnp.asarray(points), jnp.asarray(status), ellipse.chi2_scale(0.95))
    assert got == pytest.approx(expected, rel=1e-12)
    gradient = jax.grad(lambda x: ellipse_area_m2(x, jnp.asarray(status), 1.0))(jnp.asarray(points))
    assert np.all(np.isfinite(gradient)) and np.all(gradient[~ok] == 0.0)
