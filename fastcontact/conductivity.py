"""Interfacial fluid flow conductivity σ_eff(p_cont) — three theories (SPEC §3).

Reduced units throughout the kernels: ``σ̄ = 12 η σ_eff / h_rms³`` (eq. 23), ``p̄ = p/E*``.

Theories
--------
``"average"``            σ_eff = ū³ / (12η)                                   (Sec. 2)
``"critical_junction"``  σ_eff = (α_cj u1(ζc))³ / (12η), A(ζc)/A0 = a_perc     (Sec. 3, 31–32)
``"emt"``                2-D Bruggeman effective medium over P(u) from u1(ζ)  ([literature])

Percolation is exact: critical junction gives σ_eff = 0 when A(ζ1)/A0 >= a_perc; the
effective medium when A(ζ1)/A0 >= 0.5. Every result carries a ``percolated`` flag.

The effective medium integral is taken in the variable A (``-A'(ζ)dζ = -dA``) with
Gauss–Legendre nodes on [A(ζ1), 1], u1 evaluated at the magnification where A(ζ) equals
each node exactly; nodes where dA/dζ underflows get u1 = ∞ and so contribute 0 (masked).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ._validate import check_positive, check_range
from .contact import _arrays, _check_gamma, _check_psd
from .quadrature import PANEL, gauss_legendre, u1_at_area, m1_above
from .special import k_table

__all__ = ["THEORIES", "conductivity", "flow_factor", "EMT_N_AREA"]

THEORIES = ("average", "critical_junction", "emt")
#: Gauss–Legendre nodes in A for the effective-medium integral (see bench/bench_tables.py)
EMT_N_AREA = 96
#: Gauss–Hermite nodes for the Almqvist-broadened P(u)
GH_ORDER = 24


def check_theory(theory):
    if theory not in THEORIES:
        raise ValueError(f"theory = {theory!r} is invalid: must be one of {list(THEORIES)}")
    return theory


# --------------------------------------------------------------------------- kernels
@njit(cache=True)
def _area1(cum3, pbar):
    G1 = 0.25 * math.pi * cum3[-1]
    return math.erf(pbar / (2.0 * math.sqrt(G1)))


@njit(cache=True, parallel=True)
def critical_junction_kernel(qb, c, e, cum3, kinks, pbar, gamma, a_perc, ktab, glx, glw, panel,
                             u1c, zeta_c, percolated):
    """u1(ζc) [m] and ζc per reduced pressure; percolated where A(ζ1)/A0 >= a_perc."""
    for i in prange(pbar.size):
        work = np.empty(3)
        if _area1(cum3, pbar[i]) >= a_perc:
            u1c[i] = 0.0
            zeta_c[i] = math.inf
            percolated[i] = True
        else:
            u, a = u1_at_area(qb, c, e, cum3, kinks, a_perc, pbar[i], gamma, ktab, glx, glw,
                              panel, work)
            u1c[i] = u
            zeta_c[i] = a / qb[0]
            percolated[i] = False


@njit(cache=True)
def bruggeman(W, sig, A1, almqvist, hz, ghx, ghw):
    """Solve Σ_j W_j 2s/(s + σ_j) + 2 A1 - 1 = 0 for s > 0 (2-D Bruggeman, reduced units).

    With ``almqvist`` each node is a reflected Gaussian of width hz[j] around u1 = σ_j^(1/3)
    (Gauss–Hermite nodes ghx, ghw). Returns 0 when A1 >= 0.5 (percolated).
    """
    if A1 >= 0.5:
        return 0.0
    # bracket in y = ln s
    inv = 0.0
    smax = 0.0
    for j in range(W.size):
        if sig[j] > 0.0:
            inv += W[j] / sig[j]
            if sig[j] > smax and sig[j] < math.inf:
                smax = sig[j]
    if almqvist:
        # widths broaden the distribution: widen the bracket generously
        for j in range(W.size):
            if sig[j] == math.inf:
                continue
            u = sig[j] ** (1.0 / 3.0) + 8.0 * hz[j]
            if u ** 3 > smax:
                smax = u ** 3
    if smax <= 0.0:
        return 0.0
    lo = math.log(max((1.0 - 2.0 * A1) / (2.0 * inv) if inv > 0 else smax * 1e-300, 1e-300)) - 1.0
    hi = math.log(smax) + 1.0
    y = 0.5 * (lo + hi)
    for it in range(200):
        s = max(math.exp(y), 1e-300)
        f = 2.0 * A1 - 1.0
        df = 0.0
        for j in range(W.size):
            if sig[j] == math.inf:
                continue  # masked node (u1 undefined, dA/dζ = 0): zero weight
            if almqvist:
                mu = sig[j] ** (1.0 / 3.0)
                acc = 0.0
                dacc = 0.0
                for k in range(ghx.size):
                    u = abs(mu + math.sqrt(2.0) * hz[j] * ghx[k])
                    su = u * u * u
                    r = s / (s + su) if s + su > 0.0 else 1.0
                    acc += ghw[k] * 2.0 * r
                    dacc += ghw[k] * 2.0 * r * (1.0 - r)
                f += W[j] * acc / math.sqrt(math.pi)
                df += W[j] * dacc / math.sqrt(math.pi)
            else:
                sj = sig[j]
                if sj == 0.0:
                    f += 2.0 * W[j]  # a node in contact: σ(u = 0) = 0
                    continue
                r = s / (s + sj)
                f += W[j] * 2.0 * r
                df += W[j] * 2.0 * r * (1.0 - r)
        if f > 0.0:
            hi = y
        else:
            lo = y
        yn = y - f / df if df > 0.0 else 0.5 * (lo + hi)
        if not (lo < yn < hi):
            yn = 0.5 * (lo + hi)
        if abs(yn - y) < 1e-15 * max(1.0, abs(y)) or hi - lo < 1e-15:
            return math.exp(yn)
        y = yn
    return math.exp(y)


@njit(cache=True, parallel=True)
def emt_kernel(qb, c, e, cum3, kinks, pbar, h_rms, gamma, ktab, glx, glw, panel, ax, aw,
               almqvist, ghx, ghw, sigma, percolated):
    """Bruggeman σ̄ = 12ησ_eff/h_rms³ per reduced pressure (u1-based P(u), SPEC §3)."""
    n = ax.size
    for i in prange(pbar.size):
        A1 = _area1(cum3, pbar[i])
        if A1 >= 0.5:
            sigma[i] = 0.0
            percolated[i] = True
            continue
        percolated[i] = False
        work = np.empty(3)
        W = np.empty(n)
        sig = np.empty(n)
        hz = np.zeros(n)
        for j in range(n):
            area = A1 + (1.0 - A1) * 0.5 * (1.0 + ax[j])
            W[j] = (1.0 - A1) * 0.5 * aw[j]
            u, a = u1_at_area(qb, c, e, cum3, kinks, area, pbar[i], gamma, ktab, glx, glw,
                              panel, work)
            if not (u < math.inf) or u != u:
                sig[j] = math.inf  # masked: dA/dζ = 0 there, zero weight in the integral
            else:
                uh = max(u, 0.0) / h_rms
                sig[j] = uh * uh * uh
            if almqvist:
                hz[j] = math.sqrt(2.0 * math.pi * m1_above(qb, c, e, a)) / h_rms
        sigma[i] = bruggeman(W, sig, A1, almqvist, hz, ghx, ghw)


# --------------------------------------------------------------------------- reduced API
def sigma_bar(psd, pbar, theory, *, gamma=1.0, a_perc=0.5, alpha_cj=1.0, n_area=EMT_N_AREA,
              almqvist=False, glx=None, glw=None, panel=PANEL):
    """Reduced conductivity σ̄ = 12ησ_eff/h_rms³ at reduced contact pressures p̄ = p/E*.

    Returns (sigma_bar, percolated, extra) with extra = dict of by-products (u_bar, u1c, ζc).
    """
    from .contact import _separation  # local: avoid a cycle at import

    pbar = np.ascontiguousarray(np.asarray(pbar, dtype=np.float64).ravel())
    h = psd.h_rms
    if glx is None:
        glx, glw = gauss_legendre()
    arrs = _arrays(psd)
    ktab = k_table()
    extra = {}
    if theory == "average":
        u, _ = _separation(psd, pbar, 1.0, 1.0, gamma, glx, glw, panel)
        extra["u_bar"] = u / h
        return (u / h) ** 3, np.zeros(pbar.size, dtype=bool), extra
    if theory == "critical_junction":
        u1c = np.empty(pbar.size)
        zc = np.empty(pbar.size)
        perc = np.empty(pbar.size, dtype=np.bool_)
        critical_junction_kernel(*arrs, pbar, gamma, float(a_perc), ktab, glx, glw, float(panel),
                                 u1c, zc, perc)
        extra["u1c"] = u1c / h
        extra["zeta_c"] = zc
        return (alpha_cj * u1c / h) ** 3, perc, extra
    if theory == "emt":
        ax, aw = np.polynomial.legendre.leggauss(int(n_area))
        ghx, ghw = np.polynomial.hermite.hermgauss(GH_ORDER)
        sig = np.empty(pbar.size)
        perc = np.empty(pbar.size, dtype=np.bool_)
        emt_kernel(*arrs, pbar, h, gamma, ktab, glx, glw, float(panel), ax, aw, bool(almqvist),
                   ghx, ghw, sig, perc)
        return sig, perc, extra
    check_theory(theory)


def conductivity(psd, p, E_star, eta, theory="average", *, gamma=1.0, a_perc=0.5,
                 alpha_cj=1.0, n_area=EMT_N_AREA, almqvist=False):
    """Effective interfacial fluid conductivity σ_eff(p_cont) [m³/(Pa·s)] by direct quadrature.

    Parameters
    ----------
    psd : PSD          roughness spectrum
    p : array_like     contact pressure p_cont [Pa], > 0
    E_star : float     effective modulus [Pa]
    eta : float        fluid viscosity [Pa·s]
    theory : {"average", "critical_junction", "emt"}
    gamma : float      Yang–Persson factor of ū(ζ) and u1(ζ) (1 = paper)
    a_perc : float     critical-junction percolation area fraction (0.5 paper; 0.42 option)
    alpha_cj : float   critical-junction factor multiplying u1(ζc) (σ carries α_cj³)
    n_area : int       Gauss–Legendre nodes of the effective-medium integral over A
    almqvist : bool    Gaussian-broadened P(u) (Almqvist et al. 2011) in the effective medium

    Returns
    -------
    (sigma_eff [m³/(Pa·s)], percolated [bool]) arrays of p's shape; σ_eff = 0 exactly where
    percolated.
    """
    _check_psd(psd)
    check_theory(theory)
    p = check_positive("p", p, "[Pa]")
    E_star = float(check_positive("E_star", E_star, "[Pa]"))
    eta = check_positive("eta", eta, "[Pa·s]")
    gamma = _check_gamma(gamma)
    a_perc = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    alpha_cj = float(check_positive("alpha_cj", alpha_cj, "[-]"))
    sb, perc, _ = sigma_bar(psd, np.ravel(p) / E_star, theory, gamma=gamma, a_perc=a_perc,
                            alpha_cj=alpha_cj, n_area=n_area, almqvist=almqvist)
    sig = sb.reshape(np.shape(p)) * psd.h_rms ** 3 / (12.0 * eta)
    return sig, perc.reshape(np.shape(p))


def flow_factor(psd, p, E_star, theory="emt", **options):
    """Pressure flow factor φ_p = 12ησ_eff/ū³ [-] (Patir & Cheng; paper Sec. 4)."""
    from .contact import mean_separation

    sig, perc = conductivity(psd, p, E_star, 1.0, theory, **options)
    u = mean_separation(psd, p, E_star, gamma=options.get("gamma", 1.0))
    return 12.0 * sig / u ** 3, perc
