"""The flight record (``rocketmc fly``): realization I bit for bit as a campaign run flies it, the time series'
energy balance and apogee against the summary, the static margin against the aerodynamic model's derivatives."""

from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest

from rocketmc.aero import AirData
from rocketmc.aero.model import linear_derivatives, simplify
from rocketmc.aero.stability import centre_of_pressure_at
from rocketmc.analysis.flight_record import energy_balance, events, format_record
from rocketmc.campaign import load_campaign, run_chunks, with_overrides
from rocketmc.campaign.flights import flight_record
from rocketmc.campaign.model import nominal_params
from rocketmc.env import G0
from rocketmc.sim.outputs import DEPLOY_TIME_SUFFIX

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

CAMPAIGNS = Path(__file__).parents[2] / "campaigns"
N, REALIZATION = 16, 11


@pytest.fixture(scope="module")
def campaign():
    """lynx_nominal at 20 ms periods: the energy balance's trapezoid bound grows as h² (at its own 40 ms it is 1.2e-3
    of the coast's work, too loose for ``test_coast_energy_balance``'s 1e-3)."""
    return with_overrides(load_campaign(CAMPAIGNS / "lynx_nominal.toml"), n_realizations=N,
                          values={"simulation.open_loop_dt_s": 0.02})  # fmt: skip


@pytest.fixture(scope="module")
def record(campaign):
    return flight_record(campaign, REALIZATION)


def test_realization_is_the_campaign_row(campaign, record):
    # turbulence, wind, mass, thrust, drag and launch draws: every metric equal to the bit (NaNs equal)
    (chunk,) = list(run_chunks(campaign, N))[1:]
    assert record.summary.keys() <= chunk.outputs.keys()
    for name, value in record.summary.items():
        np.testing.assert_array_equal(value, chunk.outputs[name][REALIZATION], err_msg=name)
    assert record.status == chunk.outputs["status"][REALIZATION] == 0
    assert len(np.unique(chunk.outputs["apogee_agl_m"])) == N  # the realizations do differ


def test_the_summary_and_the_events_name_each_parachute(campaign, record):
    """The printed summary and the event list (the figures' and the KML's marks) carry the drogue's and the main's
    deployment at the times the flight summary holds, between apogee and impact."""
    printed, marks = format_record(record), dict(events(record))
    assert [name for name, _ in events(record)] == ["rail exit", "burnout", "apogee", "drogue deployed",
                                                    "main deployed", "impact"]  # fmt: skip
    for chute in campaign.config.rocket.parachutes:
        deployed_s = record.summary[chute.name + DEPLOY_TIME_SUFFIX]
        assert marks[f"{chute.name} deployed"] == deployed_s
        assert f"{chute.name + ' deploys':<14}{deployed_s:8.3f} s" in printed
    assert "descent rate under the main" in printed


def test_coast_energy_balance(record):
    e = energy_balance(record)
    assert e.periods > 500 and e.left_out <= 2  # the coast at 20 ms periods, a wind jump or two left out
    assert abs(e.energy_change_j - e.work_j) <= e.tolerance_j  # the integration bound (its docstring)
    assert e.tolerance_j < 1e-3 * abs(e.work_j)  # a bound tight enough to catch a missing force term


def test_apogee_against_the_samples(record):
    s, apogee = record.series, record.summary["apogee_agl_m"]
    top = int(np.argmax(s["altitude"].to_numpy()))
    t, v_down = s["time"].to_numpy()[top - 1 : top + 2], s["v_down"].to_numpy()[top - 1 : top + 2]
    h, accel = np.diff(t).max(), np.abs(np.diff(v_down) / np.diff(t)).max()
    assert abs(s["time"].iloc[top] - record.summary["apogee_time_s"]) <= h
    # the highest sample is at most h/2 from the apogee: below it by at most a·(h/2)²/2 (0.5 mm); the
    # Hermite interpolant's own error, O(h⁴) of the altitude's 4th derivative, is nanometres
    deficit = apogee - s["altitude"].iloc[top]
    assert -1e-6 <= deficit <= 0.5 * accel * (h / 2) ** 2 + 1e-6
    assert G0 / 2 < accel < 2 * G0  # gravity, and the lift of a rocket pitching over at apogee


def test_static_margin_against_the_model(campaign, record):
    # the simplified model's CNα and Cmα (``aero derivatives``) at a coast sample's Mach and altitude: the tables
    # are multilinear, so the slopes there are the same interpolation of the same node slopes (rounding apart)
    s = record.series[(record.series["phase"] == "coast") & (record.series["mach"] < 0.35)].iloc[0]
    aero = nominal_params(campaign).rocket.aero
    c = linear_derivatives(simplify(aero), s["mach"], campaign.config.site.altitude_m + s["altitude"])
    nose = campaign.config.rocket.from_nose(campaign.config.rocket.reference_point_m)
    cp = nose - float(aero.moment_ref_x_m) - c["Cma"] / c["CNa"] * float(aero.reference_length_m)
    assert s["cp"] == pytest.approx(cp, abs=1e-6)
    assert s["static_margin"] == pytest.approx((cp - s["cg"]) / float(aero.reference_length_m), abs=1e-5)
    # docs/validation.md: the build-up's CP 1.453 m, 0.82 calibre with the CG at 1.33 m (burnout) at Mach 0.3
    assert s["cg"] == pytest.approx(1.330, abs=1e-3) and s["static_margin"] == pytest.approx(0.82, abs=0.01)


def test_centre_of_pressure_of_the_linear_model(campaign):
    # docs/lynx.md's linear model: CNα 24.0744, Cmα −37.2959 per rad about the reference point, d = 0.15 m
    aero = nominal_params(with_overrides(campaign, aero_model="linear")).rocket.aero
    air = AirData(*(jnp.asarray(x) for x in (100.0, 0.0, 0.0, 0.3, 6000.0, 1.1, 1500.0)))
    x_cp = float(centre_of_pressure_at(aero, air, jnp.asarray(0.0)))
    assert x_cp == pytest.approx(-37.2959 / 24.0744 * 0.15, rel=1e-9)  # linear in α: the slope is exact


def test_a_controlled_flight_records_its_canards_and_integrators():
    """lynx_ballistic_ctrl_1s's nominal flight: four canard columns within the servos' limit, neutral on the
    rail (the window opens 1 s after liftoff) and working in the window; the integrators at rest on the rail."""
    record = flight_record(load_campaign(CAMPAIGNS / "lynx_ballistic_ctrl_1s.toml"))
    s, limit = record.series, record.campaign.config.gnc.servo.limit_deg
    canards = s[[f"canard_{i}" for i in range(1, 5)]].to_numpy()
    on_rail = s["time"].to_numpy() < record.summary["rail_exit_time_s"]
    assert on_rail.sum() > 10 and np.all(canards[on_rail] == 0.0)
    assert np.all(np.abs(canards) <= limit * (1 + 1e-12))  # clipped at the limit; rounding of the degree conversion
    assert np.abs(canards).max() > 1.0  # the controller steers (the thesis's case saturates in its first second)
    integrators = s[["integrator_p", "integrator_q", "integrator_r"]].to_numpy()
    assert np.all(integrators[on_rail] == 0.0) and np.abs(integrators).max() > 0.0
