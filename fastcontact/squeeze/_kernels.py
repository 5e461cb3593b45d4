"""Per-case quadrature engine of the squeeze-out time (``method="quad"``, and the fall-back of
the fast path for trapped-fluid rows).

Reduced units: v = ū/h_rms, π = p/E*, σ̄ = 12ησ_eff/h_rms³, t̃ = t/τ0 with
τ0 = 3ηR²/(2 h_rms² p0); dv/dt̃ = -σ̄(π_c(v)) (1 - π_c(v)/π0) (Lorenz & Persson 2010,
eqs. (18), (19), (23); arXiv:1004.1037). Times are quadratures in
w = ln(v - v_b), never time stepping. Every kernel takes the tables' kernel record ``tab``
and the model record ``mp`` (:class:`~fastcontact.squeeze.model.ModelPar`).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from ..tables import k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp

__all__ = ["Quad", "Cases", "Targets", "SqOut", "Film", "ST_OK", "ST_TRAPPED", "ST_OUT", "ST_BELOW",
           "ST_OVERFLOW", "STATUS_NAMES"]

#: Gauss–Legendre rule and panel width in w = ln(v - v_b)
Quad = namedtuple("Quad", "glx glw width")
#: one row per case (SI): p0 [Pa], E [Pa], R [m], eta [Pa s], us = u_start [m] (NaN: default)
Cases = namedtuple("Cases", "p0 E R eta us")
#: targets shared by all cases: ratios ū/ū∞, dvs = Δu/h_rms, times [s] (shape (nt, 1) shared
#: or (nt, n) per case, ascending along axis 0)
Targets = namedtuple("Targets", "ratios dvs times")
#: outputs, one column per case: T (1 + nr + nd, n) times [s] (t_star first), U (nt, n) ū at
#: the times [m], then per case u_inf, u_start, t_relax, u_trap, t_trap [SI],
#: flf (fluid load fraction), tau0 [s], status (int8)
SqOut = namedtuple("SqOut", "T U u_inf u_start t_relax u_trap t_trap flf tau0 status")
#: the film of one case, in units of h_rms: x0 = ln(p0/E*), tau = τ0 [s], vinf = ū∞,
#: vs = ū at the start, vb = the level it drains to (ū∞, or ū at the trap), trapped (bool)
Film = namedtuple("Film", "x0 tau vinf vs vb trapped")

# status codes (STATUS_NAMES gives the readable value of the ``status`` column)
ST_OK, ST_TRAPPED, ST_OUT, ST_BELOW, ST_OVERFLOW = 0, 1, 2, 3, 4
STATUS_NAMES = ("ok", "trapped", "out_of_table", "start_below_equilibrium", "overflow")
#: status code of a row no kernel has written yet (the status arrays start with it): a kernel
#: thread that fails inside a parallel loop can stop without raising, leaving its remaining
#: rows unwritten; :func:`check_computed` turns that into an error instead of garbage rows
NOT_COMPUTED = -128


def check_computed(status, engine):
    """RuntimeError if a row of ``status`` (int8 codes) still holds NOT_COMPUTED after the
    kernels of ``engine`` ran (an internal failure, never a property of the inputs)."""
    bad = np.flatnonzero(status == NOT_COMPUTED)
    if bad.size:
        raise RuntimeError(f"{engine}: {bad.size} of {status.size} rows were not computed "
                           f"(first: row {int(bad[0])}); an internal error of the kernels — "
                           f"please report it with these inputs")


def new_status(n):
    """A status array of n rows, every one NOT_COMPUTED until a kernel writes it."""
    return np.full(n, NOT_COMPUTED, dtype=np.int8)


@njit(cache=True)
def tail_sigma(mp, v):
    """(σ̄, d ln σ̄/d ln v) of the analytic tail above the table top at v > v_top [h_rms]:
    σ̄ = y (y² - cn), y = v + d + g(1/v), g(x) = x (g1 + x (g2 + ... + x g5)) (model.py)."""
    x = 1.0 / v
    g = x * (mp.g1 + x * (mp.g2 + x * (mp.g3 + x * (mp.g4 + x * mp.g5))))
    dg = mp.g1 + x * (2.0 * mp.g2 + x * (3.0 * mp.g3 + x * (4.0 * mp.g4 + x * 5.0 * mp.g5)))
    y = v + mp.d + g
    y2c = y * y - mp.cn
    return y * y2c, v * (1.0 - x * x * dg) * (3.0 * y * y - mp.cn) / (y * y2c)


@njit(cache=True, inline="always")
def _lnp_of_v(tab, mp, v):
    """ln π_c at separation v [h_rms]: tables, or the eq. (3) tail above v_top."""
    if v > mp.v_top:
        return mp.x_min - (v - mp.v_top) / mp.u0
    return k_lnp_of_lnu(tab, math.log(v))


@njit(cache=True)
def _state(tab, mp, v):
    """(ln π_c, σ̄) at separation v [h_rms]: tables, or the analytic tail above v_top."""
    lnp = _lnp_of_v(tab, mp, v)
    if v > mp.v_top:
        return lnp, tail_sigma(mp, v)[0]
    if lnp != lnp:
        return lnp, math.nan
    if lnp >= mp.x_trap:
        return lnp, 0.0
    return lnp, k_sigma_of_lnp(tab, lnp)


@njit(cache=True)
def _lnv_of_lnp(tab, mp, x):
    """ln v with π_c(v) = e^x exactly for the model's p_cont(v) (Newton on k_lnp_of_lnu)."""
    if x <= mp.x_min:
        return math.log(mp.v_top + mp.u0 * (mp.x_min - x))
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
def _dlnv_dlnp(tab, mp, x):
    """|d ln v / d ln π| of the model's p_cont(v) at ln π = x (central difference)."""
    hh = 1e-6
    if x + hh > mp.x_max:
        return abs(_lnv_of_lnp(tab, mp, x) - _lnv_of_lnp(tab, mp, x - hh)) / hh
    if x - hh < mp.x_min:
        return abs(_lnv_of_lnp(tab, mp, x + hh) - _lnv_of_lnp(tab, mp, x)) / hh
    return abs(_lnv_of_lnp(tab, mp, x + hh) - _lnv_of_lnp(tab, mp, x - hh)) / (2.0 * hh)


#: below this relative distance r = (v - v∞)/v∞ from equilibrium, 1 - π_c/π0 comes from the
#: tables' slope at v∞, -expm1(s ln(1 + r)) (the interpolant in ln v cannot resolve r there:
#: Δu < 1e-11 ū∞ targets were up to 13 % off the fast path's exact logarithmic approach)
LIN_REL = 1e-8


@njit(cache=True)
def near_equilibrium(tab, x0, vb, r):
    """(σ̄, 1 - π_c/π0) at v = vb (1 + r), 0 < r < LIN_REL, from ln π_c linear in ln v at vb
    (slope by central difference); (NaN, NaN) when vb is not the equilibrium of ln π0 = x0
    (|ln π_c(vb) - x0| > 1e-9, e.g. a trapped row's v_trap)."""
    lv = math.log(vb)
    lp = k_lnp_of_lnu(tab, lv)
    if not (abs(lp - x0) <= 1e-9):
        return math.nan, math.nan
    hh = 1e-6
    s = (k_lnp_of_lnu(tab, lv + hh) - k_lnp_of_lnu(tab, lv - hh)) / (2.0 * hh)
    return k_sigma_of_lnp(tab, lp), -math.expm1(s * math.log1p(r))


@njit(cache=True)
def state_gap(tab, mp, x0, vb, e):
    """(σ̄, 1 - π_c/π0) at v = vb + e: :func:`near_equilibrium` within LIN_REL of an
    equilibrium vb, else the model's state (:func:`_state`)."""
    d = math.nan
    if e < LIN_REL * vb:
        sig, d = near_equilibrium(tab, x0, vb, e / vb)
    if d != d:
        lnp, sig = _state(tab, mp, vb + e)
        d = -math.expm1(lnp - x0)
    return sig, d


@njit(cache=True)
def _dtdw(tab, mp, x0, vb, w):
    """dt̃/dw at w = ln(v - vb): (v - vb) / (σ̄ (1 - π_c/π0)); 0 where σ̄ = 0 (trapped)."""
    e = math.exp(w)
    sig, d = state_gap(tab, mp, x0, vb, e)
    if not (sig > 0.0):
        return 0.0
    if d <= 1e-300:
        d = 1e-300
    return e / (sig * d)


@njit(cache=True)
def _seg(tab, mp, x0, vb, w1, w2, quad):
    """∫_{w1}^{w2} dt̃/dw dw, composite Gauss–Legendre, panels of width <= width, broken at
    the tables' last open node (:func:`kink_w`) where it lies inside."""
    wk = kink_w(tab, vb)
    if w1 < wk < w2:
        return _seg_plain(tab, mp, x0, vb, w1, wk, quad) + _seg_plain(tab, mp, x0, vb, wk, w2,
                                                                        quad)
    return _seg_plain(tab, mp, x0, vb, w1, w2, quad)


@njit(cache=True, inline="always")
def kink_w(tab, vb):
    """w = ln(v_k - vb) of the tables' last open node v_k (-inf where there is none or it lies
    at or below vb). Beyond it σ̄^(1/3) falls linearly to the percolation pressure
    (:func:`~fastcontact.kernels.lookup.k_sigma_of_lnp`): d ln σ̄/d ln π jumps there (by ~20x
    on the embedded road tables), and panels straddling it lost up to 6e-2 in the time to a
    target above a trapped row's v_trap (asphalt_024mm, pmma_34um)."""
    n_open = tab.n_open
    if not (0 < n_open < tab.lnp.size):
        return -math.inf
    vk = math.exp(tab.lnu[n_open - 1])
    return math.log(vk - vb) if vk > vb else -math.inf


@njit(cache=True)
def _seg_plain(tab, mp, x0, vb, w1, w2, quad):
    """:func:`_seg` without the break."""
    if not (w2 > w1):
        return 0.0
    glx, glw, width = quad.glx, quad.glw, quad.width
    m = int(math.ceil((w2 - w1) / width))
    if m < 1:
        m = 1
    hw = (w2 - w1) / m
    s = 0.0
    for k in range(m):
        mid = w1 + (k + 0.5) * hw
        acc = 0.0
        for j in range(glx.size):
            acc += glw[j] * _dtdw(tab, mp, x0, vb, mid + 0.5 * hw * glx[j])
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
def _time(tab, mp, x0, vb, v_lo, v_hi, quad):
    """t̃ to go from v_hi (may be inf) down to v_lo > vb."""
    if not (v_hi > v_lo):
        return 0.0
    return _time_w(tab, mp, x0, vb, v_lo, math.log(v_lo - vb), v_hi, math.log(v_hi - vb), quad)


@njit(cache=True)
def _time_w(tab, mp, x0, vb, v_lo, w_lo, v_hi, w_hi, quad):
    """t̃ from v_hi (may be inf) down to v_lo, the ends also given as w = ln(v - vb) (exact
    even where v - vb is below the resolution of v, e.g. ū∞ + 1e-20 m)."""
    total = 0.0
    v_ext = mp.v_ext
    if v_hi > v_ext:
        a = v_lo if v_lo > v_ext else v_ext
        total += _tail_int(mp.c, a + mp.d, v_hi + mp.d)
        if v_lo >= v_ext:
            return total
        w_hi = math.log(v_ext - vb)
    if not (w_hi > w_lo):
        return total
    return total + _seg(tab, mp, x0, vb, w_lo, w_hi, quad)


@njit(cache=True)
def _v_at_time(tab, mp, x0, vb, v_floor, vs, t_prev, w_prev, t_target, quad):
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
        g = _dtdw(tab, mp, x0, vb, w)
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
        dt = _seg(tab, mp, x0, vb, wn, w, quad)
        if t + dt > t_target and wn < w - 1e-15:
            # overshoot: shrink until inside (monotone: halve the step)
            lo_w = wn
            hi_w = w
            for _k in range(100):
                g = _dtdw(tab, mp, x0, vb, w)
                step = (t_target - t) / g if g > 0.0 else 0.5 * (hi_w - lo_w)
                wc = w - step
                if not (lo_w < wc < hi_w):
                    wc = 0.5 * (lo_w + hi_w)
                dtc = _seg(tab, mp, x0, vb, wc, w, quad)
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
def _nan_row(out, i, x_out):
    """Every computed column of row i NaN (state cannot be computed)."""
    for k in range(out.T.shape[0]):
        out.T[k, i] = math.nan
    for k in range(out.U.shape[0]):
        out.U[k, i] = math.nan
    out.u_inf[i] = math.nan
    out.t_relax[i] = math.nan
    out.u_trap[i] = math.nan
    out.t_trap[i] = math.nan
    out.flf[i] = math.nan


@njit(cache=True, inline="always")
def reduced_time(t, tau):
    """t/τ0 [-] for a time t [s] >= 0 (inf allowed) and τ0 [s]. τ0 = 0 (3ηR²/(2h²p0) below the
    smallest double, e.g. R = 1e-300 m: the row is flagged "overflow") gives +inf for t > 0
    and 0 at t = 0 instead of numba's ZeroDivisionError, which aborted the whole batch."""
    if tau > 0.0:
        return t / tau
    return math.inf if t > 0.0 else 0.0


@njit(cache=True)
def _case_state(tab, mp, x0, vs_in, tau, h, i, out):
    """The :data:`Film` of one case; writes the per-case state columns (not the status: the
    caller writes it last, so that a row whose later steps fail keeps NOT_COMPUTED)."""
    vinf = math.exp(_lnv_of_lnp(tab, mp, x0))
    vs = vs_in
    if vs != vs:  # default start: p_cont(v_start) = DEFAULT_P_START p0
        vs = math.exp(_lnv_of_lnp(tab, mp, x0 + mp.lnp_start))
    trapped = x0 >= mp.x_trap
    out.u_inf[i] = vinf * h
    out.u_start[i] = vs * h
    if trapped:
        vb = mp.v_trap
        out.u_trap[i] = vb * h
        out.flf[i] = -math.expm1(mp.x_trap - x0)
        out.t_relax[i] = math.nan
    else:
        vb = vinf
        out.u_trap[i] = math.nan
        out.flf[i] = 0.0
        out.t_relax[i] = tau * vinf * _dlnv_dlnp(tab, mp, x0) / k_sigma_of_lnp(tab, x0)
    return Film(x0, tau, vinf, vs, vb, trapped)


@njit(cache=True)
def _case_targets(tab, mp, film, tg, quad, i, out):
    """Times to t_star, the ratios and the Δu targets: one downward pass from the start of
    ``film`` (:data:`Film`)."""
    x0, tau, vinf, vs, vb, trapped = film
    nt = out.T.shape[0]
    nr = tg.ratios.size
    vts = np.empty(nt)
    for k in range(nt):
        if k == 0:
            vts[k] = 1.01 * vinf
        elif k <= nr:
            vts[k] = tg.ratios[k - 1] * vinf
        else:
            vts[k] = vinf + tg.dvs[k - 1 - nr]
    # w = ln(v - v∞) of each target, exact (a Δu below the resolution of ū∞ stays apart)
    wts = np.empty(nt)
    for k in range(nt):
        if k == 0:
            wts[k] = math.log(0.01) + math.log(vinf)
        elif k <= nr:
            wts[k] = math.log(tg.ratios[k - 1] - 1.0) + math.log(vinf)
        else:
            wts[k] = math.log(tg.dvs[k - 1 - nr])
    order = np.argsort(-wts)
    v_cur = vs
    w_cur = math.log(vs - vinf) if vs > vinf else -math.inf
    t_cur = 0.0
    for kk in range(nt):
        k = order[kk]
        vt = vts[k]
        if vt >= vs:
            out.T[k, i] = 0.0
        elif trapped and (vt <= vb or vs <= vb):
            out.T[k, i] = math.inf
        elif trapped:
            if vt < v_cur:
                t_cur += _time(tab, mp, x0, vb, vt, v_cur, quad)
                v_cur = vt
            out.T[k, i] = tau * t_cur
        else:
            if wts[k] < w_cur:
                t_cur += _time_w(tab, mp, x0, vb, vt, wts[k], v_cur, w_cur, quad)
                v_cur = vt
                w_cur = wts[k]
            out.T[k, i] = tau * t_cur


@njit(cache=True)
def _case_times(tab, mp, film, tg, h, quad, i, out):
    """Trap time and ū at the (ascending) times of row i (``film``: :data:`Film`)."""
    x0, tau, vinf, vs, vb, trapped = film
    t_trap = math.inf
    if trapped:
        if vs <= vb:
            t_trap = 0.0
        else:
            # below w_lo = ln(v_trap) - 30 the integrand is e^w x const: closed form
            w_lo = math.log(vb) - 30.0
            t_trap = (_dtdw(tab, mp, x0, vb, w_lo)
                      + _time(tab, mp, x0, vb, vb + math.exp(w_lo), vs, quad))
    out.t_trap[i] = tau * t_trap
    tp = 0.0
    wp = math.log(vs - vb) if vs > vb else -math.inf
    col = i if tg.times.shape[1] > 1 else i - i  # same integer type as i
    for k in range(out.U.shape[0]):
        tk = reduced_time(tg.times[k, col], tau)
        if vs <= vb:
            out.U[k, i] = vs * h
        elif tk == math.inf or (trapped and tk >= t_trap):
            out.U[k, i] = vb * h
        else:
            v, tp, wp = _v_at_time(tab, mp, x0, vb, vb, vs, tp, wp, tk, quad)
            out.U[k, i] = v * h


#: panel width of a trapped row's quadrature, in units of the quadrature's ``width``: its
#: integrand 1/(σ̄ (1 - π_c/π0)) rises towards v_trap as σ̄ collapses, and with the default
#: 10 points on unit panels in ln(v - v_trap) the times to targets just above ū_trap were up
#: to 3.8e-6 off the independent reference on tables whose last open node lies below the trap
#: pressure (asphalt_072mm, copper_012mm; 2026-12-04); half the width: ≤ 5.2e-7, a third
#: ≤ 1.5e-7 (1,000 random trapped cases per table and theory; 3x the evaluations of these
#: rows, which the fast path serves from its trapped-side primitive)
TRAPPED_WIDTH = 1.0 / 3.0


@njit(cache=True, inline="always")
def trapped_quad(quad):
    """The quadrature of a trapped row: panels of TRAPPED_WIDTH times ``quad``'s width (in
    w = ln(v - v_trap); the constant-viscosity and the Barus engines alike)."""
    return Quad(quad.glx, quad.glw, TRAPPED_WIDTH * quad.width)


@njit(cache=True)
def quad_case(tab, mp, x0, vs_in, tg, tau, h, quad, i, out):
    """Everything for one case by quadrature, written in SI to column i of ``out``."""
    if not (mp.x_min <= x0 <= mp.x_max):
        _nan_row(out, i, x0)
        out.u_start[i] = vs_in * h
        out.status[i] = ST_OUT
        return
    film = _case_state(tab, mp, x0, vs_in, tau, h, i, out)
    # a start at or below ū∞ (trapped rows too), compared as reported (SI): u_start is vs h
    if not (film.vs * h > film.vinf * h):
        _nan_row(out, i, x0)
        out.u_inf[i] = film.vinf * h
        out.status[i] = ST_BELOW
        return
    if film.trapped:  # a third of the panel width on the trapped side (TRAPPED_WIDTH)
        quad = trapped_quad(quad)
    _case_targets(tab, mp, film, tg, quad, i, out)
    _case_times(tab, mp, film, tg, h, quad, i, out)
    # last: a worker thread that fails above stops without raising, and the row must keep
    # NOT_COMPUTED for check_computed to see it
    out.status[i] = ST_TRAPPED if film.trapped else ST_OK


@njit(parallel=True, cache=True)
def p_of_v_kernel(tab, mp, v, out):
    """π_c(v) of the model (tables + analytic tail) at reduced separations v: the ln π_c of
    :func:`_state`, without its σ̄ (a history asks for π_c at a million points)."""
    for i in prange(v.size):
        out[i] = math.exp(_lnp_of_v(tab, mp, v[i]))


@njit(cache=True)
def lnv_of_lnp_kernel(tab, mp, xs, out):
    """ln v consistent with the model's π_c(v) at ln π = xs."""
    for i in range(xs.size):
        out[i] = _lnv_of_lnp(tab, mp, xs[i])


@njit(cache=True)
def sigma_kernel(tab, xs, out):
    """σ̄ of the tables at ln π = xs."""
    for i in range(xs.size):
        out[i] = k_sigma_of_lnp(tab, xs[i])


@njit(cache=True)
def lnu_kernel(tab, xs, out):
    """ln(ū/h_rms) of the tables at ln π = xs."""
    for i in range(xs.size):
        out[i] = k_lnu_of_lnp(tab, xs[i])
