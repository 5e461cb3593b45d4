"""Quadrature rules and closed-form power-law moments, defined once for the whole package.

- :func:`gauss_legendre` — the only source of Gauss–Legendre nodes (cached per order).
- :func:`gauss_lobatto` — Gauss–Lobatto nodes (panel ends included).
- :func:`gauss_kronrod15` — the 7/15-point Gauss–Kronrod pair (adaptive integrals).
- :func:`gauss_hermite` — Gauss–Hermite nodes (Gaussian averages).
- :func:`seg_moment` / :func:`seg_moment_np` — ∫ q^n c (q/q_s)^e dq over one power-law
  segment of a spectrum, cancellation-free for short intervals (numba kernel and NumPy twin).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .powerlaw import seg_moment_np
from .rules import GL_ORDER, QuadRule, gauss_hermite, gauss_legendre, gauss_lobatto

__all__ = ["QuadRule", "gauss_legendre", "gauss_lobatto", "gauss_kronrod15", "gauss_hermite", "seg_moment",
           "seg_moment_constants", "seg_moment_at", "seg_moment_np", "GL_ORDER"]

_XGK = np.array([-0.991455371120812639206854697526329, -0.949107912342758524526189684047851,
                 -0.864864423359769072789712788640926, -0.741531185599394439863864773280788,
                 -0.586087235467691130294144845693013, -0.405845151377397166906606412076961,
                 -0.207784955007898467600689403773245, 0.0,
                 0.207784955007898467600689403773245, 0.405845151377397166906606412076961,
                 0.586087235467691130294144845693013, 0.741531185599394439863864773280788,
                 0.864864423359769072789712788640926, 0.949107912342758524526189684047851,
                 0.991455371120812639206854697526329])
_WGK = np.array([0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                 0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                 0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                 0.204432940075298892414161999234649, 0.209482141084727828012999174891714,
                 0.204432940075298892414161999234649, 0.190350578064785409913256402421014,
                 0.169004726639267902826583426598550, 0.140653259715525918745189590510238,
                 0.104790010322250183839876322541518, 0.063092092629978553290700663189204,
                 0.022935322010529224963732008058970])
_WG7 = np.array([0.0, 0.129484966168869693270611432679082, 0.0, 0.279705391489276667901467771423780,
                 0.0, 0.381830050505118944950369775488975, 0.0, 0.417959183673469387755102040816327,
                 0.0, 0.381830050505118944950369775488975, 0.0, 0.279705391489276667901467771423780,
                 0.0, 0.129484966168869693270611432679082, 0.0])


def gauss_kronrod15():
    """(x, w_kronrod, w_gauss7) of the 15-point Kronrod extension of 7-point Gauss–Legendre.

    ``w_gauss7`` is zero at the 8 Kronrod-only nodes, so both sums run over the same 15 nodes.
    Constants from QUADPACK (Piessens et al. 1983).
    """
    return _XGK, _WGK, _WG7


@njit(cache=True)
def seg_moment(ci, qs, ei, n, a, lr):
    """∫_a^{a e^{lr}} q^n ci (q/qs)^ei dq for one power-law segment, cancellation-free.

    Parameters
    ----------
    ci : float
        Spectrum value at the segment start ``qs`` [m⁴].
    qs : float
        Segment start [1/m].
    ei : float
        Power-law exponent of the segment [-].
    n : float
        Moment order [-].
    a : float
        Lower limit [1/m].
    lr : float
        ln(upper limit / a) [-]; ``expm1`` keeps the result exact for small ``lr``.
    """
    pref, k = seg_moment_constants(ci, qs, ei, n, a)
    return seg_moment_at(pref, k, lr)


@njit(cache=True, inline="always")
def seg_moment_constants(ci, qs, ei, n, a):
    """(pref, k) of :func:`seg_moment` for the lower limit ``a``: what stays fixed while only
    the upper limit moves (a quadrature's nodes inside one segment)."""
    return ci * (a / qs) ** ei * a ** (n + 1.0), n + ei + 1.0


@njit(cache=True, inline="always")
def seg_moment_at(pref, k, lr):
    """:func:`seg_moment` from its :func:`seg_moment_constants` and lr = ln(upper/a) [-]."""
    if abs(k) < 1e-12:
        return pref * lr
    return pref * math.expm1(k * lr) / k
