"""Order of the work items of a parallel kernel whose costs vary smoothly along the input.

numba's ``prange`` hands each thread a contiguous block of the iteration space (the OpenMP and
workqueue layers schedule the blocks statically, whatever ``set_parallel_chunksize`` asks). A
table build's pressures are sorted, and the cost of one effective-medium σ̄ grows with the
pressure towards percolation (4 to 26 Gauss–Kronrod panels): the thread with the high-pressure
block finishes last. :func:`spread_order` permutes the items so that every contiguous block is
an even sample of the whole: on two threads, a refinement round of the synthetic road
spectrum's table build ran 1.2x faster than on one thread in sorted order and 1.85x in spread
order (bench/tables_results.md).
"""
from __future__ import annotations

import numpy as np

__all__ = ["spread_order"]


def spread_order(n):
    """A permutation of range(n) in van der Corput order (indices sorted by their bit-reversed
    value): any contiguous run of k entries samples the range with gaps of at most ~2n/k.
    The inverse permutation is ``np.argsort(order)``; ``x[order]`` reorders an input."""
    n = int(n)
    if n <= 2:
        return np.arange(n)
    bits = int(n - 1).bit_length()
    i = np.arange(n, dtype=np.int64)
    r = np.zeros(n, dtype=np.int64)
    for b in range(bits):
        r |= ((i >> b) & 1) << (bits - 1 - b)
    return np.argsort(r, kind="stable")
