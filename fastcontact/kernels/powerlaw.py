"""Closed-form moments of one power-law segment of a spectrum, in NumPy (no numba import).

:func:`seg_moment_np` is the NumPy twin of the kernel :func:`fastcontact.kernels.quadrature.seg_moment`
(which re-exports it); :mod:`fastcontact.surface.psd` uses it on the import path that needs
no compiler.
"""
from __future__ import annotations

import numpy as np

__all__ = ["seg_moment_np"]


def seg_moment_np(c, qs, e, n, a, b):
    """∫_a^b q^n c (q/qs)^e dq [m^(n+5)] over one power-law segment, cancellation-free for
    b ≈ a: the NumPy twin of :func:`~fastcontact.kernels.quadrature.seg_moment` with limits
    ``a``, ``b`` [1/m] (broadcasts)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    k = n + e + 1.0
    lr = np.log(b / a)
    pref = c * (a / qs) ** e * a ** (n + 1.0)
    if abs(k) < 1e-12:
        return pref * lr
    return pref * np.expm1(k * lr) / k
