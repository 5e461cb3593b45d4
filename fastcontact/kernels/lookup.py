"""Table-lookup kernels on plain data: ū(p̄), p̄(ū) and σ̄(p̄) of one theory's tables.

:class:`TableKernel` is the flat record :meth:`fastcontact.tables.Tables.kernel_data` builds
for one theory; it passes into ``@njit`` and ``prange`` kernels as it is. Its field order is
fixed (it is also a tuple: ``tab[7]`` is ``tab.bp_lo``), so positional readers keep working.

Interpolation is quintic Hermite in ln p̄ of ln ū (and of the inverse ln p̄(ln ū)) and of
ln σ̄, with exact first and second derivatives stored at the nodes; in the interval holding a
theory's percolation pressure σ̄^(1/3) falls linearly in ln p̄ to 0. Outside the table every
kernel returns NaN (or a flag); nothing is extrapolated.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .hermite import quintic_interval
from .locate import locate_asc, locate_desc

__all__ = ["TableKernel", "k_lnu_of_lnp", "k_lnp_of_lnu", "lnp_on_interval", "k_sigma_of_lnp",
           "k_state_of_lnu", "eval_u", "eval_p", "eval_sigma"]


class TableKernel(NamedTuple):
    """One theory's table as plain arrays and scalars (all dimensionless).

    Attributes
    ----------
    lnp : ndarray
        ln p̄ = ln(p_cont/E*) at the nodes, increasing.
    lnu : ndarray
        ln(ū/h_rms) at the nodes, decreasing.
    dlnu : ndarray
        d ln ū / d ln p̄ (exact, from the quadrature of (A4)).
    lnsig : ndarray
        ln σ̄ (σ̄ = 12ησ_eff/h_rms³, eq. 23); -inf where σ̄ = 0.
    dlnsig : ndarray
        d ln σ̄ / d ln p̄ (0 where σ̄ = 0).
    lnp_perc : float
        ln of the exact percolation pressure p̄_c (inf: the theory never percolates).
    n_open : int
        Number of leading nodes with σ̄ > 0.
    bp_lo, bp_dz, bp_idx : float, float, ndarray
        O(1) bucket locator over ln p̄ (:func:`fastcontact.kernels.locate.build_bucket_map`).
    bu_lo, bu_dz, bu_idx : float, float, ndarray
        O(1) bucket locator over -ln ū.
    d2lnu : ndarray
        d² ln ū / d(ln p̄)² (exact).
    d2lnsig : ndarray
        d² ln σ̄ / d(ln p̄)².
    """

    lnp: np.ndarray
    lnu: np.ndarray
    dlnu: np.ndarray
    lnsig: np.ndarray
    dlnsig: np.ndarray
    lnp_perc: float
    n_open: int
    bp_lo: float
    bp_dz: float
    bp_idx: np.ndarray
    bu_lo: float
    bu_dz: float
    bu_idx: np.ndarray
    d2lnu: np.ndarray
    d2lnsig: np.ndarray


@njit(cache=True)
def k_lnu_of_lnp(tab, lnp_q):
    """ln(ū/h_rms) at ln p̄ (quintic Hermite); NaN outside the table."""
    lnp, lnu, dlnu, d2 = tab.lnp, tab.lnu, tab.dlnu, tab.d2lnu
    i = locate_asc(lnp_q, lnp, tab.bp_lo, tab.bp_dz, tab.bp_idx)
    if i < 0:
        return math.nan
    return quintic_interval(lnp_q, lnp[i], lnp[i + 1], lnu[i], lnu[i + 1], dlnu[i], dlnu[i + 1],
                            d2[i], d2[i + 1])


@njit(cache=True)
def k_lnp_of_lnu(tab, lnu_q):
    """ln p̄ at ln(ū/h_rms) (inverse; quintic Hermite in ln ū); NaN outside the table."""
    i = locate_desc(lnu_q, tab.lnu, tab.bu_lo, tab.bu_dz, tab.bu_idx)
    if i < 0:
        return math.nan
    return lnp_on_interval(tab.lnp, tab.lnu, tab.dlnu, tab.d2lnu, i, lnu_q)


@njit(cache=True, inline="always")
def lnp_on_interval(lnp, lnu, a, d2, i, lnu_q):
    """:func:`k_lnp_of_lnu` on its interval i (``locate_desc``) from the record's arrays
    (a = d ln ū/d ln p̄ and d2 its derivative at the nodes), for a loop that takes them out
    of the record once: a call that passes the whole record (15 fields) by value cost ~80 ns a
    lookup, measured on one thread (the lookup itself ~70 ns)."""
    return quintic_interval(lnu_q, lnu[i], lnu[i + 1], lnp[i], lnp[i + 1], 1.0 / a[i],
                            1.0 / a[i + 1], -d2[i] / a[i] ** 3, -d2[i + 1] / a[i + 1] ** 3)


@njit(cache=True, inline="always")
def sigma_interval_resolved(x0, x1, y0, y1, m0, m1):
    """Whether ln σ̄'s quintic on the open interval [x0, x1] of ln p̄ (node values y0, y1 and
    slopes m0, m1 of ln σ̄) is trusted: both end slopes times the width have the sign of
    Δ ln σ̄ and at most 3 times its size (Fritsch–Carlson); else the interval is unresolved
    and ln σ̄ is linear across it (:func:`sigma_linear`)."""
    h = x1 - x0
    dy = y1 - y0
    s0, s1 = m0 * h, m1 * h
    return s0 * dy >= 0.0 and s1 * dy >= 0.0 and abs(s0) <= 3.0 * abs(dy) \
        and abs(s1) <= 3.0 * abs(dy)


@njit(cache=True, inline="always")
def sigma_linear(t, x0, x1, y0, y1):
    """ln σ̄ at ln p̄ = t, linear between the nodes of an unresolved interval."""
    return y0 + (y1 - y0) / (x1 - x0) * (t - x0)


@njit(cache=True)
def k_sigma_of_lnp(tab, lnp_q):
    """σ̄ = 12ησ_eff/h_rms³ at ln p̄; exactly 0 at and beyond percolation; NaN outside.

    Quintic Hermite of ln σ̄ between open nodes; between the last open node and the exact
    percolation pressure σ̄^(1/3) falls linearly in ln p̄ to 0 (σ̄ < 1e-30 there). ln σ̄ is
    monotone in ln p̄: where the quintic could leave the range of its interval's node values
    (an interval the build could not resolve, next to percolation, where σ̄ drops by tens of
    decades, e.g. 1e-23 → 1e-90, below the tables' σ̄ floor; a resolved interval never does),
    ln σ̄ is interpolated linearly between the nodes instead of overshooting (σ̄ up to inf).
    The test is on the interval's data (Fritsch–Carlson: both end slopes h·(d ln σ̄/d ln p̄)
    of the sign of Δ ln σ̄ and at most 3|Δ ln σ̄|; resolved intervals have ratios 0.94–1.06),
    so an interval is interpolated one way throughout.
    """
    lnp, lnsig, dlnsig, lnp_perc, n_open = tab.lnp, tab.lnsig, tab.dlnsig, tab.lnp_perc, tab.n_open
    i = locate_asc(lnp_q, lnp, tab.bp_lo, tab.bp_dz, tab.bp_idx)
    if i < 0:
        return math.nan
    if lnp_q >= lnp_perc:
        return 0.0
    if i + 1 < n_open:
        d2 = tab.d2lnsig
        y0, y1 = lnsig[i], lnsig[i + 1]
        if sigma_interval_resolved(lnp[i], lnp[i + 1], y0, y1, dlnsig[i], dlnsig[i + 1]):
            return math.exp(quintic_interval(lnp_q, lnp[i], lnp[i + 1], y0, y1, dlnsig[i],
                                             dlnsig[i + 1], d2[i], d2[i + 1]))
        return math.exp(sigma_linear(lnp_q, lnp[i], lnp[i + 1], y0, y1))
    j = n_open - 1
    if j < 0 or lnp_perc == math.inf:
        return 0.0
    cr = math.exp(lnsig[j] / 3.0) * (lnp_perc - lnp_q) / (lnp_perc - lnp[j])
    return cr * cr * cr


@njit(cache=True)
def k_state_of_lnu(tab, lnu_q):
    """(p̄, σ̄, flag) at ln(ū/h_rms): flag 0 inside the table, 1 outside (values NaN)."""
    lnp = k_lnp_of_lnu(tab, lnu_q)
    if lnp != lnp:
        return math.nan, math.nan, 1
    return math.exp(lnp), k_sigma_of_lnp(tab, lnp), 0


@njit(cache=True)
def eval_u(tab, lnp, out):
    """out[i] = ū/h_rms at ln p̄ = lnp[i] (NaN outside the table)."""
    for i in range(lnp.size):
        out[i] = math.exp(k_lnu_of_lnp(tab, lnp[i]))


@njit(cache=True)
def eval_p(tab, lnuq, out):
    """out[i] = p̄ at ln(ū/h_rms) = lnuq[i] (NaN outside the table)."""
    for i in range(lnuq.size):
        out[i] = math.exp(k_lnp_of_lnu(tab, lnuq[i]))


@njit(cache=True)
def eval_sigma(tab, lnp, out):
    """out[i] = σ̄ at ln p̄ = lnp[i] (NaN outside the table)."""
    for i in range(lnp.size):
        out[i] = k_sigma_of_lnp(tab, lnp[i])
