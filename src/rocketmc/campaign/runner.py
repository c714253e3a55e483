"""Run a campaign: ``jit(vmap(...))`` over fixed-size chunks of realization indices.

Where campaigns are compiled and vmapped (the other modules that apply ``jit`` or ``vmap``: docs/architecture.md,
"Where jit and vmap sit"). Every chunk has the same shape (the last one
is padded with indices past N, whose results are dropped), so one compilation serves the run, and
realization ``i`` gives the same bits whatever the chunk size.

Bit-identity needs one more thing: each core's batch is a whole number of SIMD vectors. XLA
computes the leftover flights of a batch in a scalar loop whose math can differ from the vector
lanes' by an ulp (seen: lynx_nominal with turbulence, chunks of 5 against 12), so a compiled batch
holds ``LANES`` flights per core, rounded up; the extra rows are the next indices, dropped.
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field

import jax
import jax.numpy as jnp
import numpy as np

from ..pytree import tree_where
from ..sim.flight import fly_block, flight_done, initial_state, simulate_one
from ..sim.outputs import flight_summary
from ..sim.params import FlightParams
from ..sim.params import SimSettings
from .record import Campaign
from .program import Program, cached_program, program_numbers, structure_fingerprint, with_numbers
from .model import flight_params
from .sampling import realization_key, sample_dispersions, sample_faults
from .derivatives import DIFFERENTIATED_OUTPUTS, MISMATCH, sensitivities


def sim_settings(campaign: Campaign) -> SimSettings:
    s = campaign.config.simulation
    return SimSettings(
        control_dt_s=s.control_dt_s, substeps=s.substeps, descent_dt_s=max(s.descent_dt_s, s.control_dt_s),
        descent_h_omega=s.descent_h_omega, event_periods=s.event_periods,
        open_loop_dt_s=s.open_loop_dt_s or s.control_dt_s,
        point_mass_descent=s.point_mass_descent, swing_settle_s=s.swing_settle_s, max_time_s=s.max_time_s,
    )


def realization_params(campaign: Campaign, master_key, index):
    """Realization ``index``'s (flight parameters, drawn inputs)."""
    key = realization_key(master_key, index)
    drawn = {**sample_dispersions(campaign, key), **sample_faults(campaign.config.faults, key)}
    return flight_params(campaign, {**campaign.nominal, **drawn}, key), drawn


def realization(campaign: Campaign, settings: SimSettings, master_key, index):
    """Draw and fly realization ``index``: returns (summary, status, drawn inputs)."""
    params, drawn = realization_params(campaign, master_key, index)
    summary, status = simulate_one(params, settings)
    return summary, status, drawn


LANES = 8
"""Flights per SIMD vector: 8 float64 in an AVX-512 register (a multiple of the 4 of AVX2)."""

GROUP = 128
"""Flights flown side by side (vmapped lanes) on each device; a lane whose flight is done takes the
device's next one (``simulate_queue``). Measured on the 2-core machine, whole 1000-flight chunks
(``bench.throughput``, two runs each): 128 lanes fly 6-7 % more flights/s than 64 on lynx_nominal
(545-550 against 515-522) and 6-12 % more with the full GNC (lynx_nominal_gnc_1s: 524-548 against
491-494); a kernel's fixed cost is spread over twice the lanes (docs/performance.md)."""


SHARED_BATCH_FLIGHTS = 1000
"""The default chunk size: smaller chunks (a run of fewer flights) are rounded up to a power of two of SIMD vectors
per device, at most this many flights' worth, so that runs of one campaign with other small N share programs
(16, 32, ..., 512 and 1008 flights on two cores)."""


def batch_size(chunk_size: int) -> int:
    """Flights per compiled batch: ``chunk_size`` rounded up to ``LANES`` per local device, and below
    ``SHARED_BATCH_FLIGHTS`` to a power of two of those (at most the default chunk's batch)."""
    multiple = LANES * jax.local_device_count()
    vectors, shared = -(-chunk_size // multiple), -(-SHARED_BATCH_FLIGHTS // multiple)
    if vectors < shared:
        vectors = min(1 << (vectors - 1).bit_length(), shared)
    return vectors * multiple


def simulate_queue(params_of: Callable[[jnp.ndarray], FlightParams], queue, settings: SimSettings, lanes: int):
    """Fly the flights ``params_of(i)`` for i in ``queue`` (M,) on ``lanes`` vmapped lanes and return
    their (summaries, statuses), each (M,), as ``simulate_one`` gives them.

    Lanes fly ``settings.block_steps`` control periods at a time (``fly_block``); after each block a
    lane whose flight is done records it and takes the next flight of the queue, so the lanes do not
    wait for the slowest flight (lynx_nominal: 84 % of lane-steps useful in fixed groups of 64).
    A flight flies the same steps and gusts whatever its lane.
    """
    m = queue.shape[0]
    lanes = min(lanes, m)

    def params_at(position):  # positions past the queue (idle lanes) fly its last flight again, unrecorded
        return params_of(queue[jnp.minimum(position, m - 1)])

    @jax.vmap
    def lane_block(position, state, block):  # parameters made per lane: shared ones stay unbatched
        p = params_at(position)
        state = fly_block(p, settings, state, block)
        return state, flight_done(settings, state) & (position < m), *flight_summary(p, state)

    def run_block(carry):
        position, block, state, taken, summaries, statuses = carry
        state, finished, summary, status = lane_block(position, state, block)
        record = jnp.where(finished, position, m)  # m: out of bounds, dropped
        summaries = jax.tree_util.tree_map(lambda a, x: a.at[record].set(x, mode="drop"), summaries, summary)
        statuses = statuses.at[record].set(status, mode="drop")
        position = jnp.where(finished, taken + jnp.cumsum(finished) - 1, position)
        restart = finished & (position < m)
        state = jax.vmap(lambda r, i, s: tree_where(r, initial_state(params_at(i)), s))(restart, position, state)
        block = jnp.where(restart, 0, block + 1).astype(jnp.uint32)
        return position, block, state, taken + jnp.sum(finished), summaries, statuses

    position = jnp.arange(lanes)
    state = jax.vmap(lambda i: initial_state(params_at(i)))(position)
    _, _, summary, status = jax.eval_shape(lane_block, position, state, jnp.zeros(lanes, jnp.uint32))
    summaries = {k: jnp.zeros(m, v.dtype) for k, v in summary.items()}
    carry = (position, jnp.zeros(lanes, jnp.uint32), state, jnp.asarray(lanes), summaries, jnp.zeros(m, status.dtype))
    carry = jax.lax.while_loop(lambda c: jnp.any(c[0] < m), run_block, carry)
    return carry[4], carry[5]


def chunk_function(campaign: Campaign, wrt: tuple[str, ...] = ()) -> Callable:
    """The jitted chunk function of the campaign's structure (``program.structure_fingerprint``): (numbers, the master
    key's data, indices (batch,)) -> (summary, status, inputs, derivatives), the numbers ``program.program_numbers``'.
    The batch is split evenly over the local devices (the CPU cores, see ``rocketmc.__init__``) with ``shard_map``;
    each device flies its share on ``GROUP`` lanes and stops when its own flights are done. With ``wrt`` (dotted
    paths), each flight also gives its derivatives with respect to them (``derivatives.sensitivities``: a dict of
    each differentiated output's (batch, len(wrt)) and the linearity check's ``mismatch`` (batch, outputs)), the
    device's flights side by side to the last one's landing, not queued; without, derivatives is an empty dict."""
    settings = sim_settings(campaign)

    def chunk(numbers, key_data, indices):
        flying, master_key = with_numbers(campaign, numbers), jax.random.wrap_key_data(key_data)
        drawn = jax.vmap(lambda i: realization_params(flying, master_key, i)[1])(indices)
        if not wrt:
            params_of = lambda i: realization_params(flying, master_key, i)[0]  # noqa: E731
            return *simulate_queue(params_of, indices, settings, GROUP), drawn, {}
        summary, status, derivatives, mismatch = sensitivities(flying, settings, master_key, indices, wrt)
        by_output = {name: derivatives[:, k] for k, name in enumerate(DIFFERENTIATED_OUTPUTS)}
        return summary, status, drawn, {**by_output, MISMATCH: mismatch}

    P, mesh = jax.sharding.PartitionSpec, jax.sharding.Mesh(np.array(jax.local_devices()), ("batch",))
    return jax.jit(jax.shard_map(chunk, mesh=mesh, in_specs=(P(), P(), P("batch")), out_specs=P("batch"),
                                 check_vma=False))  # fmt: skip


def _chunk_program(campaign: Campaign, batch: int, wrt: tuple[str, ...] = ()) -> Program:
    """``chunk_function`` exported once per structure, batch, device count and ``wrt`` into the cache folder
    (``program.cached_program``), and jitted from that export whether it was made now or read back."""
    P = jax.sharding.PartitionSpec
    key = structure_fingerprint(campaign) + ("" if not wrt else "-wrt-" + ",".join(wrt))
    return cached_program("chunk", key, chunk_function(campaign, wrt), *_example_arguments(campaign, batch),
                          in_specs=(P(), P(), P("batch")), out_spec=P("batch"))  # fmt: skip


def _example_arguments(campaign: Campaign, batch: int) -> tuple:
    return program_numbers(campaign), jax.random.key_data(jax.random.key(0)), np.zeros(batch, dtype=np.uint32)


def lower_chunk(campaign: Campaign, batch: int) -> jax.stages.Lowered:
    """The chunk program for a batch (a ``batch_size``), lowered: its arguments are the campaign's numbers, the master
    key's data and the indices (batch,), so N, the seed and every number ``program.program_numbers`` carries are not
    in it: one program serves every campaign of the same structure (``chunk_function``)."""
    return _chunk_program(campaign, batch).lower(*_example_arguments(campaign, batch))


def _bound(compiled: Callable, campaign: Campaign) -> Callable:
    """``compiled`` with the campaign's numbers bound: (master_key, indices) -> (summary, status, inputs,
    derivatives)."""
    numbers = program_numbers(campaign)
    return lambda master_key, indices: compiled(numbers, jax.random.key_data(master_key), indices)


def compile_chunk(campaign: Campaign, batch: int, wrt: tuple[str, ...] = ()) -> Callable:
    """``lower_chunk(campaign, batch)`` compiled (with derivatives with respect to ``wrt``: ``chunk_function``), the
    campaign's numbers bound: (master_key, indices) -> (summary, status, inputs, derivatives)."""
    return _bound(_chunk_program(campaign, batch, wrt).compiled(*_example_arguments(campaign, batch)), campaign)


COMPILED_KEPT = 4
"""Compiled chunk programs a process keeps (the most recently used): a Dask worker's successive
chunks and runs, a notebook's or a test's runs of campaigns of one structure, compile once."""

_compiled: OrderedDict[tuple[str, int, tuple[str, ...]], Callable] = OrderedDict()
_compile_lock = threading.Lock()


def compiled_chunk(campaign: Campaign, batch: int, wrt: tuple[str, ...] = ()) -> Callable:
    """``compile_chunk(campaign, batch, wrt)``, its program kept per process by the campaign's structure
    (``program.structure_fingerprint``), the batch and ``wrt``; one compilation at a time, whatever the process's
    threads."""
    key = structure_fingerprint(campaign), batch, wrt
    with _compile_lock:
        compiled = _compiled.pop(key, None) or _chunk_program(campaign, batch, wrt).compiled(
            *_example_arguments(campaign, batch))
        _compiled[key] = compiled  # the most recently used last
        while len(_compiled) > COMPILED_KEPT:
            _compiled.popitem(last=False)
    return _bound(compiled, campaign)


@dataclass
class ChunkResult:
    """Host arrays of one chunk (rows ``start .. start + len``): its outputs, drawn inputs, the time it took [s] and,
    in a run with derivatives, each differentiated output's derivatives (rows, inputs) and the ``MISMATCH``."""

    start: int
    outputs: dict[str, np.ndarray]
    inputs: dict[str, np.ndarray]
    seconds: float
    derivatives: dict[str, np.ndarray] = field(default_factory=dict)


def chunking(campaign: Campaign, chunk_size: int | None = None) -> tuple[int, int]:
    """(realizations per chunk, number of chunks) for ``chunk_size`` (default: the campaign's)."""
    n = campaign.config.n_realizations
    chunk_size = min(chunk_size or campaign.config.simulation.chunk_size, n)
    return chunk_size, -(-n // chunk_size)


def fly_chunk(compiled: Callable, campaign: Campaign, chunk_size: int, batch: int, index: int) -> ChunkResult:
    """Fly chunk ``index`` (rows ``index * chunk_size`` on) with ``compiled = compile_chunk(campaign, batch)``;
    ``seconds``: the time it took [s]."""
    n = campaign.config.n_realizations
    start = index * chunk_size
    indices = np.arange(start, start + batch, dtype=np.uint32)
    master_key = jax.random.key(campaign.config.seed)
    t0 = time.perf_counter()
    summary, status, drawn, derivatives = jax.block_until_ready(compiled(master_key, indices))
    keep = min(chunk_size, n - start)
    outputs = {k: np.asarray(v)[:keep] for k, v in summary.items()}
    outputs["status"] = np.asarray(status)[:keep]
    inputs = {k: np.asarray(v)[:keep] for k, v in drawn.items()}
    derivatives = {k: np.asarray(v)[:keep] for k, v in derivatives.items()}
    return ChunkResult(start, outputs, inputs, time.perf_counter() - t0, derivatives)


def run_chunks(campaign: Campaign, chunk_size: int | None = None, chunks: list[int] | None = None,
               wrt: tuple[str, ...] = ()):  # fmt: skip
    """Yield ``ChunkResult`` for each chunk index (all chunks by default), in order, with derivatives with respect
    to ``wrt`` (``chunk_function``).

    The first item yielded is the compile time [s] (a float, ~0 when this process compiled the
    campaign's chunk before); then one ChunkResult per chunk.
    """
    chunk_size, n_chunks = chunking(campaign, chunk_size)
    t0 = time.perf_counter()
    batch = batch_size(chunk_size)
    compiled = compiled_chunk(campaign, batch, wrt)
    yield time.perf_counter() - t0
    for c in range(n_chunks) if chunks is None else chunks:
        yield fly_chunk(compiled, campaign, chunk_size, batch, c)
