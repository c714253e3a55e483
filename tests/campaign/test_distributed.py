"""Runs on Dask (``run --workers N`` / ``--scheduler ADDRESS``): a two-worker local cluster writes the
bits of a local run (the full GNC with every error source and every fault on, tests/campaign/error_sources.py),
also when resuming, stopping early or losing a worker mid-run; a scheduler that
cannot be reached (or a port that never answers, answers garbage or closes at once), a missing 'dask'
extra and bad options are one line and exit code 2."""

from __future__ import annotations

import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import dask
import jax
import numpy as np
import pytest

import rocketmc.campaign
from rocketmc.campaign import ResultWriter, load_campaign, with_overrides
from rocketmc.campaign import distributed as dask_runner
from rocketmc.campaign.fingerprint import fingerprint, setup
from rocketmc.campaign.runner import ChunkResult
from rocketmc.cli import main

from ..conftest import CAMPAIGNS
from .error_sources import assert_every_fault_recorded, write_every_error_source
from .test_resume import assert_same, contents

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

CAMPAIGN = str(CAMPAIGNS / "lynx_ballistic_gnc_1s.toml")  # the full GNC: sensors, navigation filters, controller
# (the bits are compared on it with every error source and fault on, ``faulted``; the other tests fly nothing)
N, CHUNK, SEED = 16, 2, 7  # 8 chunks of ~0.5 s on one worker core once compiled
ARGS = ["-n", str(N), "--chunk-size", str(CHUNK), "--seed", str(SEED)]


@pytest.fixture(scope="module")
def faulted(tmp_path_factory) -> str:
    """The campaign the bits are compared on: CAMPAIGN with every error source and every fault on."""
    return str(write_every_error_source(Path(CAMPAIGN), tmp_path_factory.mktemp("campaign")))


def test_two_workers_write_the_local_bits(tmp_path, monkeypatch, faulted):
    # One test for the whole cluster: pytest-xdist may split a module's tests between its processes,
    # and each would start its own cluster (one compilation per worker, ~45 s on one core).
    assert main(["run", faulted, *ARGS, "--out", str(tmp_path / "local.h5"), "--quiet"]) == 0
    want, want_attrs = contents(tmp_path / "local.h5")
    assert_every_fault_recorded(want, N)
    # The workers, and the one restarted after a kill, load the chunk function from the test session's disk
    # cache of compiled programs (tests/conftest.py), where the local run above left it, instead of compiling it.
    # Starting the cluster sets Dask's pre-spawn variables (OMP_NUM_THREADS=1, ...) in this process for
    # good: restored after this test, so that later tests' subprocesses do not inherit them. The workers
    # run with them: the bits must not depend on BLAS threads (aero.buildup pins its LAPACK solve to one).
    for name, value in dask.config.get("distributed.nanny.pre-spawn-environ").items():
        monkeypatch.setenv(name, str(value))
    with dask_runner.cluster(workers=2) as client:  # as `run --workers 2` starts it
        # Each worker has half of this machine's XLA devices (at least 1), so its batches are padded
        # otherwise than the local run's: the bits must not depend on it.
        assert client.run(jax.local_device_count) == dict.fromkeys(client.nthreads(), max(1, jax.local_device_count() // 2))
        address = client.scheduler_info()["address"]
        assert main(["run", faulted, *ARGS, "--out", str(tmp_path / "dask.h5"), "--quiet", "--scheduler", address]) == 0
        got, got_attrs = contents(tmp_path / "dask.h5")
        assert_same(got, want)
        assert got_attrs["campaign_toml"] == want_attrs["campaign_toml"]
        assert list(got_attrs["completed_chunks"]) == list(range(N // CHUNK))

        campaign = with_overrides(load_campaign(faulted), n_realizations=N, seed=SEED)
        resumes(address, faulted, campaign, want, tmp_path / "resumed.h5")
        stops_early(client, campaign)
        refuses_workers_unlike_the_client(client, campaign)
        survives_a_killed_worker(client, campaign, want)  # last: the restarted worker compiles again


def resumes(address: str, path: str, campaign, want: dict, out) -> None:
    """A killed run left chunks 0, 3 and 5 (taken from the local run): the cluster flies the others,
    out of the usual order, and the file is the local run's."""
    writer = ResultWriter(out, campaign, CHUNK)
    for index in (0, 3, 5):
        rows = slice(CHUNK * index, CHUNK * (index + 1))
        part = {group: {k.split("/")[1]: v[rows] for k, v in want.items() if k.startswith(group)} for group in ("outputs", "inputs")}
        writer.write(ChunkResult(CHUNK * index, part["outputs"], part["inputs"], 0.0), index)
    writer.close()  # the killed run's lock is gone with its process
    assert main(["run", path, *ARGS, "--out", str(out), "--quiet", "--resume", "--scheduler", address]) == 0
    assert_same(contents(out)[0], want)


def stops_early(client, campaign) -> None:
    """A consumer that stops after the first chunk (--until-converged) leaves no task of the run on the
    cluster."""
    runs = dask_runner.run_chunks(client, campaign, CHUNK)
    next(runs)  # the compile time
    assert next(runs).start == 0
    runs.close()
    deadline = time.monotonic() + 10  # releases travel on the client's batched stream, flushed every few ms
    while (left := client.run_on_scheduler(tasks_of_rocketmc)) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert left == []


def tasks_of_rocketmc(dask_scheduler) -> list:
    return [key for key in dask_scheduler.tasks if "rocketmc-chunk" in str(key)]


def refuses_workers_unlike_the_client(client, campaign) -> None:
    """A worker of another rocketmc version refuses the chunk before compiling (exit code 2 in the CLI)."""
    client_setup = setup(campaign)
    client_setup = {**client_setup, "versions": {**client_setup["versions"], "rocketmc": "0.0.0"}}
    future = client.submit(dask_runner._fly, campaign, client_setup, CHUNK, 0)
    with pytest.raises(dask_runner.ClusterError, match=r"\(versions.rocketmc\); the bits would differ"):
        future.result()


def survives_a_killed_worker(client, campaign, want: dict) -> None:
    """A worker killed mid-run costs the chunks it held, flown again by the other; the chunks received
    before are not."""
    pids = client.run(os.getpid)
    runs = dask_runner.run_chunks(client, campaign, CHUNK)
    next(runs)  # the compile time
    first = next(runs)
    victim, keys = next((worker, keys) for worker, keys in client.processing().items() if keys)  # 7 chunks left
    os.kill(pids[victim], signal.SIGKILL)
    chunks = [first, *runs]
    got = {f"{group}/{name}": np.concatenate([getattr(c, group)[name] for c in chunks])
           for group in ("outputs", "inputs") for name in getattr(first, group)}  # fmt: skip
    assert_same(got, want)

    run = keys[0][0]  # this run's task keys: (run, chunk index)
    story = client.run_on_scheduler(lambda dask_scheduler: [(key, finish) for key, _, finish, *_ in dask_scheduler.transition_log
                                                            if isinstance(key, tuple) and key[0] == run])  # fmt: skip
    flown = {index: sum(finish == "processing" for (_, i), finish in story if i == index) for index in range(N // CHUNK)}
    assert flown[0] == 1  # received before the kill: not flown again
    assert any(n > 1 for n in flown.values())  # the victim's chunk(s) were flown again


def test_the_set_up_fingerprint_is_the_same_in_every_process(faulted):
    # The compiled chunk functions are kept under it, and resumed runs are checked against it (the campaign's
    # guidance reference derived and its IGRF-14 field evaluated in each process).
    code = ("from rocketmc.campaign import load_campaign; from rocketmc.campaign.fingerprint import fingerprint, setup; "
            f"print(fingerprint(setup(load_campaign({faulted!r}), 8)))")  # fmt: skip
    found = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert found == fingerprint(setup(load_campaign(faulted), 8))


@contextmanager
def listening(answer):
    """The address of a server thread on 127.0.0.1 that hands each connection it accepts to ``answer``
    (None: nothing listens there); its connections are closed on exit."""
    if answer is None:
        with socket.socket() as s:  # a port nobody listens on
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        yield f"tcp://127.0.0.1:{port}"
        return
    stop, accepted = threading.Event(), []
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        server.settimeout(0.05)  # to see `stop`

        def serve():
            while not stop.is_set():
                try:
                    connection = server.accept()[0]
                except TimeoutError:
                    continue
                accepted.append(connection)
                answer(connection)

        thread = threading.Thread(target=serve, daemon=True)
        thread.start()
        try:
            yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
        finally:
            stop.set()
            thread.join()
            for connection in accepted:
                connection.close()


def reset(connection):
    """Close ``connection`` with a TCP reset (SO_LINGER on, 0 s)."""
    connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    connection.close()


@pytest.mark.parametrize(
    ("answer", "says"),
    [
        (None, "no Dask scheduler reachable there"),  # a refused connection is retried until CONNECT_TIMEOUT_S
        (lambda connection: None, "no answer from a Dask scheduler within 2 s"),  # accepts, then says nothing
        (lambda connection: connection.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n"),
         "not a Dask scheduler"),
        (lambda connection: connection.close(), "the connection was closed without answering as a Dask scheduler"),
        # A reset may reach Dask before its connect attempt sees the stream open (it then retries until
        # CONNECT_TIMEOUT_S) or during the handshake: the same line either way.
        (reset, "the connection was closed without answering as a Dask scheduler"),
    ],
    ids=["nothing listens", "never answers", "answers garbage", "closes at once", "resets at once"],
)  # fmt: skip
def test_a_port_without_a_scheduler_is_one_line(answer, says, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(dask_runner, "CONNECT_TIMEOUT_S", 1.0)
    monkeypatch.setattr(dask_runner, "ANSWER_MARGIN_S", 1.0)  # a 2 s deadline
    load_campaign(CAMPAIGN)  # compiles the gain design once (~9 s cold): the bound below times the CLI warm
    threads = set(threading.enumerate())
    with listening(answer) as address:
        t0 = time.monotonic()
        assert main(["run", CAMPAIGN, "-n", "4", "--scheduler", address, "--out", str(tmp_path / "r.h5")]) == 2
        # The 2 s deadline, then closing the client and loading the campaign (< 1 s each), with room for a
        # loaded machine; the port that never answers held the client forever before.
        assert time.monotonic() - t0 < 2.0 + 5.0
    err = capsys.readouterr().err
    assert err.startswith(f"rocketmc: error: --scheduler {address}: {says}") and err.count("\n") == 1
    assert not list(tmp_path.iterdir())  # no result file or partial run left to resume
    # Nothing left to keep the CLI's process alive (distributed's idle event loop thread is a daemon).
    assert [thread for thread in threading.enumerate() if thread not in threads and not thread.daemon] == []


def test_missing_extra_and_bad_options(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if not installed: importing it raises
    monkeypatch.delitem(sys.modules, "rocketmc.campaign.distributed")
    monkeypatch.delattr(rocketmc.campaign, "distributed")
    assert main(["run", CAMPAIGN, "-n", "8", "--out", str(tmp_path / "run.h5"), "--workers", "2"]) == 2
    assert capsys.readouterr().err == ("rocketmc: error: --workers/--scheduler need the optional 'dask' extra "
                                       "(pip install 'rocketmc[dask]')\n")  # fmt: skip
    for options in (["--workers", "0"], ["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"]):
        with pytest.raises(SystemExit) as exit:
            main(["run", CAMPAIGN, *options])
        assert exit.value.code == 2 and capsys.readouterr().err.count("\n") == 1
