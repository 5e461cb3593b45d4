"""Independent reference: seal Reynolds flows with a Roelands viscosity η(p).

Written from the textbook law, not from fastcontact.flow.piezoviscosity: Hamrock & Dowson,
*Ball Bearing Lubrication* (1981), eq. 4.5,

    η = η0 exp{(ln η0 + 9.67) [-1 + (1 + 5.1e-9 p)^Z]}        (η in Pa·s, p in Pa),

with the constant 5.1e-9 1/Pa generalised to ``c`` so that tests can make the law strongly
nonlinear at the small pressures of a soft seal. The flows are integrated in the fluid
pressure p itself (no reduced pressure) with scipy:

* :func:`seal_bvp` — 1-D seal d/dx[σ0(p0(x) - p) η0/η(p) dp/dx] = 0 by solve_bvp, the flux as
  unknown parameter;
* :func:`hertz_shoot` — Hertz profile by adaptive DOP853 shooting in θ (x = a(1 - cos θ)) and
  brentq on ln q.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate, optimize


def roelands(eta0, Z, c=5.1e-9, p_b=0.0):
    """η(p)/η0 of Hamrock & Dowson's eq. 4.5 (pressure above the outlet p_b; below it, where a
    shooting trial overshoots, the outlet viscosity)."""
    A = math.log(eta0) + 9.67
    return lambda p: np.exp(A * (-1.0 + (1.0 + c * np.maximum(np.asarray(p) - p_b, 0.0)) ** Z))


def seal_bvp(sigma0, p0_of_x, x0, x1, p_a, p_b, visc, n=400, tol=1e-9):
    """(q [m²/s], solution) of the 1-D seal with η(p)/η0 = visc(p)."""
    def f(x, y, par):
        pc = p0_of_x(x) - y[0]
        return np.vstack([-par[0] * visc(y[0]) / sigma0(pc)])

    def bc(ya, yb, par):
        return np.array([ya[0] - p_a, yb[0] - p_b])

    x = np.linspace(x0, x1, n)
    y = np.vstack([p_a + (p_b - p_a) * (x - x0) / (x1 - x0)])
    pm = p0_of_x(0.5 * (x0 + x1)) - 0.5 * (p_a + p_b)
    q_guess = (p_a - p_b) * float(sigma0(np.atleast_1d(pm))[0]) / (x1 - x0)
    sol = integrate.solve_bvp(f, bc, x, y, p=[q_guess], tol=tol, max_nodes=200000)
    if not sol.success:
        raise RuntimeError(f"solve_bvp failed: {sol.message}")
    return float(sol.p[0]), sol


#: the shooting's first step, relative to the zone's angular width
FIRST_STEP = 1e-7


def hertz_shoot(sigma0, pH, a, p_a, p_b, visc, rtol=1e-11):
    """q [m²/s] of the Hertz seal (zone p0 >= p_f) with η(p)/η0 = visc(p)."""
    th_s = math.asin(min(1.0, p_a / pH))
    th_e = math.pi - math.asin(min(1.0, p_b / pH))
    s_ref = float(sigma0(np.atleast_1d(pH - 0.5 * (p_a + p_b)))[0])

    def end(lnk):
        k = math.exp(lnk)

        def f(th, y):
            if y[0] < -5.0:  # overshot (the stop event below ends the trial): σ0 is not
                return [0.0]  # evaluated at absurd contact pressures
            pc = max(pH * math.sin(th) - y[0] * pH, 0.0)
            return [-k * math.sin(th) * float(visc(y[0] * pH)) * s_ref
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
