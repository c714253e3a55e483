"""Faults as dispersions (``[faults]``): their per-flight draws, their bits across chunk sizes, the report's lines,
and refused input. Each fault's effect in a flight: tests/sim/test_faults.py."""

from __future__ import annotations

import math
import tomllib

import jax
import numpy as np
import pytest

from rocketmc.analysis import format_summary, load_run, summarize
from rocketmc.campaign import campaign_from_dict, parse_campaign, read_campaign_tables, with_overrides
from rocketmc.campaign.runner import realization_params
from rocketmc.campaign.sampling import realization_key, sample_faults
from rocketmc.cli import main

from ..conftest import CAMPAIGNS, movable
from .error_sources import FAULT_KINDS as KINDS
from .error_sources import FAULTS as EVERY_FAULT
from .test_runner import collect

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

GNC = movable((CAMPAIGNS / "lynx_ballistic_gnc_1s.toml").read_text())  # loads from any folder
FAULTS = EVERY_FAULT.replace("probability = 0.5", "probability = 0.3")
DRAWS = 400
TRUTH_ONLY_GYRO = "\n[avionics.gyroscope]\ntruth_only = true\n"


def faulted(text: str = FAULTS):
    return parse_campaign(GNC + text, CAMPAIGNS)


def draws(campaign, n: int = DRAWS) -> dict[str, np.ndarray]:
    """The fault draws of realizations 0..n-1 (``sample_faults``, as the runner makes them)."""
    master = jax.random.key(campaign.config.seed)
    drawn = jax.vmap(lambda i: sample_faults(campaign.config.faults, realization_key(master, i)))(np.arange(n))
    return {k: np.asarray(v) for k, v in drawn.items()}


def test_frequency_at_p_0_3_is_binomial():
    """Over 400 flights each fault happens in 400·0.3 = 120 ± 4σ (σ = √(400·0.3·0.7) = 9.2: a false failure ~1e-4),
    independently of the others (their joint count, 400·0.09 = 36, within 4σ = 4·5.7 too); what happened is
    drawn within its window, fins 1..4 all met, vectors of the given magnitude; NaN where it did not happen."""
    d = draws(faulted())
    sigma = math.sqrt(DRAWS * 0.3 * 0.7)
    for kind in KINDS:
        happened = d[f"faults.{kind}.happened"] == 1.0
        assert np.all((d[f"faults.{kind}.happened"] == 0.0) | happened)
        assert abs(happened.sum() - 0.3 * DRAWS) < 4 * sigma, kind
        time = d[f"faults.{kind}.start_s" if kind == "gnss_outage" else f"faults.{kind}.time_s"]
        assert np.all(np.isnan(time[~happened])) and np.all(np.isfinite(time[happened]))
    both = (d["faults.stuck_canard.happened"] == 1.0) & (d["faults.gnss_outage.happened"] == 1.0)
    assert abs(both.sum() - 0.09 * DRAWS) < 4 * math.sqrt(DRAWS * 0.09 * 0.91)
    stuck = d["faults.stuck_canard.happened"] == 1.0
    assert set(d["faults.stuck_canard.fin"][stuck]) == {1.0, 2.0, 3.0, 4.0}
    assert np.all((d["faults.stuck_canard.time_s"][stuck] >= 2.0) & (d["faults.stuck_canard.time_s"][stuck] <= 6.0))
    outage = d["faults.gnss_outage.happened"] == 1.0
    duration = (d["faults.gnss_outage.end_s"] - d["faults.gnss_outage.start_s"])[outage]
    assert np.all((duration >= 2.0 - 1e-12) & (duration <= 5.0 + 1e-12))  # 1e-12: end_s − start_s's rounding at 20 s
    jump = d["faults.gyroscope_bias_jump.happened"] == 1.0
    norm = np.linalg.norm(np.stack([d[f"faults.gyroscope_bias_jump.jump_deg_s.{i}"] for i in range(3)]), axis=0)
    np.testing.assert_allclose(norm[jump], 1.0, rtol=1e-14)  # the normalisation's rounding


def test_probability_one_every_flight_and_fixed_fin():
    """At probability 1 every flight has the fault, at the fixed fin and time given."""
    d = draws(faulted('[faults.stuck_canard]\nprobability = 1.0\ntime_s = [3.0, 3.0]\nfin = 2\n'), 50)
    assert set(d) == {"faults.stuck_canard.happened", "faults.stuck_canard.time_s", "faults.stuck_canard.fin"}
    assert np.all(d["faults.stuck_canard.happened"] == 1.0) and np.all(d["faults.stuck_canard.fin"] == 2.0)
    assert np.all(d["faults.stuck_canard.time_s"] == 3.0)


def test_probability_zero_is_no_faults_at_all():
    """Every probability 0: nothing drawn, nothing recorded, the flight's parameters the same pytree with the same
    leaves as without [faults] (so the same program and bits; without [faults] the bits are the version's before
    faults, checked on lynx_ballistic_gnc_1s and lynx_nominal when they came)."""
    off = faulted(FAULTS.replace("probability = 0.3", "probability = 0.0"))
    none = faulted("")
    master = jax.random.key(none.config.seed)
    (p_off, d_off), (p_none, d_none) = (realization_params(c, master, 3) for c in (off, none))
    assert d_off.keys() == d_none.keys() and not any(k.startswith("faults.") for k in d_off)
    assert p_off.faults is None
    assert jax.tree_util.tree_structure(p_off) == jax.tree_util.tree_structure(p_none)
    data = lambda x: jax.random.key_data(x) if jax.dtypes.issubdtype(x.dtype, jax.dtypes.prng_key) else x  # noqa: E731
    for a, b in zip(jax.tree_util.tree_leaves(p_off), jax.tree_util.tree_leaves(p_none)):
        np.testing.assert_array_equal(data(a), data(b))


def test_controller_or_sensors_off_remove_their_faults():
    """``--controller off`` flies the canards neutral: the servos' faults go with [gnc]; ``--sensors off`` removes
    the sensors' faults."""
    campaign = faulted()
    assert set(with_overrides(campaign, controller=False).config.faults.active()) == set(KINDS[2:])
    assert set(with_overrides(campaign, sensors=False).config.faults.active()) == set(KINDS[:2])


@pytest.fixture(scope="module")
def chunks():
    """lynx_ballistic_gnc_1s with every fault at 0.3, 24 flights in chunks of 5 and of 20."""
    campaign = with_overrides(faulted(), n_realizations=24)
    return collect(campaign, 5), collect(campaign, 20)


def test_same_bits_for_any_chunk_size_with_faults(chunks):
    """Chunks of 5 against chunks of 20 (as tests/campaign/test_runner.py): every output and input, the faults'
    draws included, bit for bit; the flights differ and the faults did happen."""
    (a_out, a_in), (b_out, b_in) = chunks
    assert a_out.keys() == b_out.keys() and a_in.keys() == b_in.keys()
    for name in a_out:
        np.testing.assert_array_equal(a_out[name], b_out[name], err_msg=name)
    for name in a_in:
        np.testing.assert_array_equal(a_in[name], b_in[name], err_msg=name)
    assert all(0 < a_in[f"faults.{kind}.happened"].sum() < 24 for kind in KINDS)
    assert len(np.unique(a_out["impact_north_m"])) == 24


def test_report_prints_a_line_per_fault(tmp_path, capsys):
    """``run`` records the faults in /inputs and ``report`` prints one line per fault: the flights that had it and
    the 95 % ellipse's area with and without them (the same ellipses ``summarize`` gives)."""
    campaign = tmp_path / "faulted.toml"
    campaign.write_text(GNC + FAULTS)
    out = tmp_path / "faulted.h5"
    assert main(["run", str(campaign), "-n", "24", "--chunk-size", "20", "--out", str(out), "--quiet"]) == 0
    run = load_run(out)
    summary = summarize(run)
    rows = {row["fault"]: row for row in summary["faults"]}
    assert set(rows) == set(KINDS)
    for kind, row in rows.items():
        faulted_flights = run.inputs[f"faults.{kind}.happened"].to_numpy() == 1.0
        assert row["flights"] == faulted_flights.sum()
        assert row["with"]["area_m2"] == summary["impact_ellipses"][1]["area_m2"]  # every ok flight: the 95 % one
    capsys.readouterr()
    assert main(["report", str(out)]) == 0
    text = capsys.readouterr().out
    assert text == format_summary(summary) + "\n"
    lines = text[text.index("Faults (/inputs/faults.*)"):].splitlines()[2:]
    assert [line.split()[0] for line in lines] == sorted(KINDS)
    assert all(line.split()[1] == str(rows[line.split()[0]]["flights"]) for line in lines)


@pytest.mark.parametrize("faults, field", [
    ("[faults.gnss_outage]\nprobability = 1.5\nstart_s = [1.0, 2.0]\nduration_s = [1.0, 1.0]", "faults.gnss_outage.probability"),
    ("[faults.gnss_outage]\nprobability = -0.1\nstart_s = [1.0, 2.0]\nduration_s = [1.0, 1.0]", "faults.gnss_outage.probability"),
    ("[faults.gnss_outage]\nprobability = nan\nstart_s = [1.0, 2.0]\nduration_s = [1.0, 1.0]", "faults.gnss_outage.probability"),
    ("[faults.gnss_outage]\nprobability = 0.5\nstart_s = [3.0, 2.0]\nduration_s = [1.0, 1.0]", "faults.gnss_outage.start_s"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0]", "faults.stuck_canard.time_s"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nfin = 5", "faults.stuck_canard.fin"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [-1.0, 2.0]", "faults.stuck_canard.time_s.0"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nangle_deg = 90.0", "faults.stuck_canard.angle_deg"),
    ("[faults.slow_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nfactor = 0.5", "faults.slow_canard.factor"),
    ("[faults.slow_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]", "faults.slow_canard.factor"),
    ("[faults.magnetometer_step]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_ut = 0.0", "faults.magnetometer_step.magnitude_ut"),
    ("[faults.gyroscope_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_deg_s = 1.0\nwhen = 3",
     "faults.gyroscope_bias_jump.when"),
    ("[faults.leaky_tank]\nprobability = 0.5", "faults.leaky_tank"),
    ("[faults.gyroscope_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_deg_s = 1.0",
     "faults.gyroscope_bias_jump"),
    ("[faults.stuck_canard]\ntime_s = [1.0, 2.0]", "faults.stuck_canard.probability"),
    ("[faults.stuck_canard]\nprobability = 'often'\ntime_s = [1.0, 2.0]", "faults.stuck_canard.probability"),
    ("[faults.gnss_outage]\nprobability = 0.5\nstart_s = [1.0, 2.0]\nduration_s = [3.0, 1.0]",
     "faults.gnss_outage.duration_s"),
    ("[faults.gnss_outage]\nprobability = 0.5\nduration_s = [1.0, 1.0]", "faults.gnss_outage.start_s"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0, 1e9]", "faults.stuck_canard.time_s.1"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [nan, 2.0]", "faults.stuck_canard.time_s.0"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = 1.0", "faults.stuck_canard.time_s"),
    ("[faults.magnetometer_step]\nprobability = 0.5\nmagnitude_ut = 20.0", "faults.magnetometer_step.time_s"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nfin = 2.5", "faults.stuck_canard.fin"),
    ("[faults.slow_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nfactor = 2.0\nfin = 0", "faults.slow_canard.fin"),
    ("[faults.stuck_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nangle_deg = nan", "faults.stuck_canard.angle_deg"),
    ("[faults.slow_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nfactor = 200.0", "faults.slow_canard.factor"),
    ("[faults.magnetometer_step]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_ut = 2e4",
     "faults.magnetometer_step.magnitude_ut"),
    ("[faults.gyroscope_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_deg_s = 1e4",
     "faults.gyroscope_bias_jump.magnitude_deg_s"),
    ("[faults.gyroscope_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_deg_s = inf",
     "faults.gyroscope_bias_jump.magnitude_deg_s"),
    ("[faults.accelerometer_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_mps2 = -0.5",
     "faults.accelerometer_bias_jump.magnitude_mps2"),
    ("[faults.accelerometer_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]",
     "faults.accelerometer_bias_jump.magnitude_mps2"),
    ("[faults]\nstuck_canard = 0.5", "faults.stuck_canard"),
    ("[faults.stuck_canard]\nprobability = 0.0\ntime_s = [1.0, 2.0]\nfin = 9",
     "faults.stuck_canard.fin"),  # off, still checked
], ids=["probability-above-1", "probability-negative", "probability-nan", "window-reversed", "window-one-value",
        "fin-5", "negative-time", "angle-90", "factor-below-1", "factor-missing", "zero-magnitude", "unknown-key",
        "unknown-fault", "jump-on-truth-only", "probability-missing", "probability-text", "duration-reversed",
        "start-missing", "time-beyond-max-flight", "time-nan", "time-not-a-window", "time-missing", "fin-not-whole",
        "fin-0", "angle-nan", "factor-above-100", "step-above-10000-ut", "jump-above-max-rate", "jump-inf",
        "negative-jump", "jump-magnitude-missing", "fault-not-a-table", "fin-5-at-probability-0"])  # fmt: skip
def test_bad_faults_refused_with_one_line_and_no_file(tmp_path, capsys, faults, field):
    """Each refused as one ``rocketmc: error: ... <field>: ...`` line, exit code 2, nothing written (the bias jump
    on a truth-only gyroscope: the campaign's gyroscope made one)."""
    text = GNC + TRUTH_ONLY_GYRO if field == "faults.gyroscope_bias_jump" else GNC
    campaign = tmp_path / "bad.toml"
    campaign.write_text(text + "\n" + faults + "\n")
    before = set(tmp_path.iterdir())
    assert main(["run", str(campaign), "--out", str(tmp_path / "x.h5")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("rocketmc: error:") and f": {field}: " in lines[0], lines
    assert set(tmp_path.iterdir()) == before


@pytest.mark.parametrize("campaign, added, faults, message", [
    ("lynx_nominal.toml", None, "[faults.slow_canard]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nfactor = 2.0",
     "faults.slow_canard: needs [gnc]"),
    ("lynx_ballistic_ctrl_1s.toml", None, "[faults.magnetometer_step]\nprobability = 0.5\ntime_s = [1.0, 2.0]\n"
     "magnitude_ut = 20.0", "faults.magnetometer_step: needs [avionics]"),
    ("lynx_ballistic_ctrl_1s.toml", None, "[faults.accelerometer_bias_jump]\nprobability = 1.0\ntime_s = [1.0, 2.0]\n"
     "magnitude_mps2 = 0.5", "faults.accelerometer_bias_jump: needs [avionics]"),
    ("lynx_ballistic_gnc_1s.toml", "[avionics.accelerometer]\ntruth_only = true\n",
     "[faults.accelerometer_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_mps2 = 0.5",
     "faults.accelerometer_bias_jump: avionics.accelerometer is truth_only"),
    ("lynx_ballistic_gnc_1s.toml", "[avionics]\ntruth_only = true\n",  # every sensor's
     "[faults.gyroscope_bias_jump]\nprobability = 0.5\ntime_s = [1.0, 2.0]\nmagnitude_deg_s = 1.0",
     "faults.gyroscope_bias_jump: avionics.gyroscope is truth_only"),
], ids=["canard-fault-without-gnc", "magnetometer-step-without-avionics", "bias-jump-without-avionics",
        "jump-on-truth-only-accelerometer", "jump-on-truth-only-avionics"])  # fmt: skip
def test_fault_on_what_the_campaign_does_not_fly_refused_by_run(tmp_path, capsys, campaign, added, faults, message):
    """``rocketmc run`` on a fault whose servos or sensors the campaign does not fly (or flies without errors): one
    line naming the fault, exit code 2, nothing written."""
    text = movable((CAMPAIGNS / campaign).read_text()) + "\n" + (added or "")
    path = tmp_path / "bad.toml"
    path.write_text(text + "\n" + faults + "\n")
    before = set(tmp_path.iterdir())
    assert main(["run", str(path), "--out", str(tmp_path / "x.h5")]) == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"rocketmc: error: {path}: {message}"), lines
    assert set(tmp_path.iterdir()) == before


def test_a_fault_at_probability_zero_needs_nothing():
    """A fault at probability 0 is off: it needs no section (a canard fault on a campaign without [gnc] loads) and
    leaves no fault active."""
    raw = tomllib.loads((CAMPAIGNS / "lynx_nominal.toml").read_text())
    raw["faults"] = {"stuck_canard": {"probability": 0.0, "time_s": [1.0, 2.0]}}
    assert campaign_from_dict(raw, CAMPAIGNS).config.faults.active() == {}


@pytest.mark.parametrize("campaign, fault, section", [
    ("lynx_nominal.toml", "stuck_canard", "gnc"), ("lynx_ballistic_ctrl_1s.toml", "gnss_outage", "avionics")])
def test_fault_without_its_section_is_refused(campaign, fault, section):
    """A fault on servos or sensors the campaign does not fly names the fault and the section it needs."""
    raw = read_campaign_tables(CAMPAIGNS / campaign)
    raw["faults"] = {fault: {"probability": 0.5, "time_s": [1.0, 2.0]} if fault == "stuck_canard" else
                     {"probability": 0.5, "start_s": [1.0, 2.0], "duration_s": [1.0, 1.0]}}  # fmt: skip
    with pytest.raises(Exception, match=rf"^faults\.{fault}: needs \[{section}\]"):
        campaign_from_dict(raw, CAMPAIGNS)
