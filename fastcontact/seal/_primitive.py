"""Numba kernels: the primitive S(t) = ∫ σ̄ e^t dt of the seal engine and its cells (private).

Direct integrals of σ̄ (fixed and adaptive Gauss–Legendre, in t or in the offset s below an
upper end, so that a width is exact however small), the closed-form primitive of the
large-separation asymptote, and the tabulated primitive record ``sc.P`` (columns ``P_*``):
cells below the table's trusted top are bisected until their quintic Hermite partials are
verified; cells that still fail are integrated adaptively by the callers
(:mod:`fastcontact.seal._leak`). Units and records as in :mod:`fastcontact.seal._lookup`.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..kernels.hermite import _quintic_value, quintic_interval
from ..kernels.borrow import borrowed
from ._lookup import sig_d, sig_d_at

__all__ = ["build_primitive", "asym_primitive", "ADAPT_RTOL", "P_COLS"]

#: relative tolerance of the adaptive integrals and of the primitive's cell verification
ADAPT_RTOL = 1e-11

#: columns of the primitive record ``sc.P`` (one row per node): node t, S' = σ̄e^t, S'',
#: ∫ over the cell starting here, prefix sum up to here, suffix sum from here, cell verified,
#: 1/(cell width)
P_T, P_D1, P_D2, P_CELL, P_PRE, P_SUF, P_OK, P_IH = range(8)
P_COLS = 8


# =========================================================================== direct integrals
@njit(cache=True)
def _gl_t(tab, sc, a, b):
    """∫_a^b σ̄(e^t) e^t dt, fixed Gauss–Legendre (sc.glx, sc.glw)."""
    tab, sc = borrowed((tab, sc))
    half = 0.5 * (b - a)
    mid = 0.5 * (a + b)
    acc = 0.0
    for k in range(sc.glx.size):
        t = mid + half * sc.glx[k]
        acc += sc.glw[k] * sig_d_at(tab, sc, t)[0] * math.exp(t)
    return acc * half


@njit(cache=True)
def _gl_s(tab, sc, hi, s0, s1):
    """∫_{s0}^{s1} σ̄(hi − s) ds, fixed Gauss–Legendre in the offset s (widths exact)."""
    tab, sc = borrowed((tab, sc))
    half = 0.5 * (s1 - s0)
    mid = s0 + half
    acc = 0.0
    for k in range(sc.glx.size):
        acc += sc.glw[k] * sig_d_at(tab, sc, math.log(hi - (mid + half * sc.glx[k])))[0]
    return acc * half


@njit(cache=True)
def _adaptive(tab, sc, a, b, hi, in_s):
    """∫ σ̄ over [a, b] adaptively (halving until two halves agree to ADAPT_RTOL; at most
    48 levels per branch, 400 evaluations; NaN integrand → NaN). Integrands below 1e-280
    (next to percolation, where σ̄ → 0) are accepted as they are.

    in_s: a, b are offsets s below ``hi`` (integrand σ̄(hi − s): the width b − a is exact
    however small); else t values (integrand σ̄(e^t) e^t)."""
    sa = np.empty(64)
    sb = np.empty(64)
    sv = np.empty(64)
    sd = np.empty(64, dtype=np.int64)
    sa[0] = a
    sb[0] = b
    sv[0] = _gl_s(tab, sc, hi, a, b) if in_s else _gl_t(tab, sc, a, b)
    sd[0] = 0
    sp = 1
    total = 0.0
    budget = 400                            # GL evaluations (a kink costs ~2 per level)
    while sp > 0:
        sp -= 1
        budget -= 2
        x0, x1, whole, dep = sa[sp], sb[sp], sv[sp], sd[sp]
        m = 0.5 * (x0 + x1)
        if in_s:
            i1 = _gl_s(tab, sc, hi, x0, m)
            i2 = _gl_s(tab, sc, hi, m, x1)
        else:
            i1 = _gl_t(tab, sc, x0, m)
            i2 = _gl_t(tab, sc, m, x1)
        both = i1 + i2
        if both != both:
            return math.nan
        if (abs(both - whole) <= ADAPT_RTOL * both or both < 1e-280 or dep >= 48
                or budget <= 0 or not (x0 < m < x1)):
            total += both
        else:
            sa[sp], sb[sp], sv[sp], sd[sp] = m, x1, i2, dep + 1
            sa[sp + 1], sb[sp + 1], sv[sp + 1], sd[sp + 1] = x0, m, i1, dep + 1
            sp += 2
    return total


@njit(cache=True)
def _asym(t_lo, b0, b1, t):
    """∫_{-∞}^{t} σ̄ e^t' dt' for t <= t_lo (closed form of the asymptote: cubic × exp)."""
    if t == -math.inf:
        return 0.0
    y = b0 + b1 * (t_lo - t)
    return math.exp(t) * (y * y * y + 3.0 * b1 * y * y + 6.0 * b1 * b1 * y + 6.0 * b1 * b1 * b1)


@njit(cache=True)
def asym_primitive(sc, t):
    """∫_{-∞}^{t} σ̄ e^t' dt' for t <= t_lo (closed form of the asymptote: cubic × exp)."""
    return _asym(sc.t_lo, sc.b0, sc.b1, t)


# =========================================================================== primitive
@njit(cache=True)
def _node_d(tab, sc, t):
    """S' = σ̄e^t and S'' = S'(1 + d ln σ̄/dt) at t."""
    sg, dl = sig_d(tab, sc, t)
    d1 = sg * math.exp(t)
    return d1, (d1 * (1.0 + dl) if sg > 0.0 else 0.0)


@njit(cache=True)
def _cell_fit(tab, sc, a, b, d1a, d2a, d1b, d2b):
    """(∫_a^b S' dt adaptively, verified): the quintic Hermite of the partial integrals
    matches direct Gauss–Legendre within 1e-10 at 3 interior points, both edge references."""
    cell = _adaptive(tab, sc, a, b, 0.0, False) if b > a else 0.0
    good = cell > 0.0 and d1a > 0.0 and d1b > 0.0
    for f in (0.25, 0.5, 0.75):
        if not good:
            break
        t = a + f * (b - a)
        lt = _gl_t(tab, sc, a, t)               # smooth cells: one rule is exact to round-off
        rt = _gl_t(tab, sc, t, b)
        le = quintic_interval(t, a, b, 0.0, cell, d1a, d1b, d2a, d2b)
        re = -quintic_interval(t, a, b, -cell, 0.0, d1a, d1b, d2a, d2b)
        if not (abs(le - lt) <= 1e-10 * lt and abs(re - rt) <= 1e-10 * rt):
            good = False
    return cell, good


@njit(cache=True)
def build_primitive(tab, sc, tn, n_ver, max_depth):
    """The primitive record P (rows = nodes, columns P_T … P_OK) of S(t) = ∫ σ̄ e^t dt.

    Starts from the nodes ``tn``; each of the first ``n_ver`` cells (below the trusted top)
    is bisected, at most ``max_depth`` times, until its quintic Hermite partial integrals are
    verified (:func:`_cell_fit`). Cell integrals are adaptive; prefix/suffix sums compensated.
    """
    ts = [tn[0]]
    d1s = [0.0]
    d2s = [0.0]
    cells = [0.0]
    oks = [0.0]
    ts.pop()
    d1s.pop()
    d2s.pop()
    cells.pop()
    oks.pop()
    for k in range(tn.size - 1):
        stack = [(tn[k], tn[k + 1], 0)]
        while len(stack) > 0:
            a, b, dep = stack.pop()
            d1a, d2a = _node_d(tab, sc, a)
            d1b, d2b = _node_d(tab, sc, b)
            cell, good = _cell_fit(tab, sc, a, b, d1a, d2a, d1b, d2b)
            if good or k >= n_ver or dep >= max_depth:
                ts.append(a)
                d1s.append(d1a)
                d2s.append(d2a)
                cells.append(cell)
                oks.append(1.0 if good else 0.0)
            else:
                m = 0.5 * (a + b)
                stack.append((m, b, dep + 1))
                stack.append((a, m, dep + 1))
    n = len(ts)
    P = np.zeros((n + 1, P_COLS))
    for i in range(n):
        P[i, P_T] = ts[i]
        P[i, P_D1] = d1s[i]
        P[i, P_D2] = d2s[i]
        P[i, P_CELL] = cells[i]
        P[i, P_OK] = oks[i]
    P[n, P_T] = tn[tn.size - 1]
    P[n, P_D1], P[n, P_D2] = _node_d(tab, sc, tn[tn.size - 1])
    for k in range(n):
        P[k, P_IH] = 1.0 / (P[k + 1, P_T] - P[k, P_T])
    _kahan_sums(P, n, False)  # prefix sums of the cells into P_PRE (row k + 1)
    _kahan_sums(P, n, True)   # suffix sums into P_SUF (row k)
    return P


@njit(cache=True)
def _kahan_sums(P, n, suffix):
    """Compensated (Kahan) running sums of P[:n, P_CELL]: prefix sums into P[k + 1, P_PRE]
    (``suffix`` False) or suffix sums into P[k, P_SUF] (True)."""
    acc = 0.0
    comp = 0.0
    for j in range(n):
        k = n - 1 - j if suffix else j
        y = P[k, P_CELL] - comp
        s = acc + y
        comp = (s - acc) - y
        acc = s
        if suffix:
            P[k, P_SUF] = acc
        else:
            P[k + 1, P_PRE] = acc


@njit(cache=True)
def _cell(P, B, st0, ish, t):
    """Index k of the primitive cell [P[k], P[k+1]) holding t >= st0 (clamped to the last):
    bucket map over spacing 1/ish, then a scan (bisection in bisected buckets) inside it."""
    nb = B.size - 1
    c = int((t - st0) * ish)
    if c < 0:
        c = 0
    elif c >= nb:
        c = nb - 1
    k = B[c]
    hi = B[c + 1]
    if hi - k > 4:
        while k < hi:
            m = (k + hi + 1) >> 1
            if P[m, P_T] <= t:
                k = m
            else:
                hi = m - 1
    else:
        while k < hi and P[k + 1, P_T] <= t:
            k += 1
    if k > 0 and P[k, P_T] > t:              # t just below the bucket's edge (rounding)
        k -= 1
    return k


@njit(cache=True)
def _left(P, k, t):
    """∫ from the start of cell k to t (quintic); NaN if the cell is not verified."""
    a = P[k, P_T]
    if t <= a:
        return 0.0
    if P[k, P_OK] == 0.0:
        return math.nan
    return _quintic_value((t - a) * P[k, P_IH], P[k + 1, P_T] - a, 0.0, P[k, P_D1], P[k, P_D2],
                          P[k, P_CELL], P[k + 1, P_D1], P[k + 1, P_D2])


@njit(cache=True)
def _right(P, k, t):
    """∫ from t to the end of cell k (quintic); NaN if the cell is not verified."""
    b = P[k + 1, P_T]
    if t >= b:
        return 0.0
    if P[k, P_OK] == 0.0:
        return math.nan
    a = P[k, P_T]
    return -_quintic_value((t - a) * P[k, P_IH], b - a, -P[k, P_CELL], P[k, P_D1], P[k, P_D2],
                           0.0, P[k + 1, P_D1], P[k + 1, P_D2])


@njit(cache=True)
def _whole(P, k0, k1):
    """Σ cell[k0:k1] from the prefix or the suffix sums, whichever cancels less."""
    if k1 <= k0:
        return 0.0
    if P[k1, P_PRE] <= P[k0, P_SUF]:
        return P[k1, P_PRE] - P[k0, P_PRE]
    return P[k0, P_SUF] - P[k1, P_SUF]


@njit(cache=True)
def _split(P, B, st0, sh, ish, hi, w):
    """(tb, ta, kb, ka, short) of the interval [hi − w, hi]: its ends in t (ta = -inf for
    w >= hi), their cells (-1: below the table) and whether it is short (spans at most two
    cells and is no wider in t than either)."""
    tb = math.log(hi)
    if w >= hi:
        ta = -math.inf
        width = math.inf
    else:
        width = -math.log1p(-w / hi)
        ta = tb - width
    kb = _cell(P, B, st0, ish, tb) if tb >= st0 else -1
    ka = _cell(P, B, st0, ish, ta) if ta >= st0 else -1
    short = False
    if ka >= kb - 1:
        wb = P[kb + 1, P_T] - P[kb, P_T] if kb >= 0 else sh
        wa = P[ka + 1, P_T] - P[ka, P_T] if ka >= 0 else sh
        short = width <= wb and width <= wa
    return tb, ta, kb, ka, short
