"""Writing files so that a reader never sees half of one, and naming them after labels."""

from __future__ import annotations

import contextlib
import io
import os
import re
from pathlib import Path

import h5py

FILE_STEM_CHARS = 100
"""Longest file stem derived from a label: well under the 255 bytes of a file name, leaving room
for suffixes such as ``.h5.partial``."""


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


class _WriteOnceFailed(io.RawIOBase):
    """An unbuffered file for HDF5's ``fileobj`` driver that keeps the first failed write's error
    (``error``) and from then on discards what it is given: HDF5 finishes and closes the file as if
    all went well, instead of raising at every object it flushes and closes after (printed as
    ignored exceptions when Python frees them), and the caller raises that error once."""

    def __init__(self, path: Path):
        self._file = open(path, "w+b", buffering=0)
        self.error: OSError | None = None

    def write(self, data) -> int:
        view = memoryview(data).cast("B")
        if self.error is None:
            try:
                written = 0
                while written < len(view):  # an unbuffered write may take part of what it is given
                    written += self._file.write(view[written:])
            except OSError as e:
                self.error = e
        return len(view)

    def truncate(self, size=None) -> int:
        if self.error is None:
            try:
                return self._file.truncate(size)
            except OSError as e:
                self.error = e
        return self.tell() if size is None else size

    def readinto(self, buffer) -> int:
        return self._file.readinto(buffer)

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        return self._file.seek(offset, whence)

    def tell(self) -> int:
        return self._file.tell()

    def readable(self) -> bool:
        return True

    def writable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def close(self) -> None:
        self._file.close()
        super().close()


@contextlib.contextmanager
def replacing_hdf5(path, **options):
    """An ``h5py.File`` to write in place of ``path`` (as ``replacing`` does), through a Python file
    object: a failed write (a full disk, a file-size limit) is one ``OSError``, raised after HDF5 has
    closed the file. With its own file driver, HDF5 raised again at close, printed its error stack
    and could crash. ``options``: those of ``h5py.File``."""
    with replacing(path) as partial:
        with _WriteOnceFailed(partial) as raw:
            with h5py.File(raw, "w", **options) as f:
                yield f
            if raw.error is not None:
                raise raw.error


def file_stem(label: str) -> str:
    """A file name stem for ``label`` (a campaign name): each run of ``..`` and of characters other
    than letters, digits, ``.``, ``_`` and ``-`` becomes one ``_``, a leading dot goes (no hidden
    file), at most ``FILE_STEM_CHARS`` characters; ``"campaign"`` if nothing is left."""
    stem = re.sub(r"(?:[^A-Za-z0-9._-]|\.\.)+", "_", label).lstrip(".")[:FILE_STEM_CHARS]
    return stem or "campaign"
