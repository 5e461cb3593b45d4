"""Interfacial fluid flow conductivity σ_eff(p_cont) — three theories (SPEC §3).

Reduced units throughout the kernels: ``σ̄ = 12 η σ_eff / h_rms³`` (eq. 23), ``p̄ = p/E*``.

Theories
--------
``"average"``            σ_eff = ū³ / (12η)                                   (Sec. 2)
``"critical_junction"``  σ_eff = (α_cj u1(ζc))³ / (12η), A(ζc)/A0 = a_perc     (Sec. 3, 31–32)
``"emt"``                2-D Bruggeman effective medium over P(u) from u1(ζ)  ([literature])

Percolation is exact: critical junction gives σ_eff = 0 when A(ζ1)/A0 >= a_perc; the
effective medium when A(ζ1)/A0 >= 0.5. Every result carries a ``percolated`` flag.

The effective medium integral is taken in the variable A (``-A'(ζ)dζ = -dA``) on
[A(ζ1), 1], graded towards both ends (t -> A = A1 + (1-A1) t³/(t³+(1-t)³)), with adaptive
Gauss–Kronrod (7/15) panels: the panel with the largest Kronrod–Gauss difference of the
Bruggeman residual is split until the estimated relative error of σ̄ is below EMT_TOL.
u1 is evaluated where A(ζ) equals each node exactly; nodes where dA/dζ underflows get
u1 = ∞ and contribute 0 (masked, never inf/NaN in the result).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .._core.validate import check_positive, check_range
from ..contact import _arrays, _check_gamma, _check_psd
from ..contact._kernels import PANEL, gauss_legendre, u1_at_area, m1_above
from ..kernels.special import k_table

__all__ = ["THEORIES", "conductivity", "flow_factor", "sigma_bar"]

THEORIES = ("average", "critical_junction", "emt")
#: initial Gauss–Kronrod panels of the adaptive effective-medium integral over A
EMT_N_START = 4
#: Gauss–Hermite nodes for the Almqvist-broadened P(u)
GH_ORDER = 24


def check_theory(theory):
    if theory not in THEORIES:
        raise ValueError(f"theory = {theory!r} is invalid: must be one of {list(THEORIES)}")
    return theory


# --------------------------------------------------------------------------- kernels
@njit(cache=True)
def _area1(cum3, pbar):
    G1 = 0.25 * math.pi * cum3[-1]
    return math.erf(pbar / (2.0 * math.sqrt(G1)))


@njit(cache=True, parallel=True)
def critical_junction_kernel(qb, c, e, cum3, kinks, pbar, gamma, a_perc, ktab, glx, glw, panel,
                             u1c, zeta_c, percolated):
    """u1(ζc) [m] and ζc per reduced pressure; percolated where A(ζ1)/A0 >= a_perc."""
    for i in prange(pbar.size):
        work = np.empty(4)
        if _area1(cum3, pbar[i]) >= a_perc:
            u1c[i] = 0.0
            zeta_c[i] = math.inf
            percolated[i] = True
        else:
            u, a = u1_at_area(qb, c, e, cum3, kinks, a_perc, pbar[i], gamma, ktab, glx, glw,
                              panel, work)
            u1c[i] = u
            zeta_c[i] = a / qb[0]
            percolated[i] = False


_XGK = np.array([-0.991455371120812639206854697526329, -0.949107912342758524526189684047851,
                 -0.864864423359769072789712788640926, -0.741531185599394439863864773280788,
                 -0.586087235467691130294144845693013, -0.405845151377397166906606412076961,
                 -0.207784955007898467600689403773245, 0.0,
                 0.207784955007898467600689403773245, 0.405845151377397166906606412076961,
                 0.586087235467691130294144845693013, 0.741531185599394439863864773280788,
                 0.864864423359769072789712788640926, 0.949107912342758524526189684047851,
                 0.991455371120812639206854697526329])
_WGK = np.array([0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                 0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                 0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                 0.204432940075298892414161999234649, 0.209482141084727828012999174891714,
                 0.204432940075298892414161999234649, 0.190350578064785409913256402421014,
                 0.169004726639267902826583426598550, 0.140653259715525918745189590510238,
                 0.104790010322250183839876322541518, 0.063092092629978553290700663189204,
                 0.022935322010529224963732008058970])
_WG7 = np.array([0.0, 0.129484966168869693270611432679082, 0.0, 0.279705391489276667901467771423780,
                 0.0, 0.381830050505118944950369775488975, 0.0, 0.417959183673469387755102040816327,
                 0.0, 0.381830050505118944950369775488975, 0.0, 0.279705391489276667901467771423780,
                 0.0, 0.129484966168869693270611432679082, 0.0])
#: target relative accuracy of the effective-medium σ̄ (adaptive quadrature in A)
EMT_TOL = 1e-8
EMT_MAX_PANELS = 96
#: grading exponent of the map t -> A that clusters nodes at both ends of [A(ζ1), 1]
EMT_GRADE = 3.0


@njit(cache=True)
def _node_terms(s, sj, hzj, almqvist, ghx, ghw):
    """(Σ 2r, Σ 2r(1-r)) of one node, r = s/(s + σ(u)); Gauss–Hermite average if almqvist."""
    if sj == math.inf:
        return 0.0, 0.0  # masked: u1 undefined where dA/dζ = 0; zero weight
    if not almqvist:
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
        r = s / (s + su) if s + su > 0.0 else 1.0
        acc += ghw[k] * 2.0 * r
        dacc += ghw[k] * 2.0 * r * (1.0 - r)
    return acc / math.sqrt(math.pi), dacc / math.sqrt(math.pi)


@njit(cache=True)
def bruggeman(W, sig, A1, almqvist, hz, ghx, ghw):
    """Solve Σ_j W_j 2s/(s + σ_j) + 2 A1 - 1 = 0 for s > 0 (2-D Bruggeman, reduced units).

    With ``almqvist`` each node is a reflected Gaussian of width hz[j] around u1 = σ_j^(1/3)
    (Gauss–Hermite nodes ghx, ghw). Returns 0 when A1 >= 0.5 (percolated).
    """
    if A1 >= 0.5:
        return 0.0
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
    lo = math.log(max((1.0 - 2.0 * A1) / (2.0 * inv) if inv > 0 else smax * 1e-300, 1e-300)) - 1.0
    if almqvist:
        lo -= 30.0
    hi = math.log(smax) + 1.0
    y = 0.5 * (lo + hi)
    for it in range(200):
        s = max(math.exp(y), 1e-300)
        f = 2.0 * A1 - 1.0
        df = 0.0
        for j in range(W.size):
            t1, t2 = _node_terms(s, sig[j], hz[j], almqvist, ghx, ghw)
            f += W[j] * t1
            df += W[j] * t2
        if f > 0.0:
            hi = y
        else:
            lo = y
        yn = y - f / df if df > 0.0 else 0.5 * (lo + hi)
        if not (lo < yn < hi):
            yn = 0.5 * (lo + hi)
        if abs(yn - y) < 1e-15 * max(1.0, abs(y)) or hi - lo < 1e-15:
            return math.exp(yn)
        y = yn
    return math.exp(y)


@njit(cache=True)
def _emt_fill_panel(qb, c, e, cum3, kinks, pbar, A1, t0, t1, h_rms, gamma, ktab, glx, glw, panel,
                    almqvist, work, sig, hz, WK, WG, off):
    """u1-based σ(u) at the 15 Kronrod nodes of panel [t0, t1] of the graded variable t."""
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
        u, a = u1_at_area(qb, c, e, cum3, kinks, area, pbar, gamma, ktab, glx, glw, panel, work)
        if not (u < math.inf) or u != u:
            sig[off + k] = math.inf  # masked: dA/dζ = 0 there
        else:
            uh = max(u, 0.0) / h_rms
            sig[off + k] = uh * uh * uh
        hz[off + k] = math.sqrt(2.0 * math.pi * m1_above(qb, c, e, a)) / h_rms if almqvist else 0.0


@njit(cache=True)
def emt_sigma(qb, c, e, cum3, kinks, pbar, h_rms, gamma, ktab, glx, glw, panel, almqvist, ghx,
              ghw, n_start, tol):
    """Bruggeman σ̄ at one reduced pressure with adaptive Gauss–Kronrod panels in A.

    Returns (σ̄, estimated relative error, number of u1 evaluations).
    """
    A1 = _area1(cum3, pbar)
    if A1 >= 0.5:
        return 0.0, 0.0, 0
    cap = EMT_MAX_PANELS * 15
    sig = np.empty(cap)
    hz = np.zeros(cap)
    WK = np.empty(cap)
    WG = np.empty(cap)
    pt0 = np.empty(EMT_MAX_PANELS)
    pt1 = np.empty(EMT_MAX_PANELS)
    work = np.empty(4)
    npan = n_start
    for k in range(npan):
        pt0[k] = k / npan
        pt1[k] = (k + 1) / npan
        _emt_fill_panel(qb, c, e, cum3, kinks, pbar, A1, pt0[k], pt1[k], h_rms, gamma, ktab, glx,
                        glw, panel, almqvist, work, sig, hz, WK, WG, 15 * k)
    s = 0.0
    est = 0.0
    while True:
        n = 15 * npan
        s = bruggeman(WK[:n], sig[:n], A1, almqvist, hz[:n], ghx, ghw)
        if s <= 0.0:
            return 0.0, 0.0, n
        # per-panel error of the Bruggeman residual, relative to d f / d ln s
        dfl = 0.0
        worst = -1
        worst_err = 0.0
        tot = 0.0
        for k in range(npan):
            ek = 0.0
            eg = 0.0
            for j in range(15 * k, 15 * k + 15):
                t1_, t2_ = _node_terms(s, sig[j], hz[j], almqvist, ghx, ghw)
                ek += WK[j] * t1_
                eg += WG[j] * t1_
                dfl += WK[j] * t2_
            err = abs(ek - eg)
            tot += err
            if err > worst_err:
                worst_err = err
                worst = k
        est = tot / dfl if dfl > 0.0 else 0.0
        if est <= tol or npan >= EMT_MAX_PANELS or worst < 0:
            return s, est, n
        # split the worst panel: its left half replaces it, the right half is appended
        a0 = pt0[worst]
        a1 = pt1[worst]
        am = 0.5 * (a0 + a1)
        pt1[worst] = am
        _emt_fill_panel(qb, c, e, cum3, kinks, pbar, A1, a0, am, h_rms, gamma, ktab, glx, glw,
                        panel, almqvist, work, sig, hz, WK, WG, 15 * worst)
        pt0[npan] = am
        pt1[npan] = a1
        _emt_fill_panel(qb, c, e, cum3, kinks, pbar, A1, am, a1, h_rms, gamma, ktab, glx, glw,
                        panel, almqvist, work, sig, hz, WK, WG, 15 * npan)
        npan += 1


@njit(cache=True, parallel=True)
def emt_kernel(qb, c, e, cum3, kinks, pbar, h_rms, gamma, ktab, glx, glw, panel, almqvist, ghx,
               ghw, n_start, tol, sigma, percolated, err, nevals):
    """Bruggeman σ̄ = 12ησ_eff/h_rms³ per reduced pressure (u1-based P(u), SPEC §3)."""
    for i in prange(pbar.size):
        percolated[i] = _area1(cum3, pbar[i]) >= 0.5
        s, es, ne = emt_sigma(qb, c, e, cum3, kinks, pbar[i], h_rms, gamma, ktab, glx, glw, panel,
                              almqvist, ghx, ghw, n_start, tol)
        sigma[i] = s
        err[i] = es
        nevals[i] = ne


# --------------------------------------------------------------------------- reduced API
def sigma_bar(psd, pbar, theory, *, gamma=1.0, a_perc=0.5, alpha_cj=1.0, n_start=EMT_N_START,
              tol=EMT_TOL, almqvist=False, glx=None, glw=None, panel=PANEL):
    """Reduced conductivity σ̄ = 12ησ_eff/h_rms³ at reduced contact pressures p̄ = p/E*.

    Returns (sigma_bar, percolated, extra) with extra = dict of by-products (u_bar, u1c, ζc).
    """
    from ..contact import _separation  # local: avoid a cycle at import

    pbar = np.ascontiguousarray(np.asarray(pbar, dtype=np.float64).ravel())
    h = psd.h_rms
    if glx is None:
        glx, glw = gauss_legendre()
    arrs = _arrays(psd)
    ktab = k_table()
    extra = {}
    if theory == "average":
        u, _ = _separation(psd, pbar, 1.0, 1.0, gamma, glx, glw, panel)
        extra["u_bar"] = u / h
        return (u / h) ** 3, np.zeros(pbar.size, dtype=bool), extra
    if theory == "critical_junction":
        u1c = np.empty(pbar.size)
        zc = np.empty(pbar.size)
        perc = np.empty(pbar.size, dtype=np.bool_)
        critical_junction_kernel(*arrs, pbar, gamma, float(a_perc), ktab, glx, glw, float(panel),
                                 u1c, zc, perc)
        extra["u1c"] = u1c / h
        extra["zeta_c"] = zc
        return (alpha_cj * u1c / h) ** 3, perc, extra
    if theory == "emt":
        ghx, ghw = np.polynomial.hermite.hermgauss(GH_ORDER)
        sig = np.empty(pbar.size)
        perc = np.empty(pbar.size, dtype=np.bool_)
        err = np.empty(pbar.size)
        nev = np.empty(pbar.size, dtype=np.int64)
        emt_kernel(*arrs, pbar, h, gamma, ktab, glx, glw, float(panel), bool(almqvist), ghx, ghw,
                   int(n_start), float(tol), sig, perc, err, nev)
        extra["error_estimate"] = err
        extra["u1_evaluations"] = nev
        return sig, perc, extra
    check_theory(theory)


def conductivity(psd, p, E_star, eta, theory="average", *, gamma=1.0, a_perc=0.5,
                 alpha_cj=1.0, tol=EMT_TOL, almqvist=False):
    """Effective interfacial fluid conductivity σ_eff(p_cont) [m³/(Pa·s)] by direct quadrature.

    Parameters
    ----------
    psd : PSD          roughness spectrum
    p : array_like     contact pressure p_cont [Pa], > 0
    E_star : float     effective modulus [Pa]
    eta : float        fluid viscosity [Pa·s]
    theory : {"average", "critical_junction", "emt"}
    gamma : float      Yang–Persson factor of ū(ζ) and u1(ζ) (1 = paper)
    a_perc : float     critical-junction percolation area fraction (0.5 paper; 0.42 option)
    alpha_cj : float   critical-junction factor multiplying u1(ζc) (σ carries α_cj³)
    tol : float        target relative accuracy of the adaptive effective-medium integral
    almqvist : bool    Gaussian-broadened P(u) (Almqvist et al. 2011) in the effective medium

    Returns
    -------
    (sigma_eff [m³/(Pa·s)], percolated [bool]) arrays of p's shape; σ_eff = 0 exactly where
    percolated.
    """
    _check_psd(psd)
    check_theory(theory)
    p = check_positive("p", p, "[Pa]")
    E_star = float(check_positive("E_star", E_star, "[Pa]"))
    eta = check_positive("eta", eta, "[Pa·s]")
    gamma = _check_gamma(gamma)
    a_perc = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
    alpha_cj = float(check_positive("alpha_cj", alpha_cj, "[-]"))
    sb, perc, _ = sigma_bar(psd, np.ravel(p) / E_star, theory, gamma=gamma, a_perc=a_perc,
                            alpha_cj=alpha_cj, tol=tol, almqvist=almqvist)
    sig = sb.reshape(np.shape(p)) * psd.h_rms ** 3 / (12.0 * eta)
    return sig, perc.reshape(np.shape(p))


def flow_factor(psd, p, E_star, theory="emt", **options):
    """Pressure flow factor φ_p = 12ησ_eff/ū³ [-] (Patir & Cheng; paper Sec. 4)."""
    from ..contact import mean_separation

    sig, perc = conductivity(psd, p, E_star, 1.0, theory, **options)
    u = mean_separation(psd, p, E_star, gamma=options.get("gamma", 1.0))
    return 12.0 * sig / u ** 3, perc
