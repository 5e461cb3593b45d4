"""Numba kernels of the anisotropic 2-D Bruggeman medium (directional conductivities).

Reduced units ``σ̄ = 12ησ/h_rms³``; the weights W and node conductivities σ of the u1-based
P(u) come from :func:`fastcontact.flow.directional._nodes`. Depolarization odds λ: 1 (the
isotropic medium) or γ_T^{±1}, Λ^{±1} (see :mod:`fastcontact.flow.anisotropy`).
D. Stroud, Phys. Rev. B 12, 3368 (1975), doi:10.1103/PhysRevB.12.3368.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..contact._kernels import u1_at_area
from ._kernels import newton_step

__all__ = ["solve_dir", "solve_self_consistent", "u1_nodes"]


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
def solve_dir(W, sig, A1, lam):
    """σ̄ with ∫P (σ - s)/(λ s + σ) = 0 (depolarization 1/(1+λ)); 0 if A1 >= λ/(1+λ)."""
    if A1 >= lam / (1.0 + lam):
        return 0.0
    smax = 0.0
    for j in range(sig.size):
        smax = max(smax, sig[j])
    lo = -700.0
    hi = math.log(smax) + 2.0 + math.log(1.0 + 1.0 / lam)
    y = 0.5 * (lo + hi)
    for _ in range(300):
        f, df = _residual(math.exp(y), W, sig, A1, lam)
        y, lo, hi, done = newton_step(y, f, df, lo, hi)
        if done:
            break
    return math.exp(y)


@njit(cache=True)
def solve_self_consistent(W, sig, A1, gam, kk=1.0):
    """(σ̄_xx, σ̄_yy) with Λ = γ √(σ_yy/σ_xx) found by bisection in ln Λ.

    The x equation has λ = kk Λ, the y equation λ = kk/Λ; kk = A_c/(1 - A_c) is the odds of
    the tables' effective-medium threshold A_c (1 for the 2-D Bruggeman A_c = 1/2), so both
    close together at A(ζ1)/A0 = A_c (Λ = 1 there) for every γ_T.
    """
    if A1 >= kk / (1.0 + kk):
        return 0.0, 0.0
    lk = math.log(kk)
    l0 = math.log(A1 / (1.0 - A1)) if A1 > 0.0 else -60.0 - abs(lk)
    lo = l0 - lk
    hi = -l0 + lk
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lam = math.exp(mid)
        sx = solve_dir(W, sig, A1, kk * lam)
        sy = solve_dir(W, sig, A1, kk / lam)
        if sx <= 0.0:
            lo = mid
            continue
        if sy <= 0.0:
            hi = mid
            continue
        h = mid - math.log(gam) - 0.5 * (math.log(sy) - math.log(sx))
        if h > 0.0:
            hi = mid
        else:
            lo = mid
        if hi - lo < 1e-14:
            return sx, sy
    lam = math.exp(0.5 * (lo + hi))
    return solve_dir(W, sig, A1, kk * lam), solve_dir(W, sig, A1, kk / lam)


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

