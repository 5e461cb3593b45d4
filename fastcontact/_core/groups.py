"""Rows of a call that share a fluid: the groups a per-fluid table serves.

The pressure-dependent viscosity engines tabulate per fluid (the Barus squeeze-out time
primitive per α E*, the O-ring tables per α E* or Roelands law); a call of several fluids is
served group by group where a group is large enough to pay for its table, or its table is
kept from an earlier call.
"""
from __future__ import annotations

import numpy as np

__all__ = ["row_groups"]


def row_groups(keys, min_rows, most, kept=()):
    """[(key, rows), ...]: the rows sharing one value of each array in ``keys`` (arrays of one
    value per row), for the groups of at least ``min_rows`` rows or whose key (a tuple of
    floats, one per array) is in ``kept``; the largest first, at most ``most``; ``rows``
    ascending. O(n) hashing (pandas.factorize), no sort of the rows."""
    import pandas as pd

    keys = [np.asarray(a) for a in keys]
    code = np.zeros(keys[0].size, dtype=np.int64)
    for a in keys:
        c = pd.factorize(a, use_na_sentinel=False)[0]
        code = pd.factorize(code * (int(c.max(initial=0)) + 1) + c)[0]
    if code.size == 0:
        return []
    counts = np.bincount(code)
    # factorize numbers groups in order of appearance: group g starts where the running
    # maximum of the codes first reaches g
    first = np.flatnonzero(np.diff(np.maximum.accumulate(code), prepend=-1) > 0)
    take = counts >= min_rows
    for k in kept:
        take |= np.logical_and.reduce([a[first] == v for a, v in zip(keys, k)])
    cand = np.flatnonzero(take)
    cand = cand[np.argsort(-counts[cand], kind="stable")][:most]
    return [(tuple(float(a[first[g]]) for a in keys), np.flatnonzero(code == g)) for g in cand]
