"""Numba kernels of the seal leak-rate solvers (private; the API is :mod:`fastcontact.seal`).

Reduced units throughout: pressures π = p/E*, conductivities σ̄ = 12ησ_eff/h_rms³, lengths
ξ = x/ℓ (ℓ = a for a Hertz profile, L for a given array). Nothing here compiles at import.

Conductivity beyond the table (``sig_ext``)
------------------------------------------
``ext`` = [ln π_lo, ln π_hi, ln π_perc, b0, b1, ū_lo/h, u0/h, t0, h]: inside [π_lo, π_hi] the table
interpolant; at and above the percolation pressure π_perc exactly 0; below π_lo (ū > ~32 h_rms)
the large-separation asymptote, continued C¹ from the table edge:
``σ̄^(1/3) = b0 + b1 τ``, ``ū/h = ū_lo/h + (u0/h) τ``, ``τ = ln π_lo − ln π`` (ū is linear in
ln p there, p ≈ βE*e^{-ū/u0}, and σ̄^(1/3) is asymptotically linear in ū for every theory).
Contact pressure ≤ 0 means lifted off: σ = ∞, resistance 0.

Primitive of the conductivity (uniform seals)
---------------------------------------------
``S(t) = ∫_{-∞}^{t} σ̄(e^t') e^t' dt'`` (t = ln π), i.e. ∫_0^π σ̄ dπ'. Closed form below π_lo;
above it node values on a uniform grid in t (cells by Gauss–Legendre) with S' = σ̄e^t and
S'' = S'(1 + d ln σ̄/dt) exact, and quintic Hermite in between. Intervals shorter than one
cell are integrated directly by Gauss–Legendre, never as a difference of two large
primitives (no cancellation as Δp → 0).

σ̄ lookups: ln σ̄ of the table interpolant is re-tabulated (through the public kernel
``k_sigma_of_lnp``) on a uniform ln π grid with its derivative, and every cell is verified
against the table kernel at three interior points; verified cells are evaluated by an O(1)
cubic Hermite that also returns d ln σ̄/d ln π (the Newton Jacobian), the others (next to
percolation) call the table kernel directly.

Soft-seal solver with a given p0(x) (``solve_case``)
----------------------------------------------------
Unknown: the contact pressure c = p0 − p_f at Gauss–Legendre nodes of adaptive panels on the
sealing zone [x_s, x_e] (p0 > p_a to the right of x_s, p0 > p_b to the left of x_e), mapped from
t ∈ [0, 1] through a polynomial grading x = x_s + (x_e − x_s) I_t(m+1, m+1) that flattens the
logarithmic end singularities (c → 0 at the zone ends, σ → ∞ like ln³). Discrete eq. (33) in
the outlet-referenced form

    F_i = (p0_i − p_b) − c_i − Δp R̃_i / W = 0,   R̃_i = ∫_{t_i}^1 r dt,  W = ∫_0^1 r dt,
    r = (dξ/dt) / σ̄(c),

solved by damped Newton (Jacobian: d ln σ̄/dc from the re-tabulation, block back-substitution from
the outlet — the stable direction: fluid pressure perturbations decay towards the inlet — plus
a Sherman–Morrison rank-one update for W). After convergence every panel whose Legendre tail
of r exceeds ``tol``·W is halved and the solution re-converged from its interpolant.
Leak rate per unit length: q = (Δp/W) h³E*/(12ηℓ). If Newton fails from the plain initial
guess (next to percolation), ``solve_robust`` continues in p_a from an easier problem.

Batch kernels are ``nogil`` and work on row ranges; the API runs them on a thread pool.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..tables import k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp

# layout of ``ext``
E_LNP_LO, E_LNP_HI, E_LNP_PERC, E_B0, E_B1, E_U_LO, E_CU, E_T0, E_H = range(9)
# status codes of solve_case
ST_OK, ST_NOT_REFINED, ST_NEWTON_FAILED, ST_NO_ZONE = 0, 1, 2, 3


# =========================================================================== σ̄ and ū
# ``ctx`` = (tab, ext, lns, dlns, ok): the table's kernel tuple, the scalars ``ext`` (layout
# E_*), and the re-tabulation of ln σ̄ on the uniform grid t = ln π = ext[E_T0] + k ext[E_H]:
# values lns, derivatives dlns (d ln σ̄ / d ln π) and per-cell flags ok (cell verified against
# k_sigma_of_lnp at its midpoint and quarter points; otherwise the table kernel is called).
@njit(cache=True)
def sig_d(ctx, t):
    """(σ̄, d ln σ̄/d ln π) at t = ln π (asymptote below the table; (0, -inf) at percolation)."""
    tab, ext = ctx[0], ctx[1]
    if t < ext[E_LNP_LO]:
        b1 = ext[E_B1]
        s = ext[E_B0] + b1 * (ext[E_LNP_LO] - t)
        return s * s * s, -3.0 * b1 / s
    if t >= ext[E_LNP_PERC]:
        return 0.0, -math.inf
    if t > ext[E_LNP_HI]:
        return math.nan, math.nan
    lns, dlns, ok = ctx[2], ctx[3], ctx[4]
    h = ext[E_H]
    u = (t - ext[E_T0]) / h
    k = int(u)
    if k >= 0 and k < ok.size and ok[k]:
        x = u - k
        x2 = x * x
        x3 = x2 * x
        y0 = lns[k]
        y1 = lns[k + 1]
        d0 = dlns[k] * h
        d1 = dlns[k + 1] * h
        y = ((2 * x3 - 3 * x2 + 1) * y0 + (x3 - 2 * x2 + x) * d0 + (-2 * x3 + 3 * x2) * y1
             + (x3 - x2) * d1)
        dy = ((6 * x2 - 6 * x) * y0 + (3 * x2 - 4 * x + 1) * d0 + (-6 * x2 + 6 * x) * y1
              + (3 * x2 - 2 * x) * d1) / h
        return math.exp(y), dy
    # slow path: the table kernel and a central difference
    s0 = k_sigma_of_lnp(tab, t)
    if not s0 > 0.0:
        return s0, -math.inf
    dt = 1e-6
    sp = k_sigma_of_lnp(tab, t + dt) if t + dt < ext[E_LNP_PERC] else 0.0
    sm = k_sigma_of_lnp(tab, t - dt)
    if sp > 0.0 and sm > 0.0:
        return s0, (math.log(sp) - math.log(sm)) / (2.0 * dt)
    return s0, (math.log(s0) - math.log(sm)) / dt


@njit(cache=True)
def sig_ext(ctx, t):
    """σ̄ at t = ln π."""
    return sig_d(ctx, t)[0]


@njit(cache=True)
def sigma_of_c(ctx, c):
    """σ̄ at reduced contact pressure c (∞ for c <= 0: lifted off, no contact)."""
    if c <= 0.0:
        return math.inf
    return sig_d(ctx, math.log(c))[0]


@njit(cache=True)
def ubar_of_c(ctx, c):
    """ū/h_rms at reduced contact pressure c (∞ for c <= 0; asymptote below the table)."""
    tab, ext = ctx[0], ctx[1]
    if c <= 0.0:
        return math.inf
    lnp = math.log(c)
    if lnp < ext[E_LNP_LO]:
        return ext[E_U_LO] + ext[E_CU] * (ext[E_LNP_LO] - lnp)
    if lnp > ext[E_LNP_HI]:
        return math.nan
    return math.exp(k_lnu_of_lnp(tab, lnp))


@njit(cache=True)
def retabulate(tab, ext, t0, h, n):
    """ln σ̄ and d ln σ̄/d ln π of the table interpolant at t0 + k h (central differences)."""
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
def verify_cells(tab, ext, lns, dlns, tol):
    """ok[k]: the re-tabulated Hermite matches k_sigma_of_lnp within tol at 3 interior points."""
    n = lns.size - 1
    ok = np.zeros(n, dtype=np.bool_)
    ctx = (tab, ext, lns, dlns, np.ones(n, dtype=np.bool_))
    worst = 0.0
    for k in range(n):
        if not (lns[k] == lns[k] and lns[k + 1] == lns[k + 1]):
            continue
        good = True
        for f in (0.25, 0.5, 0.75):
            t = ext[E_T0] + (k + f) * ext[E_H]
            ref = k_sigma_of_lnp(tab, t)
            if not ref > 0.0:
                good = False
                break
            est = sig_d(ctx, t)[0]
            e = abs(est / ref - 1.0)
            if e > tol:
                good = False
                break
            if e > worst:
                worst = e
        ok[k] = good
    return ok, worst


# =========================================================================== primitive S
@njit(cache=True)
def _asym_primitive(ext, t):
    """∫_{-∞}^{t} σ̄ e^t' dt' for t <= ln π_lo (closed form, cubic × exponential)."""
    tau = ext[E_LNP_LO] - t
    b1 = ext[E_B1]
    y = ext[E_B0] + b1 * tau
    return math.exp(t) * (y * y * y + 3.0 * b1 * y * y + 6.0 * b1 * b1 * y + 6.0 * b1 * b1 * b1)


@njit(cache=True)
def _gl_part(ctx, a, b, glx, glw):
    """∫_a^b σ̄(e^t) e^t dt by Gauss–Legendre (a < b, short interval)."""
    half = 0.5 * (b - a)
    mid = 0.5 * (a + b)
    acc = 0.0
    for k in range(glx.size):
        t = mid + half * glx[k]
        acc += glw[k] * sig_d(ctx, t)[0] * math.exp(t)
    return acc * half


@njit(cache=True)
def build_primitive(ctx, t_lo, h, n, glx, glw):
    """(S, S', S'') at t_lo + k h, k = 0..n-1: S(t_lo) from the asymptote's closed form, the
    cells by Gauss–Legendre; S' = σ̄ e^t and S'' = S' (1 + d ln σ̄/d t) exactly."""
    S = np.empty((3, n))
    S[0, 0] = _asym_primitive(ctx[1], t_lo)
    for k in range(1, n):
        a = t_lo + (k - 1) * h
        S[0, k] = S[0, k - 1] + _gl_part(ctx, a, a + h, glx, glw)
    for k in range(n):
        t = t_lo + k * h
        sg, dl = sig_d(ctx, t)
        d1 = sg * math.exp(t)
        S[1, k] = d1
        S[2, k] = d1 * (1.0 + dl) if sg > 0.0 else 0.0
    return S


@njit(cache=True)
def primitive(ctx, S, sp, t, glx, glw):
    """S(t) = ∫_0^{e^t} σ̄ dπ (quintic Hermite between the nodes; closed form below t_lo).
    sp = [t_lo, h, t_last]; t > t_last is the caller's business."""
    if t == -math.inf:
        return 0.0
    t_lo = sp[0]
    if t <= t_lo:
        return _asym_primitive(ctx[1], t)
    h = sp[1]
    n = S.shape[1]
    u = (t - t_lo) / h
    k = int(u)
    if k >= n - 1:               # beyond the last node (at most one cell): direct quadrature
        return S[0, n - 1] + _gl_part(ctx, sp[2], t, glx, glw)
    u = u - k
    u2 = u * u
    u3 = u2 * u
    u4 = u3 * u
    u5 = u4 * u
    h0 = 1.0 - 10.0 * u3 + 15.0 * u4 - 6.0 * u5
    h1 = u - 6.0 * u3 + 8.0 * u4 - 3.0 * u5
    h2 = 0.5 * (u2 - 3.0 * u3 + 3.0 * u4 - u5)
    h3 = 10.0 * u3 - 15.0 * u4 + 6.0 * u5
    h4 = -4.0 * u3 + 7.0 * u4 - 3.0 * u5
    h5 = 0.5 * (u3 - 2.0 * u4 + u5)
    return (h0 * S[0, k] + h1 * h * S[1, k] + h2 * h * h * S[2, k]
            + h3 * S[0, k + 1] + h4 * h * S[1, k + 1] + h5 * h * h * S[2, k + 1])


@njit(cache=True)
def integral_sigma(ctx, S, sp, ta, tb, glx, glw):
    """∫ σ̄ dπ from π = e^ta to e^tb (ta < tb <= t_top); ta = -inf allowed.

    Intervals shorter than one primitive cell are integrated directly (no cancellation)."""
    if not tb > ta:
        return 0.0
    if tb - ta <= sp[1]:
        t_lo = sp[0]
        if ta < t_lo < tb:
            return _gl_part(ctx, ta, t_lo, glx, glw) + _gl_part(ctx, t_lo, tb, glx, glw)
        return _gl_part(ctx, ta, tb, glx, glw)
    return primitive(ctx, S, sp, tb, glx, glw) - primitive(ctx, S, sp, ta, glx, glw)


@njit(cache=True, nogil=True)
def uniform_kernel(ctx, S, sp, glx, glw, c_lo, c_hi, out, start, stop):
    """out[i] = ∫_{c_lo}^{c_hi} σ̄ dπ (reduced) for rows start..stop-1. c_lo <= 0 means
    "from 0" (the lift-off limit). Rows with c_hi <= 0 or NaN give NaN (flagged by the caller)."""
    for i in range(start, stop):
        hi = c_hi[i]
        lo = c_lo[i]
        if not hi > 0.0 or lo != lo:
            out[i] = math.nan
            continue
        ta = math.log(lo) if lo > 0.0 else -math.inf
        out[i] = integral_sigma(ctx, S, sp, ta, math.log(hi), glx, glw)


@njit(cache=True, nogil=True)
def sigma_c_kernel(ctx, c, out, start, stop):
    for i in range(start, stop):
        out[i] = sigma_of_c(ctx, c[i])


@njit(cache=True, nogil=True)
def ubar_c_kernel(ctx, c, out, start, stop):
    for i in range(start, stop):
        out[i] = ubar_of_c(ctx, c[i])


@njit(cache=True)
def invert_uniform(ctx, S, sp, glx, glw, ta, tb, frac, total):
    """ln c in [ta, tb] at which ∫_{e^ta}^{c} σ̄ dπ = frac·total (bisection on ln c)."""
    target = frac * total
    lo = ta if ta > -math.inf else min(sp[0], tb) - 200.0
    hi = tb
    for it in range(300):
        mid = 0.5 * (lo + hi)
        v = integral_sigma(ctx, S, sp, ta, mid, glx, glw)
        if v < target:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-14 * max(1.0, abs(mid)):
            break
    return 0.5 * (lo + hi)


# =========================================================================== geometry
@njit(cache=True)
def grade(t, m):
    """(g, 1 - g, g') of the grading map g(t) = I_t(m+1, m+1) (regularised incomplete beta)."""
    if m == 0:
        return t, 1.0 - t, 1.0
    nn = 2 * m + 1
    # B = (2m+1)! / (m!)^2
    B = 1.0
    for k in range(m + 1, nn + 1):
        B *= k
    for k in range(1, m + 1):
        B /= k
    gd = B * (t * (1.0 - t)) ** m
    # I_s(m+1, m+1) = sum_{k=m+1}^{2m+1} C(2m+1, k) s^k (1-s)^(2m+1-k); use the smaller side
    s = t if t <= 0.5 else 1.0 - t
    acc = 0.0
    comb = 1.0
    for k in range(nn + 1):
        if k >= m + 1:
            acc += comb * s ** k * (1.0 - s) ** (nn - k)
        comb = comb * (nn - k) / (k + 1)
    if t <= 0.5:
        return acc, 1.0 - acc, gd
    return 1.0 - acc, acc, gd


@njit(cache=True)
def grade_inverse(u, m):
    """t with g(t) = u (bisection; g is strictly increasing)."""
    if u <= 0.0:
        return 0.0
    if u >= 1.0:
        return 1.0
    lo, hi = 0.0, 1.0
    for it in range(100):
        mid = 0.5 * (lo + hi)
        g, _, _ = grade(mid, m)
        if g < u:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-16:
            break
    return 0.5 * (lo + hi)


@njit(cache=True)
def interp_linear(xg, pg, x):
    n = xg.size
    if x <= xg[0]:
        return pg[0], 0
    if x >= xg[n - 1]:
        return pg[n - 1], n - 2
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xg[mid] <= x:
            lo = mid
        else:
            hi = mid
    return pg[lo] + (pg[lo + 1] - pg[lo]) * (x - xg[lo]) / (xg[lo + 1] - xg[lo]), lo


@njit(cache=True)
def geometry(kind, gp, xg, pg, t, m, pia, pib):
    """(ξ, dξ/dt, π0 − π_a, π0 − π_b) at t ∈ [0, 1] of the sealing zone.

    kind 0, Hertz: gp = [π_H, θ_s, Δθ]; x = a(1 − cos θ), p0 = p_H sin θ, ξ = x/a.
    kind 1, array: gp = [ξ_s, Δξ]; p0 linear between the samples (xg = x/L, pg = p0/E*).
    The pressure differences are formed without cancellation next to the zone ends.
    """
    g, omg, gd = grade(t, m)
    if kind == 0:
        piH = gp[0]
        th_s = gp[1]
        dth = gp[2]
        th = th_s + dth * g
        s = math.sin(th)
        xi = 2.0 * math.sin(0.5 * th) ** 2
        dxi = s * dth * gd
        if t <= 0.5:
            d = dth * g
            ea = piH * (math.cos(th_s) * math.sin(d)
                        - 2.0 * math.sin(th_s) * math.sin(0.5 * d) ** 2)
            ea = ea + (piH * math.sin(th_s) - pia)
            eb = ea + (pia - pib)
        else:
            th_e = th_s + dth
            d = dth * omg
            eb = piH * (-math.cos(th_e) * math.sin(d)
                        - 2.0 * math.sin(th_e) * math.sin(0.5 * d) ** 2)
            eb = eb + (piH * math.sin(th_e) - pib)
            ea = eb - (pia - pib)
        return xi, dxi, ea, eb
    xs = gp[0]
    dx = gp[1]
    x = xs + dx * g if t <= 0.5 else (xs + dx) - dx * omg
    p, j = interp_linear(xg, pg, x)
    slope = (pg[j + 1] - pg[j]) / (xg[j + 1] - xg[j])
    ea = (pg[j] - pia) + slope * (x - xg[j])
    eb = (pg[j] - pib) + slope * (x - xg[j])
    return x, dx * gd, ea, eb


# =========================================================================== linear algebra
@njit(cache=True)
def _solve_small(K, B, n, nr):
    """Solve K X = B in place (Gaussian elimination, partial pivoting); K n×n, B n×nr."""
    for col in range(n):
        piv = col
        big = abs(K[col, col])
        for r in range(col + 1, n):
            if abs(K[r, col]) > big:
                big = abs(K[r, col])
                piv = r
        if piv != col:
            for k in range(n):
                tmp = K[col, k]
                K[col, k] = K[piv, k]
                K[piv, k] = tmp
            for k in range(nr):
                tmp = B[col, k]
                B[col, k] = B[piv, k]
                B[piv, k] = tmp
        d = K[col, col]
        if d == 0.0:
            return False
        for r in range(col + 1, n):
            f = K[r, col] / d
            if f != 0.0:
                for k in range(col, n):
                    K[r, k] -= f * K[col, k]
                for k in range(nr):
                    B[r, k] -= f * B[col, k]
    for col in range(n - 1, -1, -1):
        for k in range(nr):
            acc = B[col, k]
            for j in range(col + 1, n):
                acc -= K[col, j] * B[j, k]
            B[col, k] = acc / K[col, col]
    return True


# =========================================================================== panel solver
@njit(cache=True)
def _fill_nodes(kind, gp, xg, pg, m, pia, pib, zl, pan, P, n, t, xi, dxi, ea, eb):
    for p in range(P):
        tl = pan[p]
        tr = pan[p + 1]
        for k in range(n):
            i = p * n + k
            tt = tl + 0.5 * (tr - tl) * (zl[k] + 1.0)
            t[i] = tt
            xi[i], dxi[i], ea[i], eb[i] = geometry(kind, gp, xg, pg, tt, m, pia, pib)


@njit(cache=True)
def _resid(ctx, c, dxi, eb, dpi, pan, P, n, wl, At, r, D, Rt, F):
    """r = dξ/dt / σ̄(c), D = dr/dc, R̃ and F at c; returns (W, max|F|, ok).

    ok is False if σ̄ = 0 somewhere (c at/after percolation: infinite resistance)."""
    N = P * n
    for i in range(N):
        ci = c[i]
        if ci <= 0.0:
            r[i] = 0.0
            D[i] = 0.0
            continue
        s, dl = sig_d(ctx, math.log(ci))
        if not s > 0.0:
            return 0.0, math.inf, False
        r[i] = dxi[i] / s
        D[i] = -r[i] * dl / ci
    after = 0.0
    for p in range(P - 1, -1, -1):
        hh = 0.5 * (pan[p + 1] - pan[p])
        tot = 0.0
        for k in range(n):
            tot += wl[k] * r[p * n + k]
        for i in range(n):
            acc = 0.0
            for k in range(n):
                acc += At[i, k] * r[p * n + k]
            Rt[p * n + i] = after + hh * acc
        after += hh * tot
    W = after
    if not W > 0.0:
        return W, math.inf, False
    fmax = 0.0
    for i in range(N):
        F[i] = eb[i] - c[i] - dpi * Rt[i] / W
        if abs(F[i]) > fmax:
            fmax = abs(F[i])
    return W, fmax, True


@njit(cache=True)
def _newton(ctx, c, dxi, eb, dpi, pan, P, n, wl, At, maxit, ftol,
            r, D, Rt, F, c2, r2, D2, Rt2, F2, y1, y2, Y, K):
    """Damped Newton on the current mesh; c and r hold the result. Returns (W, its, ok)."""
    N = P * n
    W, fmax, ok = _resid(ctx, c, dxi, eb, dpi, pan, P, n, wl, At, r, D, Rt, F)
    if not ok:
        return W, 0, False
    cur = 0          # 0: current state in (c, r, D, Rt, F); 1: in the *2 arrays
    its = 0
    conv = False
    while its < maxit:
        if fmax <= ftol:
            conv = True
            break
        its += 1
        cc, rr, DD, RR, FF = (c, r, D, Rt, F) if cur == 0 else (c2, r2, D2, Rt2, F2)
        ct, rt, Dt, Rtt, Ft = (c2, r2, D2, Rt2, F2) if cur == 0 else (c, r, D, Rt, F)
        # B̃ y = b for b1 = -F and b2 = u = dπ R̃/W²: block back-substitution from the outlet
        g = dpi / W
        S1 = 0.0
        S2 = 0.0
        for p in range(P - 1, -1, -1):
            hh = 0.5 * (pan[p + 1] - pan[p])
            for i in range(n):
                for k in range(n):
                    K[i, k] = -g * hh * At[i, k] * DD[p * n + k]
                K[i, i] -= 1.0
                Y[i, 0] = -FF[p * n + i] + g * S1
                Y[i, 1] = g * RR[p * n + i] / W + g * S2
            if not _solve_small(K, Y, n, 2):
                return W, its, False
            for k in range(n):
                wk = hh * wl[k] * DD[p * n + k]
                y1[p * n + k] = Y[k, 0]
                y2[p * n + k] = Y[k, 1]
                S1 += wk * Y[k, 0]
                S2 += wk * Y[k, 1]
        # Sherman–Morrison: δ = y1 − y2 (vᵀy1)/(1 + vᵀy2), v = w∘D
        den = 1.0 + S2
        if den == 0.0:
            return W, its, False
        fac = S1 / den
        dmax = 0.0
        for i in range(N):
            y1[i] = y1[i] - y2[i] * fac
            if abs(y1[i]) > dmax:
                dmax = abs(y1[i])
        lam = 1.0
        accepted = False
        for ls in range(24):
            for i in range(N):
                ct[i] = cc[i] + lam * y1[i]
            Wt, ft, okt = _resid(ctx, ct, dxi, eb, dpi, pan, P, n, wl, At, rt, Dt, Rtt, Ft)
            if okt and ft <= (1.0 - 1e-4 * lam) * fmax:
                accepted = True
                break
            lam *= 0.5
        if not accepted:
            conv = fmax <= 1e3 * ftol      # stagnated at round-off
            break
        cur = 1 - cur
        W = Wt
        fmax = ft
        if lam * dmax <= 1e-3 * ftol:
            conv = True
            break
    if cur == 1:
        for i in range(N):
            c[i] = c2[i]
            r[i] = r2[i]
    return W, its, conv


@njit(cache=True)
def _legendre_all(z, n, out):
    """P_0..P_n at z into out[0..n]."""
    out[0] = 1.0
    if n >= 1:
        out[1] = z
    for k in range(1, n):
        out[k + 1] = ((2 * k + 1) * z * out[k] - k * out[k - 1]) / (k + 1)


@njit(cache=True)
def panel_series(r, pan, P, n, Lp, coef, after):
    """Legendre coefficients of r per panel (coef, P×n) and ∫ r over the later panels."""
    acc = 0.0
    for p in range(P - 1, -1, -1):
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += Lp[j, k] * r[p * n + k]
            coef[p, j] = s
        after[p] = acc
        acc += (pan[p + 1] - pan[p]) * coef[p, 0]      # ∫ over the panel = (h/2)·2a0
    return acc


@njit(cache=True)
def _panel_at(t, pan, P):
    """(panel p with pan[p] <= t < pan[p+1], local Legendre variable z ∈ [-1, 1]) by bisection."""
    lo, hi = 0, P
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if pan[mid] <= t:
            lo = mid
        else:
            hi = mid
    return lo, (t - pan[lo]) / (0.5 * (pan[lo + 1] - pan[lo])) - 1.0


@njit(cache=True)
def _interp_series(t, pan, P, n, coef, Pk):
    """The panel-wise Legendre series (coef) at t."""
    p, z = _panel_at(t, pan, P)
    _legendre_all(z, n, Pk)
    acc = 0.0
    for j in range(n):
        acc += coef[p, j] * Pk[j]
    return acc


@njit(cache=True)
def remaining_fraction(t, pan, P, n, coef, after, W, Pk):
    """s(t) = ∫_t^1 r / W: the fraction of the pressure drop still ahead (p_f = p_b + Δp s)."""
    if t <= 0.0:
        return 1.0
    if t >= 1.0:
        return 0.0
    p, z = _panel_at(t, pan, P)
    _legendre_all(z, n, Pk)
    acc = coef[p, 0] * (1.0 - z)
    for j in range(1, n):
        acc += coef[p, j] * (Pk[j - 1] - Pk[j + 1]) / (2 * j + 1)
    return (after[p] + 0.5 * (pan[p + 1] - pan[p]) * acc) / W


@njit(cache=True)
def solve_case(ctx, kind, gp, xg, pg, pia, pib, m, n, P0, PMAX, tol, maxit,
               zl, wl, At, Lp, pan_out, c_out, r_out, init_P, init_pan, init_s, s_out):
    """Solve one soft seal on its sealing zone (see the module docstring).

    Returns (W, status, panels, error_estimate, newton_iterations), W = ∫ dξ/σ̄ over the
    zone. pan_out (PMAX+1), c_out and r_out (PMAX·n) receive the final mesh and the nodal
    contact pressure and resistance density; s_out (optional) the remaining fraction of the
    pressure drop (p_f − p_b)/Δp at the nodes. With init_P > 0 the first mesh is init_pan and
    the initial guess c = (p0 − p_b) − Δp·init_s at its nodes (continuation); otherwise P0
    uniform panels and a fluid pressure linear in x. s_out is filled if it is large enough
    (pass an empty array to skip).
    """
    ext = ctx[1]
    dpi = pia - pib
    NMAX = PMAX * n
    t = np.empty(NMAX)
    xi = np.empty(NMAX)
    dxi = np.empty(NMAX)
    ea = np.empty(NMAX)
    eb = np.empty(NMAX)
    c = np.empty(NMAX)
    r = np.empty(NMAX)
    D = np.empty(NMAX)
    Rt = np.empty(NMAX)
    F = np.empty(NMAX)
    c2 = np.empty(NMAX)
    r2 = np.empty(NMAX)
    D2 = np.empty(NMAX)
    Rt2 = np.empty(NMAX)
    F2 = np.empty(NMAX)
    y1 = np.empty(NMAX)
    y2 = np.empty(NMAX)
    Y = np.empty((n, 2))
    K = np.empty((n, n))
    Pk = np.empty(n + 1)
    coef = np.empty((PMAX, n))
    after = np.empty(PMAX)
    pan = np.empty(PMAX + 1)
    pan2 = np.empty(PMAX + 1)
    err = np.empty(PMAX)
    if init_P > 0:
        P = init_P
        for p in range(P + 1):
            pan[p] = init_pan[p]
    else:
        P = P0
        for p in range(P + 1):
            pan[p] = p / P
    _fill_nodes(kind, gp, xg, pg, m, pia, pib, zl, pan, P, n, t, xi, dxi, ea, eb)
    N = P * n
    scale = dpi
    for i in range(N):
        scale = max(scale, abs(eb[i]))
    ftol = 1e-13 * scale
    # initial guess: fluid pressure linear in ξ across the zone, capped below percolation
    g0 = geometry(kind, gp, xg, pg, 0.0, m, pia, pib)[0]
    g1 = geometry(kind, gp, xg, pg, 1.0, m, pia, pib)[0]
    cperc = math.exp(ext[E_LNP_PERC]) if ext[E_LNP_PERC] < 700.0 else math.inf
    for i in range(N):
        if init_P > 0:
            s = init_s[i]
        else:
            s = (g1 - xi[i]) / (g1 - g0) if g1 > g0 else 0.5
        ci = eb[i] - dpi * s
        if ci > 0.9 * cperc and init_P == 0:
            ci = 0.9 * cperc
        c[i] = ci
    status = ST_OK
    total_it = 0
    est = math.inf
    W = 0.0
    for rnd in range(4 * PMAX):
        # intermediate meshes: converge loosely (the indicator needs r to ~1e-9 only)
        W, its, conv = _newton(ctx, c, dxi, eb, dpi, pan, P, n, wl, At, maxit, 1e4 * ftol,
                               r, D, Rt, F, c2, r2, D2, Rt2, F2, y1, y2, Y, K)
        total_it += its
        if not conv:
            status = ST_NEWTON_FAILED
            break
        # error indicator per panel: Legendre tail of r, relative to W
        panel_series(r, pan, P, n, Lp, coef, after)
        nsplit = 0
        est = 0.0
        for p in range(P):
            e = (abs(coef[p, n - 1]) + abs(coef[p, n - 2])) * (pan[p + 1] - pan[p]) / W
            err[p] = e
            est += e
            if e > tol:
                nsplit += 1
        if nsplit == 0 or P + nsplit > PMAX:
            if nsplit > 0:
                status = ST_NOT_REFINED
            # final mesh: polish to round-off
            W, its, conv = _newton(ctx, c, dxi, eb, dpi, pan, P, n, wl, At, maxit, ftol,
                                   r, D, Rt, F, c2, r2, D2, Rt2, F2, y1, y2, Y, K)
            total_it += its
            if not conv:
                status = ST_NEWTON_FAILED
            break
        q = 0
        for p in range(P):
            pan2[q] = pan[p]
            q += 1
            if err[p] > tol:
                pan2[q] = 0.5 * (pan[p] + pan[p + 1])
                q += 1
        pan2[q] = 1.0
        Pn = q
        # new nodes: remaining fraction s(t) of the converged solution, then c = e_b − Δπ s
        for p in range(Pn):
            tl = pan2[p]
            tr = pan2[p + 1]
            for k in range(n):
                tt = tl + 0.5 * (tr - tl) * (zl[k] + 1.0)
                y1[p * n + k] = remaining_fraction(tt, pan, P, n, coef, after, W, Pk)
        for p in range(Pn + 1):
            pan[p] = pan2[p]
        P = Pn
        N = P * n
        _fill_nodes(kind, gp, xg, pg, m, pia, pib, zl, pan, P, n, t, xi, dxi, ea, eb)
        for i in range(N):
            c[i] = eb[i] - dpi * y1[i]
    N = P * n
    for p in range(P + 1):
        pan_out[p] = pan[p]
    for i in range(N):
        c_out[i] = c[i]
        r_out[i] = r[i]
    if s_out.size >= N:
        for i in range(N):
            s_out[i] = (eb[i] - c[i]) / dpi
    return W, status, P, est, total_it


@njit(cache=True)
def _zone_params(kind, base, xg, pg, pia, pib, gp):
    """Sealing-zone parameters gp for p_a = pia: Hertz base = [π_H]; arrays from the samples."""
    if kind == 0:
        piH = base[0]
        th_s = math.asin(min(pia / piH, 1.0))
        th_e = math.pi - math.asin(min(pib / piH, 1.0))
        gp[0] = piH
        gp[1] = th_s
        gp[2] = th_e - th_s
        return th_e > th_s
    xs, xe = array_zone(xg, pg, pia, pib)
    gp[0] = xs
    gp[1] = xe - xs
    return xe > xs


@njit(cache=True)
def solve_robust(ctx, kind, base, xg, pg, pmax, pia, pib, m, n, P0, PMAX, tol, maxit,
                 zl, wl, At, Lp, pan_out, c_out, r_out):
    """solve_case, and if Newton fails from the plain initial guess (close to percolation,
    where ln σ̄ falls by ~10³ per unit ln p), continuation in p_a: start where the peak
    contact pressure max p0 − p_a is 0.6 p_perc (or halfway in p_a for the average theory),
    then step the distance to percolation δ = p_perc − (max p0 − p_a) geometrically down to
    its target, each step starting from the previous solution on the previous mesh.
    Returns (W, status, panels, error_estimate, newton_iterations, continuation_steps)."""
    gp = np.empty(3)
    if not _zone_params(kind, base, xg, pg, pia, pib, gp):
        return 0.0, ST_NO_ZONE, 0, 0.0, 0, 0
    nil = np.empty(0)
    W, st, P, est, its = solve_case(ctx, kind, gp, xg, pg, pia, pib, m, n, P0, PMAX, tol, maxit,
                                    zl, wl, At, Lp, pan_out, c_out, r_out, 0, nil, nil, nil)
    if st != ST_NEWTON_FAILED:
        return W, st, P, est, its, 0
    ext = ctx[1]
    cperc = math.exp(ext[E_LNP_PERC]) if ext[E_LNP_PERC] < 700.0 else math.inf
    if cperc < math.inf:
        dT = cperc - (pmax - pia)
        d0 = max(dT, 0.4 * cperc, cperc - pmax + pib + 0.5 * (pia - pib))
        if not d0 > dT:
            return W, st, P, est, its, 0
        pa0 = pmax - cperc + d0
    else:
        pa0 = pib + 0.5 * (pia - pib)
    NMAX = PMAX * n
    pan = np.empty(PMAX + 1)
    sn = np.empty(NMAX)
    cc = np.empty(NMAX)
    rr = np.empty(NMAX)
    _zone_params(kind, base, xg, pg, pa0, pib, gp)
    W, st, P, est, it0 = solve_case(ctx, kind, gp, xg, pg, pa0, pib, m, n, P0, PMAX, 1e-2,
                                    maxit, zl, wl, At, Lp, pan, cc, rr, 0, pan, sn, sn)
    its += it0
    if st == ST_NEWTON_FAILED:
        return W, st, P, est, its, 0
    lam = 0.0
    step = 0.1
    steps = 0
    pan_new = np.empty(PMAX + 1)
    s_new = np.empty(NMAX)
    r_prev = np.empty(NMAX)
    coef = np.empty((PMAX, n))
    after = np.empty(PMAX)
    Pk = np.empty(n + 1)
    for i in range(P * n):
        r_prev[i] = rr[i]
    W_prev = W
    while lam < 1.0 and steps < 80 and its < 4000:
        steps += 1
        lt = min(1.0, lam + step)
        if cperc < math.inf:
            pa = pmax - cperc + d0 * (dT / d0) ** lt
        else:
            pa = pa0 + lt * (pia - pa0)
        if lt == 1.0:
            pa = pia
        _zone_params(kind, base, xg, pg, pa, pib, gp)
        W2, st2, P2, est2, it2 = solve_case(ctx, kind, gp, xg, pg, pa, pib, m, n, P0, PMAX,
                                            tol, min(maxit, 25), zl, wl, At, Lp,
                                            pan_new, cc, rr, P, pan, sn, s_new)
        its += it2
        if st2 == ST_NEWTON_FAILED:
            # first refine the previous solution where its resistance concentrates (the peak
            # sharpens as δ falls and the Newton needs it resolved), then shorten the step
            panel_series(r_prev, pan, P, n, Lp, coef, after)
            q = 0
            for p in range(P):
                pan_new[q] = pan[p]
                q += 1
                if (pan[p + 1] - pan[p]) * coef[p, 0] > 0.02 * W_prev and q < PMAX:
                    pan_new[q] = 0.5 * (pan[p] + pan[p + 1])
                    q += 1
            pan_new[q] = 1.0
            if q > P and q <= PMAX:
                for p in range(q):
                    tl = pan_new[p]
                    tr = pan_new[p + 1]
                    for k in range(n):
                        tt = tl + 0.5 * (tr - tl) * (zl[k] + 1.0)
                        s_new[p * n + k] = remaining_fraction(tt, pan, P, n, coef, after,
                                                              W_prev, Pk)
                # the previous solution on the refined mesh: its r by interpolation
                for p in range(q):
                    tl = pan_new[p]
                    tr = pan_new[p + 1]
                    for k in range(n):
                        tt = tl + 0.5 * (tr - tl) * (zl[k] + 1.0)
                        rr[p * n + k] = _interp_series(tt, pan, P, n, coef, Pk)
                P = q
                for p in range(P + 1):
                    pan[p] = pan_new[p]
                for i in range(P * n):
                    sn[i] = s_new[i]
                    r_prev[i] = rr[i]
                continue
            step *= 0.5
            if step < 1e-3:
                return W2, ST_NEWTON_FAILED, P2, est2, its, steps
            continue
        lam = lt
        P = P2
        for p in range(P + 1):
            pan[p] = pan_new[p]
        for i in range(P * n):
            sn[i] = s_new[i]
            r_prev[i] = rr[i]
        W, st, est = W2, st2, est2
        W_prev = W
        step = min(2.0 * step, 0.5)
    if lam < 1.0:
        return W, ST_NEWTON_FAILED, P, est, its, steps
    for p in range(P + 1):
        pan_out[p] = pan[p]
    for i in range(P * n):
        c_out[i] = cc[i]
        r_out[i] = rr[i]
    return W, st, P, est, its, steps


@njit(cache=True)
def array_zone(xi, pg, pia, pib):
    """(ξ_s, ξ_e) of an array profile: the first point where p0 reaches p_a and the last point
    where p0 is above p_b (linear between the samples); (1, 1) if p0 never reaches p_a."""
    n = xi.size
    i = -1
    for k in range(n):
        if pg[k] >= pia:
            i = k
            break
    if i < 0:
        return 1.0, 1.0
    if i == 0 or pg[i] == pia:
        xs = xi[i]
    else:
        xs = xi[i - 1] + (pia - pg[i - 1]) / (pg[i] - pg[i - 1]) * (xi[i] - xi[i - 1])
    j = -1
    for k in range(n - 1, -1, -1):
        if pg[k] > pib:
            j = k
            break
    if j < 0:
        return xs, xs
    if j == n - 1:
        xe = xi[n - 1]
    else:
        xe = xi[j] + (pg[j] - pib) / (pg[j] - pg[j + 1]) * (xi[j + 1] - xi[j])
    return xs, xe


@njit(cache=True, nogil=True)
def solve_rows(ctx, kind, xg, p0n, amp, pia, pib, m, n, P0, PMAX, tol, maxit, zl, wl, At, Lp,
               W_out, status_out, panels_out, err_out, xs_out, xe_out, pan_keep, r_keep,
               start, stop):
    """Soft seals of rows start..stop-1 (one compiled entry point for every profile).

    kind 0, Hertz: amp[i] = π_H (p0n unused); kind 1, array: p0 = p0n·amp[i] at ξ = xg
    (p0n [Pa], amp = 1/E*). Reduced π_a, π_b per row. Outputs W = ∫dξ/σ̄, status, panels,
    error estimate and (arrays) the zone ends ξ_s, ξ_e; with a single row its final mesh and
    resistance density go to pan_keep / r_keep (for the profile evaluation)."""
    pan = np.empty(PMAX + 1)
    cc = np.empty(PMAX * n)
    rr = np.empty(PMAX * n)
    base1 = np.empty(1)
    for i in range(start, stop):
        if kind == 0:
            base1[0] = amp[i]
            W, st, P, est, its, cs = solve_robust(ctx, 0, base1, xg, p0n, amp[i], pia[i], pib[i],
                                                  m, n, P0, PMAX, tol, maxit, zl, wl, At, Lp,
                                                  pan, cc, rr)
            xs_out[i] = math.nan
            xe_out[i] = math.nan
        else:
            pg = p0n * amp[i]
            xs, xe = array_zone(xg, pg, pia[i], pib[i])
            xs_out[i] = xs
            xe_out[i] = xe
            W, st, P, est, its, cs = solve_robust(ctx, 1, pg, xg, pg, pg.max(), pia[i], pib[i],
                                                  m, n, P0, PMAX, tol, maxit, zl, wl, At, Lp,
                                                  pan, cc, rr)
        W_out[i] = W
        status_out[i] = st
        panels_out[i] = P
        err_out[i] = est
        if stop - start == 1:
            for p in range(P + 1):
                pan_keep[p] = pan[p]
            for j in range(P * n):
                r_keep[j] = rr[j]


@njit(cache=True)
def remaining_at(kind, gp, xo, x0, ell, m, pan, P, n, r, W, Lp, frac):
    """Fraction of the pressure drop still ahead, (p_f − p_b)/Δp, at the positions xo [m].

    ell is the length unit of ξ (a for Hertz, L for arrays) and x0 the inlet position."""
    coef = np.empty((P, n))
    after = np.empty(P)
    Pk = np.empty(n + 1)
    panel_series(r, pan, P, n, Lp, coef, after)
    for i in range(xo.size):
        xi = (xo[i] - x0) / ell
        if kind == 0:
            q = min(max(0.5 * xi, 0.0), 1.0)
            th = 2.0 * math.asin(math.sqrt(q))
            u = (th - gp[1]) / gp[2]
        else:
            u = (xi - gp[0]) / gp[1]
        t = grade_inverse(u, m)
        frac[i] = remaining_fraction(t, pan, P, n, coef, after, W, Pk)


# =========================================================================== stiff seals
@njit(cache=True)
def contact_of_u(ctx, ubar, lnp_out, dlnp_out, sig_out, dlns_out):
    """At ū/h_rms: ln p̄_cont, d ln p̄/dū (per h_rms), σ̄ and d ln σ̄/d ln p̄.

    Inside the table: the inverse interpolant k_lnp_of_lnu (derivative by central difference);
    above ū_lo/h (beyond ~32 h_rms) the asymptote ln p̄ = ln p̄_lo − (ū − ū_lo)/u0; below the
    table (A(ζ1)/A0 > 0.999) NaN."""
    tab, ext = ctx[0], ctx[1]
    for i in range(ubar.size):
        u = ubar[i]
        if u >= ext[E_U_LO]:
            lnp = ext[E_LNP_LO] - (u - ext[E_U_LO]) / ext[E_CU]
            dl = -1.0 / ext[E_CU]
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
        s, ds = sig_d(ctx, lnp)
        sig_out[i] = s
        dlns_out[i] = ds
