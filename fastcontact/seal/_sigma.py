"""Numba kernels: reduced conductivity σ̄(π) and its primitive for the seal engine (private).

Reduced units: π = p_cont/E*, t = ln π, σ̄ = 12ησ_eff/h_rms³ (eq. 23). Every kernel takes the
table record ``tab`` (:meth:`fastcontact.tables.Tables.kernel_data`) and the seal record ``sc``
(:class:`fastcontact.seal.context.SealRecord`), both flat, so they pass into ``prange``.

σ̄ beyond the table: at and above the percolation pressure exactly 0; below the table
(ū ≳ 32 h_rms) the large-separation asymptote, σ̄^(1/3) = b0 + b1 (t_lo − t), continued C¹.
Inside: ln σ̄ re-tabulated on a uniform t grid (cubic Hermite, every cell verified against the
table kernel); unverified cells evaluate the table's own quintic (value and exact slope).

The leak integral ∫_{π_lo}^{π_hi} σ̄ dπ is never a difference of two large primitives: an
interval no wider than the primitive cells it touches is integrated directly in π with its
width w taken as given (Gauss–Legendre in π, or adaptively in the offset s = π_hi − π, so
nothing cancels as w → 0); longer ones as (bottom partial cell) + (whole cells) + (top partial
cell), each partial a quintic Hermite referenced to its own near cell edge, the whole cells
from stored prefix or suffix sums (whichever cancels less). Primitive cells below the
table's trusted top are bisected until their quintic partials are verified; cells that still
fail (and the tail above the trusted top) are integrated adaptively.

The tables resolve σ̄ only down to their σ̄ floor (``tables.info["sigma_floor"]``); above the
last node with σ̄ above it (t_trust, just below percolation; "average" is trusted to the top)
σ̄ is an unverified extrapolation. A flat-ring row whose interval reaches past π_trust uses
the bound 0 <= σ̄ <= σ̄(π_trust) there (σ̄ falls with p_cont) and is flagged
``ST_NEAR_PERCOLATION`` unless that bound changes Q by less than ``TAIL_RTOL``.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..kernels.hermite import _quintic_value, quintic_interval, quintic_unit
from ..kernels.locate import locate_asc
from ..tables import k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp

__all__ = ["sig_d", "table_sig_d", "sigma_of_c", "ubar_of_c", "retabulate", "verify_cells",
           "build_primitive", "leak_integral", "uniform_rows", "sigma_rows", "ubar_rows",
           "invert_uniform", "ST_OK", "ST_LIFT_OFF", "ST_OPEN", "ST_PERCOLATED",
           "ST_ABOVE_TABLE", "ST_NOT_CONVERGED", "ST_NEAR_PERCOLATION", "contact_of_u",
           "asym_primitive", "TAIL_RTOL", "ADAPT_RTOL", "SHORT_RTOL", "P_COLS", "H_SIZE"]

#: row status codes (``fastcontact.seal.api.STATUS`` names them)
(ST_OK, ST_LIFT_OFF, ST_OPEN, ST_PERCOLATED, ST_ABOVE_TABLE, ST_NOT_CONVERGED,
 ST_NEAR_PERCOLATION) = range(7)

#: relative tolerance of the adaptive integrals and of the primitive's cell verification
ADAPT_RTOL = 1e-11
#: a flat-ring row is flagged ST_NEAR_PERCOLATION when the unverified tail above π_trust could
#: change its leak integral by more than this (relative)
TAIL_RTOL = 1e-9

#: slots of the hot scalars ``sc.HS`` (re-tabulation origin and step, table bottom, asymptote,
#: ln π_perc, primitive origin and coarse step, the table's bucket map, its open nodes, ln p̄_c,
#: 1/coarse step)
(H_RT0, H_RH, H_TLO, H_B0, H_B1, H_TPERC, H_ST0, H_SH, H_TQLO, H_TQDZ, H_NOPEN,
 H_LNPPERC, H_ISH) = range(13)
H_SIZE = 13

#: columns of the primitive record ``sc.P`` (one row per node): node t, S' = σ̄e^t, S'',
#: ∫ over the cell starting here, prefix sum up to here, suffix sum from here, cell verified,
#: 1/(cell width)
P_T, P_D1, P_D2, P_CELL, P_PRE, P_SUF, P_OK, P_IH = range(8)
P_COLS = 8


# =========================================================================== σ̄ and ū
@njit(cache=True)
def table_sig_d(tab, t):
    """(σ̄, d ln σ̄/dt) of the table interpolant at t = ln π (exactly k_sigma_of_lnp's value,
    and the slope of the same interpolant); (0, -inf) at/after percolation, NaN outside."""
    lnp = tab.lnp
    i = locate_asc(t, lnp, tab.bp_lo, tab.bp_dz, tab.bp_idx)
    if i < 0:
        return math.nan, math.nan
    if t >= tab.lnp_perc:
        return 0.0, -math.inf
    if i + 1 < tab.n_open:
        h = lnp[i + 1] - lnp[i]
        y, dy = quintic_unit((t - lnp[i]) / h, h, tab.lnsig[i], tab.dlnsig[i], tab.d2lnsig[i],
                             tab.lnsig[i + 1], tab.dlnsig[i + 1], tab.d2lnsig[i + 1])
        return math.exp(y), dy
    j = tab.n_open - 1
    if j < 0 or tab.lnp_perc == math.inf:
        return 0.0, -math.inf
    d = tab.lnp_perc - t
    cr = math.exp(tab.lnsig[j] / 3.0) * d / (tab.lnp_perc - lnp[j])
    return cr * cr * cr, -3.0 / d


@njit(cache=True)
def sig_d(tab, sc, t):
    """(σ̄, d ln σ̄/d t) at t = ln π; (0, -inf) at/after percolation, NaN above the table."""
    if t < sc.t_lo:
        s = sc.b0 + sc.b1 * (sc.t_lo - t)
        return s * s * s, -3.0 * sc.b1 / s
    if t >= sc.t_perc:
        return 0.0, -math.inf
    if t > sc.t_hi:
        return math.nan, math.nan
    h = sc.rh
    u = (t - sc.rt0) / h
    k = int(u)
    if k >= 0 and k < sc.ok.size and sc.ok[k]:
        x = u - k
        x2 = x * x
        x3 = x2 * x
        y0 = sc.lns[k]
        y1 = sc.lns[k + 1]
        d0 = sc.dlns[k] * h
        d1 = sc.dlns[k + 1] * h
        y = ((2 * x3 - 3 * x2 + 1) * y0 + (x3 - 2 * x2 + x) * d0 + (-2 * x3 + 3 * x2) * y1
             + (x3 - x2) * d1)
        dy = ((6 * x2 - 6 * x) * y0 + (3 * x2 - 4 * x + 1) * d0 + (-6 * x2 + 6 * x) * y1
              + (3 * x2 - 2 * x) * d1) / h
        return math.exp(y), dy
    return table_sig_d(tab, t)             # unverified cell: the table's own quintic


@njit(cache=True)
def _tab_sig(TQ, TQB, HS, t):
    """σ̄ at t from the table's own interpolant on the packed copy ``TQ`` (columns ln p̄,
    ln σ̄, d ln σ̄/d ln p̄, d² ln σ̄/d(ln p̄)²) — the same arithmetic as k_sigma_of_lnp."""
    n = TQ.shape[0]
    if not (TQ[0, 0] <= t <= TQ[n - 1, 0]):
        return math.nan
    c = int((t - HS[H_TQLO]) / HS[H_TQDZ])
    c = min(max(c, 0), TQB.size - 1)
    i = TQB[c]
    while i < n - 2 and TQ[i + 1, 0] < t:
        i += 1
    lnp_perc = HS[H_LNPPERC]
    if t >= lnp_perc:
        return 0.0
    n_open = int(HS[H_NOPEN])
    if i + 1 < n_open:
        return math.exp(quintic_interval(t, TQ[i, 0], TQ[i + 1, 0], TQ[i, 1], TQ[i + 1, 1],
                                         TQ[i, 2], TQ[i + 1, 2], TQ[i, 3], TQ[i + 1, 3]))
    j = n_open - 1
    if j < 0 or lnp_perc == math.inf:
        return 0.0
    cr = math.exp(TQ[j, 1] / 3.0) * (lnp_perc - t) / (lnp_perc - TQ[j, 0])
    return cr * cr * cr


@njit(cache=True)
def _sig_fast(R, TQ, TQB, HS, t):
    """σ̄ at t (value only): the asymptote below the table, the verified re-tabulation
    (``R`` columns ln σ̄, d ln σ̄/dt, cell verified), else the table's own quintic."""
    t_lo = HS[H_TLO]
    if t < t_lo:
        s = HS[H_B0] + HS[H_B1] * (t_lo - t)
        return s * s * s
    if t >= HS[H_TPERC]:
        return 0.0
    rh = HS[H_RH]
    u = (t - HS[H_RT0]) / rh
    k = int(u)
    if k < 0 or k >= R.shape[0] - 1 or R[k, 2] == 0.0:
        return _tab_sig(TQ, TQB, HS, t)
    x = u - k
    x2 = x * x
    x3 = x2 * x
    y = ((2 * x3 - 3 * x2 + 1) * R[k, 0] + (x3 - 2 * x2 + x) * (R[k, 1] * rh)
         + (-2 * x3 + 3 * x2) * R[k + 1, 0] + (x3 - x2) * (R[k + 1, 1] * rh))
    return math.exp(y)


@njit(cache=True)
def sigma_of_c(tab, sc, c):
    """σ̄ at reduced contact pressure c (inf for c <= 0: lifted off)."""
    if c <= 0.0:
        return math.inf
    return sig_d(tab, sc, math.log(c))[0]


@njit(cache=True)
def ubar_of_c(tab, sc, c):
    """ū/h_rms at reduced contact pressure c (inf for c <= 0; asymptote below the table)."""
    if c <= 0.0:
        return math.inf
    t = math.log(c)
    if t < sc.t_lo:
        return sc.u_lo + sc.c_u * (sc.t_lo - t)
    if t > sc.t_hi:
        return math.nan
    return math.exp(k_lnu_of_lnp(tab, t))


@njit(cache=True)
def retabulate(tab, t0, h, n):
    """ln σ̄ and d ln σ̄/d t of the table interpolant at t0 + k h (NaN where σ̄ = 0)."""
    lns = np.empty(n)
    dlns = np.empty(n)
    for k in range(n):
        s, dl = table_sig_d(tab, t0 + k * h)
        if s > 0.0 and dl == dl:
            lns[k] = math.log(s)
            dlns[k] = dl
        else:
            lns[k] = math.nan
            dlns[k] = math.nan
    return lns, dlns


@njit(cache=True)
def verify_cells(tab, sc, tol):
    """ok[k]: the re-tabulated cubic matches k_sigma_of_lnp within tol at 3 interior points.

    ``sc`` must carry ``ok`` all True (the provisional record). Returns (ok, worst error)."""
    n = sc.lns.size - 1
    ok = np.zeros(n, dtype=np.bool_)
    worst = 0.0
    for k in range(n):
        if not (sc.lns[k] == sc.lns[k] and sc.lns[k + 1] == sc.lns[k + 1]):
            continue
        good = True
        for f in (0.25, 0.5, 0.75):
            t = sc.rt0 + (k + f) * sc.rh
            ref = k_sigma_of_lnp(tab, t)
            if not ref > 0.0:
                good = False
                break
            e = abs(sig_d(tab, sc, t)[0] / ref - 1.0)
            if e > tol:
                good = False
                break
            worst = max(worst, e)
        ok[k] = good
    return ok, worst


# =========================================================================== direct integrals
@njit(cache=True)
def _gl_t(tab, sc, a, b):
    """∫_a^b σ̄(e^t) e^t dt, fixed Gauss–Legendre (sc.glx, sc.glw)."""
    half = 0.5 * (b - a)
    mid = 0.5 * (a + b)
    acc = 0.0
    for k in range(sc.glx.size):
        t = mid + half * sc.glx[k]
        acc += sc.glw[k] * sig_d(tab, sc, t)[0] * math.exp(t)
    return acc * half


@njit(cache=True)
def _gl_s(tab, sc, hi, s0, s1):
    """∫_{s0}^{s1} σ̄(hi − s) ds, fixed Gauss–Legendre in the offset s (widths exact)."""
    half = 0.5 * (s1 - s0)
    mid = s0 + half
    acc = 0.0
    for k in range(sc.glx.size):
        acc += sc.glw[k] * sig_d(tab, sc, math.log(hi - (mid + half * sc.glx[k])))[0]
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
    acc = 0.0
    comp = 0.0
    for k in range(n):                       # compensated (Kahan) sums
        y = P[k, P_CELL] - comp
        s = acc + y
        comp = (s - acc) - y
        acc = s
        P[k + 1, P_PRE] = acc
    acc = 0.0
    comp = 0.0
    for k in range(n - 1, -1, -1):
        y = P[k, P_CELL] - comp
        s = acc + y
        comp = (s - acc) - y
        acc = s
        P[k, P_SUF] = acc
    return P


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
    ta = tb - width
    if ta < HS[H_TLO]:
        return 0
    rt0 = HS[H_RT0]
    rh = HS[H_RH]
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
    st0 = HS[H_ST0]
    tb, ta, kb, ka, short = _split(P, B, st0, HS[H_SH], HS[H_ISH], hi, w)
    if short:
        if (kb >= 0 and P[kb, P_OK] == 0.0) or (ka >= 0 and P[ka, P_OK] == 0.0):
            return math.nan
        if ka < 0 <= kb:                      # split at the C¹ join with the asymptote
            e0 = math.exp(st0)
            wt = min(hi - e0, w)
            return (_gl_fast(R, TQ, TQB, HS, G, e0, w - wt, 0)
                    + _gl_fast(R, TQ, TQB, HS, G, hi, wt, 0))
        return _gl_fast(R, TQ, TQB, HS, G, hi, w, _gl_order(R, HS, tb, tb - ta))
    t_lo, b0, b1 = HS[H_TLO], HS[H_B0], HS[H_B1]
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
    tb, ta, kb, ka, short = _split(P, sc.B, sc.st0, sc.sh, sc.HS[H_ISH], hi, w)
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


@njit(cache=True, parallel=True)
def uniform_rows(tab, sc, p0, L, dp, L_y, E, eta, p_b, alpha, cj, alpha_table,
                 Q, status, p_a, lift, perc, open_in, echo, need):
    """Flat ring (eq. 32 with the fluid feedback): Q = (L_y/L) (h³E*/12η) ∫ σ̄ dπ per row.

    Inputs in SI, contiguous 1-D, each of size 1 (broadcast) or n (one value per row);
    ``cj``: scale σ̄ by (alpha/alpha_table)³. Writes Q [m³/s], the status code, p_a = p_b + dp,
    lift_off (p_a >= p0), percolated, open_inlet [m], and, where ``need[j]``, ``echo[j]``: the
    j-th input of (p0, L, dp, L_y, E, eta, p_b, alpha) repeated per row (shape (8, n); rows
    not needed are never touched).

    Contact pressures past π_trust (the tables' unverified tail) enter through the bound
    0 <= σ̄ <= σ̄(π_trust): Q takes the midpoint, and the row is ST_NEAR_PERCOLATION with
    Q = NaN when the bound is wider than TAIL_RTOL of the verified part."""
    n = Q.size
    h3 = sc.h_rms ** 3
    P, B, R, TQ, TQB, HS, G = sc.P, sc.B, sc.R, sc.TQ, sc.TQB, sc.HS, sc.G
    pi_trust, sig_trust, p_perc, p_top = sc.pi_trust, sc.sig_trust, sc.p_perc, sc.p_top
    m0 = -1 if p0.size > 1 else 0
    m1 = -1 if L.size > 1 else 0
    m2 = -1 if dp.size > 1 else 0
    m3 = -1 if L_y.size > 1 else 0
    m4 = -1 if E.size > 1 else 0
    m5 = -1 if eta.size > 1 else 0
    m6 = -1 if p_b.size > 1 else 0
    m7 = -1 if alpha.size > 1 else 0
    e0, e1, e2, e3, e4, e5, e6, e7 = (need[0], need[1], need[2], need[3], need[4], need[5],
                                      need[6], need[7])
    ne = e0 or e1 or e2 or e3 or e4 or e5 or e6 or e7
    for i in prange(n):
        p0_i = p0[i & m0]
        L_i = L[i & m1]
        dp_i = dp[i & m2]
        E_i = E[i & m4]
        pb_i = p_b[i & m6]
        if ne:
            if e0:
                echo[0, i] = p0_i
            if e1:
                echo[1, i] = L_i
            if e2:
                echo[2, i] = dp_i
            if e3:
                echo[3, i] = L_y[i & m3]
            if e4:
                echo[4, i] = E_i
            if e5:
                echo[5, i] = eta[i & m5]
            if e6:
                echo[6, i] = pb_i
            if e7:
                echo[7, i] = alpha[i & m7]
        pa = pb_i + dp_i
        p_a[i] = pa
        lift[i] = pa >= p0_i
        perc[i] = False
        if pa > p0_i:                          # open: the fluid reaches the outlet
            open_in[i] = L_i
            Q[i] = math.inf
            status[i] = ST_OPEN
            continue
        open_in[i] = 0.0
        c_pa = p0_i - pb_i                     # outlet contact pressure [Pa]
        if c_pa >= p_perc * E_i:
            Q[i] = 0.0
            status[i] = ST_PERCOLATED
            perc[i] = True
            continue
        c_hi = c_pa / E_i
        if c_hi > p_top * (1.0 + 1e-13):
            Q[i] = math.nan
            status[i] = ST_ABOVE_TABLE
            continue
        c_hi = min(c_hi, p_top)
        st = ST_LIFT_OFF if pa == p0_i else ST_OK
        if dp_i == 0.0:
            Q[i] = 0.0
            status[i] = st
            continue
        w = dp_i / E_i
        if w > c_hi or pa == p0_i:
            w = c_hi
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
        a_i = alpha[i & m7]
        scale = 1.0
        if cj:
            r = a_i / alpha_table
            scale = r * r * r
        Q[i] = L_y[i & m3] * h3 * E_i / (12.0 * eta[i & m5] * L_i) * scale * I
        status[i] = st


@njit(cache=True, parallel=True)
def sigma_rows(tab, sc, c, out):
    """σ̄ at reduced contact pressures c (inf at c <= 0)."""
    for i in prange(c.size):
        out[i] = sigma_of_c(tab, sc, c[i])


@njit(cache=True, parallel=True)
def ubar_rows(tab, sc, c, out):
    """ū/h_rms at reduced contact pressures c (inf at c <= 0)."""
    for i in prange(c.size):
        out[i] = ubar_of_c(tab, sc, c[i])


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


@njit(cache=True)
def contact_of_u(tab, sc, ubar, lnp_out, dlnp_out, sig_out, dlns_out):
    """At ū/h_rms: ln π_cont, d ln π/dū (per h_rms), σ̄ and d ln σ̄/d ln π (stiff seals).

    Inside the table: the inverse interpolant (derivative by central difference); beyond
    ū_lo (~32 h_rms) the asymptote ln π = t_lo − (ū − ū_lo)/u0; below the table NaN."""
    for i in range(ubar.size):
        u = ubar[i]
        if u >= sc.u_lo:
            lnp = sc.t_lo - (u - sc.u_lo) / sc.c_u
            dl = -1.0 / sc.c_u
        else:
            lu = math.log(u)
            lnp = k_lnp_of_lnu(tab, lu)
            if lnp != lnp:
                lnp_out[i] = math.nan
                dlnp_out[i] = math.nan
                sig_out[i] = math.nan
                dlns_out[i] = math.nan
                continue
            dd = 1e-6
            a = k_lnp_of_lnu(tab, lu + dd)
            b = k_lnp_of_lnu(tab, lu - dd)
            if a == a and b == b:
                dl = (a - b) / (2.0 * dd) / u
            elif a == a:
                dl = (a - lnp) / dd / u
            else:
                dl = (lnp - b) / dd / u
        lnp_out[i] = lnp
        dlnp_out[i] = dl
        s, dl2 = sig_d(tab, sc, lnp)
        sig_out[i] = s
        dlns_out[i] = dl2
