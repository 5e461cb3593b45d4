"""Squeeze-out with a pressure-dependent (Barus) viscosity η = η0 exp(α p_f) on the tables.

The flat block of radius R squeezes a film of uniform mean separation ū (paper Secs. 2–3,
eqs. 17–19). With η(p_f) the local flux is J = -(σ0/e^{α p_f}) ∇p_f = -σ0 ∇ψ, where σ0 is
the conductivity at η0 and ψ = (1 - e^{-α p_f})/α is the reduced pressure. Mass
conservation (dū/dt uniform) makes ψ parabolic, ψ = ψ0 (1 - r²/R²), ψ0 = -ū̇ R²/(4σ0), and
the mean fluid pressure is a closed form of b = α ψ0 (docs/theory/extensions.md, §2):

    α p̄_f = Φ(b) = 1 + (1 - b) ln(1 - b)/b,        Φ(b) → b/2 (α → 0), Φ(1) = 1.

With the force balance p̄_f = p0 - p_cont(ū) (eq. 19) the squeeze rate becomes

    dū/dt = -(8 σ0 / R²) (p0 - p_cont) g(a),   a = α (p0 - p_cont),   g(a) = Φ⁻¹(a)/(2a),

i.e. the paper's rate (18)+(19) times a factor g ∈ (1/2, 1] (g = 1 - 2a/3 + O(a²)). So a
rigid flat block at most *doubles* the squeeze-out time; for a ≥ 1 the fluid cannot carry
the load at all (the Barus centre pressure diverges at b = 1 while p̄_f stays 1/α): the
quasi-static rigid-block model fails there (elastohydrodynamic deformation or inertia take
over) and such rows are flagged ``piezo_limit`` with NaN times — never a silent number.

References: C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87;
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
import pandas as pd
from numba import njit, prange

from .._core.owned import own
from .._core.validate import check_positive
from .._core.vocab import DEFAULT_THEORY, column_name
from .api import register_extension, squeeze_out
from .model import squeeze_model
from ..kernels.quadrature import gauss_legendre
from ..kernels.records import scalar_record
from ..kernels.readonly import readonly, readonly_fields
from ._kernels import (Cases, Quad, check_computed, kink_w, new_status, reduced_time,
                       state_gap, trapped_quad)
from ._kernels import _lnv_of_lnp as qk_lnv_of_lnp
from ._kernels import _state as qk_state

__all__ = [
    "DEFAULT_P_START",
    "barus_mean_pressure",
    "barus_rate_factor",
    "squeeze_out_piezo",
]

#: default start, as in :func:`fastcontact.squeeze.squeeze_out`: p_cont(u_start) = 1e-3 p0
DEFAULT_P_START = 1e-3
ST_OK, ST_TRAPPED, ST_OUT, ST_PIEZO, ST_BELOW, ST_OVERFLOW = 0, 1, 2, 3, 4, 5
#: readable ``status`` of each code (ST_*; "overflow" is set after the kernels,
#: :func:`flag_overflow`)
STATUS = ("ok", "trapped", "out_of_table", "piezo_limit", "start_below_equilibrium", "overflow")
#: the exit search stops this far below ln(ū(0) − ū∞) (ū is then ū∞ to round-off)
W_SPAN = 60.0
#: targets shared by all cases: ratios ū/ū∞ (t_star's 1.01 first, then the ratio targets) [-],
#: dvs = Δu/h_rms of the Δu targets [-] and times [s] of the ū(t) outputs
BarusTargets = namedtuple("BarusTargets", "ratios dvs times")
#: outputs of :func:`squeeze_out_piezo`, one column per case: T (nt, n) target times [s],
#: U (n_times, n) ū at the times [m], u_inf, u_start [m], tau0 [s], g_start (rate factor at
#: the start) [-], status (int8)
BarusOut = namedtuple("BarusOut", "T U u_inf u_start tau0 g_start status")


# =========================================================================== closed forms
def barus_mean_pressure(psi0, alpha):
    """Mean fluid pressure p̄_f [Pa] under the block for centre reduced pressure ψ0 [Pa].

    ``p̄_f = [1 + (1 - b) ln(1 - b)/b]/α``, b = α ψ0 ∈ [0, 1) (ψ0 → p̄_f = ψ0/2 as α → 0).
    """
    psi0 = np.asarray(psi0, dtype=np.float64)
    alpha = float(alpha)
    if alpha == 0.0:
        return 0.5 * psi0
    b = alpha * psi0
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = 1.0 + (1.0 - b) * np.log1p(-b) / b
        small = np.abs(b) < 1e-4
        phi = np.where(small, b / 2 + b * b / 6 + b ** 3 / 12 + b ** 4 / 20, phi)
    return np.where(b < 1.0, phi / alpha, np.nan)[()]


#: the rate factor's table: q(s) = c/s on s = -ln(1 - a) ∈ [0, G_SMAX], step G_H, where
#: c = -ln(1 - b) solves c/expm1(c) = 1 - a (b = Φ⁻¹(a)); q is smooth (2 at s = 0, → 1 for
#: large s) and every a < 1 in float64 has s < 37
G_H = 1.0 / 64.0
G_SMAX = 40.0


def _q_table():
    """q(s_k) = c(s_k)/s_k at s_k = k G_H (NumPy, at import, ~1 ms): Newton in c on
    s(c) = ln(expm1(c)/c), whose derivative e^c/expm1(c) - 1/c lies in (1/2, 1)."""
    s = np.arange(1, int(round(G_SMAX / G_H)) + 6) * G_H  # s = 0 is the limit q = 2
    c = np.where(s < 1.0, 2.0 * s, s + np.log1p(s))
    for _ in range(60):
        em = np.expm1(c)
        c = c - (np.log(em / c) - s) / ((em + 1.0) / em - 1.0 / c)
    return np.ascontiguousarray(np.concatenate(([2.0], c / s)))


_G_Q = _q_table()


@njit(cache=True)
def _rate_factor(a):
    """g(a) = Φ⁻¹(a)/(2a) for a = α p̄_f in [0, 1); NaN for a >= 1 (piezoviscous limit).

    With s = -ln(1 - a) and c = -ln(1 - b): c/expm1(c) = 1 - a, c = s q(s), q from the table
    ``_G_Q`` by 6-point Lagrange interpolation (relative error of g 7e-14 at most against a
    40-digit solve, tested to 1e-12; a Newton solve per call cost ~10x more and lost ~4e-11 to
    cancellation at small a),
    g = -expm1(-c)/(2a); a < 1e-5: the series 1 - 2a/3 + 2a²/9.
    """
    if a < 0.0:
        return math.nan
    if a < 1e-5:
        return 1.0 - 2.0 * a / 3.0 + 2.0 * a * a / 9.0
    if a >= 1.0:
        return math.nan
    s = -math.log1p(-a)
    u = s / G_H
    k0 = int(u) - 2
    if k0 < 0:
        k0 = 0
    # Lagrange weights w_j = Π_{i≠j} (u - k0 - i) / Π_{i≠j} (j - i): prefix and suffix
    # products of the six factors, and the constant denominators' inverses
    d0 = u - k0
    f0, f1, f2, f3, f4, f5 = d0, d0 - 1.0, d0 - 2.0, d0 - 3.0, d0 - 4.0, d0 - 5.0
    p01 = f0 * f1
    p012 = p01 * f2
    s45 = f4 * f5
    s345 = f3 * s45
    q = (-1.0 / 120.0) * (f1 * f2 * s345) * _G_Q[k0]
    q += (1.0 / 24.0) * (f0 * f2 * s345) * _G_Q[k0 + 1]
    q += (-1.0 / 12.0) * (p01 * s345) * _G_Q[k0 + 2]
    q += (1.0 / 12.0) * (p012 * s45) * _G_Q[k0 + 3]
    q += (-1.0 / 24.0) * (p012 * f3 * f5) * _G_Q[k0 + 4]
    q += (1.0 / 120.0) * (p012 * f3 * f4) * _G_Q[k0 + 5]
    return -math.expm1(-s * q) / (2.0 * a)


@njit(cache=True)
def _rate_factor_array(a, out):
    for i in range(a.size):
        out[i] = _rate_factor(a[i])


def barus_rate_factor(a):
    """Rate factor g(a) ∈ (1/2, 1] of the squeeze-out with a Barus fluid [-].

    ``a = α_pv (p0 - p_cont)`` [-] is the Barus number of the mean fluid pressure; the
    squeeze rate is the constant-viscosity rate times g (module docstring). NaN for a ≥ 1.
    """
    a = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
    out = np.empty(a.size)
    _rate_factor_array(a.ravel(), out)
    return out.reshape(a.shape)[()]


# =========================================================================== kernels
@njit(cache=True)
def _state(tab, sc, v):
    """(ln π_c, σ̄) at v = ū/h_rms: the constant-viscosity model's state (tables; above the
    top the eq. (3) tail and the σ̄ tail fitted to the tables' direct samples)."""
    return qk_state(tab, sc[0], v)


@njit(cache=True)
def _lnv_of_lnp(tab, sc, x):
    """ln v with π_c(v) = e^x: the constant-viscosity model's inverse (the record carries the
    same x_min, v_top, u0 as its ModelPar)."""
    return qk_lnv_of_lnp(tab, sc[0], x)


@njit(cache=True)
def _start(tab, sc, x0, u_start, h):
    """(v∞, v_start) = (ū∞, ū_start)/h_rms at ln(p0/E*) = x0; u_start [m] NaN: the default
    start, where p_cont = DEFAULT_P_START·p0."""
    vinf = math.exp(_lnv_of_lnp(tab, sc, x0))
    vs = u_start / h
    if vs != vs:
        vs = math.exp(_lnv_of_lnp(tab, sc, x0 + math.log(DEFAULT_P_START)))
    return vinf, vs


@njit(cache=True)
def _case_start(tab, sc, x0, cs, h, i, out):
    """:func:`_start` of case i, also stored [m] into ``out.u_inf[i]`` and ``out.u_start[i]``."""
    vinf, vs = _start(tab, sc, x0, cs.us[i], h)
    out.u_inf[i] = vinf * h
    out.u_start[i] = vs * h
    return vinf, vs


@njit(cache=True)
def _integrand(tab, sc, x0, api, vinf, w):
    """dt̃/dw at w = ln(v - v∞): (v - v∞)/(σ̄ d g(api d)), d = 1 - π_c/π0; inf where σ̄ = 0
    or the denominator underflows (numba raises ZeroDivisionError on x/0)."""
    e = math.exp(w)
    sig, d = state_gap(tab, sc[0], x0, vinf, e)  # as the constant-viscosity quadrature
    if not (sig > 0.0):
        return math.inf
    d = max(1e-300, d)
    g = _rate_factor(api * d) if api > 0.0 else 1.0
    den = sig * d * g  # underflows to 0 where π_c/π0 rounds to 1 next to ū∞ (tiny σ̄)
    return e / den if den > 0.0 else math.inf


@njit(cache=True)
def _segment(tab, sc, x0, api, vinf, w1, w2, quad):
    """∫_{w1}^{w2} dt̃/dw dw, composite Gauss–Legendre (``quad``), panels of width <= width,
    broken at the tables' last open node where it lies inside (:func:`~._kernels.kink_w`: σ̄'s
    slope jumps there; as the constant-viscosity quadrature)."""
    wk = kink_w(tab, vinf)
    if w1 < wk < w2:
        return (_segment_plain(tab, sc, x0, api, vinf, w1, wk, quad)
                + _segment_plain(tab, sc, x0, api, vinf, wk, w2, quad))
    return _segment_plain(tab, sc, x0, api, vinf, w1, w2, quad)


@njit(cache=True)
def _segment_plain(tab, sc, x0, api, vinf, w1, w2, quad):
    """:func:`_segment` without the break."""
    glx, glw, width = quad.glx, quad.glw, quad.width
    if not (w2 > w1):
        return 0.0
    m = max(1, int(math.ceil((w2 - w1) / width)))
    hw = (w2 - w1) / m
    s = 0.0
    for k in range(m):
        mid = w1 + (k + 0.5) * hw
        for j in range(glx.size):
            s += 0.5 * hw * glw[j] * _integrand(tab, sc, x0, api, vinf, mid + 0.5 * hw * glx[j])
    return s


@njit(cache=True)
def trap_floor_v(tab, sc, x0):
    """v_trap, the separation where π_c reaches the trap pressure (σ̄ = 0 at and below it), for
    a trapped row (x0 >= x_trap); NaN otherwise."""
    x_trap = sc[0].x_trap
    return math.exp(_lnv_of_lnp(tab, sc, x_trap)) if x0 >= x_trap else math.nan


@njit(cache=True)
def _trapped_target_times(tab, sc, x0, api, vinf, vb, vs, tau, tg, quad, T, i):
    """:func:`_target_times` of a trapped row (floor vb = v_trap): w = ln(v - v_trap), where
    the integrand stays finite down to v_trap (in ln(v - v∞) the panels ran into σ̄ = 0 at
    v_trap unresolved: times to targets just above ū_trap were up to 17 % off, 2026-12-04);
    targets at or below v_trap, or every target of a start at or below it, never reached
    (inf), targets at or above the start 0."""
    vt_ratio = tg.ratios
    nt = T.shape[0]
    nr = vt_ratio.size
    q = trapped_quad(quad)
    wts = np.empty(nt)
    vts = np.empty(nt)
    for k in range(nt):
        vts[k] = vt_ratio[k] * vinf if k < nr else vinf + tg.dvs[k - nr]
        wts[k] = math.log(vts[k] - vb) if vts[k] > vb else -math.inf
    order = np.argsort(-wts)
    w_cur = math.log(vs - vb) if vs > vb else -math.inf
    t_cur = 0.0
    for kk in range(nt):
        k = order[kk]
        if vts[k] >= vs:
            T[k, i] = 0.0
            continue
        if not (vts[k] > vb and vs > vb):
            T[k, i] = math.inf
            continue
        if wts[k] < w_cur:
            t_cur += _segment(tab, sc, x0, api, vb, wts[k], w_cur, q)
            w_cur = wts[k]
        T[k, i] = tau * t_cur


@njit(cache=True)
def v_at_time(tab, sc, x0, api, vinf, vb, vs, tt, quad):
    """v at the reduced time tt from the start vs (vb = v_trap on a trapped row, else NaN): the
    start at tt = 0 or where it lies at or below v_trap; ū∞ (v_trap on a trapped row) at
    tt = inf; else :func:`exit_w` on w = ln(v - v∞), or ln(v - v_trap) on a trapped row."""
    trapped = vb == vb
    if tt == 0.0 or (trapped and not (vs > vb)):
        return vs
    vr = vb if trapped else vinf
    if tt == math.inf:
        return vr
    q = trapped_quad(quad) if trapped else quad
    return vr + math.exp(exit_w(tab, sc, x0, api, vr, math.log(vs - vr), tt, q))


@njit(cache=True)
def _target_times(tab, sc, x0, api, vinf, vb, vs, tau, tg, quad, T, i):
    """Times [s] from v_start down to each target of ``tg`` (:data:`BarusTargets`) into
    column i of T: one downward pass over the targets in descending order; 0 for targets
    passed (a trapped row, vb = :func:`trap_floor_v` not NaN: :func:`_trapped_target_times`)."""
    if vb == vb:
        _trapped_target_times(tab, sc, x0, api, vinf, vb, vs, tau, tg, quad, T, i)
        return
    vt_ratio = tg.ratios
    vt_dv = tg.dvs
    nt = T.shape[0]
    nr = vt_ratio.size
    # targets as w = ln(v - v∞): a Δu target is ln Δu exactly, even below the resolution of
    # v∞ (v∞ + Δu == v∞ in float64 gave ln 0 = -inf and t = inf, unflagged)
    wts = np.empty(nt)
    for k in range(nt):
        wts[k] = math.log(vt_ratio[k] * vinf - vinf) if k < nr else math.log(vt_dv[k - nr])
    order = np.argsort(-wts)
    w_s = math.log(vs - vinf)
    w_cur = w_s
    t_cur = 0.0
    for kk in range(nt):
        k = order[kk]
        wt = wts[k]
        if wt >= w_s:
            T[k, i] = 0.0
            continue
        if wt < w_cur:
            t_cur += _segment(tab, sc, x0, api, vinf, wt, w_cur, quad)
            w_cur = wt
        T[k, i] = tau * t_cur


@njit(cache=True)
def exit_w(tab, sc, x0, api, vinf, w0, target, quad):
    """w = ln(v − v∞) reached after reduced time ``target`` from w0 (-inf: beyond W_SPAN)."""
    width = quad.width
    t = 0.0
    w = w0
    while w > w0 - W_SPAN:
        wn = w - width
        dt = _segment(tab, sc, x0, api, vinf, wn, w, quad)
        if t + dt >= target:
            lo = wn
            hi = w
            y = 0.5 * (lo + hi)
            for _ in range(100):
                f = t + _segment(tab, sc, x0, api, vinf, y, w, quad) - target
                if f > 0.0:
                    lo = y
                else:
                    hi = y
                dtdw = _integrand(tab, sc, x0, api, vinf, y)
                yn = y + f / dtdw if 0.0 < dtdw < math.inf else 0.5 * (lo + hi)
                if not (lo < yn < hi):
                    yn = 0.5 * (lo + hi)
                if abs(yn - y) <= 1e-14 * max(1.0, abs(y)) or hi - lo <= 1e-14 * max(1.0, abs(y)):
                    return yn
                y = yn
            return y
        t += dt
        w = wn
    return -math.inf


@njit(cache=True, inline="always")
def _case_head(cs, sc, h, i):
    """(x0 = ln(p0/E*), τ0 = 3ηR²/(2 h_rms² p0) [s], x0 within the tables) of case i."""
    x0 = math.log(cs.p0[i] / cs.E[i])
    tau = 3.0 * cs.eta[i] * cs.R[i] * cs.R[i] / (2.0 * h * h * cs.p0[i])
    return x0, tau, sc[0].x_min <= x0 <= sc[0].x_max


@njit(cache=True)
def _no_times(out, i, status):
    """Row i of ``out`` (:data:`BarusOut`) gets ``status``, NaN target times and NaN ū(t)."""
    out.status[i] = status
    for k in range(out.T.shape[0]):
        out.T[k, i] = math.nan
    for k in range(out.U.shape[0]):
        out.U[k, i] = math.nan


@njit(cache=True)
def _piezo_case(tab, sc, cs, alpha, h, tg, quad, i, out):
    """Case i of :func:`_piezo_kernel` into row/column i of ``out`` (:data:`BarusOut`).

    Stores go through this (non-parallel) helper: a store made inside a prange body into an
    array taken from a record argument is silently lost (numba 0.6x parfor lowering)."""
    x0, tau, inside = _case_head(cs, sc, h, i)
    out.tau0[i] = tau
    if not inside:
        _no_times(out, i, np.int64(ST_OUT))
        out.u_inf[i] = math.nan
        out.u_start[i] = cs.us[i]
        out.g_start[i] = math.nan
        return
    vinf, vs = _case_start(tab, sc, x0, cs, h, i, out)
    if not (vs * h > vinf * h):  # a given start at or below ū∞ (as reported, SI)
        _no_times(out, i, np.int64(ST_BELOW))
        out.g_start[i] = math.nan
        return
    api = alpha[i] * cs.p0[i]
    lnps, _s = _state(tab, sc, vs)
    d_start = -math.expm1(lnps - x0)
    out.g_start[i] = _rate_factor(api * d_start) if api > 0.0 else 1.0
    if api * d_start >= 1.0:
        _no_times(out, i, np.int64(ST_PIEZO))
        return
    vb = trap_floor_v(tab, sc, x0)
    _target_times(tab, sc, x0, api, vinf, vb, vs, tau, tg, quad, out.T, i)
    for k in range(tg.times.size):
        # inf: ū∞, or ū_trap on a trapped row (as the base engine; no walk of W_SPAN panels)
        out.U[k, i] = v_at_time(tab, sc, x0, api, vinf, vb, vs, reduced_time(tg.times[k], tau),
                                quad) * h
    # last (a failing worker thread stops without raising: the row keeps NOT_COMPUTED)
    out.status[i] = ST_TRAPPED if x0 >= sc[0].x_trap else ST_OK


@njit(parallel=True, cache=True)
def _piezo_kernel(tab, sc, cs, alpha, h, tg, quad, out):
    """Per case (``cs`` :class:`~fastcontact.squeeze._kernels.Cases`, α [1/Pa] apart): targets
    (ratios × v∞, then v∞ + dv) sorted downward, one pass (t̃ → SI) into ``out``
    (:data:`BarusOut`)."""
    for i in prange(cs.p0.size):  # the index as int64, as the fast path's blocks pass it
        _piezo_case(tab, sc, cs, alpha, h, tg, quad, np.int64(i), out)


def flag_overflow(status, tau0, T, st_ok, st_trapped, st_overflow):
    """Status ``st_overflow`` (in place) on the computed rows whose τ0 [s] or a target time [s]
    is not representable: τ0 = 3ηR²/(2 h_rms² p0) outside (0, inf) (e.g. R = 1e-300 m or
    1e308 m: the times are then 0 or inf as numbers, meaningless as results), or an infinite
    time on an "ok" row (a trapped row's targets below ū_trap are inf by the physics). As the
    base engine's status "overflow"."""
    live = (status == st_ok) | (status == st_trapped)
    bad = live & ~((tau0 > 0.0) & (tau0 < np.inf))
    if T.size:
        bad |= (status == st_ok) & np.isinf(T).any(axis=0)
    status[bad] = st_overflow


# =========================================================================== model
_SC_CACHE = {}


def _scalars(tables, theory, sigma_trap):
    """The scalar record of (tables, theory): the table range, the tail above its top and the
    trap (one record, so that the kernels read them by name).

    Fields: x_min, x_max = ln π of the tables' ends [-]; v_top = ū/h_rms at the table top [-];
    u0 = -dv/d ln π there (eq. (3) tail) [-]; x_trap = ln π
    above which σ̄ is below the trap floor (inf: never) [-]; d, cn, g1..g5: the squeeze
    model's σ̄ tail above the top (:data:`~fastcontact.squeeze.model.ModelPar`) [-].
    """
    key = (id(tables), tables.surface.fingerprint(), theory, sigma_trap,
           repr(tables.info.get("tail")), repr(sorted(tables.options.items())))
    if key in _SC_CACHE:
        return _SC_CACHE[key]
    p_lo, p_hi = tables.p_range
    x_min, x_max = math.log(p_lo), math.log(p_hi)
    d = 1e-4
    v = tables.mean_separation(np.array([p_lo, p_lo * math.exp(d)]), 1.0) / tables.h_rms
    u0 = (v[0] - v[1]) / d
    floor = float(tables.info.get("sigma_floor", 1e-24) if sigma_trap is None else sigma_trap)
    perc = tables.info["percolation_p_over_E"][theory]
    x_trap = math.inf
    if np.isfinite(perc):
        hi = min(math.log(perc), x_max)
        if float(tables.sigma_bar(math.exp(hi), 1.0, theory)) < floor:
            lo = x_min
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                if float(tables.sigma_bar(math.exp(mid), 1.0, theory)) >= floor:
                    lo = mid
                else:
                    hi = mid
            x_trap = hi
        elif math.log(perc) <= x_max:
            x_trap = math.log(perc)
    mp = squeeze_model(tables, theory).mp
    sc = scalar_record({"x_min": x_min, "v_top": v[0], "u0": u0,
                        "x_trap": x_trap, "x_max": x_max, "d": mp.d, "cn": mp.cn, "g1": mp.g1,
                        "g2": mp.g2, "g3": mp.g3, "g4": mp.g4, "g5": mp.g5})
    _SC_CACHE[key] = sc
    return sc


def squeeze_out_piezo(tables, *, p0, E_star, R, eta, alpha_pv, theory=DEFAULT_THEORY,
                      u_start=None, ratios=(1.1, 1.01, 1.001), du=(), times=(),
                      method="fast", quad_order=10, quad_width=1.0, sigma_trap=None):
    """Squeeze-out times of a flat block with a Barus fluid η = η0 exp(α_pv p_f) [s].

    Parameters
    ----------
    tables : Tables
        Precomputed tables of the rough surface holding ``theory``.
    p0, E_star, R, eta : array_like
        Squeezing pressure [Pa], effective modulus [Pa], block radius [m] and the viscosity
        η0 at the outlet (ambient) pressure [Pa·s]; broadcast against each other.
    alpha_pv : array_like
        Pressure–viscosity coefficient α [1/Pa], >= 0 (0: the paper's constant viscosity).
    theory : str, default DEFAULT_THEORY ("critical_junction")
        Flow theory of σ_eff ("average", "critical_junction", "emt").
    u_start : array_like or None
        Initial separation [m]; None: where p_cont = 1e-3 p0 (as :func:`squeeze_out`).
    ratios, du : sequence
        Targets ū/ū∞ > 1 (columns ``t_ratio_<r>``) and ū - ū∞ [m] (``t_du_<Δu>``).
    times : sequence of float, default ()
        Times [s] >= 0 (inf allowed) → columns ``u_at_<t>``: ū at that time [m] (ū(0) =
        u_start; ū∞, or ū_trap on a trapped row, as t → ∞).
    method : {"fast", "quad"}, default "fast"
        "fast": the rows of one α E* run the base engine's kernel on the Barus time
        primitive G = T + α p0 S built for them (:mod:`._barus_time`, ~5-40 ms, kept for the
        last eight): every row of a call of one fluid on one rubber, the groups of at least
        20,000 rows (or with a kept primitive) of a call of several, and the rows of α = 0
        (the constant-viscosity primitive itself) — at the base engine's speed; other rows
        take two interpolations of the constant-viscosity time primitive plus the tabulated
        Barus correction per time (:mod:`._barus_primitive`, built once per tables and
        theory in ~5-20 ms); rows neither serves (α p0 > 0.6, p0 within 4.4 % of
        the trap pressure or beyond, outside the tables) take the per-case quadrature in the
        same pass. "quad": the per-case quadrature for every row.
    quad_order, quad_width :
        Gauss–Legendre order and panel width in w = ln(ū - ū∞) [-] of the quadrature (on a
        trapped row w = ln(ū - ū_trap), where the integrand stays finite down to ū_trap, and
        a third of the width: within 1e-6 of the Reynolds reference).
    sigma_trap : float, optional
        Reduced conductivity below which σ is treated as 0 (default the tables' floor).

    Returns
    -------
    pandas.DataFrame
        Inputs, ``u_start``, ``u_inf`` [m], ``t_star`` (ū = 1.01 ū∞) and target times [s],
        ``tau0`` [s], ``barus_number`` = α p0 [-], ``rate_factor_start`` g at the start [-],
        flags ``piezo_limit`` (α(p0 - p_cont) >= 1 at the start: NaN times), ``trapped``
        (p0 beyond the trap pressure: targets below ū_trap take inf), ``out_of_table``,
        ``status`` ("ok", "trapped", "out_of_table", "piezo_limit", "start_below_equilibrium":
        a given ``u_start`` at or below ū∞, NaN times and rate factor; "overflow": τ0 or a
        time not representable in float64, e.g. R = 1e-300 m; the other rows are computed).

    Notes
    -----
    Exact reduction of the radial Reynolds equation with η(p) (module docstring); the
    time is the quadrature t = ∫ dū/|dū/dt| in ln(ū - ū∞) as in the base engine.
    """
    from ..tables import Tables
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables")
    tables._need(theory)
    p0 = check_positive("p0", p0, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    R = check_positive("R", R, "[m]")
    eta = check_positive("eta", eta, "[Pa·s]")
    alpha_pv = check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True)
    us = np.array(np.nan) if u_start is None else check_positive("u_start", u_start, "[m]",
                                                                    allow_inf=False)
    ratios, du, qo, width = _check_targets(ratios, du, quad_order, quad_width)
    method = _check_method_name(method)
    times = np.ascontiguousarray(np.atleast_1d(np.asarray(
        check_positive("times", times, "[s]", allow_zero=True, allow_inf=True)
        if np.size(times) else np.empty(0), dtype=np.float64)).ravel())
    shape = np.broadcast(p0, E_star, R, eta, alpha_pv, us).shape
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape).ravel(), dtype=np.float64)
            for a in (p0, E_star, R, eta, alpha_pv, us)]
    n = flat[0].size
    h = float(tables.h_rms)
    sc = _scalars(tables, theory, sigma_trap)
    vr = np.ascontiguousarray(np.concatenate(([1.01], ratios)))
    dv = np.ascontiguousarray(du / h)
    T = np.empty((vr.size + dv.size, n))
    U = np.empty((times.size, n))
    uinf, ustart, tau0, gs = (np.empty(n) for _ in range(4))
    status = new_status(n)
    x, w = gauss_legendre(qo)
    cs = readonly_fields(Cases(flat[0], flat[1], flat[2], flat[3], flat[5]))
    al = readonly(flat[4])
    tg = readonly_fields(BarusTargets(vr, dv, times))
    quad, out = Quad(x, w, width), BarusOut(T, U, uinf, ustart, tau0, gs, status)
    served = None
    if method == "fast":
        served = _fast_rows(tables, theory, sigma_trap, sc, cs, al, h, tg, quad, out)
    else:
        _piezo_kernel(tables.kernel_data(theory), sc, cs, al, h, tg, quad, out)
    check_computed(status, "squeeze_out(alpha_pv=...)")
    flag_overflow(status, tau0, T, ST_OK, ST_TRAPPED, ST_OVERFLOW)
    df = _piezo_frame(flat, ratios, du, times, T, U, uinf, ustart, tau0, gs, status, theory,
                      method)
    if method == "fast":
        df.attrs["barus_correction"] = fast_info(tables, theory, sigma_trap)
        df.attrs["barus_time_primitive"] = served
    return df


def _fast_rows(tables, theory, sigma_trap, sc, cs, al, h, tg, quad, out):
    """method "fast": the rows a time primitive serves (the rows of one α E* of a call:
    :func:`._barus_time.served_groups`, the base engine's kernel on their G primitive), the
    others by the per-case Barus kernel (:func:`._barus_fast.squeeze_kernel`), into ``out``
    (:data:`BarusOut`). Returns the provenance of each group's primitive (None where no row
    was served)."""
    from ._barus_fast import ratio_rows, squeeze_kernel
    from ._barus_time import group_info, run_rest, served_groups, squeeze_rows
    setup = fast_setup(tables, theory, sigma_trap)
    model = squeeze_model(tables, theory, sigma_trap)
    groups, rest = served_groups(model, setup, cs.p0, cs.E, al, cs.us, h)
    info = []
    for bg, gi in groups:
        over = squeeze_rows(model, bg, cs, tg, h, quad, out, gi)
        if over.size:
            rest = np.concatenate((rest, gi[over]))
        info.append(group_info(bg, gi, over.size))
    rest = np.sort(rest)

    def per_case(sub, part):
        squeeze_kernel(tables.kernel_data(theory), sc, *setup, Cases(*(sub(a) for a in cs)),
                       sub(al), h, tg, *ratio_rows(*setup[:3], tg), quad, part, fast_scratch())
    if rest.size == cs.p0.size:
        per_case(lambda a: a, out)
    elif rest.size:  # the others as a call of their own
        run_rest(out, rest, per_case)
    return info if any(g["cases_served"] for g in info) else None


def fast_setup(tables, theory, sigma_trap):
    """(primitive, Barus table, series coefficients, largest ln(p0/E*) served) of the fast
    path for (tables, theory)."""
    from ._barus_primitive import h_coefficients
    from .primitive import fast_limit
    model = squeeze_model(tables, theory, sigma_trap)
    pr = model.primitive()
    bt, _info = model.barus_table()
    return pr, bt, h_coefficients(), float(fast_limit(model))


def fast_info(tables, theory, sigma_trap):
    """Provenance of the fast path's Barus correction: its nodes, series limits and the
    measured interpolation error of S (:func:`._barus_primitive.build`)."""
    info = squeeze_model(tables, theory, sigma_trap).barus_table()[1]
    return {k: info[k] for k in ("nodes", "k_max", "api_fast", "max_rel_err_S",
                                 "checked_cells")}


def fast_scratch():
    """Per-thread scratch rows of the fast kernels' series coefficients."""
    from numba import config
    from ._barus_primitive import K_MAX
    return np.empty((config.NUMBA_NUM_THREADS, K_MAX + 1))


def _check_method_name(method):
    if method not in ("fast", "quad"):
        raise ValueError(f"method = {method!r} is invalid: must be 'fast' or 'quad'")
    return method


def _check_targets(ratios, du, quad_order, quad_width):
    """(ratios, du [m], quadrature order, panel width) of :func:`squeeze_out_piezo`, checked."""
    ratios = np.atleast_1d(np.asarray(ratios, dtype=np.float64)).ravel()
    if ratios.size and not np.all(np.isfinite(ratios) & (ratios > 1.0)):
        raise ValueError(f"ratios = {ratios.tolist()!r} is invalid: every ratio must be a "
                         f"finite number > 1 [-]")
    du = np.atleast_1d(np.asarray(du, dtype=np.float64)).ravel()
    if du.size:
        check_positive("du", du, "[m]")
    qo = int(quad_order)
    if not 2 <= qo <= 64:
        raise ValueError(f"quad_order = {quad_order!r} is invalid: must be an integer in [2, 64]")
    width = float(check_positive("quad_width", quad_width, "[-]"))
    return ratios, du, qo, width


def _piezo_frame(flat, ratios, du, times, T, U, uinf, ustart, tau0, gs, status, theory,
                 method):
    """The result DataFrame of :func:`squeeze_out_piezo` from the kernel outputs."""
    cols = {"p0": own(flat[0]), "E_star": own(flat[1]), "R": own(flat[2]),
            "eta": own(flat[3]), "alpha_pv": own(flat[4]), "u_start": ustart, "u_inf": uinf,
            "t_star": T[0]}
    for k, r in enumerate(ratios):
        cols[column_name("t_ratio", r)] = T[1 + k]
    for k, d in enumerate(du):
        cols[column_name("t_du", d)] = T[1 + ratios.size + k]
    for k, t in enumerate(times):
        cols[column_name("u_at", t)] = U[k]
    cols.update({"tau0": tau0, "barus_number": flat[4] * flat[0], "rate_factor_start": gs,
                 "piezo_limit": status == ST_PIEZO, "trapped": status == ST_TRAPPED,
                 "out_of_table": status == ST_OUT,
                 "status": pd.Categorical.from_codes(status, categories=list(STATUS))})
    df = pd.DataFrame(cols, copy=False)
    units = {"p0": "Pa", "E_star": "Pa", "R": "m", "eta": "Pa s", "alpha_pv": "1/Pa",
             "u_start": "m", "u_inf": "m", "tau0": "s", "barus_number": "1",
             "rate_factor_start": "1"}
    units.update({c: "s" for c in cols if c.startswith("t_")})
    units.update({c: "m" for c in cols if c.startswith("u_at_")})
    df.attrs.update({"units": units, "theory": theory, "viscosity": "Barus", "method": method,
                     "model": "dū/dt = -(8σ0/R²)(p0-p_cont) g(α(p0-p_cont)), "
                              "g = Φ⁻¹(a)/(2a), Φ(b) = 1 + (1-b)ln(1-b)/b",
                     "references": ["doi:10.2475/ajs.s3-45.266.87",
                                    "arXiv:1004.1037"]})
    return df


# =========================================================================== hook
def _squeeze_hook(tables, kw, alpha_pv):
    """``squeeze_out(..., alpha_pv=α)``: α = 0 everywhere → the base engine (unchanged
    output); otherwise :func:`squeeze_out_piezo` (target times and ``u_at`` columns)."""
    a = check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True)
    rest = {k: v for k, v in kw.items() if k != "alpha_pv"}
    if not np.any(a):
        return squeeze_out(tables, **rest)
    return squeeze_out_piezo(tables, p0=rest["p0"], E_star=rest["E_star"], R=rest["R"],
                             eta=rest["eta"], alpha_pv=a, theory=rest.get("theory", "average"),
                             u_start=rest.get("u_start"), ratios=rest.get("ratios", (1.1, 1.01, 1.001)),
                             du=rest.get("du", ()), times=rest.get("times", ()),
                             method=rest.get("method", "fast"),
                             quad_order=rest.get("quad_order", 10),
                             quad_width=rest.get("quad_width", 1.0),
                             sigma_trap=rest.get("sigma_trap"))


register_extension("alpha_pv", _squeeze_hook)
