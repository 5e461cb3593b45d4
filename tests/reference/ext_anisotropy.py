"""Independent reference for the anisotropic Bruggeman medium (issue 14.3).

P(u) is built differently from the package: as -dA/dζ dζ over a Gauss–Legendre grid in
ln ζ (dA/dζ in closed form from (A1)–(A2): A' = -(2/√π) x e^{-x²} G'/(2G),
x = p/(2√G), G' = (π/4)E*² q0⁴ζ³C(ζq0)), with u1(ζ) from the public contact core; the
equations are solved with scipy brentq (nested for the self-consistent form), written from
docs/theory/extensions.md §3, not from fastcontact.flow.anisotropy.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import optimize

from fastcontact.contact import u1


def p_of_u(psd, p, E_star, n_panels=200, order=12):
    """(weights, σ̄_j = (u1/h)³, A1) on a GL grid in τ = ln(ζ - 1) ∈ [-34, ln(ζ1 - 1)]
    (A(ζ) falls from 1 within ζ - 1 ~ (p/E*)² at low pressure: the grid must resolve it)."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(-34.0, math.log(psd.zeta1 - 1.0), n_panels + 1)
    half = 0.5 * np.diff(edges)
    tau = (0.5 * (edges[:-1] + edges[1:])[:, None] + half[:, None] * x[None, :]).ravel()
    wt = (half[:, None] * w[None, :]).ravel()
    zeta = 1.0 + np.exp(tau)
    q0 = psd.q0
    G = 0.25 * math.pi * E_star ** 2 * np.asarray(psd.moment(3.0, q0, zeta * q0))
    Gp = 0.25 * math.pi * E_star ** 2 * q0 ** 4 * zeta ** 3 * psd(zeta * q0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        xx = p / (2.0 * np.sqrt(G))
        dA = -(2.0 / math.sqrt(math.pi)) * xx * np.exp(-xx * xx) * Gp / (2.0 * G)   # dA/dζ
        W = -dA * (zeta - 1.0) * wt                                      # -dA = -A' (ζ-1) dτ
        uu = u1(psd, p, E_star, zeta)
        sig = (np.ma.filled(uu, 0.0) / psd.h_rms) ** 3
    mask = np.ma.getmaskarray(uu) | ~(W > 0) | ~np.isfinite(sig) | ~np.isfinite(W)
    A1 = math.erf(p / (2.0 * math.sqrt(0.25 * math.pi * E_star ** 2 * psd.cum3[-1])))
    return np.where(mask, 0.0, W), np.where(mask, 0.0, sig), A1


def _solve(W, sig, A1, lam):
    if A1 >= lam / (1 + lam):
        return 0.0

    def f(y):
        s = math.exp(y)
        return float(np.sum(W * (sig - s) / (lam * s + sig))) - A1 / lam

    if f(-700.0) <= 0.0:
        return 0.0
    return math.exp(optimize.brentq(f, -700.0, min(math.log(sig.max()) + 5.0, 700.0), xtol=1e-14,
                                    rtol=1e-14))


def sigma_fixed(W, sig, A1, gamma, a_c=0.5):
    """(σ̄_xx, σ̄_yy): ∫P (σ - s)/(k γ s + σ) = 0 (x) and with k/γ (y), k = A_c/(1 - A_c)
    the odds of the isotropic medium's threshold A_c (docs/theory/extensions.md §3)."""
    k = a_c / (1.0 - a_c)
    return _solve(W, sig, A1, k * gamma), _solve(W, sig, A1, k / gamma)


def sigma_self_consistent(W, sig, A1, gamma, a_c=0.5):
    """(σ̄_xx, σ̄_yy) with λ_x = kΛ, λ_y = k/Λ, Λ = γ √(σ_yy/σ_xx) (brentq on ln Λ)."""
    k = a_c / (1.0 - a_c)
    if A1 >= a_c:
        return 0.0, 0.0

    def h(y):
        lam = math.exp(y)
        sx, sy = _solve(W, sig, A1, k * lam), _solve(W, sig, A1, k / lam)
        if sx == 0:
            return -50.0
        if sy == 0:
            return 50.0
        return y - math.log(gamma) - 0.5 * math.log(sy / sx)

    lo = math.log(A1 / (1 - A1) / k) + 1e-7
    hi = math.log(k * (1 - A1) / A1) - 1e-7
    y = optimize.brentq(h, lo, hi, xtol=1e-13)
    lam = math.exp(y)
    return _solve(W, sig, A1, k * lam), _solve(W, sig, A1, k / lam)
