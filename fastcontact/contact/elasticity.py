"""Elastic moduli: the effective modulus E* of one or two elastic solids."""
from __future__ import annotations

import numpy as np

from .._core.validate import check_positive, check_range

__all__ = ["effective_modulus"]


def effective_modulus(E, nu, E2=None, nu2=None):
    """Effective modulus E* [Pa].

    One elastic solid on a rigid rough substrate (the paper): ``E* = E/(1-ν²)``.
    Two elastic solids [literature]: ``1/E* = (1-ν1²)/E1 + (1-ν2²)/E2``.

    Parameters
    ----------
    E : float or array    Young's modulus of the (first) solid [Pa], > 0
    nu : float or array   its Poisson ratio [-], in [0, 0.5]
    E2, nu2 : optional    the second solid's modulus [Pa] and Poisson ratio [-]
    """
    E = check_positive("E", E, "[Pa]")
    nu = check_range("nu", nu, 0.0, 0.5, "[-]")
    if E2 is None and nu2 is None:
        out = E / (1.0 - nu ** 2)
    else:
        if E2 is None or nu2 is None:
            raise ValueError(f"E2 = {E2!r}, nu2 = {nu2!r} is invalid: give both the second solid's "
                             f"modulus E2 [Pa] and Poisson ratio nu2 [-], or neither")
        E2 = check_positive("E2", E2, "[Pa]")
        nu2 = check_range("nu2", nu2, 0.0, 0.5, "[-]")
        out = 1.0 / ((1.0 - nu ** 2) / E + (1.0 - nu2 ** 2) / E2)
    return out if np.ndim(out) else float(out)
