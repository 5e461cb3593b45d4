"""Special functions for the numba kernels: E1, the Yang–Persson K(s0), erfinv.

All kernels are ``@njit(cache=True)`` and compile on first use, never at import.

- :func:`e1` — exponential integral E1(x), series for x <= 1, Lentz continued fraction
  above; relative error <= 2e-14 against ``scipy.special.exp1`` on 1e-14 <= x <= 700.
- :func:`k_table` / :func:`k_eval` — K(s0) = ∫_{s0}^∞ erf²(s) e^{-s²} ds / s (the
  Yang–Persson correction, doi:10.1088/0953-8984/20/21/215214), a cubic Hermite table in ln s0 with exact derivatives
  dK/d(ln s0) = -erf²(s0) e^{-s0²}, with the series below the table and
  E1(s0²)/2 above it; K(0) = 0.4071249346.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
import scipy.special as sp
from numba import njit
from scipy.integrate import quad

from .hermite import cubic_uniform
from .quadrature import gauss_legendre

__all__ = ["EULER_GAMMA", "K_ZERO", "KTable", "e1", "e1_and_exp", "erfinv", "k_eval", "k_table"]

EULER_GAMMA = 0.57721566490153286061

# K(s0) is tabulated directly for t = ln s0 in [_K_TMIN, 0] and as the ratio
# ρ = 2K/E1(s0²) (smooth, -> 1) for t in [0, _R_TMAX]; beyond, K = E1(s0²)/2 (erfc(20) ~ 1e-176).
_K_TMIN = -9.0
_K_N = 1801
_R_TMAX = math.log(20.0)
_R_N = 1201


@njit(cache=True)
def e1_and_exp(x):
    """(E1(x), e^{-x}) for x > 0, sharing the exponential of the continued fraction."""
    if x <= 0.0:
        return math.inf, 1.0
    if x <= 1.0:
        s = 0.0
        term = 1.0
        k = 1
        while True:
            term *= -x / k
            d = term / k
            s += d
            if abs(d) < 1e-17 * abs(s) + 1e-300:
                break
            k += 1
        return -EULER_GAMMA - math.log(x) - s, math.exp(-x)
    if x > 745.0:
        return 0.0, 0.0
    b = x + 1.0
    c = 1e300
    d = 1.0 / b
    h = d
    i = 1
    while True:
        an = -float(i * i)
        b += 2.0
        d = 1.0 / (an * d + b)
        c = b + an / c
        de = c * d
        h *= de
        if abs(de - 1.0) < 1e-16:
            break
        i += 1
    ex = math.exp(-x)
    return h * ex, ex


@njit(cache=True)
def e1(x):
    """Exponential integral E1(x) for x > 0 (inf at 0, 0 beyond x = 745)."""
    return e1_and_exp(x)[0]


class KTable(NamedTuple):
    """The K(s0) Hermite tables: direct K on t = ln s0 in [tmin, 0], ratio ρ = 2K/E1(s0²) above."""

    tmin: float
    dt: float
    kval: np.ndarray
    kder: np.ndarray
    dtr: float
    rval: np.ndarray
    rder: np.ndarray


@lru_cache(maxsize=1)
def k_table() -> KTable:
    """(tmin, dt, K, dK/dt, dt_r, ρ, dρ/dt) of the K(s0) Hermite tables (built once, ~ms)."""
    gl_x, gl_w = gauss_legendre(12)
    # ---- ratio table on [0, _R_TMAX]
    tr = np.linspace(0.0, _R_TMAX, _R_N)
    dtr = tr[1] - tr[0]
    sr = np.exp(tr)
    # K at s = 20 from its definition by adaptive quadrature (erf² = 1 - 1e-176 there)
    k_top = quad(lambda x: sp.erf(x) ** 2 * math.exp(-x * x) / x, sr[-1], np.inf, epsabs=0.0,
                 epsrel=1e-13, limit=200)[0]
    kr = np.empty_like(tr)
    kr[-1] = k_top
    xs = 0.5 * (tr[1:] + tr[:-1])[:, None] + 0.5 * dtr * gl_x[None, :]
    ss = np.exp(xs)
    panel = 0.5 * dtr * np.sum(gl_w[None, :] * (sp.erf(ss) ** 2 * np.exp(-ss * ss)), axis=1)
    kr[:-1] = k_top + np.cumsum(panel[::-1])[::-1]
    dk_r = -sp.erf(sr) ** 2 * np.exp(-sr * sr)
    e1r = sp.exp1(sr * sr)
    rho = 2.0 * kr / e1r
    drho = (2.0 * dk_r + 2.0 * rho * np.exp(-sr * sr)) / e1r
    # ---- direct table on [_K_TMIN, 0]
    t = np.linspace(_K_TMIN, 0.0, _K_N)
    dt = t[1] - t[0]
    s = np.exp(t)
    kder = -sp.erf(s) ** 2 * np.exp(-s * s)
    xs = 0.5 * (t[1:] + t[:-1])[:, None] + 0.5 * dt * gl_x[None, :]
    ss = np.exp(xs)
    panel = 0.5 * dt * np.sum(gl_w[None, :] * (sp.erf(ss) ** 2 * np.exp(-ss * ss)), axis=1)
    kval = np.empty_like(t)
    kval[-1] = kr[0]
    kval[:-1] = kr[0] + np.cumsum(panel[::-1])[::-1]
    c = np.ascontiguousarray
    return KTable(float(t[0]), float(dt), c(kval), c(kder), float(dtr), c(rho), c(drho))


#: K(0) = ∫_0^∞ erf²(s) e^{-s²} ds/s, for tests and documentation
K_ZERO = 0.40712493463438924


#: old name of :func:`fastcontact.kernels.hermite.cubic_uniform`
hermite = cubic_uniform


@njit(cache=True)
def k_eval(s0, tmin, dt, kval, kder, dtr, rval, rder):
    """K(s0) = ∫_{s0}^∞ erf²(s) e^{-s²} ds/s from the tables of :func:`k_table`."""
    if s0 <= 0.0:
        smin = math.exp(tmin)
        return kval[0] + (2.0 / math.pi) * smin * smin - (5.0 / (3.0 * math.pi)) * smin ** 4
    t = math.log(s0)
    if t < tmin:
        # series: ∫_{s0}^{smin} erf² e^{-s²}/s ds = (2/π)(smin²-s0²) - (5/3π)(smin⁴-s0⁴) + O(s⁶)
        smin = math.exp(tmin)
        return (kval[0] + (2.0 / math.pi) * (smin * smin - s0 * s0)
                - (5.0 / (3.0 * math.pi)) * (smin ** 4 - s0 ** 4))
    if t <= 0.0:
        return cubic_uniform(t, tmin, dt, kval, kder)
    if t >= dtr * (rval.size - 1):
        return 0.5 * e1(s0 * s0)
    return 0.5 * e1(s0 * s0) * cubic_uniform(t, 0.0, dtr, rval, rder)


@njit(cache=True)
def erfinv(y):
    """Inverse error function on (-1, 1) by Newton iteration from Giles' approximation."""
    if y <= -1.0:
        return -math.inf
    if y >= 1.0:
        return math.inf
    w = -math.log((1.0 - y) * (1.0 + y))
    if w < 5.0:
        w -= 2.5
        p = 2.81022636e-08
        p = 3.43273939e-07 + p * w
        p = -3.5233877e-06 + p * w
        p = -4.39150654e-06 + p * w
        p = 0.00021858087 + p * w
        p = -0.00125372503 + p * w
        p = -0.00417768164 + p * w
        p = 0.246640727 + p * w
        p = 1.50140941 + p * w
    else:
        w = math.sqrt(w) - 3.0
        p = -0.000200214257
        p = 0.000100950558 + p * w
        p = 0.00134934322 + p * w
        p = -0.00367342844 + p * w
        p = 0.00573950773 + p * w
        p = -0.0076224613 + p * w
        p = 0.00943887047 + p * w
        p = 1.00167406 + p * w
        p = 2.83297682 + p * w
    x = p * y
    if abs(y) <= 0.5:
        for _ in range(4):
            x -= (math.erf(x) - y) / (2.0 / math.sqrt(math.pi) * math.exp(-x * x))
        return x
    # tails: Newton on ln erfc(|x|) = ln(1 - |y|), well conditioned up to |y| -> 1
    sgn = 1.0 if y > 0 else -1.0
    ax = abs(x)
    target = math.log(1.0 - abs(y))
    for _ in range(60):
        ec = math.erfc(ax)
        f = math.log(ec) - target
        dfdx = -2.0 / math.sqrt(math.pi) * math.exp(-ax * ax) / ec
        step = f / dfdx
        ax -= step
        if abs(step) < 1e-15 * ax:
            break
    return sgn * ax
