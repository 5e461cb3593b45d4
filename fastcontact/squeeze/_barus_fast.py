"""Barus squeeze-out and tire footprint on the time primitive (``method="fast"``).

Every case is a few interpolations: the base primitive T at the start and at each target,
and the Barus correction S of :mod:`._barus_primitive` at the same separations,
t = τ0 {T(ū) - T(ū_start) + α p0 [S(ū) - S(ū_start)]}; ū at the footprint exit by Newton on
the same two (:func:`~._barus_primitive.u_at_time`). Where the separation is the same function
of x0 for every case (the ratio targets v∞(1 + r) and the default start), S comes from per-call
row tables of its moments (:func:`barus_rows`): a polynomial in α p0 per case, no Taylor shift
of the series and no lookup in the correction table. Rows the tables do not serve this way
(outside the tables, p0 within 4.4 % of the trap pressure or beyond, α p0 > API_FAST) run the
per-case quadrature of :mod:`.viscosity` / :mod:`.tire_piezo` in the same pass.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import get_thread_id, njit, prange

from ..kernels.balance import spread_blocks
from ..kernels.borrow import borrowed

from ._barus_primitive import (BINOMIALS, K_MAX, BarusTable, s_at, s_cell, s_value,
                               series_order, shift, u_at_time)
from ._fastpath import BLOCK, ZTargets, _row_col, _target_time, row_targets, same_targets
from ._kernels import Cases, Quad
from ._kernels import _tail_int as qk_tail_int
from ._kernels import reduced_time
from ._primitive_eval import (Primitive, inverse_constants_ext, one_plus_exp, row_value,
                              stencil, t_of_z, tail_top)
from .tire_piezo import _BELOW as TIRE_BELOW
from .tire_piezo import _OK as TIRE_OK
from .tire_piezo import TireOut, _tire_case
from .viscosity import (ST_BELOW, ST_OK, BarusOut, BarusTargets, _case_head, _no_times,
                        _piezo_case, _rate_factor)

__all__ = ["squeeze_kernel", "tire_kernel", "ratio_rows", "BarusRows", "barus_rows"]

#: the Barus correction at the ratio targets and the default start, per row of the primitive
#: (:func:`barus_rows`): M (nx, nk + 1, K_MAX + 1) = c_m σ̄(v) M_m(v), M_m(v) = ∫_v^∞ (1 -
#: π_c/π0)^m dv'/σ̄ the m-th moment of S (S = Σ_m A^m c_m M_m), at the row's own separations
#: v = v∞ (1 + r1s[k]) (k < nk: t_star and the ratio targets) and its default start (k = nk);
#: LS (nx, nk + 1) = ln σ̄(v); Y (nx, nk + 1) = π_c(v)/π0
BarusRows = namedtuple("BarusRows", "M LS Y")
#: the records' types, by name in this module: numba's parfor lowering rebuilds the kernels'
#: argument types from the module globals
_RECORDS = (BarusRows, BarusTable, BarusOut, BarusTargets, Cases, Primitive, Quad, TireOut,
            ZTargets)


@njit(cache=True, inline="always")
def _served(pr, sc, c, cs, alpha, h, x_fast, i):
    """(x0, τ0 [s], A = α p0, K, stencil) of case i; K < 0: not served by the primitive."""
    x0, tau, inside = _case_head(cs, sc, h, i)
    A = alpha[i] * cs.p0[i]
    K = series_order(c, A)
    if not inside or x0 > x_fast:
        K = -1
    st = stencil(pr, x0) if K >= 0 else (-1, 0.0, 0.0, 0.0, 0.0)
    if st[0] < 0:
        K = -1
    return x0, tau, A, K, st


@njit(cache=True, inline="always")
def _row_S(sb, st, k, A, K):
    """S at column k of the rows ``sb`` (:data:`BarusRows`) for the stencil st: Σ_m A^m c_m
    M_m (Horner in A over the x0-combined moments; no Taylor shift), times 1/σ̄."""
    j0, w0, w1, w2, w3 = st
    M = sb.M
    acc = 0.0
    for m in range(K, -1, -1):
        acc = acc * A + (w0 * M[j0, k, m] + w1 * M[j0 + 1, k, m] + w2 * M[j0 + 2, k, m]
                         + w3 * M[j0 + 3, k, m])
    return acc * math.exp(-_row_col(sb.LS, st, k))


@njit(cache=True, inline="always")
def _start(pr, bt, sb, st, E, K, x0, A, vs_in, lnTs):
    """(v∞, v_start, z_start, T(start) or -1 (not computed yet), T(start) paired with the
    row-table targets, S(start), 1 - π_c/π0 at the start) of a served case; v_start <= v∞ is
    returned as is (the caller flags it). The default start's T and S come from the row
    tables ``lnTs`` and ``sb`` (as the base fast path's T), a given start's from t_of_z and
    s_value (the series coefficients E of the case's A needed)."""
    vinf = math.exp(row_value(pr.lnv, st))
    if vs_in != vs_in:
        zs = row_value(pr.zs, st)
        vs = vinf * one_plus_exp(zs)
        Ts_row = math.exp(row_value(lnTs, st))
        ks = sb.LS.shape[1] - 1
        return (vinf, vs, zs, -1.0, Ts_row, _row_S(sb, st, ks, A, K),
                1.0 - _row_col(sb.Y, st, ks))
    vs = vs_in
    if not (vs > vinf):
        return vinf, vs, math.nan, math.nan, math.nan, math.nan, math.nan
    if vs == math.inf:
        return vinf, vs, math.inf, 0.0, 0.0, 0.0, 1.0
    zs = math.log(vs / vinf - 1.0)
    Ts = t_of_z(pr, st, vinf, zs)
    Ss, ys = s_value(bt, E, K, x0, vs)
    return vinf, vs, zs, Ts, Ts, Ss, 1.0 - ys


@njit(cache=True, inline="always")
def _target_times(bt, pr, sb, st, E, K, x0, A, vinf, vs, zs, Ts, Ts_row, Ss, tau, zt, T, i):
    """Times [s] from the start to each target (t_star and the ratios × v∞, then v∞ + dv;
    ``zt`` the :data:`~._fastpath.ZTargets` of :func:`ratio_rows`) into column i; returns
    T(start) (computed here if a target needed it, else as given).

    The base part T(target) - T(start) is the base fast path's
    (:func:`~._fastpath._target_time`: row tables far below the start, the interpolant at
    both ends near it); the Barus part A [S(target) - S(start)]: S at a ratio target from the
    rows ``sb`` (:data:`BarusRows`), at a Δu target from the correction table (E needed)."""
    nr = zt.r1s.size
    for k in range(T.shape[0]):
        if zt.src[k] >= 0:  # the same target as an earlier one
            T[k, i] = T[zt.src[k], i]
            continue
        vt = vinf * (1.0 + (zt.r1s[k] if k < nr else zt.dvs[k - nr] / vinf))
        if vt >= vs:
            T[k, i] = 0.0
            continue
        S = _row_S(sb, st, k, A, K) if k < nr else s_at(bt, E, K, x0, vt, math.log(vt))[0]
        dt, Ts = _target_time(pr, st, vinf, vs, zs, Ts, Ts_row, tau, k, zt)
        T[k, i] = dt + tau * A * (S - Ss)
    return Ts


@njit(parallel=True, cache=True)
def squeeze_kernel(tab, sc, pr, bt, c, x_fast, cs, alpha, h, tg, zt, lnTs, sb, quad, out,
                   scratch):
    """Barus squeeze-out of every case (``cs`` :class:`~._kernels.Cases`, α [1/Pa] apart)
    into ``out`` (:data:`~.viscosity.BarusOut`): the primitive where it serves the case, else
    the per-case quadrature (``quad``). ``scratch`` (threads, K_MAX + 1): one row of series
    coefficients per thread. ``zt``, ``lnTs``, ``sb``: :func:`ratio_rows` of ``tg``.

    Blocks of :data:`~._fastpath.BLOCK` cases in parallel, each one call of
    :func:`_squeeze_block`: the case body is compiled as a plain function, outside numba's
    parfor passes (whose cost grows faster than the body: the body inline in this loop took
    ~60 s of compiling on 2 cores; a call per block costs nothing measurable), visited in
    :func:`~fastcontact.kernels.balance.spread_blocks` order (the per-case quadrature rows of
    a study sorted by pressure spread over the threads, as in :func:`~._fastpath.fast_kernel`)."""
    n = cs.p0.size
    order = spread_blocks((n + BLOCK - 1) // BLOCK)
    for q in prange(order.size):
        blk = order[q]
        _squeeze_block(tab, sc, pr, bt, c, x_fast, cs, alpha, h, tg, zt, lnTs, sb, quad, out,
                       scratch, blk * BLOCK, min(blk * BLOCK + BLOCK, n))


@njit(cache=True)
def _squeeze_block(tab, sc, pr, bt, c, x_fast, cs, alpha, h, tg, zt, lnTs, sb, quad, out,
                   scratch, b0, b1):
    """Cases b0 <= i < b1 of :func:`squeeze_kernel`.

    The records are borrowed here (:mod:`fastcontact.kernels.borrow`): each copy of a record
    into an inline helper would count references on every array in it (most of a case's time,
    contended between threads), and records reach this function from the parallel loop with
    their counts, whatever the caller of the loop passed."""
    (tab, sc, pr, bt, c, cs, alpha, tg, zt, lnTs, sb, quad, out, scratch) = borrowed(
        (tab, sc, pr, bt, c, cs, alpha, tg, zt, lnTs, sb, quad, out, scratch))
    T_out = out.T
    U_out = out.U
    u_inf = out.u_inf
    u_start = out.u_start
    tau0 = out.tau0
    g_start = out.g_start
    status = out.status
    times = tg.times
    us = cs.us
    # the series coefficients E (a Taylor shift, O(K²)) only where a given start, a Δu target
    # or a time needs S off the rows
    need_E = tg.dvs.size > 0 or times.size > 0
    T_ext = tail_top(pr)  # T at v_ext, the same for every case
    for i in range(b0, b1):
        x0, tau, A, K, st = _served(pr, sc, c, cs, alpha, h, x_fast, i)
        if K < 0:
            _piezo_case(tab, sc, cs, alpha, h, tg, quad, i, out)
            continue
        E = scratch[get_thread_id()]
        if need_E or us[i] == us[i]:
            shift(c, A, K, E)
        tau0[i] = tau
        vinf, vs, zs, Ts, Ts_row, Ss, ds = _start(pr, bt, sb, st, E, K, x0, A, us[i] / h, lnTs)
        u_inf[i] = vinf * h
        u_start[i] = vs * h
        if not (vs * h > vinf * h):  # a given start at or below ū∞ (as reported, SI)
            _no_times(out, i, np.int64(ST_BELOW))
            g_start[i] = math.nan
            continue
        g_start[i] = _rate_factor(A * ds) if A > 0.0 else 1.0
        Ts = _target_times(bt, pr, sb, st, E, K, x0, A, vinf, vs, zs, Ts, Ts_row, Ss, tau, zt,
                           T_out, i)
        if times.size:
            if Ts < 0.0:
                Ts = t_of_z(pr, st, vinf, zs)
            ic = inverse_constants_ext(pr, st, T_ext)
            for k in range(times.size):
                U_out[k, i] = u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss,
                                        reduced_time(times[k], tau), ic) * h
        status[i] = ST_OK  # last: a row whose steps above fail keeps NOT_COMPUTED


@njit(parallel=True, cache=True)
def tire_kernel(tab, sc, pr, bt, c, x_fast, cs, alpha, t_fp, h, tg, zt, lnTs, sb, quad, out,
                scratch):
    """Barus tire footprint of every case (footprint time t_fp [s] apart) into ``out``
    (:data:`~.tire_piezo.TireOut`): targets and ū at t_fp (t_fp of size 0: not asked for,
    u_exit NaN) from the primitive where it serves the case, else the per-case quadrature;
    blocks of cases in parallel as :func:`squeeze_kernel` (:func:`_tire_block`)."""
    n = cs.p0.size
    order = spread_blocks((n + BLOCK - 1) // BLOCK)
    for q in prange(order.size):
        blk = order[q]
        _tire_block(tab, sc, pr, bt, c, x_fast, cs, alpha, t_fp, h, tg, zt, lnTs, sb, quad,
                    out, scratch, blk * BLOCK, min(blk * BLOCK + BLOCK, n))


@njit(cache=True)
def _tire_block(tab, sc, pr, bt, c, x_fast, cs, alpha, t_fp, h, tg, zt, lnTs, sb, quad, out,
                scratch, b0, b1):
    """Cases b0 <= i < b1 of :func:`tire_kernel` (records borrowed as in
    :func:`_squeeze_block`)."""
    (tab, sc, pr, bt, c, cs, alpha, t_fp, tg, zt, lnTs, sb, quad, out, scratch) = borrowed(
        (tab, sc, pr, bt, c, cs, alpha, t_fp, tg, zt, lnTs, sb, quad, out, scratch))
    T_out = out.T
    u_exit = out.u_exit
    u_inf = out.u_inf
    u_start = out.u_start
    u_trap = out.u_trap
    flf = out.flf
    status = out.status
    us = cs.us
    nT = T_out.shape[0]
    T_ext = tail_top(pr)  # T at v_ext, the same for every case
    for i in range(b0, b1):
        x0, tau, A, K, st = _served(pr, sc, c, cs, alpha, h, x_fast, i)
        if K < 0:
            _tire_case(tab, sc, cs, alpha, t_fp, h, tg, quad, i, out)
            continue
        E = scratch[get_thread_id()]
        shift(c, A, K, E)
        vinf, vs, zs, Ts, Ts_row, Ss, ds = _start(pr, bt, sb, st, E, K, x0, A, us[i] / h, lnTs)
        u_inf[i] = vinf * h
        u_start[i] = vs * h
        u_trap[i] = math.nan
        if not (vs * h > vinf * h):
            for k in range(nT):
                T_out[k, i] = math.nan
            u_exit[i] = math.nan
            flf[i] = math.nan
            status[i] = TIRE_BELOW
            continue
        flf[i] = 0.0
        Ts = _target_times(bt, pr, sb, st, E, K, x0, A, vinf, vs, zs, Ts, Ts_row, Ss, tau, zt,
                           T_out, i)
        if t_fp.size == 0:  # the exit is not asked for
            u_exit[i] = math.nan
            status[i] = TIRE_OK
            continue
        if Ts < 0.0:
            Ts = t_of_z(pr, st, vinf, zs)
        ic = inverse_constants_ext(pr, st, T_ext)
        u_exit[i] = u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss,
                              reduced_time(t_fp[i], tau), ic) * h
        status[i] = TIRE_OK  # last: a row whose steps above fail keeps NOT_COMPUTED


def ratio_rows(pr, bt, c, tg):
    """(zt, lnTs, sb): the base fast path's target record (:data:`~._fastpath.ZTargets`:
    ū/ū∞ - 1 of t_star and the ratios, their logs, the Δu targets, ln T at each ratio target
    per row of the primitive ``pr``, :func:`~._fastpath.row_targets`, ~1 ms), ln T at the
    default start per row, and the Barus correction's moments there (:func:`barus_rows`,
    ``bt`` the correction table, ``c`` the series coefficients of h), for ``tg``
    (:data:`~.viscosity.BarusTargets`, whose first ratio is t_star's 1.01)."""
    if tg.ratios.size == 0 or tg.ratios[0] != 1.01:
        raise ValueError("the Barus targets must start with t_star's ratio 1.01")
    rt = row_targets(pr, tg.ratios[1:], tg.dvs)
    r1s = np.ascontiguousarray(np.concatenate(([0.01], tg.ratios[1:] - 1.0)))
    return (ZTargets(r1s, np.log(r1s), tg.dvs, rt.lnT, same_targets(r1s, tg.dvs)), rt.lnTs,
            barus_rows(pr, bt, c, r1s))


def barus_rows(pr, bt, c, r1s):
    """:data:`BarusRows` of the primitive's rows at ū/ū∞ - 1 = ``r1s`` and the default start.

    At a separation v that is the same function of x0 for every case — a ratio target
    v∞(x0)(1 + r) or the default start — S(v) = Σ_m A^m c_m M_m(x0, v) with the moments
    M_m = ∫_v^∞ (1 - π_c/π0)^m dv'/σ̄ = Σ_{i<=m} C(m, i) (-y)^i R_i(v) (y = π_c(v)/π0; the
    binomial sum is the Taylor shift's, with the same bound on its rounding). Tabulated per row
    (σ̄ M_m: smooth and O(1), as the table's ρ_j) and combined across rows with the primitive's
    4-point stencil, a case's S there is K + 1 multiply-adds in A and one exp, without the
    case's Taylor shift or a lookup in the correction table (~0.1 ms per call)."""
    nk = r1s.size
    M = np.empty((pr.xn.size, nk + 1, K_MAX + 1))
    LS = np.empty((pr.xn.size, nk + 1))
    Y = np.empty((pr.xn.size, nk + 1))
    _barus_rows_kernel(pr, bt, c, np.ascontiguousarray(r1s, dtype=np.float64), M, LS, Y)
    return BarusRows(M, LS, Y)


@njit(parallel=True, cache=True)
def _barus_rows_kernel(pr, bt, c, r1s, M, LS, Y):
    nk = r1s.size
    for j in prange(pr.xn.size):
        vinf = math.exp(pr.lnv[j])
        u = np.empty(K_MAX + 1)
        for k in range(nk + 1):
            v = vinf * (1.0 + r1s[k]) if k < nk else vinf * one_plus_exp(pr.zs[j])
            LS[j, k], Y[j, k] = _row_moments(bt, c, pr.xn[j], v, u, M[j, k])


@njit(cache=True)
def _row_moments(bt, c, x0, v, u, m_out):
    """(ln σ̄(v), π_c(v)/π0) and c_m σ̄ M_m(v), m <= K_MAX, into m_out (u: scratch). Above
    v_ext the closed-form tail: y = 0, M_m = ∫_v^∞ dv'/σ̄_tail, σ̄_tail = w³ - c w, w = v + d
    (as :func:`~._barus_primitive.s_at`, whose cell interpolation :func:`s_cell` it shares)."""
    if v >= bt.v_ext:
        w = v + bt.d
        sig = w * w * w - bt.c * w
        tail = sig * qk_tail_int(bt.c, w, math.inf)
        for m in range(m_out.size):
            m_out[m] = c[m] * tail
        return math.log(sig), 0.0
    i, h00, h10, h01, h11, lnp, lns = s_cell(bt, math.log(v))
    RHO, DRHO = bt.RHO, bt.DRHO
    y = math.exp(lnp - x0)
    yp = 1.0
    for q in range(u.size):
        u[q] = yp * (h00 * RHO[i, q] + h10 * DRHO[i, q] + h01 * RHO[i + 1, q]
                     + h11 * DRHO[i + 1, q])
        yp *= -y
    B = BINOMIALS
    for m in range(m_out.size):
        acc = 0.0
        for q in range(m + 1):
            acc += B[m, q] * u[q]
        m_out[m] = c[m] * acc
    return lns, y
