"""Numba kernels: the leak integral ∫ σ̄ dπ and the flat-ring rows of the seal engine (private).

The leak integral ∫_{π_lo}^{π_hi} σ̄ dπ is never a difference of two large primitives: an
interval no wider than the primitive cells it touches is integrated directly in π with its
width w taken as given (Gauss–Legendre in π, or adaptively in the offset s = π_hi − π, so
nothing cancels as w → 0); longer ones as (bottom partial cell) + (whole cells) + (top partial
cell), each partial a quintic Hermite referenced to its own near cell edge, the whole cells
from stored prefix or suffix sums (whichever cancels less); :mod:`fastcontact.seal._primitive`.

The tables resolve σ̄ only down to their σ̄ floor (``tables.info["sigma_floor"]``); above the
last node with σ̄ above it (t_trust, just below percolation; "average" is trusted to the top)
σ̄ is an unverified extrapolation. A flat-ring row whose interval reaches past π_trust uses
the bound 0 <= σ̄ <= σ̄(π_trust) there (σ̄ falls with p_cont) and is flagged
``ST_NEAR_PERCOLATION`` unless that bound changes Q by less than ``TAIL_RTOL``.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ..kernels._index import INT0
from ._lookup import _sig_fast
from ._primitive import (P_OK, P_T, _adaptive, _asym, _gl_s, _left, _right, _split, _whole,
                         asym_primitive)

#: the order 0 ("the rule in G") as an int64 (a literal would compile the helper once more:
#: :data:`fastcontact.kernels._index.INT0`)
_I0 = INT0

__all__ = ["leak_integral", "uniform_rows", "RingRows", "RingOut", "invert_uniform", "ST_OK",
           "ST_LIFT_OFF", "ST_OPEN", "ST_PERCOLATED", "ST_ABOVE_TABLE", "ST_NOT_CONVERGED",
           "ST_NEAR_PERCOLATION", "TAIL_RTOL", "SHORT_RTOL"]

#: row status codes (``fastcontact.seal.api.STATUS`` names them)
(ST_OK, ST_LIFT_OFF, ST_OPEN, ST_PERCOLATED, ST_ABOVE_TABLE, ST_NOT_CONVERGED,
 ST_NEAR_PERCOLATION) = range(7)

#: a flat-ring row is flagged ST_NEAR_PERCOLATION when the unverified tail above π_trust could
#: change its leak integral by more than this (relative)
TAIL_RTOL = 1e-9

# =========================================================================== leak integral
#: Gauss–Legendre rules of 1, 2 and 3 points on [-1, 1] (short intervals, :func:`_gl_fast`)
_GL2_X = 0.5773502691896257
_GL3_X = 0.7745966692414834
#: relative error target of the reduced rules (error constant × z^(2n), see _gl_order)
SHORT_RTOL = 1e-14


@njit(cache=True)
def _gl_order(R, HS, tb, width):
    """Points (1, 2, 3; 0: the full rule) of Gauss–Legendre in π enough for a short interval
    of width ``width`` in t ending at tb inside one verified re-tabulation cell.

    On the cell ln σ̄ = y(t) is a cubic; with A, B, C bounds of |y'|, |y''|, |y'''| over the
    interval, z = width (A + B^(1/2) + C^(1/3) + 4) bounds the scaled derivatives of
    σ̄(π) = exp(y(ln π)) (the 4 covers the powers of π), and the relative error of the
    n-point rule is below z^2/24, z^4/4320, 4.96e-7 z^6 for n = 1, 2, 3."""
    hs = HS[0]
    ta = tb - width
    if ta < hs.t_lo:
        return 0
    rt0 = hs.rt0
    rh = hs.rh
    ub = (tb - rt0) / rh
    k = int(ub)
    if k < 0 or k >= R.shape[0] - 1 or R[k, 2] == 0.0 or int((ta - rt0) / rh) != k:
        return 0
    x = ub - k
    y0 = R[k, 0]
    y1 = R[k + 1, 0]
    d0 = R[k, 1] * rh
    d1 = R[k + 1, 1] * rh
    c2 = 3.0 * (y1 - y0) - 2.0 * d0 - d1
    c3 = 2.0 * (y0 - y1) + d0 + d1
    C = abs(6.0 * c3) / (rh * rh * rh)
    B = abs(2.0 * c2 + 6.0 * c3 * x) / (rh * rh) + C * width
    A = abs(d0 + 2.0 * c2 * x + 3.0 * c3 * x * x) / rh + B * width
    z = width * (A + math.sqrt(B) + C ** (1.0 / 3.0) + 4.0)
    z2 = z * z
    if z2 < 24.0 * SHORT_RTOL:
        return 1
    if z2 * z2 < 4320.0 * SHORT_RTOL:
        return 2
    if z2 * z2 * z2 * 4.96e-7 < SHORT_RTOL:
        return 3
    return 0


@njit(cache=True)
def _gl_fast(R, TQ, TQB, HS, G, hi, w, n):
    """∫_{hi−w}^{hi} σ̄ dπ by n-point Gauss–Legendre in π (n = 1, 2, 3; else the rule in
    ``G`` = (nodes, weights)), the width w exact."""
    half = 0.5 * w
    mid = hi - half
    if n == 1:
        return w * _sig_fast(R, TQ, TQB, HS, math.log(mid))
    if n == 2:
        return half * (_sig_fast(R, TQ, TQB, HS, math.log(mid - half * _GL2_X))
                       + _sig_fast(R, TQ, TQB, HS, math.log(mid + half * _GL2_X)))
    if n == 3:
        return half * ((5.0 / 9.0) * (_sig_fast(R, TQ, TQB, HS, math.log(mid - half * _GL3_X))
                                      + _sig_fast(R, TQ, TQB, HS, math.log(mid + half * _GL3_X)))
                       + (8.0 / 9.0) * _sig_fast(R, TQ, TQB, HS, math.log(mid)))
    acc = 0.0
    for k in range(G.shape[1]):
        acc += G[1, k] * _sig_fast(R, TQ, TQB, HS, math.log(mid + half * G[0, k]))
    return acc * half


@njit(cache=True)
def _fast_integral(P, B, R, TQ, TQB, HS, G, hi, w):
    """∫_{hi−w}^{hi} σ̄ dπ (reduced) from verified primitive cells; NaN when an unverified
    cell is involved (then :func:`leak_integral` integrates adaptively). 0 < w <= hi."""
    hs = HS[0]
    st0 = hs.st0
    tb, ta, kb, ka, short = _split(P, B, st0, hs.sh, hs.ish, hi, w)
    if short:
        if (kb >= 0 and P[kb, P_OK] == 0.0) or (ka >= 0 and P[ka, P_OK] == 0.0):
            return math.nan
        if ka < 0 <= kb:                      # split at the C¹ join with the asymptote
            e0 = math.exp(st0)
            wt = min(hi - e0, w)
            return (_gl_fast(R, TQ, TQB, HS, G, e0, w - wt, _I0)
                    + _gl_fast(R, TQ, TQB, HS, G, hi, wt, _I0))
        return _gl_fast(R, TQ, TQB, HS, G, hi, w, _gl_order(R, HS, tb, tb - ta))
    t_lo, b0, b1 = hs.t_lo, hs.b0, hs.b1
    if kb < 0:
        return _asym(t_lo, b0, b1, tb) - _asym(t_lo, b0, b1, ta)
    top = _left(P, kb, tb)
    if ka < 0:
        bottom = _asym(t_lo, b0, b1, st0) - _asym(t_lo, b0, b1, ta)
        k0 = 0
    else:
        bottom = _right(P, ka, ta)
        k0 = ka + 1
    return bottom + _whole(P, k0, kb) + top


@njit(cache=True)
def _slow_integral(tab, sc, hi, w):
    """As :func:`_fast_integral`, with σ̄ from :func:`sig_d` (the table's quintic in
    unverified re-tabulation cells) and unverified primitive cells integrated adaptively."""
    P = sc.P
    tb, ta, kb, ka, short = _split(P, sc.B, sc.st0, sc.sh, sc.HS[0].ish, hi, w)
    if short:
        direct = not ((kb >= 0 and P[kb, P_OK] == 0.0) or (ka >= 0 and P[ka, P_OK] == 0.0))
        if ka < 0 <= kb:                      # split at the C¹ join with the asymptote
            wt = min(hi - math.exp(sc.st0), w)
            if direct:
                return _gl_s(tab, sc, hi, wt, w) + _gl_s(tab, sc, hi, 0.0, wt)
            return _adaptive(tab, sc, wt, w, hi, True) + _adaptive(tab, sc, 0.0, wt, hi, True)
        if direct:
            return _gl_s(tab, sc, hi, 0.0, w)
        return _adaptive(tab, sc, 0.0, w, hi, True)
    if kb < 0:
        return asym_primitive(sc, tb) - asym_primitive(sc, ta)
    top = _left(P, kb, tb)
    if top != top:
        top = _adaptive(tab, sc, P[kb, P_T], tb, 0.0, False)
    if ka < 0:
        bottom = asym_primitive(sc, sc.st0) - asym_primitive(sc, ta)
        k0 = 0
    else:
        bottom = _right(P, ka, ta)
        if bottom != bottom:
            bottom = _adaptive(tab, sc, ta, P[ka + 1, P_T], 0.0, False)
        k0 = ka + 1
    return bottom + _whole(P, k0, kb) + top


@njit(cache=True)
def leak_integral(tab, sc, hi, w):
    """∫_{hi−w}^{hi} σ̄ dπ (reduced), 0 < w <= hi, hi <= π_top; w = hi means from π = 0.

    The width w is taken as given (no cancellation as w → 0). The table's σ̄ throughout,
    its unverified tail above π_trust included (the flat-ring rows bound that part instead)."""
    v = _fast_integral(sc.P, sc.B, sc.R, sc.TQ, sc.TQB, sc.HS, sc.G, hi, w)
    if v == v:
        return v
    return _slow_integral(tab, sc, hi, w)


# =========================================================================== flat-ring rows
@njit(cache=True)
def _mask(a):
    """Index mask of a row input: -1 (one value per row, ``a[i & -1] = a[i]``) or 0 (size 1)."""
    return -1 if a.size > 1 else 0


@njit(cache=True)
def _ring_case(p0_i, dp_i, pb_i, E_i, pa, p_perc, p_top):
    """(status, done, Q, c_hi, w) of one flat-ring row before its integral: ``done`` rows
    (open, percolated, above the table, dp = 0) take this Q; the others integrate σ̄ over
    [c_hi − w, c_hi] (reduced outlet contact pressure c_hi, width w)."""
    if pa > p0_i:                          # open: the fluid reaches the outlet
        return ST_OPEN, True, math.inf, 0.0, 0.0
    c_pa = p0_i - pb_i                     # outlet contact pressure [Pa]
    if c_pa >= p_perc * E_i:
        return ST_PERCOLATED, True, 0.0, 0.0, 0.0
    c_hi = c_pa / E_i
    if c_hi > p_top * (1.0 + 1e-13):
        return ST_ABOVE_TABLE, True, math.nan, 0.0, 0.0
    c_hi = min(c_hi, p_top)
    st = ST_LIFT_OFF if pa == p0_i else ST_OK
    if dp_i == 0.0:
        return st, True, 0.0, c_hi, 0.0
    w = dp_i / E_i
    if w > c_hi or pa == p0_i:
        w = c_hi
    return st, False, 0.0, c_hi, w


class RingRows(NamedTuple):
    """Inputs of :func:`uniform_rows` in SI (one argument instead of eight), each contiguous
    1-D of size 1 (broadcast) or n (one value per row): p0 [Pa], L [m], dp [Pa], L_y [m],
    E* [Pa], η [Pa·s], p_b [Pa], α_cj [-]."""

    p0: np.ndarray
    L: np.ndarray
    dp: np.ndarray
    L_y: np.ndarray
    E: np.ndarray
    eta: np.ndarray
    p_b: np.ndarray
    alpha: np.ndarray


class RingOut(NamedTuple):
    """Outputs of :func:`uniform_rows` (one argument instead of seven), n rows each: Q [m³/s],
    status (int8), p_a [Pa], lift_off, percolated (bool), open_inlet [m]; ``echo`` (8, n or
    0) the broadcast size-1 inputs."""

    Q: np.ndarray
    status: np.ndarray
    p_a: np.ndarray
    lift: np.ndarray
    perc: np.ndarray
    open_in: np.ndarray
    echo: np.ndarray


@njit(cache=True, parallel=True)
def uniform_rows(tab, sc, rows, cj, alpha_table, out, need):
    """Flat ring (eq. 32 with the fluid feedback): Q = (L_y/L) (h³E*/12η) ∫ σ̄ dπ per row.

    Inputs ``rows`` (:class:`RingRows`) in SI, contiguous 1-D, each of size 1 (broadcast) or
    n (one value per row); ``cj``: scale σ̄ by (alpha/alpha_table)³. Writes into ``out``
    (:class:`RingOut`) Q [m³/s], the status code, p_a = p_b + dp, lift_off (p_a >= p0),
    percolated, open_inlet [m], and, where ``need[j]`` (inputs of size 1), ``echo[j]``: the
    j-th input of (p0, L, dp, L_y, E, eta, p_b, alpha) repeated per row (shape (8, n); rows
    not needed are never touched).

    Contact pressures past π_trust (the tables' unverified tail) enter through the bound
    0 <= σ̄ <= σ̄(π_trust): Q takes the midpoint, and the row is ST_NEAR_PERCOLATION with
    Q = NaN when the bound is wider than TAIL_RTOL of the verified part."""
    p0, L, dp, L_y, E, eta, p_b, alpha = rows
    n = out.Q.size
    h3 = sc.h_rms ** 3
    P, B, R, TQ, TQB, HS, G = sc.P, sc.B, sc.R, sc.TQ, sc.TQB, sc.HS, sc.G
    pi_trust, sig_trust, p_perc, p_top = sc.pi_trust, sc.sig_trust, sc.p_perc, sc.p_top
    m0, m1, m2, m3 = _mask(p0), _mask(L), _mask(dp), _mask(L_y)
    m4, m5, m6, m7 = _mask(E), _mask(eta), _mask(p_b), _mask(alpha)
    ne = need.any()
    first = np.zeros(8)                    # the value of every size-1 input
    if ne and n > 0:
        first = np.array([p0[0], L[0], dp[0], L_y[0], E[0], eta[0], p_b[0], alpha[0]])
    for i in prange(n):
        p0_i = p0[i & m0]
        L_i = L[i & m1]
        dp_i = dp[i & m2]
        E_i = E[i & m4]
        pb_i = p_b[i & m6]
        if ne:
            _put_echo(out, i, need, first)
        pa = pb_i + dp_i
        st, done, q, c_hi, w = _ring_case(p0_i, dp_i, pb_i, E_i, pa, p_perc, p_top)
        lift_i = pa >= p0_i
        perc_i = st == ST_PERCOLATED
        open_i = L_i if st == ST_OPEN else 0.0
        if done:
            _put_row(out, i, q, st, pa, lift_i, perc_i, open_i)
            continue
        if c_hi <= pi_trust:
            I = _fast_integral(P, B, R, TQ, TQB, HS, G, c_hi, w)
            if I != I:
                I = _slow_integral(tab, sc, c_hi, w)
        else:
            over = c_hi - pi_trust             # the part of the interval in the tail
            if w <= over:
                I = math.nan
            else:
                wv = min(w - over, pi_trust)
                I = _fast_integral(P, B, R, TQ, TQB, HS, G, pi_trust, wv)
                if I != I:
                    I = _slow_integral(tab, sc, pi_trust, wv)
                U = sig_trust * over
                if U > TAIL_RTOL * I:
                    I = math.nan
                else:
                    I += 0.5 * U
            if I != I:
                st = ST_NEAR_PERCOLATION
        scale = 1.0
        if cj:
            r = alpha[i & m7] / alpha_table
            scale = r * r * r
        _put_row(out, i, L_y[i & m3] * h3 * E_i / (12.0 * eta[i & m5] * L_i) * scale * I, st, pa,
                 lift_i, perc_i, open_i)


@njit(cache=True)
def _put_row(out, i, q, st, pa, lift, perc, open_in):
    """Row i of the flat-ring outputs :class:`RingOut`. Stored by a call, not in the prange
    body: numba 0.68's parfor pass drops stores made there into arrays taken from a
    namedtuple argument (it does not see that they alias the argument)."""
    out.Q[i] = q
    out.status[i] = st
    out.p_a[i] = pa
    out.lift[i] = lift
    out.perc[i] = perc
    out.open_in[i] = open_in


@njit(cache=True)
def _put_echo(out, i, need, first):
    """out.echo[j, i] = first[j] where need[j] (a call: see :func:`_put_row`)."""
    for j in range(8):
        if need[j]:
            out.echo[j, i] = first[j]


@njit(cache=True)
def invert_uniform(tab, sc, hi, w, frac, total):
    """ln c at which ∫_{hi−w}^{c} σ̄ dπ = frac·total (bisection in ln c; flat-ring profile)."""
    target = frac * total
    lo_t = math.log(hi - w) if w < hi else min(sc.st0, math.log(hi)) - 200.0
    hi_t = math.log(hi)
    for _ in range(300):
        mid = 0.5 * (lo_t + hi_t)
        c = math.exp(mid)
        # ∫_{lo}^{c} = ∫_{lo}^{hi} − ∫_{c}^{hi}
        v = total - leak_integral(tab, sc, hi, hi - c) if c < hi else total
        if v < target:
            lo_t = mid
        else:
            hi_t = mid
        if hi_t - lo_t < 1e-14 * max(1.0, abs(mid)):
            break
    return 0.5 * (lo_t + hi_t)

