"""The reduced pressure of a Roelands fluid, ψ(π) = ∫_0^π η0/η(π') dπ', and its inverse
(private; the soft-seal solver's O-ring with a Roelands fluid, :mod:`._panels`).

With η(p) the flux through a seal is constant in ψ, not in the fluid pressure (docs/theory/
extensions.md §2): for Barus ψ has the closed form (1 - e^{-α̃π})/α̃ and its inverse
-ln(1 - α̃ψ)/α̃. For Roelands, ln(η/η0) = A[(1 + π/π_r)^Z - 1] (C.J.A. Roelands, PhD thesis,
TU Delft (1966); B.J. Hamrock and D. Dowson, Ball Bearing Lubrication, Wiley (1981), eq. 4.5),
ψ is an incomplete gamma function with no closed-form inverse, so a solve tabulates it once:
in u = ln(1 + π/π_r) (π = π_r(e^u - 1)) the integrand

    dψ/du = g(u) = π_r exp(u - A(e^{Zu} - 1)),   d²ψ/du² = g(u)(1 - A Z e^{Zu}),

is an entire function; the table holds ψ, g and dg/du at nodes of width h <= PSI_CELL (and
<= PSI_STEEP/(1 + A Z e^{Z u_max}) where the law is steep), ψ by 8-point Gauss–Legendre per
cell, and ψ between nodes is their quintic Hermite interpolant. The table reaches PSI_REACH
times the pressure drop; beyond it ψ continues linearly with its end slope, below π = 0 as
ψ = π (η = η0 below the outlet pressure). The inverse π(ψ) is Newton with the exact
dψ/dπ = η0/η: ψ is concave, so from π = ψ (<= the root, since η >= η0) the iterates rise
monotonically to the root.

All pressures are reduced by E* (π = p/E*, π_r = p_r/E*, ψ in the same units).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from ..kernels.borrow import borrowed
from ..kernels.hermite import quintic_unit
from ..kernels.quadrature import gauss_legendre

__all__ = ["PsiTable", "psi_table", "no_psi_table", "psi_of", "psi_eta", "fluid_of", "psi_drops",
           "one_table_fits", "psi_drops_one_law", "PSI_CELL", "PSI_STEEP", "PSI_REACH"]

#: a table of ψ(π): the law (A, Z, π_r), the node width h in u = ln(1 + π/π_r), the values
#: y = ψ, g = dψ/du and s = d²ψ/du² at the nodes u_k = k h (size 0: no Roelands fluid)
PsiTable = namedtuple("PsiTable", "A Z pr h y g s")
#: largest node width in u
PSI_CELL = 0.01
#: node width where the law is steep: h <= PSI_STEEP/(1 + A Z e^{Z u_max}) (the scale on which
#: g changes is 1/(A Z e^{Zu}))
PSI_STEEP = 0.1
#: the table covers π up to PSI_REACH × the pressure drop (Newton's trial states overshoot)
PSI_REACH = 1.5
#: most nodes of one table
PSI_MAX_NODES = 20000
_GLX, _GLW = gauss_legendre(8)


@njit(cache=True)
def _g(u, A, Z, pr):
    """dψ/du at u = ln(1 + π/π_r)."""
    return pr * math.exp(u - A * math.expm1(Z * u))


@njit(cache=True)
def _nodes_wanted(A, Z, pr, dpi):
    """(u_max, cells) a table reaching PSI_REACH·dpi needs for its node width (before the
    PSI_MAX_NODES cap)."""
    umax = math.log1p(PSI_REACH * max(dpi, 0.0) / pr)
    steep = PSI_STEEP / (1.0 + A * Z * math.exp(Z * umax))
    return umax, max(1, int(math.ceil(umax / min(PSI_CELL, steep))))


@njit(cache=True)
def psi_table(A, Z, pr, dpi):
    """The :data:`PsiTable` of the law (A, Z, π_r) for fluid pressures 0 .. PSI_REACH·dpi
    above the outlet (reduced)."""
    umax, n = _nodes_wanted(A, Z, pr, dpi)
    n = min(PSI_MAX_NODES, n)
    h = umax / n if umax > 0.0 else 1.0
    y = np.empty(n + 1)
    g = np.empty(n + 1)
    s = np.empty(n + 1)
    y[0] = 0.0
    for k in range(n + 1):
        u = k * h
        gk = _g(u, A, Z, pr)
        g[k] = gk
        s[k] = gk * (1.0 - A * Z * math.exp(Z * u))
        if k < n:
            acc = 0.0
            for j in range(_GLX.size):
                acc += _GLW[j] * _g(u + 0.5 * h * (_GLX[j] + 1.0), A, Z, pr)
            y[k + 1] = y[k] + 0.5 * h * acc
    return PsiTable(A, Z, pr, h, y, g, s)


@njit(cache=True)
def no_psi_table():
    """An empty :data:`PsiTable` (no Roelands fluid)."""
    e = np.empty(0)
    return PsiTable(0.0, 0.0, 1.0, 1.0, e, e, e)


@njit(cache=True, inline="always")
def _psi_at(rt, pi, u):
    """ψ at π > 0 with u = ln(1 + π/π_r) given."""
    n = rt.y.size - 1
    t = u / rt.h
    k = int(t)
    if k >= n:
        u_end = n * rt.h
        pi_end = rt.pr * math.expm1(u_end)
        return rt.y[n] + (pi - pi_end) * rt.g[n] / (rt.pr * math.exp(u_end))
    return quintic_unit(t - k, rt.h, rt.y[k], rt.g[k], rt.s[k], rt.y[k + 1], rt.g[k + 1],
                        rt.s[k + 1])[0]


@njit(cache=True)
def psi_of(rt, pi):
    """ψ(π) [reduced] from the table ``rt`` (quintic Hermite in u; linear beyond its end)."""
    if pi <= 0.0:
        return pi
    return _psi_at(rt, pi, math.log1p(pi / rt.pr))


@njit(cache=True, inline="always")
def psi_eta(rt, pi):
    """(ψ(π), η/η0 at π): :func:`psi_of` and the law's η/η0 (ln η/η0 = A[(1 + π/π_r)^Z - 1],
    as :func:`fastcontact.flow.piezoviscosity.ln_roelands`) sharing u = ln(1 + π/π_r)."""
    if pi <= 0.0:
        return pi, 1.0
    u = math.log1p(pi / rt.pr)
    return _psi_at(rt, pi, u), math.exp(rt.A * math.expm1(rt.Z * u))


@njit(cache=True)
def fluid_of(rt, psi):
    """π(ψ): the fluid pressure above the outlet whose ψ is ``psi`` (Newton, module
    docstring; to a step of 1e-15 π)."""
    if psi <= 0.0:
        return psi
    rt = borrowed(rt)  # psi_eta inline: no reference counts per iteration
    n = rt.y.size - 1
    if psi >= rt.y[n]:  # beyond the table: its linear continuation
        u_end = n * rt.h
        slope = rt.g[n] / (rt.pr * math.exp(u_end))
        pi_end = rt.pr * math.expm1(u_end)
        return pi_end + (psi - rt.y[n]) / slope if slope > 0.0 else pi_end
    pi = psi
    for _ in range(200):
        ps, er = psi_eta(rt, pi)
        step = (ps - psi) * er
        pi -= step
        if abs(step) <= 1e-15 * pi:
            break
    return pi


@njit(cache=True)
def psi_drops(A, Z, pr, dpi, out):
    """ψ(Δπ) per row (the laws A, Z, π_r and drops Δπ, reduced) into ``out``, from the same
    table the solver builds for the row."""
    for i in range(dpi.size):
        out[i] = psi_of(psi_table(A[i], Z[i], pr[i], dpi[i]), dpi[i])


@njit(cache=True)
def one_table_fits(A, Z, pr, dpi_max):
    """Whether one table of the law (A, Z, π_r) reaching the largest drop ``dpi_max`` keeps
    the node width every smaller drop's own table would have (it needs no more than
    PSI_MAX_NODES nodes: the width bound min(PSI_CELL, PSI_STEEP/(1 + A Z e^{Z u_max}))
    only tightens as u_max grows)."""
    return _nodes_wanted(A, Z, pr, dpi_max)[1] <= PSI_MAX_NODES


@njit(cache=True)
def _psi_of_parts(A, Z, pr, h, y, g, s, pi):
    """:func:`psi_of` of the table given by its fields (a parallel loop cannot name the
    namedtuple itself)."""
    return psi_of(PsiTable(A, Z, pr, h, y, g, s), pi)


@njit(cache=True, parallel=True)
def _read_one_table(A, Z, pr, h, y, g, s, dpi, out):
    for i in prange(dpi.size):
        out[i] = _psi_of_parts(A, Z, pr, h, y, g, s, dpi[i])


@njit(cache=True)
def psi_drops_one_law(A, Z, pr, dpi, out):
    """ψ(Δπ) of rows sharing one law (A, Z, π_r; scalars, reduced) into ``out``: one table
    reaching the largest drop (node width no larger than each row's own table's bound; the
    same quintic Hermite), read in parallel, where :func:`one_table_fits`; else each row's
    own table (:func:`psi_drops`)."""
    top = 0.0
    for i in range(dpi.size):
        top = max(top, dpi[i])
    if not one_table_fits(A, Z, pr, top):
        for i in range(dpi.size):
            out[i] = psi_of(psi_table(A, Z, pr, dpi[i]), dpi[i])
        return
    rt = psi_table(A, Z, pr, top)
    _read_one_table(rt.A, rt.Z, rt.pr, rt.h, rt.y, rt.g, rt.s, dpi, out)
