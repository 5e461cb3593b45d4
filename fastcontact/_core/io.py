"""Atomic file writes: a temporary name in the target folder, then ``os.replace``.

A reader never sees a partial file, and a failed write leaves nothing behind.

    with atomic_path("out/tables.parquet") as tmp:
        pq.write_table(table, tmp)
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

__all__ = ["atomic_path", "write_bytes_atomic", "temp_beside", "publish"]


def temp_beside(path, suffix=".tmp"):
    """A new empty temporary file beside ``path`` (same folder, hidden name ``.<name>.*``),
    the folder created if needed; returns its name. :func:`publish` moves it into place."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    return tmp


def publish(tmp, path):
    """Give ``tmp`` the ordinary permissions (0666 less the umask, not mkstemp's 0600) and
    replace ``path`` with it atomically."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, path)


@contextlib.contextmanager
def atomic_path(path, suffix=".tmp"):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically
    (:func:`temp_beside`, :func:`publish`)."""
    tmp = temp_beside(path, suffix)
    try:
        yield tmp
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_bytes_atomic(path, data: bytes):
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(data)
    return Path(path)
