"""``rocketmc tune``: the ranges it keeps the guidance and the air brakes' gains in (the schema's), its objectives
against closed forms, the tuned campaign file it writes, the command on a real closed loop, the brakes' gradient
against finite differences, and its bad input."""

from __future__ import annotations

import json

import numpy as np
import pydantic
import pytest

import jax
import jax.numpy as jnp

from rocketmc.campaign import load_campaign
from rocketmc.campaign.derivatives import DIFFERENTIATED_OUTPUTS, batch_function, jacobians
from rocketmc.campaign.model import AIRBRAKE_NUMBERS, GUIDANCE_NUMBERS
from rocketmc.campaign.runner import sim_settings
from rocketmc.campaign.schema import AirbrakeReferenceConfig, AirbrakesControlConfig, GuidanceConfig
from rocketmc.campaign.tuning import bounds, calm, objective_value, tuned_campaign_text
from rocketmc.cli import main

from ..conftest import CAMPAIGNS


def _guidance(path: str, value: float) -> GuidanceConfig:
    """[gnc.guidance] of defaults with the number at ``path`` set to ``value``."""
    name, _, index = path.removeprefix("gnc.guidance.").partition(".")
    if index:
        gains = list(GuidanceConfig().integrator_gain)
        gains[int(index)] = value
        return GuidanceConfig(integrator_gain=gains)
    if name == "window_end_s":
        return GuidanceConfig(window_start_s=0.0, window_end_s=value)
    return GuidanceConfig(**{name: value})


@pytest.mark.parametrize("path", GUIDANCE_NUMBERS)
def test_bounds_are_the_schemas_ranges(path):
    low, high = bounds(path)
    for inside in (low, high):
        if np.isfinite(inside):
            _guidance(path, inside)  # accepted
    for outside in (low - 1e-3 * max(1.0, abs(low)), high + 1e-3 * max(1.0, abs(high))):
        if np.isfinite(outside):
            with pytest.raises(pydantic.ValidationError):
                _guidance(path, outside)


@pytest.mark.parametrize("path", AIRBRAKE_NUMBERS)
def test_airbrake_bounds_are_the_schemas_ranges(path):
    name = path.rpartition(".")[2]
    section = AirbrakeReferenceConfig if path.startswith("airbrakes.reference.") else AirbrakesControlConfig
    low, high = bounds(path)
    assert low == 0.0 and np.isfinite(high)
    for outside in (low - 1e-3, high * 1.001):
        with pytest.raises(pydantic.ValidationError):
            section.model_validate({name: outside}) if section is AirbrakeReferenceConfig else AirbrakesControlConfig(
                target_apogee_m=3000.0, table={"deployments": [0, 1], "machs": [0, 1], "delta_ca": [[0, 0], [1, 1]]},
                **{name: outside})  # fmt: skip


def test_apogee_error_is_the_rms_over_the_ok_flights():
    outputs = np.zeros((4, 4))
    outputs[:, 2] = [3010.0, 2990.0, 3040.0, 1000.0]
    status = np.array([0, 0, 0, 3])  # the last flight failed: left out
    expected = np.sqrt((10.0**2 + 10.0**2 + 40.0**2) / 3)
    assert float(objective_value("apogee_error", outputs, status, 3000.0)) == pytest.approx(expected, rel=1e-15)


def test_training_flights_fly_without_turbulence():
    campaign = load_campaign(CAMPAIGNS / "lynx_nominal_ctrl_1s.toml")
    trained = calm(campaign)
    assert trained.config.environment.turbulence is None
    assert set(trained.config.dispersions) == set(campaign.config.dispersions) - {"environment.turbulence.severity"}
    assert trained.config.environment.wind == campaign.config.environment.wind


def test_tuned_campaign_file_is_its_source_with_the_tuned_numbers(tmp_path):
    source = CAMPAIGNS / "lynx_nominal_ctrl_1s.toml"
    campaign = load_campaign(source)
    out = tmp_path / "tuned.toml"
    values = {"gnc.guidance.gain": 3.5, "gnc.guidance.integrator_gain.2": 8.0, "gnc.guidance.wind_gain": 2.25}
    out.write_text(tuned_campaign_text(campaign, source, out, values, "a comment\nover two lines"))
    tuned = load_campaign(out)
    guidance = tuned.config.gnc.guidance
    assert (guidance.gain, guidance.integrator_gain, guidance.wind_gain) == (3.5, [1.0, 12.0, 8.0], 2.25)
    assert tuned.config.name == "tuned"
    original = campaign.config.model_dump()
    changed = tuned.config.model_dump()
    for section in ("rocket", "environment", "launch", "dispersions", "seed", "n_realizations", "simulation"):
        assert changed[section] == original[section]
    assert changed["gnc"]["guidance"]["apogee_m"] == original["gnc"]["guidance"]["apogee_m"]


def test_tuned_brakes_file_sets_their_section(tmp_path):
    source = CAMPAIGNS / "lynx_euroc_airbrakes_pi.toml"
    out = tmp_path / "tuned.toml"
    values = {"airbrakes.reference.kp_n_s_per_m": 60.0, "airbrakes.reference.ki_n_per_m": 40.0}
    out.write_text(tuned_campaign_text(load_campaign(source), source, out, values, "brakes"))
    tuned = load_campaign(out)
    assert (float(tuned.airbrakes.reference.kp_n_s_per_m), float(tuned.airbrakes.reference.ki_n_per_m)) == (60.0, 40.0)
    assert tuned.config.airbrakes.target_apogee_m == 3000.0 and tuned.config.airbrakes.controller == "reference_pi"


@pytest.mark.slow
@pytest.mark.parametrize("campaign, path", [("custom_rocket_airbrakes.toml", "airbrakes.gain_per_m_s"),
                                            ("lynx_euroc_airbrakes_pi.toml", "airbrakes.reference.kp_n_s_per_m")])
def test_brake_gain_gradient_against_central_differences(campaign, path):
    """What ``tune`` descends: the apogee's derivative with respect to a brake gain by reverse mode through the
    bounded flight, against central differences of the forward flights (step 10⁻⁴ of the gain)."""
    campaign = calm(load_campaign(CAMPAIGNS / campaign))
    settings, master = sim_settings(campaign), jax.random.key(campaign.config.seed)
    indices = jnp.arange(3, dtype=jnp.uint32)
    _, status, derivatives = jax.jit(lambda i: jacobians(campaign, settings, master, i, (path,)))(indices)
    x0, f = batch_function(campaign, settings, master, indices, (path,))
    h = 1e-4 * x0
    apogee = DIFFERENTIATED_OUTPUTS.index("apogee_agl_m")
    difference = (f(x0 + h)[0][:, apogee] - f(x0 - h)[0][:, apogee]) / (2 * h[:, 0])
    assert np.all(np.asarray(status) == 0)
    exact = np.asarray(derivatives)[:, apogee, 0]
    # measured: within 1.3e-7 (custom rocket; one of its three flights holds the command at a stop: 0 both ways) and 5.2e-7
    # (the PI) relative; the median allows one flight where a tick's clip or saturation would fall inside the step
    assert np.median(np.abs(exact - np.asarray(difference)) / np.maximum(np.abs(np.asarray(difference)), 1e-9)) < 1e-5


def test_tune_command(tmp_path, capsys):
    """Four training flights of the ballistic closed loop, one Adam step: the step lowers the training objective
    (a descent step of 1 % on a smooth objective), the tuned file flies."""
    out = tmp_path / "tuned.toml"
    args = ["tune", str(CAMPAIGNS / "lynx_ballistic_ctrl_1s.toml"), "--params", "gnc.guidance.gain,gnc.guidance.wind_gain",
            "--train", "4", "--steps", "1", "--learning-rate", "0.01", "--test", "0", "--out", str(out), "--json",
            "--quiet"]  # fmt: skip
    assert main(args) == 0
    result = json.loads(capsys.readouterr().out)
    history = result["training_objective"]
    assert len(history) == 2 and history[1] < history[0]
    assert result["initial"] == {"gnc.guidance.gain": 5.0, "gnc.guidance.wind_gain": 1.0}
    tuned = load_campaign(out).config.gnc.guidance
    assert (tuned.gain, tuned.wind_gain) == (result["tuned"]["gnc.guidance.gain"], result["tuned"]["gnc.guidance.wind_gain"])
    assert main(args) == 2  # the file exists: --force replaces it
    assert "exists" in capsys.readouterr().err


@pytest.mark.parametrize("campaign, extra, field", [
    ("lynx_nominal_ctrl_1s.toml", ["--params", "rocket.dry_mass_kg"], "--params rocket.dry_mass_kg"),
    ("lynx_ballistic.toml", ["--params", "gnc.guidance.gain"], "--params"),
    ("lynx_nominal_ctrl_1s.toml", ["--params", "gnc.guidance.gain", "--objective", "apogee_error"], "--apogee-target-m"),
    ("lynx_nominal_ctrl_1s.toml", ["--params", "gnc.guidance.gain=fast"], "--params gnc.guidance.gain"),
    ("lynx_nominal_ctrl_1s.toml", ["--params", "gnc.guidance.gain=-1"], "gnc.guidance.gain"),
    ("lynx_euroc_airbrakes.toml", ["--params", "airbrakes.reference.kp_n_s_per_m"], "airbrakes.reference"),
    ("lynx_euroc_airbrakes_pi.toml", ["--params", "airbrakes.gain_per_m_s"], "--params airbrakes.gain_per_m_s"),
    ("lynx_euroc_airbrakes_pi.toml", ["--params", "airbrakes.reference.ki_n_per_m=-3"], "airbrakes.reference.ki_n_per_m"),
    ("lynx_euroc_airbrakes_gnc.toml", ["--params", "gnc.guidance.gain"], "--params gnc.guidance.gain"),
])  # fmt: skip
def test_tune_bad_input_is_one_line_and_exit_2(tmp_path, capsys, campaign, extra, field):
    out = tmp_path / "tuned.toml"
    assert main(["tune", str(CAMPAIGNS / campaign), *extra, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not out.exists()
