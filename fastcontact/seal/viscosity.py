"""Seal leak rate with a pressure-dependent (Barus) viscosity η = η0 exp(α (p_f - p_b)).

Steady 1-D flow across the seal width (paper Sec. 6, eqs. 25–33) with η(p_f): the flux per
unit length is q = -(σ0(p_cont)/e^{α(p_f - p_b)}) dp_f/dx = -σ0(p_cont) dψ/dx, with the
conductivity σ0 at the outlet viscosity η0 and the reduced pressure
ψ = (1 - e^{-α(p_f - p_b)})/α. If σ0 did not depend on p_f, Q would follow from
ψ(p_a) - ψ(p_b) alone — but p_cont = p0(x) - p_f couples it back (docs/theory/extensions.md §2):

* **uniform ring** (p0 fixed): dp_f/dx = -q e^{α(p_f - p_b)}/σ0(p0 - p_f) separates, and
  ``q L = ∫_{p_b}^{p_a} σ0(p0 - p) e^{-α(p - p_b)} dp`` exactly (α = 0: the paper's result
  ``q = (1/L)∫σ_eff dp``). Evaluated by Gauss–Legendre in ln p_cont on the tables.
* **Hertz O-ring** (p0(x) = p_H √(1 - ((x-a)/a)²)): dψ/dx = -q/σ0(p0(x) - p_f(ψ)) has no
  closed form; it is solved by shooting on q (RK4 in θ, x = a(1 - cos θ), on steps
  graded towards both zone ends, bracketed Illinois iteration on ln q) over the sealing zone p0(x) >= p_f.

In both, ``p_f(ψ) = p_b - ln(1 - αψ)/α``; ψ < 1/α always since ψ_a = ψ(p_a) < 1/α.

**Roelands** (``viscosity="roelands"``, :mod:`fastcontact.flow.piezoviscosity`):
ln(η/η0) = A[(1 + (p_f - p_b)/p_r)^Z - 1]. The reduced-pressure trick does **not** carry
over: ψ(p) = ∫η0/η dp is an incomplete gamma function with no closed-form inverse, and
p_cont = p0(x) - p_f needs p_f(ψ). So

* uniform ring: the separated equation holds for any η(p),
  ``q L = ∫_{p_b}^{p_a} σ0(p0 - p) η0/η(p) dp`` (same quadrature, Roelands weight);
* Hertz O-ring: the Reynolds equation is integrated in p_f itself,
  dp_f/dθ = -k a sin θ (η(p_f)/η0)/σ̄((p_H sin θ - p_f)/E*), by the same graded RK4 and
  shooting on k (no ψ anywhere).

References: C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87;
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 31, 159 (2010), arXiv:0911.3019.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
from numba import njit, prange

from .._core.validate import check_positive
from ..flow.piezoviscosity import (ROELANDS_ETA_INF, check_law, ln_roelands,
                                   roelands_parameters)
from ..tables import k_sigma_of_lnp

__all__ = ["HERTZ_STEPS", "TAIL_CUT", "seal_leak_piezo"]

#: the uniform-ring quadrature starts TAIL_CUT below ln(p_cont_min/E*) of the table (integrand ∝ p_cont)
TAIL_CUT = 60.0
#: RK4 steps across the Hertz sealing zone (graded; error <= ~1e-8 against an adaptive
#: DOP853 shooting reference, bench/bench_extensions.py)
HERTZ_STEPS = 200


# =========================================================================== kernels
@njit(cache=True)
def _sigma(tab, sc, x):
    """σ̄ at ln p̄ = x: the tables, or below them the eq. (3) tail with σ̄ ∝ ū³."""
    if x < sc[0]:
        v = sc[1] + sc[2] * (sc[0] - x)
        return math.exp(sc[3]) * (v / sc[1]) ** 3
    if x >= sc[5]:
        return 0.0
    return k_sigma_of_lnp(tab, x)


@njit(cache=True)
def _ln_eta(p, A, Z, pr):
    """ln(η/η0) at p >= 0 above the outlet: Barus (pr = 0: A = α, ln = α p) or Roelands."""
    if pr == 0.0:
        return A * p
    return ln_roelands(p, A, Z, pr)


@njit(cache=True)
def _uniform_integral(tab, sc, E, p0, pa, pb, A, Z, pr, glx, glw, width):
    """∫_{p_b}^{p_a} σ̄(p0 - p) η0/η(p - p_b) dp [Pa], in x = ln((p0 - p)/E*); the viscosity law
    as in :func:`_ln_eta` (Barus: e^{-α(p - p_b)})."""
    xb = math.log((p0 - pb) / E)
    if pa >= p0:
        xa = sc[0] - TAIL_CUT
    else:
        xa = math.log((p0 - pa) / E)
        xa = max(xa, sc[0] - TAIL_CUT)
    if not xb > xa:
        return 0.0
    m = max(1, int(math.ceil((xb - xa) / width)))
    hw = (xb - xa) / m
    s = 0.0
    for k in range(m):
        mid = xa + (k + 0.5) * hw
        for j in range(glx.size):
            x = mid + 0.5 * hw * glx[j]
            pc = E * math.exp(x)
            s += 0.5 * hw * glw[j] * _sigma(tab, sc, x) * pc * math.exp(
                -_ln_eta(max(p0 - pb - pc, 0.0), A, Z, pr))
    return s


@njit(parallel=True, cache=True)
def _uniform_kernel(tab, sc, p0, L, pa, pb, E, A, Z, pr, glx, glw, width, out):
    """q = (1/L) ∫ σ̄ η0/η dp of each ring (pr = 0: Barus with A = α, Z unused)."""
    for i in prange(p0.size):
        out[i] = _uniform_integral(tab, sc, E[i], p0[i], pa[i], pb[i], A[i], Z[i], pr, glx,
                                   glw, width) / L[i]


@njit(cache=True)
def _pf(psi, pb, alpha):
    if alpha == 0.0:
        return pb + psi
    return pb - math.log1p(-alpha * psi) / alpha


@njit(cache=True)
def _rhs(tab, sc, E, pH, a, th, psi, pb, alpha, k):
    """dψ/dθ = -k a sin θ / σ̄((p0(θ) - p_f(ψ))/E*); 0 in an open pocket (p_cont <= 0)."""
    pc = pH * math.sin(th) - _pf(psi, pb, alpha)
    if pc <= 0.0:
        return 0.0
    s = _sigma(tab, sc, math.log(pc / E))
    if s <= 0.0:
        return -1e300
    return -k * a * math.sin(th) / s


@njit(cache=True)
def _shoot(tab, sc, E, pH, a, th_s, th_e, psi_a, pb, alpha, k, n):
    """ψ at the outlet end θ_e for flux parameter k = 12η0 q/h³ [Pa/m].

    RK4 with n steps in t ∈ [0, 1], θ = θ_s + (θ_e - θ_s)(3t² - 2t³): the steps shrink
    quadratically at both zone ends, where p_cont → 0 and σ0 grows like ln³(1/p_cont).
    """
    h = 1.0 / n
    span = th_e - th_s
    psi = psi_a
    for i in range(n):
        t0 = i * h
        k1 = _rhs_t(tab, sc, E, pH, a, th_s, span, t0, psi, pb, alpha, k)
        k2 = _rhs_t(tab, sc, E, pH, a, th_s, span, t0 + 0.5 * h, psi + 0.5 * h * k1, pb, alpha, k)
        k3 = _rhs_t(tab, sc, E, pH, a, th_s, span, t0 + 0.5 * h, psi + 0.5 * h * k2, pb, alpha, k)
        k4 = _rhs_t(tab, sc, E, pH, a, th_s, span, t0 + h, psi + h * k3, pb, alpha, k)
        psi += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
        if psi < -10.0 * psi_a or psi != psi:
            return -10.0 * psi_a
    return psi


@njit(cache=True)
def _rhs_t(tab, sc, E, pH, a, th_s, span, t, psi, pb, alpha, k):
    th = th_s + span * t * t * (3.0 - 2.0 * t)
    return _rhs(tab, sc, E, pH, a, th, psi, pb, alpha, k) * span * 6.0 * t * (1.0 - t)


@njit(cache=True)
def _hertz_case(tab, sc, E, pH, a, pa, pb, alpha, n):
    """(k, converged) for one Hertz case; k = 12 η0 q / h³ [Pa/m]."""
    psi_a = pa - pb if alpha == 0.0 else -math.expm1(-alpha * (pa - pb)) / alpha
    th_s = math.asin(min(1.0, pa / pH))
    th_e = math.pi - math.asin(min(1.0, pb / pH))
    # initial guess: ψ_a over the resistance of the dry profile, then bracket in ln k
    smid = _sigma(tab, sc, math.log(max(pH - 0.5 * (pa + pb), 1e-300) / E))
    y = math.log(psi_a * max(smid, 1e-300) / (2.0 * a))
    f = _shoot(tab, sc, E, pH, a, th_s, th_e, psi_a, pb, alpha, math.exp(y), n)
    lo = y
    hi = y
    flo = f
    fhi = f
    step = 2.0
    for _ in range(400):
        if flo > 0.0 and fhi < 0.0:
            break
        if f > 0.0:
            hi = lo + step
            fhi = _shoot(tab, sc, E, pH, a, th_s, th_e, psi_a, pb, alpha, math.exp(hi), n)
            if fhi > 0.0:
                lo, flo = hi, fhi
        else:
            lo = hi - step
            flo = _shoot(tab, sc, E, pH, a, th_s, th_e, psi_a, pb, alpha, math.exp(lo), n)
            if flo < 0.0:
                hi, fhi = lo, flo
        f = flo if flo > 0.0 else fhi
        step *= 1.5
    if not (flo > 0.0 and fhi < 0.0):
        return math.nan, False
    side = 0
    for _ in range(200):                      # Illinois (regula falsi) in ln k
        y = (lo * fhi - hi * flo) / (fhi - flo)
        f = _shoot(tab, sc, E, pH, a, th_s, th_e, psi_a, pb, alpha, math.exp(y), n)
        if f > 0.0:
            lo, flo = y, f
            if side == 1:
                fhi *= 0.5
            side = 1
        else:
            hi, fhi = y, f
            if side == -1:
                flo *= 0.5
            side = -1
        if hi - lo < 1e-13 or abs(f) <= 1e-14 * psi_a:
            return math.exp(y), True
    return math.exp(y), False


@njit(parallel=True, cache=True)
def _hertz_kernel(tab, sc, E, pH, a, pa, pb, alpha, n, k, ok):
    for i in prange(E.size):
        k[i], ok[i] = _hertz_case(tab, sc, E[i], pH[i], a[i], pa[i], pb[i], alpha[i], n)


# =========================================================================== Roelands
@njit(cache=True)
def _rhs_r(tab, sc, E, pH, a, th_s, span, t, p, pb, A, Z, pr, k):
    """dp_f/dt = -k a sin θ (η/η0)/σ̄(p0(θ) - p_f) dθ/dt; 0 in an open pocket."""
    th = th_s + span * t * t * (3.0 - 2.0 * t)
    pc = pH * math.sin(th) - p
    if pc <= 0.0:
        return 0.0
    s = _sigma(tab, sc, math.log(pc / E))
    if s <= 0.0:
        return -1e300
    lv = ln_roelands(max(p - pb, 0.0), A, Z, pr)
    return -k * a * math.sin(th) * math.exp(lv) / s * span * 6.0 * t * (1.0 - t)


@njit(cache=True)
def _shoot_r(tab, sc, E, pH, a, th_s, th_e, pa, pb, A, Z, pr, k, n):
    """p_f - p_b at the outlet end θ_e for k = 12 η0 q / h³ (RK4 on the graded t of _shoot)."""
    h = 1.0 / n
    span = th_e - th_s
    p = pa
    floor = pb - 10.0 * (pa - pb)
    for i in range(n):
        t0 = i * h
        k1 = _rhs_r(tab, sc, E, pH, a, th_s, span, t0, p, pb, A, Z, pr, k)
        k2 = _rhs_r(tab, sc, E, pH, a, th_s, span, t0 + 0.5 * h, p + 0.5 * h * k1, pb, A, Z, pr, k)
        k3 = _rhs_r(tab, sc, E, pH, a, th_s, span, t0 + 0.5 * h, p + 0.5 * h * k2, pb, A, Z, pr, k)
        k4 = _rhs_r(tab, sc, E, pH, a, th_s, span, t0 + h, p + h * k3, pb, A, Z, pr, k)
        p += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
        if p < floor or p != p:
            return floor - pb
    return p - pb


@njit(cache=True)
def _hertz_case_r(tab, sc, E, pH, a, pa, pb, A, Z, pr, n):
    """(k, converged) of one Hertz case with a Roelands fluid (bracket + Illinois in ln k)."""
    dpa = pa - pb
    th_s = math.asin(min(1.0, pa / pH))
    th_e = math.pi - math.asin(min(1.0, pb / pH))
    smid = _sigma(tab, sc, math.log(max(pH - 0.5 * (pa + pb), 1e-300) / E))
    y = math.log(dpa * max(smid, 1e-300) / (2.0 * a))
    f = _shoot_r(tab, sc, E, pH, a, th_s, th_e, pa, pb, A, Z, pr, math.exp(y), n)
    lo = y
    hi = y
    flo = f
    fhi = f
    step = 2.0
    for _ in range(400):
        if flo > 0.0 and fhi < 0.0:
            break
        if f > 0.0:
            hi = lo + step
            fhi = _shoot_r(tab, sc, E, pH, a, th_s, th_e, pa, pb, A, Z, pr, math.exp(hi), n)
            if fhi > 0.0:
                lo, flo = hi, fhi
        else:
            lo = hi - step
            flo = _shoot_r(tab, sc, E, pH, a, th_s, th_e, pa, pb, A, Z, pr, math.exp(lo), n)
            if flo < 0.0:
                hi, fhi = lo, flo
        f = flo if flo > 0.0 else fhi
        step *= 1.5
    if not (flo > 0.0 and fhi < 0.0):
        return math.nan, False
    side = 0
    for _ in range(200):
        y = (lo * fhi - hi * flo) / (fhi - flo)
        f = _shoot_r(tab, sc, E, pH, a, th_s, th_e, pa, pb, A, Z, pr, math.exp(y), n)
        if f > 0.0:
            lo, flo = y, f
            if side == 1:
                fhi *= 0.5
            side = 1
        else:
            hi, fhi = y, f
            if side == -1:
                flo *= 0.5
            side = -1
        if hi - lo < 1e-13 or abs(f) <= 1e-14 * dpa:
            return math.exp(y), True
    return math.exp(y), False


@njit(parallel=True, cache=True)
def _hertz_kernel_r(tab, sc, E, pH, a, pa, pb, A, Z, pr, n, k, ok):
    for i in prange(E.size):
        k[i], ok[i] = _hertz_case_r(tab, sc, E[i], pH[i], a[i], pa[i], pb[i], A[i], Z[i], pr, n)


# =========================================================================== API
def _scalars(tables, theory):
    """(x_min, v_top, u0, ln σ̄_top, x_max, x_perc) of (tables, theory)."""
    p_lo, p_hi = tables.p_range
    d = 1e-4
    v = tables.mean_separation(np.array([p_lo, p_lo * math.exp(d)]), 1.0) / tables.h_rms
    perc = tables.info["percolation_p_over_E"][theory]
    return np.array([math.log(p_lo), v[0], (v[0] - v[1]) / d,
                     math.log(float(tables.sigma_bar(p_lo, 1.0, theory))), math.log(p_hi),
                     math.log(perc) if np.isfinite(perc) else math.inf])


def seal_leak_piezo(tables, *, dp, L_y, E_star, eta, alpha_pv, theory="critical_junction",
                    alpha_cj=1.0, p_b=0.0, profile="uniform", p0=None, L=None, R=None, f_N=None,
                    quad_order=10, quad_width=0.5, steps=HERTZ_STEPS, viscosity="barus",
                    roelands_z=None, roelands_p_r=None, roelands_eta_inf=None):
    """Leak rate Q [m³/s] of a seal with a Barus or Roelands fluid, uniform ring or O-ring.

    Parameters
    ----------
    tables : Tables
        Tables of the rough surface holding ``theory``.
    dp : array_like
        Pressure difference p_a - p_b [Pa], >= 0.
    L_y : array_like
        Seal length (circumference) [m].
    E_star : array_like
        Effective modulus [Pa].
    eta : array_like
        Viscosity η0 at the outlet pressure p_b [Pa·s].
    alpha_pv : array_like
        Pressure–viscosity coefficient α [1/Pa], >= 0; η = η0 exp(α (p_f - p_b)) (Barus).
        Roelands: the initial slope d ln η/dp at p_b, which sets Z = α p_r/ln(η0/η_∞) when
        ``roelands_z`` is None.
    theory : str
        Flow theory of σ_eff (must be in the tables).
    alpha_cj : array_like
        Critical-junction factor [-]: σ ∝ α_cj³, so Q is rescaled by (α_cj/α_table)³
        exactly (q is linear in σ in both profiles); ignored by the other theories.
    p_b : array_like
        Outlet gauge pressure [Pa], >= 0.
    profile : {"uniform", "hertz"}
        Flat ring (needs ``p0`` [Pa], ``L`` [m]) or O-ring (needs ``R`` [m], ``f_N`` [N/m]).
    quad_order, quad_width : int, float
        Gauss–Legendre order and panel width in ln p_cont (uniform ring).
    steps : int
        RK4 steps across the Hertz sealing zone.
    viscosity : {"barus", "roelands"}
        Viscosity law (module docstring; :mod:`fastcontact.flow.piezoviscosity`). Roelands:
        ln(η/η0) = ln(η0/η_∞)[(1 + (p_f - p_b)/p_r)^Z - 1], solved without the reduced
        pressure (it does not apply).
    roelands_z : array_like or None
        Roelands pressure–viscosity index Z [-] >= 0 (None: from ``alpha_pv``).
    roelands_p_r : float or None
        Roelands reference pressure p_r [Pa] (None: 1/5.1e-9 ≈ 1.96e8, Hamrock & Dowson).
    roelands_eta_inf : float or None
        Roelands limiting viscosity η_∞ [Pa·s] (None: e^-9.67 ≈ 6.3e-5); ``eta`` must exceed it.

    Returns
    -------
    pandas.DataFrame
        ``Q`` [m³/s] (inf beyond lift-off, 0 if percolated or dp = 0), ``open_inlet``,
        ``open_outlet`` [m] (zones with p0 <= p_f; Hertz also ``L`` = 2a), ``lift_off``,
        ``percolated``, ``converged`` (Hertz shooting), ``out_of_table`` (the largest
        contact pressure lies beyond the tables: Q = NaN), ``status`` ("ok", "lift_off"
        (p_a = max p0: finite limit), "open" (Q = inf), "percolated", "above_table",
        "not_converged"), and the inputs.
    """
    from ..tables import Tables
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables")
    tables._need(theory)
    if not (isinstance(profile, str) and profile in ("uniform", "hertz")):
        shown = profile if isinstance(profile, str) else "array(...)"
        raise ValueError(f"profile = {shown!r} is invalid with alpha_pv: must be 'uniform' or "
                         f"'hertz' (sampled profiles are not implemented for the Barus fluid)")
    dp = check_positive("dp", dp, "[Pa]", allow_zero=True)
    L_y = check_positive("L_y", L_y, "[m]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    eta = check_positive("eta", eta, "[Pa·s]")
    alpha_pv = check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True)
    p_b = check_positive("p_b", p_b, "[Pa]", allow_zero=True)
    roelands = check_law(viscosity) == "roelands"
    zz = np.array(math.nan) if roelands_z is None else check_positive(
        "roelands_z", roelands_z, "[-]", allow_zero=True)
    if profile == "uniform":
        if p0 is None or L is None or R is not None or f_N is not None:
            raise ValueError("profile = 'uniform' is invalid with these arguments: give p0 [Pa] "
                             "and L [m], not R / f_N")
        g1 = check_positive("p0", p0, "[Pa]")
        g2 = check_positive("L", L, "[m]")
    else:
        if R is None or f_N is None or p0 is not None or L is not None:
            raise ValueError("profile = 'hertz' is invalid with these arguments: give R [m] "
                             "and f_N [N/m], not p0 / L")
        g1 = check_positive("R", R, "[m]")
        g2 = check_positive("f_N", f_N, "[N/m]")
    a_cj = check_positive("alpha_cj", alpha_cj, "[-]")
    shape = np.broadcast(dp, L_y, E_star, eta, alpha_pv, p_b, g1, g2, zz, a_cj).shape
    dp, L_y, E, eta, al, pb, g1, g2, zz, a_cj = (
        np.ascontiguousarray(np.broadcast_to(v, shape).ravel(), dtype=np.float64)
        for v in (dp, L_y, E_star, eta, alpha_pv, p_b, g1, g2, zz, a_cj))
    if roelands:
        rA, rZ, rpr = roelands_parameters(eta, al, None if roelands_z is None else zz,
                                          roelands_p_r, roelands_eta_inf)
        rA = np.ascontiguousarray(rA, dtype=np.float64)
        rZ = np.ascontiguousarray(rZ, dtype=np.float64)
    h = float(tables.h_rms)
    sc = _scalars(tables, theory)
    tab = tables.kernel_data(theory)
    pa = pb + dp
    p_perc = math.exp(sc[5]) * E
    p_top = math.exp(sc[4]) * E
    cols = {"dp": dp, "L_y": L_y, "E_star": E, "eta": eta, "alpha_pv": al, "p_b": pb}
    if profile == "uniform":
        p0v, Lv = g1, g2
        lift = pa > p0v
        perc = (p0v - pb >= p_perc) & ~lift
        out_t = (p0v - pb > p_top) & ~perc & ~lift
        kq = np.zeros(E.size)
        run = ~lift & ~perc & ~out_t & (dp > 0)
        if np.any(run):
            x, w = np.polynomial.legendre.leggauss(int(quad_order))
            out = np.empty(int(run.sum()))
            A, Z, pr = (rA, rZ, rpr) if roelands else (al, np.zeros(E.size), 0.0)
            sub = [np.ascontiguousarray(v[run], dtype=np.float64)
                   for v in (p0v, Lv, pa, pb, E, A, Z)]
            _uniform_kernel(tab, sc, *sub, float(pr), x, w, float(quad_width), out)
            kq[run] = out
        conv = np.ones(E.size, dtype=bool)
        cols.update({"p0": p0v, "L": Lv})
    else:
        a = np.sqrt(4.0 * g2 * g1 / (math.pi * E))
        pH = 2.0 * g2 / (math.pi * a)
        lift = pa > pH
        perc = (pH - pa >= p_perc) & ~lift
        out_t = (pH - pb > p_top) & ~perc & ~lift
        kq = np.zeros(E.size)
        conv = np.ones(E.size, dtype=bool)
        run = ~lift & ~perc & ~out_t & (dp > 0)
        if np.any(run):
            k = np.empty(int(run.sum()))
            ok = np.empty(int(run.sum()), dtype=np.bool_)
            if roelands:
                sub = [np.ascontiguousarray(v[run]) for v in (E, pH, a, pa, pb, rA, rZ)]
                _hertz_kernel_r(tab, sc, *sub, rpr, int(steps), k, ok)
            else:
                sub = [np.ascontiguousarray(v[run]) for v in (E, pH, a, pa, pb, al)]
                _hertz_kernel(tab, sc, *sub, int(steps), k, ok)
            kq[run] = k
            conv[run] = ok
        cols.update({"R": g1, "f_N": g2, "a": a, "p_max": pH})
    scale = 1.0
    if theory == "critical_junction":
        scale = (a_cj / float(tables.options.get("alpha_cj", 1.0))) ** 3
    Q = scale * L_y * kq * h ** 3 / (12.0 * eta)
    Q = np.where(lift, math.inf, np.where(conv & ~out_t, Q, math.nan))
    pmax = p0v if profile == "uniform" else pH
    status = np.select([lift, pa == pmax, perc, out_t, ~conv],
                       ["open", "lift_off", "percolated", "above_table", "not_converged"], "ok")
    if profile == "uniform":
        open_in = np.where(pa > p0v, Lv, 0.0)
        open_out = np.zeros_like(Lv)
    else:
        with np.errstate(invalid="ignore"):
            sa = np.clip(pa / pH, 0.0, 1.0)
            sb = np.clip(pb / pH, 0.0, 1.0)
            open_in = np.where(~lift, a * (1.0 - np.sqrt(1.0 - sa * sa)), 2 * a)
            open_out = np.where(~lift, a * (1.0 - np.sqrt(1.0 - sb * sb)), 0.0)
        cols["L"] = 2 * a
    cols.update({"open_inlet": open_in, "open_outlet": open_out})
    cols.update({"p_a": pa, "Q": Q, "lift_off": lift | (pa == pmax), "percolated": perc,
                 "converged": conv, "out_of_table": out_t, "status": status})
    if roelands:
        cols["roelands_z"] = rZ
    df = pd.DataFrame(cols, copy=False)
    refs = ["doi:10.2475/ajs.s3-45.266.87", "arXiv:0911.3019"]
    if roelands:
        refs = ["C.J.A. Roelands, PhD thesis, TU Delft (1966)",
                "B.J. Hamrock and D. Dowson, Ball Bearing Lubrication, Wiley (1981), eq. 4.5",
                "arXiv:0911.3019"]
    df.attrs.update({"units": {"Q": "m^3/s", "dp": "Pa", "p_a": "Pa", "p_b": "Pa", "p0": "Pa",
                               "L": "m", "L_y": "m", "E_star": "Pa", "eta": "Pa s",
                               "alpha_pv": "1/Pa", "R": "m", "f_N": "N/m", "a": "m",
                               "p_max": "Pa", "roelands_z": "1", "open_inlet": "m",
                               "open_outlet": "m"},
                     "theory": theory, "profile": profile,
                     "viscosity": "Roelands" if roelands else "Barus",
                     "shape": tuple(shape), "references": refs})
    if roelands:
        df.attrs.update(roelands_p_r=float(rpr), roelands_eta_inf=float(
            ROELANDS_ETA_INF if roelands_eta_inf is None else roelands_eta_inf))
    return df
