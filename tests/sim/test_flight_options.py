"""The flight's opt-in options against closed forms: two rail buttons (the rail exit of a constant-thrust rocket
without drag), gravity falling with altitude (a vertical coast's apogee by energy conservation), a main that cuts
the drogue away (the descent rate under the main alone) and a thrust curve reshaped to a burn time (its impulse
kept)."""

from __future__ import annotations

import dataclasses
import math
import tomllib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.campaign import ConfigError, campaign_from_dict
from rocketmc.campaign.model import flight_params, nominal_params
from rocketmc.campaign.runner import sim_settings
from rocketmc.campaign.sampling import realization_key, sample_dispersions
from rocketmc.dynamics.propulsion import cumulative_impulse
from rocketmc.env import G0, isa
from rocketmc.env.atmosphere import R_EARTH_GEOPOTENTIAL
from rocketmc.sim.events import rail_travel_m
from rocketmc.sim.flight import fly
from rocketmc.sim.loads import mass_properties
from rocketmc.sim.outputs import flight_summary
from rocketmc.sim.params import Launch

from ..conftest import CAMPAIGNS
from .test_flight import calm, vacuum

NOMINAL = tomllib.loads((CAMPAIGNS / "lynx_nominal.toml").read_text())


def with_rocket(**rocket) -> dict:
    """The tables of lynx_nominal with keys of [rocket] added."""
    return {**NOMINAL, "rocket": {**NOMINAL["rocket"], **rocket}}


def constant_thrust(p, thrust_n: float, burn_s: float):
    """``p`` in vacuum without wind, its motor a constant ``thrust_n`` [N] for ``burn_s`` [s] from t = 0 with a
    propellant mass (1 µg) too small to change the rocket's: the motion of a constant mass under a constant force."""
    motor = dataclasses.replace(
        p.rocket.motor, time_s=jnp.array([0.0, burn_s]), thrust_n=jnp.array([thrust_n, thrust_n]),
        impulse_ns=jnp.array([0.0, thrust_n * burn_s]), ignition_time_s=jnp.asarray(0.0),
        propellant_mass_kg=jnp.asarray(1e-9),
    )  # fmt: skip
    p = calm(vacuum(p))
    return dataclasses.replace(p, rocket=dataclasses.replace(p.rocket, motor=motor))


@pytest.fixture(scope="module")
def settings(lynx_campaign):
    return sim_settings(lynx_campaign)


def summary_of(settings, p, n_periods: int):
    final, trajectory = jax.jit(lambda q: fly(q, settings, n_periods))(p)
    summary, _ = flight_summary(p, final)
    return {k: float(v) for k, v in summary.items()}, jax.tree_util.tree_map(np.asarray, trajectory)


# ------------------------------------------------------------------------------------------------- rail buttons


def test_upper_lug_is_the_exit_lug_and_must_be_forward_of_the_rear_one():
    """rocket.upper_lug_m (Lynx: positions from the nose tip) is the lug whose passing the rail's top frees the
    rocket; without it the rear lug is; one aft of the rear lug is refused in one line."""
    one = nominal_params(campaign_from_dict(NOMINAL))
    two = nominal_params(campaign_from_dict(with_rocket(upper_lug_m=1.2)))
    reference = 1.33  # lynx.toml's reference point: body x = 1.33 − position
    assert float(one.rocket.exit_lug_x_m) == pytest.approx(reference - 1.738, abs=1e-15)
    assert float(two.rocket.exit_lug_x_m) == pytest.approx(reference - 1.2, abs=1e-15)
    assert float(rail_travel_m(one) - rail_travel_m(two)) == pytest.approx(1.738 - 1.2, abs=1e-12)
    with pytest.raises(ConfigError, match=r"upper_lug_m \(1.9 m\) must be forward of rear_lug_m"):
        campaign_from_dict(with_rocket(upper_lug_m=1.9))


def test_rail_exit_of_two_buttons_against_the_constant_thrust_closed_form(settings, lynx_params):
    """On the rail of elevation θ a constant force F on a constant mass m slides the rocket with
    a = F/m − g·sin θ; it is free after s = L_rail − (x_lug − x_nozzle), the distance between the exit lug and the
    rail's top at rest: t = sqrt(2 s/a), v = a·t. The upper of two buttons leaves first: earlier and slower."""
    base = constant_thrust(lynx_params, 1500.0, 5.0)
    rear = float(base.rocket.exit_lug_x_m)
    upper = dataclasses.replace(base, rocket=dataclasses.replace(base.rocket, exit_lug_x_m=jnp.asarray(rear + 0.6)))
    sin_el = -float(base.launch.rail_direction_n.z)
    results = {}
    for name, p in (("rear", base), ("upper", upper)):
        s, _ = summary_of(settings, p, 100)
        m = float(mass_properties(p, 0.0).mass)
        a = 1500.0 / m - G0 * sin_el
        travel = float(p.launch.rail_length_m) - (float(p.rocket.exit_lug_x_m) - float(p.rocket.motor.nozzle_x_m))
        t_exit = math.sqrt(2.0 * travel / a)
        # the exit is found by linear interpolation of the travel inside a 20 ms step of constant acceleration:
        # |Δt| ≤ a·h²/(8 v) (2e-4 s here); the speed, linear in time, is off by a·Δt. RK4 is exact for this motion.
        bound = a * settings.control_dt_s**2 / (8.0 * a * t_exit)
        assert s["rail_exit_time_s"] == pytest.approx(t_exit, abs=bound)
        assert s["rail_exit_speed_mps"] == pytest.approx(a * t_exit, abs=a * bound + 1e-9)
        results[name] = s
    assert results["upper"]["rail_exit_speed_mps"] < results["rear"]["rail_exit_speed_mps"]


# ----------------------------------------------------------------------------------------------------- gravity


def test_gravity_option_and_its_default():
    """environment.gravity: "constant" (the default, absent from the dump) or "inverse_square"."""
    config = campaign_from_dict(NOMINAL).config
    assert config.environment.gravity == "constant" and "gravity" not in config.model_dump()["environment"]
    raw = {**NOMINAL, "environment": {**NOMINAL["environment"], "gravity": "inverse_square"}}
    assert nominal_params(campaign_from_dict(raw)).environment.gravity == "inverse_square"


def test_vertical_coast_apogee_in_an_inverse_square_field(settings, lynx_params):
    """A vertical coast without drag conserves v²/2 − μ/r with μ = g0·r0², r = r0 + z the distance from the
    centre (z above sea level): from (z, v) the apogee is at μ/(μ/r − v²/2) − r0. Constant gravity reaches
    z + v²/(2 g0) instead, tens of metres lower here (a 13 km coast)."""
    base = constant_thrust(lynx_params, 2500.0, 4.0)
    vertical = Launch.from_angles(base.launch.rail_length_m, math.pi / 2, 0.0)
    varying = dataclasses.replace(base, launch=vertical,
                                  environment=dataclasses.replace(base.environment, gravity="inverse_square"))  # fmt: skip
    s, trajectory = summary_of(settings, varying, 3000)
    site = float(varying.environment.site_altitude_m)
    mu = G0 * R_EARTH_GEOPOTENTIAL**2
    coast = (trajectory.t > s["burnout_time_s"] + 0.1) & (trajectory.t < s["apogee_time_s"])
    assert coast.sum() > 1000
    z = site - trajectory.body.r_n.z[coast]
    v = trajectory.body.v_n.z[coast]
    energy = 0.5 * v**2 - mu / (R_EARTH_GEOPOTENTIAL + z)
    assert np.ptp(energy) < 1e-9 * np.abs(energy).max()  # RK4 conserves it to rounding
    r = R_EARTH_GEOPOTENTIAL + z[0]
    apogee_msl = mu / (mu / r - 0.5 * v[0] ** 2) - R_EARTH_GEOPOTENTIAL
    assert s["apogee_agl_m"] == pytest.approx(apogee_msl - site, abs=1e-6)
    constant_apogee_msl = z[0] + v[0] ** 2 / (2.0 * G0)
    assert apogee_msl - constant_apogee_msl > 20.0


# ------------------------------------------------------------------------------------------- chute release


def test_releases_names_another_parachute():
    chutes = campaign_from_dict(NOMINAL).config.rocket.parachutes
    assert [c.name for c in chutes] == ["drogue", "main"]
    main = dict(chutes[1].model_dump(), releases="drogue")
    p = nominal_params(campaign_from_dict(with_rocket(parachutes=[chutes[0].model_dump(), main])))
    assert [c.released_by for c in p.rocket.parachutes] == [1, None]
    for wrong in ("main", "reserve"):
        bad = dict(chutes[1].model_dump(), releases=wrong)
        with pytest.raises(ConfigError, match=rf"parachutes.1.releases: '{wrong}' is not another parachute"):
            campaign_from_dict(with_rocket(parachutes=[chutes[0].model_dump(), bad]))


def test_descent_under_the_main_alone_once_it_cuts_the_drogue_away(settings, lynx_params):
    """Released at the main's opening, the drogue's drag stops: the terminal speed is sqrt(2 m g/(ρ Cd·S_main)),
    not that of both canopies, sqrt(2 m g/(ρ (Cd·S_main + Cd·S_drogue))) (test_flight's steady descent)."""
    p = calm(lynx_params)
    drogue, main = p.rocket.parachutes
    p = dataclasses.replace(p, rocket=dataclasses.replace(p.rocket, parachutes=(
        dataclasses.replace(drogue, released_by=1), main)))  # fmt: skip
    s, trajectory = summary_of(settings, p, 3000)
    t, altitude, vz = trajectory.t, -trajectory.body.r_n.z, trajectory.body.v_n.z
    window = (t > s["main_deploy_time_s"] + float(main.opening_time_s) + 5.0) & (t < s["impact_time_s"])
    assert np.ptp(t[window]) > 20.0
    m = float(p.rocket.dry_mass_kg)
    rho = np.asarray(isa(float(p.environment.site_altitude_m) + altitude[window]).density)
    alone, both = (np.sqrt(2 * m * G0 / (rho * float(cd_s))) for cd_s in (main.cd_s_m2, main.cd_s_m2 + drogue.cd_s_m2))
    # force balance with the actual deceleration, as test_flight's steady descent (measured residual ~1e-9)
    accel = np.gradient(vz, t)[window]
    np.testing.assert_allclose(vz[window], alone * np.sqrt(1 - accel / G0), rtol=1e-4)
    assert np.all(vz[window] > both * 1.01)


# ------------------------------------------------------------------------------------------ burn time reshape


def test_burn_time_reshapes_the_curve_keeping_its_impulse():
    """rocket.motor.burn_time_s scales the curve's times by T/T_curve and its thrusts by T_curve/T: the burn
    time is T and the total impulse (× thrust_scale) is the curve's; a dispersed burn time does so per flight."""
    campaign = campaign_from_dict(NOMINAL)
    curve_t, curve_f = campaign.thrust_time_s, campaign.thrust_n
    impulse = float(cumulative_impulse(curve_t, curve_f)[-1])
    motor = {**NOMINAL["rocket"].get("motor", {}), "burn_time_s": 4.0}
    raw = {**with_rocket(motor=motor), "dispersions": {**NOMINAL["dispersions"],
                                                       "rocket.motor.burn_time_s": {"dist": "uniform", "low": 2.0, "high": 5.0}}}  # fmt: skip
    reshaped = campaign_from_dict(raw)
    m = nominal_params(reshaped).rocket.motor  # thrust_scale 1
    assert float(m.burn_time_s) == pytest.approx(4.0, rel=1e-15)
    assert float(np.trapezoid(m.thrust_n, m.time_s)) == pytest.approx(impulse, rel=1e-13)
    np.testing.assert_allclose(np.asarray(m.thrust_n), curve_f * curve_t[-1] / 4.0, rtol=1e-15)
    key = realization_key(jax.random.key(reshaped.config.seed), 3)
    drawn = sample_dispersions(reshaped, key)
    flown = jax.jit(lambda k, d: flight_params(reshaped, {**reshaped.nominal, **d}, k).rocket.motor)(key, drawn)
    assert float(flown.burn_time_s) == pytest.approx(float(drawn["rocket.motor.burn_time_s"]), rel=1e-15)
    delivered = drawn["rocket.motor.thrust_scale"] * impulse
    assert float(np.trapezoid(flown.thrust_n, flown.time_s)) == pytest.approx(float(delivered), rel=1e-13)
    assert float(flown.total_impulse_ns) == pytest.approx(float(delivered), rel=1e-13)  # the mass flow's
