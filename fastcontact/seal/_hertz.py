"""Numba kernels: the tabulated O-ring resistance W(π_H, π_a, π_b) (private).

In reduced variables the Hertz soft seal depends on three groups only: π_H = p_H/E*,
r = p_a/p_H and p_b/p_H, W = ∫ dξ/σ̄ over the sealing zone (ξ = x/a; Lorenz & Persson 2010,
eq. 33). For p_b = 0, ln W is tabulated on a uniform grid in ln π_H and y, with
θ_s = (π/2)(1 − (1 − y)²) the angle of the zone start (r = sin θ_s): the quadratic map
resolves the lift-off end. For p_b > 0 a third coordinate z = y(π_b)/y(π_a) ∈ [0, 1] (the
outlet end's angle on the same map, relative to the inlet's: p_b/p_a where p_a << p_H, and
the outlet lift-off resolved as the inlet's; z = 1 is dp → 0). A case is a 6×6 (6×6×6)
Lagrange interpolation in (ln π_H, y) ((ln π_H, y, z)) inside a cell verified against the
solver; unverified cells (next to percolation or lift-off, or p_a and p_b both next to p_H)
go to the solver.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["ra_of_y", "y_of", "z_of", "hertz_interp", "pb_cells", "hertz_pb_interp", "z_cells",
           "hertz_z_interp"]


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


# --------------------------------------------------------------------------- p_b > 0
@njit(cache=True)
def z_of(piH, pia, pib):
    """Grid coordinate z = y(π_b)/y(π_a) ∈ [0, 1] of an outlet pressure 0 <= π_b <= π_a
    (y of :func:`y_of`: z ≈ p_b/p_a where p_a << p_H, and the outlet end's angle mapped as the
    inlet's next to lift-off)."""
    ya = y_of(piH, pia)
    if not ya > 0.0:
        return 0.0
    return min(y_of(piH, pib) / ya, 1.0)


@njit(cache=True)
def _start6(i, n):
    """First of the 6 stencil nodes of cell i on a line of n nodes."""
    return min(max(i - 2, 0), n - 6)


@njit(cache=True)
def _pb_cell(ht, t, y, z):
    """(k, j, m, x) of (ln π_H, y, z) in a :class:`~.hertz.HertzPbTable`: grid row k (x its
    fractional index), y cell j, z cell m; k = -1 outside the grid."""
    K = ht.slot.size
    J = ht.lw.shape[2] - 1
    NZ = ht.lw.shape[1] - 1
    x = (t - ht.t0) / ht.h1
    if not (x >= 0.0 and x < K - 1):
        return -1, 0, 0, x
    j = min(max(int(y * J), 0), J - 1)
    m = min(max(int(z * NZ), 0), NZ - 1)
    return int(math.floor(x)), j, m, x


@njit(cache=True, parallel=True)
def pb_cells(ht, piH, pia, pib, rows, k, j, m):
    """Grid row k (-1 outside), y cell j and z cell m of the rows listed (into k, j, m, in
    the order of ``rows``): the cells :func:`hertz_pb_interp` reads."""
    for jj in prange(rows.size):
        i = rows[jj]
        k[jj], j[jj], m[jj], _ = _pb_cell(ht, math.log(piH[i]), y_of(piH[i], pia[i]),
                                          z_of(piH[i], pia[i], pib[i]))


@njit(cache=True)
def _interp_pb_one(ht, t, y, z, force, w1, w2, w3):
    k, j, m, x = _pb_cell(ht, t, y, z)
    if k < 0:
        return math.nan
    s = ht.slot[k]
    if s < 0 or (not force and ht.cell[s, m, j] != 1):
        return math.nan
    J = ht.lw.shape[2] - 1
    NZ = ht.lw.shape[1] - 1
    ks = _start6(k, ht.slot.size)
    js = _start6(j, J + 1)
    ms = _start6(m, NZ + 1)
    _weights6(x - ks, w1)
    _weights6(y * J - js, w2)
    _weights6(z * NZ - ms, w3)
    acc = 0.0
    for a in range(6):
        sa = ht.slot[ks + a]
        if sa < 0:
            return math.nan
        plane = 0.0
        for c in range(6):
            row = 0.0
            for b in range(6):
                row += w2[b] * ht.lw[sa, ms + c, js + b]
            plane += w3[c] * row
        acc += w1[a] * plane
    return acc


@njit(cache=True, parallel=True)
def hertz_pb_interp(ht, piH, pia, pib, rows, force, lnW):
    """ln W of the rows listed from a :class:`~.hertz.HertzPbTable`: 6×6×6 Lagrange in
    (ln π_H, y, z) (NaN where the cell is not verified, unless ``force``)."""
    for jj in prange(rows.size):
        i = rows[jj]
        w1 = np.empty(6)
        w2 = np.empty(6)
        w3 = np.empty(6)
        lnW[i] = _interp_pb_one(ht, math.log(piH[i]), y_of(piH[i], pia[i]),
                                z_of(piH[i], pia[i], pib[i]), force, w1, w2, w3)


# ------------------------------------------------- a third coordinate given per row
@njit(cache=True, parallel=True)
def z_cells(ht, piH, pia, z, rows, k, j, m):
    """:func:`pb_cells` with the third coordinate ``z`` ∈ [0, 1] given per row (the Barus
    b/B_MAX of :func:`~.hertz.table_W_beta`)."""
    for jj in prange(rows.size):
        i = rows[jj]
        k[jj], j[jj], m[jj], _ = _pb_cell(ht, math.log(piH[i]), y_of(piH[i], pia[i]), z[i])


@njit(cache=True, parallel=True)
def hertz_z_interp(ht, piH, pia, z, rows, force, lnW):
    """:func:`hertz_pb_interp` with the third coordinate ``z`` given per row."""
    for jj in prange(rows.size):
        i = rows[jj]
        w1 = np.empty(6)
        w2 = np.empty(6)
        w3 = np.empty(6)
        lnW[i] = _interp_pb_one(ht, math.log(piH[i]), y_of(piH[i], pia[i]), z[i], force,
                                w1, w2, w3)
