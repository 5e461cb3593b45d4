"""The load-balance property shared by the spread-order tests (not a reference: no physics)."""
from __future__ import annotations

import math

import numpy as np


def runs_sample_the_range(order, n, threads):
    """True if every run of a static split of ``order`` (positions in a sorted range(n)) into
    ``threads`` runs, as numba's parallel loop hands them to its threads, spans the range with
    gaps of at most ~2n/k (k the run's length)."""
    for run in np.array_split(np.asarray(order), threads):
        srt = np.sort(run)
        gap = 2 * math.ceil(n / run.size) + 1
        if not (srt[0] < gap and srt[-1] >= n - gap and np.diff(srt).max(initial=0) <= gap):
            return False
    return True
