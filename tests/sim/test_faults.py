"""Faults in one flight (``sim.faults``), each against its closed form or the same flight without it.

The flight: lynx_ballistic_ctrl_1s (controller on from 1 s on perfect navigation, so that the sensors' faults do
not change the flight) under a constant wind, nothing dispersed, with the thesis's sensors, the gyroscope and the
accelerometer without errors but their bias (zero) and the magnetometer truth-only, so that a step shows alone. Every fault at probability 1
with fixed times and fins; the reference is the same flight with the canard faults only: the same truth, bit for
bit, so the sensors' faults show as exact differences.
"""

from __future__ import annotations

import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign import campaign_from_dict, read_campaign_tables
from rocketmc.campaign.runner import realization_params, sim_settings
from rocketmc.dynamics.servo import ServoParams, ServoState, deflection_at
from rocketmc.sim.faults import Faults, SlowCanard, StuckCanard, faulty_servos
from rocketmc.sim.flight import fly

from ..conftest import CAMPAIGNS

N_PERIODS = 800  # 16 s at 0.02 s: through the guidance window (1.3-10.3 s), the first GNSS fixes (10 s) and the outage
STUCK = {"probability": 1.0, "time_s": [3.0, 3.0], "fin": 1}
SLOW = {"probability": 1.0, "time_s": [2.0, 2.0], "fin": 2, "factor": 4.0}
SENSOR_FAULTS = {
    "gnss_outage": {"probability": 1.0, "start_s": [11.0, 11.0], "duration_s": [2.5, 2.5]},
    "magnetometer_step": {"probability": 1.0, "time_s": [0.5, 0.5], "magnitude_ut": 20.0},
    "gyroscope_bias_jump": {"probability": 1.0, "time_s": [1.0, 1.0], "magnitude_deg_s": 2.0},
    "accelerometer_bias_jump": {"probability": 1.0, "time_s": [1.5, 1.5], "magnitude_mps2": 1.0},
}
CLEAN = {"noise_std": 0.0, "bias": [0.0, 0.0, 0.0], "bias_walk": 0.0, "lsb": 0.0}
"""An inertial sensor whose measurement is the truth plus its bias: y = x + b, exactly."""


def campaign(faults: dict):
    path = CAMPAIGNS / "lynx_ballistic_ctrl_1s.toml"
    raw = read_campaign_tables(path)
    raw["environment"] = {"wind": {"model": "constant", "speed_mps": 5.0, "from_deg": 0.0}}
    raw["dispersions"] = {}
    raw["avionics"] = {"part": "thesis", "gyroscope": CLEAN, "accelerometer": CLEAN, "magnetometer": {"truth_only": True}}
    raw["faults"] = faults
    return campaign_from_dict(raw, path.parent)


@functools.cache
def compiled(settings):
    """``fly`` for N_PERIODS, jitted once per settings and pytree structure of the parameters."""
    return jax.jit(lambda p: fly(p, settings, N_PERIODS)[1])


def flown(faults: dict):
    """(parameters, drawn inputs, trajectory) of realization 0."""
    c = campaign(faults)
    params, drawn = realization_params(c, jax.random.key(c.config.seed), 0)
    return params, drawn, compiled(sim_settings(c))(params)


@pytest.fixture(scope="module")
def faulted():
    return flown({"stuck_canard": STUCK, "slow_canard": SLOW, **SENSOR_FAULTS})


@pytest.fixture(scope="module")
def reference():
    return flown({"stuck_canard": STUCK, "slow_canard": SLOW})


def sample_times(traj) -> np.ndarray:
    """The time [s] at which the state recorded after period k was sampled: the period's start, t_k (the state
    recorded after period k − 1; 0 for the first)."""
    t = np.asarray(traj.t)
    return np.concatenate([[0.0], t[:-1]])


def bus(traj):
    """The avionics bus recorded after each period (``AvionicsState.bus`` per period)."""
    return jax.vmap(lambda avionics: avionics.bus)(traj.avionics)


def test_stuck_canard_holds_its_deflection_exactly(faulted):
    """From the first period starting at or after the fault time, fin 1's deflection never changes, bit for bit,
    while the controller still commands it and the other fins move."""
    _, drawn, traj = faulted
    assert float(drawn["faults.stuck_canard.happened"]) == 1.0 and float(drawn["faults.stuck_canard.fin"]) == 1.0
    t = sample_times(traj)
    deflection = np.asarray(traj.gnc.servo.deflection_rad)  # the end of each period
    after = t >= 3.0
    first = np.argmax(after)
    assert np.all(deflection[after, 0] == deflection[first - 1, 0])  # where it was at the fault's period start
    assert deflection[first - 1, 0] != deflection[first - 2, 0]  # it was moving until then
    assert len(np.unique(deflection[after, 2])) > 100  # fin 3 kept moving


def test_slow_canard_follows_its_lag_with_the_time_constant_times_the_factor(faulted):
    """Fin 2's deflection over each period is the first-order step response δ_cmd + (δ_k − δ_cmd)·exp(−T/τ'),
    τ' = τ before the fault and 4τ from the first period starting at or after it; the same to 4 ulp of a radian
    (XLA's exp against numpy's: a few ulp apart)."""
    p, _, traj = faulted
    t = sample_times(traj)
    deflection = np.asarray(traj.gnc.servo.deflection_rad)[:, 1]
    command = np.asarray(traj.gnc.servo.command_rad)[:, 1]
    period = np.diff(np.concatenate([[0.0], np.asarray(traj.t)]))
    tau = float(p.gnc.servo.time_constant_s) * np.where(t >= 2.0, 4.0, 1.0)
    start = np.concatenate([[0.0], deflection[:-1]])
    expected = command + (start - command) * np.exp(-period / tau)
    np.testing.assert_allclose(deflection, expected, rtol=0, atol=4 * np.finfo(float).eps)
    wrong = command + (start - command) * np.exp(-period / float(p.gnc.servo.time_constant_s))
    assert np.abs(deflection - wrong)[t >= 2.0].max() > 1e-4  # the factor shows: 4τ is not τ


def test_faulty_servos_pure():
    """``faulty_servos`` at a period start: before the fault nothing changes (the same arrays' values); after it the
    stuck fin's command is its deflection (the lag then returns it exactly) or both its stuck angle, and the slow
    fin's time constant is multiplied."""
    params = ServoParams(jnp.asarray(0.08), jnp.asarray(0.2), jnp.zeros(4))
    state = ServoState(jnp.asarray([0.01, -0.02, 0.03, 0.04]), jnp.asarray([0.1, 0.1, -0.1, 0.0]))
    fin = jnp.asarray([False, True, False, False])
    faults = Faults(stuck_canard=StuckCanard(jnp.asarray(1.0), fin), slow_canard=SlowCanard(jnp.asarray(1.0), ~fin, 3.0))
    before_params, before = faulty_servos(faults, params, state, 0.98)
    np.testing.assert_array_equal(before.command_rad, state.command_rad)
    np.testing.assert_array_equal(before_params.time_constant_s, [0.08] * 4)
    after_params, after = faulty_servos(faults, params, state, 1.0)
    np.testing.assert_array_equal(after.command_rad, [0.1, -0.02, -0.1, 0.0])
    np.testing.assert_array_equal(after_params.time_constant_s, [0.08 * 3, 0.08, 0.08 * 3, 0.08 * 3])
    assert float(deflection_at(after_params, after, 0.013)[1]) == -0.02
    angle = Faults(stuck_canard=StuckCanard(jnp.asarray(1.0), fin, jnp.asarray(math.radians(5.0))))
    _, at_angle = faulty_servos(angle, params, state, 2.0)
    assert float(at_angle.deflection_rad[1]) == float(at_angle.command_rad[1]) == math.radians(5.0)
    assert float(deflection_at(params, at_angle, 0.02)[1]) == math.radians(5.0)


def test_gnss_outage_takes_no_fix(faulted, reference):
    """No fix is taken at the ticks from 11 s to 13.5 s, and every one of the 50 Hz receiver's ticks from its first
    fix (10 s) is fresh outside the outage, as without it."""
    _, drawn, traj = faulted
    assert float(drawn["faults.gnss_outage.start_s"]) == 11.0 and float(drawn["faults.gnss_outage.end_s"]) == 13.5
    t = sample_times(traj)
    fresh = np.asarray(bus(traj).gnss.fresh)
    dark = (t >= 11.0) & (t < 13.5)
    assert dark.sum() == 125 and not fresh[dark].any()
    np.testing.assert_array_equal(fresh[~dark], np.asarray(bus(reference[2]).gnss.fresh)[~dark])
    assert fresh[(t >= 10.0) & ~dark].all()


@pytest.mark.parametrize("sensor, fault, time_s, unit", [
    ("magnetometer", "magnetometer_step", 0.5, 1e-6), ("gyroscope", "gyroscope_bias_jump", 1.0, math.pi / 180.0),
    ("accelerometer", "accelerometer_bias_jump", 1.5, 1.0)])  # fmt: skip
def test_sensor_steps_exactly(faulted, reference, sensor, fault, time_s, unit):
    """The measurement jumps by exactly the drawn step at the fault time and keeps it: y = y_reference + step, bit
    for bit (a truth-only magnetometer without hard iron, inertial sensors without errors but a zero bias: the
    step is added to a zero), with the step's drawn magnitude; nothing changes before it."""
    p, drawn, traj = faulted
    vector = {"magnetometer": "step_ut", "gyroscope": "jump_deg_s", "accelerometer": "jump_mps2"}[sensor]
    drawn_step = np.asarray([float(drawn[f"faults.{fault}.{vector}.{i}"]) for i in range(3)])
    magnitude = {"magnetometer": 20.0, "gyroscope": 2.0, "accelerometer": 1.0}[sensor]
    assert abs(np.linalg.norm(drawn_step) - magnitude) < 1e-12 * magnitude  # the norm's rounding
    step = np.asarray(getattr(p.faults, fault).value)  # in the sensor frame, SI (the mounting: the identity here)
    np.testing.assert_allclose(step, drawn_step * unit, rtol=1e-15)
    t = sample_times(traj)
    measured = np.asarray(getattr(bus(traj), sensor).value)
    without = np.asarray(getattr(bus(reference[2]), sensor).value)
    after = t >= time_s
    np.testing.assert_array_equal(measured[~after], without[~after])
    np.testing.assert_array_equal(measured[after], without[after] + step)
