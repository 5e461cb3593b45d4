"""Input validation of the seal engine (private): one readable ValueError per bad input,
naming the parameter, its value and the valid range."""
from __future__ import annotations

import math

import numpy as np

from .._core.validate import as_float_array, check_positive, check_range
from ..flow.conductivity import check_theory
from ..tables import Tables

__all__ = ["check_tables", "check_theory_for", "alpha_scale", "profile_kind", "hertz_contact",
           "common_inputs", "forbid", "require", "scalar"]


def check_tables(tables):
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables object "
                         f"(fastcontact.precompute(...) or Tables.from_parquet(...))")
    return tables


def check_theory_for(tables, theory, alpha_cj, a_perc):
    check_theory(theory)
    tables._need(theory)
    if a_perc is not None:
        a = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
        have = float(tables.options.get("a_perc", 0.5))
        if theory == "critical_junction" and a != have:
            raise ValueError(f"a_perc = {a!r} is invalid for these tables: they were built with "
                             f"a_perc = {have!r} (rebuild with precompute(..., a_perc={a!r}))")
    return check_positive("alpha_cj", alpha_cj, "[-]")


def alpha_scale(sc, theory, alpha_cj):
    if theory != "critical_junction":
        return np.ones_like(alpha_cj)
    return (alpha_cj / sc.alpha_table) ** 3


def profile_kind(profile, x):
    if isinstance(profile, str):
        if profile not in ("uniform", "hertz"):
            raise ValueError(f"profile = {profile!r} is invalid: must be 'uniform', 'hertz' or an "
                             f"array of p0(x) [Pa] sampled at x")
        if x is not None:
            raise ValueError(f"x = array(...) is invalid with profile = {profile!r}: x gives the "
                             f"positions of an array profile only")
        return profile, None, None
    p = as_float_array("profile", profile, "[Pa]")
    if p.ndim != 1 or p.size < 2:
        raise ValueError(f"profile = array(shape={p.shape}) is invalid: must be 'uniform', 'hertz' "
                         f"or a 1-D array of at least 2 values of p0(x) [Pa]")
    check_positive("profile", p, "[Pa] (p0(x) samples)", allow_zero=True)
    if x is None:
        raise ValueError("x = None is invalid with an array profile: give the positions x [m] "
                         "of the p0(x) samples")
    xa = as_float_array("x", x, "[m]")
    if xa.shape != p.shape:
        raise ValueError(f"x = array(shape={xa.shape}) is invalid: must have the profile's shape "
                         f"{p.shape}")
    if not np.all(np.isfinite(xa)):
        raise ValueError("x = array(...) is invalid: must be finite [m]")
    if np.any(np.diff(xa) <= 0):
        i = int(np.argmax(np.diff(xa) <= 0)) + 1
        raise ValueError(f"x = {xa[i]!r} at index {i} is invalid: x must be strictly "
                         f"increasing [m]")
    return "array", p, xa


def hertz_contact(R, f_N, E_star):
    """Hertz line contact of a cylinder on a flat (the dry O-ring profile).

    Parameters
    ----------
    R : float or array_like
        Cylinder (O-ring cross-section) radius [m].
    f_N : float or array_like
        Load per unit length [N/m].
    E_star : float or array_like
        Effective modulus [Pa].

    Returns
    -------
    a : ndarray
        Contact half-width [m], a² = 4 f_N R/(π E*).
    p_H : ndarray
        Peak pressure [Pa], p_H = 2 f_N/(π a); p0(x) = p_H √(1 − (x/a)²).

    References
    ----------
    K.L. Johnson, Contact Mechanics (Cambridge University Press, 1985), Sec. 4.2,
    doi:10.1017/CBO9781139171731
    """
    R = check_positive("R", R, "[m]")
    f_N = check_positive("f_N", f_N, "[N/m]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    a = np.sqrt(4.0 * f_N * R / (math.pi * E_star))
    return a, 2.0 * f_N / (math.pi * a)


def common_inputs(dp, L_y, E_star, eta, p_b):
    return dict(dp=check_positive("dp", dp, "[Pa]", allow_zero=True),
                L_y=check_positive("L_y", L_y, "[m]"),
                E_star=check_positive("E_star", E_star, "[Pa]"),
                eta=check_positive("eta", eta, "[Pa·s]"),
                p_b=check_positive("p_b", p_b, "[Pa] (gauge)", allow_zero=True))


def forbid(kind, **given):
    for name, v in given.items():
        if v is not None:
            raise ValueError(f"{name} = {v!r} is invalid with profile = {kind!r}: "
                             + ("the Hertz profile derives p0(x) and L = 2a from R and f_N"
                                if kind == "hertz" else
                                "an array profile takes p0(x) from the array and L from x"))


def require(kind, **given):
    for name, v in given.items():
        if v is None:
            raise ValueError(f"{name} = None is invalid: profile = {kind!r} requires {name}")


def scalar(name, v):
    a = np.asarray(v, dtype=np.float64)
    if a.ndim != 0 and a.size != 1:
        raise ValueError(f"{name} = array(shape={a.shape}) is invalid: seal_profile takes one "
                         f"case (scalars); use seal_leak for many")
    return float(a.ravel()[0]) if a.ndim else float(a)
