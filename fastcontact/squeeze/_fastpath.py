"""Parallel per-case kernels on the time primitive (``method="fast"``).

Every output is a few interpolations of the primitive T(x0, ū) per case
(:mod:`fastcontact.squeeze.primitive`): t(a → b) = τ0 [T(b) - T(a)], ū(t) from
T(ū) = T(ū_start) + t/τ0. Trapped rows (p0 above the trap pressure) come from the trapped
side's primitive (:mod:`._trap_primitive`); the rows neither serves (p0 within 4.4 % below the
trap pressure or less than 1e-8 above it in ln p0, outside the tables) fall back to the
per-case quadrature in the same pass.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from . import _kernels as qk
from ._primitive_eval import (inverse_constants, inverse_constants_ext, tail_top, z_of_t_at,
                              z_of_t_from)
from .primitive import Primitive, first_row, row_value, stencil, t_of_z
from ._primitive_eval import lagrange_denominators, one_plus_exp, t_of_zv
from ._trap_primitive import trap_row
from ..kernels.balance import spread_blocks
from ..kernels.borrow import borrowed
from ..kernels.readonly import readonly_fields

__all__ = ["fast_kernel", "history_kernel", "one_case_primitive", "RowTargets", "row_targets"]

#: per-call tables on the primitive's rows: lnT (nx, 1 + nr + nd) = ln T at the targets
#: (t_star: ū = 1.01 ū∞, then the nr ratios, then the nd Δu targets at each row's own ū∞),
#: lnTs (nx) = ln T at the default start, lnTv (nx) = ln T at a start ū = vsh h_rms shared by
#: every case of the call (NaN where z = ln(vsh/v∞ - 1) < ZV_ROW at that row; size 0 and vsh
#: NaN when the starts differ). A case interpolates them in x0 with the same 4-point stencil as
#: everything else, so a target below the start costs four loads and one exp.
RowTargets = namedtuple("RowTargets", "lnT lnTs lnTv vsh")
#: the per-call target tables of :func:`fast_kernel` (built in the kernel, before its loop):
#: r1s = ū/ū∞ - 1 of t_star and the ratios [-], zr = ln r1s, dvs = Δu/h_rms of the Δu
#: targets [-], lnT the :data:`RowTargets` table of all the targets, src (1 + nr + nd) the
#: earlier target each one equals (-1: none; :func:`same_targets`)
ZTargets = namedtuple("ZTargets", "r1s zr dvs lnT src")
#: a per-case start within GUARD_Z (in z = ln(ū/ū∞ - 1)) above a target takes the target
#: from the same interpolant as the start (t_of_z), so that the difference stays >= 0; a
#: target farther below takes its T from the row table
GUARD_Z = 1.0
#: a shared start's T comes from the row table ``lnTv`` only where it lies at least this far
#: above equilibrium (z = ln(ū/ū∞ - 1) >= 1: ū >= 3.7 ū∞) at the case and at each stencil row:
#: closer to ū∞ the logarithmic singularity of T makes the interpolation across rows at fixed
#: ū less accurate. Measured on the four embedded tables (20,000 random pressures per start,
#: starts 0.3–1000 h_rms, z >= 1): the row table and t_of_z differ by <= 7.1e-8, by most
#: next to percolation, where the critical-junction primitive's own error is up to 1.1e-6
ZV_ROW = 1.0


@njit(cache=True, inline="always")
def _row_stencil(pr, j):
    """The stencil of row j itself (weight 1 on row j)."""
    j0 = first_row(pr, j)
    r = j - j0
    return (j0, 1.0 if r == 0 else 0.0, 1.0 if r == 1 else 0.0, 1.0 if r == 2 else 0.0,
            1.0 if r == 3 else 0.0)


@njit(parallel=True, cache=True)
def _row_targets_kernel(pr, ratios, dvs, vsh, lnT, lnTs, lnTv):
    """Blocks of rows in parallel, each one call of :func:`_row_targets_rows` (compiled
    outside numba's parfor passes: its inline interpolants in this loop cost ~10 s of
    compiling)."""
    n = pr.xn.size
    for b in prange((n + _ROWS - 1) // _ROWS):
        _row_targets_rows(pr, ratios, dvs, vsh, lnT, lnTs, lnTv, b * _ROWS,
                          min(b * _ROWS + _ROWS, n))


#: rows per call of :func:`_row_targets_rows`
_ROWS = 32


@njit(cache=True)
def _row_targets_rows(pr, ratios, dvs, vsh, lnT, lnTs, lnTv, j0, j1):
    """Rows j0 <= j < j1 of :func:`_row_targets_kernel` (the primitive borrowed: a record
    crossing the parallel loop arrives with its reference counts)."""
    pr = borrowed(pr)
    nr = ratios.size
    for j in range(j0, j1):
        st = _row_stencil(pr, j)
        vinf = math.exp(pr.lnv[j])
        lnTs[j] = math.log(t_of_z(pr, st, vinf, pr.zs[j]))
        if lnTv.size:
            zv = math.log(vsh / vinf - 1.0) if vsh > vinf else -math.inf
            lnTv[j] = math.log(t_of_zv(pr, st, vinf, zv, vsh)) if zv >= ZV_ROW else math.nan
        for k in range(lnT.shape[1]):
            r1 = 0.01 if k == 0 else ratios[k - 1] - 1.0 if k <= nr else dvs[k - 1 - nr] / vinf
            lnT[j, k] = math.log(t_of_z(pr, st, vinf, math.log(r1)))


def row_targets(pr, ratios, dvs, vsh=math.nan):
    """The :data:`RowTargets` of the primitive ``pr`` for these ratio targets [-], Δu targets
    dvs = Δu/h_rms [-] and the start vsh = ū(0)/h_rms [-] shared by every case (NaN: none;
    +inf is not tabulated) (~1 ms)."""
    ratios = np.ascontiguousarray(ratios, dtype=np.float64)
    dvs = np.ascontiguousarray(dvs, dtype=np.float64)
    lnT = np.empty((pr.xn.size, 1 + ratios.size + dvs.size))
    lnTs = np.empty(pr.xn.size)
    vsh = float(vsh)
    shared = 0.0 < vsh < math.inf
    lnTv = np.empty(pr.xn.size if shared else 0)
    _row_targets_kernel(pr, ratios, dvs, vsh, lnT, lnTs, lnTv)
    return RowTargets(lnT, lnTs, lnTv, vsh if shared else math.nan)


@njit(cache=True, inline="always")
def _row_col(A, st, k):
    """Σ_r w_r A[j0 + r, k]."""
    j0 = st[0]
    return st[1] * A[j0, k] + st[2] * A[j0 + 1, k] + st[3] * A[j0 + 2, k] + st[4] * A[j0 + 3, k]


@njit(cache=True, inline="always")
def _case_strides(cs):
    """Index multipliers of the case arrays E, R, eta, us: 1 where they hold one value per
    case, 0 where one value is shared by every case (size 1) — case i reads a[i * stride]."""
    return (1 if cs.E.size > 1 else 0, 1 if cs.R.size > 1 else 0,
            1 if cs.eta.size > 1 else 0, 1 if cs.us.size > 1 else 0)


@njit(cache=True)
def _start(pr, st, vinf, vs_in):
    """(v_start, T(v_start)) of a case: the default start (NaN in) or the given one."""
    if vs_in != vs_in:
        zs = row_value(pr.zs, st)
        vs = vinf * one_plus_exp(zs)
    else:
        vs = vs_in
        if vs == math.inf:
            return vs, 0.0
        zs = math.log(vs / vinf - 1.0)
    return vs, t_of_z(pr, st, vinf, zs)


@njit(cache=True)
def _slow_row(tab, mp, x0, vs_in, tg, tau, h, quad, i, out):
    """A row the primitive does not serve (outside the tables, trapped side): per-case
    quadrature, then the overflow flag (a plain call: big records by value are fine here,
    these rows are rare)."""
    qk.quad_case(tab, mp, x0, vs_in, tg, tau, h, quad, i, out)
    _flag_overflow(tau, tg, h, i, out)


@njit(cache=True)
def _below_row(vinf, vs_in, h, x0, i, out):
    """A row whose given start is at or below ū∞: NaN outputs, status explains."""
    qk._nan_row(out, i, x0)
    out.u_inf[i] = vinf * h
    out.u_start[i] = vs_in * h
    out.status[i] = qk.ST_BELOW


@njit(cache=True)
def _flag_overflow(tau, tg, h, i, out):
    """Status "overflow" where τ0 or a time is not representable (inf) on a computed row.

    On a trapped row the times to targets at or below ū_trap are inf by the physics (never
    reached); only τ0, t_trap and the times to targets above ū_trap can overflow."""
    st = out.status[i]
    if st != qk.ST_OK and st != qk.ST_TRAPPED:
        return
    bad = not (0.0 < tau < math.inf)
    nr = tg.ratios.size
    u_inf = out.u_inf[i]
    trapped = st == qk.ST_TRAPPED
    if trapped and out.t_trap[i] == math.inf and out.u_start[i] > out.u_trap[i]:
        bad = True
    for k in range(out.T.shape[0]):
        if out.T[k, i] == math.inf:
            if k == 0:
                ut = 1.01 * u_inf
            elif k <= nr:
                ut = tg.ratios[k - 1] * u_inf
            else:
                ut = u_inf + tg.dvs[k - 1 - nr] * h
            if not trapped or ut > out.u_trap[i]:
                bad = True
    if bad:
        out.status[i] = qk.ST_OVERFLOW


@njit(cache=True, inline="always")
def _case_start(pr, st, vinf, vs_in, rt):
    """(zs, v_start, Ts, Ts_row) of a served case: z and ū/h at the start, T at the start from
    t_of_z (-1: not computed yet) and T at the start from a row table of ``rt`` (the default
    start's, or a start shared by every case at least ZV_ROW above ū∞; paired with targets at
    least GUARD_Z below the start only), else from t_of_z."""
    if vs_in != vs_in:
        zs = row_value(pr.zs, st)
        return zs, vinf * one_plus_exp(zs), -1.0, math.exp(row_value(rt.lnTs, st))
    if vs_in == math.inf:
        return math.inf, vs_in, 0.0, 0.0
    zs = math.log(vs_in / vinf - 1.0)
    if vs_in == rt.vsh and zs >= ZV_ROW:
        Tv = math.exp(row_value(rt.lnTv, st))
        if Tv == Tv:  # every stencil row at least ZV_ROW above its ū∞
            return zs, vs_in, -1.0, Tv
    Ts = t_of_zv(pr, st, vinf, zs, vs_in)
    return zs, vs_in, Ts, Ts


@njit(cache=True, inline="always")
def _target_time(pr, st, vinf, vs, zs, Ts, Ts_row, tau, k, zt):
    """(t [s] from the start to target k, Ts): with nr = zt.r1s.size - 1 ratio targets, target
    k <= nr is t_star or a ratio (z from ``zt.zr``), above nr a Δu target; 0 for a target at
    or above the start. ``zt`` a :data:`ZTargets`."""
    nr = zt.r1s.size - 1
    r1 = zt.r1s[k] if k <= nr else zt.dvs[k - 1 - nr] / vinf
    vt = vinf * (1.0 + r1)
    if vt >= vs:
        return 0.0, Ts
    z = zt.zr[k] if k <= nr else math.log(r1)
    if z < zs - GUARD_Z:
        return tau * (math.exp(_row_col(zt.lnT, st, k)) - Ts_row), Ts
    if Ts < 0.0:  # near the start: both ends from the same interpolant
        Ts = t_of_zv(pr, st, vinf, zs, vs)
    return tau * (t_of_zv(pr, st, vinf, z, vt) - Ts), Ts


@njit(cache=True, inline="always")
def _u_at(pr, st, vinf, vs, zs, Ts, Ts_row, tt, h, ic):
    """(ū [m] at the reduced time tt = t/τ0 after the start, Ts): T(ū) = T(start) + tt, the
    start's T from the row table where ū lands at least GUARD_Z below the start, else from
    t_of_z (computed here if Ts < 0: the inverse z_of_t pairs with it); ``ic`` the stencil's
    :func:`~fastcontact.squeeze._primitive_eval.inverse_constants`."""
    if tt == 0.0:
        return vs * h, Ts
    if tt == math.inf:
        return vinf * h, Ts
    if Ts < 0.0:
        z = z_of_t_at(pr, st, vinf, Ts_row + tt, ic)
        if z < zs - GUARD_Z:
            return vinf * one_plus_exp(z) * h, Ts
        Ts = t_of_zv(pr, st, vinf, zs, vs)
        # Ts and Ts_row differ by the row table's interpolation error: the root is in or
        # next to the first one's cell
        z = z_of_t_from(pr, st, vinf, Ts + tt, ic, z)
    else:
        z = z_of_t_at(pr, st, vinf, Ts + tt, ic)
    # ū(t) <= ū(0): the inverse can land an ulp above the start for t → 0; keeps the ODE's
    # monotonicity (a round-off bound, not a clamp)
    return min(vinf * one_plus_exp(z), vs) * h, Ts


@njit(cache=True)
def same_targets(r1s, dvs):
    """src (1 + nr + nd): for each time target of :data:`ZTargets` (t_star and the ratios by
    r1 = ū/ū∞ - 1, then the Δu targets dv), the earlier target it equals (-1: none), so that
    the kernels compute it once. Ratio targets are equal when their ratios 1 + r1 are the same
    double: ``t_ratio_1.01`` is t_star (ū = 1.01 ū∞; 1.01 - 1 and 0.01 differ by 9e-16
    relative, below the resolution of the ratio 1.01 itself, 1e-14 in r1)."""
    nr = r1s.size - 1
    src = np.full(r1s.size + dvs.size, -1, dtype=np.int64)
    for k in range(1, r1s.size):
        for j in range(k):
            if src[k] < 0 and 1.0 + r1s[k] == 1.0 + r1s[j]:
                src[k] = j
    for k in range(dvs.size):
        for j in range(k):
            if src[1 + nr + k] < 0 and dvs[k] == dvs[j]:
                src[1 + nr + k] = 1 + nr + j
    return src


#: cases per block of :func:`fast_kernel`: each stage of the per-case work runs over a block
#: before the next, so that the CPU overlaps independent cases (one case alone is a chain of
#: dependent exp/log and interpolations: latency-bound)
BLOCK = 128
#: columns of a block's scratch array: the stencil (j0, four weights), v∞, z and v of the
#: start, T at the start (from t_of_z, -1 not yet), the default start's row-table T, τ0, a
#: live flag (1: the primitive serves the row), "bad" (τ0 or a time not representable) and
#: the stencil's inverse constants (five)
_J0, _W, _VINF, _ZS, _VS, _TS, _TSR, _TAU, _LIVE, _BAD, _IC = 0, 1, 5, 6, 7, 8, 9, 10, 11, 12, 13
_NSCR = 18


@njit(cache=True, inline="always")
def _st_of(scr, c):
    """The stencil of block row c (stored as floats: j0 is exact below 2^53)."""
    return (int(scr[c, _J0]), scr[c, _W], scr[c, _W + 1], scr[c, _W + 2], scr[c, _W + 3])


@njit(parallel=True, cache=True)
def fast_kernel(tab, mp, pr, rt, x_fast, tlo, thi, ttr, cs, h, tg, quad, out, timescales):
    """method="fast": every case from the primitive (fall-back rows by quadrature).

    Each parallel iteration takes a block of :data:`BLOCK` cases (:func:`_fast_block`) through
    the stages (stencil and v∞; start; each time target; each ū at a time; status) one after
    the other: within a stage the cases are independent, so the CPU overlaps them (a case
    alone is latency-bound: ×1.5–1.7 measured on the start stage). Ratio targets (same z for
    every case) come from the row tables ``rt`` unless the start lies within GUARD_Z above
    them; there, and for Δu targets, both ends come from t_of_z (one interpolant: the
    difference is accurate and >= 0 however close the target is to the start); ū at times
    from its inverse z_of_t. ``timescales=False`` leaves t_relax, t_trap and tau0 unwritten on
    the served rows (a caller that reports none of them saves the memory traffic: 24 MB per
    million rows). The case arrays E, R, eta and us hold one value per case or one value for
    all (size 1: a study's shared modulus, radius, viscosity or start needs no array of a
    million copies).

    The parallel body is one call per block: the per-case work (its helpers inline) is
    compiled as a plain function, outside numba's parfor passes, whose cost grows faster than
    the body (a body of the whole block inline here took ~65 s of compiling on 2 cores; a call
    per block of 128 cases costs nothing measurable). The blocks are visited in
    :func:`~fastcontact.kernels.balance.spread_blocks` order: numba gives each thread one
    contiguous run of them, and a study sorted by pressure would hand every fall-back row
    (quadrature: x0 next to the trap pressure or outside the tables) to the last thread.

    Trapped rows (x0 from ``ttr.x_lo`` to ``ttr.x_hi``) come from the trapped side's primitive
    ``tlo``, ``thi``, ``ttr`` (:mod:`._trap_primitive`; its ``empty()`` serves none), one case
    at a time (:func:`~._trap_primitive.trap_row`)."""
    nr = tg.ratios.size
    r1s = np.empty(1 + nr)  # ū/ū∞ - 1 of t_star and the ratios, and its log
    r1s[0] = 0.01
    r1s[1:] = tg.ratios - 1.0
    zt = ZTargets(r1s, np.log(r1s), tg.dvs, rt.lnT, same_targets(r1s, tg.dvs))
    n = cs.p0.size
    order = spread_blocks((n + BLOCK - 1) // BLOCK)
    for q in prange(order.size):
        blk = order[q]
        _fast_block(tab, mp, pr, rt, x_fast, tlo, thi, ttr, cs, h, tg, quad, out, timescales,
                    zt, blk * BLOCK, min(blk * BLOCK + BLOCK, n))


@njit(cache=True)
def _fast_block(tab, mp, pr, rt, x_fast, tlo, thi, ttr, cs, h, tg, quad, out, timescales, zt,
                b0, b1):
    """Cases b0 <= i < b1 of :func:`fast_kernel`, stage by stage (``zt`` its
    :data:`ZTargets`). The records are borrowed (:mod:`fastcontact.kernels.borrow`): each
    inline helper's copy of a record would otherwise count references on every array in it."""
    tab, mp, pr, rt, cs, tg, quad, out, zt = borrowed((tab, mp, pr, rt, cs, tg, quad, out, zt))
    tlo, thi, ttr = borrowed((tlo, thi, ttr))
    xt_lo, xt_hi = ttr.x_lo, ttr.x_hi
    T_out = out.T
    U_out = out.U
    tau0 = out.tau0
    status = out.status
    u_inf = out.u_inf
    u_start = out.u_start
    t_relax = out.t_relax
    u_trap = out.u_trap
    t_trap = out.t_trap
    flf = out.flf
    p0 = cs.p0
    E = cs.E
    R = cs.R
    eta = cs.eta
    us = cs.us
    sE, sR, seta, sus = _case_strides(cs)
    times = tg.times
    src = zt.src
    x_lo, x_hi = mp.x_min, min(mp.x_max, x_fast)
    nT, nU = T_out.shape[0], U_out.shape[0]
    per_case_times = times.shape[1] > 1
    T_ext = tail_top(pr)
    scr = np.empty((b1 - b0, _NSCR))
    for i in range(b0, b1):  # stage 1: τ0, the stencil and v∞; rows not served
        c = i - b0
        Ri = R[i * sR]
        tau = 3.0 * eta[i * seta] * Ri * Ri / (2.0 * h * h * p0[i])
        x0 = math.log(p0[i] / E[i * sE])
        vs_in = us[i * sus] / h
        if timescales:
            tau0[i] = tau
        scr[c, _LIVE] = 0.0
        if not (x_lo <= x0 <= x_hi):
            if xt_lo <= x0 <= xt_hi:
                trap_row(tab, mp, tlo, thi, ttr, x0, vs_in, tg, tau, h, i, out)
                _flag_overflow(tau, tg, h, i, out)
            else:
                _slow_row(tab, mp, x0, vs_in, tg, tau, h, quad, i, out)
            continue
        st = stencil(pr, x0)
        vinf = math.exp(row_value(pr.lnv, st))
        if not (vs_in != vs_in or vs_in * h > vinf * h):  # as reported (SI)
            _below_row(vinf, vs_in, h, x0, i, out)
            continue
        scr[c, _LIVE] = 1.0
        scr[c, _J0] = st[0]
        scr[c, _W] = st[1]
        scr[c, _W + 1] = st[2]
        scr[c, _W + 2] = st[3]
        scr[c, _W + 3] = st[4]
        scr[c, _VINF] = vinf
        scr[c, _TAU] = tau
    for i in range(b0, b1):  # stage 2: the start
        c = i - b0
        if scr[c, _LIVE] == 0.0:
            continue
        st = _st_of(scr, c)
        vinf = scr[c, _VINF]
        tau = scr[c, _TAU]
        zs, vs, Ts, Ts_row = _case_start(pr, st, vinf, us[i * sus] / h, rt)
        scr[c, _ZS] = zs
        scr[c, _VS] = vs
        scr[c, _TS] = Ts
        scr[c, _TSR] = Ts_row
        scr[c, _BAD] = 0.0 if 0.0 < tau < math.inf else 1.0
        u_inf[i] = vinf * h
        u_start[i] = vs * h
        if timescales:
            t_relax[i] = tau * math.exp(row_value(pr.lnS, st))
            t_trap[i] = math.inf
        u_trap[i] = math.nan
        flf[i] = 0.0
    for k in range(nT):  # stage 3: the time targets
        ks = src[k]
        for i in range(b0, b1):
            c = i - b0
            if scr[c, _LIVE] == 0.0:
                continue
            if ks >= 0:  # the same target as an earlier one
                T_out[k, i] = T_out[ks, i]
                continue
            tk, Ts = _target_time(pr, _st_of(scr, c), scr[c, _VINF], scr[c, _VS],
                                  scr[c, _ZS], scr[c, _TS], scr[c, _TSR], scr[c, _TAU], k,
                                  zt)
            scr[c, _TS] = Ts
            T_out[k, i] = tk
            if tk == math.inf:
                scr[c, _BAD] = 1.0
    if nU > 0:  # stage 4: ū at the times
        for i in range(b0, b1):
            c = i - b0
            if scr[c, _LIVE] == 0.0:
                continue
            ic = inverse_constants_ext(pr, _st_of(scr, c), T_ext)
            for q in range(5):
                scr[c, _IC + q] = ic[q]
        for k in range(nU):
            for i in range(b0, b1):
                c = i - b0
                if scr[c, _LIVE] == 0.0:
                    continue
                tt = qk.reduced_time(times[k, i if per_case_times else i - i], scr[c, _TAU])
                ic = (scr[c, _IC], scr[c, _IC + 1], scr[c, _IC + 2], scr[c, _IC + 3],
                      scr[c, _IC + 4])
                u, Ts = _u_at(pr, _st_of(scr, c), scr[c, _VINF], scr[c, _VS], scr[c, _ZS],
                              scr[c, _TS], scr[c, _TSR], tt, h, ic)
                U_out[k, i] = u
                scr[c, _TS] = Ts
    for i in range(b0, b1):  # stage 5: status
        c = i - b0
        if scr[c, _LIVE] != 0.0:
            status[i] = qk.ST_OVERFLOW if scr[c, _BAD] != 0.0 else qk.ST_OK


@njit(cache=True)
def _tau0(tau, i, out):
    out.tau0[i] = tau  # in a callee: a record-field setitem in the prange body is lost


@njit(parallel=True, cache=True)
def quad_kernel(tab, mp, cs, h, tg, quad, out):
    """method="quad": every case by per-case quadrature (one prange pass)."""
    sE, sR, seta, sus = _case_strides(cs)
    for j in prange(cs.p0.size):
        i = np.int64(j)  # a prange index is uint64: the helpers' other callers pass int64
        Ri = cs.R[i * sR]
        tau = 3.0 * cs.eta[i * seta] * Ri * Ri / (2.0 * h * h * cs.p0[i])
        _slow_row(tab, mp, math.log(cs.p0[i] / cs.E[i * sE]), cs.us[i * sus] / h, tg, tau, h,
                  quad, i, out)
        _tau0(tau, i, out)


def _one_row(arr, st):
    """A 4-row array whose first row is the stencil's combination of ``arr`` (others 0)."""
    j0, w0, w1, w2, w3 = st
    out = np.zeros((4,) + arr.shape[1:])
    out[0] = w0 * arr[j0] + w1 * arr[j0 + 1] + w2 * arr[j0 + 2] + w3 * arr[j0 + 3]
    return out


def one_case_primitive(pr, x0):
    """(primitive, stencil) of the single pressure x0 = ln(p0/E*): the four rows combined
    once, so that every later lookup reads one small row that stays in cache (the same
    arithmetic as combining per lookup: weights 1, 0, 0, 0 reproduce it exactly)."""
    st = stencil(pr, x0)
    if st[0] < 0:
        return None, st
    one = (0, 1.0, 0.0, 0.0, 0.0)
    xn = np.array([x0 - 1.0, x0, x0 + 1.0, x0 + 2.0])
    pr1 = readonly_fields(Primitive(xn, float(xn[0]), 1.0, np.arange(4.0),
                                    lagrange_denominators(xn), pr.z0, pr.dz, pr.nz,
                                    _one_row(pr.C, st), _one_row(pr.lnv, st),
                                    _one_row(pr.lnS, st), _one_row(pr.zs, st),
                                    _one_row(pr.lk, st), pr.v_ext, pr.c, pr.d))
    return pr1, one


@njit(parallel=True, cache=True)
def history_kernel(pr, st, vs_in, tau, h, t, u):
    """ū [m] of one case at the times t [s]; ``pr, st`` from :func:`one_case_primitive`
    (the case's start once, then blocks of :data:`BLOCK` times in parallel, each one call of
    :func:`_history_block`)."""
    vinf = math.exp(row_value(pr.lnv, st))
    vs, Ts = _start(pr, st, vinf, vs_in)
    ic = inverse_constants(pr, st)  # the same for every time of the case
    n = t.size
    for b in prange((n + BLOCK - 1) // BLOCK):
        _history_block(pr, st, vinf, vs, Ts, ic, tau, h, t, u, b * BLOCK,
                       min(b * BLOCK + BLOCK, n))


@njit(cache=True)
def _history_block(pr, st, vinf, vs, Ts, ic, tau, h, t, u, k0, k1):
    """Times k0 <= k < k1 of :func:`history_kernel` (the primitive borrowed)."""
    pr = borrowed(pr)
    z = math.nan  # the previous time's root: the search of the next starts from its cell
    for k in range(k0, k1):
        tk = qk.reduced_time(t[k], tau)
        if tk == 0.0:
            u[k] = vs * h
        elif tk == math.inf:
            u[k] = vinf * h
        else:
            z = z_of_t_from(pr, st, vinf, Ts + tk, ic, z)
            u[k] = min(vinf * one_plus_exp(z), vs) * h
