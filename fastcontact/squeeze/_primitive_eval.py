"""The time primitive's record and its evaluation: ln T at (x0, z), its inverse z(T).

Part of :mod:`fastcontact.squeeze.primitive` (the module docstring there states the
mathematics). x0 rows combine with 4-point Lagrange weights (:func:`stencil`), z cells with
the quintic Hermite of :func:`fastcontact.kernels.hermite.quintic_unit`; below the grid the
analytic logarithmic part, above v_ext the closed-form flat-film tail (Lorenz & Persson 2010,
eqs. (18), (19), (23); arXiv:1004.1037).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from ..kernels.hermite import quintic_unit
from . import _kernels as qk

__all__ = ["Primitive", "first_row", "stencil", "row_value", "row_value_2", "t_of_z", "t_of_zv",
           "z_of_t", "z_of_t_at", "z_of_t_from", "cell_root", "inverse_constants", "inverse_constants_ext", "tail_top",
           "lagrange_denominators", "one_plus_exp", "Z_NEGLIGIBLE"]

#: the tabulated primitive (reduced units). xn (nx) x0 nodes and their locator (blo, bdz,
#: bidx: fractional row index at uniform x0 samples from blo, step bdz); z0, dz, nz: the z grid; C (nx, nz, 3): ln T, d ln T/dz,
#: d² ln T/dz²; lnv (nx): ln v∞; lnS (nx): ln of the relaxation time in τ0 (the slope
#: dT/d(-z) below the grid); zs (nx): z of the default start; lk (nx): ln κ, the shift of the grid
#: variable ζ = z + ln κ (κ = (1 + (d ln σ̄/d ln v)² + (d ln π_c/d ln v)²)^½ at v∞, so that
#: the grid resolves rows where σ̄ collapses); v_ext, c, d: closed-form tail; lag (nx - 3, 4):
#: :func:`lagrange_denominators`
Primitive = namedtuple("Primitive", "xn blo bdz bidx lag z0 dz nz C lnv lnS zs lk v_ext c d")


def _index_map(xn, per_node=8):
    """(lo, dx, fidx): the fractional row index at uniform x0 samples (O(1) row location)."""
    k = per_node * xn.size
    xs = np.linspace(xn[0], xn[-1], k + 1)
    return float(xn[0]), float((xn[-1] - xn[0]) / k), np.ascontiguousarray(
        np.interp(xs, xn, np.arange(xn.size, dtype=np.float64)))


def lagrange_denominators(xn):
    """(nx - 3, 4): 1 / Π_{s≠r} (x_{j0+r} - x_{j0+s}) of the 4-point stencil starting at row j0
    (the per-case weights then need no division)."""
    m = xn.size - 3
    lag = np.empty((max(m, 0), 4))
    for r in range(4):
        d = np.ones(max(m, 0))
        for s in range(4):
            if s != r:
                d *= xn[r:r + m] - xn[s:s + m]
        lag[:, r] = 1.0 / d
    return lag


@njit(cache=True, inline="always")
def _locate(pr, x):
    """Interval j with xn[j] <= x <= xn[j+1] (-1 outside): linear estimate of the index from
    the uniform-x map, then a short walk."""
    xn = pr.xn
    n = xn.size
    if not (xn[0] <= x <= xn[n - 1]):
        return -1
    u = (x - pr.blo) / pr.bdz
    c = int(u)
    m = pr.bidx.size
    if c > m - 2:
        c = m - 2
    f = pr.bidx[c] + (u - c) * (pr.bidx[c + 1] - pr.bidx[c])
    j = int(f)
    if j > n - 2:
        j = n - 2
    while j > 0 and xn[j] > x:
        j -= 1
    while j < n - 2 and xn[j + 1] < x:
        j += 1
    return j


@njit(cache=True, inline="always")
def first_row(pr, j):
    """First of the four rows j0..j0+3 used around interval j (clamped to the grid)."""
    j0 = j - 1
    if j0 < 0:
        j0 = 0
    if j0 > pr.xn.size - 4:
        j0 = pr.xn.size - 4
    return j0


@njit(cache=True, inline="always")
def stencil(pr, x0):
    """(j0, w0, w1, w2, w3): 4-point Lagrange weights of x0 over rows j0..j0+3 (j0 = -1:
    outside the rows)."""
    j = _locate(pr, x0)
    if j < 0:
        return -1, 0.0, 0.0, 0.0, 0.0
    j0 = first_row(pr, j)
    da, db, dc, dd = x0 - pr.xn[j0], x0 - pr.xn[j0 + 1], x0 - pr.xn[j0 + 2], x0 - pr.xn[j0 + 3]
    lag = pr.lag
    ab = da * db
    cd = dc * dd
    return (j0, db * cd * lag[j0, 0], da * cd * lag[j0, 1], ab * dd * lag[j0, 2],
            ab * dc * lag[j0, 3])


@njit(cache=True, inline="always")
def row_value(arr, st):
    """Σ_r w_r arr[j0 + r] of a per-row array."""
    j0 = st[0]
    return st[1] * arr[j0] + st[2] * arr[j0 + 1] + st[3] * arr[j0 + 2] + st[4] * arr[j0 + 3]


@njit(cache=True, inline="always")
def _cell(pr, st, k):
    """Quintic Hermite coefficients (y0, d0, s0, y1, d1, s1) of the x0-combined ln T on
    z interval k."""
    j0, w0, w1, w2, w3 = st
    C = pr.C
    k1 = k + 1
    y0 = w0 * C[j0, k, 0] + w1 * C[j0 + 1, k, 0] + w2 * C[j0 + 2, k, 0] + w3 * C[j0 + 3, k, 0]
    d0 = w0 * C[j0, k, 1] + w1 * C[j0 + 1, k, 1] + w2 * C[j0 + 2, k, 1] + w3 * C[j0 + 3, k, 1]
    s0 = w0 * C[j0, k, 2] + w1 * C[j0 + 1, k, 2] + w2 * C[j0 + 2, k, 2] + w3 * C[j0 + 3, k, 2]
    y1 = w0 * C[j0, k1, 0] + w1 * C[j0 + 1, k1, 0] + w2 * C[j0 + 2, k1, 0] + w3 * C[j0 + 3, k1, 0]
    d1 = w0 * C[j0, k1, 1] + w1 * C[j0 + 1, k1, 1] + w2 * C[j0 + 2, k1, 1] + w3 * C[j0 + 3, k1, 1]
    s1 = w0 * C[j0, k1, 2] + w1 * C[j0 + 1, k1, 2] + w2 * C[j0 + 2, k1, 2] + w3 * C[j0 + 3, k1, 2]
    return y0, d0, s0, y1, d1, s1




@njit(cache=True, inline="always")
def _quintic(t, h, cf):
    """(value, d/dz) of the quintic Hermite with coefficients cf at t = (z - z_k)/h."""
    y0, d0, s0, y1, d1, s1 = cf
    return quintic_unit(t, h, y0, d0, s0, y1, d1, s1)



@njit(cache=True, inline="always")
def _tail_T(pr, v):
    """T at v >= v_ext: ∫_v^∞ dv'/σ̄_tail (closed form, π_c/π0 < e^-40 neglected)."""
    return qk._tail_int(pr.c, v + pr.d, math.inf)


@njit(cache=True, inline="always")
def _tail_v(pr, T):
    """Inverse of _tail_T: v with _tail_T(v) = T (T > 0)."""
    if pr.c == 0.0:
        a2 = 0.5 / T
    else:
        a2 = pr.c / -math.expm1(-2.0 * pr.c * T)
    return math.sqrt(a2) - pr.d


@njit(cache=True, inline="always")
def _below(pr, st):
    """(T0, h0, S) at the bottom of the z grid for the combined rows: T and dT/d(-z) at node 0
    (the cell's quintic at its left end) and the slope S = dT/d(-z) at equilibrium, the
    relaxation time t_relax/τ0, from the rows' ln S (interpolating ln S across the rows is
    exact to ~5e-9 at their midpoints, S itself only to ~1e-6 — where S grows by orders of
    magnitude over the x0 range — and S D sets ū - ū∞ = ū∞ e^z deep in the exponential
    approach, D = z0 - z relaxation times below the grid)."""
    j0, w0, w1, w2, w3 = st
    C = pr.C
    T0 = math.exp(row_value_2(C, st, 0))
    dl0 = w0 * C[j0, 0, 1] + w1 * C[j0 + 1, 0, 1] + w2 * C[j0 + 2, 0, 1] + w3 * C[j0 + 3, 0, 1]
    return T0, -T0 * dl0, math.exp(row_value(pr.lnS, st))


#: below this z = ln(v/v∞ - 1), e^z < 2^-54: 1 + e^z rounds to 1 exactly
Z_NEGLIGIBLE = -40.0


@njit(cache=True, inline="always")
def one_plus_exp(z):
    """1 + e^z, bit for bit, without calling exp where e^z is below half an ulp of 1
    (z < Z_NEGLIGIBLE; z = -inf included): there libm's exp underflows slowly or is wasted."""
    return 1.0 + math.exp(z) if z >= Z_NEGLIGIBLE else 1.0


@njit(cache=True, inline="always")
def t_of_z(pr, st, vinf, z):
    """T(x0, v) at z = ln(v/v∞ - 1) for the stencil st of x0 (v∞ = vinf)."""
    return t_of_zv(pr, st, vinf, z, vinf * one_plus_exp(z))


@njit(cache=True, inline="always")
def t_of_zv(pr, st, vinf, z, v):
    """:func:`t_of_z` where the caller has v = v∞(1 + e^z) already (saves an exp); the value
    of :func:`t_slope_of_zv` (inlined: the slope's extra arithmetic is dropped)."""
    return t_slope_of_zv(pr, st, vinf, z, v)[0]


@njit(cache=True, inline="always")
def t_slope_of_zv(pr, st, vinf, z, v):
    """(T(x0, v), dT/dz) at z, v = v∞(1 + e^z) given for the stencil st (the closed-form
    tail: dT/dv = -1/(y³ - c y), y = v + d, times dv/dz = v - v∞; below the grid the analytic
    part's; on the grid T times the quintic's d ln T/dz)."""
    if v >= pr.v_ext:
        y = v + pr.d
        return _tail_T(pr, v), -(v - vinf) / (y * (y * y - pr.c))
    z = z + row_value(pr.lk, st)
    if z < pr.z0:
        T0, h0, S = _below(pr, st)
        e = math.expm1(z - pr.z0)
        return T0 + S * (pr.z0 - z) - (h0 - S) * e, -S - (h0 - S) * (1.0 + e)
    k = int((z - pr.z0) / pr.dz)
    if k > pr.nz - 2:
        k = pr.nz - 2
    t = (z - (pr.z0 + k * pr.dz)) / pr.dz
    q, dq = _quintic(t, pr.dz, _cell(pr, st, k))
    T = math.exp(q)
    return T, T * dq


@njit(cache=True, inline="always")
def z_of_t(pr, st, vinf, T):
    """z = ln(v/v∞ - 1) with T(x0, v) = T (inverse of t_of_z; T = inf gives -inf)."""
    return z_of_t_at(pr, st, vinf, T, inverse_constants(pr, st))


@njit(cache=True, inline="always")
def inverse_constants(pr, st):
    """What :func:`z_of_t_at` needs of the stencil st beyond T: (T at v_ext, ln κ, and T0, h0,
    S of the grid's bottom, :func:`_below`) — computed once for many times of one case."""
    return inverse_constants_ext(pr, st, tail_top(pr))


@njit(cache=True, inline="always")
def tail_top(pr):
    """T at v_ext, where the closed-form tail begins (the same for every case of pr)."""
    return _tail_T(pr, pr.v_ext)


@njit(cache=True, inline="always")
def inverse_constants_ext(pr, st, T_ext):
    """:func:`inverse_constants` with T_ext = :func:`tail_top` given (hoisted out of a loop)."""
    T0, h0, S = _below(pr, st)
    return T_ext, row_value(pr.lk, st), T0, h0, S


@njit(cache=True, inline="always")
def z_of_t_at(pr, st, vinf, T, ic):
    """:func:`z_of_t` with the stencil's :func:`inverse_constants` ``ic`` given."""
    T_ext, lk, T0, h0, S = ic
    if T == math.inf:
        return -math.inf
    if not (T > 0.0):
        return math.inf
    if T <= T_ext:
        return math.log(_tail_v(pr, T) / vinf - 1.0)
    if T >= T0:
        # T - T0 = g(D), D = z0 - z >= 0, g(D) = S D + (h0 - S)(1 - e^-D): its tangent at 0
        # (slope h0) and its asymptote (S D + h0 - S) bound D on the same side (below for
        # h0 > S, g concave; above otherwise): the tighter bound starts a Newton iteration
        # that then approaches the root monotonically
        d_tan = (T - T0) / h0
        d_asy = (T - T0 - (h0 - S)) / S if S > 0.0 else d_tan
        if S > 0.0 and (d_asy >= 80.0 or (d_asy >= 40.0 and abs(h0 - S) <= 90.0 * S)):
            # far below the grid the root is the asymptote's: D - d_asy = (h0 - S)e^-D/S
            # <= 1e-17 D here, below the round-off of z (the Newton iteration would return
            # the same z, after exponentials that underflow: slow in libm)
            return pr.z0 - d_asy - row_value(pr.lk, st)
        z = pr.z0 - (max(d_tan, d_asy) if h0 > S else min(d_tan, d_asy))
        for _ in range(30):  # Newton on the analytic part below the grid
            f = T0 + S * (pr.z0 - z) - (h0 - S) * math.expm1(z - pr.z0) - T
            fp = -S - (h0 - S) * math.exp(z - pr.z0)
            dzn = f / fp
            z -= dzn
            if abs(dzn) <= 1e-13 * (1.0 + abs(z)):  # beyond the round-off of T: would stall
                break
        return z - lk
    return cell_root(pr, st, math.log(T)) - lk


@njit(cache=True, inline="always")
def cell_root(pr, st, y):
    """z of the grid (before the ln κ shift) where the combined quintic of the node values
    C[..., 0] (decreasing with k) equals y: the cell by bisection over the nodes, then the
    cell's Halley iteration (:func:`_halley_cell`)."""
    lo = 0
    hi = pr.nz - 1
    y_lo = row_value_2(pr.C, st, lo)
    y_hi = row_value_2(pr.C, st, hi)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        y_mid = row_value_2(pr.C, st, mid)
        if y_mid >= y:
            lo = mid
            y_lo = y_mid
        else:
            hi = mid
            y_hi = y_mid
    cf = _cell(pr, st, lo)
    t = _halley_cell(cf, pr.dz, y, _inverse_guess(cf, pr.dz, y_lo, y_hi, y))
    return pr.z0 + (lo + t) * pr.dz


#: cells :func:`z_of_t_from` walks from its hint's cell before it bisects instead
HINT_WALK = 3


@njit(cache=True, inline="always")
def z_of_t_from(pr, st, vinf, T, ic, z_hint):
    """:func:`z_of_t_at`, the grid cell searched from the cell of ``z_hint`` (a z near the
    root: an earlier root of a nearby T) instead of bisected over the whole grid: at most
    HINT_WALK cells either way, else the bisection. The cell is the same unique cell with
    ln T(k) >= ln T > ln T(k+1) that the bisection finds and the same Halley iteration
    follows, so the result is :func:`z_of_t_at`'s bit for bit; only the search is shorter."""
    T_ext, lk, T0, _h0, _S = ic
    if not (T_ext < T < T0) or not (abs(z_hint) < 1e300):
        return z_of_t_at(pr, st, vinf, T, ic)
    lt = math.log(T)
    k = int((z_hint + lk - pr.z0) / pr.dz)
    top = pr.nz - 2
    if k < 0:
        k = 0
    elif k > top:
        k = top
    y_lo = row_value_2(pr.C, st, k)
    y_hi = row_value_2(pr.C, st, k + 1)
    for _ in range(HINT_WALK):
        if y_lo < lt and k > 0:
            k -= 1
            y_hi = y_lo
            y_lo = row_value_2(pr.C, st, k)
        elif y_hi >= lt and k < top:
            k += 1
            y_lo = y_hi
            y_hi = row_value_2(pr.C, st, k + 1)
        else:
            break
    if not (y_lo >= lt > y_hi):
        return z_of_t_at(pr, st, vinf, T, ic)
    cf = _cell(pr, st, k)
    t = _halley_cell(cf, pr.dz, lt, _inverse_guess(cf, pr.dz, y_lo, y_hi, lt))
    return pr.z0 + (k + t) * pr.dz - lk


@njit(cache=True, inline="always")
def _inverse_guess(cf, h, y_lo, y_hi, lt):
    """Start of the cell's Halley iteration: t at ln T = lt of the cubic Hermite of the inverse
    t(ln T) from the cell's end values and slopes (error O(h⁴) — about 1e-5 on the default
    grid), the chord where the slopes do not give a monotone inverse."""
    if not (y_lo > y_hi):
        return 0.5
    s = (y_lo - lt) / (y_lo - y_hi)  # the chord
    if not (0.0 < s < 1.0):
        return 0.5
    y0, d0, _s0, y1, d1, _s1 = cf
    dy = y1 - y0
    m0 = dy / (d0 * h)  # dt/ds at the ends (s the chord variable)
    m1 = dy / (d1 * h)
    if not (0.0 < m0 < 3.0 and 0.0 < m1 < 3.0):  # slopes of a monotone cubic (Fritsch–Carlson)
        return s
    s2 = s * s
    s3 = s2 * s
    t = (s3 - 2.0 * s2 + s) * m0 + (3.0 * s2 - 2.0 * s3) + (s3 - s2) * m1
    return t if 0.0 < t < 1.0 else s


#: a Halley step of at most this (in the cell variable t) ends the cell's iteration, its
#: result taken: the error after a Halley step is ~ |f‴/(6f′) - (f″/(2f′))²| · step³,
#: ~1e-15 here, below the round-off of ln T
HALLEY_ACCEPT = 1e-5


@njit(cache=True, inline="always")
def _halley_cell(cf, h, lt, t):
    """t in (0, 1) with the cell's quintic ln T(t) = lt: safeguarded Halley iteration from ``t``
    (bisection where a step leaves the bracket). The quintic is taken in monomial form about
    the cell's left end (coefficients from its end values and derivatives, the value
    difference y1 - y0 formed first), so that an iteration is ~15 multiply-adds for f, f′ and
    f″. A step <= HALLEY_ACCEPT ends it (cubic convergence: one evaluation from the
    inverse-Hermite start, whose error is ~1e-5, in 3 of 4 solves, two in the rest — measured
    on the embedded road tables); a bracket or bisection step
    below 1e-13 (Δz <= 2.5e-14) ends it too — asking for less than the round-off of ln T
    (~1e-15 |ln T| / |d ln T/dt|) would only stall the iteration."""
    y0, d0, s0, y1, d1, s1 = cf
    dy = y1 - y0
    a1 = h * d0
    a2 = 0.5 * h * h * s0
    b1 = h * d1
    b2 = 0.5 * h * h * s1
    c3 = 10.0 * dy - 6.0 * a1 - 3.0 * a2 - 4.0 * b1 + b2
    c4 = -15.0 * dy + 8.0 * a1 + 3.0 * a2 + 7.0 * b1 - 2.0 * b2
    c5 = 6.0 * dy - 3.0 * a1 - a2 - 3.0 * b1 + b2
    g = y0 - lt
    a, b = 0.0, 1.0
    for _ in range(60):
        f = g + t * (a1 + t * (a2 + t * (c3 + t * (c4 + t * c5))))
        if f == 0.0:
            break
        if f > 0.0:
            a = t
        else:
            b = t
        f1 = a1 + t * (2.0 * a2 + t * (3.0 * c3 + t * (4.0 * c4 + t * 5.0 * c5)))
        f2 = 2.0 * a2 + t * (6.0 * c3 + t * (12.0 * c4 + t * 20.0 * c5))
        den = f1 - 0.5 * f * f2 / f1 if f1 != 0.0 else 0.0
        tn = t - f / den if den != 0.0 else 0.5 * (a + b)
        halley = a < tn < b
        if not halley:
            tn = 0.5 * (a + b)
        step = abs(tn - t)
        t = tn
        if (halley and step <= HALLEY_ACCEPT) or step <= 1e-13 or b - a <= 1e-13:
            break
    return t


@njit(cache=True, inline="always")
def row_value_2(C, st, k):
    """Σ_r w_r ln T[j0 + r, k] (the combined ln T at node k)."""
    j0 = st[0]
    return (st[1] * C[j0, k, 0] + st[2] * C[j0 + 1, k, 0] + st[3] * C[j0 + 2, k, 0]
            + st[4] * C[j0 + 3, k, 0])

