"""Numba kernels: sealing-zone geometry and panel-mesh helpers of the soft-seal solver (private).

Reduced units: ξ = x/ℓ (ℓ = a for a Hertz profile, L for a sampled profile), π = p/E*. The
sealing zone [ξ_s, ξ_e] is mapped from t ∈ [0, 1] by the polynomial grading
x = x_s + (x_e − x_s) I_t(m+1, m+1) that flattens the logarithmic end singularities of the
resistance density (p_cont → 0 at the zone ends, σ_eff → ∞ like ln³). Panels carry
n-point Gauss–Legendre nodes; a panel's Legendre series interpolates and integrates the
resistance density (the remaining fraction of the pressure drop, eq. 33).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["grade", "grade_inverse", "interp_linear", "geometry", "array_zone", "zone_params",
           "solve_small", "panel_series", "interp_series", "remaining_fraction", "remaining_at"]


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
def _bisect(a, hi, x):
    """Index k in [0, hi) with a[k] <= x < a[k+1] by bisection (a ascending; 0 below a[1],
    hi − 1 at and above a[hi − 1])."""
    lo = 0
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if a[mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True)
def interp_linear(xg, pg, x):
    n = xg.size
    if x <= xg[0]:
        return pg[0], 0
    if x >= xg[n - 1]:
        return pg[n - 1], n - 2
    lo = _bisect(xg, n - 1, x)
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


@njit(cache=True)
def zone_params(kind, base, xg, pg, pia, pib, gp):
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
def solve_small(K, B, n, nr):
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
    lo = _bisect(pan, P, t)
    return lo, (t - pan[lo]) / (0.5 * (pan[lo + 1] - pan[lo])) - 1.0


@njit(cache=True)
def interp_series(t, pan, P, n, coef, Pk):
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
def remaining_at(kind, gp, xo, x0, ell, rule, pan, P, r, W, frac):
    """Fraction of the pressure drop still ahead, (p_f − p_b)/Δp, at the positions xo [m].

    ell is the length unit of ξ (a for Hertz, L for arrays) and x0 the inlet position; the
    solution r on the mesh pan (P panels) of the panel rule ``rule`` (its m, n and Lp)."""
    m, n, Lp = rule.m, rule.n, rule.Lp
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
