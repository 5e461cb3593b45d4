"""Numba kernels of the flow-conductivity theories: critical junction, 2-D Bruggeman medium.

Reduced units: ``σ̄ = 12 η σ_eff / h_rms³`` (eq. 23 of Lorenz & Persson 2010), ``p̄ = p/E*``.
The effective-medium integral runs over the contact-area variable A on [A(ζ1), 1], graded
towards both ends (t -> A = A1 + (1-A1) t³/(t³+(1-t)³)), with adaptive 7/15 Gauss–Kronrod
panels: the panel with the largest Kronrod–Gauss difference of the Bruggeman residual is split
until the estimated relative error of σ̄ is below ``tol``. u1 is evaluated where A(ζ) equals
each node exactly; nodes where dA/dζ underflows get u1 = ∞ and weight 0 (masked).
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 31, 159 (2010), arXiv:0911.3019.
"""
from __future__ import annotations

import math
from collections import namedtuple
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ..contact._kernels import m1_above, u1_at_area
from ..kernels.borrow import borrowed
from ..kernels.quadrature import gauss_kronrod15

__all__ = ["EMTSpec", "critical_junction_kernel", "emt_kernel", "emt_sigma", "emt_panels",
           "emt_split", "panel_errors", "worst_panel", "bruggeman", "newton_step", "EMT_TOL", "EMT_MAX_PANELS", "EMT_GRADE"]


class EMTSpec(NamedTuple):
    """Flat settings of the effective-medium integral (passes into prange kernels as it is).

    Attributes
    ----------
    h_rms : float
        rms roughness [m] (σ̄ is reduced by h_rms³).
    gamma : float
        Yang–Persson factor of u1 [-].
    glx, glw : ndarray
        Gauss–Legendre rule of the (A4) panels.
    panel : float
        Panel width in τ of the (A4) quadrature.
    almqvist : bool
        Gaussian-broadened P(u) (Almqvist et al. 2011).
    ghx, ghw : ndarray
        Gauss–Hermite rule of the broadening.
    n_start : int
        Initial Gauss–Kronrod panels.
    tol : float
        Target relative accuracy of σ̄ [-].
    threshold : float
        Contact-area fraction A_c at which the generalized Bruggeman medium stops the flow
        [-] (Kirkpatrick, Rev. Mod. Phys. 45, 574 (1973), doi:10.1103/RevModPhys.45.574,
        eq. 5.8, with k = A_c/(1 - A_c)); 0.5 (k = 1) is the 2-D Bruggeman medium.
    far_area : float
        Below this A(ζ1)/A0 the u1 quadratures take the rule (glx_far, glw_far) instead of
        (glx, glw) [-]; 0 (default): never (:data:`FAR_AREA`, :data:`FAR_ORDER`).
    glx_far, glw_far : ndarray
        The u1 rule far from percolation (only read where A(ζ1)/A0 < far_area).
    """

    h_rms: float
    gamma: float
    glx: np.ndarray
    glw: np.ndarray
    panel: float
    almqvist: bool
    ghx: np.ndarray
    ghw: np.ndarray
    n_start: int
    tol: float
    threshold: float = 0.5
    far_area: float = 0.0
    glx_far: np.ndarray = np.zeros(1)
    glw_far: np.ndarray = np.zeros(1)


@njit(cache=True)
def _area1(cum3, pbar):
    G1 = 0.25 * math.pi * cum3[-1]
    return math.erf(pbar / (2.0 * math.sqrt(G1)))


@njit(cache=True, parallel=True)
def critical_junction_kernel(sk, pbar, gamma, a_perc, ktab, glx, glw, panel, u1c, zeta_c,
                             percolated):
    """u1(ζc) [m] and ζc per reduced pressure; percolated where A(ζ1)/A0 >= a_perc (eq. 31)."""
    for i in prange(pbar.size):
        work = np.empty(4)
        if _area1(sk.cum3, pbar[i]) >= a_perc:
            u1c[i] = 0.0
            zeta_c[i] = math.inf
            percolated[i] = True
        else:
            u, a = u1_at_area(sk, a_perc, pbar[i], gamma, ktab, glx, glw, panel, work)
            u1c[i] = u
            zeta_c[i] = a / sk.qb[0]
            percolated[i] = False


_XGK, _WGK, _WG7 = gauss_kronrod15()
#: the Kronrod nodes of all panels of :func:`emt_sigma` (panel k at 15k .. 15k + 14):
#: sig = σ̄ of the node (inf: masked) [-], hz = its Almqvist width [h_rms], wk, wg = its
#: Kronrod and embedded-Gauss weights in A [-]
_Nodes = namedtuple("_Nodes", "sig hz wk wg")
#: target relative accuracy of the effective-medium σ̄ (adaptive quadrature in A), met by the
#: Kronrod–Gauss estimate; against tol = 1e-13 the true error was <= 4e-9 on smooth spectra
#: and up to 3e-8 on tabulated road spectra (u1(A) has a kink where ζq0 crosses each sample,
#: which the estimate can miss), far inside the tables' σ̄ tolerance (2e-7)
EMT_TOL = 1e-8
EMT_MAX_PANELS = 96
#: grading exponent of the map t -> A that clusters nodes at both ends of [A(ζ1), 1]
EMT_GRADE = 3.0
#: the tables' effective medium (tolerance >= FAR_MIN_TOL) evaluates u1 with FAR_ORDER
#: Gauss–Legendre points per panel (not GL_ORDER = 10) at pressures whose A(ζ1)/A0 is below
#: FAR_AREA × A_c: against the 10-point rule, σ̄ moved by <= 7e-9 there on 11 spectra (three
#: self-affine, the four embedded measured ones, four synthetic roads; <= 1.2e-10 except on
#: the asphalt tables), while closer to percolation, where σ̄ hangs on the smallest u1 (down to
#: ~1e-12 h_rms), it moved by up to 1e-6 (and keeps 10 points). 8 points: the synthetic
#: road's build 0.30 -> 0.27 s (bench/tables_results.md)
FAR_ORDER = 8
FAR_AREA = 0.9
#: the smallest effective-medium tolerance that takes the FAR_ORDER rule (the tables' 1e-7)
FAR_MIN_TOL = 1e-7


@njit(cache=True)
def _node_terms(s, sj, hzj, almqvist, ghx, ghw, kk=1.0):
    """(Σ 2r, Σ 2r(1-r)) of one node, r = s/(s + σ(u)); Gauss–Hermite average if almqvist.

    Generalized medium (kk = A_c/(1 - A_c) != 1): (Σ (1+kk) r, Σ (1+kk) r (1 - kk r)) with
    r = s/(kk s + σ(u)); kk == 1 takes the 2-D Bruggeman expressions unchanged.
    """
    if sj == math.inf:
        return 0.0, 0.0  # masked: u1 undefined where dA/dζ = 0; zero weight
    if not almqvist:
        if kk != 1.0:
            if sj == 0.0:
                return (1.0 + kk) / kk, 0.0
            r = s / (kk * s + sj)
            return (1.0 + kk) * r, (1.0 + kk) * r * (1.0 - kk * r)
        if sj == 0.0:
            return 2.0, 0.0
        r = s / (s + sj)
        return 2.0 * r, 2.0 * r * (1.0 - r)
    mu = sj ** (1.0 / 3.0)
    acc = 0.0
    dacc = 0.0
    for k in range(ghx.size):
        u = abs(mu + math.sqrt(2.0) * hzj * ghx[k])
        su = u * u * u
        if kk != 1.0:
            r = s / (kk * s + su) if kk * s + su > 0.0 else 1.0 / kk
            acc += ghw[k] * (1.0 + kk) * r
            dacc += ghw[k] * (1.0 + kk) * r * (1.0 - kk * r)
            continue
        r = s / (s + su) if s + su > 0.0 else 1.0
        acc += ghw[k] * 2.0 * r
        dacc += ghw[k] * 2.0 * r * (1.0 - r)
    return acc / math.sqrt(math.pi), dacc / math.sqrt(math.pi)


@njit(cache=True)
def newton_step(y, f, df, lo, hi):
    """One safeguarded Newton step in y = ln s on a root of f (f increasing in y).

    Parameters
    ----------
    y : float
        Current iterate [-] (ln of the reduced conductivity).
    f, df : float
        Residual at y and its derivative in y [-].
    lo, hi : float
        Bracket of the root [-].

    Returns
    -------
    (y_new, lo, hi, done)
        The Newton iterate (the bracket's middle where Newton leaves it), the bracket
        narrowed by the sign of f, and whether |Δy| <= 1e-15 max(1, |y|) or the bracket
        is narrower than 1e-15.
    """
    if f > 0.0:
        hi = y
    else:
        lo = y
    yn = y - f / df if df > 0.0 else 0.5 * (lo + hi)
    if not (lo < yn < hi):
        yn = 0.5 * (lo + hi)
    done = abs(yn - y) < 1e-15 * max(1.0, abs(y)) or hi - lo < 1e-15
    return yn, lo, hi, done


@njit(cache=True)
def bruggeman(W, sig, A1, almqvist, hz, ghx, ghw, guess=0.0, threshold=0.5):
    """Solve Σ_j W_j 2s/(s + σ_j) + 2 A1 - 1 = 0 for s > 0 (2-D Bruggeman, reduced units).

    With ``almqvist`` each node is a reflected Gaussian of width hz[j] around u1 = σ_j^(1/3)
    (Gauss–Hermite nodes ghx, ghw). Safeguarded Newton in ln s, started from ``guess`` when
    it is inside the bracket (warm start), else from the bracket's middle. Returns 0 when
    A1 >= threshold (percolated). A threshold A_c != 0.5 solves the generalized medium
    Σ_j W_j (1+k)s/(σ_j + k s) + A1/k - (1 - A1) = 0, k = A_c/(1 - A_c) (Kirkpatrick 1973,
    eq. 5.8); A_c = 0.5 (k = 1) is the equation above, evaluated by the same expressions.
    """
    if A1 >= threshold:
        return 0.0
    kk = threshold / (1.0 - threshold)
    inv = 0.0
    smax = 0.0
    for j in range(W.size):
        sj = sig[j]
        if sj == math.inf:
            continue
        if almqvist:
            sj = (sj ** (1.0 / 3.0) + 8.0 * hz[j]) ** 3
        if sj > 0.0:
            inv += W[j] / sig[j] if sig[j] > 0.0 else 0.0
            if sj > smax:
                smax = sj
    if smax <= 0.0:
        return 0.0
    if kk == 1.0:
        s_lo = (1.0 - 2.0 * A1) / (2.0 * inv) if inv > 0 else smax * 1e-300
        f0 = 2.0 * A1 - 1.0
    else:
        s_lo = ((1.0 - A1) - A1 / kk) / ((1.0 + kk) * inv) if inv > 0 else smax * 1e-300
        f0 = A1 / kk - (1.0 - A1)
    lo = math.log(max(s_lo, 1e-300)) - 1.0
    if almqvist:
        lo -= 30.0
    hi = math.log(smax) + 1.0
    y = 0.5 * (lo + hi)
    if guess > 0.0 and lo < math.log(guess) < hi:
        y = math.log(guess)
    for it in range(200):
        s = max(math.exp(y), 1e-300)
        f = f0
        df = 0.0
        for j in range(W.size):
            t1, t2 = _node_terms(s, sig[j], hz[j], almqvist, ghx, ghw, kk)
            f += W[j] * t1
            df += W[j] * t2
        y, lo, hi, done = newton_step(y, f, df, lo, hi)
        if done:
            break
    return math.exp(y)


@njit(cache=True)
def _emt_fill_panel(sk, pbar, A1, t0, t1, ktab, spec, work, nodes, off):
    """u1-based σ(u) at the 15 Kronrod nodes of panel [t0, t1] of the graded variable t, into
    ``nodes`` (:data:`_Nodes`) from index ``off``."""
    sig = nodes.sig
    hz = nodes.hz
    WK = nodes.wk
    WG = nodes.wg
    h_rms = spec.h_rms
    m = EMT_GRADE
    half = 0.5 * (t1 - t0)
    mid = 0.5 * (t1 + t0)
    for k in range(15):
        t = mid + half * _XGK[k]
        tm = t ** m
        om = (1.0 - t) ** m
        sfrac = tm / (tm + om)
        ds = m * (t * (1.0 - t)) ** (m - 1.0) / (tm + om) ** 2
        area = A1 + (1.0 - A1) * sfrac
        WK[off + k] = (1.0 - A1) * ds * half * _WGK[k]
        WG[off + k] = (1.0 - A1) * ds * half * _WG7[k]
        if area >= 1.0 or area <= A1:
            sig[off + k] = math.inf
            hz[off + k] = 0.0
            continue
        if A1 < spec.far_area:
            u, a = u1_at_area(sk, area, pbar, spec.gamma, ktab, spec.glx_far, spec.glw_far,
                              spec.panel, work)
        else:
            u, a = u1_at_area(sk, area, pbar, spec.gamma, ktab, spec.glx, spec.glw, spec.panel,
                              work)
        if not (u < math.inf) or u != u:
            sig[off + k] = math.inf  # masked: dA/dζ = 0 there
        else:
            uh = max(u, 0.0) / h_rms
            sig[off + k] = uh * uh * uh
        if spec.almqvist:
            hz[off + k] = math.sqrt(2.0 * math.pi * m1_above(sk.qb, sk.c, sk.e, a)) / h_rms
        else:
            hz[off + k] = 0.0


#: the arrays of the adaptive quadrature in A (:func:`emt_panels`): the Kronrod nodes
#: (:data:`_Nodes`), the panels' ends pt0, pt1 in the graded variable t, u1's work array,
#: the panels' residual errors err (:func:`panel_errors`)
_Panels = namedtuple("_Panels", "nodes pt0 pt1 work err")


@njit(cache=True)
def _empty_panels():
    cap = EMT_MAX_PANELS * 15
    return _Panels(_Nodes(np.empty(cap), np.zeros(cap), np.empty(cap), np.empty(cap)),
                   np.empty(EMT_MAX_PANELS), np.empty(EMT_MAX_PANELS), np.empty(4),
                   np.empty(EMT_MAX_PANELS))


@njit(cache=True)
def emt_panels(sk, pbar, A1, ktab, spec):
    """(panels, n): the adaptive quadrature's arrays (room for EMT_MAX_PANELS panels,
    :data:`_Panels`) with its first n = spec.n_start equal panels in t filled."""
    pan = _empty_panels()
    npan = spec.n_start
    for k in range(npan):
        pan.pt0[k] = k / npan
        pan.pt1[k] = (k + 1) / npan
        _emt_fill_panel(sk, pbar, A1, pan.pt0[k], pan.pt1[k], ktab, spec, pan.work,
                        pan.nodes, 15 * k)
    return pan, npan


@njit(cache=True)
def emt_panels_on(sk, pbar, A1, ktab, spec, breaks, nb):
    """As :func:`emt_panels`, but the first panels are [breaks[k], breaks[k+1]], k < nb (a
    partition of [0, 1] in t, e.g. the final one of a neighbouring pressure); nb = 0: the
    spec.n_start equal panels."""
    if nb <= 0:
        return emt_panels(sk, pbar, A1, ktab, spec)
    pan = _empty_panels()
    for k in range(nb):
        pan.pt0[k] = breaks[k]
        pan.pt1[k] = breaks[k + 1]
        _emt_fill_panel(sk, pbar, A1, pan.pt0[k], pan.pt1[k], ktab, spec, pan.work,
                        pan.nodes, 15 * k)
    return pan, nb


@njit(cache=True)
def emt_split(sk, pbar, A1, ktab, spec, pan, worst, npan):
    """Halve panel ``worst`` of the npan panels of ``pan``: its left half replaces it, the
    right half is appended (both filled); returns npan + 1."""
    a0 = pan.pt0[worst]
    a1 = pan.pt1[worst]
    am = 0.5 * (a0 + a1)
    pan.pt1[worst] = am
    _emt_fill_panel(sk, pbar, A1, a0, am, ktab, spec, pan.work, pan.nodes, 15 * worst)
    pan.pt0[npan] = am
    pan.pt1[npan] = a1
    _emt_fill_panel(sk, pbar, A1, am, a1, ktab, spec, pan.work, pan.nodes, 15 * npan)
    return npan + 1


@njit(cache=True)
def panel_errors(s, kk, nodes, npan, spec, err):
    """|Kronrod - Gauss| of each of the npan panels' share of the medium's residual at s
    (depolarization odds kk, terms of :func:`_node_terms`) into err[:npan]; returns
    Σ W_K d(residual)/d ln s over all nodes, the scale that makes them relative errors of s."""
    dfl = 0.0
    for k in range(npan):
        ek = 0.0
        eg = 0.0
        for j in range(15 * k, 15 * k + 15):
            t1_, t2_ = _node_terms(s, nodes.sig[j], nodes.hz[j], spec.almqvist, spec.ghx,
                                   spec.ghw, kk)
            ek += nodes.wk[j] * t1_
            eg += nodes.wg[j] * t1_
            dfl += nodes.wk[j] * t2_
        err[k] = abs(ek - eg)
    return dfl


@njit(cache=True)
def worst_panel(err, npan):
    """Index of the largest of err[:npan] (the first of equals); -1 if all are 0."""
    worst = -1
    worst_err = 0.0
    for k in range(npan):
        if err[k] > worst_err:
            worst_err = err[k]
            worst = k
    return worst


@njit(cache=True)
def emt_sigma(sk, pbar, ktab, spec):
    """Bruggeman σ̄ at one reduced pressure with adaptive Gauss–Kronrod panels in A.

    ``sk`` a PSDKernel, ``ktab`` the K(s0) tables, ``spec`` an :class:`EMTSpec`.
    Returns (σ̄, estimated relative error, number of u1 evaluations). The records are used
    through borrowed views (:mod:`fastcontact.kernels.borrow`): the u1 quadratures below
    inline helpers that take them; on one thread the synthetic road spectrum's 258 pressures
    took 0.353 s against 0.372 s without (bit-identical σ̄).
    """
    none = np.empty(0)
    s, est, n, _nb = emt_sigma_on(sk, pbar, ktab, spec, none, 0, none)
    return s, est, n


@njit(cache=True)
def _sorted_breaks(pan, npan, final):
    """The sorted breakpoints of the npan panels (their starts, then 1) into final; npan."""
    for k in range(npan):
        final[k] = pan.pt0[k]
    final[:npan].sort()
    final[npan] = 1.0
    return npan


@njit(cache=True)
def emt_sigma_on(sk, pbar, ktab, spec, breaks, nb, final):
    """:func:`emt_sigma` started on the panels breaks[0..nb] (nb = 0: spec.n_start equal
    panels); returns (σ̄, estimated relative error, u1 evaluations kept, panels of the final
    partition), the partition's sorted breakpoints written to final[: panels + 1] when final
    has room (size 0: not written). The result meets the same ``spec.tol`` whatever the start;
    a start close to the final partition saves the nodes a split discards."""
    sk = borrowed(sk)
    ktab = borrowed(ktab)
    spec = borrowed(spec)
    almqvist, ghx, ghw, tol = spec.almqvist, spec.ghx, spec.ghw, spec.tol
    A1 = _area1(sk.cum3, pbar)
    if A1 >= spec.threshold:
        return 0.0, 0.0, 0, 0
    kk = spec.threshold / (1.0 - spec.threshold)
    pan, npan = emt_panels_on(sk, pbar, A1, ktab, spec, breaks, nb)
    sig = pan.nodes.sig
    hz = pan.nodes.hz
    WK = pan.nodes.wk
    s = 0.0
    est = 0.0
    while True:
        n = 15 * npan
        s = bruggeman(WK[:n], sig[:n], A1, almqvist, hz[:n], ghx, ghw, s, spec.threshold)
        if s <= 0.0:
            return 0.0, 0.0, n, 0
        # per-panel error of the Bruggeman residual, relative to d f / d ln s
        dfl = panel_errors(s, kk, pan.nodes, npan, spec, pan.err)
        tot = 0.0
        for k in range(npan):
            tot += pan.err[k]
        est = tot / dfl if dfl > 0.0 else 0.0
        worst = worst_panel(pan.err, npan)
        if est <= tol or npan >= EMT_MAX_PANELS or worst < 0:
            if final.size > npan:
                _sorted_breaks(pan, npan, final)
            return s, est, n, npan
        npan = emt_split(sk, pbar, A1, ktab, spec, pan, worst, npan)


@njit(cache=True, parallel=True)
def emt_kernel_warm(sk, pbar, ktab, spec, start, nstart, sigma, percolated, err, nevals, final,
                    nfinal):
    """:func:`emt_kernel` with each pressure's first panels given (start[i, :nstart[i] + 1],
    breakpoints in t; nstart[i] = 0: the equal panels), and each pressure's final partition
    written to final[i, :nfinal[i] + 1] (sorted breakpoints; nfinal 0 where percolated) when
    final has the columns (a final of width 0 keeps none)."""
    for i in prange(pbar.size):
        percolated[i] = _area1(sk.cum3, pbar[i]) >= spec.threshold
        s, es, ne, nb = emt_sigma_on(sk, pbar[i], ktab, spec, start[i], nstart[i], final[i])
        sigma[i] = s
        err[i] = es
        nevals[i] = ne
        nfinal[i] = nb


@njit(cache=True, parallel=True)
def emt_kernel(sk, pbar, ktab, spec, sigma, percolated, err, nevals):
    """Bruggeman σ̄ = 12ησ_eff/h_rms³ per reduced pressure (u1-based P(u)) into the out arrays.

    Percolated where A(ζ1)/A0 >= spec.threshold (0.5: the 2-D Bruggeman medium)."""
    for i in prange(pbar.size):
        percolated[i] = _area1(sk.cum3, pbar[i]) >= spec.threshold
        s, es, ne = emt_sigma(sk, pbar[i], ktab, spec)
        sigma[i] = s
        err[i] = es
        nevals[i] = ne
