"""Barus squeeze-out and tire footprint on the time primitive (``method="fast"``).

Every case is a few interpolations: the base primitive T at the start and at each target,
and the Barus correction S of :mod:`._barus_primitive` at the same separations,
t = τ0 {T(ū) - T(ū_start) + α p0 [S(ū) - S(ū_start)]}; ū at the footprint exit by Newton on
the same two (:func:`~._barus_primitive.u_at_time`). Rows the tables do not serve this way
(outside the tables, p0 within 4.4 % of the trap pressure or beyond, α p0 > API_FAST) run the
per-case quadrature of :mod:`.viscosity` / :mod:`.tire_piezo` in the same pass.
"""
from __future__ import annotations

import math

import numpy as np
from numba import get_thread_id, njit, prange

from ..kernels.borrow import borrowed

from ._barus_primitive import BarusTable, s_at, s_value, series_order, shift, u_at_time
from ._fastpath import ZTargets, _target_time, row_targets, same_targets
from ._kernels import Cases, Quad
from ._primitive_eval import (Primitive, inverse_constants_ext, one_plus_exp, row_value,
                              stencil, t_of_z, tail_top)
from .tire_piezo import _BELOW as TIRE_BELOW
from .tire_piezo import _OK as TIRE_OK
from .tire_piezo import TireOut, _tire_case
from .viscosity import (ST_BELOW, ST_OK, BarusOut, BarusTargets, _case_head, _no_times,
                        _piezo_case, _rate_factor)

__all__ = ["squeeze_kernel", "tire_kernel", "ratio_rows"]
#: the records' types, by name in this module: numba's parfor lowering rebuilds the kernels'
#: argument types from the module globals
_RECORDS = (BarusTable, BarusOut, BarusTargets, Cases, Primitive, Quad, TireOut, ZTargets)


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
def _start(pr, bt, st, E, K, x0, vs_in, lnTs):
    """(v∞, v_start, z_start, T(start) or -1 (not computed yet), T(start) paired with the
    row-table targets, S(start), 1 - π_c/π0 at the start) of a served case; v_start <= v∞ is
    returned as is (the caller flags it). The default start's T comes from the row table
    ``lnTs`` (as the base fast path's), a given start's from t_of_z."""
    vinf = math.exp(row_value(pr.lnv, st))
    if vs_in != vs_in:
        zs = row_value(pr.zs, st)
        vs = vinf * one_plus_exp(zs)
        Ts = -1.0
        Ts_row = math.exp(row_value(lnTs, st))
    else:
        vs = vs_in
        if not (vs > vinf):
            return vinf, vs, math.nan, math.nan, math.nan, math.nan, math.nan
        if vs == math.inf:
            return vinf, vs, math.inf, 0.0, 0.0, 0.0, 1.0
        zs = math.log(vs / vinf - 1.0)
        Ts = t_of_z(pr, st, vinf, zs)
        Ts_row = Ts
    Ss, ys = s_value(bt, E, K, x0, vs)
    return vinf, vs, zs, Ts, Ts_row, Ss, 1.0 - ys


@njit(cache=True, inline="always")
def _target_times(bt, pr, st, E, K, x0, A, vinf, vs, zs, Ts, Ts_row, Ss, tau, zt, l1r, T, i):
    """Times [s] from the start to each target (t_star and the ratios × v∞, then v∞ + dv;
    ``zt`` the :data:`~._fastpath.ZTargets` of :func:`ratio_rows`) into column i; returns
    T(start) (computed here if a target needed it, else as given).

    The base part T(target) - T(start) is the base fast path's
    (:func:`~._fastpath._target_time`: row tables far below the start, the interpolant at
    both ends near it); the Barus part A [S(target) - S(start)] from the correction table,
    at ln v = ln v∞ + ``l1r`` (ln(1 + r) of each ratio target, computed once per call)."""
    nr = zt.r1s.size
    lnvinf = row_value(pr.lnv, st)  # ln v∞ (v∞ is its exp)
    for k in range(T.shape[0]):
        if zt.src[k] >= 0:  # the same target as an earlier one
            T[k, i] = T[zt.src[k], i]
            continue
        vt = vinf * (1.0 + (zt.r1s[k] if k < nr else zt.dvs[k - nr] / vinf))
        if vt >= vs:
            T[k, i] = 0.0
            continue
        S, _ = s_at(bt, E, K, x0, vt, lnvinf + l1r[k] if k < nr else math.log(vt))
        dt, Ts = _target_time(pr, st, vinf, vs, zs, Ts, Ts_row, tau, k, zt)
        T[k, i] = dt + tau * A * (S - Ss)
    return Ts


@njit(parallel=True, cache=True)
def _squeeze_par(tab, sc, pr, bt, c, x_fast, cs, alpha, h, tg, zt, lnTs, quad, out,
                 scratch):
    """The case body inline (a call per case with ~40 arguments cost about as much as the
    case); stores go to the output arrays taken one per statement before the loop (a store
    into a record's array inside a prange body is lost in numba 0.6x's parfor lowering)."""
    T_out = out.T
    U_out = out.U
    u_inf = out.u_inf
    u_start = out.u_start
    tau0 = out.tau0
    g_start = out.g_start
    status = out.status
    times = tg.times
    us = cs.us
    l1r = np.log1p(zt.r1s)
    T_ext = tail_top(pr)  # T at v_ext, the same for every case
    for i in prange(cs.p0.size):
        x0, tau, A, K, st = _served(pr, sc, c, cs, alpha, h, x_fast, i)
        if K < 0:
            _piezo_case(tab, sc, cs, alpha, h, tg, quad, i, out)
            continue
        E = scratch[get_thread_id()]
        shift(c, A, K, E)
        tau0[i] = tau
        vinf, vs, zs, Ts, Ts_row, Ss, ds = _start(pr, bt, st, E, K, x0, us[i] / h, lnTs)
        u_inf[i] = vinf * h
        u_start[i] = vs * h
        if not (vs * h > vinf * h):  # a given start at or below ū∞ (as reported, SI)
            _no_times(out, i, ST_BELOW)
            g_start[i] = math.nan
            continue
        g_start[i] = _rate_factor(A * ds) if A > 0.0 else 1.0
        status[i] = ST_OK
        Ts = _target_times(bt, pr, st, E, K, x0, A, vinf, vs, zs, Ts, Ts_row, Ss, tau, zt,
                           l1r, T_out, i)
        if times.size:
            if Ts < 0.0:
                Ts = t_of_z(pr, st, vinf, zs)
            ic = inverse_constants_ext(pr, st, T_ext)
            for k in range(times.size):
                U_out[k, i] = u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss,
                                        times[k] / tau, ic) * h


@njit(cache=True)
def squeeze_kernel(tab, sc, pr, bt, c, x_fast, cs, alpha, h, tg, zt, lnTs, quad, out,
                   scratch):
    """Barus squeeze-out of every case (``cs`` :class:`~._kernels.Cases`, α [1/Pa] apart)
    into ``out`` (:data:`~.viscosity.BarusOut`): the primitive where it serves the case, else
    the per-case quadrature (``quad``). ``scratch`` (threads, K_MAX + 1): one row of series
    coefficients per thread. ``zt``, ``lnTs``: :func:`ratio_rows` of ``tg``.

    The records reach the per-case helper as borrowed views (:mod:`fastcontact.kernels.borrow`;
    passed by value each call costs two contended atomic reference counts per array, most of
    a case's time). They are borrowed here and handed to the parallel loop as arguments:
    numba's parfor lowering rebuilds a namedtuple captured by a prange body from the
    definition of its variable, which must be an argument or the class itself."""
    _squeeze_par(borrowed(tab), borrowed(sc), borrowed(pr), borrowed(bt), borrowed(c), x_fast,
                 borrowed(cs), borrowed(alpha), h, borrowed(tg), borrowed(zt), borrowed(lnTs),
                 borrowed(quad), borrowed(out), borrowed(scratch))


@njit(parallel=True, cache=True)
def _tire_par(tab, sc, pr, bt, c, x_fast, cs, alpha, t_fp, h, tg, zt, lnTs, quad, out,
              scratch):
    """The case body inline, as :func:`_squeeze_par`."""
    T_out = out.T
    u_exit = out.u_exit
    u_inf = out.u_inf
    u_start = out.u_start
    u_trap = out.u_trap
    flf = out.flf
    status = out.status
    us = cs.us
    nT = T_out.shape[0]
    l1r = np.log1p(zt.r1s)
    T_ext = tail_top(pr)  # T at v_ext, the same for every case
    for i in prange(cs.p0.size):
        x0, tau, A, K, st = _served(pr, sc, c, cs, alpha, h, x_fast, i)
        if K < 0:
            _tire_case(tab, sc, cs, alpha, t_fp, h, tg, quad, i, out)
            continue
        E = scratch[get_thread_id()]
        shift(c, A, K, E)
        vinf, vs, zs, Ts, Ts_row, Ss, ds = _start(pr, bt, st, E, K, x0, us[i] / h, lnTs)
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
        status[i] = TIRE_OK
        Ts = _target_times(bt, pr, st, E, K, x0, A, vinf, vs, zs, Ts, Ts_row, Ss, tau, zt,
                           l1r, T_out, i)
        if t_fp.size == 0:  # the exit is not asked for
            u_exit[i] = math.nan
            continue
        if Ts < 0.0:
            Ts = t_of_z(pr, st, vinf, zs)
        ic = inverse_constants_ext(pr, st, T_ext)
        u_exit[i] = u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss, t_fp[i] / tau,
                              ic) * h


@njit(cache=True)
def tire_kernel(tab, sc, pr, bt, c, x_fast, cs, alpha, t_fp, h, tg, zt, lnTs, quad, out,
                scratch):
    """Barus tire footprint of every case (footprint time t_fp [s] apart) into ``out``
    (:data:`~.tire_piezo.TireOut`): targets and ū at t_fp (t_fp of size 0: not asked for,
    u_exit NaN) from the primitive where it serves the case, else the per-case quadrature
    (records borrowed as in :func:`squeeze_kernel`)."""
    _tire_par(borrowed(tab), borrowed(sc), borrowed(pr), borrowed(bt), borrowed(c), x_fast,
              borrowed(cs), borrowed(alpha), borrowed(t_fp), h, borrowed(tg), borrowed(zt),
              borrowed(lnTs), borrowed(quad), borrowed(out), borrowed(scratch))


def ratio_rows(pr, tg):
    """(zt, lnTs): the base fast path's target record (:data:`~._fastpath.ZTargets`: ū/ū∞ - 1
    of t_star and the ratios, their logs, the Δu targets, ln T at each ratio target per row
    of the primitive ``pr``, :func:`~._fastpath.row_targets`, ~1 ms) and ln T at the default
    start per row, for ``tg`` (:data:`~.viscosity.BarusTargets`, whose first ratio is
    t_star's 1.01)."""
    if tg.ratios.size == 0 or tg.ratios[0] != 1.01:
        raise ValueError("the Barus targets must start with t_star's ratio 1.01")
    rt = row_targets(pr, tg.ratios[1:], tg.dvs)
    r1s = np.ascontiguousarray(np.concatenate(([0.01], tg.ratios[1:] - 1.0)))
    return ZTargets(r1s, np.log(r1s), tg.dvs, rt.lnT, same_targets(r1s, tg.dvs)), rt.lnTs
