"""Interfacial fluid flow conductivity σ_eff(p_cont) by direct quadrature — three theories.

Reduced units: ``σ̄ = 12 η σ_eff / h_rms³`` (eq. 23), ``p̄ = p/E*``.

Theories
--------
``"average"``            σ_eff = ū³ / (12η)                                   (Sec. 2)
``"critical_junction"``  σ_eff = (α_cj u1(ζc))³ / (12η), A(ζc)/A0 = a_perc     (Sec. 3, 31–32)
``"emt"``                2-D Bruggeman effective medium over P(u) from u1(ζ)

Percolation is exact: critical junction gives σ_eff = 0 when A(ζ1)/A0 >= a_perc; the
effective medium when A(ζ1)/A0 >= emt_threshold (0.5: 2-D Bruggeman; other values: the
generalized medium of Kirkpatrick, Rev. Mod. Phys. 45, 574 (1973), doi:10.1103/RevModPhys.45.574).
Every result carries a ``percolated`` flag.
References: B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010),
arXiv:1004.1037 and Eur. Phys. J. E 31, 159 (2010), arXiv:0911.3019.
"""
from __future__ import annotations

import contextlib
import math
from typing import NamedTuple, Optional

import numpy as np
from numba import get_parallel_chunksize, set_parallel_chunksize

from .._core.validate import check_positive, check_range
from .._core.vocab import DEFAULT_THEORY, THEORIES
from ..contact import _check_gamma, _check_pbar, _check_psd, _separation, mean_separation
from ..contact._kernels import PANEL, psd_kernel
from ..kernels.balance import spread_order
from ..kernels.quadrature import gauss_hermite, gauss_legendre
from ..kernels.special import k_table
from ._kernels import (EMT_MAX_PANELS, EMT_TOL, FAR_AREA, FAR_MIN_TOL, FAR_ORDER, EMTSpec,
                       critical_junction_kernel, emt_kernel_warm)

__all__ = ["THEORIES", "EMT_TOL", "check_theory", "check_emt_threshold", "check_anisotropy", "conductivity", "flow_factor", "sigma_bar",
           "SigmaBar", "SigmaDetails", "Conductivity", "FlowFactor"]

#: initial Gauss–Kronrod panels of the adaptive effective-medium integral over A
EMT_N_START = 4
#: Gauss–Hermite nodes for the Almqvist-broadened P(u)
GH_ORDER = 24


class SigmaDetails(NamedTuple):
    """By-products of :func:`sigma_bar` (None where the theory does not produce them).

    Also readable as a mapping, ``details["u1c"]``, for older callers.
    """

    u_bar: Optional[np.ndarray] = None           #: ū/h_rms [-] (average)
    u1c: Optional[np.ndarray] = None             #: u1(ζc)/h_rms [-] (critical junction)
    zeta_c: Optional[np.ndarray] = None          #: ζc [-] (critical junction)
    error_estimate: Optional[np.ndarray] = None  #: estimated relative error of σ̄ (emt)
    u1_evaluations: Optional[np.ndarray] = None  #: u1 quadratures used (emt)

    def __getitem__(self, key):
        if isinstance(key, str):
            value = getattr(self, key, None)
            if value is None:
                raise KeyError(key)
            return value
        return tuple.__getitem__(self, key)

    def __contains__(self, key):
        return getattr(self, key, None) is not None if isinstance(key, str) else \
            tuple.__contains__(self, key)


class SigmaBar(NamedTuple):
    """Result of :func:`sigma_bar`: ``(sigma_bar, percolated, details)``."""

    sigma_bar: np.ndarray      #: σ̄ = 12ησ_eff/h_rms³ [-]; exactly 0 where percolated
    percolated: np.ndarray     #: bool, the contact percolates (σ_eff = 0)
    details: SigmaDetails


class Conductivity(NamedTuple):
    """Result of :func:`conductivity`: ``(sigma_eff, percolated)``."""

    sigma_eff: np.ndarray      #: σ_eff [m³/(Pa·s)]; exactly 0 where percolated
    percolated: np.ndarray     #: bool


class FlowFactor(NamedTuple):
    """Result of :func:`flow_factor`: ``(phi, percolated)``."""

    phi: np.ndarray            #: pressure flow factor φ_p = 12ησ_eff/ū³ [-]
    percolated: np.ndarray     #: bool


@contextlib.contextmanager
def _dynamic_schedule():
    """prange splits the pressures into chunks of one (their costs differ by 100x near
    percolation). The OpenMP and workqueue layers still hand each thread a contiguous block of
    chunks, so the callers also permute the pressures (:mod:`fastcontact.kernels.balance`)."""
    old = get_parallel_chunksize()
    set_parallel_chunksize(1)
    try:
        yield
    finally:
        set_parallel_chunksize(old)


def check_theory(theory):
    """``theory`` if it names a flow theory, else ValueError listing them."""
    if theory not in THEORIES:
        raise ValueError(f"theory = {theory!r} is invalid: must be one of {list(THEORIES)}")
    return theory


def check_emt_threshold(emt_threshold):
    """``emt_threshold`` as a float in (0, 1) [-], else ValueError naming it."""
    return float(check_range("emt_threshold", emt_threshold, 0.0, 1.0, "[-]",
                             lo_open=True, hi_open=True))


def check_anisotropy(anisotropy):
    """The Peklenik number γ_T = ξ_x/ξ_y >= 1 [-] as a float, or ValueError naming it."""
    return float(check_range("anisotropy", anisotropy, 1.0, math.inf, "[-] (Peklenik number "
                             "γ_T = ξ_x/ξ_y >= 1; put the long correlation length along x)",
                             hi_open=True))


def sigma_bar(psd, pbar, theory, *, gamma=1.0, a_perc=0.5, alpha_cj=1.0, n_start=EMT_N_START,
              tol=EMT_TOL, almqvist=False, glx=None, glw=None, panel=PANEL, emt_threshold=0.5):
    """Reduced conductivity σ̄ = 12ησ_eff/h_rms³ [-] at reduced contact pressures p̄ = p/E*.

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    pbar : array_like
        Reduced contact pressures p/E* [-], >= 1e-150 (flattened; PBAR_MIN, below which the
        quadrature underflows).
    theory : {"average", "critical_junction", "emt"}
        Flow theory.
    gamma, a_perc, alpha_cj, tol, almqvist, emt_threshold
        As in :func:`conductivity`.
    n_start : int
        Initial Gauss–Kronrod panels of the effective-medium integral.
    glx, glw, panel
        Gauss–Legendre rule and panel width in τ of the (A4) quadrature (defaults: order 10, 1).

    Returns
    -------
    SigmaBar
        ``(sigma_bar, percolated, details)``; ``details`` is a :class:`SigmaDetails`.
    """
    check_theory(theory)
    emt_threshold = check_emt_threshold(emt_threshold)
    pbar = _check_pbar(np.ascontiguousarray(np.asarray(pbar, dtype=np.float64).ravel()))
    h = psd.h_rms
    if glx is None:
        glx, glw = gauss_legendre()
    if theory == "average":
        u, _ = _separation(psd, pbar, 1.0, 1.0, gamma, glx, glw, panel)
        return SigmaBar((u / h) ** 3, np.zeros(pbar.size, dtype=bool), SigmaDetails(u_bar=u / h))
    sk = psd_kernel(psd)
    perc = np.empty(pbar.size, dtype=np.bool_)
    if theory == "critical_junction":
        u1c = np.empty(pbar.size)
        zc = np.empty(pbar.size)
        with _dynamic_schedule():
            critical_junction_kernel(sk, pbar, gamma, float(a_perc), k_table(), glx, glw,
                                     float(panel), u1c, zc, perc)
        return SigmaBar((alpha_cj * u1c / h) ** 3, perc, SigmaDetails(u1c=u1c / h, zeta_c=zc))
    ghx, ghw = gauss_hermite(GH_ORDER)
    spec = EMTSpec(float(h), float(gamma), glx, glw, float(panel), bool(almqvist), ghx, ghw,
                   int(n_start), float(tol), emt_threshold)
    return _emt(sk, pbar, spec, None, None)[0]


def _emt(sk, pbar, spec, start, nstart):
    """(SigmaBar, final partitions, their panel counts) of the effective medium at pbar, the
    pressures handed to the threads in :func:`~fastcontact.kernels.balance.spread_order`
    (start None: every quadrature on spec.n_start equal panels)."""
    n = pbar.size
    order = spread_order(n)
    # a cold call (a direct σ̄ of many pressures) neither reads nor keeps partitions: no
    # (n, EMT_MAX_PANELS + 1) arrays (78 MB each for 1e5 pressures)
    width = 0 if start is None else EMT_MAX_PANELS + 1
    if start is None:
        start = np.zeros((n, 1))
        nstart = np.zeros(n, dtype=np.int64)
    sig = np.empty(n)
    err = np.empty(n)
    nev = np.empty(n, dtype=np.int64)
    perc = np.empty(n, dtype=np.bool_)
    final = np.zeros((n, width))
    nfinal = np.zeros(n, dtype=np.int64)
    with _dynamic_schedule():
        emt_kernel_warm(sk, np.ascontiguousarray(pbar[order]), k_table(), spec,
                        np.ascontiguousarray(start[order], dtype=np.float64),
                        np.ascontiguousarray(nstart[order], dtype=np.int64), sig, perc, err, nev,
                        final, nfinal)
    back = np.argsort(order)
    return (SigmaBar(sig[back], perc[back],
                     SigmaDetails(error_estimate=err[back], u1_evaluations=nev[back])),
            final[back], nfinal[back])


def emt_sigma_bar_started(psd, pbar, start, nstart, *, gamma=1.0, tol=EMT_TOL, almqvist=False,
                          emt_threshold=0.5, n_start=EMT_N_START, **_ignored):
    """Effective-medium σ̄ as :func:`sigma_bar` (``theory="emt"``), each pressure's adaptive
    quadrature in A started on given panels (a table build passes each new pressure the final
    partition of a neighbouring node: the splits that partition already made are not repeated,
    and the nodes they would discard are not computed). The result meets the same ``tol``.
    With ``tol`` >= FAR_MIN_TOL (1e-7, a table's), u1 takes FAR_ORDER Gauss points per panel
    at pressures with A(ζ1)/A0 < FAR_AREA × A_c (:data:`~fastcontact.flow._kernels.FAR_ORDER`:
    σ̄ within 7e-9 of the 10-point rule's there).

    Parameters
    ----------
    psd, pbar, gamma, tol, almqvist, emt_threshold, n_start
        As in :func:`sigma_bar` (``pbar`` validated by the caller: contiguous float64).
    start : ndarray
        (n, EMT_MAX_PANELS + 1) float64: row i holds the breakpoints 0 = t_0 < ... < t_m = 1 of
        pressure i's first panels in the graded variable t.
    nstart : ndarray
        (n,) int64: m per row; 0 starts on n_start equal panels.

    Returns
    -------
    (SigmaBar, final, nfinal)
        σ̄ as :func:`sigma_bar`; the final partitions in the layout of ``start``.
    """
    ghx, ghw = gauss_hermite(GH_ORDER)
    glx, glw = gauss_legendre()
    threshold = check_emt_threshold(emt_threshold)
    # a table's tolerance: fewer u1 points far from percolation (FAR_ORDER)
    far = (FAR_AREA * threshold, *gauss_legendre(FAR_ORDER)) if tol >= FAR_MIN_TOL else ()
    spec = EMTSpec(float(psd.h_rms), float(gamma), glx, glw, float(PANEL), bool(almqvist), ghx,
                   ghw, int(n_start), float(tol), threshold, *far)
    return _emt(psd_kernel(psd), pbar, spec, start, nstart)


def conductivity(psd, p, E_star, eta, theory=DEFAULT_THEORY, *, gamma=1.0, a_perc=0.5,
                 alpha_cj=1.0, tol=EMT_TOL, almqvist=False, emt_threshold=0.5):
    """Effective interfacial fluid conductivity σ_eff(p_cont) [m³/(Pa·s)] by direct quadrature.

    Parameters
    ----------
    psd : PSD
        Roughness spectrum.
    p : array_like
        Contact pressure p_cont [Pa], > 0, with p/E* >= 1e-150.
    E_star : float
        Effective modulus [Pa], > 0.
    eta : float
        Fluid viscosity [Pa·s], > 0.
    theory : {"average", "critical_junction", "emt"}
        Flow theory (default :data:`~fastcontact._core.vocab.DEFAULT_THEORY`,
        "critical_junction", as everywhere in the package).
    gamma : float
        Yang–Persson factor of ū(ζ) and u1(ζ) in (0, 1] [-] (1 = paper).
    a_perc : float
        Critical-junction percolation area fraction in (0, 1) [-] (0.5 paper; 0.42 option).
    alpha_cj : float
        Critical-junction factor multiplying u1(ζc) [-] (σ carries α_cj³).
    tol : float
        Target relative accuracy of the adaptive effective-medium integral [-] (its estimate;
        on tabulated spectra the true error can be up to ~3x larger, see ``EMT_TOL``).
    almqvist : bool
        Gaussian-broadened P(u) (Almqvist et al. 2011, doi:10.1016/j.jmps.2011.08.004).
    emt_threshold : float
        Effective-medium percolation threshold A_c in (0, 1) [-]: the flow stops at
        A(ζ1)/A0 = A_c. 0.5 is the 2-D Bruggeman medium (bit-identical to earlier releases);
        other values solve Σ W (1+k)σ̄/(σ + kσ̄) + A1/k - (1 - A1) = 0, k = A_c/(1 - A_c)
        (Kirkpatrick 1973, eq. 5.8).

    Returns
    -------
    Conductivity
        ``(sigma_eff [m³/(Pa·s)], percolated [bool])``, arrays of p's shape; σ_eff = 0
        exactly where percolated.
    """
    _check_psd(psd)
    check_theory(theory)
    p = check_positive("p", p, "[Pa]")
    E_star = float(check_positive("E_star", E_star, "[Pa]"))
    eta = check_positive("eta", eta, "[Pa·s]")
    gamma = _check_gamma(gamma)
    a_perc = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    alpha_cj = float(check_positive("alpha_cj", alpha_cj, "[-]"))
    tol = float(check_range("tol", tol, 1e-14, 1e-2, "[-]"))
    sb, perc, _ = sigma_bar(psd, np.ravel(p) / E_star, theory, gamma=gamma, a_perc=a_perc,
                            alpha_cj=alpha_cj, tol=tol, almqvist=bool(almqvist),
                            emt_threshold=emt_threshold)
    sig = sb.reshape(np.shape(p)) * psd.h_rms ** 3 / (12.0 * eta)
    return Conductivity(sig, perc.reshape(np.shape(p)))


def flow_factor(psd, p, E_star, theory="emt", **options):
    """Pressure flow factor φ_p = 12ησ_eff/ū³ [-] (Patir & Cheng 1978; paper Sec. 4).

    Parameters
    ----------
    psd, p, E_star
        As in :func:`conductivity`.
    theory : {"average", "critical_junction", "emt"}
        Flow theory (default "emt": the flow factor is an effective-medium concept).
    **options
        Keywords of :func:`conductivity`.

    Returns
    -------
    FlowFactor
        ``(phi [-], percolated [bool])``.
    """
    sig, perc = conductivity(psd, p, E_star, 1.0, theory, **options)
    u = mean_separation(psd, p, E_star, gamma=options.get("gamma", 1.0))
    return FlowFactor(12.0 * sig / u ** 3, perc)
