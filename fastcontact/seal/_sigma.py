"""Numba kernels: reduced conductivity σ̄(π) and its primitive for the seal engine (private).

Reduced units: π = p_cont/E*, t = ln π, σ̄ = 12ησ_eff/h_rms³ (eq. 23). Every kernel takes the
table record ``tab`` (:meth:`fastcontact.tables.Tables.kernel_data`) and the seal record ``sc``
(:class:`fastcontact.seal.context.SealRecord`), both flat, so they pass into ``prange``.

σ̄ beyond the table: at and above the percolation pressure exactly 0; below the table
(ū ≳ 32 h_rms) the large-separation asymptote, σ̄^(1/3) = b0 + b1 (t_lo − t), continued C¹.
Inside: ln σ̄ re-tabulated on a uniform t grid (cubic Hermite, every cell verified against the
table kernel; unverified cells call the table kernel).

The leak integral ∫_{π_lo}^{π_hi} σ̄ dπ is never a difference of two large primitives: short
intervals are integrated directly, longer ones as (bottom partial cell) + (whole cells) +
(top partial cell), each partial a quintic Hermite referenced to its own near cell edge, the
whole cells from stored prefix or suffix sums (whichever cancels less); cells whose Hermite
failed verification, and the last cell below percolation, are integrated adaptively.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..kernels.locate import quintic_interval
from ..tables import k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp

__all__ = ["sig_d", "sigma_of_c", "ubar_of_c", "retabulate", "verify_cells", "build_primitive",
           "leak_integral", "uniform_rows", "sigma_rows", "ubar_rows", "invert_uniform",
           "ST_OK", "ST_LIFT_OFF", "ST_OPEN", "ST_PERCOLATED", "ST_ABOVE_TABLE",
           "ST_NOT_CONVERGED", "contact_of_u", "asym_primitive"]

#: row status codes (``fastcontact.seal.api.STATUS`` names them)
ST_OK, ST_LIFT_OFF, ST_OPEN, ST_PERCOLATED, ST_ABOVE_TABLE, ST_NOT_CONVERGED = range(6)

#: relative tolerance of the adaptive integrals and of the primitive's cell verification
ADAPT_RTOL = 1e-11


# =========================================================================== σ̄ and ū
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
    s0 = k_sigma_of_lnp(tab, t)            # slow path: table kernel, central difference
    if not s0 > 0.0:
        return s0, -math.inf
    dt = 1e-6
    sp = k_sigma_of_lnp(tab, t + dt) if t + dt < sc.t_perc else 0.0
    sm = k_sigma_of_lnp(tab, t - dt)
    if sp > 0.0 and sm > 0.0:
        return s0, (math.log(sp) - math.log(sm)) / (2.0 * dt)
    return s0, (math.log(s0) - math.log(sm)) / dt


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
    """ln σ̄ and d ln σ̄/d t of the table interpolant at t0 + k h (central differences)."""
    lns = np.empty(n)
    dlns = np.empty(n)
    dt = 1e-5
    for k in range(n):
        t = t0 + k * h
        s0 = k_sigma_of_lnp(tab, t)
        sp = k_sigma_of_lnp(tab, t + dt)
        sm = k_sigma_of_lnp(tab, t - dt)
        if s0 > 0.0 and sp > 0.0 and sm > 0.0:
            lns[k] = math.log(s0)
            dlns[k] = (math.log(sp) - math.log(sm)) / (2.0 * dt)
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
def _gl_pi(tab, sc, hi, w):
    """∫_{hi−w}^{hi} σ̄(π) dπ, fixed Gauss–Legendre in π (the width w is exact)."""
    half = 0.5 * w
    mid = hi - half
    acc = 0.0
    for k in range(sc.glx.size):
        acc += sc.glw[k] * sig_d(tab, sc, math.log(mid + half * sc.glx[k]))[0]
    return acc * half


@njit(cache=True)
def _adaptive(tab, sc, a, b, in_pi):
    """∫ σ̄ over [a, b] adaptively (halving until two halves agree to ADAPT_RTOL; at most
    48 levels per branch, 400 evaluations; NaN integrand → NaN). Integrands below 1e-280
    (next to percolation, where σ̄ → 0) are accepted as they are.

    in_pi: a, b are π values (integrand σ̄(π)); else t values (integrand σ̄(e^t) e^t)."""
    sa = np.empty(64)
    sb = np.empty(64)
    sv = np.empty(64)
    sd = np.empty(64, dtype=np.int64)
    sa[0] = a
    sb[0] = b
    sv[0] = _gl_pi(tab, sc, b, b - a) if in_pi else _gl_t(tab, sc, a, b)
    sd[0] = 0
    sp = 1
    total = 0.0
    budget = 400                            # GL evaluations (a kink costs ~2 per level)
    while sp > 0:
        sp -= 1
        budget -= 2
        x0, x1, whole, dep = sa[sp], sb[sp], sv[sp], sd[sp]
        m = 0.5 * (x0 + x1)
        if in_pi:
            i1 = _gl_pi(tab, sc, m, m - x0)
            i2 = _gl_pi(tab, sc, x1, x1 - m)
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
def asym_primitive(sc, t):
    """∫_{-∞}^{t} σ̄ e^t' dt' for t <= t_lo (closed form of the asymptote: cubic × exp)."""
    if t == -math.inf:
        return 0.0
    tau = sc.t_lo - t
    b1 = sc.b1
    y = sc.b0 + b1 * tau
    return math.exp(t) * (y * y * y + 3.0 * b1 * y * y + 6.0 * b1 * b1 * y + 6.0 * b1 * b1 * b1)


# =========================================================================== primitive
@njit(cache=True)
def build_primitive(tab, sc, tn):
    """Node derivatives and cell integrals of S(t) = ∫ σ̄ e^t dt on the nodes tn (n+1).

    Returns d1 = S' = σ̄e^t, d2 = S'' = S'(1 + d ln σ̄/dt) at the nodes; cell[k] = ∫ over
    [tn[k], tn[k+1]] (adaptive); cell_ok[k] (the quintic Hermite of the cell's partial
    integrals matches direct Gauss–Legendre within 1e-10 at 3 points, both edge references);
    prefix[k] = Σ_{j<k} cell[j], suffix[k] = Σ_{j>=k} cell[j] (k = 0..n, compensated)."""
    n = tn.size - 1
    d1 = np.empty(n + 1)
    d2 = np.empty(n + 1)
    cell = np.empty(n)
    cell_ok = np.zeros(n, dtype=np.bool_)
    for k in range(n + 1):
        t = tn[k]
        sg, dl = sig_d(tab, sc, t)
        d1[k] = sg * math.exp(t)
        d2[k] = d1[k] * (1.0 + dl) if sg > 0.0 else 0.0
    for k in range(n):
        a, b = tn[k], tn[k + 1]
        cell[k] = _adaptive(tab, sc, a, b, False) if b > a else 0.0
        good = cell[k] > 0.0 and d1[k] > 0.0 and d1[k + 1] > 0.0
        for f in (0.25, 0.5, 0.75):
            if not good:
                break
            t = a + f * (b - a)
            lt = _gl_t(tab, sc, a, t)           # smooth cells: one rule is exact to round-off
            rt = _gl_t(tab, sc, t, b)
            le = quintic_interval(t, a, b, 0.0, cell[k], d1[k], d1[k + 1], d2[k], d2[k + 1])
            re = -quintic_interval(t, a, b, -cell[k], 0.0, d1[k], d1[k + 1], d2[k], d2[k + 1])
            if not (abs(le - lt) <= 1e-10 * lt and abs(re - rt) <= 1e-10 * rt):
                good = False
        cell_ok[k] = good
    prefix = np.zeros(n + 1)
    suffix = np.zeros(n + 1)
    acc = 0.0
    comp = 0.0
    for k in range(n):                       # compensated (Kahan) sums
        y = cell[k] - comp
        s = acc + y
        comp = (s - acc) - y
        acc = s
        prefix[k + 1] = acc
    acc = 0.0
    comp = 0.0
    for k in range(n - 1, -1, -1):
        y = cell[k] - comp
        s = acc + y
        comp = (s - acc) - y
        acc = s
        suffix[k] = acc
    return d1, d2, cell, cell_ok, prefix, suffix


@njit(cache=True)
def _cell_of(sc, t):
    """Index k of the primitive cell [tn[k], tn[k+1]) holding t >= st0 (clamped to the last):
    spacing sh up to node nc, fh beyond."""
    tn = sc.tn
    n = tn.size - 1
    if t < tn[sc.nc]:
        k = int((t - sc.st0) / sc.sh)
    else:
        k = sc.nc + int((t - tn[sc.nc]) / sc.fh)
    k = min(max(k, 0), n - 1)
    while k > 0 and tn[k] > t:
        k -= 1
    while k < n - 1 and tn[k + 1] <= t:
        k += 1
    return k


@njit(cache=True)
def _left_part(tab, sc, k, t):
    """∫ from the start of cell k to t."""
    a = sc.tn[k]
    if t <= a:
        return 0.0
    if sc.cell_ok[k]:
        return quintic_interval(t, a, sc.tn[k + 1], 0.0, sc.cell[k], sc.d1[k], sc.d1[k + 1],
                                sc.d2[k], sc.d2[k + 1])
    return _adaptive(tab, sc, a, t, False)


@njit(cache=True)
def _right_part(tab, sc, k, t):
    """∫ from t to the end of cell k."""
    a = sc.tn[k]
    b = sc.tn[k + 1]
    if t >= b:
        return 0.0
    if sc.cell_ok[k]:
        return -quintic_interval(t, a, b, -sc.cell[k], 0.0, sc.d1[k], sc.d1[k + 1],
                                 sc.d2[k], sc.d2[k + 1])
    return _adaptive(tab, sc, t, b, False)


@njit(cache=True)
def _whole_cells(sc, k0, k1):
    """Σ cell[k0:k1] from the prefix or the suffix sums, whichever cancels less."""
    if k1 <= k0:
        return 0.0
    if sc.prefix[k1] <= sc.suffix[k0]:
        return sc.prefix[k1] - sc.prefix[k0]
    return sc.suffix[k0] - sc.suffix[k1]


@njit(cache=True)
def _short(tab, sc, hi, w, ta, tb):
    """A short interval [hi − w, hi] (t from ta to tb) integrated directly in π."""
    lo = hi - w
    k0 = _cell_of(sc, ta) if ta >= sc.st0 else -1
    k1 = _cell_of(sc, tb) if tb >= sc.st0 else -1
    direct = True
    for k in range(max(k0, 0), k1 + 1):
        if not sc.cell_ok[k]:
            direct = False
    if ta < sc.st0 < tb:                      # split at the C¹ join with the asymptote
        e0 = math.exp(sc.st0)
        if direct:
            return _gl_pi(tab, sc, e0, e0 - lo) + _gl_pi(tab, sc, hi, hi - e0)
        return _gl_pi(tab, sc, e0, e0 - lo) + _adaptive(tab, sc, e0, hi, True)
    if direct:
        return _gl_pi(tab, sc, hi, w)
    return _adaptive(tab, sc, lo, hi, True)


@njit(cache=True)
def leak_integral(tab, sc, hi, w):
    """∫_{hi−w}^{hi} σ̄ dπ (reduced), 0 < w <= hi, hi <= π_top; w = hi means from π = 0.

    The width w is taken as given (no cancellation as w → 0)."""
    tb = math.log(hi)
    if w >= hi:
        ta = -math.inf
        width = math.inf
    else:
        width = -math.log1p(-w / hi)
        ta = tb - width
    kb = _cell_of(sc, tb) if tb >= sc.st0 else 0
    if width <= sc.tn[kb + 1] - sc.tn[kb]:
        return _short(tab, sc, hi, w, ta, tb)
    # long: bottom partial + whole cells + top partial
    if tb <= sc.st0:
        return asym_primitive(sc, tb) - asym_primitive(sc, ta)
    top = _left_part(tab, sc, kb, tb)
    if ta < sc.st0:
        bottom = asym_primitive(sc, sc.st0) - asym_primitive(sc, ta)
        k0 = 0
    else:
        ka = _cell_of(sc, ta)
        if ka == kb:
            return _adaptive(tab, sc, ta, tb, False)
        bottom = _right_part(tab, sc, ka, ta)
        k0 = ka + 1
    return bottom + _whole_cells(sc, k0, kb) + top


@njit(cache=True, parallel=True)
def uniform_rows(tab, sc, p0, L, dp, L_y, E, eta, p_b, scale, Q, status):
    """Flat ring (eq. 32 with the fluid feedback): Q = (L_y/L) (h³E*/12η) ∫ σ̄ dπ per row.

    Inputs in SI (contiguous 1-D, one row each); writes Q [m³/s] and the status code."""
    h3 = sc.h_rms ** 3
    for i in prange(p0.size):
        E_i = E[i]
        c_hi = (p0[i] - p_b[i]) / E_i
        gap = p0[i] - p_b[i] - dp[i]          # p0 − p_a, the inlet contact pressure
        if gap < 0.0:
            Q[i] = math.inf
            status[i] = ST_OPEN
            continue
        st = ST_LIFT_OFF if gap == 0.0 else ST_OK
        if p0[i] - p_b[i] >= sc.p_perc * E_i:
            Q[i] = 0.0
            status[i] = ST_PERCOLATED
            continue
        if c_hi > sc.p_top * (1.0 + 1e-13):
            Q[i] = math.nan
            status[i] = ST_ABOVE_TABLE
            continue
        status[i] = st
        c_hi = min(c_hi, sc.p_top)
        if dp[i] == 0.0:
            Q[i] = 0.0
            continue
        w = dp[i] / E_i
        if w > c_hi or gap == 0.0:
            w = c_hi
        Q[i] = (L_y[i] * h3 * E_i / (12.0 * eta[i] * L[i]) * scale[i]
                * leak_integral(tab, sc, c_hi, w))


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
        s, ds = sig_d(tab, sc, lnp)
        sig_out[i] = s
        dlns_out[i] = ds
