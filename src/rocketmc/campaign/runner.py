"""Run a campaign: ``jit(vmap(...))`` over fixed-size chunks of realization indices.

The only place where ``jit`` and ``vmap`` are applied. Every chunk has the same shape (the last one
is padded with indices past N, whose results are dropped), so one compilation serves the run, and
realization ``i`` gives the same bits whatever the chunk size.

Bit-identity needs one more thing: each core's batch is a whole number of SIMD vectors. XLA
computes the leftover flights of a batch in a scalar loop whose math can differ from the vector
lanes' by an ulp (seen: lynx_nominal with turbulence, chunks of 5 against 12), so a compiled batch
holds ``LANES`` flights per core, rounded up; the extra rows are the next indices, dropped.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from ..sim.flight import simulate_one
from ..sim.params import SimSettings
from .config import Campaign
from .model import flight_params
from .sampling import realization_key, sample_dispersions


def sim_settings(campaign: Campaign) -> SimSettings:
    s = campaign.config.simulation
    return SimSettings(
        control_dt_s=s.control_dt_s, substeps=s.substeps, descent_dt_s=max(s.descent_dt_s, s.control_dt_s),
        max_time_s=s.max_time_s,
    )


def realization(campaign: Campaign, settings: SimSettings, master_key, index):
    """Draw and fly realization ``index``: returns (summary, status, drawn inputs)."""
    key = realization_key(master_key, index)
    drawn = sample_dispersions(campaign, key)
    params = flight_params(campaign, {**campaign.nominal, **drawn}, key)
    summary, status = simulate_one(params, settings)
    return summary, status, drawn


LANES = 8
"""Flights per SIMD vector: 8 float64 in an AVX-512 register (a multiple of the 4 of AVX2)."""


def batch_size(chunk_size: int) -> int:
    """Flights per compiled batch: ``chunk_size`` rounded up to ``LANES`` per local device."""
    multiple = LANES * jax.local_device_count()
    return -(-chunk_size // multiple) * multiple


def compile_chunk(campaign: Campaign, batch: int) -> Callable:
    """A compiled function: (master_key, indices (batch,)) -> (summary, status, inputs).

    The batch (a ``batch_size``) is split evenly over the local devices (the CPU cores, see
    ``rocketmc.__init__``) with ``shard_map``; each device runs its own while-loop and stops when its
    own flights are done.
    """
    settings = sim_settings(campaign)

    def chunk(master_key, indices):
        return jax.vmap(lambda i: realization(campaign, settings, master_key, i))(indices)

    mesh = jax.sharding.Mesh(np.array(jax.local_devices()), ("batch",))
    P = jax.sharding.PartitionSpec
    sharded = jax.shard_map(chunk, mesh=mesh, in_specs=(P(), P("batch")), out_specs=P("batch"))
    key = jax.random.key(campaign.config.seed)
    return jax.jit(sharded).lower(key, jnp.zeros(batch, dtype=jnp.uint32)).compile()


@dataclass
class ChunkResult:
    """Host arrays of one chunk (rows ``start .. start + len``)."""

    start: int
    outputs: dict[str, np.ndarray]
    inputs: dict[str, np.ndarray]
    seconds: float


def run_chunks(campaign: Campaign, chunk_size: int | None = None, chunks: list[int] | None = None):
    """Yield ``ChunkResult`` for each chunk index (all chunks by default), in order.

    The first item yielded is the compile time [s] (a float); then one ChunkResult per chunk.
    """
    n = campaign.config.n_realizations
    chunk_size = min(chunk_size or campaign.config.simulation.chunk_size, n)
    n_chunks = -(-n // chunk_size)
    t0 = time.perf_counter()
    batch = batch_size(chunk_size)
    compiled = compile_chunk(campaign, batch)
    yield time.perf_counter() - t0
    master_key = jax.random.key(campaign.config.seed)
    for c in range(n_chunks) if chunks is None else chunks:
        start = c * chunk_size
        indices = np.arange(start, start + batch, dtype=np.uint32)
        t0 = time.perf_counter()
        summary, status, drawn = jax.block_until_ready(compiled(master_key, indices))
        keep = min(chunk_size, n - start)
        outputs = {k: np.asarray(v)[:keep] for k, v in summary.items()}
        outputs["status"] = np.asarray(status)[:keep]
        inputs = {k: np.asarray(v)[:keep] for k, v in drawn.items()}
        yield ChunkResult(start, outputs, inputs, time.perf_counter() - t0)
