"""The time primitive of the trapped side: films that stop above equilibrium, by interpolation.

Part of :mod:`fastcontact.squeeze.primitive`. Above the trap pressure (π0 > π_trap, the
nominal pressure at which the tables' σ̄ falls to the trap floor) the film drains towards
v_trap, the separation at which π_c = π_trap, not towards its equilibrium v∞ < v_trap
(Lorenz & Persson 2010, Sec. 3: the fluid is trapped once the non-contact area no longer
percolates; arXiv:1004.1037). The time from v_a down to v_b is again a difference of

    T(x0, v) = ∫_v^∞ dv' / (σ̄(π_c(v')) (1 - π_c(v')/π0)),      x0 = ln π0 > x_trap,

but the integrand no longer has the logarithmic singularity of the equilibrium: at v_trap
σ̄ = σ_trap > 0 and 1 - π_trap/π0 > 0, so T(x0, v_trap) is finite (t_trap, the time to reach
the trap floor: ∝ 1/σ_trap, "never drains" on any practical time scale). Its grid:

* z = ln(v/v_trap - 1), uniform, from Z_LO_TRAP (below it the integrand is e^z × its value
  there: T = T0 + h0 (1 - e^(z - z0)), T(v_trap) = T0 + h0) to the closed-form flat-film
  tail above v_ext. v_trap is the same for every row, so the tables' nodes (where their
  interpolants are only C², and the cubic continuation of σ̄ beyond the last open node
  begins) lie at the same z on every row: the node quadrature breaks its panels there.
* s = ln(x0 - x_trap), uniform: the rows' x0 dependence is 1/(1 - π_c/π0), ~ 1/(x0 - ℓ(v))
  for x0 → x_trap, smooth on a logarithmic scale of x0 - x_trap; 4-point Lagrange in s.

Two pieces meet at z_split, the z of the tables' last open node (where σ̄'s cubic continuation
to percolation begins and d ln σ̄/d ln π jumps): each is a :data:`~._primitive_eval.Primitive`
whose "x0" nodes are the s nodes, with ln κ = 0 and no slope below the grid. The upper piece
holds ln T (its evaluation t_of_zv and inverse z_of_t_at are the equilibrium side's code); the
lower one holds T itself (see :data:`TrapPrimitive`). A case's v∞ and default start come from
the tables (Newton, as the per-case quadrature has them), its times from a few interpolations
(0.8–1.3e6 cases/s on two cores against 4–6e3 by quadrature: bench/trapped_results.md).

Build: v_trap is the same on every row, so a z node is the same separation on every row and
only the factor 1/(1 - π_c/π0) of the integrand depends on x0: the tables are looked up once
per quadrature point and each row is a weighted sum over those points (~4 ms for ~200 rows ×
~400 nodes on two cores; its error check, which shares the same idea, ~5 ms).
"""
from __future__ import annotations

import functools
import math
import time as _clock
from collections import namedtuple

import numpy as np
from numba import njit, prange

from ..kernels.quadrature import gauss_legendre
from ..kernels.readonly import readonly_fields
from . import _kernels as qk
from ..kernels.hermite import quintic_unit
from ._primitive_eval import (Primitive, _cell, _index_map, cell_root, inverse_constants,
                              lagrange_denominators, one_plus_exp, row_value_2, stencil,
                              t_of_zv, z_of_t_at)

__all__ = ["TrapPrimitive", "TrapRows", "piece", "build", "measure_error", "empty", "trap_row",
           "trap_history_kernel", "trap_start", "trap_v_at", "trap_t", "trap_z", "trap_z_at",
           "trap_inverse_constants",
           "trap_floor", "trap_stencil", "S_MIN", "DS", "Z_LO_TRAP", "DZ_TRAP", "PANEL_POINTS"]

#: the trapped side's primitive: two :data:`~._primitive_eval.Primitive` pieces on the same
#: rows s = ln(x0 - x_trap), ``lo`` for z <= z_split (down to the grid's bottom and the
#: closed form below it; no flat-film tail: its v_ext is inf) and ``hi`` for z >= z_split (to
#: the closed-form tail above v_ext); x_trap; x_lo, x_hi the
#: x0 range served (x_lo > x_hi: none); lnvb = ln v_trap; z_split the z of the tables' last
#: open node (where σ̄'s cubic continuation to percolation begins: d ln σ̄/d ln π jumps, by
#: ~20x on the embedded road tables, so no interpolant may straddle it) or SPLIT_Z where that
#: node lies below the trap pressure. The lower piece holds T itself, not ln T: below the
#: kink T grows from T(z_split) by h dz per step while h/T reaches ~20 at z_split, so that
#: ln T = ln(T_split + h (z_split - z)) is singular ~0.05 above z_split (a quintic in ln T on
#: cells of 0.1 missed it by 3e-3), whereas T is as smooth as h; ln(T - A) with an offset A
#: moving that singularity away cancels ~20x between A and T (9e-7 after interpolation
#: across rows)
#: (kernels take the three records as separate arguments: numba's parallel loops do not pass
#: nested records)
TrapPrimitive = namedtuple("TrapPrimitive", "lo hi rows")
TrapRows = namedtuple("TrapRows", "x_trap x_lo x_hi lnvb z_split")

#: s = ln(x0 - x_trap) of the first row: rows from x0 = x_trap + e^S_MIN (cases between the
#: trap pressure and it take the per-case quadrature). 1e-8: p0 within 1e-6 % of the trap
#: pressure; closer, x0 - x_trap itself carries the rounding of x0 (~1e-16 |x0|) at more
#: than 1e-8 relative (times 1e-8 off the reference at 1.2e-8: 2.6e-9; until 2026-12-04 the
#: rows began at 1e-4, when the build cost ~50x more a row)
S_MIN = math.log(1e-8)
#: spacing of the rows in s
DS = 0.05
#: bottom of the z grid and the largest spacing of the two pieces (each piece's spacing
#: divides its range, so that z_split is a node of both)
Z_LO_TRAP = -30.0
DZ_TRAP = 0.1
#: z_split where the tables' last open node lies below the trap pressure (no kink)
SPLIT_Z = -10.0
#: Gauss–Legendre points per panel of the node quadrature (panels end at the z nodes and at
#: the tables' nodes)
PANEL_POINTS = 8
#: difference step (in z) of d ln h/dz at the nodes (fourth order; one-sided at z_split)
FD_Z = 1e-3


# ------------------------------------------------------------------ build
# On the trapped side every row has the same floor v_trap, so a z node is the same separation
# v on every row, and of the integrand h = (v - v_trap) / (σ̄(v) (1 - π_c(v)/π0)) only the
# factor 1/(1 - π_c/π0) depends on the row's x0 = ln π0. The tables are therefore looked up
# once per quadrature point (g = (v - v_trap)/σ̄ and ln π_c, :func:`_shared_kernel`), and a
# row is a weighted sum of g / (1 - e^(ln π_c - x0)) over those points (:func:`_row_sums`):
# ~20 ns a point instead of the tables' ~0.1-0.3 µs, for every row.


@njit(cache=True)
def _gap_points(st, zbreak, width, glx, glw, pz, pw, off):
    """Gauss–Legendre points of the gaps between consecutive stations ``st`` (descending):
    gap q = [st[q+1], st[q]] in ceil(length/width) equal panels (width = inf: one), each
    broken at the breakpoints ``zbreak`` (ascending) inside it. Writes the points pz, their
    weights pw (times the panel's half width) and off (gap q: points off[q] to off[q+1]);
    returns the number of points."""
    n = 0
    npt = glx.size
    for q in range(st.size - 1):
        off[q] = n
        za, zb = st[q + 1], st[q]
        m = 1 if width == math.inf else max(int(math.ceil((zb - za) / width)), 1)
        for p in range(m):
            a = za + (zb - za) * p / m
            b = za + (zb - za) * (p + 1) / m if p < m - 1 else zb
            for r in range(zbreak.size + 1):
                e = b
                if r < zbreak.size:
                    zq = zbreak[r]
                    if zq <= a:
                        continue
                    if zq < b:
                        e = zq
                hw = 0.5 * (e - a)
                mid = 0.5 * (a + e)
                for j in range(npt):
                    pz[n] = mid + hw * glx[j]
                    pw[n] = glw[j] * hw
                    n += 1
                if e == b:
                    break
                a = e
    off[st.size - 1] = n
    return n


def _points(st, zbreak, width, points):
    """(pz, pw, off) of :func:`_gap_points` (arrays sized to the points)."""
    glx, glw = gauss_legendre(int(points))
    gaps = -np.diff(st)
    m = np.ones(gaps.size) if width == math.inf else np.maximum(np.ceil(gaps / width), 1.0)
    cap = int((m.sum() + zbreak.size) * glx.size) + glx.size
    pz, pw = np.empty(cap), np.empty(cap)
    off = np.empty(st.size, dtype=np.int64)
    n = _gap_points(st, zbreak, float(width), glx, glw, pz, pw, off)
    return np.ascontiguousarray(pz[:n]), np.ascontiguousarray(pw[:n]), off


@njit(parallel=True, cache=True)
def _shared_kernel(tab, mp, lvb, z, g, lnp):
    """At each z = ln(v/v_trap - 1): g = (v - v_trap)/σ̄ (0 where σ̄ = 0, trapped) and ln π_c,
    the tables' part of the integrand, the same on every row."""
    vb = math.exp(lvb)
    for i in prange(z.size):
        e = math.exp(lvb + z[i])
        lp, sig = qk._state(tab, mp, vb + e)
        lnp[i] = lp
        g[i] = e / sig if sig > 0.0 else 0.0


@njit(cache=True, inline="always")
def _gap(x0, lnp, k):
    """1 - π_c/π0 at point k on the row x0 (floored at 1e-300 as the quadrature's)."""
    d = -math.expm1(lnp[k] - x0)
    return d if d > 1e-300 else 1e-300


@njit(cache=True)
def _row_sums(x0, g, lnp, pw, off, T_top, T):
    """T at the stations of one row: T_top at the first, then the sums of h = g/(1 - π_c/π0)
    over each gap's points added going down."""
    acc = T_top
    T[0] = acc
    for q in range(off.size - 1):
        s = 0.0
        for k in range(off[q], off[q + 1]):
            s += pw[k] * g[k] / _gap(x0, lnp, k)
        acc += s
        T[q + 1] = acc


#: offsets (in FD_Z steps) of a node's difference points: central (side 0; the fifth unused)
#: and one-sided (side ±1, times the side)
FD_CENTRAL = np.array([-2.0, -1.0, 1.0, 2.0, 0.0])
FD_ONE_SIDED = np.array([0.0, 1.0, 2.0, 3.0, 4.0])


@njit(cache=True)
def _node_slopes(side, g, lnp, dlg, dlp):
    """d ln g/dz and d ln π_c/dz at each node n, fourth order, from g and ln π_c at its
    difference points (row n of g and lnp; :data:`FD_CENTRAL`, :data:`FD_ONE_SIDED`)."""
    for n in range(side.size):
        s = side[n]
        a, b = g[n], lnp[n]
        if s == 0:
            dlg[n] = (math.log(a[0]) - 8.0 * math.log(a[1]) + 8.0 * math.log(a[2])
                      - math.log(a[3])) / (12.0 * FD_Z)
            dlp[n] = (b[0] - 8.0 * b[1] + 8.0 * b[2] - b[3]) / (12.0 * FD_Z)
        else:
            e = 12.0 * FD_Z * s
            dlg[n] = (-25.0 * math.log(a[0]) + 48.0 * math.log(a[1]) - 36.0 * math.log(a[2])
                      + 16.0 * math.log(a[3]) - 3.0 * math.log(a[4])) / e
            dlp[n] = (-25.0 * b[0] + 48.0 * b[1] - 36.0 * b[2] + 16.0 * b[3] - 3.0 * b[4]) / e


@njit(parallel=True, cache=True)
def _rows_kernel(x0s, pg, plnp, pw, off, T_ext, piece_of, k_of, station, T_tail, ng, nlnp,
                 dlg, dlp, C_lo, C_hi):
    """Every row's node data. Row j (x0 = x0s[j]): T at the stations (:func:`_row_sums`; the
    first, v_ext, T_ext), then at each node n its T (station[n], or T_tail[n] at and above
    v_ext), h = g/(1 - π_c/π0) and d ln h/dz = d ln g/dz + (π_c/π0) (d ln π_c/dz)/(1 - π_c/π0)
    (ln h = ln g - ln(1 - π_c/π0)) into piece_of[n] (0: upper, ln T; 1: lower, T) at
    node k_of[n]."""
    for j in prange(x0s.size):
        x0 = x0s[j]
        T = np.empty(off.size)
        _row_sums(x0, pg, plnp, pw, off, T_ext, T)
        for n in range(k_of.size):
            q = station[n]
            Tn = T[q] if q >= 0 else T_tail[n]
            d = _gap(x0, nlnp, n)
            h = ng[n] / d
            dl = dlg[n] + (1.0 - d) * dlp[n] / d
            k = k_of[n]
            if piece_of[n] == 0:
                C_hi[j, k, 0] = math.log(Tn)
                C_hi[j, k, 1] = -h / Tn
                C_hi[j, k, 2] = -h * dl / Tn - (h / Tn) ** 2
            else:
                C_lo[j, k, 0] = Tn
                C_lo[j, k, 1] = -h
                C_lo[j, k, 2] = -h * dl


def _shared(model, lvb, z):
    """(g, ln π_c) of :func:`_shared_kernel` at the points z (any shape)."""
    zf = np.ascontiguousarray(np.ravel(z), dtype=np.float64)
    g, lnp = np.empty(zf.size), np.empty(zf.size)
    _shared_kernel(model.tab, model.mp, float(lvb), zf, g, lnp)
    return g.reshape(np.shape(z)), lnp.reshape(np.shape(z))


def _nodes(z_split, dz_lo, n_lo, dz_hi, n_hi, z_ext):
    """The nodes of both pieces in station order: the upper piece's from its top down (side
    +1, forward, at z_split), the lower piece's from z_split (side -1) down. Returns z, side,
    piece (0 upper, 1 lower), k (node index in its piece), station (index into the stations,
    -1 at and above v_ext) and the stations (v_ext's z first, then every node below it, the
    z_split node once)."""
    zs, side, piece_of, k_of, station = [], [], [], [], []
    st = [z_ext]
    for k in range(n_hi + 1, -1, -1):
        z = z_split + k * dz_hi
        zs.append(z), side.append(1 if k == 0 else 0), piece_of.append(0), k_of.append(k)
        if z >= z_ext:
            station.append(-1)
        else:
            st.append(z)
            station.append(len(st) - 1)
    zs.append(z_split), side.append(-1), piece_of.append(1), k_of.append(n_lo)
    station.append(station[-1])
    for k in range(n_lo - 1, -1, -1):
        z = z_split - (n_lo - k) * dz_lo
        st.append(z)
        zs.append(z), side.append(0), piece_of.append(1), k_of.append(k)
        station.append(len(st) - 1)
    i64 = lambda a: np.asarray(a, dtype=np.int64)
    return (np.asarray(zs), i64(side), i64(piece_of), i64(k_of), i64(station),
            np.asarray(st))


def _breakpoints(model, vb, z0, z_ext):
    """z of the tables' nodes above v_trap and of the table top (ascending, inside the grid)."""
    v = np.exp(np.asarray(model.tab.lnu, dtype=np.float64))
    v = np.append(v, model.mp.v_top)
    v = v[v > vb * (1.0 + math.exp(z0))]
    z = np.log(v / vb - 1.0)
    return np.ascontiguousarray(np.unique(z[(z > z0) & (z < z_ext)]))


def _split(model, vb, z_ext):
    """z_split: the z of the tables' last open node if it lies above v_trap, else SPLIT_Z."""
    tab = model.tab
    n_open = int(tab.n_open)
    if 0 < n_open < tab.lnp.size:
        v = math.exp(float(tab.lnu[n_open - 1]))
        if v > vb:
            z = math.log(v / vb - 1.0)
            if Z_LO_TRAP + 1.0 < z < z_ext - 1.0:
                return z
    return SPLIT_Z


def piece(sn, z0, dz, C, v_ext, c, d):
    """One piece of a :data:`TrapPrimitive` on the s nodes ``sn`` (its node data C; v_ext,
    c, d of the closed-form tail; ln v∞ = 0, ln S = -inf, z_start = 0, ln κ = 0 unused)."""
    n = sn.size
    return readonly_fields(Primitive(sn, *_index_map(sn), lagrange_denominators(sn), float(z0),
                                     float(dz), C.shape[1], C, np.zeros(n), np.full(n, -math.inf),
                                     np.zeros(n), np.zeros(n), float(v_ext), float(c), float(d)))


@functools.lru_cache(maxsize=1)
def empty():
    """A :data:`TrapPrimitive` that serves nothing (tables without a trap, engines whose
    trapped rows take the per-case quadrature): the kernels take the same record types
    either way."""
    pr = piece(np.arange(4.0), Z_LO_TRAP, DZ_TRAP, np.zeros((4, 2, 3)), math.inf, 0.0, 0.0)
    return TrapPrimitive(pr, pr, readonly_fields(TrapRows(math.inf, math.inf,
                                                          -math.inf, 0.0, SPLIT_Z)))


def build(model, s_min=S_MIN, ds=DS, z_lo=Z_LO_TRAP, dz=DZ_TRAP, points=PANEL_POINTS,
          check=True):
    """The trapped side's primitive of ``model`` (a
    :class:`~fastcontact.squeeze.model.SqueezeModel` with a finite trap pressure). Returns
    ``(TrapPrimitive, info)``; ``info`` holds the grid, the build time and, with ``check``,
    the measured maximum relative error of T at cell centres against direct quadrature."""
    t0 = _clock.perf_counter()
    mp, tab = model.mp, model.tab
    x_trap = float(model.x_trap)
    if not (math.isfinite(x_trap) and x_trap + math.exp(s_min) < model.x_max):
        return empty(), {"rows": 0}
    s_hi = math.log(model.x_max - x_trap)
    nx = max(int(math.ceil((s_hi - s_min) / ds)) + 1, 4)
    sn = np.ascontiguousarray(np.linspace(s_min, s_hi, nx))
    vb = float(mp.v_trap)
    z_ext = math.log(mp.v_ext / vb - 1.0)
    z_split = _split(model, vb, z_ext)
    n_lo = int(math.ceil((z_split - z_lo) / dz))
    dz_lo = (z_split - z_lo) / n_lo
    n_hi = int(math.ceil((z_ext - z_split) / dz))
    dz_hi = (z_ext - z_split) / n_hi
    zbreak = _breakpoints(model, vb, z_lo, z_ext)
    lvb = math.log(vb)
    zn, side, piece_of, k_of, station, st = _nodes(z_split, dz_lo, n_lo, dz_hi, n_hi, z_ext)
    pz, pw, off = _points(st, zbreak, math.inf, points)
    fd = np.where(side[:, None] == 0, FD_CENTRAL[None, :], side[:, None] * FD_ONE_SIDED)
    # the tables once for every row: the quadrature points, the nodes, their difference points
    g, lnp = _shared(model, lvb, np.concatenate([pz, zn, (zn[:, None] + FD_Z * fd).ravel()]))
    n_p, n_n = pz.size, zn.size
    fg = np.ascontiguousarray(g[n_p + n_n:].reshape(n_n, -1))
    flnp = np.ascontiguousarray(lnp[n_p + n_n:].reshape(n_n, -1))
    dlg, dlp = np.empty(n_n), np.empty(n_n)
    _node_slopes(side, fg, flnp, dlg, dlp)
    T_tail = np.array([qk._tail_int(mp.c, vb * one_plus_exp(z) + mp.d, math.inf)
                       if q < 0 else math.nan for z, q in zip(zn, station)])
    T_ext = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
    C_lo = np.empty((nx, n_lo + 1, 3))
    C_hi = np.empty((nx, n_hi + 2, 3))  # one node above v_ext: the top cell is all tail
    _rows_kernel(np.ascontiguousarray(x_trap + np.exp(sn)), g[:n_p], lnp[:n_p], pw, off,
                 T_ext, piece_of, k_of, station, T_tail, np.ascontiguousarray(g[n_p:n_p + n_n]),
                 np.ascontiguousarray(lnp[n_p:n_p + n_n]), dlg, dlp, C_lo, C_hi)
    lo = piece(sn, z_split - n_lo * dz_lo, dz_lo, C_lo, math.inf, mp.c, mp.d)
    hi = piece(sn, z_split, dz_hi, C_hi, mp.v_ext, mp.c, mp.d)
    tp = TrapPrimitive(lo, hi, readonly_fields(TrapRows(x_trap, x_trap + math.exp(s_min),
                                                        float(model.x_max), math.log(vb),
                                                        float(z_split))))
    info = {"rows": int(nx), "nz_lo": int(n_lo + 1), "nz_hi": int(n_hi + 2),
            "s_min": float(s_min), "ds": float(ds), "z0": float(z_lo), "dz_lo": dz_lo,
            "dz_hi": dz_hi, "z_split": float(z_split), "breakpoints": int(zbreak.size),
            "build_seconds": _clock.perf_counter() - t0}
    if check:
        t1 = _clock.perf_counter()
        info.update(measure_error(model, tp))
        info["check_seconds"] = _clock.perf_counter() - t1
    return tp, info


# ------------------------------------------------------------------ evaluation
@njit(cache=True, inline="always")
def trap_stencil(lo, tr, x0):
    """The row stencil of x0 (x_lo <= x0 <= x_hi) on both pieces (the same rows)."""
    return stencil(lo, math.log(x0 - tr.x_trap))


@njit(cache=True, inline="always")
def _lo_bottom(lo, st):
    """(T0, h0) of the lower piece's bottom node: T and dT/d(-z) there."""
    j0, w0, w1, w2, w3 = st
    C = lo.C
    return (row_value_2(C, st, 0),
            -(w0 * C[j0, 0, 1] + w1 * C[j0 + 1, 0, 1] + w2 * C[j0 + 2, 0, 1]
              + w3 * C[j0 + 3, 0, 1]))


@njit(cache=True, inline="always")
def _lo_t(lo, st, z):
    """T of the lower piece at z <= z_split (its quintic in T; below the grid the closed
    form T0 + h0 (1 - e^(z - z0)))."""
    if z < lo.z0:
        T0, h0 = _lo_bottom(lo, st)
        return T0 - h0 * math.expm1(z - lo.z0)
    k = int((z - lo.z0) / lo.dz)
    if k > lo.nz - 2:
        k = lo.nz - 2
    t = (z - (lo.z0 + k * lo.dz)) / lo.dz
    y0, d0, s0, y1, d1, s1 = _cell(lo, st, k)
    return quintic_unit(t, lo.dz, y0, d0, s0, y1, d1, s1)[0]


@njit(cache=True, inline="always")
def _lo_offset(lo, hi, st):
    """What the lower piece adds to its combined T so that both pieces give the same T at
    z_split: the rows share T there, but the upper piece combines ln T across rows and the
    lower one T (they differ by the x0 interpolation error, ~1e-7 relative), and a T that
    rose by that much across z_split would make a time negative."""
    return math.exp(row_value_2(hi.C, st, 0)) - row_value_2(lo.C, st, lo.nz - 1)


@njit(cache=True, inline="always")
def trap_t(lo, hi, tr, st, vb, z):
    """T(x0, v) at z = ln(v/v_trap - 1) (z = -inf: v_trap itself, the trap floor's T)."""
    if z < tr.z_split:
        return _lo_t(lo, st, z) + _lo_offset(lo, hi, st)
    return t_of_zv(hi, st, vb, z, vb * one_plus_exp(z))


@njit(cache=True, inline="always")
def trap_floor(lo, hi, st):
    """T at v_trap: the bottom node's T0 plus the closed form below it, h0."""
    T0, h0 = _lo_bottom(lo, st)
    return T0 + h0 + _lo_offset(lo, hi, st)


@njit(cache=True, inline="always")
def trap_inverse_constants(lo, hi, st):
    """What :func:`trap_z_at` needs of the stencil st beyond T (computed once for many times of
    one case): T at z_split, the upper piece's :func:`~._primitive_eval.inverse_constants`,
    the lower piece's offset (:func:`_lo_offset`) and its bottom (T0, h0)."""
    T0, h0 = _lo_bottom(lo, st)
    return (math.exp(row_value_2(hi.C, st, 0)), inverse_constants(hi, st),
            _lo_offset(lo, hi, st), T0, h0)


@njit(cache=True)
def trap_z(lo, hi, tr, st, vb, T):
    """z = ln(v/v_trap - 1) with T(x0, v) = T (-inf at and beyond the trap floor's T)."""
    return trap_z_at(lo, hi, st, vb, T, trap_inverse_constants(lo, hi, st))


@njit(cache=True, inline="always")
def trap_z_at(lo, hi, st, vb, T, kc):
    """:func:`trap_z` with the stencil's :func:`trap_inverse_constants` ``kc`` given."""
    T_split, ic, off, T0, h0 = kc
    if T <= T_split:
        return z_of_t_at(hi, st, vb, T, ic)
    T = T - off  # above the lower piece's top node value from here
    if T >= T0:  # below the grid: T = T0 + h0 (1 - e^(z - z0)), solved in closed form
        r = -(T - T0) / h0
        return lo.z0 + math.log1p(r) if r > -1.0 else -math.inf
    return cell_root(lo, st, T)  # the lower piece's quintic is in T itself


@njit(cache=True, inline="always")
def trap_start(tab, mp, lo, hi, tr, x0, vs_in):
    """What every output of a trapped case (x_lo <= x0 <= x_hi) starts from: (stencil, v_trap,
    v∞, v_start, T at the start, T at the trap floor). v∞ and the default start (vs_in NaN)
    come from the tables, as the per-case quadrature has them (ln v∞ falls by ~15 over the
    rows' last unit of s: interpolated across rows it was off by up to 1e-3); a start at or
    below v_trap has T_start = T_floor."""
    st = trap_stencil(lo, tr, x0)
    vb = math.exp(tr.lnvb)
    vinf = math.exp(qk._lnv_of_lnp(tab, mp, x0))
    vs = vs_in
    if vs != vs:  # the default start: p_cont(v_start) = DEFAULT_P_START p0
        vs = math.exp(qk._lnv_of_lnp(tab, mp, x0 + mp.lnp_start))
    T_floor = trap_floor(lo, hi, st)
    if vs == math.inf:
        Ts = 0.0
    elif vs > vb:
        Ts = trap_t(lo, hi, tr, st, vb, math.log(vs / vb - 1.0))
    else:
        Ts = T_floor
    return st, vb, vinf, vs, Ts, T_floor


@njit(cache=True, inline="always")
def trap_v_at(lo, hi, st, vb, vs, Ts, T_floor, tk, kc):
    """v at the reduced time tk after the start (:func:`trap_start`'s values; kc the
    stencil's :func:`trap_inverse_constants`): the start at tk = 0 or where it lies at or
    below v_trap, v_trap from t_trap on (inf included)."""
    if not (vs > vb) or tk == 0.0:
        return vs
    if tk == math.inf or tk >= T_floor - Ts:
        return vb
    return min(vb * one_plus_exp(trap_z_at(lo, hi, st, vb, Ts + tk, kc)), vs)


@njit(cache=True)
def trap_row(tab, mp, lo, hi, tr, x0, vs_in, tg, tau, h, i, out):
    """Row i of a trapped case (x_lo <= x0 <= x_hi) from the trapped side's primitive: the
    same columns and statuses as the per-case quadrature (:func:`~._kernels.quad_case`)."""
    st, vb, vinf, vs, Ts, T_floor = trap_start(tab, mp, lo, hi, tr, x0, vs_in)
    if not (vs * h > vinf * h):  # at or below ū∞, compared as reported (SI)
        qk._nan_row(out, i, x0)
        out.u_inf[i] = vinf * h
        out.u_start[i] = vs * h
        out.status[i] = qk.ST_BELOW
        return
    out.u_inf[i] = vinf * h
    out.u_start[i] = vs * h
    out.u_trap[i] = vb * h
    out.flf[i] = -math.expm1(tr.x_trap - x0)
    out.t_relax[i] = math.nan
    above = vs > vb
    out.t_trap[i] = tau * (T_floor - Ts if above else 0.0)
    nr = tg.ratios.size
    for k in range(out.T.shape[0]):
        if k == 0:
            vt = 1.01 * vinf
        elif k <= nr:
            vt = tg.ratios[k - 1] * vinf
        else:
            vt = vinf + tg.dvs[k - 1 - nr]
        if vt >= vs:
            out.T[k, i] = 0.0
        elif vt <= vb or not above:
            out.T[k, i] = math.inf
        else:
            out.T[k, i] = tau * (trap_t(lo, hi, tr, st, vb, math.log(vt / vb - 1.0)) - Ts)
    col = i if tg.times.shape[1] > 1 else i - i
    if out.U.shape[0] > 0:
        kc = trap_inverse_constants(lo, hi, st)
        for k in range(out.U.shape[0]):
            tk = qk.reduced_time(tg.times[k, col], tau)
            out.U[k, i] = trap_v_at(lo, hi, st, vb, vs, Ts, T_floor, tk, kc) * h
    out.status[i] = qk.ST_TRAPPED


#: times per parallel block of :func:`trap_history_kernel`
HISTORY_BLOCK = 4096


@njit(parallel=True, cache=True)
def trap_history_kernel(tab, mp, lo, hi, tr, x0, vs_in, tau, h, t, u):
    """ū [m] of one trapped case (x_lo <= x0 <= x_hi, start vs_in [h_rms] or NaN: the
    default) at the times t [s] (any order; τ0 = tau [s]): the values of :func:`trap_row`'s
    ū at a time, one inversion per time, in parallel blocks (each a plain call: the start's
    constants, tuples of tuples, do not pass numba's parallel array analysis inline)."""
    nb = (t.size + HISTORY_BLOCK - 1) // HISTORY_BLOCK
    for b in prange(nb):
        _trap_history_block(tab, mp, lo, hi, tr, x0, vs_in, tau, h, t, u, b * HISTORY_BLOCK,
                            min(b * HISTORY_BLOCK + HISTORY_BLOCK, t.size))


@njit(cache=True)
def _trap_history_block(tab, mp, lo, hi, tr, x0, vs_in, tau, h, t, u, k0, k1):
    """Times k0 <= k < k1 of :func:`trap_history_kernel` (the start computed once a block,
    ~1 µs against the block's ~0.5 ms)."""
    st, vb, vinf, vs, Ts, T_floor = trap_start(tab, mp, lo, hi, tr, x0, vs_in)
    kc = trap_inverse_constants(lo, hi, st)
    for k in range(k0, k1):
        u[k] = trap_v_at(lo, hi, st, vb, vs, Ts, T_floor, qk.reduced_time(t[k], tau), kc) * h


# ------------------------------------------------------------------ error check
@njit(parallel=True, cache=True)
def _check_kernel(lo, hi, tr, xm, zc, pg, plnp, pw, off, T_ext, err):
    """|T interpolated / T direct - 1| on row xm[j] at the stations zc[1:] (descending; zc[0]
    at v_ext): the direct T summed down the stations' points (:func:`_row_sums`)."""
    vb = math.exp(tr.lnvb)
    for j in prange(xm.size):
        x0 = xm[j]
        T = np.empty(off.size)
        _row_sums(x0, pg, plnp, pw, off, T_ext, T)
        st = trap_stencil(lo, tr, x0)
        for q in range(1, off.size):
            err[j, q - 1] = abs(trap_t(lo, hi, tr, st, vb, zc[q]) / T[q] - 1.0)


def measure_error(model, tp, n_x=48, order=12):
    """Max relative error of the interpolated T at cell centres (n_x row cells × every z cell
    of both pieces below v_ext) against direct quadrature: panels of a quarter of the grid's
    spacing, broken at the tables' nodes, ``order`` points each."""
    rng = np.random.default_rng(0)
    sn = tp.lo.xn
    cells = np.unique(rng.integers(0, sn.size - 1, n_x))
    sm = 0.5 * (sn[cells] + sn[cells + 1])
    lvb = tp.rows.lnvb
    z_ext = math.log(model.mp.v_ext / math.exp(lvb) - 1.0)
    zc = np.concatenate([p.z0 + (np.arange(p.nz - 1) + 0.5) * p.dz for p in (tp.lo, tp.hi)])
    zc = np.concatenate([[z_ext], np.sort(zc[zc < z_ext])[::-1]])
    pz, pw, off = _points(zc, _breakpoints(model, math.exp(lvb), tp.lo.z0, z_ext),
                          0.25 * DZ_TRAP, order)
    g, lnp = _shared(model, lvb, pz)
    xm = np.ascontiguousarray(tp.rows.x_trap + np.exp(sm))
    err = np.empty((xm.size, zc.size - 1))
    _check_kernel(tp.lo, tp.hi, tp.rows, xm, np.ascontiguousarray(zc), g, lnp, pw, off,
                  qk._tail_int(model.mp.c, model.mp.v_ext + model.mp.d, math.inf), err)
    return {"max_rel_err_T": float(np.max(err)), "checked_points": int(err.size)}
