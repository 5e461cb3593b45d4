"""Persson contact mechanics by direct quadrature — the accurate core (SPEC §2, App. A).

Everything here is evaluated without tables; the precomputed tables of
:mod:`fastcontact.tables` are checked against these functions.

Glossary
--------
p        nominal contact pressure (in squeeze-out and seals: p_cont) [Pa]
E_star   effective modulus E* [Pa] (see :func:`fastcontact.effective_modulus`)
ζ        magnification q/q0 [-]; ζ1 = q1/q0
G(ζ)     (π/4) E*² ∫_{q0}^{ζq0} q³ C dq [Pa²]                          (A2)
A(ζ)/A0  apparent relative contact area at magnification ζ [-]          (A1)
ū(ζ)     mean interfacial separation at magnification ζ [m]             (A4)
u1(ζ)    separation of the surfaces that come into contact at ζ [m]      (A3)
γ        Yang–Persson correction factor (1 = the paper's A4) [-]
u0, β    asymptote p ≈ β E* exp(-ū/u0) [m], [-]                          (3)
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._core.validate import check_positive, check_range
from ..surface.psd import PSD
from ._kernels import (PANEL, area_state, clip_at_kink, gauss_legendre, m3_from, psd_value, q_for_m3,
                         separation_integrals, u1_at)
from ..kernels.special import EULER_GAMMA, K_ZERO, erfinv, k_table

__all__ = ["area_fraction", "mean_separation", "u1", "critical_magnification",
           "contact_pressure", "asymptote", "asymptote_self_affine", "stiffness_G",
           "percolation_pressure", "separation_slope"]


# --------------------------------------------------------------------------- validation
def _check_psd(psd):
    if not isinstance(psd, PSD):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object "
                         f"(SelfAffinePSD, TabulatedPSD, read_psd(...), psd_from_heights(...))")
    return psd


def _check_gamma(gamma):
    return float(check_range("gamma", gamma, 0.0, 1.0, "[-] (Yang–Persson factor; 1 = paper)",
                             lo_open=True))


def _check_zeta(psd, zeta):
    return check_range("zeta", zeta, 1.0, psd.zeta1, "[-] (magnification, 1 to q1/q0)")


def _arrays(psd):
    qb, c, e, cum3 = psd.kernel_arrays()
    kinks = np.ascontiguousarray(np.sort(np.asarray(psd.kinks, dtype=np.float64)))
    return qb, c, e, cum3, kinks


# --------------------------------------------------------------------------- kernels
@njit(cache=True)
def _mean_separation_kernel(qb, c, e, cum3, kinks, pbar, zeta, gamma, ktab, glx, glw, panel,
                            out, dout, d2out):
    work = np.empty(4)
    q0 = qb[0]
    for i in range(pbar.size):
        a = zeta[i] * q0
        A, ratio, P = area_state(qb, c, e, cum3, a, pbar[i])
        separation_integrals(qb, c, e, cum3, kinks, a, P, gamma, ktab, glx, glw, panel, work)
        out[i] = work[0]
        dout[i] = -work[1]
        d2out[i] = -work[3]


@njit(cache=True)
def _u1_kernel(qb, c, e, cum3, kinks, pbar, zeta, gamma, ktab, glx, glw, panel, out):
    work = np.empty(4)
    q0 = qb[0]
    for i in range(pbar.size):
        out[i] = u1_at(qb, c, e, cum3, kinks, zeta[i] * q0, pbar[i], gamma, ktab, glx, glw,
                       panel, work)


@njit(cache=True)
def _contact_pressure_kernel(qb, c, e, cum3, kinks, ubar, lnp_guess, gamma, ktab, glx, glw,
                             panel, out):
    """Solve ū(p) = u for ln p by safeguarded Newton (ū decreasing, dū/dln p = -I_g)."""
    work = np.empty(4)
    q0 = qb[0]
    for i in range(ubar.size):
        target = ubar[i]
        lo = -745.0
        hi = 50.0
        x = lnp_guess[i]
        if x < lo or x > hi:
            x = 0.5 * (lo + hi)
        for it in range(200):
            separation_integrals(qb, c, e, cum3, kinks, q0, math.exp(x), gamma, ktab, glx,
                                 glw, panel, work)
            f = work[0] - target
            if f > 0.0:
                lo = x
            else:
                hi = x
            d = -work[1]
            step = f / d if d < 0.0 else 0.0
            xn = x - step
            if not (lo < xn < hi) or d >= 0.0:
                xn = 0.5 * (lo + hi)
            if abs(xn - x) < 1e-14 * max(1.0, abs(x)) or hi - lo < 1e-14:
                x = xn
                break
            x = xn
        out[i] = x


@njit(cache=True)
def _asymptote_kernel(qb, c, e, cum3, kinks, glx, glw, panel):
    """(√π ∫ q²C w dq [m], ∫ q²C w ln w dq / ∫ q²C w dq) at ζ = 1 (SPEC §2)."""
    a = qb[0]
    ia = 0
    tau_hi = math.log(qb[-1] / a - 1.0)
    t0 = -120.0
    s0 = 0.0
    s1 = 0.0
    ik = 0
    while t0 < tau_hi:
        t1, ik = clip_at_kink(kinks, ik, a, qb[-1], t0, min(t0 + panel, tau_hi))
        half = 0.5 * (t1 - t0)
        mid = 0.5 * (t1 + t0)
        for j in range(glx.size):
            tau = mid + half * glx[j]
            delta = math.exp(tau)
            q = a * (1.0 + delta)
            w = 1.0 / math.sqrt(math.pi * m3_from(qb, c, e, cum3, a, ia, delta))
            wt = glw[j] * half * a * delta * q * q * psd_value(qb, c, e, q) * w
            s0 += wt
            s1 += wt * math.log(w)
        t0 = t1
    return math.sqrt(math.pi) * s0, s1 / s0


# --------------------------------------------------------------------------- public API
def stiffness_G(psd, E_star, zeta):
    """G(ζ) = (π/4) E*² ∫_{q0}^{ζq0} q³ C(q) dq [Pa²] (A2)."""
    _check_psd(psd)
    E_star = check_positive("E_star", E_star, "[Pa]")
    zeta = _check_zeta(psd, zeta)
    return 0.25 * math.pi * E_star ** 2 * np.asarray(psd.moment(3.0, psd.q0, zeta * psd.q0))


def area_fraction(psd, p, E_star, zeta=None):
    """Apparent relative contact area A(ζ)/A0 = erf(p / (2√G(ζ))) [-] (A1).

    Parameters
    ----------
    psd : PSD          surface roughness spectrum
    p : array_like     nominal contact pressure [Pa], > 0
    E_star : float     effective modulus [Pa], > 0
    zeta : array_like, optional   magnification in [1, ζ1]; None = ζ1 (the true contact area)
    """
    _check_psd(psd)
    p = check_positive("p", p, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    zeta = psd.zeta1 if zeta is None else _check_zeta(psd, zeta)
    G = 0.25 * math.pi * E_star ** 2 * np.asarray(psd.moment(3.0, psd.q0, np.asarray(zeta) * psd.q0))
    with np.errstate(divide="ignore"):
        x = p / (2.0 * np.sqrt(G))
    from scipy.special import erf
    return erf(x)


def percolation_pressure(psd, E_star, a_perc=0.5):
    """Nominal pressure [Pa] at which A(ζ1)/A0 = a_perc (the contact percolates)."""
    _check_psd(psd)
    E_star = check_positive("E_star", E_star, "[Pa]")
    a_perc = check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True)
    G1 = 0.25 * math.pi * E_star ** 2 * psd.cum3[-1]
    from scipy.special import erfinv as sp_erfinv
    return 2.0 * np.sqrt(G1) * sp_erfinv(a_perc)


def _separation(psd, p, E_star, zeta, gamma, glx=None, glw=None, panel=PANEL, second=False):
    """(ū, dū/d ln p[, d²ū/d(ln p)²]) [m] by direct quadrature (broadcast over p, E*, ζ)."""
    _check_psd(psd)
    p = check_positive("p", p, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    zeta = _check_zeta(psd, zeta)
    gamma = _check_gamma(gamma)
    pb, Eb, zb = np.broadcast_arrays(p, E_star, zeta)
    shape = pb.shape
    pbar = np.ascontiguousarray((pb / Eb).ravel(), dtype=np.float64)
    z = np.ascontiguousarray(zb.ravel(), dtype=np.float64)
    if glx is None:
        glx, glw = gauss_legendre()
    out = np.empty(pbar.size)
    dout = np.empty(pbar.size)
    d2out = np.empty(pbar.size)
    _mean_separation_kernel(*_arrays(psd), pbar, z, gamma, k_table(), glx, glw, float(panel),
                            out, dout, d2out)
    if second:
        return out.reshape(shape), dout.reshape(shape), d2out.reshape(shape)
    return out.reshape(shape), dout.reshape(shape)


def mean_separation(psd, p, E_star, zeta=1.0, gamma=1.0):
    """Mean interfacial separation ū(ζ) [m] at nominal contact pressure p (A4).

    ``ū(ζ) = (√π/2) ∫_{ζq0}^{q1} dq q² C(q) w(q,ζ) E1((w p(ζ)/E*)²)`` with
    ``p(ζ) = p A0/A(ζ)``; with γ ≠ 1 the Yang–Persson corrected form (SPEC §2).

    Parameters
    ----------
    psd : PSD        roughness spectrum
    p : array_like   nominal contact pressure [Pa], > 0
    E_star : float   effective modulus [Pa], > 0
    zeta : array_like  magnification in [1, ζ1] (default 1: the macroscopic separation)
    gamma : float    Yang–Persson factor in (0, 1]; 1 = the paper's (A4)

    Returns
    -------
    ndarray  ū [m], broadcast shape of (p, E_star, zeta). Relative accuracy ~1e-10
    (Gauss–Legendre order 10 on unit panels in ln(q/ζq0 - 1)).
    """
    return _separation(psd, p, E_star, zeta, gamma)[0]


def separation_slope(psd, p, E_star, gamma=1.0):
    """dū/d ln p [m] at ζ = 1 (negative), from the same quadrature as :func:`mean_separation`."""
    return _separation(psd, p, E_star, 1.0, gamma)[1]


def u1(psd, p, E_star, zeta, gamma=1.0):
    """u1(ζ) = ū(ζ) + ū'(ζ) A(ζ)/A'(ζ) [m] (A3), in the closed form of SPEC §2.

    Where dA/dζ underflows to zero (ζ = 1, or A(ζ) = 1 to double precision at high pressure)
    u1 is undefined; those entries are **masked** in the returned ``numpy.ma.MaskedArray``
    (they carry zero weight in every flow theory), never returned as inf or NaN.
    """
    _check_psd(psd)
    p = check_positive("p", p, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    zeta = _check_zeta(psd, zeta)
    gamma = _check_gamma(gamma)
    pb, Eb, zb = np.broadcast_arrays(p, E_star, zeta)
    pbar = np.ascontiguousarray((pb / Eb).ravel(), dtype=np.float64)
    z = np.ascontiguousarray(zb.ravel(), dtype=np.float64)
    glx, glw = gauss_legendre()
    out = np.empty(pbar.size)
    _u1_kernel(*_arrays(psd), pbar, z, gamma, k_table(), glx, glw, PANEL, out)
    out = out.reshape(pb.shape)
    mask = ~np.isfinite(out)
    return np.ma.MaskedArray(np.where(mask, 0.0, out), mask=mask)


def critical_magnification(psd, p, E_star, a_perc=0.5):
    """ζc, the smallest magnification with A(ζc)/A0 = a_perc [-] (critical junction, Sec. 3).

    Returns ``inf`` where A(ζ1)/A0 >= a_perc: the contact has percolated, no open channel.
    """
    _check_psd(psd)
    p = check_positive("p", p, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    a_perc = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    pb, Eb = np.broadcast_arrays(p, E_star)
    pbar = (pb / Eb).ravel()
    x = float(erfinv(a_perc))
    target = 4.0 / math.pi * (pbar / (2.0 * x)) ** 2
    qb, c, e, cum3 = psd.kernel_arrays()
    out = np.array([q_for_m3(qb, c, e, cum3, t) / psd.q0 if t < cum3[-1] else math.inf
                    for t in target])
    return out.reshape(pb.shape)


def contact_pressure(psd, u, E_star, gamma=1.0):
    """Nominal contact pressure p_cont [Pa] at which ū(p) = u: the inverse of
    :func:`mean_separation` (ζ = 1), solved by safeguarded Newton to 1e-14 in ln p.

    Parameters
    ----------
    u : array_like   mean separation [m], > 0
    """
    _check_psd(psd)
    u = check_positive("u", u, "[m]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    gamma = _check_gamma(gamma)
    ub, Eb = np.broadcast_arrays(u, E_star)
    ubar = np.ascontiguousarray(ub.ravel(), dtype=np.float64)
    u0, beta = asymptote(psd, gamma)
    guess = np.ascontiguousarray(np.log(beta) - ubar / u0)
    glx, glw = gauss_legendre()
    out = np.empty(ubar.size)
    _contact_pressure_kernel(*_arrays(psd), ubar, guess, gamma, k_table(), glx, glw, PANEL, out)
    return (np.exp(out) * Eb.ravel()).reshape(ub.shape)


def asymptote(psd, gamma=1.0):
    """Large-separation asymptote p_cont ≈ β E* exp(-ū/u0) (eq. 3): returns (u0 [m], β [-]).

    From the exact small-p limit of (A4): ``u0 = √π ∫ q² C w dq``,
    ``β = exp(-γ_E/2 - <ln w>)`` (weights q² C w); with γ ≠ 1, ``u0 -> γ u0`` and
    ``β -> β exp(3(1-γ)K(0)/γ)`` (SPEC §2). Independent of E*.
    """
    _check_psd(psd)
    gamma = _check_gamma(gamma)
    glx, glw = gauss_legendre()
    u0, mean_lnw = _asymptote_kernel(*_arrays(psd), glx, glw, PANEL)
    beta = math.exp(-0.5 * EULER_GAMMA - mean_lnw)
    if gamma != 1.0:
        beta *= math.exp(3.0 * (1.0 - gamma) * K_ZERO / gamma)
        u0 *= gamma
    return float(u0), float(beta)


def asymptote_self_affine(h_rms, hurst, q0, gamma=1.0):
    """Closed-form asymptote (u0 [m], β [-]) of a self-affine spectrum without roll-off, ζ1 → ∞.

    With ``b = H/(2-2H)`` (SPEC §2, derived from the small-p limit of A4):
    ``u0/h_rms = √(H/(π(2-2H))) B(½, b)``,
    ``β/(q0 h_rms) = e^{-γ_E/2} √(H/(2-2H)) exp(½[ψ(½) - ψ(b)])``;
    with γ ≠ 1, ``u0 -> γ u0`` and ``β -> β exp(3(1-γ)K(0)/γ)``.
    For H = 0.8: u0/h_rms = 1.063846, β/(q0 h_rms) = 0.321364. A finite ζ1 changes both by
    a relative amount of order ζ1^(-H) ln ζ1 (compare :func:`asymptote`).
    """
    from scipy.special import beta as beta_fn, digamma

    h_rms = float(check_positive("h_rms", h_rms, "[m]"))
    H = float(check_range("hurst", hurst, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    q0 = float(check_positive("q0", q0, "[1/m]"))
    gamma = _check_gamma(gamma)
    b = H / (2.0 - 2.0 * H)
    u0 = h_rms * math.sqrt(H / (math.pi * (2.0 - 2.0 * H))) * beta_fn(0.5, b)
    beta = (q0 * h_rms * math.exp(-0.5 * EULER_GAMMA) * math.sqrt(H / (2.0 - 2.0 * H))
            * math.exp(0.5 * (digamma(0.5) - digamma(b))))
    if gamma != 1.0:
        beta *= math.exp(3.0 * (1.0 - gamma) * K_ZERO / gamma)
        u0 *= gamma
    return float(u0), float(beta)
