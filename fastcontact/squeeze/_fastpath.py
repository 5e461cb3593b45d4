"""Parallel per-case kernels on the time primitive (``method="fast"``).

Every output is a few interpolations of the primitive T(x0, ū) per case
(:mod:`fastcontact.squeeze.primitive`): t(a → b) = τ0 [T(b) - T(a)], ū(t) from
T(ū) = T(ū_start) + t/τ0. Rows the primitive does not serve (trapped fluid, p0 within 1 % of
the trap pressure) fall back to the per-case quadrature in the same pass.
"""
from __future__ import annotations

import math

from numba import njit, prange

from . import _kernels as qk
from .primitive import row_value, stencil, t_of_z, z_of_t

__all__ = ["fast_kernel", "history_kernel"]


@njit(cache=True)
def _start(pr, st, vinf, vs_in):
    """(v_start, T(v_start)) of a case: the default start (NaN in) or the given one."""
    if vs_in != vs_in:
        zs = row_value(pr.zs, st)
        vs = vinf * (1.0 + math.exp(zs))
    else:
        vs = vs_in
        if vs == math.inf:
            return vs, 0.0
        zs = math.log(vs / vinf - 1.0)
    return vs, t_of_z(pr, st, vinf, zs)


@njit(cache=True)
def _targets(pr, st, vinf, vs, Ts, tg, tau, i, out):
    """Times [s] to t_star (ū = 1.01 ū∞), the ratios and the Δu targets; 0 if passed."""
    nr = tg.ratios.size
    for k in range(out.T.shape[0]):
        if k == 0:
            r1 = 0.01
        elif k <= nr:
            r1 = tg.ratios[k - 1] - 1.0
        else:
            r1 = tg.dvs[k - 1 - nr] / vinf
        if vinf * (1.0 + r1) >= vs:
            out.T[k, i] = 0.0
        else:
            out.T[k, i] = tau * (t_of_z(pr, st, vinf, math.log(r1)) - Ts)


@njit(cache=True)
def _times(pr, st, vinf, vs, Ts, tg, tau, h, i, out):
    """ū [m] at the times of row i (shared or per case)."""
    col = i if tg.times.shape[1] > 1 else i - i  # same integer type as i
    for k in range(out.U.shape[0]):
        tk = tg.times[k, col] / tau
        if tk == 0.0:
            out.U[k, i] = vs * h
        elif tk == math.inf:
            out.U[k, i] = vinf * h
        else:
            z = z_of_t(pr, st, vinf, Ts + tk)
            # ū(t) <= ū(0): the inverse interpolation can land an ulp above the start for
            # t → 0; keep the ODE's monotonicity exactly (a round-off bound, not a clamp of data)
            out.U[k, i] = min(vinf * (1.0 + math.exp(z)), vs) * h


@njit(cache=True)
def fast_case(tab, mp, pr, x_fast, x0, vs_in, tg, tau, h, quad, i, out):
    """Everything for one case from the primitive, written in SI to column i of ``out``."""
    if not (mp.x_min <= x0 <= mp.x_max):
        qk.quad_case(tab, mp, x0, vs_in, tg, tau, h, quad, i, out)  # writes the NaN row
        return
    if x0 > x_fast:
        qk.quad_case(tab, mp, x0, vs_in, tg, tau, h, quad, i, out)
        return
    st = stencil(pr, x0)
    vinf = math.exp(row_value(pr.lnv, st))
    out.u_inf[i] = vinf * h
    if not (vs_in != vs_in or vs_in > vinf):
        qk._nan_row(out, i, x0)
        out.u_inf[i] = vinf * h
        out.u_start[i] = vs_in * h
        out.status[i] = qk.ST_BELOW
        return
    vs, Ts = _start(pr, st, vinf, vs_in)
    out.u_start[i] = vs * h
    out.t_relax[i] = tau * math.exp(row_value(pr.lnS, st))
    out.u_trap[i] = math.nan
    out.t_trap[i] = math.inf
    out.flf[i] = 0.0
    out.status[i] = qk.ST_OK
    _targets(pr, st, vinf, vs, Ts, tg, tau, i, out)
    _times(pr, st, vinf, vs, Ts, tg, tau, h, i, out)


@njit(cache=True)
def _flag_overflow(tau, i, out):
    """Write τ0; status "overflow" where τ0 or a time is not representable (inf or 0) on a
    computed row. (Writes happen in this callee: a setitem on a record field directly in
    the prange body is lost by numba's parfor lowering.)"""
    out.tau0[i] = tau
    if out.status[i] != qk.ST_OK:
        return
    bad = not (0.0 < tau < math.inf)
    for k in range(out.T.shape[0]):
        if out.T[k, i] == math.inf:
            bad = True
    if bad:
        out.status[i] = qk.ST_OVERFLOW


@njit(parallel=True, cache=True)
def fast_kernel(tab, mp, pr, x_fast, cs, h, tg, quad, out):
    """method="fast": every case from the primitive (fall-back rows by quadrature)."""
    for i in prange(cs.p0.size):
        tau = 3.0 * cs.eta[i] * cs.R[i] * cs.R[i] / (2.0 * h * h * cs.p0[i])
        fast_case(tab, mp, pr, x_fast, math.log(cs.p0[i] / cs.E[i]), cs.us[i] / h, tg, tau, h,
                  quad, i, out)
        _flag_overflow(tau, i, out)


@njit(parallel=True, cache=True)
def quad_kernel(tab, mp, cs, h, tg, quad, out):
    """method="quad": every case by per-case quadrature (one prange pass)."""
    for i in prange(cs.p0.size):
        tau = 3.0 * cs.eta[i] * cs.R[i] * cs.R[i] / (2.0 * h * h * cs.p0[i])
        qk.quad_case(tab, mp, math.log(cs.p0[i] / cs.E[i]), cs.us[i] / h, tg, tau, h, quad, i,
                     out)
        _flag_overflow(tau, i, out)


@njit(parallel=True, cache=True)
def history_kernel(pr, x0, vs_in, tau, h, t, u):
    """ū [m] of one case (on the primitive's rows) at the times t [s]."""
    st = stencil(pr, x0)
    vinf = math.exp(row_value(pr.lnv, st))
    vs, Ts = _start(pr, st, vinf, vs_in)
    for k in prange(t.size):
        tk = t[k] / tau
        if tk == 0.0:
            u[k] = vs * h
        elif tk == math.inf:
            u[k] = vinf * h
        else:
            u[k] = min(vinf * (1.0 + math.exp(z_of_t(pr, st, vinf, Ts + tk))), vs) * h
