"""HDF5 result files (the output contract of docs/conventions.md), written so that a killed run loses
at most the chunks in flight and a resumed one never mixes two set-ups.

A run keeps its finished chunks in the folder ``<out>.partial/``: ``manifest.json`` (what the run is:
its set-up and that set-up's fingerprint, ``fingerprint.py``) and one ``chunk_<k>.h5`` per finished
chunk (its rows, the fingerprint, its index and first row, each dataset with a Fletcher-32 checksum),
each written under a temporary name, flushed to disk and renamed, so a chunk file that exists is
whole. ``finish()`` checks the chunks again and streams them, one at a time, into ``<out>`` (written
the same way) and removes the folder: a file at ``<out>`` is complete.
``ResultWriter(..., resume=True)`` reopens the folder of a killed run and checks every file in it
against the set-up given: a manifest of another set-up or edited by hand, a chunk of another set-up,
one renamed, truncated or damaged, or a file that is not the run's are refused in one line, and
nothing is overwritten.
A run that keeps trajectories (``rocketmc run --trajectories``) or derivatives (``rocketmc sensitivities``) says which
in its manifest (a resume must ask for the same) and writes them in ``finish()``, into the file before it is marked complete: a run killed while flying
them keeps its chunks and resumes to fly them again.
One run at a time writes a partial folder: the writer holds an exclusive lock (``flock``) on its ``run.lock`` from
the start to the end, which the system releases when the process ends, however it ends; a second run on the same
folder is refused in one line.
"""

from __future__ import annotations

import fcntl
import json
import re
from pathlib import Path

import h5py
import numpy as np

from ..runtime import __version__
from ..errors import RocketmcError
from ..files import replacing, replacing_hdf5
from ..sim.outputs import metric
from ..sim.state import Status
from .record import Campaign
from .fingerprint import differences, fingerprint, setup
from .flights import TRAJECTORY_RULE
from .derivatives import DIFFERENTIATED_OUTPUTS, LINEARITY_STEP, MISMATCH
from .runner import ChunkResult, chunking

MANIFEST = "manifest.json"
LOCK = "run.lock"
"""The partial folder's lock file: held (``flock``) by the run writing the folder."""
MANIFEST_FORMAT = 2
"""Version of the partial folder's layout: 2 since the set-up fingerprint (rocketmc 0.1)."""
CHUNK_FILE = re.compile(r"chunk_(\d{6})\.h5")
GROUPS = ("outputs", "inputs", "derivatives")
"""The groups of a chunk file and of the result file; "derivatives" only in a run with derivatives
(``rocketmc sensitivities``): each differentiated output's derivatives, (rows, inputs), and the linearity check's
mismatch, (rows, outputs)."""
TRAJECTORIES = "trajectories"
"""The result file's group of kept trajectories (``run --trajectories``), absent when none were asked for."""
DERIVATIVES_DESCRIPTION = (
    "each flight's derivatives of its outputs (attribute outputs, one dataset each, rows × inputs) with respect to "
    "its inputs (attribute wrt), its gusts and sensor errors held; NaN where the output is")
MISMATCH_DESCRIPTION = (
    "the linearity check per flight and output (columns: the group's outputs): the flights with every dispersed "
    f"input moved by ±{100 * LINEARITY_STEP:g} % of its spread against the derivatives' prediction, |half difference − J·d| / √Σ(J_k d_k)²; "
    "near 0 where the flight is smooth there, of order 1 where a discontinuity lies within the step")
SHOWN_DIFFERENCES = 4
"""Differing set-up fields a refusal names before '...'."""


class ResumeError(RocketmcError, ValueError):
    """A partial run that cannot be resumed (another set-up's, or damaged); one line."""


class WriteError(RocketmcError, OSError):
    """A chunk or the result file that could not be written (a full disk, a read-only folder); one
    line saying what is kept and how to complete the run."""


def partial_dir(out: Path) -> Path:
    return out.with_name(out.name + ".partial")


def _plural(n: int, what: str) -> str:
    return f"{n} {what}{'' if n == 1 else 's'}"


def _read_manifest(path: Path) -> dict:
    try:
        found = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError):
        raise ResumeError(f"{path.parent}: no readable {MANIFEST}, not a rocketmc partial run") from None
    if not isinstance(found, dict):
        raise ResumeError(f"{path}: not a rocketmc manifest")
    return found


class ResultWriter:
    """Writes one campaign's results: ``write(chunk, index)`` per finished chunk, then ``finish()``.

    ``trajectories``: the realizations whose trajectories the file keeps and their sample interval,
    ``{"realizations": [i, ...], "interval_s": s}`` (None: none), kept in the manifest.
    ``derivatives``: the inputs (dotted paths) the chunks' derivatives are taken with respect to (None: a run
    without derivatives), kept in the manifest.
    ``already_complete``: resuming found no partial folder but a complete result file at ``out`` of
    the same set-up, trajectories and derivatives, which is kept (``finish()`` does nothing)."""

    def __init__(self, out: str | Path, campaign: Campaign, chunk_size: int, resume: bool = False,
                 trajectories: dict | None = None, derivatives: list[str] | None = None):  # fmt: skip
        self.out = Path(out)
        self.dir = partial_dir(self.out)
        self.n = campaign.config.n_realizations
        self.chunk_size, self.n_chunks = chunking(campaign, chunk_size)
        self.setup = setup(campaign, self.chunk_size)
        self.overrides = campaign.overrides
        self.fingerprint = fingerprint(self.setup)
        self.manifest = {"format": MANIFEST_FORMAT, "fingerprint": self.fingerprint, "setup": self.setup}
        self.trajectories = trajectories
        if trajectories is not None:  # absent otherwise: the manifests of runs without trajectories are unchanged
            self.manifest["trajectories"] = trajectories
        self.derivatives = derivatives
        if derivatives is not None:
            self.manifest["derivatives"] = derivatives
        self.already_complete = False
        self._chunks: set[int] = set()  # indices of the chunks written and checked
        self._names: dict[str, set[str]] | None = None  # the datasets of every chunk, from the first checked
        if self.out.is_dir():
            raise WriteError(f"{self.out}: is a folder, expected a result file name")
        self._lock_file = None
        if resume:
            if not self.dir.exists() and self.out.is_file():
                self._check_complete_result()
                self.already_complete = True
                return
            self._lock()
            try:
                self._check_manifest(_read_manifest(self.dir / MANIFEST))
                for index in self._listed_chunks():
                    self._read_chunk(index)
                    self._chunks.add(index)
            except ResumeError:
                self.close()
                raise
        else:
            if self.dir.exists():
                self._lock()  # another run writing it is said first
                self.close()
                raise ResumeError(f"{self.dir}: a partial run is there already; resume it with --resume or delete it")
            try:
                self.dir.mkdir(parents=True)
                self._lock()
                with replacing(self.dir / MANIFEST) as path:
                    path.write_text(json.dumps(self.manifest, indent=1))
            except OSError as e:
                self.close()
                (self.dir / LOCK).unlink(missing_ok=True)
                if self.dir.is_dir() and not any(self.dir.iterdir()):
                    self.dir.rmdir()
                raise WriteError(f"{e.filename or self.dir}: could not start the run ({e.strerror or e})") from None

    def _lock(self) -> None:
        """Hold the partial folder's lock, or refuse in one line while another run holds it (no folder: nothing to
        hold, the checks that follow say so)."""
        if not self.dir.is_dir():
            return
        try:
            self._lock_file = open(self.dir / LOCK, "a")
        except OSError as e:
            raise WriteError(f"{self.dir / LOCK}: could not open ({e.strerror or e})") from None
        try:
            fcntl.flock(self._lock_file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self.close()
            raise ResumeError(f"{self.dir}: in use by another rocketmc run writing it; wait for that run to end (or "
                              "stop it), then --resume") from None  # fmt: skip

    def close(self) -> None:
        """Release the partial folder's lock (the end of the process releases it too)."""
        if self._lock_file is not None:
            self._lock_file.close()
            self._lock_file = None

    def _check_complete_result(self) -> None:
        """Resuming with no partial folder: ``out`` must be a complete result file of this set-up."""
        try:
            with h5py.File(self.out, "r") as f:
                complete, found = bool(f.attrs.get("complete", False)), f.attrs.get("fingerprint")
                kept = f.get(TRAJECTORIES)
                kept = None if kept is None else {"realizations": kept.attrs["realizations"].tolist(),
                                                  "interval_s": float(kept.attrs["interval_s"])}  # fmt: skip
                derived = f.get("derivatives")
                derived = None if derived is None else json.loads(derived.attrs["wrt"])
        except (OSError, KeyError):  # KeyError: a /trajectories group without what was asked for, not rocketmc's
            raise ResumeError(f"{self.out}: no partial run {self.dir.name} to resume, and not a result file") from None
        if not complete:
            raise ResumeError(f"{self.out}: no partial run {self.dir.name} to resume, and the file is incomplete")
        if found != self.fingerprint:
            raise ResumeError(f"{self.out}: complete already, from another set-up (or an older rocketmc); "
                              "nothing to resume")  # fmt: skip
        if kept != self.trajectories:
            raise ResumeError(f"{self.out}: complete already, keeping other trajectories than asked (--trajectories, "
                              "--trajectory-interval); nothing to resume")  # fmt: skip
        if derived != self.derivatives:
            raise ResumeError(f"{self.out}: complete already, with derivatives with respect to other inputs than asked "
                              "(--wrt); nothing to resume")  # fmt: skip

    def _check_manifest(self, found: dict) -> None:
        if found == self.manifest:
            return
        if found.get("format") != MANIFEST_FORMAT:
            raise ResumeError(f"{self.dir}: a partial run of another campaign or set-up, by another rocketmc "
                              f"version (manifest format {found.get('format', 1)!r}); not resumed, nothing overwritten")  # fmt: skip
        if not isinstance(found.get("setup"), dict) or found.get("fingerprint") != fingerprint(found["setup"]):
            raise ResumeError(f"{self.dir / MANIFEST}: edited or damaged (its fingerprint does not match its set-up); "
                              "not resumed, nothing overwritten")  # fmt: skip
        differing = [path.removeprefix("setup.") for path in differences(found, self.manifest) if path != "fingerprint"]
        shown = ", ".join(differing[:SHOWN_DIFFERENCES]) + (", ..." if len(differing) > SHOWN_DIFFERENCES else "")
        raise ResumeError(f"{self.dir}: a partial run of another campaign or set-up ({shown} differ); "
                          "not resumed, nothing overwritten")  # fmt: skip

    def _listed_chunks(self) -> list[int]:
        """Indices of the chunk files in the folder; anything there that is not the run's is refused
        (``finish`` would remove the folder)."""
        indices = []
        for path in sorted(self.dir.iterdir()):
            match = CHUNK_FILE.fullmatch(path.name)
            if path.name in (MANIFEST, LOCK) or (path.name.endswith(".writing") and path.is_file()):
                continue  # .writing: a write cut short by a kill, replaced when its chunk is written
            if match is None or not path.is_file():
                raise ResumeError(f"{path}: not a file of a rocketmc partial run; move it out of {self.dir.name} "
                                  "and resume")  # fmt: skip
            index = int(match.group(1))
            if index >= self.n_chunks:
                raise ResumeError(f"{path}: chunk {index} of a run of {self.n_chunks} chunks; not resumed")
            indices.append(index)
        return indices

    def _chunk_path(self, index: int) -> Path:
        return self.dir / f"chunk_{index:06d}.h5"

    def _rows(self, index: int) -> int:
        return min(self.chunk_size, self.n - index * self.chunk_size)

    def _read_chunk(self, index: int) -> dict[str, dict[str, np.ndarray]]:
        """Chunk ``index``'s ``{"outputs": {name: rows}, "inputs": {...}}``, read whole (checksums
        verified) and checked to be this run's: its fingerprint, index, first row and datasets."""
        path = self._chunk_path(index)
        try:
            with h5py.File(path, "r") as chunk:
                attrs = {k: chunk.attrs.get(k) for k in ("fingerprint", "chunk_index", "start")}
                data = {group: {name: ds[()] for name, ds in chunk.get(group, {}).items()} for group in GROUPS}
        except (OSError, KeyError, TypeError, ValueError) as e:
            raise ResumeError(f"{path}: unreadable (truncated or damaged: {str(e).splitlines()[0]}); delete it and "
                              "resume to fly that chunk again") from None  # fmt: skip
        if attrs["fingerprint"] != self.fingerprint:
            raise ResumeError(f"{path}: a chunk of another set-up; not resumed, nothing overwritten")
        if attrs["chunk_index"] != index or attrs["start"] != index * self.chunk_size:
            raise ResumeError(f"{path}: holds the rows of chunk {attrs['chunk_index']} (renamed or copied); "
                              "not resumed, nothing overwritten")  # fmt: skip
        names = {group: set(data[group]) for group in GROUPS}
        lengths = {len(values) for group in GROUPS for values in data[group].values()}
        if self._names is None:
            self._names = names
        if names != self._names or "status" not in names["outputs"] or lengths != {self._rows(index)}:
            raise ResumeError(f"{path}: its datasets differ from the run's (edited); not resumed, nothing overwritten")
        return data

    def completed_chunks(self) -> list[int]:
        """Indices of the chunks already written."""
        return sorted(self._chunks)

    def write(self, chunk: ChunkResult, chunk_index: int) -> None:
        """Commit one chunk: written whole or not at all."""
        path = self._chunk_path(chunk_index)
        try:
            with replacing_hdf5(path, libver="latest") as f:  # checksummed datasets stored compactly (HDF5 ≥ 1.10)
                f.attrs.update({"fingerprint": self.fingerprint, "chunk_index": chunk_index, "start": chunk.start})
                for group, data in zip(GROUPS, (chunk.outputs, chunk.inputs, chunk.derivatives)):
                    if not data and group == "derivatives":
                        continue
                    g = f.create_group(group)
                    for name, values in data.items():
                        g.create_dataset(name, data=values, fletcher32=True)
        except OSError as e:
            raise WriteError(f"{path}: could not write ({e.strerror or e}); the {_plural(len(self._chunks), 'chunk')} "
                             f"finished are kept in {self.dir}: free space and run the same command with --resume") from None  # fmt: skip
        self._chunks.add(chunk_index)

    def chunk_outputs(self, index: int, names) -> dict[str, np.ndarray]:
        """Some ``/outputs`` of a written chunk."""
        with h5py.File(self._chunk_path(index), "r") as chunk:
            return {name: chunk["outputs"][name][()] for name in names}

    def finish(self, n_rows: int | None = None, warnings=None, trajectories=None) -> Path:
        """Check the chunks and gather them into ``<out>`` (complete), then remove the partial folder.
        ``n_rows``: the realizations kept when a run stopped early (``--until-converged``), the first
        chunks' rows; ``warnings``: a function of the gathered file returning warning lines, kept in its
        ``warnings`` attribute (a JSON list) before the file is marked complete; ``trajectories``: with trajectories asked
        for, a function returning each kept flight's (record, samples before decimation), ``campaign.flights.
        trajectories``, written to ``/trajectories/<index>`` (one dataset per column with ``unit`` and ``description``;
        ``status``, ``status_message`` and ``samples`` as attributes) before the file is marked complete."""
        if self.already_complete:
            return self.out
        n = self.n if n_rows is None else n_rows
        needed = range(-(-n // self.chunk_size))
        missing = [index for index in needed if index not in self._chunks]
        if missing:
            raise ResumeError(f"{self.dir}: chunk(s) {', '.join(map(str, missing[:5]))} missing; resume to fly them")
        try:
            with replacing_hdf5(self.out) as f:
                config = self.setup["config"]
                f.attrs.update({
                    "campaign_name": config["name"], "seed": config["seed"], "n_realizations": n,
                    "chunk_size": self.chunk_size, "completed_chunks": np.asarray(needed, dtype=np.int64),
                    "rocketmc_version": __version__, "fingerprint": self.fingerprint,
                    "campaign_toml": self.setup["campaign_toml"],  # apart from the rest: an attribute holds ≤ 64 kB
                    "setup": json.dumps({k: v for k, v in self.setup.items() if k != "campaign_toml"}),
                    "overrides": json.dumps(self.overrides),
                })  # fmt: skip
                for group in GROUPS[:2]:
                    f.create_group(group)
                if self.derivatives is not None:
                    f.create_group("derivatives").attrs.update({
                        "wrt": json.dumps(self.derivatives), "outputs": json.dumps(list(DIFFERENTIATED_OUTPUTS)),
                        "description": DERIVATIVES_DESCRIPTION})  # fmt: skip
                for index in needed:  # each chunk checked again: it could have changed since it was written
                    start = index * self.chunk_size
                    for group, data in self._read_chunk(index).items():
                        for name, values in data.items():
                            values = values[: max(0, n - start)]
                            self._dataset(f, group, name, values, n)[start : start + len(values)] = values
                if self.trajectories is not None:
                    group = f.create_group(TRAJECTORIES)
                    group.attrs.update({"realizations": np.asarray(self.trajectories["realizations"], dtype=np.int64),
                                        "interval_s": self.trajectories["interval_s"]})  # fmt: skip
                    group.attrs["description"] = TRAJECTORY_RULE
                    for record, samples in trajectories():
                        g = group.create_group(str(record.realization), track_order=True)
                        g.attrs.update({"status": record.status, "status_message": Status(record.status).message,
                                        "samples": samples})  # fmt: skip
                        write_columns(g, record.series, record.columns)
                if warnings is not None:
                    f.attrs["warnings"] = json.dumps(warnings(f))
                f.attrs["complete"] = True
        except OSError as e:
            raise WriteError(f"{self.out}: could not write ({e.strerror or e}); all {_plural(len(needed), 'chunk')} are "
                             f"kept in {self.dir}: free space and run the same command with --resume") from None  # fmt: skip
        for path in [self.dir / MANIFEST, *map(self._chunk_path, self._chunks), self.dir / LOCK]:
            path.unlink()
        self.close()
        try:
            self.dir.rmdir()
        except OSError:  # a file put there since the checks: the user's, kept
            pass
        return self.out

    @staticmethod
    def _dataset(f: h5py.File, group: str, name: str, like: np.ndarray, n: int):
        g = f.require_group(group)
        if name not in g:
            fill = 0 if np.issubdtype(like.dtype, np.integer) else np.nan
            ds = g.create_dataset(name, shape=(n, *like.shape[1:]), dtype=like.dtype, fillvalue=fill)
            if group == "outputs":
                ds.attrs["unit"], ds.attrs["description"] = metric(name)
            if group == "derivatives" and name != MISMATCH:
                ds.attrs["unit"] = f"{metric(name).unit} per unit of each input (the group's wrt)"
                ds.attrs["description"] = f"derivatives of {name}: {metric(name).meaning}"
            if name == MISMATCH:
                ds.attrs["unit"], ds.attrs["description"] = "1", MISMATCH_DESCRIPTION
            if name == "status":
                ds.attrs["codes"] = json.dumps({str(int(s)): s.message for s in Status})
        return g[name]


def write_columns(group: h5py.Group, series, columns: dict) -> None:
    """Each column of the DataFrame ``series`` as a dataset of ``group`` (strings as bytes) with the ``unit`` and
    ``description`` of its ``Metric`` in ``columns``."""
    for name, m in columns.items():
        values = series[name].to_numpy()
        data = group.create_dataset(name, data=values.astype("S") if values.dtype == object else values)
        data.attrs.update({"unit": m.unit, "description": m.meaning})
