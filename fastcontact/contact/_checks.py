"""Validation shared by the contact-mechanics wrappers (messages name parameter, value, range)."""
from __future__ import annotations

from .._core.validate import check_range
from ..surface.psd import PSD
from ._kernels import psd_kernel

__all__ = ["_check_psd", "_check_gamma", "_check_zeta", "_arrays"]


def _check_psd(psd):
    """``psd`` itself if it is a fastcontact PSD, else ValueError."""
    if not isinstance(psd, PSD):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object "
                         f"(SelfAffinePSD, TabulatedPSD, read_psd(...), psd_from_heights(...))")
    return psd


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
