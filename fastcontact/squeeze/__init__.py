"""Fluid squeeze-out between a flat cylindrical block and a rough substrate (SPEC §4, paper
Secs. 2–3) on precomputed :class:`~fastcontact.tables.Tables` — millions of cases per call.

Physics
-------
Stefan–Reynolds flow out of a block of radius R with the force balance p_cont + p̄_f = p0
(paper eqs. 17–19):

    dū/dt = -(8 σ_eff(p_cont) / R²) (p0 - p_cont(ū)).

Reduced units: v = ū/h_rms, π = p/E*, σ̄ = 12ησ_eff/h_rms³ (eq. 23). With
``τ0 = 3ηR²/(2 h_rms² p0)`` [s] (the paper's τ of eq. 6 with α = 1) and t = τ0 t̃,

    dv/dt̃ = -σ̄(π_c(v)) (1 - π_c(v)/π0).

The right-hand side depends on v only, so the time is a quadrature (never time stepping):
``t̃(v_a → v_b) = ∫_{v_b}^{v_a} dv / (σ̄ (1 - π_c/π0))``. Equilibrium: π_c(v∞) = π0.
Near it the approach is exponential with the e-folding time
``t_relax = τ0 · v∞ |d ln ū/d ln p|/σ̄(π0)`` (= R²u_0/(8σ_eff p0) of the paper, with the
local decay length u_0 = |dū/d ln p|); far from it algebraic (ū ∝ t^{-1/2}, Stefan).

Model details (decisions, all documented in the result's ``attrs``)
-----------------------------------------------------------------
* **p_cont(ū)** is the tables' inverse interpolation ``k_lnp_of_lnu``; ū∞ (and every
  target separation) is made *consistent* with it (Newton on that same function), so
  1 - π_c/π0 vanishes exactly at ū∞ and the log singularity is clean.
* **Above the table top** (ū > ū_top ≈ 32 h_rms) the analytic large-separation tail is
  used: ``π_c = π_top exp(-(v - v_top)/u0)`` (eq. 3, u0 = the tables' local decay length at
  the top) and ``σ̄ = v³(1 - c/v²)`` with c matched to σ̄ at the top (continuous; c = 0 for
  "average" where σ̄ = v³ exactly; ≈ +1.5 for "emt", i.e. φ_p ≈ 1 - (3/2)(h/ū)², SPEC §3;
  slightly negative for "critical_junction", whose u1(ζc) exceeds ū). Leading order σ̄ = v³
  is exact (paper Sec. 3); the c term is the first correction. Beyond
  v_ext = v_top + 40 u0 the contact pressure is < e^{-40} π_top and the integral
  ∫dv/(v³ - cv) is done in closed form, so ``u_start`` may be anything up to +inf.
* **Trapped fluid.** σ̄ of critical junction / EMT vanishes exactly at the percolation
  pressure π_perc, but collapses super-exponentially before it; below σ̄ ≈ 1e-24 the tables
  do not resolve σ̄ (their refinement floor ``info["sigma_floor"]``) and the remaining
  approach would take > ~1e20 τ0. The criterion used: **the conductivity is set to zero
  where σ̄ < σ_trap** (default ``σ_trap = info["sigma_floor"]`` = 1e-24), i.e. at
  π ≥ π_trap with σ̄(π_trap) = σ_trap (π_trap < π_perc by a few percent). If
  π_trap ≤ π0 the film stops at ū_trap = ū(π_trap) > ū∞ after the finite (astronomically
  long) time ``t_trap``; times to any target below ū_trap are +inf; the fluid keeps the
  load fraction 1 - π_trap/π0. Rows with π_trap ≤ π0 < π_perc (where the exact theory
  would still leak, over > 1e20 τ0) are flagged ``percolated = False, trapped = True``.
  "average" never percolates (σ̄ = v³ > 1e-24 everywhere in the table).
* **Default start** ``u_start = None``: the separation where p_cont = 1e-3 p0 (the fluid
  carries 99.9 % of the load; the same rule as :mod:`fastcontact.reduced`). It is
  κ-independent in the paper's variable p_cont/p0 (its eq. 7 integrates p_cont), and it is
  always defined — above the table top it lies on the analytic tail — whereas "the table
  top" (≈ 32 h_rms) would make t* depend on how the table was built.
* **Out of table**: p0/E* outside the tables' p̄ range gives ``out_of_table = True`` and
  NaN in every computed column (no exception: one bad row must not sink a million).
  Invalid inputs (non-positive, non-finite, u_start ≤ ū∞) raise ``ValueError`` naming the
  parameter.

Numerics
--------
Two engines, one pass over all cases each (``@njit(parallel=True)``, prange):

``method="quad"``  per case, composite Gauss–Legendre in w = ln(v - v∞) (order
    ``quad_order``, panel width ``quad_width`` in w); the substitution turns the log
    divergence at equilibrium into a flat integrand over a finite range.
``method="fast"`` (default)  per (tables, theory) and per target (each ratio, each Δu) a
    1-D not-a-knot cubic spline in x0 = ln(p0/E*) of the *normalised* time
    ``t̃(start → target)/S(x0)``, S = v∞|d ln v/d ln π|/σ̄ (the relaxation time in τ0), plus
    splines of ln S, ln v∞ and ln v_start. Nodes are uniform in ξ = ln π0 - ln σ̄(π0) (dense
    where σ̄ collapses); node values come from the quad engine at high order. A case then
    costs one O(1) interval lookup and one Horner polynomial per column. The π0-dependence
    of the time lives in 1/(π0 - π_c), so a generic 1-D primitive cannot carry it; but the
    targets (ratios, Δu) and the default start are fixed per call, so each target's time is
    a function of π0 alone. Rows the spline cannot serve (user ``u_start``, trapped rows,
    p0 within one node of the trap) fall back to the quad engine inside the same kernel,
    and so do all rows when ``times`` is given. Structures are built lazily and cached per
    (tables, theory, target): ~0.3 s per target on 2 cores, ~2000 nodes.

``u_at_<t>`` columns and :func:`squeeze_history` invert t̃(v) per case by safeguarded
Newton in w with incremental Gauss–Legendre integration (tens of µs per time point).
"""
from __future__ import annotations

import math
import threading
import time as _clock
import weakref

import numpy as np
import pandas as pd
from numba import njit, prange

from .._core.validate import as_float_array, check_positive
from ..kernels.locate import build_bucket_map, locate_asc
from ..tables import k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp

__all__ = ["squeeze_out", "squeeze_history", "squeeze_model", "DEFAULT_P_START",
           "QUAD_ORDER", "QUAD_WIDTH", "FAST_DXI"]

#: default start: p_cont(u_start) = DEFAULT_P_START * p0
DEFAULT_P_START = 1e-3
#: default per-case Gauss–Legendre order and panel width in w = ln(v - v∞) (method="quad")
QUAD_ORDER = 10
QUAD_WIDTH = 1.0
#: order / width used to compute the spline nodes of the fast path (GL6, width 1 already
#: agrees with the direct reference to ~1e-9; see bench/squeeze_results.md)
NODE_ORDER = 20
NODE_WIDTH = 0.25
#: spacing of the fast-path spline nodes in ξ = ln π0 - ln σ̄(π0) (see bench/bench_squeeze.py)
FAST_DXI = 0.05
#: extent of the analytic tail above the table top, in units of u0 (π drops by e^-40)
TAIL_EXTENT = 40.0

# par vector layout
P_XMIN, P_XMAX, P_VTOP, P_U0, P_C, P_XTRAP, P_VEXT, P_XPERC, P_VTRAP, P_LNPST, P_D = range(11)
N_PAR = 11

# status codes
ST_OK, ST_TRAPPED, ST_OUT = 0, 1, 2


# =========================================================================== numba core
@njit(cache=True)
def _state(tab, par, v):
    """(ln π_c, σ̄) at separation v [h_rms]: tables, or the analytic tail above v_top."""
    v_top = par[P_VTOP]
    if v > v_top:
        y = v + par[P_D]
        return par[P_XMIN] - (v - v_top) / par[P_U0], y * (y * y - par[P_C])
    lnp = k_lnp_of_lnu(tab, math.log(v))
    if lnp != lnp:
        return lnp, math.nan
    if lnp >= par[P_XTRAP]:
        return lnp, 0.0
    return lnp, k_sigma_of_lnp(tab, lnp)


@njit(cache=True)
def _lnv_of_lnp(tab, par, x):
    """ln v with π_c(v) = e^x exactly for the model's p_cont(v) (Newton on k_lnp_of_lnu)."""
    if x <= par[P_XMIN]:
        return math.log(par[P_VTOP] + par[P_U0] * (par[P_XMIN] - x))
    y = k_lnu_of_lnp(tab, x)
    if y != y:
        return y
    hh = 1e-6
    for _ in range(6):
        f = k_lnp_of_lnu(tab, y) - x
        if f == 0.0:
            break
        fp = k_lnp_of_lnu(tab, y + hh)
        fm = k_lnp_of_lnu(tab, y - hh)
        if fp == fp and fm == fm:
            slope = (fp - fm) / (2.0 * hh)
        elif fp == fp:
            slope = (fp - (f + x)) / hh
        else:
            slope = ((f + x) - fm) / hh
        if not (slope < 0.0):
            break
        step = f / slope
        y -= step
        if abs(step) < 1e-15:
            break
    return y


@njit(cache=True)
def _dlnv_dlnp(tab, par, x):
    """|d ln v / d ln π| of the model's p_cont(v) at ln π = x (central difference)."""
    hh = 1e-6
    if x + hh > par[P_XMAX]:
        return abs(_lnv_of_lnp(tab, par, x) - _lnv_of_lnp(tab, par, x - hh)) / hh
    if x - hh < par[P_XMIN]:
        return abs(_lnv_of_lnp(tab, par, x + hh) - _lnv_of_lnp(tab, par, x)) / hh
    return abs(_lnv_of_lnp(tab, par, x + hh) - _lnv_of_lnp(tab, par, x - hh)) / (2.0 * hh)


@njit(cache=True)
def _dtdw(tab, par, x0, vb, w):
    """dt̃/dw at w = ln(v - vb): (v - vb) / (σ̄ (1 - π_c/π0)); 0 where σ̄ = 0 (trapped)."""
    e = math.exp(w)
    lnp, sig = _state(tab, par, vb + e)
    if not (sig > 0.0):
        return 0.0
    d = -math.expm1(lnp - x0)
    if d <= 1e-300:
        d = 1e-300
    return e / (sig * d)


@njit(cache=True)
def _seg(tab, par, x0, vb, w1, w2, glx, glw, width):
    """∫_{w1}^{w2} dt̃/dw dw, composite Gauss–Legendre, panels of width <= width."""
    if not (w2 > w1):
        return 0.0
    m = int(math.ceil((w2 - w1) / width))
    if m < 1:
        m = 1
    hw = (w2 - w1) / m
    s = 0.0
    for k in range(m):
        mid = w1 + (k + 0.5) * hw
        acc = 0.0
        for j in range(glx.size):
            acc += glw[j] * _dtdw(tab, par, x0, vb, mid + 0.5 * hw * glx[j])
        s += acc * 0.5 * hw
    return s


@njit(cache=True)
def _tail_int(c, a, b):
    """∫_a^b dv/(v³ - c v) (b may be inf) — the σ̄ tail with π_c/π0 negligible."""
    ia2 = 1.0 / (a * a)
    ib2 = 0.0 if b == math.inf else 1.0 / (b * b)
    if abs(c) * ia2 < 1e-6:
        return (0.5 * (ia2 - ib2) + 0.25 * c * (ia2 * ia2 - ib2 * ib2)
                + c * c / 6.0 * (ia2 * ia2 * ia2 - ib2 * ib2 * ib2))
    lb = 0.0 if b == math.inf else math.log1p(-c * ib2)
    return (lb - math.log1p(-c * ia2)) / (2.0 * c)


@njit(cache=True)
def _time(tab, par, x0, vb, v_lo, v_hi, glx, glw, width):
    """t̃ to go from v_hi (may be inf) down to v_lo > vb."""
    if not (v_hi > v_lo):
        return 0.0
    total = 0.0
    v_ext = par[P_VEXT]
    if v_hi > v_ext:
        a = v_lo if v_lo > v_ext else v_ext
        total += _tail_int(par[P_C], a + par[P_D], v_hi + par[P_D])
        if v_lo >= v_ext:
            return total
        v_hi = v_ext
    return total + _seg(tab, par, x0, vb, math.log(v_lo - vb), math.log(v_hi - vb), glx, glw,
                        width)


@njit(cache=True)
def _v_at_time(tab, par, x0, vb, v_floor, vs, t_prev, w_prev, t_target, glx, glw, width):
    """Solve t̃(vs → v) = t_target for v (vb < v_floor <= v <= vs), continuing from the
    previous solution (t_prev at w_prev = ln(v_prev - vb)). Returns (v, t_reached, w).

    Safeguarded Newton in w with incremental quadrature; v_floor is v∞ (→ returned for
    t = inf) or v_trap (→ returned once t̃ >= the trap time)."""
    if t_target <= t_prev:
        return vb + math.exp(w_prev), t_prev, w_prev
    w = w_prev
    t = t_prev
    if v_floor > vb:
        w_min = math.log(v_floor - vb)
    else:
        w_min = math.log(vb * 1e-13 + 1e-300)
    for _ in range(200):
        g = _dtdw(tab, par, x0, vb, w)
        rem = t_target - t
        if g > 0.0:
            step = rem / g
        else:
            step = 1.0
        if step > 2.0:
            step = 2.0
        wn = w - step
        if wn < w_min:
            wn = w_min
        dt = _seg(tab, par, x0, vb, wn, w, glx, glw, width)
        if t + dt > t_target and wn < w - 1e-15:
            # overshoot: shrink until inside (monotone: halve the step)
            lo_w = wn
            hi_w = w
            for _k in range(100):
                g = _dtdw(tab, par, x0, vb, w)
                step = (t_target - t) / g if g > 0.0 else 0.5 * (hi_w - lo_w)
                wc = w - step
                if not (lo_w < wc < hi_w):
                    wc = 0.5 * (lo_w + hi_w)
                dtc = _seg(tab, par, x0, vb, wc, w, glx, glw, width)
                if t + dtc > t_target:
                    lo_w = wc
                else:
                    hi_w = wc
                    t += dtc
                    w = wc
                if abs(t - t_target) <= 1e-14 * t_target or hi_w - lo_w < 1e-14:
                    return vb + math.exp(w), t, w
            return vb + math.exp(w), t, w
        t += dt
        w = wn
        if abs(t - t_target) <= 1e-14 * t_target:
            break
        if w <= w_min:
            # floor reached: trapped (v_trap reached in finite time) or v∞ to precision
            return v_floor if v_floor > vb else vb, t_target, w
    return vb + math.exp(w), t, w


@njit(cache=True)
def _case(tab, par, x0, vs_in, ratios, dvs, times_s, tau, h, glx, glw, width, i, T, U, uinf,
          ustart, trelax, utrap, ttrap, flf, status):
    """Everything for one case, written in SI to column i of the outputs.

    Reduced internally (v in h_rms, t̃ in τ0 = tau); T[k, i]: time to target k (k = 0: t*,
    then ``ratios``, then ``dvs`` in h_rms); U[k, i]: ū at ``times_s[k]`` (ascending)."""
    nt = T.shape[0]
    nu = U.shape[0]
    if not (par[P_XMIN] <= x0 <= par[P_XMAX]):
        for k in range(nt):
            T[k, i] = math.nan
        for k in range(nu):
            U[k, i] = math.nan
        uinf[i] = math.nan
        ustart[i] = vs_in * h
        trelax[i] = math.nan
        utrap[i] = math.nan
        ttrap[i] = math.nan
        flf[i] = math.nan
        status[i] = ST_OUT
        return
    vinf = math.exp(_lnv_of_lnp(tab, par, x0))
    vs = vs_in
    if vs != vs:  # default start: p_cont(v_start) = DEFAULT_P_START p0
        vs = math.exp(_lnv_of_lnp(tab, par, x0 + par[P_LNPST]))
    trapped = x0 >= par[P_XTRAP]
    uinf[i] = vinf * h
    ustart[i] = vs * h
    if trapped:
        vb = par[P_VTRAP]
        status[i] = ST_TRAPPED
        utrap[i] = vb * h
        flf[i] = -math.expm1(par[P_XTRAP] - x0)
        trelax[i] = math.nan
    else:
        vb = vinf
        status[i] = ST_OK
        utrap[i] = math.nan
        flf[i] = 0.0
        trelax[i] = tau * vinf * _dlnv_dlnp(tab, par, x0) / k_sigma_of_lnp(tab, x0)
    # targets: one downward pass from the start, segment by segment (sorted by separation)
    nr = ratios.size
    vts = np.empty(nt)
    for k in range(nt):
        if k == 0:
            vts[k] = 1.01 * vinf
        elif k <= nr:
            vts[k] = ratios[k - 1] * vinf
        else:
            vts[k] = vinf + dvs[k - 1 - nr]
    order = np.argsort(-vts)
    v_cur = vs
    t_cur = 0.0
    for kk in range(nt):
        k = order[kk]
        vt = vts[k]
        if vt >= vs:
            T[k, i] = 0.0
        elif trapped and (vt <= vb or vs <= vb):
            T[k, i] = math.inf
        else:
            if vt < v_cur:
                t_cur += _time(tab, par, x0, vb, vt, v_cur, glx, glw, width)
                v_cur = vt
            T[k, i] = tau * t_cur
    # trap time: finite (σ̄ >= σ_trap down to v_trap); below w_lo = ln(v_trap) - 30 the
    # integrand is e^w × const (relative change O(1e-13)), added in closed form
    t_trap = math.inf
    if trapped:
        if vs <= vb:
            t_trap = 0.0
        else:
            w_lo = math.log(vb) - 30.0
            t_trap = (_dtdw(tab, par, x0, vb, w_lo)
                      + _time(tab, par, x0, vb, vb + math.exp(w_lo), vs, glx, glw, width))
    ttrap[i] = tau * t_trap
    tp = 0.0
    wp = math.log(vs - vb) if vs > vb else -math.inf
    for k in range(nu):
        tk = times_s[k] / tau
        if vs <= vb:
            U[k, i] = vs * h
        elif tk == math.inf or (trapped and tk >= t_trap):
            U[k, i] = vb * h
        else:
            v, tp, wp = _v_at_time(tab, par, x0, vb, vb, vs, tp, wp, tk, glx, glw, width)
            U[k, i] = v * h


@njit(parallel=True, cache=True)
def _quad_kernel(tab, par, p0, E, R, eta, us, h, ratios, dvs, times_s, glx, glw, width, T, U,
                 uinf, ustart, trelax, utrap, ttrap, flf, tau0, status):
    """method="quad": every case by per-case quadrature (one prange pass)."""
    for i in prange(p0.size):
        tau = 3.0 * eta[i] * R[i] * R[i] / (2.0 * h * h * p0[i])
        tau0[i] = tau
        _case(tab, par, math.log(p0[i] / E[i]), us[i] / h, ratios, dvs, times_s, tau, h, glx,
              glw, width, i, T, U, uinf, ustart, trelax, utrap, ttrap, flf, status)


@njit(cache=True)
def _horner(C, j, s, d):
    """Spline s of the packed coefficients C[interval, spline, power] at offset d."""
    return ((C[j, s, 0] * d + C[j, s, 1]) * d + C[j, s, 2]) * d + C[j, s, 3]


@njit(parallel=True, cache=True)
def _fast_kernel(tab, par, p0, E, R, eta, us, h, ratios, dvs, times_s, glx, glw, width, xn, blo,
                 bdz, bidx, C, T, U, uinf, ustart, trelax, utrap, ttrap, flf, tau0, status):
    """method="fast": default-start, non-trapped, in-table rows from the splines (C packs,
    per interval, ln S, ln v∞, ln v_start and t̃/S of every target: one or two cache lines
    per case); all other rows (user u_start, trapped, out of table, or any u_at column) by
    the quad engine."""
    nt = T.shape[0]
    x_lo = xn[0]
    x_hi = xn[xn.size - 1]
    use_spline = times_s.size == 0
    for i in prange(p0.size):
        x0 = math.log(p0[i] / E[i])
        tau = 3.0 * eta[i] * R[i] * R[i] / (2.0 * h * h * p0[i])
        tau0[i] = tau
        if use_spline and us[i] != us[i] and x_lo <= x0 <= x_hi:
            j = locate_asc(x0, xn, blo, bdz, bidx)
            d = x0 - xn[j]
            tS = tau * math.exp(_horner(C, j, 0, d))
            for k in range(nt):
                T[k, i] = tS * _horner(C, j, 3 + k, d)
            uinf[i] = h * math.exp(_horner(C, j, 1, d))
            ustart[i] = h * math.exp(_horner(C, j, 2, d))
            trelax[i] = tS
            utrap[i] = math.nan
            ttrap[i] = math.inf
            flf[i] = 0.0
            status[i] = ST_OK
        else:
            _case(tab, par, x0, us[i] / h, ratios, dvs, times_s, tau, h, glx, glw, width, i, T,
                  U, uinf, ustart, trelax, utrap, ttrap, flf, status)


@njit(parallel=True, cache=True)
def _node_kernel(tab, par, xs, ratios, dvs, glx, glw, width, T, uinf, ustart, trelax):
    """Spline node values (reduced units): the quad engine at high order, default start."""
    n = xs.size
    tt = np.empty(0)
    U = np.empty((0, n))
    utrap = np.empty(n)
    ttrap = np.empty(n)
    flf = np.empty(n)
    status = np.empty(n, dtype=np.int8)
    for i in prange(n):
        _case(tab, par, xs[i], math.nan, ratios, dvs, tt, 1.0, 1.0, glx, glw, width, i, T, U,
              uinf, ustart, trelax, utrap, ttrap, flf, status)


# =========================================================================== model setup
_GL_CACHE = {}


def _gl(n):
    n = int(n)
    if n not in _GL_CACHE:
        x, w = np.polynomial.legendre.leggauss(n)
        _GL_CACHE[n] = (np.ascontiguousarray(x), np.ascontiguousarray(w))
    return _GL_CACHE[n]


class SqueezeModel:
    """The per-(tables, theory) model: kernel tuple, scalar parameters, fast-path splines."""

    def __init__(self, tables, theory, sigma_trap=None):
        t_start = _clock.perf_counter()
        self.tables = weakref.proxy(tables)
        self.theory = theory
        self.h_rms = float(tables.h_rms)
        tab = tables.kernel_data(theory)
        self.tab = tab
        p_lo, p_hi = tables.p_range
        x_min, x_max = math.log(p_lo), math.log(p_hi)
        self.sigma_trap = float(tables.info.get("sigma_floor", 1e-24) if sigma_trap is None
                                else sigma_trap)
        ev_u = _ev_lnu(tab, np.array([x_min, x_min + 1e-4]))
        v_top = math.exp(ev_u[0])
        u0 = -(math.exp(ev_u[1]) - v_top) / 1e-4          # -dv/dln p at the top
        # tail σ̄ = y³ - c y, y = v + d: value and slope matched to the table at the top
        hx = 1e-4
        sg = _ev_sig(tab, np.array([x_min, x_min + hx, x_min + 2 * hx]))
        sig_top = float(sg[0])
        dlns_dx = (-3.0 * math.log(sg[0]) + 4.0 * math.log(sg[1]) - math.log(sg[2])) / (2 * hx)
        s1 = sig_top * dlns_dx / (-u0)                    # dσ̄/dv at the top
        y = v_top
        for _ in range(100):                              # 2y³ - s1 y + σ̄ = 0 near v_top
            f = 2 * y ** 3 - s1 * y + sig_top
            dy = f / (6 * y * y - s1)
            y -= dy
            if abs(dy) < 1e-15 * y:
                break
        d = y - v_top
        c = 3 * y * y - s1
        if not (abs(d) < 0.1 * v_top and abs(c) < 0.1 * y * y):   # fall back: value only
            d, c = 0.0, v_top ** 2 - sig_top / v_top
        perc = tables.info["percolation_p_over_E"][theory]
        x_perc = math.log(perc) if np.isfinite(perc) else math.inf
        x_trap = self._find_trap(tab, x_min, x_max, x_perc)
        par = np.zeros(N_PAR)
        par[P_XMIN], par[P_XMAX], par[P_VTOP], par[P_U0], par[P_C] = x_min, x_max, v_top, u0, c
        par[P_XTRAP], par[P_VEXT], par[P_XPERC] = x_trap, v_top + TAIL_EXTENT * u0, x_perc
        par[P_LNPST] = math.log(DEFAULT_P_START)
        par[P_D] = d
        par[P_VTRAP] = math.nan
        if np.isfinite(x_trap):
            par[P_VTRAP] = math.exp(_ev_lnv_consistent(tab, par, np.array([x_trap]))[0])
        self.par = par
        self.x_min, self.x_max, self.x_trap, self.x_perc = x_min, x_max, x_trap, x_perc
        self.v_top, self.u0, self.c_tail, self.d_tail = v_top, u0, c, d
        self._fast = None
        self._targets = {}
        self._lock = threading.Lock()
        self.setup_seconds = _clock.perf_counter() - t_start

    def _find_trap(self, tab, x_min, x_max, x_perc):
        """ln π where σ̄ falls to sigma_trap (bisection on the tables' σ̄); inf if never."""
        if not np.isfinite(x_perc):
            return math.inf  # "average": σ̄ = v³ exactly, no percolation, nothing to floor
        hi = min(x_perc, x_max)
        s_hi = float(_ev_sig(tab, np.array([hi]))[0])
        if s_hi >= self.sigma_trap:
            return math.inf if not np.isfinite(x_perc) or x_perc > x_max else x_perc
        lo = x_min
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if float(_ev_sig(tab, np.array([mid]))[0]) >= self.sigma_trap:
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-15:
                break
        return hi

    # ------------------------------------------------------------------ fast path
    def _fast_nodes(self, dxi=FAST_DXI):
        """x0 nodes uniform in ξ = x - ln σ̄(x) on [x_min, x_trap) (x_max if no trap)."""
        if self._fast is not None:
            return self._fast
        x_hi = self.x_trap if np.isfinite(self.x_trap) else self.x_max
        if np.isfinite(self.x_trap):
            x_hi = self.x_trap - 1e-9
        xs = np.linspace(self.x_min, x_hi, 40001)
        sig = _ev_sig(self.tab, xs)
        xi = xs - np.log(sig)
        xi = np.maximum.accumulate(xi)
        n = max(int(math.ceil((xi[-1] - xi[0]) / dxi)) + 1, 8)
        xi_n = np.linspace(xi[0], xi[-1], n)
        xn = np.interp(xi_n, xi, xs)
        xn[0], xn[-1] = self.x_min, x_hi
        xn = np.unique(xn)
        vals = self._node_values(xn, np.zeros(0), np.zeros(0))
        self._fast = {
            "xn": np.ascontiguousarray(xn), "bucket": build_bucket_map(xn, ascending=True),
            "lnS": _spline(xn, np.log(vals["S"])), "lnv": _spline(xn, np.log(vals["vinf"])),
            "lnvs": _spline(xn, np.log(vals["vs"])), "dxi": dxi, "S": vals["S"],
        }
        self._targets[("ratio", 1.01)] = _spline(xn, vals["T"][0] / vals["S"])
        return self._fast

    def _node_values(self, xs, ratios, dvs, order=NODE_ORDER, width=NODE_WIDTH):
        """Reduced quad-engine results at x0 = xs (default start): T (targets × nodes), S..."""
        n = xs.size
        glx, glw = _gl(order)
        T = np.empty((1 + ratios.size + dvs.size, n))
        uinf, ustart, trelax = np.empty(n), np.empty(n), np.empty(n)
        _node_kernel(self.tab, self.par, np.ascontiguousarray(xs, dtype=np.float64),
                     np.ascontiguousarray(ratios, dtype=np.float64),
                     np.ascontiguousarray(dvs, dtype=np.float64), glx, glw, float(width), T,
                     uinf, ustart, trelax)
        return {"T": T, "vinf": uinf, "vs": ustart, "S": trelax}

    def packed(self, targets):
        """Coefficients (intervals, 3 + len(targets), 4): ln S, ln v∞, ln v_start, then t̃/S
        of each target — C order, so one case reads one contiguous block."""
        key = tuple(targets)
        cache = self.__dict__.setdefault("_packed", {})
        if key not in cache:
            fast = self._fast_nodes()
            parts = [fast["lnS"], fast["lnv"], fast["lnvs"]] + [self.target_coef(k, v)
                                                                 for k, v in targets]
            cache[key] = np.ascontiguousarray(np.stack(parts).transpose(2, 0, 1))
        return cache[key]

    def target_coef(self, kind, value):
        """Spline coefficients of t̃(start → target)/S for one target ('ratio' or 'dv')."""
        with self._lock:
            fast = self._fast_nodes()
            key = (kind, float(value))
            if key not in self._targets:
                xn = fast["xn"]
                r = np.array([value]) if kind == "ratio" else np.zeros(0)
                dv = np.array([value]) if kind == "dv" else np.zeros(0)
                vals = self._node_values(xn, r, dv)
                self._targets[key] = _spline(xn, vals["T"][1] / vals["S"])
            return self._targets[key]


def _spline(x, y):
    """Not-a-knot cubic spline coefficients (4, n-1), local in (x - x_j) (Horner order)."""
    from scipy.interpolate import CubicSpline
    return np.ascontiguousarray(CubicSpline(x, y, bc_type="not-a-knot").c)


@njit(cache=True)
def _ev_lnu_k(tab, xs, out):
    for i in range(xs.size):
        out[i] = k_lnu_of_lnp(tab, xs[i])


@njit(cache=True)
def _ev_sig_k(tab, xs, out):
    for i in range(xs.size):
        out[i] = k_sigma_of_lnp(tab, xs[i])


@njit(cache=True)
def _ev_lnvc_k(tab, par, xs, out):
    for i in range(xs.size):
        out[i] = _lnv_of_lnp(tab, par, xs[i])


def _ev_lnu(tab, xs):
    out = np.empty(xs.size)
    _ev_lnu_k(tab, np.ascontiguousarray(xs, dtype=np.float64), out)
    return out


def _ev_sig(tab, xs):
    out = np.empty(xs.size)
    _ev_sig_k(tab, np.ascontiguousarray(xs, dtype=np.float64), out)
    return out


def _ev_lnv_consistent(tab, par, xs):
    out = np.empty(xs.size)
    _ev_lnvc_k(tab, par, np.ascontiguousarray(xs, dtype=np.float64), out)
    return out


_MODELS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_MODELS_LOCK = threading.Lock()


def _fingerprint(tables):
    return (tables.surface.fingerprint(), tuple(tables.theories), tables.p_range,
            int(tables.info.get("nodes", -1)), repr(sorted(tables.options.items())))


def squeeze_model(tables, theory="average", sigma_trap=None) -> SqueezeModel:
    """The cached :class:`SqueezeModel` of (tables, theory) — built on first use."""
    from ..tables import Tables
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables "
                         f"(fastcontact.precompute(...) or Tables.from_parquet(...))")
    tables._need(theory)
    fp = _fingerprint(tables)
    with _MODELS_LOCK:
        entry = _MODELS.get(tables)
        if entry is None or entry["fp"] != fp:
            entry = {"fp": fp}
            _MODELS[tables] = entry
        key = (theory, sigma_trap)
        if key not in entry:
            entry[key] = SqueezeModel(tables, theory, sigma_trap)
        return entry[key]


# =========================================================================== API helpers
def _values(name, value, unit):
    """A 1-D float64 array of ``value`` (for ratios / du / times), or raise naming it."""
    return np.atleast_1d(as_float_array(name, value)).ravel()


def _col(prefix, value):
    return f"{prefix}_{float(value):g}"


def squeeze_out(tables, *, p0, E_star, R, eta, theory="average", u_start=None,
                ratios=(1.1, 1.01, 1.001), du=(), times=(), method="fast",
                quad_order=QUAD_ORDER, quad_width=QUAD_WIDTH, sigma_trap=None):
    """Squeeze-out of a flat cylindrical block against the tables' rough surface (SPEC §4).

    One row per broadcast case of (p0, E_star, R, eta, u_start) — numpy broadcasting, C
    order; millions of rows are fine.

    Parameters
    ----------
    tables : Tables        precomputed surface tables holding ``theory``
    p0 : array_like        nominal squeezing pressure [Pa], > 0
    E_star : array_like    effective modulus E* [Pa], > 0
    R : array_like         block radius [m], > 0
    eta : array_like       fluid viscosity η [Pa·s], > 0
    theory : str           "average", "critical_junction" or "emt" (σ_eff, SPEC §3)
    u_start : array_like or None   initial separation [m], > ū∞ (+inf allowed). None: where
                           p_cont = 1e-3 p0 (module docstring).
    ratios : sequence      targets ū/ū∞ > 1 → columns ``t_ratio_<r>`` [s]
    du : sequence          targets ū - ū∞ [m] > 0 → columns ``t_du_<Δu>`` [s]
    times : sequence       times [s] ≥ 0 → columns ``u_at_<t>`` (ū at that time) [m]
    method : "fast" | "quad"   spline fast path (default) or per-case quadrature
    quad_order, quad_width : Gauss–Legendre order and panel width in ln(ū-ū∞) of "quad"
                           (also used for fall-back rows and u_at columns in "fast")
    sigma_trap : float or None  conductivity floor of the trapping criterion (default:
                           the tables' ``info["sigma_floor"]``, 1e-24)

    Returns
    -------
    pandas.DataFrame with columns

    ``p0, E_star, R, eta`` inputs [SI]; ``u_start`` [m] (the default filled in);
    ``u_inf`` dry equilibrium separation ū∞ [m] (p_cont(ū∞) = p0);
    ``t_star`` time to ū = 1.01 ū∞ [s] (always computed);
    ``t_ratio_<r>``, ``t_du_<Δu>`` [s] (0 where already below the target at t = 0; +inf if
    the fluid is trapped above the target); ``u_at_<t>`` [m];
    ``tau0`` = 3ηR²/(2 h_rms² p0) [s], the time unit (t = tau0 · t̃);
    ``t_relax`` e-folding time of the final exponential approach [s] (NaN if trapped);
    ``trapped`` the film stops at ``u_trap`` [m] > ū∞ (NaN if not trapped);
    ``percolated`` p0 ≥ the exact percolation pressure of the theory;
    ``t_trap`` [s] finite time to reach u_trap (astronomical; inf if not trapped);
    ``fluid_load_fraction`` p̄_f/p0 at the end state = 1 - π_trap/π0 (0 if not trapped);
    ``out_of_table`` p0/E* outside the tables (every computed column NaN).

    ``DataFrame.attrs`` records the model decisions (trap criterion, tail, default start).
    """
    from ..tables import Tables
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables")
    if method not in ("fast", "quad"):
        raise ValueError(f"method = {method!r} is invalid: must be 'fast' or 'quad'")
    quad_order = int(quad_order)
    if not 2 <= quad_order <= 64:
        raise ValueError(f"quad_order = {quad_order!r} is invalid: must be an integer in [2, 64]")
    quad_width = float(check_positive("quad_width", quad_width, "[-] (panel width in ln(u-u_inf))"))
    if sigma_trap is not None:
        sigma_trap = float(check_positive("sigma_trap", sigma_trap, "[-] (reduced conductivity floor)"))
    model = squeeze_model(tables, theory, sigma_trap)
    h = model.h_rms
    p0 = check_positive("p0", p0, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    R = check_positive("R", R, "[m]")
    eta = check_positive("eta", eta, "[Pa·s]")
    if u_start is None:
        us = np.array(np.nan)
    else:
        us = check_positive("u_start", u_start, "[m]", allow_inf=True)
    ratios = _values("ratios", ratios, "[-]")
    if ratios.size and not np.all(np.isfinite(ratios) & (ratios > 1.0)):
        bad = ratios[~(np.isfinite(ratios) & (ratios > 1.0))][0]
        raise ValueError(f"ratios = {float(bad)!r} is invalid: every ratio must be a finite "
                         f"number > 1 [-] (target u/u_inf)")
    du = _values("du", du, "[m]")
    if du.size:
        check_positive("du", du, "[m]")
    times = _values("times", times, "[s]")
    if times.size:
        check_positive("times", times, "[s]", allow_zero=True, allow_inf=True)
    order = np.argsort(times, kind="stable")
    times_sorted = np.ascontiguousarray(times[order])
    try:
        b = np.broadcast(p0, E_star, R, eta, us)
    except ValueError:
        raise ValueError(f"p0, E_star, R, eta, u_start are invalid: shapes "
                         f"{[np.shape(a) for a in (p0, E_star, R, eta, us)]} do not broadcast") from None
    shape = b.shape
    n = int(np.prod(shape)) if shape else 1

    def flat(a):
        return np.ascontiguousarray(np.broadcast_to(a, shape).ravel(), dtype=np.float64)

    p0f, Ef, Rf, etaf, usf = (flat(a) for a in (p0, E_star, R, eta, us))
    rr = np.ascontiguousarray(ratios)
    dv = np.ascontiguousarray(du / h)
    nt = 1 + rr.size + dv.size
    out = {"T": np.empty((nt, n)), "U": np.empty((times_sorted.size, n))}
    for k in ("u_inf", "u_start", "t_relax", "u_trap", "t_trap", "fluid_load_fraction", "tau0"):
        out[k] = np.empty(n)
    out["status"] = np.empty(n, dtype=np.int8)
    outs = (out["T"], out["U"], out["u_inf"], out["u_start"], out["t_relax"], out["u_trap"],
            out["t_trap"], out["fluid_load_fraction"], out["tau0"], out["status"])
    glx, glw = _gl(quad_order)
    tab, par = model.tab, model.par
    if method == "quad":
        _quad_kernel(tab, par, p0f, Ef, Rf, etaf, usf, h, rr, dv, times_sorted, glx, glw,
                     quad_width, *outs)
    else:
        fast = model._fast_nodes()
        C = model.packed([("ratio", 1.01)] + [("ratio", float(r)) for r in rr]
                         + [("dv", float(d)) for d in dv])
        _fast_kernel(tab, par, p0f, Ef, Rf, etaf, usf, h, rr, dv, times_sorted, glx, glw,
                     quad_width, fast["xn"], *fast["bucket"], C, *outs)
    if u_start is not None:
        bad = (out["status"] == ST_OK) & ~(usf > out["u_inf"])
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"u_start = {float(usf[i])!r} is invalid: must be > u_inf = "
                             f"{float(out['u_inf'][i])!r} [m] (p0 = {float(p0f[i])!r} Pa, "
                             f"E_star = {float(Ef[i])!r} Pa): the film must start above "
                             f"equilibrium")
    cols = {"p0": p0f, "E_star": Ef, "R": Rf, "eta": etaf, "u_start": out["u_start"],
            "u_inf": out["u_inf"], "t_star": out["T"][0]}
    k = 1
    for r in rr:
        cols[_col("t_ratio", r)] = out["T"][k]
        k += 1
    for d in du:
        cols[_col("t_du", d)] = out["T"][k]
        k += 1
    inv = np.empty_like(order)
    inv[order] = np.arange(order.size)
    for j, t in enumerate(times):
        cols[_col("u_at", t)] = out["U"][inv[j]]
    status = out["status"]
    trapped = status == ST_TRAPPED
    cols.update({"tau0": out["tau0"], "t_relax": out["t_relax"], "trapped": trapped,
                 "percolated": trapped & (np.log(p0f / Ef) >= model.x_perc)
                 if np.isfinite(model.x_perc) else np.zeros(n, dtype=bool),
                 "u_trap": out["u_trap"], "t_trap": out["t_trap"],
                 "fluid_load_fraction": out["fluid_load_fraction"],
                 "out_of_table": status == ST_OUT})
    df = pd.DataFrame(cols, copy=False)
    df.attrs.update(_attrs(model))
    df.attrs["method"] = method
    return df


def _attrs(model):
    return {
        "theory": model.theory,
        "h_rms_m": model.h_rms,
        "time_unit": "tau0 = 3 eta R^2 / (2 h_rms^2 p0) [s]",
        "default_u_start": f"p_cont(u_start) = {DEFAULT_P_START:g} p0",
        "trap_criterion": (f"sigma_bar < sigma_trap = {model.sigma_trap:g} is treated as 0 "
                           f"(p/E* >= {math.exp(model.x_trap) if np.isfinite(model.x_trap) else math.inf:.8g}; "
                           f"exact percolation at p/E* = "
                           f"{math.exp(model.x_perc) if np.isfinite(model.x_perc) else math.inf:.8g})"),
        "tail": (f"u > {model.v_top:.6g} h_rms: p = p_top exp(-(u-u_top)/{model.u0:.6g} h_rms), "
                 f"sigma_bar = y^3 - {model.c_tail:.6g} y, y = u/h_rms + {model.d_tail:.6g}"),
    }


def squeeze_history(tables, p0, E_star, R, eta, theory="average", t=None, u_start=None, *,
                    quad_order=16, quad_width=0.5, sigma_trap=None):
    """ū(t), p_cont(t)/p0 and the mean fluid pressure of ONE case on a time array (plots).

    Parameters: as :func:`squeeze_out` but scalars; ``t`` array of times [s] ≥ 0.

    Returns a DataFrame with ``t`` [s], ``u`` [m], ``p_cont_over_p0`` [-],
    ``p_fluid_mean`` [Pa] (= p0 - p_cont, the nominal fluid pressure p̄_f of eq. 19; the
    pressure profile is 2 p̄_f (1 - r²/R²)), ``u_flat`` [m] (Stefan law for a flat
    substrate from the same u_start, SPEC §4), in the order of ``t``.
    """
    for name, val in (("p0", p0), ("E_star", E_star), ("R", R), ("eta", eta)):
        if np.ndim(val) != 0:
            raise ValueError(f"{name} = {val!r} is invalid: squeeze_history takes one case "
                             f"(scalars); use squeeze_out for many")
    if t is None:
        raise ValueError("t = None is invalid: give an array of times [s] >= 0")
    t = np.atleast_1d(check_positive("t", t, "[s]", allow_zero=True, allow_inf=True)).ravel()
    df = squeeze_out(tables, p0=p0, E_star=E_star, R=R, eta=eta, theory=theory,
                     u_start=u_start, ratios=(), times=t, method="quad",
                     quad_order=quad_order, quad_width=quad_width, sigma_trap=sigma_trap)
    if bool(df["out_of_table"].iloc[0]):
        raise ValueError(f"p0 = {float(p0)!r} is invalid: p0/E_star = {float(p0) / float(E_star):.6g} "
                         f"is outside the tables' range {tables.p_range}")
    row = df.iloc[0]
    h = float(tables.h_rms)
    names = [_col("u_at", x) for x in t]
    u = np.array([row[c] for c in names], dtype=np.float64)
    model = squeeze_model(tables, theory, sigma_trap)
    pc = _p_of_u(model, u / h)
    ratio = pc / (float(p0) / float(E_star))
    from .reduced import flat_separation
    us = float(row["u_start"])
    flat = np.asarray(flat_separation(us, np.where(np.isfinite(t), t, 0.0), float(p0),
                                      float(eta), float(R)), dtype=np.float64)
    flat = np.where(np.isfinite(t), flat, 0.0)
    out = pd.DataFrame({"t": t, "u": u, "p_cont_over_p0": ratio,
                        "p_fluid_mean": float(p0) * (1.0 - ratio), "u_flat": np.atleast_1d(flat)})
    out.attrs.update(df.attrs)
    for k in ("u_inf", "u_start", "t_star", "trapped", "u_trap", "fluid_load_fraction",
              "tau0", "t_relax"):
        out.attrs[k] = row[k].item() if hasattr(row[k], "item") else row[k]
    return out


@njit(cache=True)
def _p_of_u_k(tab, par, v, out):
    for i in range(v.size):
        out[i] = math.exp(_state(tab, par, v[i])[0])


def _p_of_u(model, v):
    """π_c(v) of the model (tables + tail)."""
    v = np.ascontiguousarray(v, dtype=np.float64)
    out = np.empty(v.size)
    _p_of_u_k(model.tab, model.par, v, out)
    return out
