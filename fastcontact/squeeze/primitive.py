"""The time primitive of one (tables, theory): every squeeze-out time is a difference of it.

The squeeze-out ODE dv/dt̃ = -σ̄(π_c(v)) (1 - π_c(v)/π0) (Lorenz & Persson 2010, eqs. (18),
(19), (23); arXiv:1004.1037) is autonomous, so with

    T(x0, v) = ∫_v^∞ dv' / (σ̄(π_c(v')) (1 - π_c(v')/π0)),      x0 = ln π0 = ln(p0/E*),

the time from v_a down to v_b is T(x0, v_b) - T(x0, v_a) (in τ0 = 3ηR²/(2h_rms²p0)).
T is tabulated as ln T on a grid in x0 (nodes uniform in ξ = x0 - ln σ̄(x0), dense where
σ̄ collapses) × z = ln(v/v∞ - 1) (uniform), with its exact z-derivatives from the integrand,
so that z-interpolation is quintic Hermite and x0-interpolation 4-point Lagrange. Below
the grid (the logarithmic singularity at v∞) T = T0 + S (z0 - z) + (h0 - S)(1 - e^{z - z0})
analytically; above v_ext (the flat-film tail, σ̄ = y³ - c y with π_c/π0 < e^-40) T is the
closed form ∫dy/(y³ - c y). The inverse (v at a given T) is a bracketed Newton solve on the
same interpolant, so forward and inverse agree to rounding and ū(t) is monotone.

A primitive is built in one parallel pass (node quadrature, composite Gauss–Legendre in z),
and can be written to / read from Parquet with its grid and its measured interpolation error.
"""
from __future__ import annotations

import json
import math
import time as _clock
from collections import namedtuple
from pathlib import Path

import numpy as np
from numba import njit, prange

from .._core.io import atomic_path
from .._core.vocab import METADATA_KEY
from . import _kernels as qk

__all__ = ["Primitive", "load_or_build", "build", "write", "read", "set_primitive_cache",
           "primitive_path", "PRIMITIVE_VERSION", "t_of_z", "z_of_t", "stencil"]

PRIMITIVE_VERSION = 1
#: grid spacing in ξ = x0 - ln σ̄(x0) of the x0 rows
DXI = 0.1
#: z = ln(v/v∞ - 1) grid: lower end and spacing (below: analytic log singularity)
Z_LO = -10.0
DZ = 0.25
#: Gauss–Legendre order per z panel of the node quadrature
NODE_ORDER = 6
#: relative step of the central difference for dh/dz at the nodes
HZ = 1e-4

#: the tabulated primitive (reduced units). xn (nx) x0 nodes and their locator (blo, bdz,
#: bidx: fractional row index at uniform x0 samples from blo, step bdz); z0, dz, nz: the z grid; C (nx, nz, 3): ln T, d ln T/dz,
#: d² ln T/dz²; lnv (nx): ln v∞; lnS (nx): ln of the relaxation time in τ0; zs (nx): z of the
#: default start; sx (nx): slope dT/d(-z) below the grid; lk (nx): ln κ, the shift of the grid
#: variable ζ = z + ln κ (κ = (1 + (d ln σ̄/d ln v)² + (d ln π_c/d ln v)²)^½ at v∞, so that
#: the grid resolves rows where σ̄ collapses); v_ext, c, d: closed-form tail
Primitive = namedtuple("Primitive", "xn blo bdz bidx z0 dz nz C lnv lnS zs sx lk v_ext c d")


# =========================================================================== evaluation
def _index_map(xn, per_node=8):
    """(lo, dx, fidx): the fractional row index at uniform x0 samples (O(1) row location)."""
    k = per_node * xn.size
    xs = np.linspace(xn[0], xn[-1], k + 1)
    return float(xn[0]), float((xn[-1] - xn[0]) / k), np.ascontiguousarray(
        np.interp(xs, xn, np.arange(xn.size, dtype=np.float64)))


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
    a, b, c, d = pr.xn[j0], pr.xn[j0 + 1], pr.xn[j0 + 2], pr.xn[j0 + 3]
    w0 = (x0 - b) * (x0 - c) * (x0 - d) / ((a - b) * (a - c) * (a - d))
    w1 = (x0 - a) * (x0 - c) * (x0 - d) / ((b - a) * (b - c) * (b - d))
    w2 = (x0 - a) * (x0 - b) * (x0 - d) / ((c - a) * (c - b) * (c - d))
    w3 = (x0 - a) * (x0 - b) * (x0 - c) / ((d - a) * (d - b) * (d - c))
    return j0, w0, w1, w2, w3


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
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    t5 = t4 * t
    val = ((1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5) * y0
           + (t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5) * h * d0
           + 0.5 * (t2 - 3.0 * t3 + 3.0 * t4 - t5) * h * h * s0
           + (10.0 * t3 - 15.0 * t4 + 6.0 * t5) * y1
           + (-4.0 * t3 + 7.0 * t4 - 3.0 * t5) * h * d1
           + 0.5 * (t3 - 2.0 * t4 + t5) * h * h * s1)
    der = ((-30.0 * t2 + 60.0 * t3 - 30.0 * t4) * y0
           + (1.0 - 18.0 * t2 + 32.0 * t3 - 15.0 * t4) * h * d0
           + 0.5 * (2.0 * t - 9.0 * t2 + 12.0 * t3 - 5.0 * t4) * h * h * s0
           + (30.0 * t2 - 60.0 * t3 + 30.0 * t4) * y1
           + (-12.0 * t2 + 28.0 * t3 - 15.0 * t4) * h * d1
           + 0.5 * (3.0 * t2 - 8.0 * t3 + 5.0 * t4) * h * h * s1)
    return val, der / h


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
    """(T0, h0, S) at the bottom of the z grid for the combined rows."""
    cf = _cell(pr, st, 0)
    l0, dl0 = _quintic(0.0, pr.dz, cf)
    T0 = math.exp(l0)
    return T0, -T0 * dl0, row_value(pr.sx, st)


@njit(cache=True, inline="always")
def t_of_z(pr, st, vinf, z):
    """T(x0, v) at z = ln(v/v∞ - 1) for the stencil st of x0 (v∞ = vinf)."""
    v = vinf * (1.0 + math.exp(z))
    if v >= pr.v_ext:
        return _tail_T(pr, v)
    z = z + row_value(pr.lk, st)
    if z < pr.z0:
        T0, h0, S = _below(pr, st)
        return T0 + S * (pr.z0 - z) - (h0 - S) * math.expm1(z - pr.z0)
    k = int((z - pr.z0) / pr.dz)
    if k > pr.nz - 2:
        k = pr.nz - 2
    t = (z - (pr.z0 + k * pr.dz)) / pr.dz
    return math.exp(_quintic(t, pr.dz, _cell(pr, st, k))[0])


@njit(cache=True, inline="always")
def z_of_t(pr, st, vinf, T):
    """z = ln(v/v∞ - 1) with T(x0, v) = T (inverse of t_of_z; T = inf gives -inf)."""
    if T == math.inf:
        return -math.inf
    if not (T > 0.0):
        return math.inf
    if T <= _tail_T(pr, pr.v_ext):
        return math.log(_tail_v(pr, T) / vinf - 1.0)
    lk = row_value(pr.lk, st)
    T0, h0, S = _below(pr, st)
    if T >= T0:
        z = pr.z0 - (T - T0) / h0
        for _ in range(30):  # Newton on the analytic part below the grid
            f = T0 + S * (pr.z0 - z) - (h0 - S) * math.expm1(z - pr.z0) - T
            fp = -S - (h0 - S) * math.exp(z - pr.z0)
            dzn = f / fp
            z -= dzn
            if abs(dzn) <= 1e-13 * (1.0 + abs(z)):  # beyond the round-off of T: would stall
                break
        return z - lk
    lt = math.log(T)
    # bracket: combined ln T at the nodes decreases with k
    lo = 0
    hi = pr.nz - 1
    y_lo = row_value_2(pr.C, st, lo)
    y_hi = row_value_2(pr.C, st, hi)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        y_mid = row_value_2(pr.C, st, mid)
        if y_mid >= lt:
            lo = mid
            y_lo = y_mid
        else:
            hi = mid
            y_hi = y_mid
    cf = _cell(pr, st, lo)
    a, b = 0.0, 1.0
    # start from the chord, then safeguarded Newton on the combined quintic; |Δt| <= 1e-13
    # (Δz <= 2.5e-14) ends it: quadratic convergence makes the last step's error far smaller,
    # and asking for less than the round-off of ln T (~1e-15 |ln T| / |d ln T/dt|) would
    # only stall the iteration in bisection
    t = (y_lo - lt) / (y_lo - y_hi) if y_lo > y_hi else 0.5
    if not (0.0 < t < 1.0):
        t = 0.5
    for _ in range(60):
        val, der = _quintic(t, pr.dz, cf)
        f = val - lt
        if f == 0.0:
            break
        if f > 0.0:
            a = t
        else:
            b = t
        tn = t - f / (der * pr.dz) if der != 0.0 else 0.5 * (a + b)
        if not (a < tn < b):
            tn = 0.5 * (a + b)
        if abs(tn - t) <= 1e-13 or b - a <= 1e-13:
            t = tn
            break
        t = tn
    return pr.z0 + (lo + t) * pr.dz - lk


@njit(cache=True, inline="always")
def row_value_2(C, st, k):
    """Σ_r w_r ln T[j0 + r, k] (the combined ln T at node k)."""
    j0 = st[0]
    return (st[1] * C[j0, k, 0] + st[2] * C[j0 + 1, k, 0] + st[3] * C[j0 + 2, k, 0]
            + st[4] * C[j0 + 3, k, 0])


# =========================================================================== build
#: x0-independent state along s = ln v (cubic Hermite on a fine uniform grid, below the table
#: top): ell = ln π_c, lam = ln σ̄ and their s-derivatives; above v_top the analytic tail
Profile = namedtuple("Profile", "s0 ds A")  # A[i] = (ell, dell, lam, dlam) at s0 + i ds
#: spacing of the profile grid in ln v and the central-difference step of its derivatives
PROFILE_DS = 0.004
PROFILE_FD = 1e-5


@njit(cache=True)
def _state_fd(tab, s):
    """(ln π_c, ln σ̄) of the tables at ln v = s."""
    lp = qk.k_lnp_of_lnu(tab, s)
    return lp, math.log(qk.k_sigma_of_lnp(tab, lp))


@njit(parallel=True, cache=True)
def _profile_kernel(tab, s0, ds, A):
    n = A.shape[0]
    hh = PROFILE_FD
    for i in prange(n):
        s = s0 + i * ds
        lp, ls = _state_fd(tab, s)
        A[i, 0] = lp
        A[i, 2] = ls
        if 0 < i < n - 1:
            la, lsa = _state_fd(tab, s - hh)
            lb, lsb = _state_fd(tab, s + hh)
            A[i, 1] = (lb - la) / (2.0 * hh)
            A[i, 3] = (lsb - lsa) / (2.0 * hh)
        else:  # one-sided, second order, inside the table
            sg = 1.0 if i == 0 else -1.0
            la, lsa = _state_fd(tab, s + sg * hh)
            lb, lsb = _state_fd(tab, s + 2.0 * sg * hh)
            A[i, 1] = sg * (-3.0 * lp + 4.0 * la - lb) / (2.0 * hh)
            A[i, 3] = sg * (-3.0 * ls + 4.0 * lsa - lsb) / (2.0 * hh)


@njit(cache=True)
def _pstate(pf, mp, v):
    """(ln π_c, ln σ̄, d ln π_c/d ln v, d ln σ̄/d ln v) at v: the profile below the table
    top, the analytic tail above."""
    if v > mp.v_top:
        y = v + mp.d
        y2c = y * y - mp.c
        return (mp.x_min - (v - mp.v_top) / mp.u0, math.log(y * y2c), -v / mp.u0,
                v * (3.0 * y * y - mp.c) / (y * y2c))
    u = (math.log(v) - pf.s0) / pf.ds
    i = int(u)
    A = pf.A
    n = A.shape[0]
    if i < 0:
        i = 0
    if i > n - 2:
        i = n - 2
    t = u - i
    h = pf.ds
    t2 = t * t
    t3 = t2 * t
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = (t3 - 2.0 * t2 + t) * h
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = (t3 - t2) * h
    g00 = (6.0 * t2 - 6.0 * t) / h
    g10 = 3.0 * t2 - 4.0 * t + 1.0
    g11 = 3.0 * t2 - 2.0 * t
    e0, de0, l0, dl0 = A[i, 0], A[i, 1], A[i, 2], A[i, 3]
    e1, de1, l1, dl1 = A[i + 1, 0], A[i + 1, 1], A[i + 1, 2], A[i + 1, 3]
    return (h00 * e0 + h10 * de0 + h01 * e1 + h11 * de1,
            h00 * l0 + h10 * dl0 + h01 * l1 + h11 * dl1,
            g00 * (e0 - e1) + g10 * de0 + g11 * de1,
            g00 * (l0 - l1) + g10 * dl0 + g11 * dl1)


@njit(cache=True)
def _plnv(pf, mp, x):
    """ln v with ln π_c(v) = x on the profile (Newton; the tail above the table top)."""
    if x <= mp.x_min:
        return math.log(mp.v_top + mp.u0 * (mp.x_min - x))
    # start: bisection bracket over the grid (ell decreases with s)
    lo = 0
    hi = pf.A.shape[0] - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if pf.A[mid, 0] > x:
            lo = mid
        else:
            hi = mid
    s = pf.s0 + (lo + 0.5) * pf.ds
    for _ in range(50):
        e, lm, de, dl = _pstate(pf, mp, math.exp(s))
        step = (e - x) / de
        s -= step
        if abs(step) < 1e-15:
            break
    return s


@njit(cache=True)
def _h(pf, mp, x0, vinf, z):
    """dT/d(-z) at z: the integrand (v - v∞)/(σ̄ (1 - π_c/π0)) in z."""
    e = vinf * math.exp(z)
    lp, lm, de, dl = _pstate(pf, mp, vinf + e)
    return e / (math.exp(lm) * -math.expm1(lp - x0))


@njit(cache=True)
def _h_dlnh(pf, mp, x0, vinf, z):
    """(h, d ln h/dz) at z (exact derivative of the profile's h)."""
    e = vinf * math.exp(z)
    v = vinf + e
    lp, lm, de, dl = _pstate(pf, mp, v)
    dd = -math.expm1(lp - x0)
    q = math.exp(lp - x0)
    r = e / v
    return e / (math.exp(lm) * dd), 1.0 - r * dl + r * q * de / dd


@njit(cache=True)
def _panel(pf, mp, x0, vinf, za, zb, glx, glw):
    """∫_{za}^{zb} h dz, one Gauss–Legendre panel."""
    if not (zb > za):
        return 0.0
    hw = 0.5 * (zb - za)
    mid = 0.5 * (za + zb)
    acc = 0.0
    for j in range(glx.size):
        acc += glw[j] * _h(pf, mp, x0, vinf, mid + hw * glx[j])
    return acc * hw


@njit(cache=True)
def _build_row(pf, mp, x0, vinf, lk, z0, dz, glx, glw, C, j):
    """ln T and its z-derivatives at the ζ nodes (z = ζ - lk) of row j; returns the slope
    S below the grid."""
    nz = C.shape[1]
    z_ext = math.log(mp.v_ext / vinf - 1.0) if mp.v_ext > vinf else -math.inf
    z_prev = z_ext
    T_prev = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
    for k in range(nz - 1, -1, -1):
        z = z0 + k * dz - lk
        if z >= z_ext:
            T = qk._tail_int(mp.c, vinf * (1.0 + math.exp(z)) + mp.d, math.inf)
        else:
            T = T_prev + _panel(pf, mp, x0, vinf, z, z_prev, glx, glw)
            z_prev = z
            T_prev = T
        h, dlnh = _h_dlnh(pf, mp, x0, vinf, z)
        C[j, k, 0] = math.log(T)
        C[j, k, 1] = -h / T
        C[j, k, 2] = -h * dlnh / T - (h / T) ** 2
    # slope below the grid: h(z) = S + a e^z fitted to the two lowest nodes
    h0 = -C[j, 0, 1] * math.exp(C[j, 0, 0])
    h1 = -C[j, 1, 1] * math.exp(C[j, 1, 0])
    a = (h1 - h0) / (math.exp(z0 + dz) - math.exp(z0))
    return h0 - a * math.exp(z0)


@njit(cache=True)
def _lnkappa(pf, mp, vinf):
    """ln κ of the row with equilibrium vinf (see :data:`Primitive`)."""
    e, lm, de, dl = _pstate(pf, mp, vinf)
    return 0.5 * math.log(1.0 + de * de + dl * dl)


@njit(parallel=True, cache=True)
def _build_kernel(pf, mp, xn, z0, dz, glx, glw, C, lnv, lnS, zs, sx, lk):
    for j in prange(xn.size):
        x0 = xn[j]
        lv = _plnv(pf, mp, x0)
        vinf = math.exp(lv)
        lnv[j] = lv
        lk[j] = _lnkappa(pf, mp, vinf)
        sx[j] = _build_row(pf, mp, x0, vinf, lk[j], z0, dz, glx, glw, C, j)
        e, lm, de, dl = _pstate(pf, mp, vinf)
        lnS[j] = lv - math.log(-de) - lm  # S = v∞ |d ln v/d ln π| / σ̄(π0)
        vs = math.exp(_plnv(pf, mp, x0 + mp.lnp_start))
        zs[j] = math.log(vs / vinf - 1.0)


@njit(parallel=True, cache=True)
def _check_kernel(pf, mp, pr, xm, zm, glx, glw, err):
    """Relative error of the interpolated T at (xm[i], zm[i]) against direct quadrature."""
    for i in prange(xm.size):
        x0 = xm[i]
        vinf = math.exp(_plnv(pf, mp, x0))
        st = stencil(pr, x0)
        z = zm[i] - row_value(pr.lk, st)
        v = vinf * (1.0 + math.exp(z))
        z_ext = math.log(mp.v_ext / vinf - 1.0)
        if z >= z_ext:
            T = qk._tail_int(mp.c, v + mp.d, math.inf)
        else:
            T = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
            m = int(math.ceil((z_ext - z) / (0.25 * pr.dz)))
            hw = (z_ext - z) / m
            for q in range(m):
                T += _panel(pf, mp, x0, vinf, z + q * hw, z + (q + 1) * hw, glx, glw)
        err[i] = abs(t_of_z(pr, st, vinf, z) / T - 1.0)


@njit(cache=True)
def _lnkappa_rows_k(pf, mp, xn, out):
    for j in range(xn.size):
        out[j] = _lnkappa(pf, mp, math.exp(_plnv(pf, mp, xn[j])))


def _lnkappa_rows(pf, mp, xn):
    out = np.empty(xn.size)
    _lnkappa_rows_k(pf, mp, xn, out)
    return out


def profile(model, v_lo):
    """The x0-independent state on s = ln v ∈ [ln v_lo, ln v_top] (see :data:`Profile`)."""
    lnu = model.tables.u_range
    s0 = max(math.log(v_lo) - 4 * PROFILE_DS, math.log(lnu[0]) + 1e-13)
    s1 = math.log(lnu[1]) - 1e-13
    n = int(math.ceil((s1 - s0) / PROFILE_DS)) + 1
    ds = (s1 - s0) / (n - 1)
    A = np.empty((n, 4))
    _profile_kernel(model.tab, s0, ds, A)
    return Profile(s0, ds, A)


#: rows end X_END below the trap; cases within X_FALLBACK of it use the per-case quadrature
#: (σ̄ collapses there faster than any fixed grid resolves; < 1 % of the pressure range)
X_END = 0.005
X_FALLBACK = 0.01


def _kink(model):
    """ln p̄ of the tables' last node with σ̄ > 0: beyond it σ̄^(1/3) is linear to the exact
    percolation pressure, so ln σ̄ has a kink there that no smooth grid may straddle."""
    lnp, n_open = model.tab[0], int(model.tab[6])
    return float(lnp[n_open - 1]) if n_open < lnp.size else math.inf


def fast_limit(model):
    """Largest ln(p0/E*) the primitive serves (above: per-case quadrature)."""
    lim = min(model.x_trap - X_FALLBACK, _kink(model) - 2 * X_FALLBACK)
    return min(lim, model.x_max)


def _x_nodes(model, dxi):
    """x0 nodes uniform in ξ = x0 - ln σ̄(x0) on [x_min, x_hi]."""
    x_hi = min(model.x_trap - X_END, _kink(model) - X_END, model.x_max)
    xs = np.linspace(model.x_min, x_hi, 20001)
    sig = np.empty(xs.size)
    qk.sigma_kernel(model.tab, xs, sig)
    xi = np.maximum.accumulate(xs - np.log(sig))
    n = max(int(math.ceil((xi[-1] - xi[0]) / dxi)) + 1, 8)
    xn = np.interp(np.linspace(xi[0], xi[-1], n), xi, xs)
    xn[0], xn[-1] = model.x_min, x_hi
    return np.ascontiguousarray(np.unique(xn))


def build(model, dxi=DXI, z_lo=Z_LO, dz=DZ, order=NODE_ORDER, check=True):
    """Build the primitive of ``model`` (a :class:`~fastcontact.squeeze.model.SqueezeModel`).

    Returns ``(Primitive, info)``; ``info`` holds the grid sizes, build time and the measured
    maximum relative interpolation error of T at cell centres (``max_rel_err_T``).
    """
    t0 = _clock.perf_counter()
    mp, tab = model.mp, model.tab
    xn = _x_nodes(model, dxi)
    lnv_lo = np.empty(1)
    qk.lnv_of_lnp_kernel(tab, mp, np.array([xn[-1]]), lnv_lo)
    pf = profile(model, math.exp(lnv_lo[0]))
    lk_max = float(np.max(_lnkappa_rows(pf, mp, xn)))
    z_hi = math.log(mp.v_ext / math.exp(lnv_lo[0]) - 1.0) + lk_max
    nz = int(math.ceil((z_hi - z_lo) / dz)) + 2
    nx = xn.size
    C = np.empty((nx, nz, 3))
    lnv, lnS, zs, sx, lk = (np.empty(nx) for _ in range(5))
    glx, glw = np.polynomial.legendre.leggauss(order)
    _build_kernel(pf, mp, xn, float(z_lo), float(dz), glx, glw, C, lnv, lnS, zs, sx, lk)
    pr = Primitive(xn, *_index_map(xn), float(z_lo), float(dz), nz, C, lnv, lnS, zs, sx, lk, float(mp.v_ext), float(mp.c), float(mp.d))
    info = {"nx": int(nx), "nz": int(nz), "dxi": float(dxi), "build_seconds":
            _clock.perf_counter() - t0}
    if check:
        info.update(measure_error(model, pr, pf))
    return pr, info


def measure_error(model, pr, pf, n_x=64, order=NODE_ORDER):
    """Max relative error of the interpolated T at cell centres (n_x x0 cells × all z cells)."""
    rng = np.random.default_rng(0)
    served = int(np.searchsorted(pr.xn, fast_limit(model), side="right")) - 1
    cells = np.unique(rng.integers(0, max(served, 1), n_x))  # cells the fast path serves
    xm = 0.5 * (pr.xn[cells] + pr.xn[cells + 1])
    zc = pr.z0 + (np.arange(pr.nz - 1) + 0.5) * pr.dz
    X, Z = np.meshgrid(xm, zc, indexing="ij")
    err = np.empty(X.size)
    glx, glw = np.polynomial.legendre.leggauss(order)
    _check_kernel(pf, model.mp, pr, np.ascontiguousarray(X.ravel()),
                  np.ascontiguousarray(Z.ravel()), glx, glw, err)
    return {"max_rel_err_T": float(np.max(err)), "checked_points": int(err.size)}


# =========================================================================== storage
_CACHE_ATTR = "_squeeze_primitive_dir"


def set_primitive_cache(tables, directory):
    """Keep the time primitives of ``tables`` in ``directory`` (Parquet, keyed by content):
    later calls on equal tables, in this or another process, read them instead of building."""
    setattr(tables, _CACHE_ATTR, None if directory is None else Path(directory))


def primitive_path(directory, model) -> Path:
    """File of ``model``'s primitive in ``directory``."""
    return Path(directory) / f"squeeze_primitive_{model.theory}_{model.key()}.parquet"


def load_or_build(model, cache_dir=None):
    """The primitive of ``model``: read from the cache directory if present, else built (and
    written there when a directory is configured)."""
    if cache_dir is None:
        cache_dir = getattr(model.tables, _CACHE_ATTR, None)
    if cache_dir is not None:
        path = primitive_path(cache_dir, model)
        if path.is_file():
            try:
                pr, info = read(path, expect_key=model.key())
                model.primitive_info = info
                return pr
            except ValueError:
                pass  # damaged or stale: rebuild and overwrite
    pr, info = build(model, check=cache_dir is not None)
    model.primitive_info = info
    if cache_dir is not None:
        write(primitive_path(cache_dir, model), pr, info, model)
    return pr


def write(path, pr, info, model):
    """Write a primitive to Parquet atomically (rows = x0 nodes; grid and error in metadata)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    nz = pr.nz
    cols = {"x0": pr.xn, "ln_v_inf": pr.lnv, "ln_S": pr.lnS, "z_start": pr.zs, "slope_below": pr.sx,
            "ln_kappa": pr.lk}
    arrays = {k: pa.array(v) for k, v in cols.items()}
    for q, k in enumerate(("L", "D1", "D2")):
        arrays[k] = pa.FixedSizeListArray.from_arrays(
            pa.array(np.ascontiguousarray(pr.C[:, :, q]).ravel()), nz)
    meta = {"kind": "squeeze_time_primitive", "version": PRIMITIVE_VERSION, "key": model.key(),
            "theory": model.theory, "z0": pr.z0, "dz": pr.dz, "nz": nz, "v_ext": pr.v_ext,
            "c": pr.c, "d": pr.d, "info": info,
            "units": "reduced: x0 = ln(p0/E*), z = ln(u/u_inf - 1), T in tau0 = 3 eta R^2/(2 h_rms^2 p0)",
            "columns": {"L": "ln T", "D1": "d ln T/dz", "D2": "d2 ln T/dz2"}}
    table = pa.table(arrays).replace_schema_metadata(
        {METADATA_KEY: json.dumps(meta, sort_keys=True).encode()})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, write_page_checksum=True)
    return Path(path)


def read(path, expect_key=None):
    """Read a primitive written by :func:`write`; ValueError if damaged or not the expected."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path, page_checksum_verification=True)
        meta = json.loads(table.schema.metadata[METADATA_KEY])
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
        raise ValueError(f"primitive file {str(path)!r} cannot be read ({exc})") from None
    if meta.get("version") != PRIMITIVE_VERSION or (expect_key and meta.get("key") != expect_key):
        raise ValueError(f"primitive file {str(path)!r} does not belong to these tables")
    nz = int(meta["nz"])
    col = {k: np.ascontiguousarray(table.column(k).to_numpy(), dtype=np.float64)
           for k in ("x0", "ln_v_inf", "ln_S", "z_start", "slope_below", "ln_kappa")}
    mats = {k: np.ascontiguousarray(table.column(k).combine_chunks().flatten().to_numpy()
                                    .reshape(-1, nz), dtype=np.float64) for k in ("L", "D1", "D2")}
    xn = col["x0"]
    pr = Primitive(xn, *_index_map(xn), float(meta["z0"]),
                   float(meta["dz"]), nz,
                   np.ascontiguousarray(np.stack([mats["L"], mats["D1"], mats["D2"]], axis=2)),
                   col["ln_v_inf"],
                   col["ln_S"], col["z_start"], col["slope_below"], col["ln_kappa"],
                   float(meta["v_ext"]),
                   float(meta["c"]), float(meta["d"]))
    return pr, meta["info"]
