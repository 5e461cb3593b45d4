"""Contact area and elastic energy of Persson's theory: G(ζ) (A2), A(ζ)/A0 (A1), percolation.

``G(ζ) = (π/4) E*² ∫_{q0}^{ζq0} q³ C(q) dq`` and ``A(ζ)/A0 = erf(p / (2√G(ζ)))``
(B.N.J. Persson, J. Chem. Phys. 115, 3840 (2001), doi:10.1063/1.1388626; B. Lorenz and
B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037, App. A).
"""
from __future__ import annotations

import math

import numpy as np

from .._core.validate import check_positive, check_range
from ..kernels.special import erfinv
from ._checks import _check_load, _check_pbar, _check_psd, _check_zeta
from ._kernels import q_for_m3

__all__ = ["stiffness_G", "area_fraction", "percolation_pressure", "critical_magnification"]


def _stiffness(psd, E_star, zeta):
    """G(ζ) [Pa²] (A2) of validated inputs (E_star [Pa] and ζ [-] broadcast)."""
    m3 = psd.moment(3.0, psd.q0, np.asarray(zeta) * psd.q0)
    return 0.25 * math.pi * E_star ** 2 * np.asarray(m3)


def stiffness_G(psd, E_star, zeta):
    """Elastic energy factor G(ζ) = (π/4) E*² ∫_{q0}^{ζq0} q³ C(q) dq (A2).

    Parameters
    ----------
    psd : PSD
        Roughness spectrum (Persson convention).
    E_star : float or array_like
        Effective modulus E* [Pa], > 0.
    zeta : float or array_like
        Magnification ζ = q/q0 in [1, ζ1] [-].

    Returns
    -------
    ndarray
        G(ζ) [Pa²].
    """
    _check_psd(psd)
    E_star = check_positive("E_star", E_star, "[Pa]")
    return _stiffness(psd, E_star, _check_zeta(psd, zeta))


def area_fraction(psd, p, E_star, zeta=None):
    """Apparent relative contact area A(ζ)/A0 = erf(p / (2√G(ζ))) [-] (A1).

    Parameters
    ----------
    psd : PSD
        Surface roughness spectrum.
    p : array_like
        Nominal contact pressure [Pa], > 0.
    E_star : float
        Effective modulus [Pa], > 0.
    zeta : array_like, optional
        Magnification in [1, ζ1]; None = ζ1 (the true contact area).

    Returns
    -------
    ndarray
        A(ζ)/A0 [-], in [0, 1].
    """
    p, E_star = _check_load(psd, p, E_star)
    zeta = psd.zeta1 if zeta is None else _check_zeta(psd, zeta)
    G = _stiffness(psd, E_star, zeta)
    with np.errstate(divide="ignore"):
        x = p / (2.0 * np.sqrt(G))
    from scipy.special import erf   # here: importing fastcontact needs no scipy.special
    return erf(x)


def percolation_pressure(psd, E_star, a_perc=0.5):
    """Nominal pressure [Pa] at which A(ζ1)/A0 = a_perc: the contact percolates (inverse of A1).

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    E_star : float or array_like
        Effective modulus [Pa], > 0.
    a_perc : float
        Percolation threshold A(ζ1)/A0 in (0, 1) [-] (default 0.5).

    Returns
    -------
    ndarray
        ``2 √G(ζ1) erfinv(a_perc)`` [Pa].
    """
    _check_psd(psd)
    E_star = check_positive("E_star", E_star, "[Pa]")
    a_perc = check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True)
    G1 = 0.25 * math.pi * E_star ** 2 * psd.cum3[-1]
    from scipy.special import erfinv as sp_erfinv
    return 2.0 * np.sqrt(G1) * sp_erfinv(a_perc)


def critical_magnification(psd, p, E_star, a_perc=0.5):
    """ζc, the smallest magnification with A(ζc)/A0 = a_perc [-] (critical junction, Sec. 3).

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    p : array_like
        Nominal contact pressure [Pa], > 0, with p/E* >= 1e-150.
    E_star : float or array_like
        Effective modulus [Pa], > 0.
    a_perc : float
        Percolation threshold in (0, 1) [-] (default 0.5).

    Returns
    -------
    ndarray
        ζc [-]; ``inf`` where A(ζ1)/A0 >= a_perc (the contact has percolated, no open channel).
    """
    p, E_star = _check_load(psd, p, E_star)
    a_perc = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    pb, Eb = np.broadcast_arrays(p, E_star)
    pbar = _check_pbar((pb / Eb).ravel())
    x = float(erfinv(a_perc))
    target = 4.0 / math.pi * (pbar / (2.0 * x)) ** 2
    qb, c, e, cum3 = psd.kernel_arrays()
    out = np.array([q_for_m3(qb, c, e, cum3, t) / psd.q0 if t < cum3[-1] else math.inf
                    for t in target])
    return out.reshape(pb.shape)
