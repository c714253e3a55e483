"""HDF5 result files (the output contract of docs/architecture.md).

A run writes ``<out>.partial`` chunk by chunk, with ``complete = False`` and the list of finished
chunks in the root attributes; only when every chunk is in does it set ``complete = True`` and
rename the file to ``<out>``. A file that looks complete therefore is.
"""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np

from .. import __version__
from ..sim.flight import Status, unit_of
from .config import Campaign
from .runner import ChunkResult


def partial_path(out: Path) -> Path:
    return out.with_name(out.name + ".partial")


class ResultWriter:
    """Writes one campaign's results; use as a context manager, ``write(chunk)``, then ``finish()``."""

    def __init__(self, out: str | Path, campaign: Campaign, chunk_size: int):
        self.out = Path(out)
        self.path = partial_path(self.out)
        self.n = campaign.config.n_realizations
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.file = h5py.File(self.path, "w")
        attrs = self.file.attrs
        attrs["campaign_name"] = campaign.config.name
        attrs["campaign_toml"] = campaign.text
        attrs["rocketmc_version"] = __version__
        attrs["seed"] = campaign.config.seed
        attrs["n_realizations"] = self.n
        attrs["chunk_size"] = chunk_size
        attrs["completed_chunks"] = np.zeros(0, dtype=np.int64)
        attrs["complete"] = False
        self.file.create_group("outputs")
        self.file.create_group("inputs")

    def _dataset(self, group: str, name: str, like: np.ndarray):
        g = self.file[group]
        if name not in g:
            fill = 0 if np.issubdtype(like.dtype, np.integer) else np.nan
            ds = g.create_dataset(name, shape=(self.n,), dtype=like.dtype, fillvalue=fill)
            if name == "status":
                ds.attrs["unit"] = "1"
                ds.attrs["codes"] = json.dumps({str(int(s)): s.message for s in Status})
            elif group == "outputs":
                ds.attrs["unit"] = unit_of(name)
        return g[name]

    def write(self, chunk: ChunkResult, chunk_index: int) -> None:
        rows = slice(chunk.start, chunk.start + len(chunk.outputs["status"]))
        for group, data in (("outputs", chunk.outputs), ("inputs", chunk.inputs)):
            for name, values in data.items():
                self._dataset(group, name, values)[rows] = values
        done = self.file.attrs["completed_chunks"]
        self.file.attrs["completed_chunks"] = np.append(done, chunk_index)
        self.file.flush()

    def finish(self) -> Path:
        """Mark complete and move into place."""
        self.file.attrs["complete"] = True
        self.file.close()
        self.path.replace(self.out)
        return self.out

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.file.close()  # a no-op after finish(); leaves the .partial file on error
