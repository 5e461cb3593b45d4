"""Independent reference for the trapped rows of squeeze-out (issue 11.1): the time
t̃ = ∫ dv/(σ̄ (1 - π_c/π0)) between two separations above v_trap, and to v_trap itself.

A composite Gauss–Legendre quadrature in w = ln(v - v_trap), written apart from the library:
its panels are broken at the tables' nodes (where their interpolants are only C² and σ̄'s
cubic continuation to percolation begins at the last open node) and its own convergence is
checked by halving the panels. The integrand's state (π_c, σ̄ of the tables' interpolants)
is the library's (``state_gap``): this measures the engine's error on its tables, not the
tables' error against the direct core.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from fastcontact.squeeze import _kernels as qk


@njit
def _gl_sum(tab, mp, x0, vb, wa, wb, breaks, width, gx, gw):
    """∫_{wa}^{wb} e^w / (σ̄ (1 - π_c/π0)) dw at v = vb + e^w: panels of at most ``width``,
    broken at ``breaks`` (ascending)."""
    acc = 0.0
    a = wa
    for q in range(breaks.size + 1):
        b = wb if q == breaks.size else breaks[q]
        if b <= a:
            continue
        if b > wb:
            b = wb
        m = int(math.ceil((b - a) / width))
        hw = (b - a) / m
        for k in range(m):
            s = 0.0
            for j in range(gx.size):
                w = a + k * hw + 0.5 * hw * (1.0 + gx[j])
                sig, d = qk.state_gap(tab, mp, x0, vb, math.exp(w))
                s += gw[j] * math.exp(w) / (sig * d)
            acc += 0.5 * hw * s
        a = b
        if a >= wb:
            break
    return acc


class TrappedReference:
    """Reference times of one model's trapped rows (reduced units, τ0)."""

    def __init__(self, m):
        self.m = m
        self.vb = m.mp.v_trap
        v = np.exp(np.asarray(m.tab.lnu, dtype=np.float64))
        v = np.append(v, m.mp.v_top)
        v = np.sort(v[v > self.vb * (1.0 + 1e-14)])
        self.breaks = np.ascontiguousarray(np.log(v - self.vb))
        self.gx, self.gw = np.polynomial.legendre.leggauss(12)

    def _int(self, x0, wa, wb, width):
        return _gl_sum(self.m.tab, self.m.mp, x0, self.vb, wa, wb, self.breaks, width, self.gx,
                       self.gw)

    def time(self, x0, v_hi, v_lo, width=0.05):
        """t̃ from v_hi down to v_lo (both above v_trap, below v_ext), converged: the result
        with half the panel width agrees to 1e-9 (asserted)."""
        return self.time_w(x0, math.log(v_lo - self.vb), math.log(v_hi - self.vb), width)

    def time_w(self, x0, wa, wb, width=0.05):
        """:meth:`time` between w = ln(v - v_trap) = wb and wa < wb."""
        a, b = self._int(x0, wa, wb, width), self._int(x0, wa, wb, 0.5 * width)
        assert abs(a / b - 1.0) < 1e-9, (x0, wa, wb, a, b)
        return b

    def t_trap(self, x0, v_hi):
        """t̃ from v_hi down to v_trap: 40 e-folds of w below v_trap by quadrature, the rest
        in closed form (the integrand is e^w × its value there)."""
        w_lo = math.log(self.vb) - 40.0
        sig, d = qk.state_gap(self.m.tab, self.m.mp, x0, self.vb, math.exp(w_lo))
        return math.exp(w_lo) / (sig * d) + self.time_w(x0, w_lo, math.log(v_hi - self.vb))


class BelowTrapReference:
    """Reference times of one non-trapped case (ln π0 = x0 below the trap pressure) on the
    same tables (reduced units, τ0): ū∞ and the default start by brentq on the tables'
    ln π_c(v) (independent of the engine's Newton solves), times by :func:`_gl_sum` in
    w = ln(v - v∞) with panels broken at the tables' nodes, converged by halving."""

    def __init__(self, m, x0):
        self.m, self.x0 = m, float(x0)
        self.v_inf = self._root_v(self.x0)
        self.v_start = self._root_v(self.x0 + math.log(1e-3))  # documented: p_cont = 1e-3 p0
        v = np.exp(np.asarray(m.tab.lnu, dtype=np.float64))
        v = np.sort(np.append(v, m.mp.v_top))
        self.breaks = np.ascontiguousarray(np.log(v[v > self.v_inf * (1 + 1e-12)] - self.v_inf))
        self.gx, self.gw = np.polynomial.legendre.leggauss(12)

    def _root_v(self, x):
        from scipy.optimize import brentq

        m = self.m

        def f(lv):
            return qk._state(m.tab, m.mp, math.exp(lv))[0] - x

        lo, hi = math.log(m.tables.u_range[0]) + 1e-12, math.log(m.tables.u_range[1]) - 1e-12
        return math.exp(brentq(f, lo, hi, xtol=1e-15, rtol=1e-15, maxiter=400))

    def time(self, dv_lo, v_hi=None, width=0.05):
        """t̃ from v_hi (default: the default start) down to v∞ + dv_lo; the result with half
        the panel width agrees to 1e-10 (asserted)."""
        v_hi = self.v_start if v_hi is None else v_hi
        wa, wb = math.log(dv_lo), math.log(v_hi - self.v_inf)
        a, b = (_gl_sum(self.m.tab, self.m.mp, self.x0, self.v_inf, wa, wb, self.breaks, w,
                        self.gx, self.gw) for w in (width, 0.5 * width))
        assert abs(a / b - 1.0) < 1e-10, (self.x0, dv_lo, a, b)
        return b
