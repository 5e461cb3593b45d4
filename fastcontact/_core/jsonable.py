"""JSON encoding of the values results and provenance carry (numpy scalars and arrays, paths,
records with ``to_dict()``): the ``default=`` hooks of :func:`json.dumps`."""
from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["json_default", "json_plain"]


def json_default(o):
    """Strict hook: numpy scalars and arrays, paths, tuples and records with ``to_dict()``;
    TypeError for anything else."""
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    if isinstance(o, tuple):
        return list(o)
    if hasattr(o, "to_dict"):
        return o.to_dict()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def json_plain(o):
    """Lenient hook for free-form provenance: as :func:`json_default`, else ``str(o)``."""
    try:
        return json_default(o)
    except TypeError:
        return str(o)
