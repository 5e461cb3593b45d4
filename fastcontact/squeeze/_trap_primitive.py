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
(0.8–1.2e6 cases/s on two cores against 4–6e3 by quadrature: bench/trapped_results.md).
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

__all__ = ["TrapPrimitive", "TrapRows", "piece", "build", "measure_error", "empty", "trap_row", "trap_t", "trap_z",
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
#: trap pressure and it take the per-case quadrature)
S_MIN = math.log(1e-4)
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


@njit(cache=True)
def _h(tab, mp, x0, vb, lvb, z):
    """dT/d(-z): (v - v_trap)/(σ̄ (1 - π_c/π0)) at z = ln(v/v_trap - 1)."""
    return qk._dtdw(tab, mp, x0, vb, lvb + z)


@njit(cache=True)
def _dlnh(tab, mp, x0, vb, lvb, z, side):
    """d ln h/dz at z, fourth order: central (side 0), forward (side 1) or backward (-1)."""
    e = FD_Z
    if side == 0:
        a = math.log(_h(tab, mp, x0, vb, lvb, z - 2.0 * e))
        b = math.log(_h(tab, mp, x0, vb, lvb, z - e))
        c = math.log(_h(tab, mp, x0, vb, lvb, z + e))
        d = math.log(_h(tab, mp, x0, vb, lvb, z + 2.0 * e))
        return (a - 8.0 * b + 8.0 * c - d) / (12.0 * e)
    e = e * side
    f0 = math.log(_h(tab, mp, x0, vb, lvb, z))
    f1 = math.log(_h(tab, mp, x0, vb, lvb, z + e))
    f2 = math.log(_h(tab, mp, x0, vb, lvb, z + 2.0 * e))
    f3 = math.log(_h(tab, mp, x0, vb, lvb, z + 3.0 * e))
    f4 = math.log(_h(tab, mp, x0, vb, lvb, z + 4.0 * e))
    return (-25.0 * f0 + 48.0 * f1 - 36.0 * f2 + 16.0 * f3 - 3.0 * f4) / (12.0 * e)


@njit(cache=True)
def _panel(tab, mp, x0, vb, lvb, za, zb, glx, glw):
    """∫_{za}^{zb} h dz, one Gauss–Legendre panel."""
    hw = 0.5 * (zb - za)
    mid = 0.5 * (za + zb)
    acc = 0.0
    for j in range(glx.size):
        acc += glw[j] * _h(tab, mp, x0, vb, lvb, mid + hw * glx[j])
    return acc * hw


@njit(cache=True)
def _between(tab, mp, x0, vb, lvb, za, zb, zbreak, glx, glw):
    """∫_{za}^{zb} h dz with the panel broken at the breakpoints ``zbreak`` (ascending)
    inside it."""
    acc = 0.0
    a = za
    for q in range(zbreak.size):
        zq = zbreak[q]
        if zq <= a:
            continue
        if zq >= zb:
            break
        acc += _panel(tab, mp, x0, vb, lvb, a, zq, glx, glw)
        a = zq
    return acc + _panel(tab, mp, x0, vb, lvb, a, zb, glx, glw)


@njit(cache=True)
def _node(tab, mp, x0, vb, lvb, z, T, side, C, j, k):
    """Row j, node k of the upper piece's C: ln T and its z-derivatives from T and the
    integrand at z."""
    h = _h(tab, mp, x0, vb, lvb, z)
    dl = _dlnh(tab, mp, x0, vb, lvb, z, side)
    C[j, k, 0] = math.log(T)
    C[j, k, 1] = -h / T
    C[j, k, 2] = -h * dl / T - (h / T) ** 2


@njit(cache=True)
def _node_lin(tab, mp, x0, vb, lvb, z, T, side, C, j, k):
    """Row j, node k of the lower piece's C: T and its z-derivatives -h, -h d ln h/dz."""
    h = _h(tab, mp, x0, vb, lvb, z)
    C[j, k, 0] = T
    C[j, k, 1] = -h
    C[j, k, 2] = -h * _dlnh(tab, mp, x0, vb, lvb, z, side)


@njit(cache=True)
def _build_row(tab, mp, x0, vb, z_split, dz_lo, dz_hi, zbreak, glx, glw, C_lo, C_hi, j):
    """ln T and its z-derivatives at the z nodes of row j of both pieces (T summed downward
    from the closed-form tail above v_ext; the node z_split shared, its derivatives one-sided
    on each piece's side)."""
    lvb = math.log(vb)
    z_ext = math.log(mp.v_ext / vb - 1.0)
    T_prev = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
    z_prev = z_ext
    for k in range(C_hi.shape[1] - 1, -1, -1):
        z = z_split + k * dz_hi
        if z >= z_ext:
            T = qk._tail_int(mp.c, vb * one_plus_exp(z) + mp.d, math.inf)
        else:
            T = T_prev + _between(tab, mp, x0, vb, lvb, z, z_prev, zbreak, glx, glw)
            T_prev = T
            z_prev = z
        _node(tab, mp, x0, vb, lvb, z, T, 1 if k == 0 else 0, C_hi, j, k)
    top = C_lo.shape[1] - 1
    _node_lin(tab, mp, x0, vb, lvb, z_split, T_prev, -1, C_lo, j, top)
    for k in range(top - 1, -1, -1):
        z = z_split - (top - k) * dz_lo
        T_prev = T_prev + _between(tab, mp, x0, vb, lvb, z, z_prev, zbreak, glx, glw)
        z_prev = z
        _node_lin(tab, mp, x0, vb, lvb, z, T_prev, 0, C_lo, j, k)


@njit(parallel=True, cache=True)
def _build_kernel(tab, mp, x_trap, sn, vb, z_split, dz_lo, dz_hi, zbreak, glx, glw, C_lo,
                  C_hi):
    """Every row's z nodes (:func:`_build_row`)."""
    for j in prange(sn.size):
        _build_row(tab, mp, x_trap + math.exp(sn[j]), vb, z_split, dz_lo, dz_hi, zbreak, glx,
                   glw, C_lo, C_hi, np.int64(j))


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
    glx, glw = gauss_legendre(int(points))
    C_lo = np.empty((nx, n_lo + 1, 3))
    C_hi = np.empty((nx, n_hi + 2, 3))  # one node above v_ext: the top cell is all tail
    _build_kernel(tab, mp, x_trap, sn, vb, z_split, dz_lo, dz_hi, zbreak, glx, glw, C_lo, C_hi)
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
        info.update(measure_error(model, tp))
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


@njit(cache=True)
def trap_z(lo, hi, tr, st, vb, T):
    """z = ln(v/v_trap - 1) with T(x0, v) = T (-inf at and beyond the trap floor's T)."""
    if T <= math.exp(row_value_2(hi.C, st, 0)):
        return z_of_t_at(hi, st, vb, T, inverse_constants(hi, st))
    T = T - _lo_offset(lo, hi, st)  # above the lower piece's top node value from here
    T0, h0 = _lo_bottom(lo, st)
    if T >= T0:  # below the grid: T = T0 + h0 (1 - e^(z - z0)), solved in closed form
        r = -(T - T0) / h0
        return lo.z0 + math.log1p(r) if r > -1.0 else -math.inf
    return cell_root(lo, st, T)  # the lower piece's quintic is in T itself


@njit(cache=True)
def trap_row(tab, mp, lo, hi, tr, x0, vs_in, tg, tau, h, i, out):
    """Row i of a trapped case (x_lo <= x0 <= x_hi) from the trapped side's primitive: the
    same columns and statuses as the per-case quadrature (:func:`~._kernels.quad_case`)."""
    st = trap_stencil(lo, tr, x0)
    vb = math.exp(tr.lnvb)
    # v∞ and the default start from the tables, as the quadrature has them (ln v∞ falls by
    # ~15 over the rows' last unit of s: interpolated across rows it was off by up to 1e-3)
    vinf = math.exp(qk._lnv_of_lnp(tab, mp, x0))
    vs = vs_in
    if vs != vs:  # the default start: p_cont(v_start) = DEFAULT_P_START p0
        vs = math.exp(qk._lnv_of_lnp(tab, mp, x0 + mp.lnp_start))
    zs = math.log(vs / vb - 1.0) if vs > vb else -math.inf
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
    T_floor = trap_floor(lo, hi, st)
    Ts = trap_t(lo, hi, tr, st, vb, zs) if above else T_floor
    if vs == math.inf:
        Ts = 0.0
    t_trap = T_floor - Ts if above else 0.0
    out.t_trap[i] = tau * t_trap
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
    for k in range(out.U.shape[0]):
        tk = qk.reduced_time(tg.times[k, col], tau)
        if not above or tk == 0.0:
            out.U[k, i] = vs * h
        elif tk == math.inf or tk >= t_trap:
            out.U[k, i] = vb * h
        else:
            z = trap_z(lo, hi, tr, st, vb, Ts + tk)
            out.U[k, i] = min(vb * one_plus_exp(z), vs) * h
    out.status[i] = qk.ST_TRAPPED


# ------------------------------------------------------------------ error check
@njit(cache=True)
def _check_point(tab, mp, lo, hi, tr, x0, z, zbreak, glx, glw):
    """|T interpolated / T direct - 1| at (x0, z): the direct quadrature on panels of a
    quarter of the grid's spacing, broken at the tables' nodes."""
    lvb = tr.lnvb
    vb = math.exp(lvb)
    st = trap_stencil(lo, tr, x0)
    z_ext = math.log(mp.v_ext / vb - 1.0)
    T = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
    m = int(math.ceil((z_ext - z) / (0.25 * DZ_TRAP)))
    hw = (z_ext - z) / m
    for q in range(m):
        T += _between(tab, mp, x0, vb, lvb, z + q * hw, z + (q + 1) * hw, zbreak, glx, glw)
    return abs(trap_t(lo, hi, tr, st, vb, z) / T - 1.0)


@njit(parallel=True, cache=True)
def _check_kernel(tab, mp, lo, hi, tr, xm, zm, zbreak, glx, glw, err):
    """:func:`_check_point` at (xm[i], zm[i]) in parallel."""
    for i in prange(xm.size):
        err[i] = _check_point(tab, mp, lo, hi, tr, xm[i], zm[i], zbreak, glx, glw)


def measure_error(model, tp, n_x=48, order=12):
    """Max relative error of the interpolated T at cell centres (n_x row cells × every z cell
    of both pieces below v_ext) against direct quadrature."""
    rng = np.random.default_rng(0)
    sn = tp.lo.xn
    cells = np.unique(rng.integers(0, sn.size - 1, n_x))
    sm = 0.5 * (sn[cells] + sn[cells + 1])
    vb = math.exp(tp.rows.lnvb)
    z_ext = math.log(model.mp.v_ext / vb - 1.0)
    zc = np.concatenate([p.z0 + (np.arange(p.nz - 1) + 0.5) * p.dz for p in (tp.lo, tp.hi)])
    zc = zc[zc < z_ext]
    S, Z = np.meshgrid(sm, zc, indexing="ij")
    xm = np.ascontiguousarray(tp.rows.x_trap + np.exp(S.ravel()))
    err = np.empty(xm.size)
    glx, glw = gauss_legendre(order)
    _check_kernel(model.tab, model.mp, tp.lo, tp.hi, tp.rows, xm, np.ascontiguousarray(Z.ravel()),
                  _breakpoints(model, vb, tp.lo.z0, z_ext), glx, glw, err)
    return {"max_rel_err_T": float(np.max(err)), "checked_points": int(err.size)}
