"""One compiled program per campaign structure (campaign/program.py, runner.chunk_function): the campaign's numbers
are the program's arguments, so campaigns that differ only in numbers lower to the same program text, a structure
change is another program, a process compiles once for both, and the cache folder gives the same bits as a program
compiled anew."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

from rocketmc.campaign import campaign_from_dict, load_campaign, program, read_campaign_tables, runner, with_overrides
from rocketmc.campaign.limits import fixed_reason
from rocketmc.campaign.program import program_numbers, structure_fingerprint, with_numbers

from ..conftest import CAMPAIGNS, REPO

FAULTS = {
    "stuck_canard": {"probability": 0.3, "time_s": [1.0, 10.0]},
    "gnss_outage": {"probability": 0.3, "start_s": [10.0, 20.0], "duration_s": [5.0, 10.0]},
    "magnetometer_step": {"probability": 0.5, "time_s": [0.5, 3.0], "magnitude_ut": 20.0},
}


def _configured(config: dict, path: str):
    node = config
    for part in path.split("."):
        node = node[int(part)] if isinstance(node, list) else node[part]
    return node


def every_number_moved(campaign):
    """``campaign`` with each number the program takes as an argument (a dispersible float field, not zero) 0.1 %
    larger: another wind, mass, rail, motor, servo, sensor errors; the same structure."""
    config = json.loads(campaign.config.model_dump_json())
    moved = {path: value * 1.001 for path, value in campaign.nominal.items()
             if fixed_reason(path) is None and isinstance(_configured(config, path), float) and value != 0.0}  # fmt: skip
    return with_overrides(campaign, values=moved), len(moved)


def shipped(name: str, **tables):
    raw = read_campaign_tables(CAMPAIGNS / f"{name}.toml")
    return campaign_from_dict({**raw, **tables}, CAMPAIGNS)


@pytest.mark.parametrize("make", [
    lambda: shipped("lynx_ballistic_gnc_1s_realistic", faults=FAULTS),  # full GNC, sensor spreads, faults
    lambda: shipped("lynx_roccaraso_2021"),  # DATCOM table, measured wind profile, airbrakes
    lambda: shipped("lynx_euroc_era5"),  # the day's atmosphere from a reanalysis
    lambda: load_campaign(CAMPAIGNS / "custom_rocket.toml"),  # build-up tables, a library motor, boat-tail
], ids=["gnc_realistic_faults", "roccaraso_2021", "euroc_era5", "custom_rocket"])  # fmt: skip
def test_numbers_are_arguments_not_constants(make):
    """Lowered anew (no cache), a campaign and the same with every argument number moved are the same program text,
    and have one structure fingerprint: a number read as a constant would change the text. Each realization's
    flight parameters are rebuilt from the numbers alone (``with_numbers``)."""
    campaign = make()
    moved, n_moved = every_number_moved(campaign)
    assert n_moved > 20
    assert structure_fingerprint(moved) == structure_fingerprint(campaign)
    arguments = runner._example_arguments(campaign, 16)
    text = runner.chunk_function(campaign).lower(*arguments).as_text()
    assert runner.chunk_function(moved).lower(*runner._example_arguments(moved, 16)).as_text() == text
    numbers = program_numbers(moved)
    assert not all(np.array_equal(a, b) for a, b in zip(numbers, arguments[0]))
    rebuilt = with_numbers(campaign, numbers)
    assert all(float(rebuilt.nominal[path]) == value for path, value in moved.nominal.items())


def test_a_structure_change_is_another_program(monkeypatch):
    """N, the seed and a number share the program (compiled once in a process); a number fixed per campaign (the
    fins' span builds the tables, but is itself a constant of the program) or a subsystem is another structure."""
    campaign = load_campaign(CAMPAIGNS / "lynx_ballistic.toml")
    others = [with_overrides(campaign, n_realizations=37, seed=campaign.config.seed + 1),
              with_overrides(campaign, values={"rocket.dry_mass_kg": campaign.config.rocket.dry_mass_kg + 1.0,
                                               "environment.wind.layers.1.speed_mps": 3.0})]  # fmt: skip
    changed = [with_overrides(campaign, values={"simulation.control_dt_s": 0.01}),
               with_overrides(campaign, controller=True)]
    assert {structure_fingerprint(c) for c in others} == {structure_fingerprint(campaign)}
    assert len({structure_fingerprint(c) for c in [campaign, *changed]}) == 3
    lowered = []
    program = type("Program", (), {"compiled": lambda self, *args: object()})()
    monkeypatch.setattr(runner, "_chunk_program", lambda c, batch, wrt: lowered.append(c) or program)
    monkeypatch.setattr(runner, "_compiled", runner.OrderedDict())
    for c in [campaign, *others]:
        runner.compiled_chunk(c, 16)
    runner.compiled_chunk(changed[0], 16)
    assert lowered == [campaign, changed[0]]


def test_another_code_is_another_cached_program(tmp_path, monkeypatch):
    """A program exported by other code (an edited editable install) is not read back: the cache file's name hashes
    rocketmc's source (``source_digest``) too."""
    monkeypatch.setattr(program, "CACHE_DIR", str(tmp_path))
    double = lambda x: 2.0 * x  # noqa: E731
    program.cached_program("probe", "key", double, np.ones(3))
    program.cached_program("probe", "key", double, np.ones(3))  # read back
    assert len(list((tmp_path / "programs").iterdir())) == 1
    monkeypatch.setattr(program, "source_digest", lambda: "edited")
    program.cached_program("probe", "key", double, np.ones(3))
    assert len(list((tmp_path / "programs").iterdir())) == 2


def test_small_runs_share_batches():
    """A run of fewer flights than the default chunk flies a power of two of SIMD vectors per device (at most the
    default chunk's batch), so that N = 100 and N = 120 share a program; the default chunk keeps its own."""
    multiple = runner.LANES * runner.jax.local_device_count()
    assert runner.batch_size(100) == runner.batch_size(120) == multiple * (1 << (-(-100 // multiple) - 1).bit_length())
    assert runner.batch_size(1000) == -(-1000 // multiple) * multiple
    assert runner.batch_size(900) == runner.batch_size(1000) and runner.batch_size(2000) == -(-2000 // multiple) * multiple
    assert all(runner.batch_size(n) >= n for n in range(1, 2100, 7))


def _run(out, cache: str, jax_cache: str | None):
    env = {k: v for k, v in os.environ.items() if k != "JAX_COMPILATION_CACHE_DIR"}
    env.update(ROCKETMC_CACHE_DIR=cache, **({} if jax_cache is None else {"JAX_COMPILATION_CACHE_DIR": jax_cache}))
    done = subprocess.run([sys.executable, "-m", "rocketmc.cli", "run", str(CAMPAIGNS / "lynx_ballistic.toml"), "-n", "20",
                           "--out", str(out), "--force"], env=env, capture_output=True, text=True, cwd=REPO)  # fmt: skip
    assert done.returncode == 0, done.stderr
    with h5py.File(out) as f:
        return {k: f["outputs"][k][()] for k in f["outputs"]}, done.stdout + done.stderr


def test_same_bits_with_and_without_the_cache(tmp_path):
    """Three fresh processes: the cache folder empty (the program exported and compiled anew, both saved), the same
    folder again (both read back), and the cache off (XLA's disk cache too): every output bit-identical."""
    cache = tmp_path / "cache"
    cold, _ = _run(tmp_path / "cold.h5", str(cache), None)
    assert any((cache / "programs").glob("chunk-*.jaxexport")) and any((cache / "xla").iterdir())
    warm, _ = _run(tmp_path / "warm.h5", str(cache), None)
    off, _ = _run(tmp_path / "off.h5", "off", None)
    for name in cold:
        np.testing.assert_array_equal(warm[name], cold[name], err_msg=name)
        np.testing.assert_array_equal(off[name], cold[name], err_msg=name)
    assert len(list((cache / "programs").glob("chunk-*.jaxexport"))) == 1
