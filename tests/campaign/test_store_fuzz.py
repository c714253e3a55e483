"""Partial runs that must not be resumed, result files that cannot be written, and names that are
not paths: each refusal is one line naming the file or field,
exit code 2, and leaves every file as it was; what can be completed is completed to the same bits.

One small run (lynx_ballistic, 24 flights in 3 chunks) is flown once per
test process: its partial folder and its result file are copied into each case, and every run in
these tests reuses its compiled chunk (``runner.compiled_chunk``), so no case compiles again.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rocketmc.campaign import ResultWriter, load_campaign, run_chunks, with_overrides
from rocketmc.campaign.runner import ChunkResult
from rocketmc.cli import main

from ..conftest import CAMPAIGNS, MOTORS
from .test_resume import assert_same, contents

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

ARGS = ["-n", "24", "--chunk-size", "8", "--quiet"]  # the campaign's interpolated model: loaded in ~0.1 s
# (the simplified one is linearised anew at each load, ~5 s)
N_CHUNKS = 3


def _campaign_dir(root: Path) -> Path:
    """lynx_ballistic beside its own copy of the thrust curve (which some cases edit)."""
    root.mkdir()
    text = (CAMPAIGNS / "lynx_ballistic.toml").read_text()
    (root / "lynx_ballistic.toml").write_text(text.replace('preset = "lynx"', 'preset = "lynx"\nmotor.thrust_curve = "motor.eng"'))
    shutil.copy(MOTORS / "Cesaroni_4263L1350-P.eng", root / "motor.eng")
    return root / "lynx_ballistic.toml"


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    """(campaign file, a partial folder holding all 3 chunks, the complete result file)."""
    root = tmp_path_factory.mktemp("flown")
    campaign_file = _campaign_dir(root / "campaign")
    reference = root / "reference.h5"
    assert main(["run", str(campaign_file), *ARGS, "--out", str(reference)]) == 0
    campaign = with_overrides(load_campaign(campaign_file), n_realizations=24)
    partial_out = root / "partial.h5"
    writer = ResultWriter(partial_out, campaign, 8)
    runs = run_chunks(campaign, 8)
    next(runs)
    for index, chunk in enumerate(runs):
        writer.write(chunk, index)
    return campaign_file, Path(f"{partial_out}.partial"), reference


@pytest.fixture
def case(flown, tmp_path):
    """A fresh copy of the campaign, of the partial folder (as ``run.h5.partial``) and its ``out``."""
    campaign_file, partial, _ = flown
    campaign = _campaign_dir(tmp_path / "campaign")
    shutil.copytree(partial, tmp_path / "run.h5.partial")
    return campaign, tmp_path / "run.h5"


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def refused(capsys, argv, *needles) -> str:
    """Run the CLI, expect exit 2 and one stderr line naming each of ``needles``."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("rocketmc: error: "), err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
    return lines[0]


def resume_refused(capsys, campaign, out, *needles, extra=()):
    """``--resume`` refused: one line, every file of the partial folder untouched, no result file."""
    partial = Path(f"{out}.partial")
    before = snapshot(partial)
    line = refused(capsys, ["run", str(campaign), *ARGS, "--out", str(out), "--resume", *extra], *needles)
    assert snapshot(partial) == before and not out.exists()
    return line


# --- class 1: a resumed run never mixes two set-ups -----------------------------------------------

@pytest.mark.parametrize("option, value, field", [
    ("--aero-model", "simplified", "config.rocket.aero.model"),
    ("--seed", "7", "config.seed"),
    ("-n", "23", "config.n_realizations"),
    ("--chunk-size", "12", "chunk_size"),
])  # fmt: skip
def test_resume_with_other_options_is_refused(case, capsys, option, value, field):
    campaign, out = case
    args = [*ARGS, option, value]  # the last of an option given twice wins
    partial = Path(f"{out}.partial")
    before = snapshot(partial)
    refused(capsys, ["run", str(campaign), *args, "--out", str(out), "--resume"], "another campaign or set-up", field)
    assert snapshot(partial) == before and not out.exists()


def test_resume_in_the_other_precision_is_refused(case):
    campaign, out = case
    env = {**os.environ, "ROCKETMC_PRECISION": "float32", "PYTHONPATH": os.pathsep.join(sys.path)}
    before = snapshot(Path(f"{out}.partial"))
    done = subprocess.run([sys.executable, "-m", "rocketmc.cli", "run", str(campaign), *ARGS, "--out", str(out),
                           "--resume"], env=env, capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1, done.stderr
    assert "precision" in done.stderr and snapshot(Path(f"{out}.partial")) == before and not out.exists()


@pytest.mark.parametrize("edit, field", [
    (lambda text: text.replace("1350", "1351", 1), "files.rocket.motor.thrust_curve"),  # a header number
    (lambda text: text + "; a comment\n", "files.rocket.motor.thrust_curve"),  # same numbers, other bytes
])  # fmt: skip
def test_resume_after_the_thrust_curve_changed_is_refused(case, capsys, edit, field):
    campaign, out = case
    motor = campaign.parent / "motor.eng"
    motor.write_text(edit(motor.read_text()))
    resume_refused(capsys, campaign, out, "another campaign or set-up", field)


def test_resume_after_the_campaign_text_changed_is_refused(case, capsys):
    campaign, out = case
    campaign.write_text(campaign.read_text() + "\n# a comment: the text is part of the result\n")
    resume_refused(capsys, campaign, out, "campaign_toml")


def test_a_chunk_copied_under_another_name_is_refused(case, capsys):
    campaign, out = case
    partial = Path(f"{out}.partial")
    shutil.copy(partial / "chunk_000000.h5", partial / "chunk_000002.h5")
    resume_refused(capsys, campaign, out, "chunk_000002.h5", "rows of chunk 0")


def test_a_chunk_of_another_set_up_is_refused(case, capsys, tmp_path):
    """The same rows, committed by a run of another seed: its fingerprint is not this run's."""
    campaign, out = case
    partial = Path(f"{out}.partial")
    with h5py.File(partial / "chunk_000001.h5") as f:
        rows = ChunkResult(8, *({k: v[()] for k, v in f[g].items()} for g in ("outputs", "inputs")), 0.0)
    other = ResultWriter(tmp_path / "other.h5", with_overrides(load_campaign(campaign), n_realizations=24, seed=99), 8)
    other.write(rows, 1)
    shutil.copy(tmp_path / "other.h5.partial" / "chunk_000001.h5", partial / "chunk_000001.h5")
    resume_refused(capsys, campaign, out, "chunk_000001.h5", "another set-up")


def _edit_chunk(path: Path, edit) -> None:
    with h5py.File(path, "r+") as f:
        edit(f)


@pytest.mark.parametrize("edit, needle", [
    (lambda f: f.attrs.__setitem__("chunk_index", 0), "rows of chunk 0"),
    (lambda f: f.attrs.__setitem__("start", 0), "rows of chunk 1"),
    (lambda f: f.attrs.__setitem__("fingerprint", "0" * 64), "another set-up"),
    (lambda f: f["outputs"].__delitem__("apogee_agl_m"), "datasets differ"),
    (lambda f: f["outputs"].__delitem__("status"), "datasets differ"),
    (lambda f: (f["outputs"].__delitem__("impact_east_m"), f["outputs"].create_dataset("impact_east_m", data=np.zeros(3))),
     "datasets differ"),
])  # fmt: skip
def test_an_edited_chunk_is_refused(case, capsys, edit, needle):
    campaign, out = case
    _edit_chunk(Path(f"{out}.partial") / "chunk_000001.h5", edit)
    resume_refused(capsys, campaign, out, "chunk_000001.h5", needle)


def test_a_flipped_data_byte_is_caught_by_the_checksum(case, capsys):
    campaign, out = case
    path = Path(f"{out}.partial") / "chunk_000001.h5"
    with h5py.File(path) as f:
        offset = f["outputs/impact_north_m"].id.get_chunk_info(0).byte_offset
    data = bytearray(path.read_bytes())
    data[offset + 3] ^= 0x10  # one bit of the first impact point: a value still finite and plausible
    path.write_bytes(bytes(data))
    resume_refused(capsys, campaign, out, "chunk_000001.h5", "unreadable")


@pytest.mark.parametrize("keep_bytes", [0, 100, 4000])
def test_a_truncated_chunk_is_refused_even_when_converging(case, capsys, keep_bytes):
    campaign, out = case
    path = Path(f"{out}.partial") / "chunk_000001.h5"
    path.write_bytes(path.read_bytes()[:keep_bytes])
    resume_refused(capsys, campaign, out, "chunk_000001.h5", "unreadable", extra=["--until-converged", "5"])


@pytest.mark.parametrize("name, needle", [
    ("notes.txt", "notes.txt"),
    ("chunk_1.h5", "chunk_1.h5"),  # not the run's naming: refused, not guessed
    ("chunk_000009.h5", "chunk 9 of a run of 3 chunks"),
    ("subfolder/", "subfolder"),
])  # fmt: skip
def test_a_stray_file_in_the_partial_folder_is_refused(case, capsys, name, needle):
    campaign, out = case
    target = Path(f"{out}.partial") / name
    if name.endswith("/"):
        target.mkdir()
    else:
        shutil.copy(Path(f"{out}.partial") / "chunk_000000.h5", target)
    resume_refused(capsys, campaign, out, needle)


@pytest.mark.parametrize("edit, needle", [
    (lambda m: {**m, "n_realizations": 25}, "n_realizations"),  # a top-level field
    (lambda m: {**m, "setup": {**m["setup"], "chunk_size": 4}}, "edited or damaged"),  # the set-up itself
    (lambda m: {**m, "fingerprint": "f" * 64}, "edited or damaged"),
    (lambda m: [m], "not a rocketmc manifest"),
    (lambda m: {k: v for k, v in m.items() if k != "format"}, "manifest format 1"),
])  # fmt: skip
def test_a_manifest_edited_by_hand_is_refused(case, capsys, edit, needle):
    campaign, out = case
    manifest = Path(f"{out}.partial") / "manifest.json"
    manifest.write_text(json.dumps(edit(json.loads(manifest.read_text()))))
    resume_refused(capsys, campaign, out, needle)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_any_single_edit_of_the_manifest_is_refused(case, capsys, data):
    """Replace one leaf of the manifest (a string, number, bool or null anywhere in it) by another
    value: the resume is refused in one line and nothing changes."""
    campaign, out = case
    manifest = Path(f"{out}.partial") / "manifest.json"
    original = manifest.read_text()
    tree = json.loads(original)
    leaves = []

    def walk(node, path):
        children = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else None
        if children is None:
            leaves.append(path)
        else:
            for key, child in children:
                walk(child, (*path, key))

    walk(tree, ())
    path = data.draw(st.sampled_from(leaves))
    node = tree
    for key in path[:-1]:
        node = node[key]
    value = data.draw(st.one_of(st.integers(-3, 10**6), st.text(max_size=8), st.booleans(), st.none(),
                                st.floats(allow_nan=False)).filter(lambda v: v != node[path[-1]]))  # fmt: skip
    node[path[-1]] = value
    manifest.write_text(json.dumps(tree))
    try:
        resume_refused(capsys, campaign, out)
    finally:
        manifest.write_text(original)


def test_a_killed_write_left_behind_is_replaced_and_the_run_completes(case, flown, capsys):
    """A ``.writing`` file (a kill during a chunk's write) and a missing chunk: the resume flies that
    chunk again and the file is the uninterrupted run's, bit for bit."""
    campaign, out = case
    partial = Path(f"{out}.partial")
    (partial / "chunk_000001.h5").rename(partial / "chunk_000001.h5.writing")
    assert main(["run", str(campaign), *ARGS, "--out", str(out), "--resume"]) == 0
    assert not partial.exists()
    assert_same(contents(out)[0], contents(flown[2])[0])


def test_resume_of_a_complete_run_says_so(flown, capsys, tmp_path):
    campaign, _, reference = flown
    out = tmp_path / "done.h5"
    shutil.copy(reference, out)
    assert main(["run", str(campaign), *ARGS, "--out", str(out), "--resume"]) == 0
    assert "complete already" in capsys.readouterr().err
    assert out.read_bytes() == reference.read_bytes()
    other = ["--seed", "3"]
    refused(capsys, ["run", str(campaign), *ARGS, *other, "--out", str(out), "--resume"], "complete already",
            "another set-up")  # fmt: skip
    with h5py.File(out, "r+") as f:
        f.attrs["complete"] = False
    refused(capsys, ["run", str(campaign), *ARGS, "--out", str(out), "--resume"], "incomplete")


def test_the_gather_checks_the_chunks_again(flown, tmp_path):
    """A chunk damaged after it was written (and checked): ``finish`` refuses, keeps the chunks and
    writes no result file."""
    campaign_file, partial, _ = flown
    shutil.copytree(partial, tmp_path / "run.h5.partial")
    campaign = with_overrides(load_campaign(campaign_file), n_realizations=24)
    writer = ResultWriter(tmp_path / "run.h5", campaign, 8, resume=True)
    chunk = tmp_path / "run.h5.partial" / "chunk_000002.h5"
    chunk.write_bytes(chunk.read_bytes()[:-50])
    with pytest.raises(ValueError, match="chunk_000002.h5: unreadable"):
        writer.finish()
    assert not (tmp_path / "run.h5").exists() and len(list((tmp_path / "run.h5.partial").glob("chunk_*"))) == 3


# --- class 3: a full disk ends in one line, and --resume completes the run ------------------------

@pytest.fixture
def file_size_limit():
    """Set RLIMIT_FSIZE (bytes) for this process, as a full disk would stop a write (EFBIG instead
    of ENOSPC, the same OSError path; Python ignores SIGXFSZ); restored after the test."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    yield lambda limit: resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
    resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))


@pytest.mark.parametrize("limit, chunks_kept, needle", [
    (14_000, 0, "chunk_000000.h5: could not write"),  # the manifest (~10 kB) fits, the first chunk (~17 kB) not
    (24_000, 3, "run.h5: could not write"),  # the chunks fit, the gathered file (~31 kB) does not
])  # fmt: skip
def test_a_full_disk_ends_in_one_line_and_resume_completes(flown, tmp_path, capsys, file_size_limit, limit,
                                                         chunks_kept, needle):  # fmt: skip
    campaign, _, reference = flown
    out = tmp_path / "run.h5"
    argv = ["run", str(campaign), *ARGS, "--out", str(out)]
    file_size_limit(limit)
    line = refused(capsys, argv, needle, "--resume")
    file_size_limit(resource.RLIM_INFINITY)
    partial = Path(f"{out}.partial")
    assert f"{chunks_kept} chunk" in line and not out.exists()
    assert sorted(p.name for p in partial.iterdir()) == sorted(["manifest.json", "run.lock", *(f"chunk_{i:06d}.h5" for i in range(chunks_kept))])
    assert main([*argv, "--resume"]) == 0
    assert_same(contents(out)[0], contents(reference)[0])


@pytest.mark.parametrize("out, needle", [
    ("folder_instead/", "folder_instead"),  # --out names an existing folder
    ("a_file/run.h5", "a_file"),  # under a file, not a folder
])  # fmt: skip
def test_an_output_that_cannot_be_written_is_one_line(flown, tmp_path, capsys, out, needle):
    (tmp_path / "folder_instead").mkdir()
    (tmp_path / "a_file").write_text("not a folder")
    before = snapshot(tmp_path)
    refused(capsys, ["run", str(flown[0]), *ARGS, "--out", str(tmp_path / out)], needle)
    assert snapshot(tmp_path) == before and sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "folder_instead"]


# --- class 4: a campaign name is a label ---------------------------------------------------------

@pytest.mark.parametrize("name, stem", [
    ("../../escaped", "_escaped"),
    ("/etc/passwd", "_etc_passwd"),
    ("Lynx nominal, 2021", "Lynx_nominal_2021"),
    ("..", "_"),
    (".hidden", "hidden"),
    ("x" * 10_000, "x" * 100),
])  # fmt: skip
def test_file_names_from_campaign_names_stay_in_the_folder(name, stem):
    from rocketmc.files import file_stem

    assert file_stem(name) == stem


def test_a_run_named_with_a_path_writes_in_the_working_folder(flown, tmp_path, monkeypatch):
    campaign = _campaign_dir(tmp_path / "campaign")
    campaign.write_text(campaign.read_text().replace('name = "lynx_ballistic"', 'name = "../../outside"'))
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    assert main(["run", str(campaign), *ARGS]) == 0
    assert sorted(p.name for p in work.iterdir()) == ["_outside.h5"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["campaign", "work"]
