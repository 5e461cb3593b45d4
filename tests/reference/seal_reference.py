"""Slow, independent reference for seal leak rates (Lorenz & Persson 2010, eqs. 25–33).

Built from the DIRECT contact core only (``fastcontact.conductivity.conductivity``: quadrature
of (A1)–(A4) and the flow theories, no tables), written from the paper's Sec. 6, not from
``fastcontact.seal``. It is slow on purpose (a handful of cases per test).

Uniform ring (eq. 32 with the fluid feedback, eq. 33 for uniform p0 in closed form)::

    Q = (L_y / L) ∫_{p0 − p_a}^{p0 − p_b} σ_eff(p) dp

integrated in t = ln p by composite Gauss–Legendre (16 nodes per panel, panels of width
<= 0.25 in t, σ_eff evaluated directly at every node in one vectorised call), over the
offset below t_b = ln(p0 − p_b) whose width −ln(1 − dp/(p0 − p_b)) is formed from dp itself
(no cancellation however small dp/p0); the lower limit p → 0 (lift-off equality) is cut at
t = ln(p0 − p_b) − 46 (σ grows like ln³, the neglected part is < e^-40 relative). Error
estimate: the same with panels halved.

Hertz O-ring (soft seal, fixed dry p0(x)): sealing zone θ ∈ [θ_s, θ_e] with x = a(1 − cos θ),
p0 = p_H sin θ, sin θ_s = p_a/p_H, sin θ_e = p_b/p_H (θ_e = π for p_b = 0). Eq. (33) is
discretised *from the inlet*,

    p_f(θ_j) = p_a − Δp s(θ_j)/s(θ_e),   s(θ) = ∫_{θ_s}^{θ} a sin θ' / σ_eff(p0 − p_f) dθ',

on composite Gauss–Legendre panels geometrically graded (ratio 0.2, down to 1e-13 of the zone)
towards both ends, where p_cont → 0, and solved by damped Newton with a dense Jacobian
(numpy.linalg.solve; finite-difference dσ/dp). Error estimate: the same on a mesh with twice
the panels and 4 more nodes each. σ_eff(p) inside the Newton loop comes from
:class:`SigmaInterp`, a Chebyshev interpolant of ln σ_eff against ln p built from direct
evaluations at Chebyshev nodes and checked against direct evaluations between them; below
its range (p < 1e-16 E*, reached only within ~1e-13 of the zone ends) σ is taken as the
value at the bound — a resistance contribution < 1e-12 relative there.

Linear response (dp → 0): Q/dp = L_y / ∫ dx/σ_eff(p0(x) − p_b), by scipy quad over the zone.

Run ``python tests/reference/seal_reference.py`` for a self-check printout.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
from numpy.polynomial import chebyshev as C
from numpy.polynomial import legendre as Lg
from scipy import integrate

from fastcontact.conductivity import conductivity


# --------------------------------------------------------------------------- direct σ
def sigma_direct(psd, p, E_star, eta, theory, a_perc=0.5, alpha_cj=1.0):
    """σ_eff [m³/(Pa·s)] at contact pressures p [Pa] (vectorised direct quadrature)."""
    p = np.atleast_1d(np.asarray(p, dtype=float))
    s, _ = conductivity(psd, p, E_star, eta, theory, a_perc=a_perc, alpha_cj=alpha_cj)
    return np.asarray(s, dtype=float)


def _gl(n):
    return Lg.leggauss(n)


# --------------------------------------------------------------------------- uniform
def uniform_reference(psd, *, p0, dp, L, L_y, E_star, eta, theory, p_b=0.0, a_perc=0.5,
                      alpha_cj=1.0, width=0.25, nodes=16, sigma=None):
    """(Q [m³/s], relative error estimate) of a flat ring (closed form of eq. 33 for uniform p0).

    The integral runs over the offset u = t_b − t in [0, W] below t_b = ln(p0 − p_b), with the
    width W = −ln(1 − dp/(p0 − p_b)) formed directly from dp (log1p), never as a difference
    ln(p0 − p_b) − ln(p0 − p_a): tiny dp keeps all its digits. σ_eff is evaluated directly at
    every quadrature node, or by ``sigma(p)`` if given (e.g. a :class:`SigmaInterp` for the
    slow effective-medium theory; the integral is then cut at its lower bound, which neglects
    < 1e-12 of Q)."""
    p_a = p_b + dp
    hi = p0 - p_b
    if dp == 0:
        return 0.0, 0.0
    if p_a > p0:
        return math.inf, 0.0
    tb = math.log(hi)
    W = -math.log1p(-dp / hi) if dp < hi else 46.0
    W = min(W, 46.0)
    if sigma is not None:
        W = min(W, tb - sigma.t_lo)

    def integral(w):
        m = max(1, int(math.ceil(W / w)))
        edges = W * np.arange(m + 1) / m            # offsets u from t_b (exact near u = 0)
        z, wt = _gl(nodes)
        h = 0.5 * np.diff(edges)
        mid = 0.5 * (edges[1:] + edges[:-1])
        t = tb - (mid[:, None] + h[:, None] * z[None, :]).ravel()
        ww = (h[:, None] * wt[None, :]).ravel()
        if sigma is None:
            s = sigma_direct(psd, np.exp(t), E_star, eta, theory, a_perc, alpha_cj)
        else:
            s = sigma(np.exp(t))
        return float(np.sum(ww * s * np.exp(t)))

    I1 = integral(width)
    I2 = integral(width / 2)
    if I2 == 0.0:                 # σ_eff = 0 at every node: percolated throughout, Q = 0
        return 0.0, abs(I1)
    Q = L_y / L * I2
    return Q, abs(I1 / I2 - 1.0)


# --------------------------------------------------------------------------- σ interpolant
class SigmaInterp:
    """Chebyshev interpolant of ln σ_eff(ln p) on [p_lo, p_hi] from direct evaluations.

    ``check`` direct evaluations between the nodes give ``max_error`` (relative, in σ)."""

    def __init__(self, psd, *, E_star, eta, theory, p_lo, p_hi, a_perc=0.5, alpha_cj=1.0,
                 degree=80, check=24, seed=0):
        self.t_lo, self.t_hi = math.log(p_lo), math.log(p_hi)
        k = np.arange(degree + 1)
        s = np.cos(np.pi * k / degree)
        t = self._t(s)
        sig = sigma_direct(psd, np.exp(t), E_star, eta, theory, a_perc, alpha_cj)
        if np.any(sig <= 0):
            raise ValueError("SigmaInterp: σ = 0 inside the range (percolated): narrow p_hi")
        self.coef = C.chebfit(s, np.log(sig), degree)
        rng = np.random.default_rng(seed)
        sc = rng.uniform(-1, 1, check)
        ref = sigma_direct(psd, np.exp(self._t(sc)), E_star, eta, theory, a_perc, alpha_cj)
        self.max_error = float(np.max(np.abs(np.exp(C.chebval(sc, self.coef)) / ref - 1)))
        self.direct_evaluations = degree + 1 + check

    def _t(self, s):
        return 0.5 * (self.t_hi + self.t_lo) + 0.5 * (self.t_hi - self.t_lo) * s

    def __call__(self, p):
        p = np.asarray(p, dtype=float)
        t = np.log(np.clip(p, math.exp(self.t_lo), math.exp(self.t_hi)))
        s = (2 * t - self.t_hi - self.t_lo) / (self.t_hi - self.t_lo)
        return np.exp(C.chebval(s, self.coef))


# --------------------------------------------------------------------------- Hertz
def hertz_geometry(R, f_N, E_star):
    a = math.sqrt(4 * f_N * R / (math.pi * E_star))
    return a, 2 * f_N / (math.pi * a)


def _graded_edges(panels, ratio=0.2, depth=1e-13):
    """Breakpoints on [0, 1]: geometric towards both ends, ``panels`` uniform in between."""
    k = int(math.ceil(math.log(depth) / math.log(ratio)))
    g = ratio ** np.arange(k, 0, -1)            # depth ... ratio
    inner = np.linspace(ratio, 1 - ratio, panels + 1)
    return np.unique(np.concatenate(([0.0], g * 1.0, inner, 1 - g[::-1], [1.0])))


def _panel_matrices(n):
    z, w = _gl(n)
    V = Lg.legvander(z, n - 1)
    Vi = np.linalg.inv(V)
    A = np.empty((n, n))                        # A[i, k] = ∫_{-1}^{z_i} ℓ_k
    for k in range(n):
        ic = Lg.legint(Vi[:, k], lbnd=-1)
        A[:, k] = Lg.legval(z, ic)
    return z, w, A


def _solve_mesh(sigma, a, pH, p_a, p_b, th_s, th_e, panels, nodes, guess=None):
    edges = th_s + (th_e - th_s) * _graded_edges(panels)
    z, w, A = _panel_matrices(nodes)
    P = edges.size - 1
    h = 0.5 * np.diff(edges)
    th = (0.5 * (edges[1:] + edges[:-1])[:, None] + h[:, None] * z[None, :]).ravel()
    wq = (h[:, None] * w[None, :]).ravel()
    N = th.size
    # cumulative integration matrix from θ_s (block lower triangular)
    M = np.zeros((N, N))
    for p in range(P):
        rows = slice(p * nodes, (p + 1) * nodes)
        M[rows, p * nodes:(p + 1) * nodes] = h[p] * A
        if p:
            M[rows, :p * nodes] = wq[None, :p * nodes]
    dx = a * np.sin(th)                         # dx/dθ
    p0 = pH * np.sin(th)
    dp = p_a - p_b
    x = a * (1 - np.cos(th))
    xs, xe = a * (1 - math.cos(th_s)), a * (1 - math.cos(th_e))
    pf = p_a - dp * (x - xs) / (xe - xs) if guess is None else guess(th)

    def resid(pf):
        c = p0 - pf
        s = sigma(np.where(c > 0, c, 1.0))
        r = np.where(c > 0, dx / s, 0.0)
        cum = M @ r
        tot = wq @ r
        return pf - p_a + dp * cum / tot, r, cum, tot, s, c

    F, r, cum, tot, s, c = resid(pf)
    for it in range(80):
        fn = np.max(np.abs(F))
        if fn < 1e-13 * pH:
            break
        eps = 1e-7
        s1 = sigma(np.where(c > 0, c * (1 + eps), 1.0))
        dlns_dc = np.where(c > 0, (np.log(s1) - np.log(s)) / (eps * np.where(c > 0, c, 1.0)), 0)
        dr_dpf = r * dlns_dc                    # d r / d p_f = −dr/dc = r d ln σ/dc
        J = np.eye(N) + dp * (M * dr_dpf[None, :] / tot - np.outer(cum, wq * dr_dpf) / tot ** 2)
        d = np.linalg.solve(J, -F)
        lam = 1.0
        while lam > 1e-8:
            new = pf + lam * d
            Fn, rn, cumn, totn, sn, cn = resid(new)
            if np.all(np.isfinite(Fn)) and np.max(np.abs(Fn)) < (1 - 1e-4 * lam) * fn:
                break
            lam /= 2
        pf, F, r, cum, tot, s, c = new, Fn, rn, cumn, totn, sn, cn
    else:
        raise RuntimeError("hertz reference: Newton did not converge")
    return tot, th, pf


def hertz_reference(sigma, *, R, f_N, dp, L_y, E_star, p_b=0.0, panels=12, nodes=16):
    """(Q [m³/s], relative error estimate, x_s [m]) of an O-ring; ``sigma(p)`` [m³/(Pa·s)]."""
    a, pH = hertz_geometry(R, f_N, E_star)
    p_a = p_b + dp
    if dp == 0:
        return 0.0, 0.0, None
    if p_a > pH:
        return math.inf, 0.0, None
    th_s = math.asin(min(p_a / pH, 1.0))
    th_e = math.pi - math.asin(min(p_b / pH, 1.0))
    W1, th1, pf1 = _solve_mesh(sigma, a, pH, p_a, p_b, th_s, th_e, panels, nodes)
    W2, _, _ = _solve_mesh(sigma, a, pH, p_a, p_b, th_s, th_e, 2 * panels, nodes + 4,
                           guess=lambda th: np.interp(th, th1, pf1))
    return L_y * dp / W2, abs(W1 / W2 - 1), a * (1 - math.cos(th_s))


def hertz_linear_reference(sigma, *, R, f_N, L_y, E_star, p_b=0.0):
    """lim_{dp→0} Q/dp = L_y / ∫_{zone} dx/σ_eff(p0(x) − p_b) [m³/(Pa·s)], by quad in θ."""
    a, pH = hertz_geometry(R, f_N, E_star)
    th_s = math.asin(min(p_b / pH, 1.0))
    th_e = math.pi - th_s

    def f(th):
        c = pH * math.sin(th) - p_b
        return 0.0 if c <= 0 else a * math.sin(th) / float(sigma(np.array([c]))[0])

    with warnings.catch_warnings():
        warnings.simplefilter("error", integrate.IntegrationWarning)
        val, _ = integrate.quad(f, th_s, th_e, epsabs=0, epsrel=1e-12, limit=500,
                                points=[0.5 * (th_s + th_e)])
    return L_y / val


if __name__ == "__main__":  # pragma: no cover - self-check printout
    import time

    import fastcontact as fc

    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    E, eta = 1e7, 1e-3
    for th in ("average", "critical_junction"):
        t0 = time.perf_counter()
        Q, e = uniform_reference(psd, p0=5e4, dp=2.5e4, L=5e-3, L_y=0.1, E_star=E, eta=eta,
                                 theory=th)
        print(f"uniform {th}: Q = {Q:.12e}  est. rel. error {e:.1e}  "
              f"({time.perf_counter() - t0:.2f} s)")
    for th in ("average", "critical_junction"):
        t0 = time.perf_counter()
        si = SigmaInterp(psd, E_star=E, eta=eta, theory=th, p_lo=1e-16 * E, p_hi=3e5)
        Q, e, xs = hertz_reference(si, R=1e-3, f_N=2.0, dp=5e4, L_y=0.1, E_star=E)
        print(f"hertz {th}: Q = {Q:.12e}  est. rel. error {e:.1e}  interp. error "
              f"{si.max_error:.1e} ({time.perf_counter() - t0:.2f} s)")
