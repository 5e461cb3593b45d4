"""Numba kernels of the anisotropic 2-D Bruggeman medium (directional conductivities).

Reduced units ``σ̄ = 12ησ/h_rms³``. The weights W and node conductivities σ of the u1-based
P(u) come either from the adaptive Gauss–Kronrod panels of :func:`directional_adaptive` (the
isotropic effective medium's, :func:`fastcontact.flow._kernels.emt_panels`; the default) or
from the fixed panels of :func:`fastcontact.flow.directional._nodes` (the reference).
Depolarization odds λ: 1 (the isotropic medium) or γ_T^{±1}, Λ^{±1} (see
:mod:`fastcontact.flow.anisotropy`).
D. Stroud, Phys. Rev. B 12, 3368 (1975), doi:10.1103/PhysRevB.12.3368.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..contact._kernels import u1_at_area
from ..kernels.borrow import borrowed
from ._kernels import (EMT_MAX_PANELS, _area1, _sorted_breaks, emt_panels_on, emt_split,
                       newton_step, panel_errors, worst_panel)

__all__ = ["solve_dir", "solve_self_consistent", "u1_nodes", "directional_adaptive",
           "directional_kernel"]


@njit(cache=True)
def _residual(s, W, sig, A1, lam):
    """Σ W (1+λ)s/(λs + σ_j) + A1(1+λ)/λ - 1 and its derivative in ln s."""
    f = A1 * (1.0 + lam) / lam - 1.0
    df = 0.0
    for j in range(W.size):
        if W[j] == 0.0:
            continue
        d = lam * s + sig[j]
        f += W[j] * (1.0 + lam) * s / d
        df += W[j] * (1.0 + lam) * (s / d) * (sig[j] / d)
    return f, df


@njit(cache=True)
def solve_dir(W, sig, A1, lam, guess=math.nan):
    """σ̄ with ∫P (σ - s)/(λ s + σ) = 0 (depolarization 1/(1+λ)); 0 if A1 >= λ/(1+λ).

    Safeguarded Newton in y = ln s, from ``guess`` (ln s of a nearby solution) when it lies
    inside the bracket, else from the bracket's middle."""
    if A1 >= lam / (1.0 + lam):
        return 0.0
    smax = 0.0
    for j in range(sig.size):
        smax = max(smax, sig[j])
    lo = -700.0
    hi = math.log(smax) + 2.0 + math.log(1.0 + 1.0 / lam)
    y = guess if lo < guess < hi else 0.5 * (lo + hi)
    for _ in range(300):
        f, df = _residual(math.exp(y), W, sig, A1, lam)
        y, lo, hi, done = newton_step(y, f, df, lo, hi)
        if done:
            break
    return math.exp(y)


#: the self-consistent iteration ends when |h| (a bound on the error of ln Λ, dh/dμ >= 1) or
#: its bracket is below this (relative to max(1, |ln Λ|)), or, where round-off in ln σ̄ keeps
#: |h| above it, when a step is below SC_XTOL/10 with |h| <= SC_HNOISE
SC_XTOL = 1e-14
SC_HNOISE = 1e-12


@njit(cache=True)
def solve_self_consistent(W, sig, A1, gam, kk=1.0):
    """(σ̄_xx, σ̄_yy) with Λ = γ √(σ_yy/σ_xx), solved in μ = ln Λ.

    The x equation has λ = kk Λ, the y equation λ = kk/Λ; kk = A_c/(1 - A_c) is the odds of
    the tables' effective-medium threshold A_c (1 for the 2-D Bruggeman A_c = 1/2), so both
    close together at A(ζ1)/A0 = A_c (Λ = 1 there) for every γ_T.

    h(μ) = μ - ln γ - ½ (ln σ_yy - ln σ_xx) increases with μ (σ_xx grows and σ_yy falls with
    Λ, so dh/dμ > 1): secant steps safeguarded by the bracket where both directions are
    open (bisection where a step leaves it or a direction closes), each directional solve
    warm-started from the previous one. Since dh/dμ >= 1, |h| bounds the error of μ: the
    iteration ends at |h| or a bracket below SC_XTOL (see SC_HNOISE for round-off).
    """
    if A1 >= kk / (1.0 + kk):
        return 0.0, 0.0
    lk = math.log(kk)
    l0 = math.log(A1 / (1.0 - A1)) if A1 > 0.0 else -60.0 - abs(lk)
    lo = l0 - lk
    hi = -l0 + lk
    lg = math.log(gam)
    mu = lg if lo < lg < hi else 0.5 * (lo + hi)  # the fixed form's Λ = γ_T
    gx = math.nan
    gy = math.nan
    mu_p = math.nan
    h_p = math.nan
    sx = 0.0
    sy = 0.0
    for _ in range(200):
        sx = solve_dir(W, sig, A1, kk * math.exp(mu), gx)
        sy = solve_dir(W, sig, A1, kk * math.exp(-mu), gy)
        if sx <= 0.0 or sy <= 0.0:  # a direction closed: μ outside the open bracket
            if sx <= 0.0:
                lo = mu
            else:
                hi = mu
            mu_n = 0.5 * (lo + hi)
            mu_p = math.nan
        else:
            gx = math.log(sx)
            gy = math.log(sy)
            h = mu - lg - 0.5 * (gy - gx)
            scale = max(1.0, abs(mu))
            if abs(h) <= SC_XTOL * scale:
                return sx, sy
            if h > 0.0:
                hi = mu
            else:
                lo = mu
            # secant through the last two points; the first step takes slope 1 (dh/dμ >= 1)
            slope = (h - h_p) / (mu - mu_p) if mu_p == mu_p and mu != mu_p else 1.0
            mu_n = mu - h / slope if slope > 0.0 else 0.5 * (lo + hi)
            if not (lo < mu_n < hi):
                mu_n = 0.5 * (lo + hi)
            mu_p = mu
            h_p = h
            if abs(mu_n - mu) <= 0.1 * SC_XTOL * scale and abs(h) <= SC_HNOISE * scale:
                return sx, sy
        if hi - lo < SC_XTOL:
            break
        mu = mu_n
    lam = math.exp(0.5 * (lo + hi))
    return solve_dir(W, sig, A1, kk * lam, gx), solve_dir(W, sig, A1, kk / lam, gy)


@njit(cache=True, parallel=True)
def u1_nodes(sk, pbar, area, gamma, ktab, glx, glw, panel, out):
    """out[i, j] = (u1 at A(ζ)/A0 = area[i, j], pressure pbar[i]) [m]; inf where masked."""
    n, m = area.shape
    for k in prange(n * m):
        i = k // m
        j = k - i * m
        work = np.empty(4)
        u, _a = u1_at_area(sk, area[i, j], pbar[i], gamma, ktab, glx, glw, panel, work)
        out[i, j] = u



# ============================================================== adaptive quadrature in A
@njit(cache=True)
def _open_nodes(sig, WK, n, Wc, sc):
    """Wc, sc = the Kronrod weights and σ̄ of the first n nodes, masked nodes (σ̄ = inf: u1
    undefined) at weight 0 — the (W, σ̄) arrays :func:`solve_dir` reads."""
    for j in range(n):
        if sig[j] == math.inf:
            Wc[j] = 0.0
            sc[j] = 0.0
        else:
            Wc[j] = WK[j]
            sc[j] = sig[j]


@njit(cache=True)
def _add_direction(s, lam, pan, npan, spec, pe):
    """Adds each panel's residual error of the direction with odds λ at s (relative to the
    residual's derivative in ln s; :func:`~fastcontact.flow._kernels.panel_errors`) into
    ``pe``; returns their sum, the direction's relative error estimate of s."""
    dfl = panel_errors(s, lam, pan.nodes, npan, spec, pan.err)
    if not (dfl > 0.0):
        return 0.0
    tot = 0.0
    for k in range(npan):
        e = pan.err[k] / dfl
        pe[k] += e
        tot += e
    return tot


@njit(cache=True)
def directional_adaptive(sk, pbar, ktab, spec, gam, kk, self_consistent, breaks, nb, final):
    """(σ̄_xx, σ̄_yy, estimated relative error, u1 evaluations, panels) at one reduced
    pressure with adaptive Gauss–Kronrod panels in A — the nodes, weights and error control of
    the isotropic :func:`~fastcontact.flow._kernels.emt_sigma_on` (``spec`` an EMTSpec, whose
    ``tol`` and ``n_start`` it uses; started on the panels breaks[0..nb], nb = 0: n_start equal
    panels; the final partition's sorted breakpoints into ``final`` when it has room), the
    solves of :func:`solve_self_consistent` (``self_consistent``) or :func:`solve_dir` with
    λ = kk γ_T^{±1} ("fixed").

    The panel with the largest error (summed over both open directions, each relative to its
    residual's derivative in ln σ̄) is halved until the larger of the two directions'
    estimates is <= tol or EMT_MAX_PANELS is reached."""
    sk = borrowed(sk)
    ktab = borrowed(ktab)
    spec = borrowed(spec)
    A1 = _area1(sk.cum3, pbar)
    lx = kk if self_consistent else kk * gam
    ly = kk if self_consistent else kk / gam
    if A1 >= lx / (1.0 + lx) and A1 >= ly / (1.0 + ly):
        return 0.0, 0.0, 0.0, 0, 0
    pan, npan = emt_panels_on(sk, pbar, A1, ktab, spec, breaks, nb)
    sig = pan.nodes.sig
    WK = pan.nodes.wk
    cap = EMT_MAX_PANELS * 15
    Wc = np.empty(cap)
    sc = np.empty(cap)
    pe = np.empty(EMT_MAX_PANELS)
    gx = math.nan
    gy = math.nan
    while True:
        n = 15 * npan
        _open_nodes(sig, WK, n, Wc, sc)
        if self_consistent:
            sx, sy = solve_self_consistent(Wc[:n], sc[:n], A1, gam, kk)
            if sx > 0.0 and sy > 0.0:
                lam = gam * math.sqrt(sy / sx)
                lx = kk * lam
                ly = kk / lam
        else:
            sx = solve_dir(Wc[:n], sc[:n], A1, lx, gx)
            sy = solve_dir(Wc[:n], sc[:n], A1, ly, gy)
        if not (sx > 0.0 or sy > 0.0):
            return 0.0, 0.0, 0.0, n, 0
        gx = math.log(sx) if sx > 0.0 else math.nan
        gy = math.log(sy) if sy > 0.0 else math.nan
        for k in range(npan):
            pe[k] = 0.0
        est = 0.0
        if sx > 0.0:
            est = max(est, _add_direction(sx, lx, pan, npan, spec, pe))
        if sy > 0.0:
            est = max(est, _add_direction(sy, ly, pan, npan, spec, pe))
        worst = worst_panel(pe, npan)
        if est <= spec.tol or npan >= EMT_MAX_PANELS or worst < 0:
            if final.size > npan:
                _sorted_breaks(pan, npan, final)
            return sx, sy, est, n, npan
        npan = emt_split(sk, pbar, A1, ktab, spec, pan, worst, npan)


@njit(cache=True, parallel=True)
def directional_kernel(sk, pbar, ktab, spec, gam, kk, self_consistent, start, nstart, sx, sy, err,
                       nevals, final, nfinal):
    """:func:`directional_adaptive` per reduced pressure into the out arrays, started on
    start[i, :nstart[i] + 1] (nstart[i] = 0: equal panels), the final partitions into
    final[i, :nfinal[i] + 1]."""
    for i in prange(pbar.size):
        a, b, e, m, nb = directional_adaptive(sk, pbar[i], ktab, spec, gam, kk, self_consistent,
                                              start[i], nstart[i], final[i])
        sx[i] = a
        sy[i] = b
        err[i] = e
        nevals[i] = m
        nfinal[i] = nb
