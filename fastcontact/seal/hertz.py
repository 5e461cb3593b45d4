"""The O-ring fast path: a lazily built, verified table of the reduced resistance W.

:class:`HertzTable` (a flat record) holds ln W on a grid in (ln π_H, y) for p_b = 0 (see
:mod:`._hertz`); columns are solved on demand, cells verified at their centre against the
solver before use. Built per (tables, theory), cached on its :class:`SealContext`; a Barus
fluid's table (α̃ = α E*, p_b = 0: one α and one E* make W a function of (π_H, π_a) again)
the same way, per α̃, the solver run with that α̃; a Roelands fluid's per law (A, Z, p_r/E*).
"""
from __future__ import annotations

import math
import threading
from typing import NamedTuple

import numpy as np

from . import _hertz, _panels
from .context import RowsOut, panel_rule, solver_options

__all__ = ["HertzTable", "hertz_table", "table_W", "H1", "NY", "TABLE_TOL", "VERIFY_TOL"]

#: grid spacing in ln π_H, number of y intervals
H1 = 0.05
NY = 128
#: solver panel tolerance of the table nodes, and the verification tolerance (in ln W)
TABLE_TOL = 1e-7
VERIFY_TOL = 2e-7


class HertzTable(NamedTuple):
    """Flat record: ln W at ln π_H = t0 + k h1 (rows) and y = j/NY (columns).

    Attributes
    ----------
    t0, h1 : float
        Grid in ln π_H.
    lw : ndarray
        ln W (NaN where not built or the solver failed), shape (K, NY + 1).
    cell : ndarray of int8
        Cell state: 0 not checked, 1 verified, 2 failed (solver fallback).
    built : ndarray of bool
        Rows (π_H columns of the grid) solved.
    """

    t0: float
    h1: float
    lw: np.ndarray
    cell: np.ndarray
    built: np.ndarray


_LOCK = threading.Lock()


#: fluids (Barus α̃ = α E* > 0, or a Roelands law) whose O-ring tables a SealContext keeps
#: (the last asked)
PIEZO_TABLES = 4


def hertz_table(sc, al=0.0, vis=None):
    """The (empty, lazily filled) :class:`HertzTable` of a SealContext; ``al`` > 0: the table
    of a Barus fluid of reduced coefficient α̃ = α E* (η = η0 e^{α p_f}, p_b = 0: with one α and
    one E*, W is again a function of (π_H, π_a) alone); ``vis`` = (A, Z, π_r): a Roelands
    fluid's (the law of :mod:`fastcontact.flow.piezoviscosity`, π_r = p_r/E*); kept for the
    last PIEZO_TABLES fluids."""
    key = float(al) if vis is None else tuple(float(x) for x in vis)
    with _LOCK:
        if key == 0.0:
            if sc.hertz is None:
                sc.hertz = _empty_table(sc)
            return sc.hertz
        memo = sc.hertz_piezo
        if key in memo:
            memo[key] = memo.pop(key)  # most recent last
        else:
            memo[key] = _empty_table(sc)
            while len(memo) > PIEZO_TABLES:
                memo.pop(next(iter(memo)))
        return memo[key]


def _empty_table(sc):
    t0 = sc.rec.t_lo - 3.0
    K = int(math.ceil((math.log(sc.p_top) - t0) / H1)) + 1
    return HertzTable(t0, H1, np.full((K, NY + 1), np.nan), np.zeros((K, NY), dtype=np.int8),
                      np.zeros(K, dtype=np.bool_))


def _solve_W(sc, piH, pia, equal, al=0.0, vis=None):
    """W of (π_H, π_a) points (p_b = 0; Barus α̃ = ``al``, or the Roelands law ``vis``) with
    the table's tight solver settings."""
    o = solver_options(None)
    out = RowsOut.empty(piH.size)
    law = (np.zeros((piH.size, 0)) if vis is None
           else np.ascontiguousarray(np.tile(np.asarray(vis, dtype=np.float64), (piH.size, 1))))
    for sel, eq in ((~equal, False), (equal, True)):
        idx = np.flatnonzero(sel)
        if not idx.size:
            continue
        rule = panel_rule(o, tol=1e-9 if eq else TABLE_TOL, max_panels=256)
        _panels.solve_rows(sc.tab, sc.rec, rule, 0, np.zeros(2), np.zeros(2),
                           np.ascontiguousarray(piH), np.ascontiguousarray(pia),
                           np.zeros(piH.size), np.full(piH.size, float(al)), law,
                           idx.astype(np.int64), out)
    return np.where(out.status == _panels.ST_NEWTON_FAILED, np.nan, out.W)


def _build_rows(sc, ht, ks, al=0.0, vis=None):
    """Solve the grid rows ks (all y nodes)."""
    ks = np.asarray([k for k in ks if not ht.built[k]], dtype=np.int64)
    if not ks.size:
        return
    y = np.arange(NY + 1) / NY
    r = np.array([_hertz.ra_of_y(v) for v in y])
    r[0] = 1e-12                                   # dp → 0: the linear-response limit
    r[-1] = 1.0
    piH = np.repeat(np.exp(ht.t0 + ht.h1 * ks), NY + 1)
    rr = np.tile(r, ks.size)
    W = _solve_W(sc, piH, rr * piH, np.tile(np.arange(NY + 1) == NY, ks.size), al, vis)
    with np.errstate(divide="ignore", invalid="ignore"):
        ht.lw[ks] = np.log(W).reshape(ks.size, NY + 1)
    ht.built[ks] = True


def _verify_cells(sc, ht, kc, jc, al=0.0, vis=None):
    """Solve at the centres of cells (kc, jc) and compare with the interpolation."""
    piH = np.exp(ht.t0 + ht.h1 * (kc + 0.5))
    pia = piH * np.array([_hertz.ra_of_y((j + 0.5) / NY) for j in jc])
    W = _solve_W(sc, piH, pia, np.zeros(kc.size, dtype=bool), al, vis)
    est = np.empty(kc.size)
    _hertz.hertz_interp(ht, piH, pia, np.arange(kc.size, dtype=np.int64), True, est)
    with np.errstate(invalid="ignore", divide="ignore"):
        good = np.abs(est - np.log(W)) <= VERIFY_TOL
    ht.cell[kc, jc] = np.where(good, 1, 2)


def table_W(sc, piH, pia, rows, al=0.0, vis=None, max_solves=None):
    """W [-] of the rows (p_b = 0) from the table (of the Barus fluid α̃ = ``al`` > 0, or the
    Roelands law ``vis`` = (A, Z, π_r), one for every row); NaN where the solver must be
    used. ``max_solves``: None (and no table read) where completing the table for these rows
    — its grid rows still to build (NY + 1 solves each) and cells still to verify (one each) —
    would take more solver calls than that (e.g. than solving the rows themselves)."""
    ht = hertz_table(sc, al, vis)
    K = ht.lw.shape[0]
    t = np.log(piH[rows])
    k = np.floor((t - ht.t0) / ht.h1).astype(np.int64)
    y = np.array([_hertz.y_of(a, b) for a, b in zip(piH[rows], pia[rows])]) \
        if rows.size < 64 else _y_vec(piH[rows], pia[rows])
    j = np.clip((y * NY).astype(np.int64), 0, NY - 1)
    inside = (k >= 2) & (k <= K - 4)
    with _LOCK:
        cells = np.unique(k[inside] * NY + j[inside])
        kc, jc = cells // NY, cells % NY
        todo = ht.cell[kc, jc] == 0
        if todo.any():
            need = np.unique((kc[todo][:, None] + np.arange(-2, 4)[None, :]).ravel())
            need = need[(need >= 0) & (need < K)]
            if (max_solves is not None
                    and int((~ht.built[need]).sum()) * (NY + 1) + int(todo.sum()) > max_solves):
                return None
            _build_rows(sc, ht, need, al, vis)
            _verify_cells(sc, ht, kc[todo], jc[todo], al, vis)
    lnW = np.full(piH.size, np.nan)
    sel = rows[inside]
    _hertz.hertz_interp(ht, piH, pia, np.ascontiguousarray(sel, dtype=np.int64), False, lnW)
    return np.exp(lnW)


def _y_vec(piH, pia):
    q = np.maximum((piH - pia) / (2.0 * piH), 0.0)
    thp = 2.0 * np.arcsin(np.sqrt(q))
    return 1.0 - np.sqrt(np.maximum(2.0 * thp / np.pi, 0.0))
