"""The Barus squeeze-out time as one primitive, for a study of one fluid on one rubber.

With a Barus fluid the reduced time from v_s down to v is G(x0, v) - G(x0, v_s),

    G(x0, v) = T(x0, v) + A S(x0, A, v),   A = α p0 = α E* e^x0,

T the constant-viscosity time primitive (:mod:`.primitive`) and S the Barus correction of
:mod:`._barus_primitive`. Where every case of a call shares α and E* (one oil or water, one
tread compound: the usual tire or road study; or the rows of one α E* in a call of several,
:func:`served_groups`), A is a function of x0 = ln(p0/E*) alone, so G is a function of (x0, z)
as T is: it is tabulated here on the base primitive's rows (with rows inserted where they are
too far apart for G's x0-dependence through A, :data:`DX_G`) and z nodes, as ln G with its first
two z-derivatives (exact at the nodes),

    dG/dz   = T'/g(a),                     a = A (1 - y),  y = π_c(v)/π0,
    d²G/dz² = T''/g(a) - T' A (1/g)'(a) dy/dz,   dy/dz = y (d ln π_c/d ln v)(v - v∞)/v,

(1/g(a) = 1 + a P_K(a), the same truncated series as S), and the result is a
:data:`~._primitive_eval.Primitive`: the base engine's kernels then run the Barus cases
unchanged (ratio targets from row tables, Δu targets and ū at the footprint time from one
interpolation and one inversion per case) — the Barus tire at the base engine's speed.

Differences to the base primitive: no closed-form tail (v_ext = inf in the record): the z
grid is extended above the base grid's top by nodes of the closed-form flat-film tail,
G = T_tail/g(A) there (y = 0), far enough for the call's starts; below the grid the same
analytic part (T0 + S D + (h0 - S)(1 - e^-D), the relaxation slope S unchanged since g → 1 at
equilibrium, where p_cont → p0). Rows end where A leaves the series' range (API_FAST, the
stencil's rows up to three beyond it at most A_ROW_MAX, where K_MAX terms are exact to
< 1e-12). A case is served when its x0 lies at or below ``x_served`` and its start inside the
grid; the others keep the per-case Barus kernels.

References: C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87;
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
"""
from __future__ import annotations

import math
from collections import OrderedDict
from threading import Lock

import numpy as np
from numba import njit, prange

from .._core.groups import row_groups
from ..kernels.readonly import readonly, readonly_fields
from . import _kernels as qk
from ._barus_primitive import API_FAST, K_MAX, s_at, s_cell, series_order, shift
from ._fastpath import fast_kernel, row_targets
from ._trap_primitive import empty as _NONE_TRAPPED  # Barus rows: trapped ones by quadrature
from ._primitive_eval import (Primitive, _index_map, _locate, lagrange_denominators,
                              row_value, stencil)
from .viscosity import _rate_factor, _rate_factor_array

__all__ = ["A_ROW_MAX", "BarusTime", "MIN_GROUP_ROWS", "barus_time", "served_groups"]

#: largest A = α p0 of a row of the G primitive (the stencil's rows beyond API_FAST): the
#: truncated series of K_MAX terms is exact there to c_49 A^50 < 1e-12
A_ROW_MAX = 0.75


class BarusTime:
    """A G primitive (``pr``, a :data:`~._primitive_eval.Primitive`), the largest x0 it
    serves (``x_served``), the largest z = ln(v/v∞ - 1) + ln κ of a start it covers
    (``z_top``), its α E* (``aE``) and the rate-factor tables built for it
    (:func:`default_rate_table`)."""

    __slots__ = ("pr", "x_served", "z_top", "aE", "rate_tables")

    def __init__(self, pr, x_served, z_top, aE):
        self.pr, self.x_served, self.z_top, self.aE = pr, x_served, z_top, aE
        self.rate_tables = {}


#: the rate-factor table's stand-in where none is read (a given start)
_NO_TABLE = readonly(np.zeros(2))

_MEMO: OrderedDict = OrderedDict()
_LOCK = Lock()
_MEMO_SIZE = 8


def barus_time(model, pr, bt, c, x_fast, aE, v_max):
    """The :class:`BarusTime` of ``model`` (its primitive ``pr``, Barus table ``bt``, series
    coefficients ``c``, fast limit ``x_fast``) for α E* = ``aE`` [-], its z grid reaching the
    start v = ū(0)/h_rms = ``v_max`` on every row (0: the base grid); None where fewer than
    four rows have A <= API_FAST. Kept for the last few (model, α E*) asked (a sweep of one
    fluid builds it once; a taller grid asked later is built again)."""
    x_lim = math.log(API_FAST / aE)
    xn = pr.xn
    j_lim = int(np.searchsorted(xn, x_lim, side="right"))  # rows with A <= API_FAST
    rows = min(xn.size, j_lim + 3)
    while rows > 0 and aE * math.exp(xn[rows - 1]) > A_ROW_MAX:
        rows -= 1
    if rows < 4 or j_lim < 1:
        return None
    z_need = pr.z0 + (pr.nz - 1) * pr.dz
    vinf_min = math.exp(float(np.min(pr.lnv[:rows])))
    if v_max > vinf_min:  # the highest start on the row of the smallest ū∞ and largest κ
        z_need = max(z_need, math.log(v_max / vinf_min - 1.0) + float(np.max(pr.lk[:rows])))
    key = (model.key(), float(aE))
    with _LOCK:
        hit = _MEMO.get(key)
        if hit is not None and hit.z_top >= z_need:
            _MEMO.move_to_end(key)
            return hit
    nz = pr.nz
    if z_need > pr.z0 + (nz - 1) * pr.dz:
        nz = int(math.ceil((z_need - pr.z0) / pr.dz)) + 2
    prr = refined_rows(pr, rows, aE)
    xg = prr.xn
    C = np.empty((xg.size, nz, 3))
    _build_kernel(prr, bt, c, float(aE), nz, C)
    rec = readonly_fields(Primitive(xg, *_index_map(xg), lagrange_denominators(xg), pr.z0, pr.dz,
                                    nz, C, prr.lnv, prr.lnS, prr.zs, prr.lk,
                                    math.inf, pr.c, pr.d))
    out = BarusTime(rec, float(min(x_fast, x_lim, xg[-1])), pr.z0 + (nz - 1) * pr.dz, aE)
    with _LOCK:
        _MEMO[key] = out
        _MEMO.move_to_end(key)
        while len(_MEMO) > _MEMO_SIZE:
            _MEMO.popitem(last=False)
    return out


#: spacing in x0 = ln(p0/E*) of the G primitive's rows where A = α p0 = API_FAST: G = T + A S
#: varies with x0 through A ∝ e^x0 as well, so that its 4-point Lagrange interpolation across
#: rows errs by ~ (A S/G) Δx⁴/40 — 1e-6 of the times at A = 0.6 on the base rows' widest
#: spacing (0.08-0.09 where σ̄ barely changes, low p0/E*), against 1e-9 for T itself. Rows are
#: inserted (by the base primitive's own interpolant) until Δx <= DX_G (API_FAST/A)^(1/4)
#: (error ∝ A Δx⁴ held below its value at DX_G, A = API_FAST: ~1e-8 of the times)
DX_G = 0.025


def refined_rows(pr, rows, aE):
    """The base primitive's first ``rows`` rows, with rows inserted where their spacing in x0
    exceeds DX_G (API_FAST/A)^(1/4) (A = α E* e^x0 at the interval's upper end): each inserted
    row is the base interpolant at its x0 (C, ln v∞, ln S, z of the default start and ln κ
    combined with the base stencil's weights), so that T on the refined rows is the base
    engine's T; only the correction A S is evaluated anew on them. A record with the fields
    ``xn, lnv, lnS, zs, lk, C`` and the base's z grid and tail (as :func:`_build_kernel`
    reads it), every array read-only (one compiled signature whether or not rows were
    inserted); the base rows themselves (as before) where none is inserted."""
    xn = pr.xn[:rows]
    A_hi = np.minimum(aE * np.exp(xn[1:]), A_ROW_MAX)
    dx_max = DX_G * (API_FAST / np.maximum(A_hi, 1e-300)) ** 0.25
    m = np.maximum(np.ceil(np.diff(xn) / dx_max).astype(np.int64), 1)
    fields = [np.ascontiguousarray(a[:rows]) for a in (pr.lnv, pr.lnS, pr.zs, pr.lk)]
    if np.all(m == 1):
        return readonly_fields(Primitive(
            np.ascontiguousarray(xn), 0.0, 0.0, np.zeros(0), np.zeros((0, 4)), pr.z0, pr.dz,
            pr.nz, np.ascontiguousarray(pr.C[:rows]), *fields, pr.v_ext, pr.c, pr.d))
    base = np.cumsum(np.concatenate(([0], m)))          # positions of the base rows
    nr = int(base[-1]) + 1
    xr = np.empty(nr)
    new = np.ones(nr, dtype=bool)
    new[base] = False
    j = np.repeat(np.arange(m.size), m - 1)             # the base interval of each new row
    k = np.arange(nr)[new] - base[j]                    # its place in the interval (1..m-1)
    xr[new] = xn[j] + (xn[j + 1] - xn[j]) * k / m[j]
    xr[base] = xn
    C = np.empty((nr, pr.nz, 3))
    C[base] = pr.C[:rows]
    lnv, lnS, zs, lk = (np.empty(nr) for _ in range(4))
    for out, a in zip((lnv, lnS, zs, lk), fields):
        out[base] = a
    _refined_kernel(pr, xr, np.flatnonzero(new), C, lnv, lnS, zs, lk)
    return readonly_fields(Primitive(xr, 0.0, 0.0, np.zeros(0), np.zeros((0, 4)), pr.z0,
                                     pr.dz, pr.nz, C, lnv, lnS, zs, lk, pr.v_ext, pr.c, pr.d))


@njit(parallel=True, cache=True)
def _refined_kernel(pr, xr, idx, C, lnv, lnS, zs, lk):
    """The inserted rows ``idx`` of :func:`refined_rows` (at x0 = xr[idx]): the base rows'
    stencil combination."""
    for ii in prange(idx.size):
        i = idx[ii]
        _refined_row(pr, xr[i], i, C, lnv, lnS, zs, lk)


@njit(cache=True)
def _refined_row(pr, x0, i, C, lnv, lnS, zs, lk):
    st = stencil(pr, x0)
    j0, w0, w1, w2, w3 = st
    lnv[i] = row_value(pr.lnv, st)
    lnS[i] = row_value(pr.lnS, st)
    zs[i] = row_value(pr.zs, st)
    lk[i] = row_value(pr.lk, st)
    B = pr.C
    for k in range(pr.nz):
        for q in range(3):
            C[i, k, q] = (w0 * B[j0, k, q] + w1 * B[j0 + 1, k, q] + w2 * B[j0 + 2, k, q]
                          + w3 * B[j0 + 3, k, q])


@njit(cache=True)
def _lnp_slope(bt, s):
    """d ln π_c/d ln v of the correction table's cubic Hermite of ln π_c at s = ln v (the
    derivative of the interpolant :func:`~._barus_primitive.s_cell` evaluates)."""
    sn = bt.xn
    i = _locate(bt, s)
    if i < 0:
        i = 0 if s < sn[0] else sn.size - 2
    h = sn[i + 1] - sn[i]
    t = (s - sn[i]) / h
    ST = bt.ST
    return ((6.0 * t * t - 6.0 * t) * (ST[i, 0] - ST[i + 1, 0]) / h
            + (3.0 * t * t - 4.0 * t + 1.0) * ST[i, 1] + (3.0 * t * t - 2.0 * t) * ST[i + 1, 1])


@njit(cache=True)
def _g_series(c, K, a):
    """(1/g(a), d(1/g)/da) of the truncated series 1/g = 1 + a P_K(a)."""
    p = 0.0
    dp = 0.0
    for k in range(K, -1, -1):
        dp = dp * a + p
        p = p * a + c[k]
    return 1.0 + a * p, p + a * dp


@njit(parallel=True, cache=True)
def _build_kernel(pr, bt, c, aE, nz, C):
    """ln G and its first two z-derivatives at every (row, node) of C (rows, nz, 3)."""
    for jj in prange(C.shape[0]):
        j = np.int64(jj)
        _build_row(pr, bt, c, aE, nz, j, C)


@njit(cache=True)
def _build_row(pr, bt, c, aE, nz, j, C):
    x0 = pr.xn[j]
    A = aE * math.exp(x0)
    K = series_order(c, A)
    if K < 0:
        K = K_MAX
    E = np.empty(K_MAX + 1)
    shift(c, A, K, E)
    vinf = math.exp(pr.lnv[j])
    lk = pr.lk[j]
    for k in range(nz):
        z = pr.z0 + k * pr.dz - lk  # ln(v/v∞ - 1)
        ez = math.exp(z)
        v = vinf * (1.0 + ez)
        if k < pr.nz:
            T = math.exp(pr.C[j, k, 0])
            L1, L2 = pr.C[j, k, 1], pr.C[j, k, 2]
        else:  # above the base grid: the closed-form flat-film tail (v >= v_ext here)
            y_ = v + pr.d
            T = qk._tail_int(pr.c, y_, math.inf)
            den = y_ * (y_ * y_ - pr.c)
            dT = -1.0 / den  # dT/dv
            d2T = (3.0 * y_ * y_ - pr.c) / (den * den)
            dv = vinf * ez  # dv/dz
            L1 = dT * dv / T
            L2 = (d2T * dv * dv + dT * dv) / T - L1 * L1
        s = math.log(v)
        S, y = s_at(bt, E, K, x0, v, s)
        a = A * (1.0 - y)
        ig, dig = _g_series(c, K, a)
        T1 = T * L1
        T2 = T * (L2 + L1 * L1)
        dy = 0.0 if y == 0.0 else y * _lnp_slope(bt, s) * (vinf * ez) / v
        G = T + A * S
        G1 = T1 * ig
        G2 = T2 * ig - T1 * A * dig * dy
        l1 = G1 / G
        C[j, k, 0] = math.log(G)
        C[j, k, 1] = l1
        C[j, k, 2] = G2 / G - l1 * l1


#: a call of several fluids or rubbers builds the G primitive of a group (the rows of one
#: α E*) of at least this many rows: a build costs 10-40 ms on 2 cores, what the per-case
#: kernel spends on 2-5e4 rows more than the base kernel (measured on the embedded road tables);
#: a smaller group runs the per-case kernel unless its primitive is kept from an earlier call.
#: A call of one fluid on one rubber always builds it (a study's later calls reuse it).
MIN_GROUP_ROWS = 20_000


def served_groups(model, setup, p, E, alpha, us_in, h):
    """([(BarusTime, indices of the rows it serves), ...], indices of the other rows) of Barus
    cases (p0 [Pa], E* [Pa], α [1/Pa], ū(0) [m] (NaN: the default start), one per row).

    Rows of one α E* form a group (G depends on α and E* through their product alone),
    served by that group's G primitive where it is built: a call of one group; a group of
    at least MIN_GROUP_ROWS rows, or one whose primitive is kept from an earlier call, at most
    _MEMO_SIZE per call, the largest first. The rows of
    α = 0 form one group whatever their E*, served by the constant-viscosity primitive itself
    (G = T: the base engine's numbers). Within a group the rows with ln(p0/E*) in the tables
    and at most its ``x_served`` and a finite start (or the default) are served; its grid is
    built to reach their highest start."""
    n = p.size
    every = np.arange(n)
    if n == 0:
        return [], every
    x0 = np.log(p / E)
    prod = alpha * E  # G depends on α and E* through α E* alone (0 exactly where α = 0)
    groups = [(float(prod[0]), every)] if prod.min() == prod.max() else _groups(model, prod)
    served, done = [], np.zeros(n, dtype=bool)
    for aE, rows in groups:
        bg, ok = _group_primitive(model, setup, aE, x0[rows], us_in[rows], h)
        if bg is not None and ok.any():
            served.append((bg, rows[ok]))
            done[rows[ok]] = True
    return served, every[~done]


def _groups(model, prod):
    """[(α E*, rows), ...] of a call of several α E* = ``prod`` (one per row): the rows of α = 0
    first, then the groups whose G primitive (of ``model``) is kept or which have at least
    MIN_GROUP_ROWS rows, the largest first, at most _MEMO_SIZE (:func:`served_groups`)."""
    out = []
    zero = prod == 0.0
    if zero.any():
        out.append((0.0, np.flatnonzero(zero)))
    idx = np.flatnonzero(~zero)
    if idx.size:
        mkey = model.key()
        with _LOCK:
            kept = [(k[1],) for k in _MEMO if k[0] == mkey]
        out += [(key[0], idx[rows]) for key, rows in
                row_groups([prod[idx]], MIN_GROUP_ROWS, _MEMO_SIZE, kept)]
    return out


def _group_primitive(model, setup, aE, x0, us_in, h):
    """(BarusTime or None, mask of the rows it serves) of one group: α E* = ``aE``, the rows'
    ln(p0/E*) ``x0`` and starts ``us_in`` [m]."""
    pr, bt, c, x_fast = setup
    x_hi = x_fast if aE == 0.0 else min(x_fast, math.log(API_FAST / aE))
    ok = (x0 >= model.mp.x_min) & (x0 <= x_hi) & ~(us_in == math.inf)
    if aE == 0.0:  # constant viscosity: the base primitive is G, its tail closed-form
        return BarusTime(pr, x_fast, math.inf, 0.0), ok
    if not ok.any():
        return None, ok
    v_s = us_in[ok] / h
    bg = barus_time(model, pr, bt, c, x_fast, aE,
                    float(np.max(v_s[np.isfinite(v_s)], initial=0.0)))
    if bg is None:
        return None, ok
    return bg, ok & (x0 <= bg.x_served)


def group_info(bg, rows, over=0):
    """Provenance of one group's G primitive (``rows`` served, ``over`` of them handed back to
    the per-case kernel)."""
    return {"alpha_E_star": bg.aE, "rows": int(bg.pr.xn.size), "z_nodes": int(bg.pr.nz),
            "max_ln_p0_over_E_star": bg.x_served, "cases_served": int(rows.size - over),
            "primitive": "constant viscosity (alpha_pv = 0)" if bg.aE == 0.0 else "Barus G"}


def _base_inputs(bg, cs, idx, every, ratios, dvs, times2d, h):
    """(cases, targets, row targets) of the base fast kernel for the rows ``idx`` of ``cs``
    (``every``: all rows, no copy), ratio targets ``ratios`` (without t_star's), Δu targets
    ``dvs`` [-] and times ``times2d`` [s] (rows × (1 or the rows))."""
    def sub(a):
        return a if a.size == 1 or every else readonly(np.ascontiguousarray(a[idx]))

    csg = qk.Cases(*(sub(a) for a in cs))
    if times2d.shape[1] > 1:  # one time per case: the served rows'
        times2d = readonly(sub(times2d[0]).reshape(1, -1))
    tg = readonly_fields(qk.Targets(np.ascontiguousarray(ratios, dtype=np.float64),
                                    np.ascontiguousarray(dvs, dtype=np.float64),
                                    np.ascontiguousarray(times2d)))
    us = csg.us
    shared = idx.size > 1 and (us.size == 1 or us.min() == us.max())
    return csg, tg, row_targets(bg.pr, tg.ratios, tg.dvs, us[0] / h if shared else math.nan)


def tire_rows(model, bg, cs, t_fp, h, ratios, dvs, quad, res, idx):
    """The Barus tire rows ``idx`` of the cases ``cs`` (:class:`~._kernels.Cases`, footprint
    times t_fp [s], size 0: no exit asked) by the base engine's fast kernel on the G primitive
    ``bg`` (:class:`BarusTime`), into ``res`` (:data:`~.tire_piezo.TireOut`): targets t_star,
    the ratios, Δu = dvs h_rms [m] (reduced ``dvs``), ū at the footprint exit."""
    ng = idx.size
    every = ng == res.u_inf.size  # every row: the kernel writes into res itself
    csg, tg, rt = _base_inputs(bg, cs, idx, every, ratios, dvs,
                               t_fp.reshape(1, -1) if t_fp.size else np.empty((0, 1)), h)
    if every:  # status codes: the base engine's names come first in the Barus tire's
        U = res.u_exit.reshape(1, -1) if t_fp.size else np.empty((0, ng))
        out = qk.SqOut(res.T, U, res.u_inf, res.u_start, np.empty(ng), res.u_trap,
                       np.empty(ng), res.flf, np.empty(ng), res.status)
        fast_kernel(model.tab, model.mp, bg.pr, rt, bg.x_served, *_NONE_TRAPPED(), csg, h, tg,
                    quad, out, False)
        if not t_fp.size:
            res.u_exit[:] = math.nan
        return
    out = qk.SqOut(np.empty((res.T.shape[0], ng)), np.empty((tg.times.shape[0], ng)),
                   *(np.empty(ng) for _ in range(7)), qk.new_status(ng))
    fast_kernel(model.tab, model.mp, bg.pr, rt, bg.x_served, *_NONE_TRAPPED(), csg, h, tg,
                quad, out, False)
    qk.check_computed(out.status, "tire_footprint(alpha_pv=...)")
    res.T[:, idx] = out.T
    res.u_exit[idx] = out.U[0] if t_fp.size else math.nan
    res.u_inf[idx] = out.u_inf
    res.u_start[idx] = out.u_start
    res.u_trap[idx] = out.u_trap
    res.flf[idx] = out.flf
    res.status[idx] = out.status


def run_rest(out, rest, run):
    """``run(sub, part)`` on the rows ``rest`` of the record ``out`` (arrays with the rows on
    their last axis) as a call of its own — ``sub(a)`` the rows' read-only copy of a case
    array, ``part`` a fresh record of ``out``'s shape for them — and its part written back."""
    part = type(out)(*(np.empty(a.shape[:-1] + (rest.size,), a.dtype) for a in out))
    if hasattr(part, "status"):  # unwritten rows stay visible to check_computed
        part.status[:] = qk.NOT_COMPUTED
    run(lambda a: readonly(np.ascontiguousarray(a[rest])), part)
    for a, b in zip(out, part):
        a[..., rest] = b


def squeeze_rows(model, bg, cs, tg, h, quad, out, idx):
    """The Barus squeeze-out rows ``idx`` of the cases ``cs`` by the base engine's fast kernel
    on the G primitive ``bg``, into ``out`` (:data:`~.viscosity.BarusOut`; ``tg`` its
    :data:`~.viscosity.BarusTargets`, t_star's ratio first): target times, ū at the times,
    ū∞, ū(0), τ0, the rate factor g at the start and the status. Returns the indices (into
    ``idx``'s rows) the base kernel flagged "overflow" (τ0 or a time not representable),
    which the Barus engine has no status for: the caller runs them by its per-case kernel."""
    from .model import DEFAULT_P_START
    from .viscosity import ST_BELOW, ST_OK

    ng = idx.size
    every = ng == out.u_inf.size  # every row: the kernel writes into out itself
    csg, tgb, rt = _base_inputs(bg, cs, idx, every, tg.ratios[1:], tg.dvs, tg.times[:, None], h)
    us = csg.us
    times2d = tgb.times
    code = qk.new_status(ng)
    if every:
        o = qk.SqOut(out.T, out.U, out.u_inf, out.u_start, np.empty(ng), np.empty(ng),
                     np.empty(ng), np.empty(ng), out.tau0, code)
        gs = out.g_start
    else:
        o = qk.SqOut(np.empty((out.T.shape[0], ng)), np.empty((times2d.shape[0], ng)),
                     *(np.empty(ng) for _ in range(7)), code)
        gs = np.empty(ng)
    fast_kernel(model.tab, model.mp, bg.pr, rt, bg.x_served, *_NONE_TRAPPED(), csg, h, tgb,
                quad, o, True)
    qk.check_computed(code, "squeeze_out(alpha_pv=...)")  # before the codes become statuses
    # the default start is where p_cont = DEFAULT_P_START p0: y there needs no table
    y_default = DEFAULT_P_START if np.isnan(us).all() else -1.0
    status = out.status if every else np.empty(ng, dtype=np.int8)
    # α = 0 (the base primitive): g = 1 exactly from _rate_factor(0), no table
    gx = default_rate_table(bg, y_default) if y_default >= 0.0 and bg.aE > 0.0 else _NO_TABLE
    _g_start_kernel(model.barus_table()[0], bg.aE, csg.p0, csg.E, o.u_start, h, y_default, gx,
                    code, np.int8(ST_OK), np.int8(ST_BELOW), gs, status)
    if not every:
        out.T[:, idx] = o.T
        out.U[:, idx] = o.U
        out.u_inf[idx] = o.u_inf
        out.u_start[idx] = o.u_start
        out.tau0[idx] = o.tau0
        out.g_start[idx] = gs
        out.status[idx] = status
    return np.flatnonzero((code != qk.ST_OK) & (code != qk.ST_BELOW))


@njit(parallel=True, cache=True)
def _g_start_kernel(bt, aE, p0, E, u_start, h, y_default, gx, code, st_ok, st_below, gs,
                    status):
    """Per row (p0 [Pa] and E* [Pa] one per row or one for all, ū(0) [m] and the base
    kernel's status ``code``): g(α p0 (1 - y)), y = π_c(v_s)/π0 at the start v_s = ū(0)/h
    (``y_default`` >= 0: every start the default one, y = y_default, g read from ``gx`` =
    (x_first, dx, g at x_first + k dx...) of :func:`default_rate_table`, 4-point Lagrange in
    x0) into gs, NaN where the start is at or below ū∞; the Barus engine's status
    (``st_ok`` / ``st_below``) into ``status``."""
    n = u_start.size
    for b in prange((n + 255) // 256):
        _g_start_rows(bt, aE, p0, E, u_start, h, y_default, gx, code, st_ok, st_below, gs,
                      status, b * 256, min(b * 256 + 256, n))


@njit(cache=True)
def _g_start_rows(bt, aE, p0, E, u_start, h, y_default, gx, code, st_ok, st_below, gs, status,
                  b0, b1):
    sp = 1 if p0.size > 1 else 0
    sE = 1 if E.size > 1 else 0
    m = gx.size - 2
    for i in range(b0, b1):
        if code[i] == qk.ST_BELOW:
            gs[i] = math.nan
            status[i] = st_below
            continue
        status[i] = st_ok
        r = p0[i * sp] / E[i * sE]
        x0 = math.log(r)
        if y_default >= 0.0 and m >= 4:
            u = (x0 - gx[0]) / gx[1]
            k = int(u) - 1
            if k < 0:
                k = 0
            if k > m - 4:
                k = m - 4
            t = u - k
            a0, a1, a2, a3 = t, t - 1.0, t - 2.0, t - 3.0
            gs[i] = (-a1 * a2 * a3 / 6.0 * gx[2 + k] + a0 * a2 * a3 / 2.0 * gx[3 + k]
                     - a0 * a1 * a3 / 2.0 * gx[4 + k] + a0 * a1 * a2 / 6.0 * gx[5 + k])
            continue
        y = y_default
        if y < 0.0:
            vs = u_start[i] / h
            y = 0.0
            if vs < bt.v_ext:
                y = math.exp(s_cell(bt, math.log(vs))[5] - x0)
        gs[i] = _rate_factor(aE * r * (1.0 - y))


#: nodes per unit of ln(p0/E*) of :func:`default_rate_table`: the cubic Lagrange error is
#: ~h⁴/40 times g's fourth derivative in ln p0, which is O(1) for α p0 <= 0.6 (~1e-12)
RATE_TABLE_DENSITY = 512


def default_rate_table(bg, y):
    """(x_first, dx, g at x_first + k dx, k = 0...) for :func:`_g_start_kernel`: the rate
    factor at the default start g(α E* e^x (1 - y)) on a uniform grid over the x0 = ln(p0/E*)
    the G primitive ``bg`` serves (one ``_rate_factor`` per row was as long as the kernel's
    whole default-start case); kept on ``bg``."""
    key = float(y)
    hit = bg.rate_tables.get(key)
    if hit is not None:
        return hit
    lo, hi = float(bg.pr.xn[0]) - 0.01, bg.x_served + 0.01
    m = max(8, int(math.ceil((hi - lo) * RATE_TABLE_DENSITY)) + 1)
    x = np.linspace(lo, hi, m)
    g = np.empty(m)
    _rate_factor_array(bg.aE * np.exp(x) * (1.0 - y), g)
    out = readonly(np.concatenate(([lo, (hi - lo) / (m - 1)], g)))
    bg.rate_tables[key] = out
    return out
