"""Independent reference: Reynolds flows with a pressure-dependent viscosity η(p).

Written from the Reynolds equation itself, NOT from the reduced-pressure (ψ) reduction the
package uses: every solution here integrates the flow with η(p) directly (scipy solve_ivp /
solve_bvp), so it checks the derivation as well as the code.

* :func:`radial_mean_pressure` — flat circular block of radius R, uniform squeeze rate ū̇:
  r J = -ū̇ r²/2 with J = -(σ0 η0/η(p)) dp/dr, i.e. dp/ds = -K s η(p)/η0 (s = r/R,
  K = -ū̇R²/(2σ0)), p(1) = 0, integrated inwards; mean p̄ = 2∫_0^1 p s ds.
* :func:`squeeze_time` — time from ū_a down to ū_b: at each ū the rate solves
  p̄(K) = p0 - p_cont(ū) (brentq on ln K with the ODE above); t = ∫ dū/|ū̇| by scipy quad
  in ln(ū - ū∞). Contact pressure and σ0 from the tables' Python methods.
* :func:`seal_bvp` — 1-D seal, d/dx[σ0(p0(x) - p)/η(p) · dp/dx] = 0, p(x_0) = p_a,
  p(x_1) = p_b, by solve_bvp with the flux as unknown parameter; :func:`hertz_shoot` a Hertz
  profile by adaptive shooting in θ (x = a(1 - cos θ), p0 = p_H sin θ).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate, optimize


def barus(alpha):
    return lambda p: np.exp(alpha * p)


def radial_mean_pressure(K, visc_ratio, rtol=1e-12):
    """Mean fluid pressure [Pa] under the block for K = -ū̇R²/(2σ0) [Pa] and η(p)/η0."""
    def f(s, y):
        p = y[0]
        return [-K * s * visc_ratio(p), 2.0 * p * s]

    sol = integrate.solve_ivp(f, (1.0, 0.0), [0.0, 0.0], rtol=rtol, atol=1e-14 * max(K, 1.0),
                              method="DOP853")
    if not sol.success or not np.all(np.isfinite(sol.y[:, -1])):
        return math.inf
    # y[1] accumulates ∫_1^s 2 p s ds (negative direction)
    return -sol.y[1, -1]


def squeeze_time(tables, theory, p0, E_star, R, eta, alpha, u_a, u_b, u_inf, rtol=1e-9):
    """Time [s] from ū = u_a down to u_b (> u_inf) for a Barus fluid, from the Reynolds ODE."""
    visc = barus(alpha)

    def rate(u):
        pc = float(tables.contact_pressure(u, E_star))
        pf = p0 - pc
        sig = float(tables.conductivity(pc, E_star, eta, theory))
        g = lambda lk: radial_mean_pressure(math.exp(lk), visc) - pf
        lo, hi = math.log(pf) - 1.0, math.log(pf) + 1.0
        while g(lo) > 0:
            lo -= 2.0
        while g(hi) < 0:
            hi -= 0.5 * (hi - lo) if not np.isfinite(radial_mean_pressure(math.exp(hi), visc)) else -1.0
        K = math.exp(optimize.brentq(g, lo, hi, xtol=1e-14, rtol=1e-14))
        return 2.0 * sig * K / R ** 2                       # |dū/dt|

    def integrand(w):
        u = u_inf + math.exp(w)
        return math.exp(w) / rate(u)

    val, _ = integrate.quad(integrand, math.log(u_b - u_inf), math.log(u_a - u_inf),
                            epsrel=rtol, limit=200)
    return val


def seal_bvp(sigma0, p0_of_x, x0, x1, p_a, p_b, alpha, n=400, tol=1e-9):
    """(q [m²/s], solution) of the 1-D seal with η = η0 e^{α(p - p_b)}.

    sigma0(p_cont) -> σ0 [m³/(Pa s)] vectorised; p0_of_x(x) -> nominal pressure [Pa].
    """
    def f(x, y, par):
        q = par[0]
        pc = p0_of_x(x) - y[0]
        return np.vstack([-q * np.exp(alpha * (y[0] - p_b)) / sigma0(pc)])

    def bc(ya, yb, par):
        return np.array([ya[0] - p_a, yb[0] - p_b])

    x = np.linspace(x0, x1, n)
    y = np.vstack([p_a + (p_b - p_a) * (x - x0) / (x1 - x0)])
    q_guess = (p_a - p_b) * sigma0(np.atleast_1d(p0_of_x(0.5 * (x0 + x1)) - 0.5 * (p_a + p_b)))[0] / (x1 - x0)
    sol = integrate.solve_bvp(f, bc, x, y, p=[q_guess], tol=tol, max_nodes=200000)
    if not sol.success:
        raise RuntimeError(f"solve_bvp failed: {sol.message}")
    return float(sol.p[0]), sol


#: the shooting's first step, relative to the zone's angular width
FIRST_STEP = 1e-7


def hertz_shoot(sigma0, pH, a, p_a, p_b, alpha, rtol=1e-11):
    """q [m²/s] of the Hertz seal (zone p0 >= p_f) with η = η0 e^{α(p - p_b)}.

    Adaptive DOP853 on dp/dθ = -q a sin θ e^{α(p - p_b)}/σ0(p_H sin θ - p) (x = a(1 - cos θ),
    which removes the square-root edges of p0(x)) from the inlet p(θ_s) = p_a, and brentq
    on ln q for p(θ_e) = p_b. (solve_bvp does not converge here: σ0 varies by orders of
    magnitude within a few µm of the zone ends.)
    """
    th_s = math.asin(min(1.0, p_a / pH))
    th_e = math.pi - math.asin(min(1.0, p_b / pH))
    s_ref = float(sigma0(np.atleast_1d(pH - 0.5 * (p_a + p_b)))[0])

    def end(lnk):
        k = math.exp(lnk)

        def f(th, y):
            if y[0] < -5.0:  # overshot (the stop event below ends the trial): σ0 is not
                return [0.0]  # evaluated at absurd contact pressures
            pc = max(pH * math.sin(th) - y[0] * pH, 0.0)
            return [-k * math.sin(th) * math.exp(alpha * (y[0] * pH - p_b)) * s_ref
                    / float(sigma0(np.atleast_1d(pc))[0])]

        stop = lambda th, y: y[0] + 5.0
        stop.terminal = True
        # first step 1e-7 of the zone: the inlet starts at zero contact pressure, a boundary
        # layer that DOP853's own first step can skip (the shooting was then off by up to 6e-6
        # at rtol 1e-11; with this step within 2.3e-10 of rtol 1e-13)
        sol = integrate.solve_ivp(f, (th_s, th_e), [p_a / pH], method="DOP853", rtol=rtol,
                                  atol=1e-13, events=stop, first_step=FIRST_STEP * (th_e - th_s))
        return sol.y[0, -1] - p_b / pH if sol.status == 0 else -5.0

    k0 = math.log((p_a - p_b) / pH / 2.0)
    lo, hi = k0 - 1.0, k0 + 1.0
    while end(lo) < 0:
        lo -= 2.0
    while end(hi) > 0:
        hi += 2.0
    lnk = optimize.brentq(end, lo, hi, xtol=1e-13, rtol=1e-13)
    return math.exp(lnk) * s_ref * pH / a
