"""Numba kernels of the seal engine with a pressure-dependent viscosity (private).

Uniform ring: ``q L = ∫_{p_b}^{p_a} σ0(p0 - p) η0/η(p) dp`` by composite Gauss–Legendre in
ln p_cont (Barus is the p_r = 0 case of the Roelands weight). Hertz O-ring: shooting on
k = 12 η0 q / h³ with RK4 on steps graded towards both zone ends, in the reduced pressure ψ
(Barus) or in p_f itself (Roelands), bracketed Illinois iteration in ln k. The wrapper and
the equations: :mod:`fastcontact.seal.viscosity`. ``sc`` is the float array of
:func:`fastcontact.seal.viscosity._scalars`.
"""
from __future__ import annotations

import math

from numba import njit, prange

from ..flow.piezoviscosity import ln_roelands
from ..tables import k_sigma_of_lnp

__all__ = ["TAIL_CUT"]

#: the uniform-ring quadrature starts TAIL_CUT below ln(p_cont_min/E*) of the table (integrand ∝ p_cont)
TAIL_CUT = 60.0


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
def _mismatch(tab, sc, E, pH, a, th_s, th_e, psi_a, pa, pb, alpha, A, Z, pr, roelands, y, n):
    """Outlet value of the shooting for k = e^y: ψ (Barus, from ψ_a) or p_f − p_b (Roelands,
    from p_a); 0 is the outlet condition."""
    if roelands:
        return _shoot_r(tab, sc, E, pH, a, th_s, th_e, pa, pb, A, Z, pr, math.exp(y), n)
    return _shoot(tab, sc, E, pH, a, th_s, th_e, psi_a, pb, alpha, math.exp(y), n)


@njit(cache=True)
def _solve_k(tab, sc, E, pH, a, pa, pb, psi_a, alpha, A, Z, pr, roelands, n):
    """(k, converged) of one Hertz case, k = 12 η0 q / h³ [Pa/m]: bracket the outlet
    condition in ln k, starting from the pressure scale (ψ_a for Barus, p_a − p_b for
    Roelands) over the resistance of the dry profile, then Illinois (regula falsi)."""
    scale = pa - pb if roelands else psi_a
    th_s = math.asin(min(1.0, pa / pH))
    th_e = math.pi - math.asin(min(1.0, pb / pH))
    smid = _sigma(tab, sc, math.log(max(pH - 0.5 * (pa + pb), 1e-300) / E))
    y = math.log(scale * max(smid, 1e-300) / (2.0 * a))
    f = _mismatch(tab, sc, E, pH, a, th_s, th_e, psi_a, pa, pb, alpha, A, Z, pr, roelands, y, n)
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
            fhi = _mismatch(tab, sc, E, pH, a, th_s, th_e, psi_a, pa, pb, alpha, A, Z, pr,
                            roelands, hi, n)
            if fhi > 0.0:
                lo, flo = hi, fhi
        else:
            lo = hi - step
            flo = _mismatch(tab, sc, E, pH, a, th_s, th_e, psi_a, pa, pb, alpha, A, Z, pr,
                            roelands, lo, n)
            if flo < 0.0:
                hi, fhi = lo, flo
        f = flo if flo > 0.0 else fhi
        step *= 1.5
    if not (flo > 0.0 and fhi < 0.0):
        return math.nan, False
    side = 0
    for _ in range(200):                      # Illinois (regula falsi) in ln k
        y = (lo * fhi - hi * flo) / (fhi - flo)
        f = _mismatch(tab, sc, E, pH, a, th_s, th_e, psi_a, pa, pb, alpha, A, Z, pr, roelands,
                      y, n)
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
        if hi - lo < 1e-13 or abs(f) <= 1e-14 * scale:
            return math.exp(y), True
    return math.exp(y), False


@njit(cache=True)
def _hertz_case(tab, sc, E, pH, a, pa, pb, alpha, n):
    """(k, converged) for one Hertz case with a Barus fluid; k = 12 η0 q / h³ [Pa/m]."""
    psi_a = pa - pb if alpha == 0.0 else -math.expm1(-alpha * (pa - pb)) / alpha
    return _solve_k(tab, sc, E, pH, a, pa, pb, psi_a, alpha, 0.0, 0.0, 0.0, False, n)


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
    """(k, converged) of one Hertz case with a Roelands fluid (:func:`_solve_k`)."""
    return _solve_k(tab, sc, E, pH, a, pa, pb, 0.0, 0.0, A, Z, pr, True, n)


@njit(parallel=True, cache=True)
def _hertz_kernel_r(tab, sc, E, pH, a, pa, pb, A, Z, pr, n, k, ok):
    for i in prange(E.size):
        k[i], ok[i] = _hertz_case_r(tab, sc, E[i], pH[i], a[i], pa[i], pb[i], A[i], Z[i], pr, n)

