"""The Barus squeeze-out at table speed: the base time primitive plus a series of 1-D ones.

With a Barus fluid the squeeze rate is the constant-viscosity rate times g(a),
a = α p0 d, d = 1 - π_c(v)/π0 (:mod:`.viscosity`), so the reduced time from v_s down to v is

    t̃ = ∫_v^{v_s} dv'/(σ̄ d g(a)) = [T(x0, v) - T(x0, v_s)] + α p0 [S(v) - S(v_s)],

T the constant-viscosity time primitive (:mod:`.primitive`) and, with 1/g(a) = 1 + a h(a),

    S(v) = ∫_v^∞ h(α p0 d(v'))/σ̄(v') dv'

— the correction has no 1/d: it is regular at ū∞. h is analytic for |a| < 1 with positive
Taylor coefficients c_k (h(0) = 2/3, c_k ≈ 0.06 k^-2.2), so for A = α p0 <= ``API_FAST``
the truncation P_K(a) = Σ_{k<=K} c_k a^k is exact to ``SERIES_TOL`` on a ∈ [0, A] and, with
y = π_c(v)/π0 = 1 - d,

    P_K(A (1 - y)) = Σ_j E_j (-y)^j,   E_j = Σ_{k>=j} C(k, j) c_k A^k   (a Taylor shift),
    S(v) = Σ_j E_j (-1)^j y(v)^j R_j(v),   R_j(v) = π_c(v)^-j ∫_v^∞ π_c(v')^j/σ̄(v') dv'.

The R_j depend on v alone (neither on p0 nor on α): they are tabulated once per (tables,
theory) on nodes in s = ln v, dense where σ̄ collapses, as ρ_j = σ̄ R_j (smooth, O(1)) with
their exact s-derivatives dρ_j/ds = ρ_j (d ln σ̄/ds - j d ln π_c/ds) - v (cubic Hermite), beside
ln π_c and ln σ̄. A case then costs its E_j (O(K²), K ≈ 10 at α p0 = 0.1) and K + 1
multiply-adds per evaluated separation. Above v_ext (π_c/π0 < e^-40) only j = 0 remains,
the closed-form flat-film tail of the base primitive. Since every E_j is a sum of positive
terms and Σ_j E_j <= P_K(2A), rounding is not amplified for A <= 1/2 and by at most
P_K(1.2) ≈ 2 at A = 0.6; beyond ``API_FAST`` the per-case quadrature of :mod:`.viscosity`
runs.

ū at a given time solves G(z) = T(x0, v(z)) + α p0 S(v(z)) = G*, z = ln(v/v∞ - 1): Newton in
z with G' = T'(z)/g(a), from the base solution (the base primitive's inverse at G*), each step
a forward evaluation of T and S.

References: C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87;
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
"""
from __future__ import annotations

import math
import time as _clock
from collections import namedtuple
from decimal import Decimal, localcontext
from functools import lru_cache

import numpy as np
from numba import njit, prange

from ..kernels.balance import spread_blocks
from ..kernels.quadrature import gauss_legendre
from . import _kernels as qk
from ._primitive_build import _pstate, fast_limit, profile
from ..kernels.hermite import cubic_basis
from ._primitive_eval import _index_map, _locate, one_plus_exp, t_slope_of_zv, z_of_t_at

__all__ = ["API_FAST", "K_MAX", "SERIES_TOL", "BarusTable", "build", "h_coefficients", "h_series",
           "series_order", "shift", "s_at", "s_cell", "s_value", "solve_u_at_time", "u_at_time"]

#: highest series order of h; A = α p0 above API_FAST runs the per-case quadrature
K_MAX = 48
API_FAST = 0.6
#: bound on Σ_{k>K} c_k A^(k+1) of the truncated series (relative error of t̃ it may cause)
SERIES_TOL = 1e-13
#: a Newton step in z of at most this (times 1 + |z|) ends the solve for ū at a time: the
#: error left after it is ~ |G''/(2G')| step² (measured ≤ 7.4e-10 in z, i.e. relative in
#: ū - ū∞, against a bisection to 1e-12 on 2,000 random cases with α p0 up to 0.6)
Z_ACCEPT = 1e-5
#: the bisection that finishes a solve the Newton steps did not (:func:`solve_u_at_time`)
#: stops at a bracket this wide (times 1 + |z|)
Z_BISECT = 1e-12
#: Gauss–Legendre order of the cell integrals; sub-panels keep K_MAX |Δ ln π_c| <= SUB_SPAN
CELL_ORDER = 8
SUB_SPAN = 1.0

#: the tabulated R_j of one (tables, theory): nodes xn in s = ln v (the last one at ln v_ext)
#: and their locator (blo, bdz, bidx: fractional node index at uniform s samples, as the
#: primitive's rows, so that its ``_locate`` serves both); ST (ns, 4) = ln π_c, d ln π_c/ds,
#: ln σ̄, d ln σ̄/ds; RHO, DRHO (ns, K_MAX + 1) = ρ_j = σ̄ R_j and dρ_j/ds; v_ext, c, d: the
#: base primitive's closed-form tail above v_ext (T there is ∫dy/(y³ - c y), y = v + d)
BarusTable = namedtuple("BarusTable", "xn blo bdz bidx ST RHO DRHO v_ext c d")


def _inverse_series(p, n):
    """Coefficients of 1/p (p[0] != 0), n terms (Decimal arithmetic)."""
    q = [Decimal(0)] * n
    q[0] = 1 / p[0]
    for k in range(1, n):
        q[k] = -sum(p[i] * q[k - i] for i in range(1, min(k, len(p) - 1) + 1)) / p[0]
    return q


def h_series(n=K_MAX + 2, digits=60):
    """Taylor coefficients c_0..c_{n-1} of h(a) = (1/g(a) - 1)/a [-] (~20 ms).

    g(a) = b(a)/(2a) with b = Φ⁻¹(a), Φ(b) = 1 + (1 - b) ln(1 - b)/b = b φ(b),
    φ(b) = Σ_{m>=1} b^(m-1)/(m(m+1)). Lagrange inversion, [a^k] b = [b^(k-1)] ψ^k / k with
    ψ = 1/φ, then 1/g by series division; in ``digits``-digit decimal arithmetic (the
    powers ψ^k have coefficients up to ~2^k that cancel: float64 loses every digit of c_k
    beyond k ≈ 30)."""
    with localcontext() as ctx:
        ctx.prec = digits
        m = n + 2
        phi = [Decimal(1) / ((k + 1) * (k + 2)) for k in range(m)]
        psi = _inverse_series(phi, m)
        b = [Decimal(0)] * (m + 1)
        pw = [Decimal(1)] + [Decimal(0)] * (m - 1)  # ψ^0
        for k in range(1, m + 1):
            pw = [sum(pw[i] * psi[j - i] for i in range(j + 1)) for j in range(m)]  # ψ^k
            b[k] = pw[k - 1] / k
        g = [b[k + 1] / 2 for k in range(m)]  # g = b/(2a)
        ig = _inverse_series(g, m)
        return np.array([float(x) for x in ig[1:n + 1]])


@lru_cache(maxsize=1)
def h_coefficients():
    """c_0..c_{K_MAX+1} of h (the last one bounds the truncation), computed on first use."""
    return np.ascontiguousarray(h_series(K_MAX + 2))


@njit(cache=True)
def series_order(c, A):
    """Smallest K <= K_MAX with A c_{K+1} A^{K+1}/(1 - A) <= SERIES_TOL (c decreasing);
    -1 for A > API_FAST (the per-case quadrature's)."""
    if A == 0.0:
        return 0
    if not (A <= API_FAST):
        return -1
    pw = A * A  # A^(K+1) · A at K = 0
    thr = SERIES_TOL * (1.0 - A)  # the bound times (1 - A): no division per order
    for k in range(K_MAX + 1):
        if c[k + 1] * pw <= thr:
            return k
        pw *= A
    return -1


def _binomials(n):
    """(n + 1, n + 1): C(k, j) for j <= k <= n, 0 above the diagonal (exact in float64 for
    n <= 56)."""
    B = np.zeros((n + 1, n + 1))
    for k in range(n + 1):
        for j in range(k + 1):
            B[k, j] = float(math.comb(k, j))
    return B


#: C(k, j), k, j <= K_MAX (the largest, C(48, 24) ≈ 3.2e13, is exact)
BINOMIALS = _binomials(K_MAX)


@njit(cache=True)
def shift(c, A, K, E):
    """E_j = Σ_{k=j}^K C(k, j) c_k A^k, j = 0..K, into E (Taylor shift by one of the
    coefficients c_k A^k; positive terms only). Each order k adds C(k, j) c_k A^k to every
    E_j, j <= k: the K + 1 sums are independent, so the inner loop has no chain of dependent
    additions (the Pascal-triangle recurrence had one of K²/2 adds, ~75 ns/case at K ≈ 10)."""
    B = BINOMIALS
    for j in range(K + 1):
        E[j] = 0.0
    p = 1.0
    for k in range(K + 1):
        ak = c[k] * p
        p *= A
        for j in range(k + 1):
            E[j] += B[k, j] * ak


@njit(cache=True, inline="always")
def s_value(bt, E, K, x0, v):
    """(S(v), y(v)) by :func:`s_at` at s = ln v."""
    return s_at(bt, E, K, x0, v, math.log(v))


@njit(cache=True, inline="always")
def s_cell(bt, s):
    """(i, h00, h10, h01, h11, ln π_c, ln σ̄) at s = ln v < ln v_ext: the table's cell i and
    its cubic Hermite basis at s (the weights of ρ_j and dρ_j/ds there), and the interpolated
    ln π_c and ln σ̄."""
    sn = bt.xn
    i = _locate(bt, s)
    if i < 0:  # v below the lowest ū∞ served or at v_ext to rounding: the end cell
        i = 0 if s < sn[0] else sn.size - 2
    h = sn[i + 1] - sn[i]
    h00, h10, h01, h11 = cubic_basis((s - sn[i]) / h, h)
    ST = bt.ST
    lnp = h00 * ST[i, 0] + h10 * ST[i, 1] + h01 * ST[i + 1, 0] + h11 * ST[i + 1, 1]
    lns = h00 * ST[i, 2] + h10 * ST[i, 3] + h01 * ST[i + 1, 2] + h11 * ST[i + 1, 3]
    return i, h00, h10, h01, h11, lnp, lns


@njit(cache=True, inline="always")
def s_at(bt, E, K, x0, v, s):
    """(S(v), y): S = Σ_{j<=K} E_j (-y)^j R_j(v), y = π_c(v)/π0, π0 = e^x0, s = ln v given
    (the ratio targets' is ln v∞ + ln(1 + r), no log per case). Above v_ext π_c/π0 < e^-40
    is neglected, as in the flat-film tail: y = 0 there. The callers take d = 1 - y
    (absolute error ~1e-16, all that a = α p0 d needs in 1/g(a) and g(a))."""
    if v >= bt.v_ext:
        return E[0] * qk._tail_int(bt.c, v + bt.d, math.inf), 0.0
    i, h00, h10, h01, h11, lnp, lns = s_cell(bt, s)
    y = math.exp(lnp - x0)
    my = -y
    RHO = bt.RHO
    DRHO = bt.DRHO
    acc = 0.0
    yp = 1.0
    for j in range(K + 1):
        rho = h00 * RHO[i, j] + h10 * DRHO[i, j] + h01 * RHO[i + 1, j] + h11 * DRHO[i + 1, j]
        acc += E[j] * yp * rho
        yp *= my
    return acc * math.exp(-lns), y


@njit(cache=True, inline="always")
def _inv_g(c, K, a):
    """1/g(a) = 1 + a P_K(a) (the truncated series, consistent with S)."""
    p = 0.0
    for k in range(K, -1, -1):
        p = p * a + c[k]
    return 1.0 + a * p


@njit(cache=True, inline="always")
def u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss, tt, ic):
    """v = ū/h_rms reached at reduced time tt after the start (T(start) = Ts, S(start) = Ss):
    the root of G(z) = T(z) + A S(v(z)) - (Ts + A Ss + tt) in z = ln(v/v∞ - 1), T the base
    primitive's interpolant (:func:`~._primitive_eval.t_slope_of_zv`).

    Newton in z from the base solution z(Ts + tt) (one inverse), G' = T'(z)/g(a): each step
    is a forward evaluation of T and S, no inverse (~35 against ~90 ns). A step of at most
    Z_ACCEPT ends it, its result taken: the error left is of order |G''/G'| · Z_ACCEPT² (see
    Z_ACCEPT). The iteration is safeguarded (:func:`solve_u_at_time`): it never returns an
    unconverged z."""
    return solve_u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss, tt, ic, NEWTON_STEPS)


#: Newton steps of :func:`u_at_time` before it finishes by bisection on its bracket (2–5
#: evaluations measured on the benchmark's tire cases)
NEWTON_STEPS = 40


@njit(cache=True)
def solve_u_at_time(pr, st, bt, c, E, K, x0, A, vinf, vs, Ts, Ss, tt, ic, newton_steps):
    """:func:`u_at_time` with at most ``newton_steps`` Newton steps, then bisection.

    The root is bracketed: T decreases with z and 1 <= 1/g(a) < 2 (g ∈ (1/2, 1],
    :mod:`.viscosity`), so the base time T(z*) - Ts of the root lies in [tt/2, tt]:
    z_b(Ts + tt) <= z* <= z_b(Ts + tt/2), z_b the base primitive's inverse. Newton starts at
    the lower end; every evaluation narrows the bracket by the sign of G (G >= 0 below the
    root); a step that would leave the bracket (or G' = 0) ends the Newton steps, and then,
    as after ``newton_steps`` of them, the bracket is bisected until it is Z_BISECT (1 + |z|)
    wide (at most ~70 halvings from the widest bracket): the result is converged in every
    case, never a capped iteration's last iterate."""
    if tt == 0.0:
        return vs
    if tt == math.inf:
        return vinf
    target = Ts + A * Ss + tt
    z = z_of_t_at(pr, st, vinf, Ts + tt, ic)
    if z == -math.inf:  # Ts + tt beyond the primitive: ū∞ to round-off
        return vinf
    if z != z:
        return math.nan
    lo = z
    hi = math.inf
    done = False
    for _ in range(newton_steps):
        v = vinf * one_plus_exp(z)
        T, Tz = t_slope_of_zv(pr, st, vinf, z, v)
        s, y = s_value(bt, E, K, x0, v)
        f = T + A * s - target
        if f >= 0.0:
            lo = max(lo, z)
        else:
            hi = min(hi, z)
        step = f / (Tz * _inv_g(c, K, A * (1.0 - y)))
        zn = z - step
        if not (lo <= zn <= hi):  # a step out of the bracket (or G' = 0): bisect
            break
        z = zn
        if abs(step) <= Z_ACCEPT * (1.0 + abs(z)):
            done = True
            break
    if not done:
        if hi == math.inf:
            hi = z_of_t_at(pr, st, vinf, Ts + 0.5 * tt, ic)
        for _ in range(200):
            z = 0.5 * (lo + hi)
            if hi - lo <= Z_BISECT * (1.0 + abs(z)):
                break
            v = vinf * one_plus_exp(z)
            T = t_slope_of_zv(pr, st, vinf, z, v)[0]
            if T + A * s_value(bt, E, K, x0, v)[0] - target >= 0.0:
                lo = z
            else:
                hi = z
    return min(vinf * one_plus_exp(z), vs)


# =========================================================================== build
@njit(parallel=True, cache=True)
def _nodes_kernel(pf, mp, sn, ST):
    """(ln π_c, d ln π_c/ds, ln σ̄, d ln σ̄/ds) at the nodes sn (the primitive's profile below
    the table top, the analytic tail above)."""
    for i in prange(sn.size):
        lp, ls, dlp, dls = _pstate(pf, mp, math.exp(sn[i]))
        ST[i, 0] = lp
        ST[i, 1] = dlp
        ST[i, 2] = ls
        ST[i, 3] = dls


@njit(parallel=True, cache=True)
def _cells_kernel(pf, mp, sn, ST, glx, glw, I):
    """I[i, j] = ∫_{v_i}^{v_i+1} (π_c(v')/π_c(v_i))^j /σ̄(v') dv' (composite GL in s, with
    sub-panels so that the steepest power varies by at most e^SUB_SPAN on one). The cells go
    to the threads in :func:`~fastcontact.kernels.balance.spread_blocks` order: their
    sub-panel counts grow along v (3-4x more work in the upper half of the nodes), and each
    thread takes one contiguous run of the loop."""
    nj = I.shape[1]
    order = spread_blocks(sn.size - 1)
    for ii in prange(order.size):
        i = order[ii]
        lp0 = ST[i, 0]
        m = max(1, int(math.ceil((nj - 1) * abs(ST[i + 1, 0] - lp0) / SUB_SPAN)))
        hw = (sn[i + 1] - sn[i]) / m
        for j in range(nj):
            I[i, j] = 0.0
        for p in range(m):
            mid = sn[i] + (p + 0.5) * hw
            for q in range(glx.size):
                s = mid + 0.5 * hw * glx[q]
                lp, ls, dlp, dls = _pstate(pf, mp, math.exp(s))
                base = 0.5 * hw * glw[q] * math.exp(s - ls)
                r = math.exp(lp - lp0)
                for j in range(nj):
                    I[i, j] += base
                    base *= r


@njit(cache=True)
def _sweep(ST, sn, I, u0, R_top0, RHO, DRHO):
    """R_j from the top down, R_j(i) = (π_{i+1}/π_i)^j R_j(i+1) + I[i, j]; then ρ_j = σ̄ R_j
    and dρ_j/ds into RHO, DRHO. At the top (v >= v_ext) R_0 is the closed-form tail and
    R_j, j >= 1, Laplace's leading term u0/(j σ̄): weighted by (π_top/π)^j < e^(-40 j) at
    every v where y = π_c/π0 is not itself below e^-40."""
    ns, nj = RHO.shape
    R = np.empty(nj)
    R[0] = R_top0
    for j in range(1, nj):
        R[j] = u0 / (j * math.exp(ST[ns - 1, 2]))
    for i in range(ns - 1, -1, -1):
        if i < ns - 1:
            q = math.exp(ST[i + 1, 0] - ST[i, 0])
            qp = 1.0
            for j in range(nj):
                R[j] = qp * R[j] + I[i, j]
                qp *= q
        sig = math.exp(ST[i, 2])
        v = math.exp(sn[i])
        for j in range(nj):
            RHO[i, j] = sig * R[j]
            DRHO[i, j] = RHO[i, j] * (ST[i, 3] - j * ST[i, 1]) - v


#: node spacing: at most DS_MAX in s = ln v, DLNS_MAX in ln σ̄ and DLNP_MAX in ln π_c
#: (the nodes are uniform in χ = s/DS_MAX + ln σ̄/DLNS_MAX - ln π_c/DLNP_MAX: dense where σ̄
#: collapses towards percolation, as the primitive's rows)
DS_MAX = 0.02
DLNS_MAX = 0.05
DLNP_MAX = 0.2


def _nodes(pf, mp, s_lo, s_hi):
    """Nodes sn on [s_lo, s_hi], uniform in χ (see DS_MAX)."""
    fine = np.linspace(s_lo, s_hi, int(math.ceil((s_hi - s_lo) / (DS_MAX / 8))) + 1)
    st = np.empty((fine.size, 4))
    _nodes_kernel(pf, mp, fine, st)
    chi = fine / DS_MAX + st[:, 2] / DLNS_MAX - st[:, 0] / DLNP_MAX
    chi = np.maximum.accumulate(chi)
    n = int(math.ceil(chi[-1] - chi[0])) + 1
    sn = np.interp(np.linspace(chi[0], chi[-1], n), chi, fine)
    sn[0], sn[-1] = s_lo, s_hi
    return np.ascontiguousarray(np.unique(sn))


def build(model, pr, check=True):
    """The :data:`BarusTable` of ``model`` (a SqueezeModel) beside its primitive ``pr``;
    returns (table, info) with the node count, build time and the measured maximum relative
    interpolation error of S (``max_rel_err_S``, :func:`measure_error`)."""
    t0 = _clock.perf_counter()
    mp = model.mp
    # the lowest separation a served case reaches: ū∞ at the fast path's highest pressure
    lnv_lo = np.empty(1)
    qk.lnv_of_lnp_kernel(model.tab, mp, np.array([fast_limit(model)]), lnv_lo)
    pf = profile(model, math.exp(lnv_lo[0]))
    sn = _nodes(pf, mp, max(float(pf.s0), lnv_lo[0] - 2 * DS_MAX), math.log(mp.v_ext) + 1e-9)
    ns = sn.size
    ST = np.empty((ns, 4))
    _nodes_kernel(pf, mp, sn, ST)
    glx, glw = gauss_legendre(CELL_ORDER)
    I = np.empty((ns - 1, K_MAX + 1))
    _cells_kernel(pf, mp, sn, ST, glx, glw, I)
    R_top0 = float(qk._tail_int(mp.c, math.exp(sn[-1]) + mp.d, math.inf))
    RHO = np.empty((ns, K_MAX + 1))
    DRHO = np.empty((ns, K_MAX + 1))
    _sweep(ST, sn, I, float(mp.u0), R_top0, RHO, DRHO)
    bt = BarusTable(sn, *_index_map(sn), ST, RHO, DRHO, float(mp.v_ext), float(mp.c),
                    float(mp.d))
    info = {"nodes": int(ns), "k_max": K_MAX, "api_fast": API_FAST,
            "build_seconds": _clock.perf_counter() - t0}
    if check:
        info.update(measure_error(model, bt, pf, pr))
    return bt, info


@njit(parallel=True, cache=True)
def _check_kernel(pf, mp, bt, x0s, cells, glx, glw, c, err):
    """Relative error of S interpolated at the midpoint of cell i against S at node i + 1
    (the nodal values) plus ∫_{v_mid}^{v_i+1} P_K(A d)/σ̄ dv' by composite GL (A = API_FAST)."""
    K = series_order(c, API_FAST)
    for n in prange(x0s.size):
        E = np.empty(K + 1)
        shift(c, API_FAST, K, E)
        x0 = x0s[n]
        i = cells[n]
        sa = 0.5 * (bt.xn[i] + bt.xn[i + 1])
        sb = bt.xn[i + 1]
        s_mid, _ = s_value(bt, E, K, x0, math.exp(sa))
        s_node, _ = s_value(bt, E, K, x0, math.exp(sb))
        m = 16
        hw = (sb - sa) / m
        acc = 0.0
        for p in range(m):
            mid = sa + (p + 0.5) * hw
            for q in range(glx.size):
                s = mid + 0.5 * hw * glx[q]
                lp, ls, dlp, dls = _pstate(pf, mp, math.exp(s))
                a = API_FAST * -math.expm1(lp - x0)
                pk = 0.0
                for k in range(K, -1, -1):
                    pk = pk * a + c[k]
                acc += 0.5 * hw * glw[q] * math.exp(s - ls) * pk
        err[n] = abs(s_mid / (s_node + acc) - 1.0)


def measure_error(model, bt, pf, pr, n=500, seed=0):
    """Max relative interpolation error of S at the midpoints of n random cells (x0 random
    up to the fast path's limit, at least ln π_c of the cell: y <= 1 as on the way down to
    ū∞), at the largest series the fast path uses (A = API_FAST)."""
    rng = np.random.default_rng(seed)
    served = np.flatnonzero(bt.ST[:-1, 0] <= fast_limit(model))
    cells = np.ascontiguousarray(served[rng.integers(0, served.size, n)])
    x0s = rng.uniform(pr.xn[0], fast_limit(model), n)
    x0s = np.ascontiguousarray(np.maximum(x0s, bt.ST[cells, 0]))
    err = np.empty(n)
    glx, glw = gauss_legendre(CELL_ORDER)
    _check_kernel(pf, model.mp, bt, x0s, cells, glx, glw, h_coefficients(), err)
    return {"max_rel_err_S": float(np.max(err)), "checked_cells": int(n)}
