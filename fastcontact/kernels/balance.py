"""Order of the work items of a parallel kernel whose costs vary smoothly along the input.

numba's ``prange`` hands each thread a contiguous block of the iteration space (the OpenMP and
workqueue layers schedule the blocks statically, whatever ``set_parallel_chunksize`` asks). A
table build's pressures are sorted, and the cost of one effective-medium σ̄ grows with the
pressure towards percolation (4 to 26 Gauss–Kronrod panels): the thread with the high-pressure
block finishes last. :func:`spread_order` permutes the items so that every contiguous block is
an even sample of the whole: on two threads, a refinement round of the synthetic road
spectrum's table build ran 1.2x faster than on one thread in sorted order and 1.85x in spread
order (bench/tables_results.md). :func:`spread_blocks` is the same order built inside a kernel
(the squeeze-out kernels' blocks of cases: a study's rows sorted by pressure put every
quadrature fall-back row — trapped fluid, outside the primitive — on the last thread).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["spread_order", "spread_blocks"]


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


@njit(cache=True)
def spread_blocks(n):
    """:func:`spread_order` (n) built inside a kernel: the same permutation (int64), for a
    parallel loop over n blocks, ``for q in prange(n): b = order[q]``. The indices are
    emitted in the order of their bit-reversed values by enumerating those values (bit
    reversal is its own inverse), O(n) without a sort."""
    order = np.empty(max(n, 0), dtype=np.int64)
    if n <= 2:
        for i in range(n):
            order[i] = i
        return order
    bits = 0
    while (1 << bits) < n:  # (n - 1).bit_length()
        bits += 1
    k = 0
    for r in range(1 << bits):
        i = 0
        for b in range(bits):
            i |= ((r >> b) & 1) << (bits - 1 - b)
        if i < n:
            order[k] = i
            k += 1
    return order
