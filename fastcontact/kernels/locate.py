"""Log grids as plain data and the O(1) interpolation kernels the integrators call.

A grid is the triple ``(log10_min, log10_max, n)``; node i sits at
``10**(log10_min + i (log10_max - log10_min)/(n - 1))``. The same triple is written to
the Parquet metadata. Kernels work in natural logs: ``ln x_i = ln_lo + i * dln``.

Every lookup reports whether its argument was inside the table (-1 outside); nothing is
extrapolated silently. (The quintic Hermite interpolant lives in :mod:`.hermite`.)

Inverse lookups (contact pressure from separation) use the same nodes: ln ū is monotone
on the pressure grid, and a uniform bucket map over -ln ū finds the interval in O(1).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ._index import clamp_index
from .hermite import quintic_interval  # noqa: F401  (re-export, old home)

__all__ = ["Grid", "quintic_interval", "build_bucket_map", "locate_desc", "locate_desc_from",
           "locate_asc"]

LN10 = math.log(10.0)


class Grid(NamedTuple):
    """A log grid ``(log10_min, log10_max, n)``."""

    log10_min: float
    log10_max: float
    n: int

    @property
    def ln_lo(self) -> float:
        """ln of the first node."""
        return self.log10_min * LN10

    @property
    def dln(self) -> float:
        """Node spacing in ln x."""
        return (self.log10_max - self.log10_min) * LN10 / (self.n - 1)

    def nodes(self) -> np.ndarray:
        """The n nodes 10**linspace(log10_min, log10_max, n)."""
        return 10.0 ** np.linspace(self.log10_min, self.log10_max, self.n)

    def ln_nodes(self) -> np.ndarray:
        """The n nodes in natural log, ln_lo + i dln."""
        return self.ln_lo + self.dln * np.arange(self.n)

    def to_list(self):
        """[log10_min, log10_max, n] as plain Python numbers (JSON metadata)."""
        return [float(self.log10_min), float(self.log10_max), int(self.n)]


def build_bucket_map(y_desc, n_buckets=None, ascending=False):
    """O(1) locator for a strictly decreasing array ``y_desc`` (e.g. ln ū on the p grid).

    Returns (lo, dz, idx): bucket b covers z in [lo + b dz, lo + (b+1) dz) with z = -y, and
    ``idx[b]`` is the first interval i (y_desc[i] >= y >= y_desc[i+1]) that can hold it.
    With ``ascending=True`` the array is increasing instead (z = y).
    """
    z = (1.0 if ascending else -1.0) * np.asarray(y_desc, dtype=np.float64)
    if np.any(np.diff(z) <= 0):
        raise ValueError("table column is not strictly monotone: cannot build an inverse")
    n = z.size
    nb = int(n_buckets or 4 * n)
    lo = float(z[0])
    dz = float((z[-1] - z[0]) / nb)
    edges = lo + dz * np.arange(nb)
    idx = np.searchsorted(z, edges, side="right") - 1
    idx = np.clip(idx, 0, n - 2).astype(np.int64)
    return lo, dz, np.ascontiguousarray(idx)


@njit(cache=True)
def locate_desc(y, y_desc, b_lo, b_dz, b_idx):
    """Interval i with y_desc[i] >= y >= y_desc[i+1] (-1 if y is outside the table)."""
    n = y_desc.size
    if y > y_desc[0] or y < y_desc[n - 1]:
        return -1
    i = b_idx[clamp_index(int((-y - b_lo) / b_dz), b_idx.size - 1)]
    while i < n - 2 and y_desc[i + 1] > y:
        i += 1
    return i


@njit(cache=True, inline="always")
def locate_desc_from(y, y_desc, b_lo, b_dz, b_idx, hint):
    """:func:`locate_desc`, first trying the interval ``hint`` (an earlier result, for a
    nearby y): taken where y_desc[hint] > y >= y_desc[hint+1], the one interval whose upper
    node lies strictly above y — the interval locate_desc's walk stops at — else located."""
    if 0 <= hint < y_desc.size - 1 and y_desc[hint] > y >= y_desc[hint + 1]:
        return hint
    return locate_desc(y, y_desc, b_lo, b_dz, b_idx)


@njit(cache=True)
def locate_asc(y, y_asc, b_lo, b_dz, b_idx):
    """Interval i with y_asc[i] <= y <= y_asc[i+1] (-1 if y is outside the table)."""
    n = y_asc.size
    if not (y_asc[0] <= y <= y_asc[n - 1]):
        return -1
    i = b_idx[clamp_index(int((y - b_lo) / b_dz), b_idx.size - 1)]
    while i < n - 2 and y_asc[i + 1] < y:
        i += 1
    return i
