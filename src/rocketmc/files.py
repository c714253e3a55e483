"""Writing files so that a reader never sees half of one."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path


@contextlib.contextmanager
def replacing(path):
    """Yields a temporary path next to ``path`` to write; moves it onto ``path`` (an atomic rename,
    after its bytes reach the disk) only on success."""
    path = Path(path)
    partial = path.with_name(path.name + ".writing")
    try:
        yield partial
        with open(partial, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)
