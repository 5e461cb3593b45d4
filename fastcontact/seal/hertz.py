"""The O-ring fast path: lazily built, verified tables of the reduced resistance W.

W = ∫ dξ/σ̄ over the sealing zone (ξ = x/a; Lorenz & Persson 2010, eq. 33 with the Hertz
profile p0 = p_H √(1 − ((x − a)/a)²)) depends on π_H = p_H/E*, π_a = p_a/E* and π_b = p_b/E*
alone (q = Δp h_rms³/(12 η a W) [m²/s], h_rms [m], a [m]). Two tables (kernels in
:mod:`._hertz`):

* :class:`HertzTable`: ln W on a grid in (ln π_H, y) for p_b = 0 (:func:`table_W`);
* :class:`HertzPbTable`: ln W on a grid in (ln π_H, y, z) for p_b > 0 (:func:`table_W_pb`),
  z = y(π_b)/y(π_a) ∈ [0, 1] on NZ = 24 uniform intervals (z ≈ p_b/p_a where p_a << p_H;
  z = 1 is dp → 0, the linear-response limit, solved at p_b = p_a (1 − 1e-12) as the p_b = 0
  table's y = 0 at p_a = 1e-12 p_H). Its grid lines (ln π_H, z) are solved on demand, all
  NY + 1 y nodes at once, and its planes allocated as first needed.

Both are filled only as far as the rows of a call need (grid rows, resp. lines, of the 6-point
stencils of their cells), every cell verified at its centre against the solver (VERIFY_TOL =
2e-7 in ln W) before use; cells that fail — next to lift-off and percolation, and for p_b > 0
where p_a and p_b both approach p_H (the zone shrinks to the peak; with NZ = 24 about 10 % of
the (y, z) cells, at p_a/p_H > 0.99) — go to the solver. Built per (tables, theory), kept on
the :class:`SealContext`; a Barus fluid's tables (α̃ = α E*, η = η0 e^{α(p_f − p_b)}: one α
and one E* make W a function of (π_H, π_a, π_b) again) the same way, per α̃, the solver run
with that α̃; a Roelands fluid's per law (A, Z, p_r/E*); the last PIEZO_TABLES fluids of each
kind of table are kept.

Barus O-rings whose fluids differ from row to row (a study over oils, each with too few rows
for a table of its own) read, for p_b = 0, one more table (:func:`table_W_beta`): ln W on a
grid in (ln π_H, y, b), b = α p_H = α̃ π_H ∈ [0, B_MAX] the third coordinate (the same record
and lazy, verified line-by-line filling as the p_b > 0 table); rows past B_MAX, and with
p_b > 0, are solved.
"""
from __future__ import annotations

import math
import threading
from typing import NamedTuple

import numpy as np

from . import _hertz, _panels
from .context import RowsOut, panel_rule, solver_options, spread_rows

__all__ = ["HertzTable", "hertz_table", "table_W", "HertzPbTable", "hertz_pb_table", "table_W_pb",
           "tabled_W", "hertz_beta_table", "table_W_beta", "H1", "NY", "NZ", "NB", "B_MAX",
           "TABLE_TOL", "VERIFY_TOL"]

#: grid spacing in ln π_H, number of y intervals
H1 = 0.05
NY = 128
#: solver panel tolerance of the table nodes, and the verification tolerance (in ln W)
TABLE_TOL = 1e-7
VERIFY_TOL = 2e-7


class HertzTable(NamedTuple):
    """Flat record: ln W for p_b = 0 at ln π_H = t0 + k h1 (rows) and y = j/NY (columns).

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
    return _kept(sc, "hertz", "hertz_piezo", al, vis, _empty_table)


def _kept(sc, base, piezo, al, vis, make):
    """The table ``make(sc)`` of a fluid kept on the SealContext: the base fluid's in the
    attribute ``base``, a Barus (α̃ = ``al`` > 0) or Roelands (``vis``) fluid's in the dict
    ``piezo`` (the last PIEZO_TABLES fluids asked, most recent last)."""
    key = float(al) if vis is None else tuple(float(x) for x in vis)
    with _LOCK:
        if key == 0.0:
            if getattr(sc, base) is None:
                setattr(sc, base, make(sc))
            return getattr(sc, base)
        memo = getattr(sc, piezo)
        if key in memo:
            memo[key] = memo.pop(key)  # most recent last
        else:
            memo[key] = make(sc)
            while len(memo) > PIEZO_TABLES:
                memo.pop(next(iter(memo)))
        return memo[key]


def _empty_table(sc):
    t0 = sc.rec.t_lo - 3.0
    K = int(math.ceil((math.log(sc.p_top) - t0) / H1)) + 1
    return HertzTable(t0, H1, np.full((K, NY + 1), np.nan), np.zeros((K, NY), dtype=np.int8),
                      np.zeros(K, dtype=np.bool_))


def _solve_W(sc, piH, pia, equal, al=0.0, vis=None, pib=None):
    """W of (π_H, π_a, π_b) points (``pib`` None: p_b = 0; Barus α̃ = ``al``, one or per point,
    or the Roelands law ``vis``) with the table's tight solver settings; ``equal``: the points at the lift-off
    equality p_a = p_H (panel tolerance 1e-9)."""
    pib = np.zeros(piH.size) if pib is None else np.ascontiguousarray(pib, dtype=np.float64)
    o = solver_options(None)
    alr = np.array(np.broadcast_to(np.asarray(al, dtype=np.float64), (piH.size,)))  # per point
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
                           pib, alr, law, spread_rows(idx), out)
    return np.where(out.status == _panels.ST_NEWTON_FAILED, np.nan, out.W)


def _build_rows(sc, ht, ks, al=0.0, vis=None):
    """Solve the grid rows ks (all y nodes)."""
    ks = np.asarray([k for k in ks if not ht.built[k]], dtype=np.int64)
    if not ks.size:
        return
    r = _r_nodes()
    piH = np.repeat(np.exp(ht.t0 + ht.h1 * ks), NY + 1)
    rr = np.tile(r, ks.size)
    W = _solve_W(sc, piH, rr * piH, np.tile(np.arange(NY + 1) == NY, ks.size), al, vis)
    with np.errstate(divide="ignore", invalid="ignore"):
        ht.lw[ks] = np.log(W).reshape(ks.size, NY + 1)
    ht.built[ks] = True


def _r_nodes():
    """r = p_a/p_H at the y nodes j/NY (r = 1e-12 at y = 0: dp → 0, the linear-response
    limit; 1 at y = 1, the lift-off equality)."""
    r = np.array([_hertz.ra_of_y(v) for v in np.arange(NY + 1) / NY])
    r[0] = 1e-12
    r[-1] = 1.0
    return r


def _verify_cells(sc, ht, kc, jc, al=0.0, vis=None):
    """Solve at the centres of cells (kc, jc) and compare with the interpolation."""
    piH = np.exp(ht.t0 + ht.h1 * (kc + 0.5))
    pia = piH * np.array([_hertz.ra_of_y((j + 0.5) / NY) for j in jc])
    est = np.empty(kc.size)
    _hertz.hertz_interp(ht, piH, pia, np.arange(kc.size, dtype=np.int64), True, est)
    ht.cell[kc, jc] = np.where(_verified(sc, piH, pia, None, est, al, vis), 1, 2)


def _verified(sc, piH, pia, pib, est, al, vis):
    """True where the interpolated ln W ``est`` at the points (π_H, π_a, π_b) is within
    VERIFY_TOL of the solver's."""
    W = _solve_W(sc, piH, pia, np.zeros(piH.size, dtype=bool), al, vis, pib)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.abs(est - np.log(W)) <= VERIFY_TOL


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


# =========================================================================== p_b > 0
#: intervals of the outlet coordinate z = y(π_b)/y(π_a) of the p_b > 0 table: measured on
#: the (y, z) cells at π_H = 1.1e-3, 0.01, 0.045 (critical junction and EMT), cells verified
#: 77–80 % (49 % at 0.045) with 16, 86 % with 20, 87–90 % with 24, 94 % with 32 intervals,
#: every cell below y = 0.6 (p_a/p_H < 0.97) with 24; a line costs NY + 1 = 129 solves
NZ = 24
#: z = 1 (dp → 0, the linear-response limit) is solved at p_b = p_a (1 − Z_TOP_GAP)
Z_TOP_GAP = 1e-12


class HertzPbTable(NamedTuple):
    """Flat record: ln W for p_b > 0 at ln π_H = t0 + k h1, z = m/NZ and y = j/NY.

    Grid rows k are stored as planes, allocated as they are first needed.

    Attributes
    ----------
    t0, h1 : float
        Grid in ln π_H.
    slot : ndarray of int64
        Plane of grid row k in ``lw``, ``cell`` and ``built`` (-1: none yet), shape (K,).
    lw : ndarray
        ln W (NaN where not built or the solver failed), shape (planes, NZ + 1, NY + 1).
    cell : ndarray of int8
        Cell state (planes, NZ, NY): 0 not checked, 1 verified, 2 failed (solver fallback).
    built : ndarray of bool
        Grid lines (k, z_m) solved (all NY + 1 y nodes), shape (planes, NZ + 1).
    """

    t0: float
    h1: float
    slot: np.ndarray
    lw: np.ndarray
    cell: np.ndarray
    built: np.ndarray


class _PbBox:
    """The :class:`HertzPbTable` of one fluid kept on a SealContext (``rec`` is replaced as
    planes are added)."""

    __slots__ = ("rec",)

    def __init__(self, sc, nz=NZ):
        t0 = sc.rec.t_lo - 3.0
        K = int(math.ceil((math.log(sc.p_top) - t0) / H1)) + 1
        self.rec = HertzPbTable(t0, H1, np.full(K, -1, dtype=np.int64),
                                np.zeros((0, nz + 1, NY + 1)),
                                np.zeros((0, nz, NY), dtype=np.int8),
                                np.zeros((0, nz + 1), dtype=np.bool_))


def hertz_pb_table(sc, al=0.0, vis=None):
    """The (lazily filled) :class:`HertzPbTable` holder of a SealContext for p_b > 0, keyed
    as :func:`hertz_table` (base; Barus α̃ = α E*, η = η0 e^{α(p_f − p_b)}; Roelands law
    (A, Z, π_r) about p_b): W depends on (π_H, π_a, π_b) alone for each."""
    return _kept(sc, "hertz_pb", "hertz_pb_piezo", al, vis, _PbBox)


def _ra(y):
    """:func:`._hertz.ra_of_y` of an array."""
    return np.sin(0.5 * np.pi * (1.0 - (1.0 - y) ** 2))


def _with_planes(ht, ks):
    """``ht`` with planes for the grid rows ks that have none."""
    new = np.unique(ks[ht.slot[ks] < 0])
    if not new.size:
        return ht
    slot = ht.slot.copy()
    slot[new] = ht.lw.shape[0] + np.arange(new.size)
    n = new.size
    nz = ht.cell.shape[1]
    return ht._replace(
        slot=slot, lw=np.concatenate((ht.lw, np.full((n, nz + 1, NY + 1), np.nan))),
        cell=np.concatenate((ht.cell, np.zeros((n, nz, NY), dtype=np.int8))),
        built=np.concatenate((ht.built, np.zeros((n, nz + 1), dtype=np.bool_))))


def _stencil_lines(kc, mc, nz=NZ):
    """Grid lines (k(nz + 1) + m) of the 6×6 (ln π_H, z) stencils of cells (kc, mc) of a
    table of nz intervals in its third coordinate."""
    ms = np.clip(mc - 2, 0, nz - 5)
    k = kc[:, None, None] + np.arange(-2, 4)[None, :, None]
    m = ms[:, None, None] + np.arange(6)[None, None, :]
    return np.unique((k * (nz + 1) + m).ravel())


def _unbuilt(ht, lines):
    """Number of the grid lines not solved yet."""
    n1 = ht.cell.shape[1] + 1
    return int((~_on_planes(ht.built, ht.slot[lines // n1], lines % n1)).sum())


def _on_planes(a, s, *idx):
    """a[s, *idx] where the plane s exists (s >= 0), else 0 (False)."""
    out = np.zeros(s.size, dtype=a.dtype)
    has = s >= 0
    out[has] = a[(s[has],) + tuple(i[has] for i in idx)]
    return out


def _lines_to_solve(ht, lines):
    """(``ht`` with planes for the grid lines, and of those not solved yet: grid row k, third
    coordinate's node m, plane s)."""
    n1 = ht.cell.shape[1] + 1
    kl, ml = lines // n1, lines % n1
    ht = _with_planes(ht, kl)
    s = ht.slot[kl]
    todo = ~ht.built[s, ml]
    return ht, kl[todo], ml[todo], s[todo]


def _store_lines(ht, s, ml, W):
    """Keep ln W of the solved lines (planes s, nodes ml; W of all NY + 1 y nodes each)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ht.lw[s, ml] = np.log(W).reshape(s.size, NY + 1)
    ht.built[s, ml] = True
    return ht


def _build_lines(sc, ht, lines, al=0.0, vis=None):
    """``ht`` with the grid lines solved (all y nodes; planes added as needed)."""
    ht, kl, ml, s = _lines_to_solve(ht, lines)
    if not kl.size:
        return ht
    r = _r_nodes()
    ya = np.array([_hertz.y_of(1.0, v) for v in r])     # the nodes' own y (r[0] = 1e-12)
    z = (ml / NZ)[:, None]
    rb = np.where(ml[:, None] == NZ, r * (1.0 - Z_TOP_GAP), _ra(z * ya[None, :]))
    piH = np.repeat(np.exp(ht.t0 + ht.h1 * kl), NY + 1)
    W = _solve_W(sc, piH, np.tile(r, kl.size) * piH,
                 np.tile(np.arange(NY + 1) == NY, kl.size), al, vis, rb.ravel() * piH)
    return _store_lines(ht, s, ml, W)


def _verify_pb_cells(sc, ht, kc, mc, jc, al=0.0, vis=None):
    """Solve at the centres of cells (kc, mc, jc) and compare with the interpolation."""
    piH = np.exp(ht.t0 + ht.h1 * (kc + 0.5))
    y = (jc + 0.5) / NY
    pia = piH * _ra(y)
    pib = piH * _ra((mc + 0.5) / NZ * y)
    est = np.empty(kc.size)
    _hertz.hertz_pb_interp(ht, piH, pia, pib, np.arange(kc.size, dtype=np.int64), True, est)
    ht.cell[ht.slot[kc], mc, jc] = np.where(_verified(sc, piH, pia, pib, est, al, vis), 1, 2)


def _pb_cells(ht, piH, pia, pib, rows):
    """(k, m, j): grid row, z cell and y cell of the rows (:func:`._hertz.pb_cells`)."""
    k, j, m = (np.empty(rows.size, dtype=np.int64) for _ in range(3))
    _hertz.pb_cells(ht, piH, pia, pib, np.ascontiguousarray(rows, dtype=np.int64), k, j, m)
    return k, m, j


def table_W_pb(sc, piH, pia, pib, rows, al=0.0, vis=None, max_solves=None):
    """W [-] of the rows with p_b > 0 (π_b = ``pib`` < π_a <= π_H) from the p_b > 0 table (of
    the base fluid, the Barus fluid α̃ = ``al`` > 0 or the Roelands law ``vis``); NaN where
    the solver must be used. As :func:`table_W`: the grid lines (k, z_m) the rows' cells need
    are solved (NY + 1 solves each) and the cells verified at their centre (one solve each)
    first; ``max_solves``: None (and no table read) where that would take more solves."""
    pib = np.ascontiguousarray(pib, dtype=np.float64)
    box = hertz_pb_table(sc, al, vis)
    with _LOCK:
        ht = box.rec
        k, m, j = _pb_cells(ht, piH, pia, pib, rows)
        inside = (k >= 2) & (k <= ht.slot.size - 4)
        cells = np.unique((k[inside] * NZ + m[inside]) * NY + j[inside])
        kc, mc, jc = cells // (NZ * NY), (cells // NY) % NZ, cells % NY
        todo = _on_planes(ht.cell, ht.slot[kc], mc, jc) == 0
        if todo.any():
            lines = _stencil_lines(kc[todo], mc[todo])
            if (max_solves is not None
                    and _unbuilt(ht, lines) * (NY + 1) + int(todo.sum()) > max_solves):
                return None
            ht = box.rec = _build_lines(sc, ht, lines, al, vis)
            _verify_pb_cells(sc, ht, kc[todo], mc[todo], jc[todo], al, vis)
    lnW = np.full(piH.size, np.nan)
    _hertz.hertz_pb_interp(ht, piH, pia, pib, np.ascontiguousarray(rows[inside], dtype=np.int64),
                           False, lnW)
    return np.exp(lnW)


def tabled_W(sc, piH, pia, pib, rows, zero, al=0.0, vis=None, budget_zero=False):
    """W [-] of O-ring rows below lift-off (π_a < π_H) from the verified tables of the fluid
    (base; Barus α̃ = ``al``; Roelands law ``vis``), NaN for the rows to solve; None where
    neither table is read. Rows with p_b = 0 (``zero``, per row of the call) from
    :func:`table_W` (``budget_zero``: only where completing it costs no more solves than those
    rows), rows with p_b > 0 from :func:`table_W_pb` where that holds."""
    piH, pia, pib = (np.ascontiguousarray(x, dtype=np.float64) for x in (piH, pia, pib))
    at0, back = rows[zero[rows]], rows[~zero[rows]]
    read = []
    if at0.size or not budget_zero:
        read.append((at0, table_W(sc, piH, pia, at0, al, vis,
                                  max_solves=at0.size if budget_zero else None)))
    if back.size:
        read.append((back, table_W_pb(sc, piH, pia, pib, back, al, vis, max_solves=back.size)))
    read = [(r, W) for r, W in read if W is not None]
    if not read:
        return None
    out = np.full(piH.size, np.nan)
    for r, W in read:
        out[r] = W[r]
    return out


# ===================================================== Barus, one α per row (p_b = 0)
#: the third coordinate of the O-ring table of Barus fluids given one per row: b = α p_H =
#: α̃ π_H on [0, B_MAX] in NB uniform intervals (Δb = 0.25). Measured at π_H = 2e-3, 0.01,
#: 0.04 and p_a/p_H = 1e-3 … 0.99 (critical junction): ln W is smooth in b, its 6-point
#: Lagrange interpolation within 7e-8 of the solver at every cell centre (5.6e-7 with
#: Δb = 0.5, 4e-6 with Δb = 0.67); past b ~ 5 the solver itself fails next to lift-off
B_MAX = 4.0
NB = 16


def hertz_beta_table(sc):
    """The (lazily filled) table holder of a SealContext for Barus O-rings with p_b = 0 and
    any α per row: ln W on a grid in (ln π_H, y, b/B_MAX), b = α p_H (a
    :class:`HertzPbTable` record with NB intervals in its third coordinate)."""
    return _kept(sc, "hertz_beta", None, 0.0, None, lambda c: _PbBox(c, NB))


def _build_beta_lines(sc, ht, lines):
    """``ht`` with the grid lines (k, b_m) solved (all y nodes; α̃ = b_m/π_H per line)."""
    ht, kl, ml, s = _lines_to_solve(ht, lines)
    if not kl.size:
        return ht
    r = _r_nodes()
    piHk = np.exp(ht.t0 + ht.h1 * kl)
    piH = np.repeat(piHk, NY + 1)
    al = np.repeat(ml / NB * B_MAX / piHk, NY + 1)
    W = _solve_W(sc, piH, np.tile(r, kl.size) * piH,
                 np.tile(np.arange(NY + 1) == NY, kl.size), al)
    return _store_lines(ht, s, ml, W)


def _verify_beta_cells(sc, ht, kc, mc, jc):
    """Solve at the centres of cells (kc, b cell mc, jc) and compare with the interpolation."""
    piH = np.exp(ht.t0 + ht.h1 * (kc + 0.5))
    pia = piH * _ra((jc + 0.5) / NY)
    z = (mc + 0.5) / NB
    est = np.empty(kc.size)
    _hertz.hertz_z_interp(ht, piH, pia, z, np.arange(kc.size, dtype=np.int64), True, est)
    ht.cell[ht.slot[kc], mc, jc] = np.where(
        _verified(sc, piH, pia, None, est, z * B_MAX / piH, None), 1, 2)


def table_W_beta(sc, piH, pia, al, rows, max_solves=None):
    """W [-] of Barus O-ring rows with p_b = 0 and one reduced coefficient α̃ = α E* per row
    (``al``), below lift-off (π_a < π_H), from the table of (π_H, π_a, b = α̃ π_H); NaN where
    the solver must be used (b > B_MAX, cells not verified). As :func:`table_W_pb`: the grid
    lines (k, b_m) the rows' cells need are solved (NY + 1 solves each) and the cells verified
    at their centre (one solve each) first; ``max_solves``: None (and no table read) where
    that would take more solves."""
    piH, pia = (np.array(x, dtype=np.float64) for x in (piH, pia))
    rows = np.array(rows, dtype=np.int64)
    z = np.zeros(piH.size)
    z[rows] = np.asarray(al, dtype=np.float64)[rows] * piH[rows] / B_MAX
    box = hertz_beta_table(sc)
    with _LOCK:
        ht = box.rec
        k, j, m = (np.empty(rows.size, dtype=np.int64) for _ in range(3))
        _hertz.z_cells(ht, piH, pia, z, rows, k, j, m)
        inside = (k >= 2) & (k <= ht.slot.size - 4) & (z[rows] <= 1.0)
        cells = np.unique((k[inside] * NB + m[inside]) * NY + j[inside])
        kc, mc, jc = cells // (NB * NY), (cells // NY) % NB, cells % NY
        todo = _on_planes(ht.cell, ht.slot[kc], mc, jc) == 0
        if todo.any():
            lines = _stencil_lines(kc[todo], mc[todo], NB)
            if (max_solves is not None
                    and _unbuilt(ht, lines) * (NY + 1) + int(todo.sum()) > max_solves):
                return None
            ht = box.rec = _build_beta_lines(sc, ht, lines)
            _verify_beta_cells(sc, ht, kc[todo], mc[todo], jc[todo])
    lnW = np.full(piH.size, np.nan)
    _hertz.hertz_z_interp(ht, piH, pia, z, rows[inside], False, lnW)
    return np.exp(lnW)
