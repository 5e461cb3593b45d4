"""Kernel inputs as read-only, C-contiguous arrays: one compiled signature per kernel (private).

numba types an array by its dtype, layout *and* writability, and compiles a kernel once per
distinct type. The same squeeze-out call made with arrays a user built, with a column of a
pandas DataFrame (read-only under pandas' copy-on-write), with a ``np.broadcast_to`` view or
with tables read zero-copy from Parquet would otherwise compile the same kernel up to four
times — 50–120 s each for the fused squeeze-out kernels on two shared cores — and keep one
entry per signature in numba's on-disk cache. So every array a kernel only reads reaches it
as a read-only view (no copy where it already is C-contiguous of the right dtype: marking a
view read-only leaves its base writable); kernels write only into fresh output arrays.
tests/test_kernel_signatures.py checks that mixed inputs compile each kernel once.
"""
from __future__ import annotations

import numpy as np

__all__ = ["readonly", "readonly_fields"]


def readonly(a, dtype=np.float64) -> np.ndarray:
    """``a`` as a C-contiguous, read-only array of ``dtype`` (a view where no copy is needed)."""
    v = np.require(a, dtype=dtype, requirements="C").view()
    v.flags.writeable = False
    return v


def readonly_fields(rec):
    """The NamedTuple ``rec`` with each of its ndarray fields a :func:`readonly` view (same
    dtype); other fields (scalars) unchanged."""
    return rec._make(readonly(f, f.dtype) if isinstance(f, np.ndarray) else f for f in rec)
