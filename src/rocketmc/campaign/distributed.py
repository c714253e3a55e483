"""Fly a campaign's chunks on a Dask cluster (``rocketmc run --scheduler ADDRESS`` or ``--workers N``).

Needs the optional ``distributed`` package (``pip install 'rocketmc[dask]'``). The client sends the
campaign once (the workers copy it from each other), then one task per chunk index; a worker
compiles the chunk function on its first chunk and keeps it for the next ones (``runner.compiled_chunk``,
keyed by the campaign's set-up fingerprint and the batch), and sends back the chunk's host arrays. The client alone
writes the result file.

Realization i's bits depend neither on the worker that flies it nor on that worker's device count
(``runner``: a compiled batch is whole SIMD vectors on each device), so the file is the one a local
run writes, provided the workers run the same rocketmc and numerical packages, with the same precision
(the set-up is checked on each worker), on the same kind of CPU (XLA compiles for the host's vector instructions).

A worker lost mid-run costs the chunks it held: the scheduler gives them to another worker, first in
line (up to ``distributed.scheduler.allowed-failures`` times per chunk, then ``KilledWorker``).
Tasks get no ``retries``: those repeat a task that raised, and a chunk that raises would raise again.
Chunks already received are not flown again (their futures are released on arrival).
"""

from __future__ import annotations

import asyncio
import dataclasses
import os
import time
import uuid
from collections import deque
from concurrent.futures import CancelledError
from contextlib import contextmanager

import jax
from distributed import Client, KilledWorker, LocalCluster
from distributed.comm import CommClosedError

from ..errors import RocketmcError
from .record import Campaign
from .fingerprint import differences, setup
from .runner import ChunkResult, batch_size, chunking, compiled_chunk, fly_chunk

CONNECT_TIMEOUT_S = 10.0
"""How long to try reaching a scheduler [s]: a scheduler on the network answers in well under 1 s."""

ANSWER_MARGIN_S = 2.0
"""How much longer than ``CONNECT_TIMEOUT_S`` a scheduler reached has to answer [s]: once past it, a port that
accepted the connection without answering as a Dask scheduler is given up (a refused one, retried by Dask until
``CONNECT_TIMEOUT_S``, says so first)."""


class ClusterError(RocketmcError, RuntimeError):
    """A Dask cluster that cannot be reached, that lost a chunk for good, or whose workers differ from
    the client; one line."""


class _Client(Client):
    """A ``Client`` whose start ends within ``CONNECT_TIMEOUT_S + ANSWER_MARGIN_S`` [s], closed if it fails.

    Its ``timeout`` bounds the TCP connection and the scheduler's first replies, not the comm handshake between
    them: ``distributed.comm.core.connect`` awaits the peer's handshake without a deadline (dask/distributed#7698,
    2023; still so in 2026.8) and no setting bounds it, so a port that accepts and never answers would hold the
    ``Client`` constructor forever. ``sync``'s ``callback_timeout`` bounds the whole start instead."""

    def start(self, **kwargs):
        try:
            super().start(callback_timeout=CONNECT_TIMEOUT_S + ANSWER_MARGIN_S, **kwargs)
        except BaseException:
            self.close()  # a start cut short leaves its comm and event loop open
            raise


def _closed_by_peer(error: Exception) -> bool:
    """Whether reaching a scheduler failed because the port accepted the connection and closed it.

    Dask retries a connect attempt closed before it saw the stream open (a refused one too) until its timeout,
    then raises a timed-out ``OSError`` from the last attempt's ``CommClosedError``; a refused attempt's comes
    from a ``ConnectionRefusedError``."""
    closed = error if isinstance(error, CommClosedError) else error.__cause__
    return isinstance(closed, CommClosedError) and not isinstance(closed.__cause__, ConnectionRefusedError)


def worker_env(n_workers: int, devices: int) -> dict[str, str]:
    """Environment of each of ``n_workers`` local worker processes on a machine of ``devices`` XLA CPU
    devices (one per core, ``rocketmc.__init__``): ``devices // n_workers`` devices each, at least 1.

    Each worker flies one chunk at a time (one thread) spread over its devices, so together the
    workers use every core once instead of each starting one device per core; other XLA_FLAGS are kept.
    """
    flags = [f for f in os.environ.get("XLA_FLAGS", "").split() if "xla_force_host_platform_device_count" not in f]
    return {"XLA_FLAGS": " ".join([*flags, f"--xla_force_host_platform_device_count={max(1, devices // n_workers)}"])}


@contextmanager
def cluster(scheduler: str | None = None, workers: int | None = None):
    """A ``Client`` of the scheduler at ``scheduler``, or of a new local cluster of ``workers`` processes
    of 1 thread each with ``worker_env`` (closed on exit).

    The workers of an existing cluster are started by their owner: one single-threaded worker process
    per machine (``dask worker ADDRESS --nthreads 1``) spreads each chunk over all of its cores."""
    if scheduler is None:
        env = worker_env(workers, jax.local_device_count())
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, env=env) as local:
            with Client(local) as client:
                yield client
        return
    where, deadline = f"--scheduler {scheduler}", CONNECT_TIMEOUT_S + ANSWER_MARGIN_S
    try:
        client = _Client(scheduler, timeout=CONNECT_TIMEOUT_S)
    except (TimeoutError, asyncio.TimeoutError):  # an OSError, asyncio's too from Python 3.11 on
        raise ClusterError(f"{where}: no answer from a Dask scheduler within {deadline:g} s (the port accepted the "
                           "connection)") from None  # fmt: skip
    except (OSError, ValueError) as e:
        if _closed_by_peer(e):
            raise ClusterError(f"{where}: the connection was closed without answering as a Dask scheduler") from None
        raise ClusterError(f"{where}: no Dask scheduler reachable there ({e})") from None
    except ImportError:  # the scheduler refused this client's packages
        raise
    except Exception:  # whatever decoding a foreign answer raises: MemoryError, struct.error, msgpack's, ...
        raise ClusterError(f"{where}: not a Dask scheduler (its answer is not a scheduler's)") from None
    with client:
        yield client


def describe(client: Client) -> str:
    """One line: the cluster, its workers and threads, its dashboard when it has one."""
    info, threads = client.scheduler_info(), client.nthreads()  # the info lists ≤ 5 workers in 2025.4-2026.6
    dashboard = f", dashboard {client.dashboard_link}" if "dashboard" in info.get("services", {}) else ""
    return (f"Dask cluster {info['address']}: {len(threads)} worker(s), {sum(threads.values())} thread(s)"
            f"{dashboard}; each worker compiles on its first chunk")  # fmt: skip


def _campaign(campaign: Campaign) -> Campaign:
    """The task that holds the campaign on a worker, whence the others copy it; run again if every
    worker holding it is lost (scattered data would be gone for good)."""
    return campaign


def _fly(campaign: Campaign, client_setup: dict, chunk_size: int, index: int) -> tuple[ChunkResult, float]:
    """On a worker: chunk ``index``, and the seconds spent compiling for it first [s] (~0 once cached);
    refused unless the worker's set-up of the campaign (``fingerprint.setup``: package versions and
    precision among it) is the client's."""
    differing = differences(setup(campaign), client_setup)
    if differing:
        raise ClusterError(f"a worker's set-up differs from the client's ({', '.join(differing)}); the bits would differ")
    batch = batch_size(chunk_size)
    t0 = time.perf_counter()
    compiled = compiled_chunk(campaign, batch)
    compile_s = time.perf_counter() - t0
    return fly_chunk(compiled, campaign, chunk_size, batch, index), compile_s


def _received(future, index: int) -> tuple[ChunkResult, float]:
    """The result of chunk ``index``'s future, which is then released: a worker lost from then on owes
    nothing for it."""
    try:
        return future.result()
    except (KilledWorker, CancelledError) as e:
        raise ClusterError(f"the Dask cluster lost chunk {index} ({type(e).__name__}: {e}); the chunks received "
                           "are kept, --resume completes the run") from None  # fmt: skip
    finally:
        future.release()


def run_chunks(client: Client, campaign: Campaign, chunk_size: int | None = None, chunks: list[int] | None = None):
    """``runner.run_chunks`` on the workers of ``client``: yields the compile time [s] of the worker
    that flew the first chunk (~0 if it kept the function from an earlier run), then one ChunkResult
    per chunk index (all chunks by default, else the non-empty ``chunks``), in that order.

    Every chunk is submitted at once, earlier ones first in line. A chunk's ``seconds`` is the client's
    wall time since the chunk before it [s]: the workers fly in parallel, so their own times would not
    add up to the run's. Closing the generator (``--until-converged``) cancels the chunks not received.
    """
    chunk_size, n_chunks = chunking(campaign, chunk_size)
    order = range(n_chunks) if chunks is None else chunks
    run = f"rocketmc-chunk-{uuid.uuid4().hex}"  # task keys unique to this run
    t_last = time.perf_counter()
    shared = client.submit(_campaign, campaign, key=f"{run}-campaign")
    client_setup = setup(campaign)
    pending = deque(
        client.submit(_fly, shared, client_setup, chunk_size, index, key=(run, index), priority=-position)
        for position, index in enumerate(order)
    )
    try:
        for position, index in enumerate(order):
            chunk, compile_s = _received(pending.popleft(), index)
            if position == 0:
                yield compile_s
                t_last += compile_s
            now = time.perf_counter()
            yield dataclasses.replace(chunk, seconds=now - t_last)
            t_last = now
    finally:
        client.cancel([*pending, shared])
