"""Numba kernels: reduced conductivity σ̄(π) and separation ū(π) of the seal engine (private).

Reduced units: π = p_cont/E*, t = ln π, σ̄ = 12ησ_eff/h_rms³ (eq. 23). Every kernel takes the
table record ``tab`` (:meth:`fastcontact.tables.Tables.kernel_data`) and the seal record ``sc``
(:class:`fastcontact.seal.context.SealRecord`), both flat, so they pass into ``prange``.

σ̄ beyond the table: at and above the percolation pressure exactly 0; below the table
(ū ≳ 32 h_rms) the large-separation asymptote, σ̄^(1/3) = b0 + b1 (t_lo − t), continued C¹.
Inside: ln σ̄ re-tabulated on a uniform t grid (cubic Hermite, every cell verified against the
table kernel); unverified cells evaluate the table's own quintic (value and exact slope).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..kernels.hermite import quintic_interval, quintic_unit
from ..kernels.locate import locate_asc
from ..kernels.lookup import sigma_interval_resolved, sigma_linear
from ..kernels.records import scalar_record
from ..tables import k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp

__all__ = ["sig_d", "table_sig_d", "sigma_of_c", "ubar_of_c", "retabulate", "verify_cells",
           "sigma_rows", "ubar_rows", "contact_of_u", "HS_FIELDS", "hot_scalars"]

#: fields of the hot scalars ``sc.HS`` (re-tabulation origin and step, table bottom, asymptote,
#: ln π_perc, primitive origin, coarse step and its inverse, the table's bucket map, its open
#: nodes, ln p̄_c), read as ``HS[0].rt0``. A structured record (:func:`scalar_record`), not a
#: namedtuple: numba 0.68's parfor lowering fails on a namedtuple of scalars used inside a
#: prange body, and these scalars reach the innermost σ̄ lookups there.
HS_FIELDS = ("rt0", "rh", "t_lo", "b0", "b1", "t_perc", "st0", "sh", "tq_lo", "tq_dz", "n_open",
             "lnp_perc", "ish")


def hot_scalars(**fields) -> np.ndarray:
    """The record ``sc.HS`` from its fields (:data:`HS_FIELDS`, ``n_open`` an integer)."""
    if set(fields) != set(HS_FIELDS):
        raise ValueError(f"hot_scalars needs exactly the fields {HS_FIELDS}")
    return scalar_record({k: fields[k] for k in HS_FIELDS}, ints=("n_open",))


# =========================================================================== σ̄ and ū
@njit(cache=True)
def table_sig_d(tab, t):
    """(σ̄, d ln σ̄/dt) of the table interpolant at t = ln π (exactly k_sigma_of_lnp's value,
    and the slope of the same interpolant); (0, -inf) at/after percolation, NaN outside."""
    lnp = tab.lnp
    i = locate_asc(t, lnp, tab.bp_lo, tab.bp_dz, tab.bp_idx)
    if i < 0:
        return math.nan, math.nan
    if t >= tab.lnp_perc:
        return 0.0, -math.inf
    if i + 1 < tab.n_open:
        h = lnp[i + 1] - lnp[i]
        if not sigma_interval_resolved(lnp[i], lnp[i + 1], tab.lnsig[i], tab.lnsig[i + 1],
                                       tab.dlnsig[i], tab.dlnsig[i + 1]):
            # as k_sigma_of_lnp: linear in ln σ̄ across an unresolved interval
            return (math.exp(sigma_linear(t, lnp[i], lnp[i + 1], tab.lnsig[i], tab.lnsig[i + 1])),
                    (tab.lnsig[i + 1] - tab.lnsig[i]) / h)
        y, dy = quintic_unit((t - lnp[i]) / h, h, tab.lnsig[i], tab.dlnsig[i], tab.d2lnsig[i],
                             tab.lnsig[i + 1], tab.dlnsig[i + 1], tab.d2lnsig[i + 1])
        return math.exp(y), dy
    j = tab.n_open - 1
    if j < 0 or tab.lnp_perc == math.inf:
        return 0.0, -math.inf
    d = tab.lnp_perc - t
    cr = math.exp(tab.lnsig[j] / 3.0) * d / (tab.lnp_perc - lnp[j])
    return cr * cr * cr, -3.0 / d


@njit(cache=True)
def sig_d(tab, sc, t):
    """(σ̄, d ln σ̄/d t) at t = ln π; (0, -inf) at/after percolation, NaN above the table."""
    return sig_d_at(tab, sc, t)


@njit(cache=True, inline="always")
def sig_d_at(tab, sc, t):
    """:func:`sig_d` inline, for loops over nodes on borrowed records
    (:mod:`fastcontact.kernels.borrow`): a call per node that passes both records by value
    cost more than the lookup."""
    s, dl, hit = sig_d_cells(sc.t_lo, sc.t_hi, sc.t_perc, sc.b0, sc.b1, sc.rt0, sc.rh, sc.ok,
                             sc.lns, sc.dlns, t)
    if hit:
        return s, dl
    return table_sig_d(tab, t)             # unverified cell: the table's own quintic


@njit(cache=True, inline="always")
def sig_d_cells(t_lo, t_hi, t_perc, b0, b1, rt0, rh, ok, lns, dlns, t):
    """:func:`sig_d` from the seal record's fields (a loop over nodes takes them out of the
    record once: passing the seal and table records, 45 fields, to a call per node cost more
    than the lookup): (σ̄, d ln σ̄/dt, True), or (NaN, NaN, False) in a cell the
    re-tabulation did not verify (then ``table_sig_d`` answers)."""
    if t < t_lo:
        s = b0 + b1 * (t_lo - t)
        return s * s * s, -3.0 * b1 / s, True
    if t >= t_perc:
        return 0.0, -math.inf, True
    if t > t_hi:
        return math.nan, math.nan, True
    h = rh
    u = (t - rt0) / h
    k = int(u)
    if k >= 0 and k < ok.size and ok[k]:
        x = u - k
        x2 = x * x
        x3 = x2 * x
        y0 = lns[k]
        y1 = lns[k + 1]
        d0 = dlns[k] * h
        d1 = dlns[k + 1] * h
        y = ((2 * x3 - 3 * x2 + 1) * y0 + (x3 - 2 * x2 + x) * d0 + (-2 * x3 + 3 * x2) * y1
             + (x3 - x2) * d1)
        dy = ((6 * x2 - 6 * x) * y0 + (3 * x2 - 4 * x + 1) * d0 + (-6 * x2 + 6 * x) * y1
              + (3 * x2 - 2 * x) * d1) / h
        return math.exp(y), dy, True
    return math.nan, math.nan, False


@njit(cache=True)
def _tab_sig(TQ, TQB, HS, t):
    """σ̄ at t from the table's own interpolant on the packed copy ``TQ`` (columns ln p̄,
    ln σ̄, d ln σ̄/d ln p̄, d² ln σ̄/d(ln p̄)²) — the same arithmetic as k_sigma_of_lnp."""
    hs = HS[0]
    n = TQ.shape[0]
    if not (TQ[0, 0] <= t <= TQ[n - 1, 0]):
        return math.nan
    c = int((t - hs.tq_lo) / hs.tq_dz)
    c = min(max(c, 0), TQB.size - 1)
    i = TQB[c]
    while i < n - 2 and TQ[i + 1, 0] < t:
        i += 1
    lnp_perc = hs.lnp_perc
    if t >= lnp_perc:
        return 0.0
    n_open = hs.n_open
    if i + 1 < n_open:
        if not sigma_interval_resolved(TQ[i, 0], TQ[i + 1, 0], TQ[i, 1], TQ[i + 1, 1], TQ[i, 2],
                                       TQ[i + 1, 2]):  # as k_sigma_of_lnp
            return math.exp(sigma_linear(t, TQ[i, 0], TQ[i + 1, 0], TQ[i, 1], TQ[i + 1, 1]))
        return math.exp(quintic_interval(t, TQ[i, 0], TQ[i + 1, 0], TQ[i, 1], TQ[i + 1, 1],
                                         TQ[i, 2], TQ[i + 1, 2], TQ[i, 3], TQ[i + 1, 3]))
    j = n_open - 1
    if j < 0 or lnp_perc == math.inf:
        return 0.0
    cr = math.exp(TQ[j, 1] / 3.0) * (lnp_perc - t) / (lnp_perc - TQ[j, 0])
    return cr * cr * cr


@njit(cache=True)
def _sig_fast(R, TQ, TQB, HS, t):
    """σ̄ at t (value only): the asymptote below the table, the verified re-tabulation
    (``R`` columns ln σ̄, d ln σ̄/dt, cell verified), else the table's own quintic."""
    hs = HS[0]
    t_lo = hs.t_lo
    if t < t_lo:
        s = hs.b0 + hs.b1 * (t_lo - t)
        return s * s * s
    if t >= hs.t_perc:
        return 0.0
    rh = hs.rh
    u = (t - hs.rt0) / rh
    k = int(u)
    if k < 0 or k >= R.shape[0] - 1 or R[k, 2] == 0.0:
        return _tab_sig(TQ, TQB, HS, t)
    x = u - k
    x2 = x * x
    x3 = x2 * x
    y = ((2 * x3 - 3 * x2 + 1) * R[k, 0] + (x3 - 2 * x2 + x) * (R[k, 1] * rh)
         + (-2 * x3 + 3 * x2) * R[k + 1, 0] + (x3 - x2) * (R[k + 1, 1] * rh))
    return math.exp(y)


@njit(cache=True)
def sigma_of_c(tab, sc, c):
    """σ̄ at reduced contact pressure c (inf for c <= 0: lifted off)."""
    if c <= 0.0:
        return math.inf
    return sig_d(tab, sc, math.log(c))[0]


@njit(cache=True)
def ubar_of_c(tab, sc, c):
    """ū/h_rms at reduced contact pressure c (inf for c <= 0; asymptote below the table)."""
    if c <= 0.0:
        return math.inf
    t = math.log(c)
    if t < sc.t_lo:
        return sc.u_lo + sc.c_u * (sc.t_lo - t)
    if t > sc.t_hi:
        return math.nan
    return math.exp(k_lnu_of_lnp(tab, t))


@njit(cache=True)
def retabulate(tab, t0, h, n):
    """ln σ̄ and d ln σ̄/d t of the table interpolant at t0 + k h (NaN where σ̄ = 0)."""
    lns = np.empty(n)
    dlns = np.empty(n)
    for k in range(n):
        s, dl = table_sig_d(tab, t0 + k * h)
        if s > 0.0 and dl == dl:
            lns[k] = math.log(s)
            dlns[k] = dl
        else:
            lns[k] = math.nan
            dlns[k] = math.nan
    return lns, dlns


@njit(cache=True)
def verify_cells(tab, sc, tol):
    """ok[k]: the re-tabulated cubic matches k_sigma_of_lnp within tol at 3 interior points.

    ``sc`` must carry ``ok`` all True (the provisional record). Returns (ok, worst error)."""
    n = sc.lns.size - 1
    ok = np.zeros(n, dtype=np.bool_)
    worst = 0.0
    for k in range(n):
        if not (sc.lns[k] == sc.lns[k] and sc.lns[k + 1] == sc.lns[k + 1]):
            continue
        good = True
        for f in (0.25, 0.5, 0.75):
            t = sc.rt0 + (k + f) * sc.rh
            ref = k_sigma_of_lnp(tab, t)
            if not ref > 0.0:
                good = False
                break
            e = abs(sig_d(tab, sc, t)[0] / ref - 1.0)
            if e > tol:
                good = False
                break
            worst = max(worst, e)
        ok[k] = good
    return ok, worst


@njit(cache=True, parallel=True)
def sigma_rows(tab, sc, c, out):
    """σ̄ at reduced contact pressures c (inf at c <= 0)."""
    for i in prange(c.size):
        out[i] = sigma_of_c(tab, sc, c[i])


@njit(cache=True, parallel=True)
def ubar_rows(tab, sc, c, out):
    """ū/h_rms at reduced contact pressures c (inf at c <= 0)."""
    for i in prange(c.size):
        out[i] = ubar_of_c(tab, sc, c[i])



@njit(cache=True)
def contact_of_u(tab, sc, ubar, lnp_out, dlnp_out, sig_out, dlns_out):
    """At ū/h_rms: ln π_cont, d ln π/dū (per h_rms), σ̄ and d ln σ̄/d ln π (stiff seals).

    Inside the table: the inverse interpolant (derivative by central difference); beyond
    ū_lo (~32 h_rms) the asymptote ln π = t_lo − (ū − ū_lo)/u0; below the table NaN."""
    for i in range(ubar.size):
        u = ubar[i]
        if u >= sc.u_lo:
            lnp = sc.t_lo - (u - sc.u_lo) / sc.c_u
            dl = -1.0 / sc.c_u
        else:
            lu = math.log(u)
            lnp = k_lnp_of_lnu(tab, lu)
            if lnp != lnp:
                lnp_out[i] = math.nan
                dlnp_out[i] = math.nan
                sig_out[i] = math.nan
                dlns_out[i] = math.nan
                continue
            dd = 1e-6
            a = k_lnp_of_lnu(tab, lu + dd)
            b = k_lnp_of_lnu(tab, lu - dd)
            if a == a and b == b:
                dl = (a - b) / (2.0 * dd) / u
            elif a == a:
                dl = (a - lnp) / dd / u
            else:
                dl = (lnp - b) / dd / u
        lnp_out[i] = lnp
        dlnp_out[i] = dl
        s, dl2 = sig_d(tab, sc, lnp)
        sig_out[i] = s
        dlns_out[i] = dl2
