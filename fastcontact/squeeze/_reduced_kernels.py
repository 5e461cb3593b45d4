"""Numba kernels of the reduced squeeze-out model: the time quadrature t(ū_a → ū_b) in
w = ln(ū - ū∞) and its inverse ū(t) (Lorenz & Persson 2010, eqs. (7)–(10) with law (8);
arXiv:1004.1037).

Part of :mod:`fastcontact.squeeze.reduced` (its docstring, "Numerics of t*", states the
method and the measured accuracy). Everything here is in reduced units: ū in h_rms, t in
τ = 3ηR²/(2α h_rms² p0) (eq. 6).
"""
from __future__ import annotations

import math

from numba import njit

from ..kernels.quadrature import gauss_legendre

_GL_ORDER = 20
_GLX, _GLW = gauss_legendre(_GL_ORDER)
#: above α·v = 40 the factor 1 - e^{-αv} is 1 to 4e-18: closed-form tail
_X_TAIL = 40.0
#: v below ū∞·e^{-40} (4e-18 relative) leaves ū = ū∞ in double precision
_W_FLOOR_OFFSET = 40.0


@njit(cache=True)
def _phi(x):
    """x / (1 - e^{-x}) for x > 0, accurate for tiny x."""
    if x < 1e-5:
        return 1.0 + x * (0.5 + x / 12.0)
    return -x / math.expm1(-x)


@njit(cache=True)
def _integrand(w, a, lnk_a, alpha, below):
    """dt/dw in the variable w = ln(ū - a).

    below (κ < 1): a = ū∞, 1 - p = 1 - e^{-α v}, dt/dw = φ(αv)/ū³.
    otherwise:     a = 0,  1 - p = 1 - e^{-(αū + ln κ)}, dt/dw = α ū/(ū³(1 - p)).
    """
    v = math.exp(w)
    u = a + v
    if below:
        return _phi(alpha * v) / (u * u * u)
    x = alpha * u + lnk_a
    if x < 1e-5:
        return _phi(x) / (u * u * x) * alpha
    return alpha / (u * u * (-math.expm1(-x)))


@njit(cache=True)
def _quad_w(w_lo, w_hi, a, lnk_a, alpha, below, w_c, glx, glw):
    """∫_{w_lo}^{w_hi} dt/dw dw with graded Gauss–Legendre panels (w_hi finite)."""
    total = 0.0
    b = w_hi
    n = glx.size
    while b > w_lo:
        width = 1.0
        if b < w_c:
            g = 0.5 * (w_c - b)
            if below:
                if g > width:
                    width = g
        lo = b - width
        if lo < w_lo:
            lo = w_lo
        h = 0.5 * (b - lo)
        m = 0.5 * (b + lo)
        s = 0.0
        for k in range(n):
            s += glw[k] * _integrand(m + h * glx[k], a, lnk_a, alpha, below)
        total += h * s
        b = lo
    return total


@njit(cache=True)
def _time_between(w_lo, w_hi, a, lnk_a, alpha, below, w_c, glx, glw):
    """Reduced time to go from w_hi (may be +inf) down to w_lo: quadrature below
    v = 40/α, closed form α/2 [1/(a+V)² - 1/(a+U)²] above (1 - p = 1 to 4e-18)."""
    w_tail = math.log(_X_TAIL / alpha)
    total = 0.0
    if w_lo < w_tail:
        top = w_hi if w_hi < w_tail else w_tail
        total += _quad_w(w_lo, top, a, lnk_a, alpha, below, w_c, glx, glw)
    if w_hi > w_tail:
        bot = w_lo if w_lo > w_tail else w_tail
        V = math.exp(bot)
        pv = 1.0 / (a + V)
        if math.isinf(w_hi):
            total += 0.5 * alpha * pv * pv
        else:
            U = math.exp(w_hi)
            if math.isinf(U):
                total += 0.5 * alpha * pv * pv
            else:
                qv = 1.0 / (a + U)
                diff = ((U - V) / (a + U)) / (a + V)     # pv - qv without cancellation
                total += 0.5 * alpha * diff * (pv + qv)
    return total


@njit(cache=True)
def _case_setup(kappa, alpha):
    """(a, lnk_a, below, w_c) for one case; see _integrand."""
    lnk = math.log(kappa)
    s = -lnk / alpha                 # formal ū∞ (≤ 0 for κ ≥ 1)
    below = kappa < 1.0
    two_pi_a = math.log(2.0 * math.pi / alpha)
    if below:
        a = s
        lnk_a = 0.0
        w_c = min(math.log(s), two_pi_a)
    else:
        a = 0.0
        lnk_a = lnk
        w_c = two_pi_a if s == 0.0 else min(math.log(-s), two_pi_a)
    return a, lnk_a, below, w_c


@njit(cache=True)
def _w_of_u(u, a):
    if math.isinf(u):
        return math.inf
    return math.log(u - a)


@njit(cache=True)
def _t_star_kernel(kappa, alpha, u_start, ratio, glx, glw, out):
    for i in range(kappa.size):
        if not kappa[i] < 1.0:
            out[i] = math.inf
            continue
        a, lnk_a, below, w_c = _case_setup(kappa[i], alpha[i])
        w_lo = math.log((ratio[i] - 1.0) * a)
        w_hi = _w_of_u(u_start[i], a)
        out[i] = _time_between(w_lo, w_hi, a, lnk_a, alpha[i], below, w_c, glx, glw)


@njit(cache=True)
def _u_of_t_kernel(kappa, alpha, u_start, t, glx, glw, out):
    for i in range(kappa.size):
        al = alpha[i]
        a, lnk_a, below, w_c = _case_setup(kappa[i], al)
        ti = t[i]
        if ti == 0.0:
            out[i] = u_start[i]
            continue
        if math.isinf(ti):
            out[i] = a
            continue
        w_s = _w_of_u(u_start[i], a)
        us = u_start[i]
        w_tail = math.log(_X_TAIL / al)
        hi = w_s                 # g(hi) <= 0
        if w_s > w_tail:
            # above v = 40/α the contact pressure is < e^-40 p0: the motion is the flat
            # (Stefan) law there, 1/ū² = 1/u_start² + 2t/α, exactly invertible
            if ti <= _time_between(w_tail, w_s, a, lnk_a, al, below, w_c, glx, glw):
                inv = 1.0 / us if not math.isinf(us) else 0.0
                out[i] = 1.0 / math.sqrt(2.0 * ti / al + inv * inv)
                continue
            hi = w_tail
        # first guess from the flat (Stefan) law, which lies below the rough solution
        if math.isinf(us):
            uf = math.sqrt(al / (2.0 * ti))
        else:
            uf = us / math.sqrt(1.0 + 2.0 * us * us * ti / al)
        if uf - a > 0.0:
            w = math.log(uf - a)
        elif below:
            w = math.log(a) - 1.0
        else:
            w = -1.0
        if w > hi:
            w = hi
        w_floor = math.log(a) - _W_FLOOR_OFFSET if below else -math.inf
        lo = -math.inf           # g(lo) > 0 (too deep: T(lo) > t)
        maxstep = 4.0
        done = False
        for it in range(200):
            g = _time_between(w, w_s, a, lnk_a, al, below, w_c, glx, glw) - ti
            if g == 0.0:
                break
            if g > 0.0:
                lo = w
            else:
                hi = w
            if abs(g) <= 2e-15 * ti:
                break
            f = _integrand(w, a, lnk_a, al, below)
            wn = w + g / f if f > 0.0 else lo
            if wn <= lo or wn >= hi:
                if lo > -math.inf and hi < math.inf:
                    wn = 0.5 * (lo + hi)
                elif lo == -math.inf:
                    wn = hi - maxstep
                    maxstep *= 2.0
                else:
                    wn = lo + maxstep
                    maxstep *= 2.0
            elif lo == -math.inf and wn < w - maxstep:
                # no lower bracket yet: limit the jump, growing geometrically
                wn = w - maxstep
                maxstep *= 2.0
            if wn < w_floor:
                # ū would equal ū∞ to double precision: check the floor once
                gf = _time_between(w_floor, w_s, a, lnk_a, al, below, w_c, glx, glw) - ti
                if gf <= 0.0:
                    out[i] = a
                    done = True
                    break
                lo = w_floor
                wn = 0.5 * (lo + hi)
            if abs(wn - w) <= 1e-15 * max(1.0, abs(w)):
                w = wn
                break
            w = wn
        if not done:
            out[i] = a + math.exp(w)
