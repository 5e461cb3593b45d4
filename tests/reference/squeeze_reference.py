"""Slow, independent reference for the squeeze-out time (SPEC §4, paper eqs. 18–19, 24).

Written from SPEC §4 only; uses the DIRECT contact-mechanics core of fastcontact
(``contact.mean_separation``, ``contact.contact_pressure``, ``conductivity.conductivity``)
and no tables, no interpolation, no splines, nothing from ``fastcontact.squeeze``.

Model (reduced units v = ū/h_rms, π = p/E*, σ̄ = 12ησ_eff/h_rms³):

    dv/dt̃ = -σ̄(π_c(v)) (1 - π_c(v)/π0),    t = τ0 t̃,   τ0 = 3ηR²/(2 h_rms² p0),

which is dū/dt = -(8σ_eff/R²)(p0 - p_cont) of SPEC §4 rewritten. The time from v_a down
to v_b is the quadrature

    t̃ = ∫_{w_b}^{w_a} e^w dw / (σ̄(π_c(v)) · (1 - π_c(v)/π0)),   v = v∞ + e^w,

(w = ln(v - v∞) removes the logarithmic divergence at equilibrium), evaluated with
``scipy.integrate.quad`` (epsabs = 0, epsrel = 1e-11). ``1 - π_c/π0`` is evaluated as
``-expm1(ln π_c - ln π0)``; π_c comes from the direct Newton inverse of (A4)
(``contact_pressure``, 1e-14 in ln p), v∞ from the direct (A4) at p0.

Above v = V_DIRECT = 200 h_rms (π_c < 1e-80, so π_c/π0 is negligible) the direct core is not
used: σ̄ = y³ - c y with y = v + d, (c, d) fitted to the direct σ̄ and its slope at
V_DIRECT, integrated in closed form (σ̄ → v³ is exact to leading order, paper Sec. 3; the
correction is < 0.5 % of σ̄ there and that part of the integral < 1e-2 of t* in the tests).

Cost: every integrand value is one Newton inverse plus one σ̄ (the effective medium costs
~5–10 ms), so a t* takes 0.1–5 s; keep the case count small.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate

from fastcontact.contact import contact_pressure, mean_separation
from fastcontact.conductivity import conductivity

V_DIRECT = 200.0
EPSREL = 1e-11
P_START = 1e-3


class SqueezeReference:
    """t̃ (in τ0 = 3ηR²/(2h²p0) units) for one surface, E*, theory and p0."""

    def __init__(self, psd, E_star, theory, p0):
        self.psd = psd
        self.h = psd.h_rms
        self.E = float(E_star)
        self.theory = theory
        self.p0 = float(p0)
        self.lnpi0 = math.log(self.p0 / self.E)
        self.v_inf = float(mean_separation(psd, self.p0, self.E)) / self.h
        self.evals = 0
        self._tail_cd = None

    # -- model pieces (direct core)
    def sigma_bar_at_p(self, p):
        s, perc = conductivity(self.psd, np.array([p]), self.E, 1.0, self.theory)
        return float(s[0]) * 12.0 / self.h ** 3, bool(perc[0])

    def state(self, v):
        """(ln π_c, σ̄) at v [h_rms]."""
        p = float(contact_pressure(self.psd, v * self.h, self.E))
        s, _ = self.sigma_bar_at_p(p)
        return math.log(p / self.E), s

    def default_start(self):
        """v where p_cont = 1e-3 p0 (the fastcontact default start rule, SPEC-independent)."""
        return float(mean_separation(self.psd, P_START * self.p0, self.E)) / self.h

    def _f(self, w):
        self.evals += 1
        e = math.exp(w)
        lnp, s = self.state(self.v_inf + e)
        if s <= 0.0:
            return 0.0
        return e / (s * -math.expm1(lnp - self.lnpi0))

    def _tail(self, a, b):
        """∫_a^b dv/σ̄ for v >= V_DIRECT (π_c/π0 negligible), σ̄ = y³ - c y, y = v + d, with
        (c, d) fitted to the direct σ̄ and its slope (central difference) at V_DIRECT.

        (Critical junction: u1(ζc) ≈ ū + 0.33 h_rms at large ū, so σ̄ ≈ (v + d)³; effective
        medium: σ̄ ≈ v³ - 1.7 v, i.e. φ_p ≈ 1 - 1.7/v²; average: σ̄ = v³.)"""
        if self._tail_cd is None:
            v, hv = V_DIRECT, 0.5
            s = self.state(v)[1]
            s1 = (self.state(v + hv)[1] - self.state(v - hv)[1]) / (2 * hv)
            y = v
            for _ in range(100):
                dy = (2 * y ** 3 - s1 * y + s) / (6 * y * y - s1)
                y -= dy
                if abs(dy) < 1e-15 * y:
                    break
            self._tail_cd = (3 * y * y - s1, y - v)
        c, d = self._tail_cd
        a, b = a + d, b + d
        ia2 = 1.0 / (a * a)
        ib2 = 0.0 if b == math.inf else 1.0 / (b * b)
        if abs(c) * ia2 < 1e-6:
            return (0.5 * (ia2 - ib2) + 0.25 * c * (ia2 ** 2 - ib2 ** 2)
                    + c * c / 6.0 * (ia2 ** 3 - ib2 ** 3))
        lb = 0.0 if b == math.inf else math.log1p(-c * ib2)
        return (lb - math.log1p(-c * ia2)) / (2.0 * c)

    def time(self, v_b, v_a):
        """t̃ to go from v_a down to v_b (v∞ < v_b < v_a <= inf), τ0 units."""
        total = 0.0
        if v_a > V_DIRECT:
            lo = max(v_b, V_DIRECT)
            total += self._tail(lo, v_a)
            if v_b >= V_DIRECT:
                return total
            v_a = V_DIRECT
        wa = math.log(v_a - self.v_inf)
        wb = math.log(v_b - self.v_inf)
        # break points every unit in w: keeps quad's bisection honest over long ranges
        pts = list(np.arange(math.ceil(wb), wa, 1.0)) if wa - wb > 1 else None
        val, err = integrate.quad(self._f, wb, wa, epsabs=0.0, epsrel=EPSREL, limit=400,
                                  points=pts)
        return total + val

    def t_ratio(self, ratio, v_start=None):
        v_start = self.default_start() if v_start is None else v_start
        return self.time(ratio * self.v_inf, v_start)

    def t_du(self, dv, v_start=None):
        v_start = self.default_start() if v_start is None else v_start
        return self.time(self.v_inf + dv, v_start)


    def v_at(self, t, v_start=None, tol=1e-12):
        """v(t̃) from v_start (τ0 units): root of time(v, v_start) = t̃ in w = ln(v - v∞),
        safeguarded Newton with dt̃/dw = the integrand (each step one scipy quad)."""
        v_start = self.default_start() if v_start is None else v_start
        if t <= 0.0:
            return v_start
        hi = math.log(v_start - self.v_inf) if math.isfinite(v_start) else math.log(1e6)
        lo = hi - 2.0
        while self.time(self.v_inf + math.exp(lo), v_start) < t:
            hi, lo = lo, lo - 4.0
        w = 0.5 * (lo + hi)
        for _ in range(60):
            f = self.time(self.v_inf + math.exp(w), v_start) - t
            if f > 0.0:
                lo = w
            else:
                hi = w
            wn = w + f / self._f(w)  # dt/dw = -integrand: t decreases with w
            if not (lo < wn < hi):
                wn = 0.5 * (lo + hi)
            if abs(wn - w) < tol or hi - lo < tol:
                w = wn
                break
            w = wn
        return self.v_inf + math.exp(w)


def tau0(eta, R, h_rms, p0):
    """τ0 = 3ηR²/(2 h_rms² p0) [s]."""
    return 3.0 * eta * R * R / (2.0 * h_rms * h_rms * p0)


def flat_stefan_time(u_a, u_b, p0, eta, R):
    """Stefan law for flat surfaces (SPEC §4): time [s] from film u_a to u_b (< u_a) [m],
    from ū(t) = ū0 [1 + 4ū0² p0 t/(3ηR²)]^{-1/2}."""
    return 3.0 * eta * R * R / (4.0 * p0) * (1.0 / u_b ** 2 - 1.0 / u_a ** 2)


if __name__ == "__main__":  # pragma: no cover - quick self-check
    import time

    from fastcontact import SelfAffinePSD

    psd = SelfAffinePSD(h_rms=1e-5, hurst=0.8, q0=1e4, q1=1e8)
    for th in ("average", "critical_junction", "emt"):
        t0 = time.perf_counter()
        ref = SqueezeReference(psd, 1e7, th, 1e4)
        ts = ref.t_ratio(1.01)
        print(th, "v_inf", ref.v_inf, "t* [tau0]", ts, "evals", ref.evals,
              f"{time.perf_counter() - t0:.2f} s")
