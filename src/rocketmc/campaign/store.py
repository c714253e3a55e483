"""HDF5 result files (the output contract of docs/conventions.md), written so that a killed run loses
at most the chunks in flight.

A run keeps its finished chunks in the folder ``<out>.partial/``: ``manifest.json`` (what the run is:
campaign text, seed, N, chunk size) and one ``chunk_<k>.h5`` per finished chunk, each written under a
temporary name, flushed to disk and renamed, so a chunk file that exists is whole. ``finish()`` streams
the chunk files, one at a time, into ``<out>`` (written the same way) and removes the folder: a file at
``<out>`` is complete. ``ResultWriter(..., resume=True)`` reopens the folder of a killed run, refuses
one that belongs to another campaign, and reports which chunks are done.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import h5py
import numpy as np

from .. import __version__
from ..files import replacing
from ..sim.flight import Status, unit_of
from .config import Campaign
from .runner import ChunkResult


class ResumeError(ValueError):
    """A partial run that cannot be resumed (another campaign's, or damaged); one line."""


def partial_dir(out: Path) -> Path:
    return out.with_name(out.name + ".partial")


class ResultWriter:
    """Writes one campaign's results: ``write(chunk, index)`` per finished chunk, then ``finish()``."""

    def __init__(self, out: str | Path, campaign: Campaign, chunk_size: int, resume: bool = False):
        self.out = Path(out)
        self.dir = partial_dir(self.out)
        cfg = campaign.config
        self.n = cfg.n_realizations
        self.manifest = {"campaign_name": cfg.name, "campaign_toml": campaign.text, "seed": cfg.seed,
                         "n_realizations": self.n, "chunk_size": chunk_size}  # fmt: skip
        manifest_path = self.dir / "manifest.json"
        if resume:
            try:
                found = json.loads(manifest_path.read_text())
            except (OSError, ValueError):
                raise ResumeError(f"{self.dir}: no readable manifest.json, not a rocketmc partial run") from None
            differing = [k for k, v in self.manifest.items() if found.get(k) != v]
            if differing:
                raise ResumeError(f"{self.dir}: a partial run of another campaign or set-up ({', '.join(differing)} "
                                  "differ); not resumed, nothing overwritten")  # fmt: skip
        else:
            if self.dir.exists():
                raise ResumeError(f"{self.dir}: a partial run is there already; resume it with --resume or delete it")
            self.dir.mkdir(parents=True)
            with replacing(manifest_path) as path:
                path.write_text(json.dumps(self.manifest, indent=1))

    def _chunk_path(self, index: int) -> Path:
        return self.dir / f"chunk_{index:06d}.h5"

    def completed_chunks(self) -> list[int]:
        """Indices of the chunks already written."""
        return sorted(int(p.stem.removeprefix("chunk_")) for p in self.dir.glob("chunk_*.h5"))

    def write(self, chunk: ChunkResult, chunk_index: int) -> None:
        """Commit one chunk: written whole or not at all."""
        with replacing(self._chunk_path(chunk_index)) as path, h5py.File(path, "w") as f:
            f.attrs["start"] = chunk.start
            for group, data in (("outputs", chunk.outputs), ("inputs", chunk.inputs)):
                g = f.create_group(group)
                for name, values in data.items():
                    g.create_dataset(name, data=values)

    def chunk_outputs(self, index: int, names) -> dict[str, np.ndarray]:
        """Some ``/outputs`` of a written chunk."""
        with h5py.File(self._chunk_path(index), "r") as chunk:
            return {name: chunk["outputs"][name][()] for name in names}

    def finish(self, n_rows: int | None = None) -> Path:
        """Gather the chunks into ``<out>`` (complete) and remove the partial folder. ``n_rows``: the
        realizations kept when a run stopped early (``--until-converged``), the first chunks' rows."""
        n = self.n if n_rows is None else n_rows
        done = [c for c in self.completed_chunks() if c * self.manifest["chunk_size"] < n]
        with replacing(self.out) as path, h5py.File(path, "w") as f:
            f.attrs.update({k: v for k, v in self.manifest.items()})
            f.attrs["n_realizations"] = n
            f.attrs["rocketmc_version"] = __version__
            f.attrs["completed_chunks"] = np.asarray(done, dtype=np.int64)
            f.create_group("outputs")
            f.create_group("inputs")
            rows = 0
            for index in done:
                try:
                    with h5py.File(self._chunk_path(index), "r") as chunk:
                        start = int(chunk.attrs["start"])
                        for group in ("outputs", "inputs"):
                            for name, ds in chunk[group].items():
                                values = ds[()]
                                self._dataset(f, group, name, values, n)[start : start + len(values)] = values
                        rows += len(chunk["outputs/status"])
                except (OSError, KeyError) as e:
                    raise ResumeError(f"{self._chunk_path(index)}: unreadable chunk ({e}); delete it and resume") from None
            if rows != n:
                raise ResumeError(f"{self.dir}: the chunks hold {rows} of {n} realizations")
            f.attrs["complete"] = True
        shutil.rmtree(self.dir)
        return self.out

    @staticmethod
    def _dataset(f: h5py.File, group: str, name: str, like: np.ndarray, n: int):
        g = f.require_group(group)
        if name not in g:
            fill = 0 if np.issubdtype(like.dtype, np.integer) else np.nan
            ds = g.create_dataset(name, shape=(n,), dtype=like.dtype, fillvalue=fill)
            if name == "status":
                ds.attrs["unit"] = "1"
                ds.attrs["codes"] = json.dumps({str(int(s)): s.message for s in Status})
            elif group == "outputs":
                ds.attrs["unit"] = unit_of(name)
        return g[name]
