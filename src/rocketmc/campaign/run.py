"""Run a campaign into its HDF5 result file: the one run loop that ``rocketmc run``, the notebook and Python users
call (``run_campaign``).

The loop flies the chunks a partial run lacks (``runner.run_chunks`` on this machine, or its Dask twin), commits
each to the partial folder as it comes (``store.ResultWriter``), stops early once the 95 % ellipse's area has
converged when asked, flies the trajectories to keep, and gathers the file, which is complete only then. A run
killed at any point resumes with ``resume=True`` from the chunks it finished; realization i has the same bits
whatever the chunk size, the machine count or the resumes.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from ..errors import RocketmcError
from ..files import file_stem
from .checks import VALIDITY_OUTPUTS, outputs_validity_warnings, preflight_warnings
from ..ellipse import AreaConvergence
from .derivatives import check_inputs
from .flights import check_realization, trajectories
from .record import Campaign
from .runner import chunking, run_chunks
from .store import ResultWriter

MAX_TRAJECTORIES = 100
"""Most realizations whose trajectories a run keeps: with the default interval, 0.1 s, and the flights' longest
time (``simulation.max_time_s``, 300 s by default) each at most 3002 rows of 43 float64 columns (53 with a
controller) and the phase, ≤ 1.3 MB."""
TRAJECTORY_INTERVAL_S = 0.1
"""The kept trajectories' sample interval by default [s]."""


class RunWarning(UserWarning):
    """A warning about a campaign or its flights (stability, calibration, the motor, aerodynamic validity), kept in the
    result file's ``warnings`` attribute too."""


def _silent(line: str, transient: bool = False) -> None:
    """The default progress: nothing."""


def _warn(line: str) -> None:
    warnings.warn(" ".join(line.split()), RunWarning, stacklevel=4)  # the caller of run_campaign


def kept_trajectories(campaign: Campaign, realizations: Sequence[int]) -> list[int]:
    """``realizations`` ascending and once each, checked: at most ``MAX_TRAJECTORIES``, each one of the campaign's
    (a one-line RocketmcError naming ``--trajectories`` otherwise)."""
    kept = sorted(set(realizations))
    if len(kept) > MAX_TRAJECTORIES:
        raise RocketmcError(f"--trajectories: {len(kept)} realizations, at most {MAX_TRAJECTORIES} are kept")
    if kept:
        check_realization(campaign, kept[-1], "--trajectories")
    return kept


def run_campaign(campaign: Campaign, out: str | Path | None = None, *, chunk_size: int | None = None,
                 resume: bool = False, force: bool = False, until_converged_pct: float | None = None,
                 trajectories_of: Sequence[int] = (), trajectory_interval_s: float = TRAJECTORY_INTERVAL_S,
                 executor: Callable = run_chunks, progress: Callable[..., None] = _silent,
                 warn: Callable[[str], None] = _warn, derivatives_wrt: Sequence[str] = ()) -> Path:  # fmt: skip
    """Fly ``campaign`` and write its result file; returns its path (default: ``<campaign name>.h5``).

    chunk_size: realizations flown and committed together (default: the campaign's ``simulation.chunk_size``);
    resume: complete the partial run left in ``<out>.partial/`` (a complete file of the same set-up is kept);
    force: replace an existing result file; until_converged_pct: stop once the 95 % ellipse area's 95 % bootstrap
    interval is narrower than this percentage of it (the realizations flown so far are kept);
    trajectories_of: realizations whose time series the file keeps, decimated to ``trajectory_interval_s`` [s];
    executor: flies chunks, ``runner.run_chunks`` or ``distributed.run_chunks`` bound to a Dask client;
    progress(line, transient): progress lines (transient ones may be overwritten by the next);
    warn(line): the campaign's and the flights' warnings, and a resume with nothing left to fly (by default
    Python warnings of ``RunWarning``); derivatives_wrt: inputs (dotted paths, ``derivatives.check_inputs``) each
    flight's derivatives are taken with respect to, written to ``/derivatives`` (``runner.chunk_function``; the
    local executor only).
    Raises RocketmcError (one line) for what cannot be run or written; a killed run keeps its finished chunks.
    """
    cfg = campaign.config
    out = Path(out or f"{file_stem(cfg.name)}.h5")
    if out.is_file() and not (resume or force):
        raise RocketmcError(f"--out {out}: the file exists; use --resume to continue it or --force to replace it")
    chunk_size, n_chunks = chunking(campaign, chunk_size)
    kept = kept_trajectories(campaign, trajectories_of)
    asked = {"realizations": kept, "interval_s": trajectory_interval_s} if kept else None
    wrt = tuple(derivatives_wrt)
    if wrt:
        check_inputs(campaign, wrt)
        executor = functools.partial(executor, wrt=wrt)
    writer = ResultWriter(out, campaign, chunk_size, resume=resume, trajectories=asked,
                          derivatives=list(wrt) if wrt else None)  # fmt: skip
    try:
        if writer.already_complete:
            warn(f"{out}: complete already (the same campaign and options); nothing to resume")
            return out
        return _fly(campaign, writer, executor, until_converged_pct, kept, trajectory_interval_s, progress, warn)
    finally:
        writer.close()


def _fly(campaign: Campaign, writer: ResultWriter, executor: Callable, until_converged_pct: float | None,
         kept: list[int], interval_s: float, progress: Callable[..., None], warn: Callable[[str], None]) -> Path:  # fmt: skip
    """``run_campaign``'s loop once its writer holds the partial folder. The pre-flight checks run on a thread beside
    the compilation (which leaves a core idle); their warnings come once it is done, before the first flight."""
    pool = ThreadPoolExecutor(1)
    checks = pool.submit(preflight_warnings, campaign)
    pool.shutdown(wait=False)  # the thread ends with the checks
    cfg = campaign.config
    chunk_size, n_chunks = writer.chunk_size, writer.n_chunks
    done = set(writer.completed_chunks())
    todo = [c for c in range(n_chunks) if c not in done]
    progress(f"{cfg.name}: {cfg.n_realizations} realizations, seed {cfg.seed}, {n_chunks} chunk(s) of {chunk_size}"
             + (f"; resuming with {len(done)} done" if done else ""))  # fmt: skip
    if campaign.gnc_inputs is not None:
        from .gains import describe_reference

        progress(describe_reference(campaign.gnc_inputs.reference))
    flown, seconds, failed = 0, 0.0, 0
    convergence = None if until_converged_pct is None else AreaConvergence(until_converged_pct / 100.0)
    if convergence is not None:
        for index in sorted(done):
            convergence.add(writer.chunk_outputs(index, ("status", "impact_north_m", "impact_east_m")))
    runs = executor(campaign, chunk_size, chunks=todo) if todo and not (convergence and convergence.check()) else None
    try:
        compile_s = None if runs is None else next(runs)
        campaign_warnings = checks.result()
        for line in campaign_warnings:
            warn(line)
        if runs is not None:
            progress(f"compiled in {compile_s:.1f} s")
            for i, (index, chunk) in enumerate(zip(todo, runs)):
                writer.write(chunk, index)
                flown, seconds = flown + len(chunk.outputs["status"]), seconds + chunk.seconds
                failed += int((chunk.outputs["status"] != 0).sum())
                left = (len(todo) - i - 1) * seconds / (i + 1)
                progress(f"chunk {index + 1}/{n_chunks}: {flown} flights this run, {flown / seconds:.0f} flights/s, "
                         f"ETA {'≤ ' if convergence else ''}{left:.0f} s{f', {failed} not ok' if failed else ''}", True)  # fmt: skip
                if convergence is not None:
                    convergence.add(chunk.outputs)
                    if convergence.check():
                        break
    except KeyboardInterrupt:
        progress(f"interrupted: the chunks finished are kept in {writer.dir}; the same command with --resume "
                 "completes the run")  # fmt: skip
        raise
    finally:
        if runs is not None:
            runs.close()  # a cluster's chunks still in flight are cancelled
    n_rows = None
    if convergence is not None:
        n_rows = convergence.n
        state = "converged" if convergence.converged else f"not converged within the {cfg.n_realizations} allowed"
        progress(f"{state} at N = {n_rows}: the 95 % ellipse's area is {convergence.area_m2 / 1e6:.4g} km², its 95 % "
                 f"bootstrap interval {100 * convergence.width:.2f} % of it wide (target {until_converged_pct:g} %)")  # fmt: skip
    validity = []

    def kept_warnings(f):  # the gathered flights' validity, with the pre-flight warnings, in the file
        validity.extend(outputs_validity_warnings(campaign, {n: f["outputs"][n][()] for n in VALIDITY_OUTPUTS}))
        return campaign_warnings + validity

    rows = n_rows or cfg.n_realizations
    flown_kept, left = [i for i in kept if i < rows], [i for i in kept if i >= rows]
    if left:
        validity.append(f"--trajectories {','.join(map(str, left))}: beyond the {n_rows} realizations --until-converged "
                        "kept, so not in /trajectories")  # fmt: skip
    if flown_kept:
        progress(f"trajectories of realizations {', '.join(map(str, flown_kept))}, every {interval_s:g} s (compiling, "
                 "then flying each)")  # fmt: skip
    out = writer.finish(n_rows, kept_warnings, lambda: trajectories(campaign, flown_kept, interval_s))
    rate = f", {flown / seconds:.0f} flights/s after compilation" if seconds else ""
    progress(f"wrote {out} ({flown} flights flown in this run{rate})")
    for line in validity:
        warn(line)
    return out
