"""Numba quadrature of Persson's contact mechanics (App. A of Lorenz & Persson 2010).

The spectrum enters as a flat :class:`PSDKernel` record (the piecewise power-law arrays
``(qb, c, e, cum3)`` of :meth:`fastcontact.surface.psd.PSD.kernel_arrays` and the sorted
kinks); pressures are reduced, ``P = p/E*``.

Integrals over q in (A4) and its derivatives are taken in the variable
``τ = ln((q - a)/a)`` (``a = ζ q0``, the lower limit), i.e. ``q = a(1 + e^τ)``. This resolves
the ``(q - a)^{-1/2}`` divergence of ``w(q, ζ)`` at the lower limit at every
pressure: in τ the integrands decay exponentially on both sides. ``∫_a^q q'³C dq'`` is
evaluated in closed form from ``q - a`` (``expm1``/``log1p``), free of cancellation.
Composite Gauss–Legendre panels of width ``PANEL`` in τ, with panel boundaries at the
spectrum's kinks (the roll-off).

For one lower limit ``a`` and reduced pressure ``P = p(ζ)/E*`` the kernel returns
(all [m], the √π included)::

    I_F = √π ∫ q²C w F(wP) dq                     = ū(ζ)          (A4)
    I_g = √π ∫ q²C w g(wP) dq                     = -dū/d ln p(ζ)
    J   = √π ∫ q²C w³ (F(wP) - g(wP)) dq

and ``I_g' = dI_g/d ln P = √π ∫ q²C w s0 g'(s0) dq`` (so d²ū/d(ln p)² = -I_g'),
with ``F(s) = (γ/2) E1(s²) + 3(1-γ) K(s)`` and ``g(s) = [γ + 3(1-γ) erf²(s)] e^{-s²}``
(γ = 1 is the paper's A4; the Yang–Persson correction otherwise), so that (A3) becomes
``u1(ζ) = I_F + I_g + k(ζ) (A/A') J`` with ``k = (π/2) q0 (ζq0)³ C(ζq0)``.

References: B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010),
arXiv:1004.1037; C. Yang and B.N.J. Persson, J. Phys.: Condens. Matter 20,
215214 (2008), doi:10.1088/0953-8984/20/21/215214.
"""
from __future__ import annotations

import math

from typing import NamedTuple

import numpy as np
from numba import njit

from ..kernels.quadrature import (GL_ORDER, gauss_legendre, seg_moment as _seg_moment,
                                  seg_moment_at, seg_moment_constants)
from ..kernels.special import e1_and_exp, erfinv, k_eval

__all__ = ["PSDKernel", "psd_kernel", "GL_ORDER", "PANEL", "gauss_legendre", "separation_integrals",
           "area_state", "u1_at", "u1_at_area", "m1_above", "m3_between", "q_for_m3",
           "mean_separation_kernel", "u1_kernel", "contact_pressure_kernel", "asymptote_kernel"]

#: panel width in τ (see bench/bench_tables.py); GL_ORDER nodes per panel
PANEL = 1.0
#: s0² above which the integrands are negligible (e^{-64} ~ 1.6e-28)
S2_CUT = 64.0
#: panel grading: width = PANEL * clip(distance to the nearest feature / GRADE, 1, GRADE_MAX)
GRADE = 2.5
GRADE_MAX = 8.0
TAU_FLOOR = -300.0
#: narrow panels (cut short by a kink of the spectrum) take fewer nodes: Gauss–Legendre
#: with n nodes on a panel of width w errs as (w/2ρ)^(2n) for an integrand analytic within ρ
#: of the panel (the Bernstein-ellipse bound; L.N. Trefethen, SIAM Rev. 50, 67 (2008),
#: doi:10.1137/060659831), so n = ceil(n0 ln(2ρ/PANEL)/ln(2ρ/w)) keeps a narrow panel's bound
#: at that of a full one (n0 nodes, width PANEL; only where 2ρ > PANEL). A tabulated spectrum
#: has a kink at every sample, so its panels are mostly narrow. ρ = 2 measured against panels
#: of 0.25 with 20 nodes, on two synthetic road spectra (47 segments), a 400-point and a
#: 12-point table and two smooth spectra with a roll-off: the largest errors of ū, dū/d ln p
#: and σ̄ of each spectrum are unchanged (<= 4e-13 on the tables; 5e-10 and 1e-9 on the
#: smooth two, where both share them), d²ū/d(ln p)² <= 1e-11 (was 3e-13); single values may
#: move by up to 4e-10 (the roll-off kink's panels near s0 ~ 1). u1 is 1.75x faster on the
#: road spectra (80 -> 46 us). ρ = 1.5 was 1.1x faster still but lost ū to 2e-12 on the
#: tables.
ANALYTIC_RADIUS = 2.0
#: the fewest nodes of a narrow panel
NARROW_MIN_ORDER = 2
_NARROW_X = np.zeros((GL_ORDER + 1, GL_ORDER))
_NARROW_W = np.zeros((GL_ORDER + 1, GL_ORDER))
for _n in range(1, GL_ORDER + 1):
    _NARROW_X[_n, :_n], _NARROW_W[_n, :_n] = gauss_legendre(_n)

SQRT_PI = math.sqrt(math.pi)


class PSDKernel(NamedTuple):
    """A spectrum as plain arrays for the kernels (Persson convention, SI).

    Attributes
    ----------
    qb : ndarray
        Segment boundaries q0 = qb[0] < ... < qb[-1] = q1 [1/m].
    c : ndarray
        C(q) at each segment start [m⁴].
    e : ndarray
        Power-law exponent of each segment [-].
    cum3 : ndarray
        ∫_{q0}^{qb[i]} q³ C dq at the boundaries [1/m²].
    kinks : ndarray
        Sorted wavenumbers where C(q) has a kink (panel breaks) [1/m].
    """

    qb: np.ndarray
    c: np.ndarray
    e: np.ndarray
    cum3: np.ndarray
    kinks: np.ndarray


def psd_kernel(psd) -> PSDKernel:
    """The :class:`PSDKernel` record of a :class:`~fastcontact.surface.psd.PSD`."""
    qb, c, e, cum3 = psd.kernel_arrays()
    kinks = np.ascontiguousarray(np.sort(np.asarray(psd.kinks, dtype=np.float64)))
    return PSDKernel(qb, c, e, cum3, kinks)


@njit(cache=True)
def seg_index(qb, q):
    """Index i of the segment [qb[i], qb[i+1]] holding q (clipped to the valid range)."""
    i = np.searchsorted(qb, q, side="right") - 1
    if i < 0:
        return 0
    if i > qb.size - 2:
        return qb.size - 2
    return i


@njit(cache=True)
def psd_value(qb, c, e, q):
    """C(q) [m⁴] of the piecewise power law."""
    i = seg_index(qb, q)
    return c[i] * (q / qb[i]) ** e[i]


@njit(cache=True)
def m3_from(qb, c, e, cum3, a, ia, delta):
    """∫_a^{a(1+δ)} q³ C dq for a in segment ia, accurate for tiny δ."""
    q = a * (1.0 + delta)
    end = qb[ia + 1]
    if q <= end:
        return _seg_moment(c[ia], qb[ia], e[ia], 3.0, a, math.log1p(delta))
    tot = _seg_moment(c[ia], qb[ia], e[ia], 3.0, a, math.log(end / a))
    j = seg_index(qb, q)
    tot += cum3[j] - cum3[ia + 1]
    tot += _seg_moment(c[j], qb[j], e[j], 3.0, qb[j], math.log(q / qb[j]))
    return tot


@njit(cache=True)
def m3_between(qb, c, e, cum3, a, b):
    """∫_a^b q³ C dq (0 if b <= a)."""
    if b <= a:
        return 0.0
    return m3_from(qb, c, e, cum3, a, seg_index(qb, a), (b - a) / a)


@njit(cache=True)
def m1_above(qb, c, e, a):
    """∫_a^{q1} q C dq."""
    q1 = qb[-1]
    if a >= q1:
        return 0.0
    ia = seg_index(qb, a)
    tot = _seg_moment(c[ia], qb[ia], e[ia], 1.0, a, math.log(qb[ia + 1] / a))
    for j in range(ia + 1, c.size):
        tot += _seg_moment(c[j], qb[j], e[j], 1.0, qb[j], math.log(qb[j + 1] / qb[j]))
    return tot


@njit(cache=True)
def q_for_m3(qb, c, e, cum3, target):
    """The q with ∫_{q0}^q q'³ C dq' = target (inverse of the cumulative moment)."""
    if target <= 0.0:
        return qb[0]
    if target >= cum3[-1]:
        return qb[-1]
    j = np.searchsorted(cum3, target, side="right") - 1
    if j > c.size - 1:
        j = c.size - 1
    rem = target - cum3[j]
    a = qb[j]
    k = 4.0 + e[j]
    base = c[j] * a ** 4
    if abs(k) < 1e-12:
        lr = rem / base
    else:
        lr = math.log1p(k * rem / base) / k
    q = a * math.exp(lr)
    if q > qb[j + 1]:
        q = qb[j + 1]
    return q


@njit(cache=True)
def clip_at_kink(kinks, ik, a, q1, t0, t1):
    """End of the panel [t0, t1] in τ = ln(q/a - 1), clipped at the next (sorted) kink.

    Returns (t1, ik) with ik advanced past kinks at or before t0.
    """
    while ik < kinks.size:
        qk = kinks[ik]
        if qk <= a or qk >= q1:
            ik += 1
            continue
        tk = math.log(qk / a - 1.0)
        if tk <= t0 + 1e-12:
            ik += 1
            continue
        if tk < t1:
            t1 = tk
        break
    return t1, ik


@njit(cache=True)
def f_and_g(s0, gamma, kt0, kdt, kval, kder, rdt, rval, rder):
    """F(s0) and g(s0) of the module docstring."""
    x = s0 * s0
    if gamma == 1.0:
        e1x, ex = e1_and_exp(x)
        return 0.5 * e1x, ex
    e1x, ex = e1_and_exp(x)
    ef = math.erf(s0)
    F = 0.5 * gamma * e1x + 3.0 * (1.0 - gamma) * k_eval(s0, kt0, kdt, kval, kder, rdt, rval, rder)
    g = (gamma + 3.0 * (1.0 - gamma) * ef * ef) * ex
    return F, g


@njit(cache=True)
def _tau_lower(qb, c, e, cum3, a, ia, ca, P, tau_hi):
    """Lower end in τ of the (A4) integrals: where s0² = S2_CUT (linearised w, then checked
    with the exact moment), at most tau_hi - 1e-3 and at least TAU_FLOOR."""
    dlo = P * P / (math.pi * a ** 3 * ca * S2_CUT)
    tau_lo = math.log(dlo / a)
    if tau_lo > tau_hi - 1e-3:
        tau_lo = tau_hi - 1e-3
    while tau_lo > TAU_FLOOR:
        m = m3_from(qb, c, e, cum3, a, ia, math.exp(tau_lo))
        if P * P / (math.pi * m) >= S2_CUT:
            break
        tau_lo -= 1.0
    if tau_lo < TAU_FLOOR:
        tau_lo = TAU_FLOOR
    return tau_lo


@njit(cache=True)
def _panel_order(width, panel, order_num, glx, glw, xs, ws):
    """Nodes of a panel of ``width`` in τ (:data:`ANALYTIC_RADIUS`), its rule copied into xs, ws.

    The given rule (glx, glw) where the panel is full-width or the reduced order would not be
    lower, else the Gauss–Legendre rule of the reduced order."""
    ng = glx.size
    nn = ng
    if width < panel and ng > NARROW_MIN_ORDER and order_num > 0.0:  # (2ρ > panel)
        den = math.log(2.0 * ANALYTIC_RADIUS / width)
        if den > 0.0:
            nn = max(NARROW_MIN_ORDER, int(math.ceil(order_num / den)))
    if nn >= ng or nn > GL_ORDER:
        for j in range(ng):
            xs[j] = glx[j]
            ws[j] = glw[j]
        return ng
    for j in range(nn):
        xs[j] = _NARROW_X[nn, j]
        ws[j] = _NARROW_W[nn, j]
    return nn


@njit(cache=True)
def separation_integrals(sk, a, P, gamma, ktab, glx, glw, panel, out):
    """(I_F, I_g, J, I_g') for lower limit ``a`` [1/m] and reduced pressure P into out[0:4] [m].

    ``sk`` is a :class:`PSDKernel`; ``I_g' = √π ∫ q²C w s0 g'(s0) dq = dI_g/d ln P``, so
    ``d²ū/d(ln p)² = -I_g'``.
    """
    qb, c, e, cum3, kinks = sk
    kt0, kdt, kval, kder, rdt, rval, rder = ktab
    for i in range(4):
        out[i] = 0.0
    q1 = qb[-1]
    if a >= q1 or P <= 0.0:
        return
    tau_hi = math.log(q1 / a - 1.0)
    ia = seg_index(qb, a)
    # the first (partial) segment's closed-form moment: pref * expm1(k ln(q/a)) / k
    pref3, k3 = seg_moment_constants(c[ia], qb[ia], e[ia], 3.0, a)
    end_ia = qb[ia + 1]
    lna = math.log(a)
    ca = c[ia] * (a / qb[ia]) ** e[ia]
    tau_lo = _tau_lower(qb, c, e, cum3, a, ia, ca, P, tau_hi)
    # panels, graded: width `panel` near the two features of the integrands (s0 ~ 1 at
    # tau_1, and q - a ~ a at tau = 0), growing to GRADE_MAX * panel away from them where
    # the integrands are smooth exponentials in tau; split at kinks
    tau_1 = math.log(P * P / (math.pi * a ** 4 * ca))
    ik = 0
    t0 = tau_lo
    sF = 0.0
    sg = 0.0
    sJ = 0.0
    sG = 0.0
    ng = glx.size
    xs = np.empty(ng)
    ws = np.empty(ng)
    # per node of a panel: δ = q/a - 1, ln(1 + δ), C(q), the moment m(q)
    dl = np.empty(ng)
    lp = np.empty(ng)
    cq = np.empty(ng)
    mm = np.empty(ng)
    order_num = ng * math.log(2.0 * ANALYTIC_RADIUS / panel)
    iq = ia  # segment of the current node (nodes increase monotonically)
    lnqb = math.log(qb[ia])
    seg_pref, seg_k = seg_moment_constants(c[ia], qb[ia], e[ia], 3.0, qb[ia])
    m_first = seg_moment_at(pref3, k3, math.log(end_ia / a))  # the whole first segment
    while t0 < tau_hi:
        dist = min(abs(t0 - tau_1), abs(t0))
        width = panel * min(max(1.0, dist / GRADE), GRADE_MAX)
        t1 = t0 + width
        if t1 > tau_hi:
            t1 = tau_hi
        t_end = t1
        t1, ik = clip_at_kink(kinks, ik, a, q1, t0, t1)
        half = 0.5 * (t1 - t0)
        mid = 0.5 * (t1 + t0)
        # fewer nodes only on a panel cut short by a kink (not by the upper limit)
        nn = _panel_order(t1 - t0 if t1 < t_end else panel, panel, order_num, glx, glw, xs, ws)
        # the nodes in stages, each a loop over the panel's nodes: the libm calls of one stage
        # (exp, log1p; the moment's expm1 and C(q)'s exp) are independent across nodes, so the
        # processor overlaps them, where one long chain per node left it waiting (u1 quadrature
        # on the road spectrum 1.3-1.6x faster, bit for bit the same sums: every value is
        # computed as before and accumulated in the same order)
        for j in range(nn):
            dl[j] = math.exp(mid + half * xs[j])
        for j in range(nn):
            lp[j] = math.log1p(dl[j])
        for j in range(nn):
            q = a * (1.0 + dl[j])
            while iq < qb.size - 2 and q > qb[iq + 1]:
                iq += 1
                lnqb = math.log(qb[iq])
                seg_pref, seg_k = seg_moment_constants(c[iq], qb[iq], e[iq], 3.0, qb[iq])
            lr = lna + lp[j] - lnqb
            cq[j] = c[iq] * math.exp(e[iq] * lr)
            if q <= end_ia:
                mm[j] = seg_moment_at(pref3, k3, lp[j])
            else:  # the segment's constants hoisted out of seg_moment
                mm[j] = m_first + cum3[iq] - cum3[ia + 1] + seg_moment_at(seg_pref, seg_k, lr)
        for j in range(nn):
            delta = dl[j]
            q = a * (1.0 + delta)
            w = 1.0 / math.sqrt(math.pi * mm[j])
            s0 = w * P
            F, g = f_and_g(s0, gamma, kt0, kdt, kval, kder, rdt, rval, rder)
            wt = ws[j] * half * a * delta * q * q * cq[j] * w
            sF += wt * F
            sg += wt * g
            sJ += wt * w * w * (F - g)
            x = s0 * s0
            if gamma == 1.0:
                sgp = -2.0 * x * g  # s g'(s) for g = e^{-s²}
            else:
                sgp = (3.0 * (1.0 - gamma) * 4.0 / SQRT_PI * s0 * math.erf(s0) * math.exp(-2.0 * x)
                       - 2.0 * x * g)
            sG += wt * sgp
        t0 = t1
    out[0] = SQRT_PI * sF
    out[1] = SQRT_PI * sg
    out[2] = SQRT_PI * sJ
    out[3] = SQRT_PI * sG


@njit(cache=True)
def area_state(sk, a, pbar):
    """(A(ζ)/A0, A/A' [ζ units], P = p(ζ)/E*) at lower limit a = ζ q0 (A1, A2 of the paper).

    A/A' is -inf where dA/dζ underflows (ζ = 1, or p/(2√G) > 26): u1 is undefined there.
    """
    qb, c, e, cum3 = sk.qb, sk.c, sk.e, sk.cum3
    q0 = qb[0]
    if a <= q0:
        return 1.0, -math.inf, pbar
    m = m3_between(qb, c, e, cum3, q0, a)
    G = 0.25 * math.pi * m  # G / E*²
    x = pbar / (2.0 * math.sqrt(G))
    A = math.erf(x)
    gp_over_g = q0 * a ** 3 * psd_value(qb, c, e, a) / m
    if x * x > 700.0 or A == 0.0:
        ratio = -math.inf if A > 0.0 else 0.0
    else:
        ratio = -SQRT_PI * A * math.exp(x * x) / (x * gp_over_g)
    return A, ratio, pbar / A if A > 0.0 else math.inf


@njit(cache=True)
def u1_at(sk, a, pbar, gamma, ktab, glx, glw, panel, work):
    """u1(ζ) [m] (A3) at a = ζq0 for reduced nominal pressure pbar; inf where masked."""
    A, ratio, P = area_state(sk, a, pbar)
    if not (ratio > -math.inf) or A <= 0.0:
        return math.inf
    separation_integrals(sk, a, P, gamma, ktab, glx, glw, panel, work)
    k = 0.5 * math.pi * sk.qb[0] * a ** 3 * psd_value(sk.qb, sk.c, sk.e, a)
    return work[0] + work[1] + k * ratio * work[2]


@njit(cache=True)
def u1_at_area(sk, area, pbar, gamma, ktab, glx, glw, panel, work):
    """u1 [m] at the magnification where A(ζ)/A0 = area (exact, no ζ round-off).

    Returns (u1, a = ζ q0). ``area`` must be in (A(ζ1)/A0, 1).
    """
    qb, c, e, cum3 = sk.qb, sk.c, sk.e, sk.cum3
    x = erfinv(area)
    G = (pbar / (2.0 * x)) ** 2
    target = 4.0 * G / math.pi
    a = q_for_m3(qb, c, e, cum3, target)
    gp_over_g = qb[0] * a ** 3 * psd_value(qb, c, e, a) / target
    ratio = -SQRT_PI * area * math.exp(x * x) / (x * gp_over_g)
    P = pbar / area
    separation_integrals(sk, a, P, gamma, ktab, glx, glw, panel, work)
    k = 0.5 * math.pi * qb[0] * a ** 3 * psd_value(qb, c, e, a)
    return work[0] + work[1] + k * ratio * work[2], a


# --------------------------------------------------------------------------- drivers
@njit(cache=True)
def mean_separation_kernel(sk, pbar, zeta, gamma, ktab, glx, glw, panel, out, dout, d2out):
    """ū(ζ) [m], dū/d ln p [m] and d²ū/d(ln p)² [m] per (reduced pressure, ζ) (A4)."""
    work = np.empty(4)
    q0 = sk.qb[0]
    for i in range(pbar.size):
        a = zeta[i] * q0
        A, ratio, P = area_state(sk, a, pbar[i])
        separation_integrals(sk, a, P, gamma, ktab, glx, glw, panel, work)
        out[i] = work[0]
        dout[i] = -work[1]
        d2out[i] = -work[3]


@njit(cache=True)
def u1_kernel(sk, pbar, zeta, gamma, ktab, glx, glw, panel, out):
    """u1(ζ) [m] per (reduced pressure, ζ) (A3); inf where dA/dζ underflows."""
    work = np.empty(4)
    q0 = sk.qb[0]
    for i in range(pbar.size):
        out[i] = u1_at(sk, zeta[i] * q0, pbar[i], gamma, ktab, glx, glw, panel, work)


@njit(cache=True)
def contact_pressure_kernel(sk, ubar, lnp_guess, gamma, ktab, glx, glw, panel, out):
    """Solve ū(p) = u for ln p̄ by safeguarded Newton (ū decreasing, dū/d ln p = -I_g)."""
    work = np.empty(4)
    q0 = sk.qb[0]
    for i in range(ubar.size):
        target = ubar[i]
        lo = -745.0
        hi = 50.0
        x = lnp_guess[i]
        if x < lo or x > hi:
            x = 0.5 * (lo + hi)
        for it in range(200):
            separation_integrals(sk, q0, math.exp(x), gamma, ktab, glx, glw, panel, work)
            f = work[0] - target
            if f > 0.0:
                lo = x
            else:
                hi = x
            d = -work[1]
            step = f / d if d < 0.0 else 0.0
            xn = x - step
            if not (lo < xn < hi) or d >= 0.0:
                xn = 0.5 * (lo + hi)
            if abs(xn - x) < 1e-14 * max(1.0, abs(x)) or hi - lo < 1e-14:
                x = xn
                break
            x = xn
        out[i] = x


@njit(cache=True)
def asymptote_kernel(sk, glx, glw, panel):
    """(√π ∫ q²C w dq [m], ∫ q²C w ln w dq / ∫ q²C w dq) at ζ = 1 (small-p limit of A4)."""
    qb, c, e, cum3, kinks = sk
    a = qb[0]
    ia = 0
    tau_hi = math.log(qb[-1] / a - 1.0)
    t0 = -120.0
    s0 = 0.0
    s1 = 0.0
    ik = 0
    while t0 < tau_hi:
        t1, ik = clip_at_kink(kinks, ik, a, qb[-1], t0, min(t0 + panel, tau_hi))
        half = 0.5 * (t1 - t0)
        mid = 0.5 * (t1 + t0)
        for j in range(glx.size):
            tau = mid + half * glx[j]
            delta = math.exp(tau)
            q = a * (1.0 + delta)
            w = 1.0 / math.sqrt(math.pi * m3_from(qb, c, e, cum3, a, ia, delta))
            wt = glw[j] * half * a * delta * q * q * psd_value(qb, c, e, q) * w
            s0 += wt
            s1 += wt * math.log(w)
        t0 = t1
    return math.sqrt(math.pi) * s0, s1 / s0
