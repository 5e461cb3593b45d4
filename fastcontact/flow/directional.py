"""Directional conductivities σ_xx, σ_yy of anisotropic roughness by direct quadrature.

The anisotropic 2-D Bruggeman medium on the u1-based P(u) of the angle-averaged spectrum
(:func:`directional_sigma_bar`), the checks of its options and the directional percolation
thresholds of the "fixed" form (:func:`directional_threshold`). The model (forms,
thresholds, the critical junction per direction) is described in
:mod:`fastcontact.flow.anisotropy`, which re-exports every name here and holds the SI
wrapper :func:`~fastcontact.flow.anisotropy.sigma_directional` and the table path.

References: B.N.J. Persson, J. Phys.: Condens. Matter 22, 265004 (2010),
doi:10.1088/0953-8984/22/26/265004; D. Stroud, Phys. Rev. B 12, 3368 (1975),
doi:10.1103/PhysRevB.12.3368.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import erf

from ..contact._kernels import PANEL, psd_kernel
from ..kernels.balance import spread_order
from ..kernels.quadrature import gauss_hermite, gauss_legendre
from ..kernels.special import k_table
from ._anisotropic_kernels import directional_kernel, solve_dir, solve_self_consistent, u1_nodes
from ._kernels import EMT_MAX_PANELS, EMT_TOL, EMTSpec
from .conductivity import (EMT_N_START, GH_ORDER, _dynamic_schedule, check_anisotropy,
                           check_emt_threshold, check_theory)

__all__ = [
    "FORMS",
    "N_PANELS",
    "directional_sigma_bar",
    "directional_threshold",
]

FORMS = ("self_consistent", "fixed")
#: composite Gauss–Legendre panels (order 10) in the graded variable t of A of the
#: fixed-panel solver (``n_panels=``; the default is the adaptive quadrature). Against 192
#: panels, 48 gave <= 2.5e-8 on a smooth spectrum but up to 2e-6 on synthetic road spectra
#: (γ_T 1.5-9, A(ζ1)/A0 < 0.6, σ̄ > 1e-20); the adaptive quadrature's error control avoids it
N_PANELS = 48
GL_ORDER = 10
GRADE = 3.0


def _nodes(psd, pbar, gamma, n_panels):
    """(W, σ̄ = (u1/h)³, A1) per pressure (rows): the u1-based P(u) of the Bruggeman medium
    on graded Gauss–Legendre nodes in A ∈ [A(ζ1), 1] (masked u1 → zero weight).

    u1 is evaluated where A(ζ)/A0 equals each node *exactly* (contact core's u1_at_area):
    at low pressure A(ζ) falls within ζ - 1 ~ (p/E*)² < 1e-16, where ζ is not representable.
    """
    A1 = erf(pbar / (2.0 * math.sqrt(0.25 * math.pi * psd.cum3[-1])))
    x, w = gauss_legendre(GL_ORDER)
    edges = np.linspace(0.0, 1.0, n_panels + 1)
    half = 0.5 * np.diff(edges)
    t = (0.5 * (edges[:-1] + edges[1:])[:, None] + half[:, None] * x[None, :]).ravel()
    wt = (half[:, None] * w[None, :]).ravel()
    m = GRADE
    tm, om = t ** m, (1.0 - t) ** m
    s = tm / (tm + om)
    ds = m * (t * (1.0 - t)) ** (m - 1.0) / (tm + om) ** 2
    area = A1[:, None] + (1.0 - A1[:, None]) * s[None, :]
    W = (1.0 - A1[:, None]) * (ds * wt)[None, :]
    ok = (area > A1[:, None]) & (area < 1.0)
    glx, glw = gauss_legendre()
    u = np.empty(area.shape)
    u1_nodes(psd_kernel(psd), np.ascontiguousarray(pbar), np.ascontiguousarray(
        np.where(ok, area, 0.5)), float(gamma), k_table(), glx, glw, float(PANEL), u)
    with np.errstate(over="ignore", invalid="ignore"):
        sig = (np.maximum(u, 0.0) / psd.h_rms) ** 3
    bad = ~ok | ~np.isfinite(sig)
    return (np.ascontiguousarray(np.where(bad, 0.0, W)),
            np.ascontiguousarray(np.where(bad, 0.0, sig)), A1)


def _odds(emt_threshold):
    """kk = A_c/(1 - A_c) of an effective-medium threshold A_c (1 for A_c = 1/2)."""
    a = float(check_emt_threshold(emt_threshold))
    return 1.0 if a == 0.5 else a / (1.0 - a)


def directional_sigma_bar(psd, pbar, anisotropy, *, form="self_consistent", gamma=1.0,
                          n_panels=None, emt_threshold=0.5, tol=EMT_TOL):
    """(σ̄_xx, σ̄_yy) = 12ησ/h_rms³ [-] of the anisotropic Bruggeman medium at p̄ = p/E*.

    Always runs the anisotropic solver (also at γ_T = 1; used to test continuity).
    ``emt_threshold`` A_c [-] is the isotropic medium's percolation threshold (0.5: 2-D
    Bruggeman; a calibrated value as in :func:`~fastcontact.flow.conductivity.conductivity`):
    the depolarization odds (1 - n)/n become kk γ_T^{±1} ("fixed") or kk Λ^{±1}
    ("self_consistent"), kk = A_c/(1 - A_c), so that γ_T = 1 is the generalized isotropic
    medium and the self-consistent thresholds stay at A_c.

    The P(u) integral in A: adaptive Gauss–Kronrod panels to the relative error estimate
    ``tol`` [-] (the isotropic effective medium's nodes and error control; default), or, with
    ``n_panels`` an int, that many fixed Gauss–Legendre panels of order 10 (the reference
    the adaptive quadrature is tested against).
    """
    pbar = np.atleast_1d(np.asarray(pbar, dtype=np.float64)).ravel()
    g = float(anisotropy)
    kk = _odds(emt_threshold)
    if n_panels is None:
        return _adaptive(psd, pbar, g, form, gamma, kk, tol)[:2]
    sx = np.empty(pbar.size)
    sy = np.empty(pbar.size)
    W, sig, A1 = _nodes(psd, pbar, gamma, int(n_panels))
    for i in range(pbar.size):
        if form == "self_consistent":
            sx[i], sy[i] = solve_self_consistent(W[i], sig[i], float(A1[i]), g, kk)
        else:
            sx[i] = solve_dir(W[i], sig[i], float(A1[i]), kk * g)
            sy[i] = solve_dir(W[i], sig[i], float(A1[i]), kk / g)
    return sx, sy


def _adaptive(psd, pbar, g, form, gamma, kk, tol, memory=None, keep=False):
    """(σ̄_xx, σ̄_yy, error estimate, u1 evaluations, final partitions, their panel counts)
    per p̄ by the adaptive kernel; with a :class:`~fastcontact.flow.panel_memory.PanelMemory`
    each quadrature starts on a recorded pressure's final partition (the same pressure's, else
    the neighbour's with fewer panels). The partitions are returned with ``keep`` (else an
    array of width 0: a direct call of many pressures allocates no (n, 97) array)."""
    tol = float(tol)
    if not (0.0 < tol < 1.0):
        raise ValueError(f"tol = {tol!r} is invalid: must be in (0, 1) [-] (relative error "
                         f"estimate of the adaptive quadrature)")
    glx, glw = gauss_legendre()
    ghx, ghw = gauss_hermite(GH_ORDER)
    spec = EMTSpec(float(psd.h_rms), float(gamma), glx, glw, float(PANEL), False, ghx, ghw,
                   int(EMT_N_START), tol, kk / (1.0 + kk))
    pbar = np.ascontiguousarray(pbar, dtype=np.float64)
    n = pbar.size
    if memory is None:  # equal first panels
        start, nstart = np.zeros((n, 1)), np.zeros(n, dtype=np.int64)
    else:
        start, nstart = memory.starts(np.log(pbar))
    order = spread_order(n)  # balanced threads (costs grow towards percolation)
    sx = np.empty(n)
    sy = np.empty(n)
    err = np.empty(n)
    nev = np.empty(n, dtype=np.int64)
    final = np.zeros((n, EMT_MAX_PANELS + 1 if keep else 0))
    nfinal = np.zeros(n, dtype=np.int64)
    with _dynamic_schedule():
        directional_kernel(psd_kernel(psd), np.ascontiguousarray(pbar[order]), k_table(), spec,
                           float(g), float(kk), form == "self_consistent",
                           np.ascontiguousarray(start[order]),
                           np.ascontiguousarray(nstart[order]), sx, sy, err, nev, final, nfinal)
    back = np.argsort(order)
    return sx[back], sy[back], err[back], nev[back], final[back], nfinal[back]


def _check(theory, anisotropy, direction, form):
    check_theory(theory)
    g = check_anisotropy(anisotropy)
    if direction not in ("x", "y"):
        raise ValueError(f"direction = {direction!r} is invalid: must be 'x' (along the long "
                         f"correlation length) or 'y'")
    if form not in FORMS:
        raise ValueError(f"form = {form!r} is invalid: must be one of {list(FORMS)}")
    if theory == "critical_junction" and form != "fixed" and g != 1.0:
        raise ValueError("form = 'self_consistent' is invalid with theory = "
                         "'critical_junction': the directional junction is defined for "
                         "form = 'fixed' (directional percolation thresholds) only")
    return g


def directional_threshold(a_perc, anisotropy, direction):
    """Directional percolation area fraction of the 'fixed' form: odds scaled by γ_T^{±1}."""
    g = anisotropy if direction == "x" else 1.0 / anisotropy
    return g * a_perc / (1.0 - a_perc + g * a_perc)
