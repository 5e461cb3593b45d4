"""Output columns derived from the squeeze-out kernels' per-row results (and from a
history's ū(t)), each set in one parallel pass (private).

A million-row study spent a fifth of its time outside the time-primitive kernel, in NumPy
expressions that each make one pass and one temporary over the rows (the status flags, ū at
the footprint exit relative to ū∞, the inertia estimates): here each set is one pass over the
rows on every core, with the same IEEE operations in the same order as those expressions
(bit-identical, except ``t_star_inertia``, whose logarithm is libm's instead of NumPy's: within
an ulp).

Case arrays that may hold one value for all rows (E*, R, ρ, ū(0)) are read with a stride of
0 when their size is 1 (as :mod:`fastcontact.squeeze._fastpath` reads them).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..kernels.locate import locate_desc_from
from ..kernels.lookup import lnp_on_interval
from ..kernels.readonly import readonly
from ._kernels import ST_OUT, ST_OVERFLOW, ST_TRAPPED

__all__ = ["status_flags", "exit_columns", "inertia_columns", "history_columns"]


def _one_or_n(a):
    """``a`` as a read-only contiguous float64 1-D array (one value, or one per row): one
    compiled signature whatever the caller's array (:mod:`fastcontact.kernels.readonly`)."""
    return readonly(np.reshape(a, -1))


@njit(parallel=True, cache=True)
def _status_flags(status, u_trap, p0, E, x_perc, trapped, percolated, out_of_table):
    sE = 1 if E.size > 1 else 0
    want_perc = percolated.size > 0
    for i in prange(status.size):
        st = status[i]
        tr = st == ST_TRAPPED or (st == ST_OVERFLOW and math.isfinite(u_trap[i]))
        trapped[i] = tr
        out_of_table[i] = st == ST_OUT
        if want_perc:
            percolated[i] = tr and math.log(p0[i] / E[i * sE]) >= x_perc


def status_flags(status, u_trap, p0=None, E=None, x_perc=math.nan):
    """(trapped, percolated, out_of_table) boolean columns of the int8 ``status`` codes.

    ``trapped``: fluid trapped by the physics (ū_trap set), also on rows whose status says
    "overflow" (τ0 or a time not representable). ``percolated`` (None unless ``p0`` [Pa] and
    ``E`` [Pa] are given): trapped with ln(p0/E*) >= ``x_perc`` (all False where x_perc is not
    finite: no percolation). ``out_of_table``: outside the tables' pressure range."""
    n = status.size
    trapped = np.empty(n, dtype=np.bool_)
    oot = np.empty(n, dtype=np.bool_)
    perc = None if p0 is None else np.zeros(n, dtype=np.bool_)
    live = perc is not None and math.isfinite(x_perc)
    _status_flags(readonly(status, np.int8), _one_or_n(u_trap), _one_or_n(p0 if live else 1.0),
                  _one_or_n(E if live else 1.0), float(x_perc), trapped,
                  perc if live else np.empty(0, dtype=np.bool_), oot)
    return trapped, perc, oot


@njit(parallel=True, cache=True)
def _exit_columns(u_exit, u_inf, du_complete, du_exit, complete):
    for i in prange(u_exit.size):
        d = u_exit[i] - u_inf[i]
        du_exit[i] = d
        complete[i] = d <= du_complete  # NaN rows: False


def exit_columns(u_exit, u_inf, du_complete):
    """(du_exit = ū_exit − ū∞ [m], squeeze_complete = du_exit <= du_complete) of the rows
    (ū_exit and ū∞ [m]; du_complete [m]); NaN rows are not complete."""
    n = u_exit.size
    du_exit = np.empty(n)
    complete = np.empty(n, dtype=np.bool_)
    _exit_columns(_one_or_n(u_exit), _one_or_n(u_inf), float(du_complete), du_exit, complete)
    return du_exit, complete


@njit(parallel=True, cache=True)
def _inertia_columns(R, rho, p, u0, h_rms, tau, tstar):
    sR = 1 if R.size > 1 else 0
    sr = 1 if rho.size > 1 else 0
    n = p.size
    for i in prange(n):  # no branch: the loop vectorizes (sqrt and division)
        D = 2.0 * R[i * sR]
        v = D * D
        v *= rho[i * sr]
        v /= p[i]
        v *= 1.0 / 64.0
        tau[i] = math.sqrt(v)
    if tstar.size == 0:
        return
    if u0.size == 1:  # one ū(0) for all rows: one logarithm
        L = math.log(u0[0] / h_rms) if u0[0] > h_rms else math.nan
        for i in prange(n):
            tstar[i] = tau[i] * L
        return
    for i in prange(n):
        u = u0[i]
        tstar[i] = tau[i] * math.log(u / h_rms) if u > h_rms else math.nan


def inertia_columns(R, rho, p, u_start, h_rms):
    """(tau_inertia, t_star_inertia) [s] of the rows: τ' = (D²ρ/(64 p))^{1/2} with D = 2R
    and t*' = τ' ln(ū(0)/h_rms) (Lorenz & Persson 2010, Sec. 5; NaN where ū(0) <= h_rms or
    unknown). R [m], ρ [kg/m³] and ū(0) [m] one value or one per row (one ū(0): one
    logarithm for all rows), p [Pa] one per row, h_rms [m]; ``u_start`` None: t*' is all NaN.
    τ' = inf where D²ρ/p overflows (R ~ 1e308 m; the squeeze-out status of such a row says
    "overflow")."""
    n = p.size
    tau = np.empty(n)
    tstar = np.empty(n) if u_start is not None else np.full(n, np.nan)
    _inertia_columns(_one_or_n(R), _one_or_n(rho), _one_or_n(p),
                     _one_or_n(1.0 if u_start is None else u_start), float(h_rms), tau,
                     tstar if u_start is not None else np.empty(0))
    return tau, tstar


#: points per block of :func:`_history_columns` (each block walks its points in order, each
#: lookup first trying the interval of the one before: ū(t) of sorted times is monotone)
HISTORY_BLOCK = 1024


@njit(parallel=True, cache=True)
def _history_columns(tab, mp, u, h, pi0, p0, us, c_num, c_den, t, ratio, pfm, flat):
    # the table's arrays taken out of the record once: a lookup that receives the whole
    # record by value costs twice the lookup (kernels.lookup.lnp_on_interval)
    n = u.size
    for b in prange((n + HISTORY_BLOCK - 1) // HISTORY_BLOCK):
        _history_block(tab.lnp, tab.lnu, tab.dlnu, tab.d2lnu, tab.bu_lo, tab.bu_dz, tab.bu_idx,
                       mp.v_top, mp.x_min, mp.u0, u, h, pi0, p0, us, c_num, c_den, t, ratio,
                       pfm, flat, b * HISTORY_BLOCK, min(b * HISTORY_BLOCK + HISTORY_BLOCK, n))


@njit(cache=True)
def _history_block(lnp, lnu, a, d2, blo, bdz, bidx, v_top, x_min, u0, u, h, pi0, p0, us,
                   c_num, c_den, t, ratio, pfm, flat, k0, k1):
    i = -1
    for k in range(k0, k1):
        v = u[k] / h
        if v > v_top:  # eq. (3) tail above the table top (squeeze._kernels._lnp_of_v)
            x = x_min - (v - v_top) / u0
        else:
            y = math.log(v)
            i = locate_desc_from(y, lnu, blo, bdz, bidx, i)
            x = math.nan if i < 0 else lnp_on_interval(lnp, lnu, a, d2, i, y)
        r = math.exp(x) / pi0
        ratio[k] = r
        pfm[k] = p0 * (1.0 - r)
        tk = t[k]
        flat[k] = us / math.sqrt(1.0 + c_num * tk / c_den) if tk < math.inf else 0.0


def history_columns(model, u, t, p0, E_star, eta, R, u_start):
    """(p_cont_over_p0, p_fluid_mean [Pa], u_flat [m]) of one case's history ū(t) [m] at the
    times t [s] (>= 0, +inf allowed), in one parallel pass.

    p_cont/p0 = π_c(ū/h_rms)/(p0/E*) from the model's tables (their eq. (3) tail above the
    top), p̄_f = p0 (1 − p_cont/p0) (eq. 19), and the Stefan law for a flat substrate from
    the same start, ū0 [1 + 4ū0² p0 t/(3ηR²)]^{-1/2} (eq. 1 with p_cont = 0; 0 at t = inf).
    Scalars p0 [Pa], E_star [Pa], eta [Pa·s], R [m], u_start = ū0 [m]. Same values as
    ``model.p_of_v`` and :func:`fastcontact.squeeze.reduced.flat_separation` (bit for bit:
    the same operations in the same order)."""
    n = u.size
    ratio, pfm, flat = np.empty(n), np.empty(n), np.empty(n)
    us, p0, eta, R = (np.float64(x) for x in (u_start, p0, eta, R))
    _history_columns(model.tab, model.mp, _one_or_n(u), float(model.h_rms),
                     float(p0 / np.float64(E_star)), float(p0), float(us),
                     float(4.0 * us**2 * p0), float(3.0 * eta * R**2), _one_or_n(t), ratio,
                     pfm, flat)
    return ratio, pfm, flat
