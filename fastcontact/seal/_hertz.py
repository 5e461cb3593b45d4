"""Numba kernels: the tabulated O-ring resistance W(π_H, π_a) for p_b = 0 (private).

In reduced variables the Hertz soft seal depends on two groups only: π_H = p_H/E* and
r = p_a/p_H (p_b = 0), W = ∫ dξ/σ̄ over the sealing zone (ξ = x/a). ln W is tabulated on a
uniform grid in ln π_H and y, with θ_s = (π/2)(1 − (1 − y)²) the angle of the zone start
(r = sin θ_s): the quadratic map resolves the lift-off end. A case is a 6×6 Lagrange
interpolation in (ln π_H, y) inside a cell verified against the solver; unverified cells
(next to percolation or lift-off) go to the solver.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["ra_of_y", "y_of", "hertz_interp"]


@njit(cache=True)
def ra_of_y(y):
    """r = p_a/p_H at the grid coordinate y ∈ [0, 1]."""
    return math.sin(0.5 * math.pi * (1.0 - (1.0 - y) ** 2))


@njit(cache=True)
def y_of(piH, pia):
    """Grid coordinate y of (π_H, π_a), without cancellation next to lift-off."""
    q = max((piH - pia) / (2.0 * piH), 0.0)
    thp = 2.0 * math.asin(math.sqrt(q))          # π/2 − θ_s
    return 1.0 - math.sqrt(max(2.0 * thp / math.pi, 0.0))


@njit(cache=True)
def _weights6(u, w):
    """Lagrange weights of the nodes 0..5 at u."""
    d = (-120.0, 24.0, -12.0, 12.0, -24.0, 120.0)
    for a in range(6):
        p = 1.0
        for b in range(6):
            if b != a:
                p *= u - b
        w[a] = p / d[a]


@njit(cache=True)
def _interp_one(ht, t, y, force, w1, w2):
    K = ht.lw.shape[0]
    J = ht.lw.shape[1] - 1
    x = (t - ht.t0) / ht.h1
    k = int(math.floor(x))
    if k < 0 or k >= K - 1:
        return math.nan
    j = min(int(y * J), J - 1)
    if j < 0:
        return math.nan
    if not force and ht.cell[k, j] != 1:
        return math.nan
    ks = min(max(k - 2, 0), K - 6)
    js = min(max(j - 2, 0), J + 1 - 6)
    _weights6(x - ks, w1)
    _weights6(y * J - js, w2)
    acc = 0.0
    for a in range(6):
        row = 0.0
        for b in range(6):
            row += w2[b] * ht.lw[ks + a, js + b]
        acc += w1[a] * row
    return acc


@njit(cache=True, parallel=True)
def hertz_interp(ht, piH, pia, rows, force, lnW):
    """ln W of the rows listed (NaN where the cell is not verified, unless ``force``)."""
    for jj in prange(rows.size):
        i = rows[jj]
        w1 = np.empty(6)
        w2 = np.empty(6)
        lnW[i] = _interp_one(ht, math.log(piH[i]), y_of(piH[i], pia[i]), force, w1, w2)
