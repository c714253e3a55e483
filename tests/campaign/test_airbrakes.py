"""Air brakes in a campaign: the gain design at set-up, flights with them against without, brakes that never open
changing nothing, the same flights whatever the chunking, and their bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rocketmc.campaign import load_campaign, run_chunks, with_overrides
from rocketmc.cli import main

from ..conftest import CAMPAIGNS
from ..test_cli_errors import one_line

pytestmark = pytest.mark.slow  # campaigns: left out by make test-fast

EUROC = CAMPAIGNS / "lynx_euroc_airbrakes.toml"


def fly(campaign, chunk_size=None):
    chunks = list(run_chunks(campaign, chunk_size))[1:]  # the first item is the compile time
    return {k: np.concatenate([c.outputs[k] for c in chunks]) for k in chunks[0].outputs}


@pytest.fixture(scope="module")
def euroc():
    return with_overrides(load_campaign(EUROC), n_realizations=8)


def test_the_design_is_the_prediction_from_the_nominal_window(euroc):
    d = euroc.airbrake_design
    # the prediction retracted from the estimate's own state at the window is the estimate's apogee (two integrators
    # of one model: the estimate's 10 ms steps against the prediction's 20 RK4 steps)
    assert d.apogee_retracted_m == pytest.approx(d.nominal_apogee_m, abs=5.0)
    assert d.apogee_deployed_m < d.target_apogee_m < d.apogee_retracted_m
    assert d.gain_per_m_s == pytest.approx(1.0 / ((d.apogee_retracted_m - d.apogee_deployed_m) * d.response_time_s), rel=1e-12)


def test_brakes_bring_the_apogee_toward_the_target(euroc):
    on, off = fly(euroc), fly(with_overrides(euroc, airbrakes=False))
    assert np.all(on["status"] == 0) and np.all(off["status"] == 0)
    target = euroc.config.airbrakes.target_apogee_m
    assert np.all(off["apogee_agl_m"] > target + 300.0)  # without them, every flight overshoots by far
    assert np.all(on["apogee_agl_m"] < off["apogee_agl_m"] - 300.0)
    assert np.all(np.abs(on["apogee_error_m"]) < np.abs(off["apogee_agl_m"] - target))
    assert np.array_equal(on["apogee_error_m"], on["apogee_agl_m"] - target)
    assert np.all(on["airbrake_active_time_s"] > 0.0) and np.all(on["airbrake_deployment_time_s"] > 0.0)


def test_the_reference_pi_is_designed_for_its_second_order_response():
    campaign = load_campaign(CAMPAIGNS / "lynx_euroc_airbrakes_pi.toml")
    d, r, pi = campaign.airbrake_design, campaign.airbrakes.reference, campaign.config.airbrakes.reference_pi
    mass = float(campaign.airbrakes.coast_mass_kg)
    assert d.controller == "reference_pi" and d.references == len(pi.levels) == r.climb_mps.shape[0]
    assert float(r.kp_n_s_per_m) == pytest.approx(2.0 * pi.damping * pi.natural_frequency_rad_s * mass, rel=1e-15)
    assert float(r.ki_n_per_m) == pytest.approx(pi.natural_frequency_rad_s**2 * mass, rel=1e-15)
    # the more the brakes are held out, the faster the coast that still ends at the target: references never cross
    assert np.all(np.diff(np.asarray(r.climb_mps)[:, :-1], axis=0) > 0.0)
    given = with_overrides(campaign, values={"airbrakes.reference": {"kp_n_s_per_m": 55.0, "ki_n_per_m": 50.0}})
    assert (float(given.airbrakes.reference.kp_n_s_per_m), float(given.airbrakes.reference.ki_n_per_m)) == (55.0, 50.0)
    assert not given.airbrake_design.gain_designed


def test_the_reference_pi_brings_the_apogee_to_the_target(euroc):
    pi = fly(with_overrides(load_campaign(CAMPAIGNS / "lynx_euroc_airbrakes_pi.toml"), n_realizations=8))
    assert np.all(pi["status"] == 0)
    error = pi["apogee_error_m"]
    # on the truth, the flights the brakes can reach land within a metre (N = 200: median +0.1 m, 5th percentile
    # −0.4 m); the others are those the brakes cannot slow enough, fully out (saturated) to the end
    reached = pi["airbrake_saturated_fraction"] < 0.9
    assert reached.sum() >= 4 and np.all(np.abs(error[reached]) < 3.0)
    assert np.all(error[~reached] > 0.0)


def test_brakes_that_never_open_change_no_bit(euroc):
    """A target out of reach above: the command stays 0, ΔCA(0) = 0, and the flights are those without brakes flown on
    the same GNC periods."""
    never = with_overrides(euroc, values={"airbrakes.target_apogee_m": 40_000.0})
    without = with_overrides(euroc, airbrakes=False, values={"simulation.event_periods": False})
    flown, reference = fly(never), fly(without)
    assert np.all(flown["airbrake_deployment_time_s"] == 0.0)
    for name, values in reference.items():
        assert np.array_equal(flown[name], values, equal_nan=True), name


def stuck(campaign, probability, deployment):
    fault = {"probability": probability, "time_s": [0.0, 12.0]}
    return with_overrides(campaign, values={"faults": {"stuck_airbrakes": fault | ({} if deployment is None else
                                                                                      {"deployment": deployment})}})  # fmt: skip


def test_brakes_stuck_retracted_from_the_pad_fly_as_brakes_that_never_open(euroc):
    jammed = with_overrides(euroc, values={"faults": {"stuck_airbrakes": {"probability": 1.0, "time_s": [0.0, 0.0],
                                                                          "deployment": 0.0}}})  # fmt: skip
    never = with_overrides(euroc, values={"airbrakes.target_apogee_m": 40_000.0})
    flown, reference = fly(jammed), fly(never)
    for name in ("apogee_agl_m", "impact_north_m", "impact_east_m", "impact_time_s", "airbrake_deployment_time_s"):
        assert np.array_equal(flown[name], reference[name]), name


def test_brakes_stuck_out_are_recorded_not_crashed(euroc):
    flown, healthy = fly(stuck(euroc, 0.5, 1.0)), fly(euroc)
    happened = list(run_chunks(stuck(euroc, 0.5, 1.0)))[1].inputs["faults.stuck_airbrakes.happened"] > 0.5
    assert happened.any() and (~happened).any()
    assert np.all(flown["status"] == 0)
    # jammed fully out from a time in [0, 12] s: lower than the controller would take them, or as low (jammed late)
    assert np.all(flown["apogee_agl_m"][happened] < healthy["apogee_agl_m"][happened] + 1.0)
    assert np.array_equal(flown["apogee_agl_m"][~happened], healthy["apogee_agl_m"][~happened])


def test_realizations_do_not_depend_on_the_chunking(euroc):
    whole, split = fly(euroc), fly(euroc, chunk_size=3)
    for name, values in whole.items():
        assert np.array_equal(split[name], values, equal_nan=True), name


def test_airbrakes_design_command(capsys):
    assert main(["airbrakes", "design", str(EUROC)]) == 0
    out = capsys.readouterr().out
    assert "target apogee 3000 m above the pad: within reach" in out and "integral gain K_i" in out
    assert main(["airbrakes", "design", str(CAMPAIGNS / "lynx_euroc_airbrakes_pi.toml"), "--json"]) == 0
    design = json.loads(capsys.readouterr().out)  # strict JSON: the other law's numbers are null
    assert design["controller"] == "reference_pi" and design["gain_per_m_s"] is None and design["references"] == 9


BRAKES = """
[airbrakes]
target_apogee_m = 3000.0
"""


@pytest.mark.parametrize("section, needle", [
    (BRAKES, "airbrakes: give the brakes' drag as exactly one of panels or table"),
    (BRAKES + "max_mach = 1.2\n[airbrakes.panels]\ncount = 3\nwidth_m = 0.05\nmax_extension_m = 0.02\n", "airbrakes.max_mach"),
    (BRAKES + "[airbrakes.panels]\ncount = 0\nwidth_m = 0.05\nmax_extension_m = 0.02\n", "airbrakes.panels.count"),
    (BRAKES + "[airbrakes.table]\ndeployments = [0.0, 0.5]\nmachs = [0.0, 0.8]\ndelta_ca = [[0.0, 0.0], [0.3, 0.35]]\n",
     "deployments must increase from 0 to 1"),
    (BRAKES + "[airbrakes.table]\ndeployments = [0.0, 0.5, 1.0]\nmachs = [0.0, 0.8]\ndelta_ca = [[0.0, 0.0], [0.3, 0.35]]\n",
     "delta_ca needs 3 rows"),
    (BRAKES + "[airbrakes.servo]\ntime_constant_s = -0.1\n[airbrakes.panels]\ncount = 3\nwidth_m = 0.05\nmax_extension_m = 0.02\n",
     "airbrakes.servo.time_constant_s"),
    (BRAKES + "[airbrakes.reference]\n[airbrakes.panels]\ncount = 3\nwidth_m = 0.05\nmax_extension_m = 0.02\n",
     "reference: read only by controller = 'reference_pi'"),
    (BRAKES + "controller = 'reference_pi'\ngain_per_m_s = 0.01\n[airbrakes.panels]\ncount = 3\nwidth_m = 0.05\n"
     "max_extension_m = 0.02\n", "gain_per_m_s: the prediction law's gain"),
    (BRAKES + "controller = 'reference_pi'\n[airbrakes.reference]\nlevels = [0.5, 0.2]\n[airbrakes.panels]\ncount = 3\n"
     "width_m = 0.05\nmax_extension_m = 0.02\n", "levels must be strictly increasing"),
    (BRAKES + "controller = 'reference_pi'\n[airbrakes.reference]\nki_n_per_m = -1.0\n[airbrakes.panels]\ncount = 3\n"
     "width_m = 0.05\nmax_extension_m = 0.02\n", "airbrakes.reference.ki_n_per_m"),
    (BRAKES + "controller = 'pid'\n[airbrakes.panels]\ncount = 3\nwidth_m = 0.05\nmax_extension_m = 0.02\n",
     "airbrakes.controller"),
])  # fmt: skip
def test_bad_airbrakes_are_one_line(tmp_path, capsys, section, needle):
    path = tmp_path / "brakes.toml"
    path.write_text(EUROC.read_text().split("[airbrakes]")[0] + section)
    one_line(capsys, ["airbrakes", "design", str(path)], needle)
    assert not (tmp_path / "out.h5").exists()
    one_line(capsys, ["run", str(path), "--out", str(tmp_path / "out.h5")], needle)
    assert not (tmp_path / "out.h5").exists()


def test_a_schedule_and_flown_brakes_are_refused(tmp_path, capsys):
    path = tmp_path / "both.toml"
    path.write_text(EUROC.read_text() + "\n[rocket.airbrakes]\ntime_s = [0.0, 1.0]\ndelta_ca = [0.0, 0.1]\n")
    one_line(capsys, ["run", str(path), "--out", str(tmp_path / "out.h5")], "rocket.airbrakes")


def test_design_without_airbrakes(capsys):
    one_line(capsys, ["airbrakes", "design", str(CAMPAIGNS / "lynx_ballistic.toml")], "no [airbrakes] section")


def test_brakes_on_the_navigation_alone():
    """gnc.canards = false: the filters run and the brakes read them, no canard controller and none of its outputs."""
    campaign = with_overrides(load_campaign(CAMPAIGNS / "lynx_euroc_airbrakes_gnc.toml"), n_realizations=4)
    assert campaign.gnc_schedule is None  # nothing designed for canards the rocket has not
    flown = fly(campaign)
    assert np.all(flown["status"] == 0)
    assert "control_active_time_s" not in flown and "position_error_apogee_m" in flown
    assert np.all(flown["position_error_apogee_m"] > 0.0)  # the estimate is not the truth
    assert np.all(np.abs(flown["apogee_error_m"]) < 300.0) and np.all(flown["airbrake_deployment_time_s"] > 0.0)


def test_canard_faults_need_canards(tmp_path, capsys):
    path = tmp_path / "no_canards.toml"
    path.write_text(f'extends = "{CAMPAIGNS / "lynx_euroc_airbrakes_gnc.toml"}"\n'
                    '[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\n')  # fmt: skip
    one_line(capsys, ["run", str(path), "--out", str(tmp_path / "out.h5")], "faults.stuck_canard", "gnc.canards is false")
    assert not (tmp_path / "out.h5").exists()
