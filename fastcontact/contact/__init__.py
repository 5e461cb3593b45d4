"""Persson contact mechanics by direct quadrature — the accurate core (App. A of the paper).

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

References: B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010),
arXiv:1004.1037; B.N.J. Persson, J. Chem. Phys. 115, 3840 (2001),
doi:10.1063/1.1388626.
"""
from __future__ import annotations

# private checks re-exported for flow and tables
from ._checks import (PBAR_MIN, _arrays, _check_gamma, _check_load, _check_pbar,  # noqa: F401
                      _check_psd, _check_zeta)
from .area import area_fraction, critical_magnification, percolation_pressure, stiffness_G
from .elasticity import effective_modulus  # noqa: F401
from .separation import (_separation, asymptote, asymptote_self_affine,  # noqa: F401
                         contact_pressure, mean_separation, separation_slope, u1)

__all__ = ["area_fraction", "mean_separation", "u1", "critical_magnification",
           "contact_pressure", "asymptote", "asymptote_self_affine", "stiffness_G",
           "percolation_pressure", "separation_slope"]
