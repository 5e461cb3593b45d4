"""Validation shared by the contact-mechanics wrappers (messages name parameter, value, range)."""
from __future__ import annotations

from .._core.validate import check_positive, check_range
from ..surface.psd import PSD
from ._kernels import psd_kernel

__all__ = ["_check_psd", "_check_load", "_check_gamma", "_check_zeta", "_arrays", "_check_pbar",
           "PBAR_MIN"]

#: smallest reduced pressure p/E* the direct quadrature accepts: below it G(ζ)/E*² ∝ (p/E*)²
#: underflows in float64 (ū ≈ 400 h_rms on a typical surface, far beyond any table)
PBAR_MIN = 1e-150


def _check_psd(psd):
    """``psd`` itself if it is a fastcontact PSD, else ValueError."""
    if not isinstance(psd, PSD):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object "
                         f"(SelfAffinePSD, TabulatedPSD, read_psd(...), psd_from_heights(...))")
    return psd


def _check_load(psd, p, E_star, p_name="p", p_unit="[Pa]"):
    """Validate a (psd, p, E_star) triple, in that order (the first bad one raises).

    Parameters
    ----------
    psd : PSD
        Roughness spectrum (a fastcontact PSD object).
    p : array_like
        Nominal contact pressure [Pa], > 0 (or the quantity named ``p_name``).
    E_star : float or array_like
        Effective modulus [Pa], > 0.
    p_name : str
        Name of ``p`` in the error message (default "p"; "u" for a separation).
    p_unit : str
        Unit of ``p`` in the error message (default "[Pa]").

    Returns
    -------
    (ndarray, ndarray)
        ``p`` and ``E_star`` as float arrays
        (see :func:`fastcontact._core.validate.check_positive`).
    """
    _check_psd(psd)
    return check_positive(p_name, p, p_unit), check_positive("E_star", E_star, "[Pa]")


def _check_pbar(pbar, p_name="p"):
    """ValueError naming ``p_name`` if a reduced pressure p/E* is below :data:`PBAR_MIN`."""
    low = pbar < PBAR_MIN
    if low.any():
        v = float(pbar[low][0])
        raise ValueError(f"{p_name}/E_star = {v!r} is invalid: the direct quadrature needs "
                         f"p/E_star >= {PBAR_MIN:g} (below it G(zeta)/E*^2 underflows)")
    return pbar


def _check_gamma(gamma):
    """The Yang–Persson factor γ in (0, 1] as a float."""
    return float(check_range("gamma", gamma, 0.0, 1.0, "[-] (Yang–Persson factor; 1 = paper)",
                             lo_open=True))


def _check_zeta(psd, zeta):
    """Magnifications ζ in [1, ζ1] as a float array."""
    return check_range("zeta", zeta, 1.0, psd.zeta1, "[-] (magnification, 1 to q1/q0)")


def _arrays(psd):
    """(qb, c, e, cum3, kinks): the :class:`~._kernels.PSDKernel` record of ``psd``."""
    return psd_kernel(psd)
