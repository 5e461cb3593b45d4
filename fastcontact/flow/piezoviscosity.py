"""Pressure-dependent viscosity laws η(p) of the extensions (issue 14): Barus and Roelands.

p is the fluid pressure above the outlet (ambient) pressure and η0 = η(0) the viscosity
there (the engines' ``eta``).

* **Barus** (C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87):
  ln(η/η0) = α p, α = ``alpha_pv`` [1/Pa].
* **Roelands** (C.J.A. Roelands, *Correlational aspects of the viscosity–temperature–pressure
  relationship of lubricating oils*, PhD thesis, TU Delft (1966); the isothermal form of
  B.J. Hamrock and D. Dowson, *Ball Bearing Lubrication*, Wiley (1981), eq. 4.5):
  ln(η/η0) = A [(1 + p/p_r)^Z − 1],  A = ln(η0/η_∞),
  with p_r = 1/(5.1·10⁻⁹ Pa⁻¹) ≈ 1.96·10⁸ Pa and η_∞ = e^{−9.67} Pa·s ≈ 6.3·10⁻⁵ Pa·s
  (the constants of Hamrock & Dowson's eq. 4.5, reproduced exactly by default), Z the
  pressure–viscosity index (0.5–0.7 for mineral oils). Its initial slope is
  α_0 = d ln η/dp|₀ = A Z/p_r, so ``roelands_z`` may be given through α: Z = α p_r/A
  (the same oil at low pressure as the Barus law with that α). For Z < 1 it grows slower
  than Barus at high pressure.

For the Barus law the Reynolds flows here reduce exactly through the reduced pressure
ψ = (1 − e^{−αp})/α (docs/theory/extensions.md §2). For Roelands ψ(p) = ∫_0^p η0/η dp′ is an
incomplete gamma function without a closed-form inverse p(ψ), so the engines that need p(ψ)
(the Hertz O-ring, whose σ0 depends on p_f) integrate the Reynolds equation in p_f directly.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._core.validate import check_positive

__all__ = ["VISCOSITY_LAWS", "ROELANDS_P_R", "ROELANDS_ETA_INF", "roelands_parameters",
           "viscosity_ratio", "check_law"]

VISCOSITY_LAWS = ("barus", "roelands")
#: Roelands' reference pressure p_r [Pa] and limiting viscosity η_∞ [Pa·s]: the constants
#: 5.1e-9 1/Pa and 9.67 of Hamrock & Dowson's eq. 4.5 (p_r ≈ 1.96e8 Pa, η_∞ ≈ 6.3e-5 Pa·s)
ROELANDS_P_R = 1.0 / 5.1e-9
ROELANDS_ETA_INF = math.exp(-9.67)


def check_law(viscosity):
    """``viscosity`` as one of :data:`VISCOSITY_LAWS`, else ValueError naming it."""
    if viscosity not in VISCOSITY_LAWS:
        raise ValueError(f"viscosity = {viscosity!r} is invalid: must be one of "
                         f"{list(VISCOSITY_LAWS)}")
    return viscosity


def roelands_parameters(eta, alpha_pv=0.0, roelands_z=None, p_r=None, eta_inf=None):
    """(A, Z, p_r) arrays of the Roelands law for viscosities ``eta`` [Pa·s] at the outlet.

    Parameters
    ----------
    eta : array_like
        η0 [Pa·s], > ``eta_inf``.
    alpha_pv : array_like
        Initial pressure–viscosity coefficient α0 [1/Pa] >= 0; sets Z = α0 p_r / A when
        ``roelands_z`` is None.
    roelands_z : array_like or None
        Pressure–viscosity index Z [-], >= 0.
    p_r : float or None
        Reference pressure [Pa], > 0 (None: :data:`ROELANDS_P_R`).
    eta_inf : float or None
        Limiting viscosity η_∞ [Pa·s], > 0 (None: :data:`ROELANDS_ETA_INF`).

    Returns
    -------
    (A [-], Z [-], p_r [Pa]) broadcast arrays.
    """
    eta = check_positive("eta", eta, "[Pa·s]")
    p_r = ROELANDS_P_R if p_r is None else float(check_positive("roelands_p_r", p_r, "[Pa]"))
    eta_inf = ROELANDS_ETA_INF if eta_inf is None else float(
        check_positive("roelands_eta_inf", eta_inf, "[Pa·s]"))
    if np.any(eta <= eta_inf):
        bad = float(np.ravel(eta)[np.ravel(eta) <= eta_inf][0])
        raise ValueError(f"eta = {bad!r} is invalid for the Roelands law: must be > "
                         f"roelands_eta_inf = {eta_inf!r} [Pa·s]")
    A = np.log(eta / eta_inf)
    if roelands_z is None:
        a = check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True)
        Z = a * p_r / A
    else:
        Z = check_positive("roelands_z", roelands_z, "[-]", allow_zero=True, allow_inf=False)
    A, Z = np.broadcast_arrays(A, Z)
    return A, Z, p_r


@njit(cache=True)
def ln_roelands(p, A, Z, p_r):
    """ln(η/η0) = A [(1 + p/p_r)^Z − 1] at p >= 0 above the outlet (expm1/log1p form)."""
    return A * math.expm1(Z * math.log1p(p / p_r))


def viscosity_ratio(p, viscosity="barus", *, alpha_pv=0.0, eta=None, roelands_z=None,
                    p_r=None, eta_inf=None):
    """η(p)/η0 [-] of a law at pressures p [Pa] above the outlet (module docstring)."""
    check_law(viscosity)
    p = check_positive("p", p, "[Pa]", allow_zero=True)
    if viscosity == "barus":
        a = check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True)
        return np.exp(a * p)
    if eta is None:
        raise ValueError("eta = None is invalid for the Roelands law: give η0 [Pa·s]")
    A, Z, pr = roelands_parameters(eta, alpha_pv, roelands_z, p_r, eta_inf)
    return np.exp(A * np.expm1(Z * np.log1p(p / pr)))
