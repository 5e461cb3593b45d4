"""Mean interfacial separation ū(ζ) (A4), u1(ζ) (A3), its inverse p_cont(ū) and the asymptote (3).

All by direct quadrature (:mod:`._kernels`), relative accuracy ~1e-10. B. Lorenz and
B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037; the γ ≠ 1
form is C. Yang and B.N.J. Persson, J. Phys.: Condens. Matter 20, 215214 (2008),
doi:10.1088/0953-8984/20/21/215214.
"""
from __future__ import annotations

import math

import numpy as np

from .._core.validate import check_positive, check_range
from ..kernels.quadrature import gauss_legendre
from ..kernels.special import EULER_GAMMA, K_ZERO, k_table
from ._checks import _check_gamma, _check_load, _check_pbar, _check_psd, _check_zeta
from ._kernels import (PANEL, asymptote_kernel, contact_pressure_kernel, mean_separation_kernel,
                       psd_kernel, u1_kernel)

__all__ = ["mean_separation", "separation_slope", "u1", "contact_pressure", "asymptote",
           "asymptote_self_affine"]


def _reduced_inputs(psd, p, E_star, zeta, gamma):
    """(shape, p̄ = p/E* [-], ζ [-], γ): the (A4) inputs checked, broadcast and flattened."""
    p, E_star = _check_load(psd, p, E_star)
    zeta = _check_zeta(psd, zeta)
    gamma = _check_gamma(gamma)
    pb, Eb, zb = np.broadcast_arrays(p, E_star, zeta)
    pbar = _check_pbar(np.ascontiguousarray((pb / Eb).ravel(), dtype=np.float64))
    z = np.ascontiguousarray(zb.ravel(), dtype=np.float64)
    return pb.shape, pbar, z, gamma


def _separation(psd, p, E_star, zeta, gamma, glx=None, glw=None, panel=PANEL, second=False):
    """(ū, dū/d ln p[, d²ū/d(ln p)²]) [m] by direct quadrature (broadcast over p, E*, ζ)."""
    shape, pbar, z, gamma = _reduced_inputs(psd, p, E_star, zeta, gamma)
    if glx is None:
        glx, glw = gauss_legendre()
    out = np.empty(pbar.size)
    dout = np.empty(pbar.size)
    d2out = np.empty(pbar.size)
    mean_separation_kernel(psd_kernel(psd), pbar, z, gamma, k_table(), glx, glw, float(panel),
                           out, dout, d2out)
    if second:
        return out.reshape(shape), dout.reshape(shape), d2out.reshape(shape)
    return out.reshape(shape), dout.reshape(shape)


def mean_separation(psd, p, E_star, zeta=1.0, gamma=1.0):
    """Mean interfacial separation ū(ζ) [m] at nominal contact pressure p (A4).

    ``ū(ζ) = (√π/2) ∫_{ζq0}^{q1} dq q² C(q) w(q,ζ) E1((w p(ζ)/E*)²)`` with
    ``p(ζ) = p A0/A(ζ)``; with γ ≠ 1 the Yang–Persson corrected form.

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    p : array_like
        Nominal contact pressure [Pa], > 0, with p/E* >= 1e-150 (below, the quadrature
        underflows: ValueError).
    E_star : float or array_like
        Effective modulus [Pa], > 0.
    zeta : array_like
        Magnification in [1, ζ1] [-] (default 1: the macroscopic separation).
    gamma : float
        Yang–Persson factor in (0, 1] [-]; 1 = the paper's (A4).

    Returns
    -------
    ndarray
        ū [m], broadcast shape of (p, E_star, zeta). Relative accuracy ~1e-10
        (Gauss–Legendre order 10 on unit panels in ln(q/ζq0 - 1)).
    """
    return _separation(psd, p, E_star, zeta, gamma)[0]


def separation_slope(psd, p, E_star, gamma=1.0):
    """dū/d ln p [m] at ζ = 1 (negative), from the same quadrature as :func:`mean_separation`.

    Parameters are those of :func:`mean_separation`.
    """
    return _separation(psd, p, E_star, 1.0, gamma)[1]


def u1(psd, p, E_star, zeta, gamma=1.0):
    """u1(ζ) = ū(ζ) + ū'(ζ) A(ζ)/A'(ζ) [m] (A3), in closed form from the (A4) integrals.

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    p : array_like
        Nominal contact pressure [Pa], > 0, with p/E* >= 1e-150.
    E_star : float or array_like
        Effective modulus [Pa], > 0.
    zeta : array_like
        Magnification in [1, ζ1] [-].
    gamma : float
        Yang–Persson factor in (0, 1] [-].

    Returns
    -------
    numpy.ma.MaskedArray
        u1 [m]. Where dA/dζ underflows to zero (ζ = 1, or A(ζ) = 1 to double precision at
        high pressure) u1 is undefined; those entries are **masked** (they carry zero weight
        in every flow theory), never returned as inf or NaN.
    """
    shape, pbar, z, gamma = _reduced_inputs(psd, p, E_star, zeta, gamma)
    glx, glw = gauss_legendre()
    out = np.empty(pbar.size)
    u1_kernel(psd_kernel(psd), pbar, z, gamma, k_table(), glx, glw, PANEL, out)
    out = out.reshape(shape)
    mask = ~np.isfinite(out)
    return np.ma.MaskedArray(np.where(mask, 0.0, out), mask=mask)


def contact_pressure(psd, u, E_star, gamma=1.0):
    """Nominal contact pressure p_cont [Pa] at which ū(p) = u (inverse of (A4) at ζ = 1).

    Solved by safeguarded Newton to 1e-14 in ln p, started from the asymptote (3).

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    u : array_like
        Mean separation [m], > 0.
    E_star : float or array_like
        Effective modulus [Pa], > 0.
    gamma : float
        Yang–Persson factor in (0, 1] [-].

    Returns
    -------
    ndarray
        p_cont [Pa], broadcast shape of (u, E_star).
    """
    u, E_star = _check_load(psd, u, E_star, "u", "[m]")
    gamma = _check_gamma(gamma)
    ub, Eb = np.broadcast_arrays(u, E_star)
    ubar = np.ascontiguousarray(ub.ravel(), dtype=np.float64)
    u0, beta = asymptote(psd, gamma)
    guess = np.ascontiguousarray(np.log(beta) - ubar / u0)
    glx, glw = gauss_legendre()
    out = np.empty(ubar.size)
    contact_pressure_kernel(psd_kernel(psd), ubar, guess, gamma, k_table(), glx, glw, PANEL, out)
    return (np.exp(out) * Eb.ravel()).reshape(ub.shape)


def _gamma_correction(u0, beta, gamma):
    """The asymptote's (u0, β) for γ ≠ 1: u0 → γ u0, β → β exp(3(1-γ)K(0)/γ)."""
    if gamma != 1.0:
        beta *= math.exp(3.0 * (1.0 - gamma) * K_ZERO / gamma)
        u0 *= gamma
    return float(u0), float(beta)


def asymptote(psd, gamma=1.0):
    """Large-separation asymptote p_cont ≈ β E* exp(-ū/u0) (eq. 3).

    From the exact small-p limit of (A4): ``u0 = √π ∫ q² C w dq``,
    ``β = exp(-γ_E/2 - <ln w>)`` (weights q² C w); with γ ≠ 1, ``u0 -> γ u0`` and
    ``β -> β exp(3(1-γ)K(0)/γ)``. Independent of E*.

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    gamma : float
        Yang–Persson factor in (0, 1] [-].

    Returns
    -------
    (float, float)
        u0 [m] and β [-].
    """
    _check_psd(psd)
    gamma = _check_gamma(gamma)
    glx, glw = gauss_legendre()
    u0, mean_lnw = asymptote_kernel(psd_kernel(psd), glx, glw, PANEL)
    beta = math.exp(-0.5 * EULER_GAMMA - mean_lnw)
    return _gamma_correction(u0, beta, gamma)


def asymptote_self_affine(h_rms, hurst, q0, gamma=1.0):
    """Closed-form asymptote (u0 [m], β [-]) of a self-affine spectrum without roll-off, ζ1 → ∞.

    With ``b = H/(2-2H)`` (the small-p limit of A4):
    ``u0/h_rms = √(H/(π(2-2H))) B(½, b)``,
    ``β/(q0 h_rms) = e^{-γ_E/2} √(H/(2-2H)) exp(½[ψ(½) - ψ(b)])``;
    with γ ≠ 1, ``u0 -> γ u0`` and ``β -> β exp(3(1-γ)K(0)/γ)``.
    For H = 0.8: u0/h_rms = 1.063846, β/(q0 h_rms) = 0.321364. A finite ζ1 changes both by
    a relative amount of order ζ1^(-H) ln ζ1 (compare :func:`asymptote`).

    Parameters
    ----------
    h_rms : float
        rms roughness [m], > 0.
    hurst : float
        Hurst exponent H in (0, 1) [-].
    q0 : float
        Lower cut-off wavenumber [1/m], > 0.
    gamma : float
        Yang–Persson factor in (0, 1] [-].
    """
    h_rms = float(check_positive("h_rms", h_rms, "[m]"))
    H = float(check_range("hurst", hurst, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    q0 = float(check_positive("q0", q0, "[1/m]"))
    gamma = _check_gamma(gamma)
    from scipy.special import beta as beta_fn, digamma   # here: import fastcontact stays light
    b = H / (2.0 - 2.0 * H)
    u0 = h_rms * math.sqrt(H / (math.pi * (2.0 - 2.0 * H))) * beta_fn(0.5, b)
    beta = (q0 * h_rms * math.exp(-0.5 * EULER_GAMMA) * math.sqrt(H / (2.0 - 2.0 * H))
            * math.exp(0.5 * (digamma(0.5) - digamma(b))))
    return _gamma_correction(u0, beta, gamma)
