"""The LQI gain schedule a campaign designs at set-up (campaign/gains.py, docs/gnc.md §5): the plant of each
grid point against a hand-built one and against the nonlinear flight's own derivatives, the stability
of the default Lynx schedule for each aerodynamic model, the flight estimate behind the grid check,
and the set-up's fingerprint."""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.aero.canards import allocate
from rocketmc.campaign import ConfigError, campaign_from_dict, load_campaign, with_overrides
from rocketmc.campaign.limits import DEFAULT_ALTITUDES_M, DEFAULT_SPEEDS_MPS
from rocketmc.campaign.loader import preset_rocket
from rocketmc.campaign.fingerprint import data_digest
from rocketmc.campaign.gains import design_grid, plant_point, trim_angles_deg
from rocketmc.campaign.model import airframe_params, nominal_params
from rocketmc.gnc.design import (
    THESIS_Q, THESIS_R, PlantPoint, augment, density, discretise, flown_loop, lqi_gain, lqi_plant,
)  # fmt: skip
from rocketmc.gnc.guidance import Navigation, rate_command, reference_direction
from rocketmc.math import Quat, Vec3
from rocketmc.sim.flight import initial_state
from rocketmc.sim.loads import derivatives

from ..conftest import CAMPAIGNS

NOMINAL = tomllib.loads((CAMPAIGNS / "lynx_nominal.toml").read_text())
SITE_M = NOMINAL["site"]["altitude_m"]  # Roccaraso, 1416 m


def lynx(model: str = "linear", gnc: dict | None = None, **rocket) -> dict:
    """lynx_nominal with ``model`` aerodynamics, a [gnc] section (the defaults unless given), the
    rocket's fields ``rocket`` overridden."""
    raw = copy.deepcopy(NOMINAL)
    raw["rocket"].update(aero={"model": model}, **rocket)
    return {**raw, "gnc": {} if gnc is None else gnc}


@pytest.fixture(scope="module")
def linear():
    return campaign_from_dict(lynx("linear"), CAMPAIGNS)


@pytest.fixture(scope="module")
def simplified(linear):
    """Designed anew by ``with_overrides`` (the CLI's --aero-model): simplify of the build-up tables, ~7 s."""
    return with_overrides(linear, aero_model="simplified")


def test_linear_schedule_is_the_thesis_plant_at_burnout(linear):
    """A grid point of the linear Lynx against docs/gnc.md §5's plant written by hand: docs/lynx.md's coefficients
    (force damping 154 per ω·d/V), the Lynx at burnout (18.362 kg, Ixx 0.06, Iyy 6.436 kg·m², its CG on the
    moment reference, so no shift), S 0.01767 m², d 0.15 m, ρ of the ISA at the grid altitude above
    Roccaraso, ω_a = 1/0.0769 s, dt 0.02 s, ZOH, the weights flown, the integrators augmented with the gains
    they are flown with (1, 12, 12: gnc.guidance.integrator_gain's default)."""
    schedule = linear.gnc_schedule
    i, j = DEFAULT_SPEEDS_MPS.index(150.0), DEFAULT_ALTITUDES_M.index(1000.0)
    assert schedule.speeds[i] == 150.0 and schedule.altitudes[j] == SITE_M + 1000.0  # altitudes above sea level
    point = PlantPoint(
        cy_beta=-24.0744, cy_r=154.0, cy_delta=3.4045, cn_alpha=24.0744, cn_q=154.0, cn_delta=3.4045,
        cl_p=-19.0, cl_delta=2.3963, cm_alpha=-37.2959, cm_q=-1813.0, cm_delta=21.8445,
        cn_yaw_beta=37.2959, cn_r=-1813.0, cn_yaw_delta=21.8445,
        mass=18.362, ixx=0.06, iyy=6.436, area=0.01767, diameter=0.15,
        speed=150.0, density=density(SITE_M + 1000.0), omega_a=1.0 / 0.0769,
    )  # fmt: skip
    expected = lqi_gain(*discretise(*augment(*lqi_plant(point), (1.0, 12.0, 12.0)), 0.02, "zoh"), THESIS_Q, THESIS_R)
    # The same arithmetic but for the coefficients' trip through the mixing matrix and the table
    # (rounding ~1e-16 relative) and the propellant left at burnout (0 to rounding): K (|K| ≲ 2)
    # agrees to ~1e-14; 1e-12 leaves room and still catches any real difference.
    np.testing.assert_allclose(schedule.gains[i, j], expected.gain, rtol=0, atol=1e-12)
    assert schedule.spectral_radius[i, j] == pytest.approx(expected.spectral_radius, abs=1e-12)


@pytest.mark.parametrize("model", ["linear", "simplified"])
def test_default_lynx_schedule_is_stable_and_solved(model, request):
    schedule = request.getfixturevalue(model).gnc_schedule
    assert schedule.gains.shape == (len(DEFAULT_SPEEDS_MPS), len(DEFAULT_ALTITUDES_M), 3, 11)
    np.testing.assert_array_equal(schedule.altitudes, SITE_M + np.asarray(DEFAULT_ALTITUDES_M))
    assert np.all(schedule.spectral_radius < 1.0), schedule.spectral_radius.max()
    assert np.all(schedule.flown_radius < 1.0), schedule.flown_radius.max()
    # scipy's Schur solution satisfies the DARE to rounding (measured < 5e-14 relative).
    assert np.all(schedule.residual < 1e-9), schedule.residual.max()


def test_flown_loop_of_the_default_lynx_schedule(linear):
    """The loop as flown (the plant, the schedule's K, the integrators stepped with k_int = 1, 12, 12, in the
    flight's order) at every point of the default grid: stable, and its spectral radius the designed loop's to
    1e-3 (the two integrator discretisations differ by half a step of the rate's integral: measured ≤ 4.9e-4 on
    this grid, at 300 m/s, growing with speed). The gains designed with k_int = 1 and flown with 12 were stable here too (≤ 0.9971) but their
    designed radius (≤ 0.9988) was not what flew: 1.7e-3 apart at 20 m/s, 3.2e-2 at 300 m/s."""
    inputs, schedule = linear.gnc_inputs, linear.gnc_schedule
    flown = np.zeros(schedule.spectral_radius.shape)
    for i, speed in enumerate(schedule.speeds):
        for j, altitude in enumerate(schedule.altitudes):
            a, b = lqi_plant(plant_point(inputs.aero, inputs.mass, speed, altitude, inputs.omega_a))
            flown[i, j] = np.abs(np.linalg.eigvals(flown_loop(a, b, schedule.gains[i, j], (1.0, 12.0, 12.0), 0.02))).max()
    np.testing.assert_array_equal(flown, schedule.flown_radius)  # the same arithmetic
    assert flown.max() < 1.0
    np.testing.assert_allclose(flown, schedule.spectral_radius, rtol=0, atol=1e-3)


def test_unstable_flown_loop_is_refused():
    """Integrator gains of 500 on every axis: each point's design (ZOH of ė = −500 C x) is stable, but from 200 m/s
    on (first in the grid's order) the flight's forward-Euler step of the integrators (k_int·T = 10) is not
    (flown spectral radius 1.0021 there)."""
    with pytest.raises(ConfigError, match=r"^gnc.guidance.integrator_gain: LQI design at speed 200 m/s.* the loop as flown "
                                          r".* is not stable, spectral radius 1.002.*gnc.control\)$"):  # fmt: skip
        campaign_from_dict(lynx("linear", gnc={"guidance": {"integrator_gain": [500.0, 500.0, 500.0]}}), CAMPAIGNS)


def test_interpolated_designs_on_its_own_linearisation(simplified):
    """The interpolated model is designed from ``simplify`` of its tables: the simplified model's gains."""
    interpolated = campaign_from_dict(lynx("interpolated"), CAMPAIGNS).gnc_schedule
    assert np.all(interpolated.spectral_radius < 1.0) and np.all(interpolated.residual < 1e-9)
    # The same derivatives (one simplify, the same bits) through the same design: equal to rounding.
    np.testing.assert_allclose(interpolated.gains, simplified.gnc_schedule.gains, rtol=0, atol=1e-12)


def test_overrides_keep_or_redesign_the_gains(linear, simplified):
    """Overrides are loaded again, the gains designed again: the same bits where the design's inputs are the same,
    others where the rocket changes."""
    kept = with_overrides(linear, n_realizations=5, seed=1).gnc_schedule
    np.testing.assert_array_equal(kept.gains, linear.gnc_schedule.gains)
    heavier = with_overrides(linear, values={"rocket.dry_mass_kg": linear.config.rocket.dry_mass_kg + 1.0})
    assert not np.array_equal(heavier.gnc_schedule.gains, linear.gnc_schedule.gains)
    # The build-up's derivatives are not the thesis's (Cmα, Cm_δ differ by tens of %): other gains.
    assert np.abs(simplified.gnc_schedule.gains - linear.gnc_schedule.gains).max() > 0.01


def test_without_gnc_nothing_is_designed():
    campaign = campaign_from_dict(NOMINAL, CAMPAIGNS)
    assert campaign.config.gnc is None and campaign.gnc_schedule is None


def test_controller_and_sensors_added_at_once():
    """``with_overrides(controller=True, sensors=True)`` on a campaign with neither: the default [gnc] (its
    navigation the schema's "truth" until the sensors come) flies on raw sensors, designed."""
    campaign = with_overrides(campaign_from_dict(NOMINAL, CAMPAIGNS), controller=True, sensors=True)
    assert campaign.config.gnc.navigation == "sensors" and campaign.config.avionics is not None
    assert campaign.gnc_schedule is not None


def shifted_rate_jacobian(raw: dict, speed: float, height: float):
    """(A rows v, w, p, q, r of the plant the campaign designs from, the same rows by central differences
    of the flight's own right-hand side ``sim.loads.derivatives``) at axial speed [m/s] and height above
    the pad [m], coasting (after burnout) in calm air; columns v, w, p, q, r, u_y, u_p, u_r."""
    campaign = campaign_from_dict({**raw, "environment": {}, "dispersions": {}}, CAMPAIGNS)  # no wind
    inputs = campaign.gnc_inputs
    point = plant_point(inputs.aero, inputs.mass, speed, SITE_M + height, inputs.omega_a)
    a_plant = lqi_plant(point)[0][:5]

    params = airframe_params(campaign.config, campaign.thrust_time_s, campaign.thrust_n, campaign.aero,
                             campaign.wind_profile, campaign.weather, campaign.nominal)  # fmt: skip
    motor = params.rocket.motor
    t = motor.ignition_time_s + motor.burn_time_s + 1.0
    events = dataclasses.replace(initial_state(params).events, rail_exit_time=jnp.zeros(()))  # off the rail

    @jax.jit
    def body_rates(x):
        """(v̇, ẇ, ṗ, q̇, ṙ) in body axes at the state x = (v, w, p, q, r, u_y, u_p, u_r): the body x axis
        north and level (body = NED), so v̇_b = a_n − ω × v_b; gravity is a constant and drops out."""
        v_b, omega = Vec3(speed, x[0], x[1]), Vec3(x[2], x[3], x[4])
        body = initial_state(params).body._replace(
            r_n=Vec3(0.0, 0.0, -height), v_n=v_b, q_nb=Quat(1.0, 0.0, 0.0, 0.0), omega_b=omega
        )
        d_body, _ = derivatives(t, body, params, jnp.stack(allocate(x[5], x[6], x[7])), Vec3(0.0, 0.0, 0.0), events)
        accel = d_body.v_n - omega.cross(v_b)
        return jnp.stack([accel.y, accel.z, d_body.omega_b.x, d_body.omega_b.y, d_body.omega_b.z])

    h = 1e-4
    steps = jnp.asarray(np.vstack([h * np.eye(8), -h * np.eye(8)]))
    values = np.asarray(jax.vmap(body_rates)(steps))
    return a_plant, (values[:8] - values[8:]).T / (2 * h)


def test_moments_about_a_shifted_cg_against_the_flight():
    """The dry CG 7 cm aft of the moment reference (Lynx's is on it): a = x_ref − x_cg = +0.07 m, and the
    plant's pitch and yaw moments gain (a/d)·CN and (a/d)·CY terms. Its A (rates and lateral forces) is
    the Jacobian of the flight's own right-hand side there: signs, the halved force damping and the
    per-virtual-command derivatives included."""
    rocket = preset_rocket("lynx")
    raw = lynx("linear", dry_cg_m=rocket["reference_point_m"] + 0.07)
    a_plant, a_flight = shifted_rate_jacobian(raw, speed=120.0, height=800.0)
    cm_alpha = a_plant[3, 1]  # q̇ per w: Cm_α·k_s·u, about the CG
    unshifted = shifted_rate_jacobian(lynx("linear"), speed=120.0, height=800.0)[0]
    # The shift is no rounding: (a/d)·CNα = 0.47·24.07 = 11.2 against Cmα = −37.3 moves q̇/w by 30 %
    # (the wrong sign would move it by as much the other way).
    assert 0.2 < (cm_alpha - unshifted[3, 1]) / -unshifted[3, 1] < 0.4
    # Central differences, step 1e-4 in m/s, rad/s and rad: truncation ~h²·(third derivatives of atan2,
    # asin, the arm's cross product) ~1e-8 relative; rounding ~ε·|f|/h ~1e-12·|f|/1e-4. Entries reach
    # ~1e2 (|u| = 120 in the kinematic terms), and the smallest non-zero ones ~1e-1: 1e-6 relative
    # plus 1e-7 absolute is far above both and far below any convention slip (a factor 2 or a sign).
    np.testing.assert_allclose(a_plant, a_flight, rtol=1e-6, atol=1e-7)


def test_window_estimate_of_lynx(linear):
    """The point-mass estimate the grid check uses, on Lynx (1-10 s after liftoff): the 6-DOF flight
    (calm, linear model) measured 62.0-183.3 m/s and 31-1224 m above the pad there. The estimate has
    no rotation and starts the CG at the pad (it starts ~1 m up the rail): within 1 % and 5 m."""
    inputs = linear.gnc_inputs
    np.testing.assert_allclose(inputs.speeds, (62.0, 183.3), rtol=0.01)
    np.testing.assert_allclose(inputs.altitudes_agl, (31.2, 1223.6), atol=5.0)


def test_default_grid_grows_to_a_faster_rocket(linear):
    """The Lynx's window lies inside the default grid, which it keeps point for point. The same Lynx on 2.2× the
    thrust (148-405 m/s and 72-2646 m above the pad in the window) is designed on the defaults grown by 50 m/s
    and 1000 m until they cover it (it was refused naming the grid before); a grid set in the campaign is not grown."""
    assert design_grid(linear.config, linear.gnc_inputs) == {"speeds_mps": DEFAULT_SPEEDS_MPS,
                                                             "altitudes_m": DEFAULT_ALTITUDES_M}  # fmt: skip
    raw = lynx("linear")
    raw["rocket"]["motor"] = {**raw["rocket"].get("motor", {}), "thrust_scale": 2.2}
    del raw["dispersions"]["rocket.motor.thrust_scale"]
    fast = campaign_from_dict(raw, CAMPAIGNS)
    assert fast.gnc_inputs.speeds[1] > DEFAULT_SPEEDS_MPS[-1] and fast.gnc_inputs.altitudes_agl[1] > 2000.0
    grid = design_grid(fast.config, fast.gnc_inputs)
    assert grid == {"speeds_mps": [*DEFAULT_SPEEDS_MPS, 350.0, 400.0, 450.0], "altitudes_m": [*DEFAULT_ALTITUDES_M, 3000.0]}
    np.testing.assert_array_equal(fast.gnc_schedule.speeds, grid["speeds_mps"])
    assert fast.gnc_schedule.gains.shape == (13, 4, 3, 11)
    slow_start = fast.gnc_inputs._replace(speeds=(12.7, 200.0))
    assert design_grid(fast.config, slow_start)["speeds_mps"][:2] == [12.0, 20.0]
    with pytest.raises(ConfigError, match=r"^gnc\.control\.speeds_mps: the grid spans 20 to 300 m/s, the nominal flight 148"):
        campaign_from_dict({**raw, "gnc": {"control": {"speeds_mps": DEFAULT_SPEEDS_MPS}}}, CAMPAIGNS)


def test_gains_are_in_the_fingerprint(linear):
    """A resumed run refuses chunks of other gains: the digest of the set-up's data changes with them."""
    weights = lynx("linear", gnc={"control": {"q_weights": [0.0, 0.0, 0.0, 5.0, 5.0, 0.0, 0.0, 0.0, 10.0, 10.0, 20.0]}})
    other = campaign_from_dict(weights, CAMPAIGNS)
    assert not np.array_equal(other.gnc_schedule.gains, linear.gnc_schedule.gains)
    assert data_digest(other) != data_digest(linear)
    assert data_digest(campaign_from_dict(lynx("linear"), CAMPAIGNS)) == data_digest(linear)  # reproducible
    assert data_digest(dataclasses.replace(linear, gnc_schedule=None)) != data_digest(linear)


def flown_guidance(raw: dict):
    """The guidance parameters and the rail attitude q_nb0 a campaign flies (its nominal realization)."""
    params = nominal_params(campaign_from_dict(raw, CAMPAIGNS))
    return params.gnc.guidance, params.launch.q_nb0


def test_reference_derived_from_an_88_degree_rail():
    """Left out, the reference's γ0 is the rail's elevation (the thesis's 84° default pitched an 88° rail's
    rocket down), its heading the launch azimuth, its roll heading the one with no roll error on the rail, its
    climb the nominal flight's after t0."""
    raw = lynx("linear")
    raw["launch"].update(elevation_deg=88.0, azimuth_deg=130.0)
    guidance, q_nb0 = flown_guidance(raw)
    assert float(guidance.flight_path_angle_rad) == math.radians(88.0)
    assert float(guidance.heading_rad) == math.radians(130.0)
    # On the rail the roll command is zero: the roll error atan2(−t_b,y, t_b,z) of the derived heading, at q_nb0
    # (rounding of the quaternion's rotation, ~1e-16 rad; 1e-12 catches any real heading error).
    nav = Navigation(Vec3(0.0, 0.0, 0.0), Vec3(0.0, 0.0, 0.0), q_nb0, Vec3(0.0, 0.0, 0.0))
    command, _ = rate_command(guidance, nav, jnp.asarray(guidance.window_start_s))
    assert abs(float(command.x)) < 1e-12
    assert float(guidance.roll_heading_rad) == pytest.approx(math.radians(130.0), abs=1e-12)  # Euler roll 0 on the rail
    # The climb after t0 = 1.5 s of the point-mass estimate of the Lynx (no wind): below the apogee above the pad
    # (~1.6 km) and well above nothing. Measured 1561 m.
    assert 1000.0 < float(guidance.apogee_m) < 2000.0


def test_reference_on_a_vertical_rail_is_clipped():
    raw = lynx("linear")
    raw["launch"]["elevation_deg"] = 90.0
    guidance, _ = flown_guidance(raw)
    assert float(guidance.flight_path_angle_rad) == math.radians(89.0)  # MAX_DERIVED_FLIGHT_PATH_ANGLE_DEG
    assert np.isfinite(float(reference_direction(guidance, None, jnp.asarray(3.0)).x))


def test_reference_set_is_honoured():
    raw = lynx("linear", gnc={"guidance": {"apogee_m": 1614.0, "flight_path_angle_deg": 84.0, "roll_heading_deg": 90.0,
                                           "heading_deg": 100.0}})  # fmt: skip
    raw["launch"]["elevation_deg"] = 88.0
    campaign = campaign_from_dict(raw, CAMPAIGNS)
    assert campaign.gnc_inputs.reference.derived == ()
    guidance, _ = flown_guidance(raw)
    assert float(guidance.apogee_m) == 1614.0 and float(guidance.flight_path_angle_rad) == math.radians(84.0)
    assert float(guidance.roll_heading_rad) == math.radians(90.0) and float(guidance.heading_rad) == math.radians(100.0)


def test_no_climb_after_t0_is_refused():
    """t0 60 s after liftoff: the Lynx is past its apogee (~17 s) then, so no climb to derive."""
    with pytest.raises(ConfigError, match=r"^gnc.guidance.apogee_m: the nominal flight .* does not climb after t0_s"):
        campaign_from_dict(lynx("linear", gnc={"guidance": {"t0_s": 60.0}}), CAMPAIGNS)


def test_canards_without_authority_are_refused():
    """The thesis's Lynx trims |Cm_δ·δ_max/Cmα| = 21.8445 × 10° / 37.2959 = 5.857° (its linear model's own numbers:
    the moment reference is the CG at burnout, so the same at every corner of the window, to rounding); with the
    deflection limited to 0.08° it would trim 0.047°: one line naming the field."""
    campaign = load_campaign(CAMPAIGNS / "lynx_ballistic_ctrl_1s.toml")
    np.testing.assert_allclose(trim_angles_deg(campaign.config, campaign.gnc_inputs), 21.8445 * 10 / 37.2959, rtol=1e-9)
    with pytest.raises(ConfigError, match=r"^gnc\.servo\.limit_deg: the canards at 0\.08° trim the rocket to 0\.047°"):
        with_overrides(campaign, values={"gnc.servo.limit_deg": 0.08})
