"""The closed loop in flight (perfect navigation): the thesis's Fig. 7 case, the Lynx under a constant 10 m/s
headwind, controller off, on from 1 s and on from 3.5 s (campaigns/lynx_ballistic_ctrl_*.toml, nominal, no
turbulence), and a controller that never acts.

What could break and is checked: the command's sign (the flight path must be pulled back onto the
reference, not pushed away), the window (the deflections are zero outside it, the active time is its
length), the servo limit, and that an idle controller leaves the open-loop flight bit for bit.
"""

from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign import campaign_from_dict, read_campaign_tables
from rocketmc.campaign.model import nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.gnc.guidance import reference_direction
from rocketmc.sim.flight import fly
from rocketmc.sim.outputs import flight_summary

from ..conftest import CAMPAIGNS

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

N_PERIODS = 650  # 13 s at 0.02 s: ignition at 0.5 s, the window ends 10 s after liftoff (~0.6 s)


def headwind(name: str):
    """The campaign ``name`` with a constant 10 m/s wind from the launch azimuth, nothing dispersed."""
    path = CAMPAIGNS / f"{name}.toml"
    raw = read_campaign_tables(path)
    raw["environment"] = {"wind": {"model": "constant", "speed_mps": 10.0, "from_deg": raw["launch"]["azimuth_deg"]}}
    raw["dispersions"] = {}
    return campaign_from_dict(raw, path.parent)


@pytest.fixture(scope="module")
def flights():
    """Trajectories and summaries of the three cases, one compilation per pytree structure."""
    out = {}
    for case in ("off", "1s", "3p5s"):
        campaign = headwind(f"lynx_ballistic_ctrl_{case}")
        settings = sim_settings(campaign)
        if case == "off":  # the controller's periods (no event periods), so the idle controller's flight is its twin
            settings = dataclasses.replace(settings, event_periods=False)
        fly_once = jax.jit(lambda p: (lambda s, tr: (tr, flight_summary(p, s)[0]))(*fly(p, settings, N_PERIODS)))
        out[case] = (nominal_params(campaign), *fly_once(nominal_params(campaign)))
    return out


def flight_path_deg(traj):
    v = traj.body.v_n
    return np.degrees(np.arctan2(-np.asarray(v.z), np.hypot(np.asarray(v.x), np.asarray(v.y))))


@pytest.mark.parametrize("case, start", [("1s", 1.0), ("3p5s", 3.5)])
def test_controller_pulls_the_flight_path_onto_the_reference(flights, case, start):
    """Open loop, the rocket weathercocks into the headwind: γ falls ~20° below the reference by 10 s. With the
    controller on, γ is within 1.5° of the reference from 5 s after the window opens to its end (measured with the
    linear model and the gains designed for the integrator gains flown, 1, 12, 12: 0.86° from 1 s, 1.25° from
    3.5 s; 4 s after it opens 1.00° and 2.14°. The gains designed for integrator gain 1 and flown with 12 held
    0.46° and 1.13° 4 s after), and the active time is the window's length."""
    _, off, _ = flights["off"]
    p, traj, summary = flights[case]
    t = np.asarray(traj.t)
    liftoff = float(traj.gnc.liftoff_time[-1])
    assert 0.5 < liftoff < 0.6  # ignition at 0.5 s, thrust over weight a few periods later
    d = reference_direction(p.gnc.guidance, None, t - liftoff)
    reference = np.degrees(np.arcsin(-np.asarray(d.z)))
    settled = (t - liftoff >= start + 5.0) & (t - liftoff < 10.0)
    assert np.abs(flight_path_deg(traj) - reference)[settled].max() < 1.5
    assert (reference - flight_path_deg(off))[np.searchsorted(t, liftoff + 10.0)] > 15.0
    # One control period of rounding: the window opens at the first period start at or after it.
    assert math.isclose(float(summary["control_active_time_s"]), 10.0 - start, abs_tol=0.02 + 1e-9)
    assert 0.0 < float(summary["tracking_error_rms_rad"]) < math.radians(10.0)


@pytest.mark.parametrize("case, start", [("1s", 1.0), ("3p5s", 3.5)])
def test_canards_move_only_inside_the_window_and_within_the_limit(flights, case, start):
    p, traj, summary = flights[case]
    t = np.asarray(traj.t) - float(traj.gnc.liftoff_time[-1])
    command = np.asarray(traj.gnc.servo.command_rad)  # held over the period that ends at t
    deflection = np.asarray(traj.gnc.servo.deflection_rad)
    limit = float(p.gnc.servo.limit_rad)
    outside = (t < start) | (t > 10.0 + 0.02)  # the period starting inside the window ends up to T after it
    assert np.all(command[outside] == 0.0) and np.all(deflection[t < start] == 0.0)
    assert np.abs(command).max() <= limit and np.abs(deflection).max() <= limit
    assert np.abs(deflection).max() > math.radians(2.0)  # the controller did steer
    assert float(summary["canard_deflection_max_rad"]) == np.abs(deflection[:-1]).max()


def test_a_controller_that_never_acts_flies_the_open_loop_bits(flights):
    """The window moved past the flight: the servos hold zero, so every period flies the open-loop flight's
    arithmetic on the same state (same program around the rigid body), bit for bit."""
    p_off, off, _ = flights["off"]
    p_on = flights["1s"][0]
    guidance = dataclasses.replace(p_on.gnc.guidance, window_start_s=jnp.asarray(1e3), window_end_s=jnp.asarray(2e3))
    idle = dataclasses.replace(p_off, gnc=dataclasses.replace(p_on.gnc, guidance=guidance))
    settings = sim_settings(headwind("lynx_ballistic_ctrl_off"))
    _, traj = jax.jit(lambda p: fly(p, settings, N_PERIODS))(idle)
    for a, b in zip(jax.tree_util.tree_leaves(traj.body), jax.tree_util.tree_leaves(off.body)):
        np.testing.assert_array_equal(a, b)
