"""The seal engine's per-(tables, theory) context: one flat record for every numba kernel.

:class:`SealRecord` is a flat namedtuple (arrays and scalars only), so it passes into
``prange`` drivers next to the table record ``tab``; :class:`SealContext` holds both with the
metadata the Python side needs. Built lazily, once per Tables object and theory, and cached.
"""
from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from .._core.cache import PerObjectCache
from ..flow.conductivity import check_theory
from ..kernels.balance import spread_order
from ..kernels.quadrature import gauss_legendre
from ..tables.build import verified_top
from . import _panels, _sigma

__all__ = ["SealRecord", "SealContext", "seal_context", "PanelRule", "RowsOut", "panel_rule",
           "solver_options", "SOLVER_DEFAULTS", "RETAB_H", "RETAB_TOL", "PRIM_H", "PRIM_GL",
           "PRIM_DEPTH", "TAIL_SPLIT", "NEAR_LIFT_OFF", "EQUALITY_TOL", "solve_profile_rows",
           "spread_rows", "peak_past_trust"]

#: re-tabulation of ln σ̄ (uniform in ln π): spacing and per-cell verification tolerance
RETAB_H = 1.0 / 64.0
RETAB_TOL = 1e-9
#: primitive of σ̄: coarse node spacing in ln π and the Gauss–Legendre order of direct intervals
PRIM_H = 1.0 / 64.0
PRIM_GL = 6
#: cells below the trusted top whose quintic partials fail verification are bisected at most
#: this many times (down to PRIM_H / 2**PRIM_DEPTH)
PRIM_DEPTH = 10
#: the unverified tail above the trusted top gets cells this many times finer than PRIM_H
TAIL_SPLIT = 16


class SealRecord(NamedTuple):
    """Flat record of one (tables, theory) for the seal kernels (reduced units).

    Attributes
    ----------
    t_lo, t_hi : float
        ln π at the table's ends (π = p_cont/E*).
    t_perc : float
        ln π_perc (inf: the theory never percolates).
    b0, b1 : float
        σ̄^(1/3) = b0 + b1 (t_lo − t) below the table (C¹ continuation of the asymptote).
    u_lo, c_u : float
        ū/h_rms at the table bottom and u0/h_rms: ū/h_rms = u_lo + c_u (t_lo − t) below it.
    rt0, rh : float
        Re-tabulation grid of ln σ̄: t = rt0 + k rh.
    lns, dlns : ndarray
        ln σ̄ and d ln σ̄/d ln π at the re-tabulation nodes.
    ok : ndarray of bool
        Re-tabulation cells verified against the table kernel.
    st0, sh : float
        Start (= t_lo) and coarse spacing of the primitive's nodes; the bucket map ``B``
        works on this spacing.
    t_top : float
        Last primitive node, min(t_hi, t_perc).
    t_trust, pi_trust, sig_trust : float
        ln π, π and σ̄ at the table's last node with σ̄ above its floor: beyond it, just below
        percolation, σ̄ is not verified ("average": the table's top, σ̄ = (ū/h_rms)³ is
        verified through ū everywhere).
    P : ndarray, shape (n + 1, 8)
        The primitive S(t) = ∫ σ̄ e^t dt per node k: t, S', S'', ∫ over cell k, prefix and
        suffix sums (compensated), cell k verified (1.0), 1/width of cell k — columns
        ``_sigma.P_*``.
    B : ndarray of int64
        B[c]: the cell holding st0 + c sh (bucket map of P's nodes).
    glx, glw : ndarray
        Gauss–Legendre rule of the direct intervals.
    R, TQ, TQB, HS, G : ndarray
        Packed copies for the flat-ring kernel: R = (ln σ̄, d ln σ̄/dt, cell verified) per
        re-tabulation node; TQ = the table's (ln p̄, ln σ̄, d ln σ̄, d² ln σ̄) per node and
        TQB its bucket map; HS the hot scalars (record, fields ``_sigma.HS_FIELDS``);
        G = (glx, glw).
    h_rms : float
        rms roughness [m].
    p_perc, p_top : float
        Percolation pressure and table top, reduced (p/E*).
    """

    t_lo: float
    t_hi: float
    t_perc: float
    b0: float
    b1: float
    u_lo: float
    c_u: float
    rt0: float
    rh: float
    lns: np.ndarray
    dlns: np.ndarray
    ok: np.ndarray
    st0: float
    sh: float
    t_top: float
    t_trust: float
    pi_trust: float
    sig_trust: float
    P: np.ndarray
    B: np.ndarray
    glx: np.ndarray
    glw: np.ndarray
    R: np.ndarray
    TQ: np.ndarray
    TQB: np.ndarray
    HS: np.ndarray
    G: np.ndarray
    h_rms: float
    p_perc: float
    p_top: float


def _bucket_map(tn, st0, sh):
    nb = max(int(math.ceil((tn[-1] - st0) / sh)), 1)
    edges = st0 + sh * np.arange(nb + 1)
    B = np.searchsorted(tn, edges, side="right") - 1
    return np.ascontiguousarray(np.clip(B, 0, tn.size - 2).astype(np.int64))


class SealContext:
    """A (tables, theory) pair prepared for the seal kernels.

    Attributes
    ----------
    tab : TableKernel or tuple
        The table record (``tables.kernel_data(theory)``).
    rec : SealRecord
        The seal record.
    theory : str
    h_rms : float
        [m]
    p_perc, p_top : float
        Reduced percolation pressure (inf for "average") and table top.
    pi_trust : float
        Reduced contact pressure above which the tables' σ̄ is not verified.
    alpha_table, a_perc : float
        Junction factor and percolation area fraction the tables were built with.
    retab_worst : float
        Largest verified re-tabulation error of σ̄ (relative).
    retab_fallback_cells, prim_fallback_cells : int
        Re-tabulation cells evaluated through the table's quintic; primitive cells (below the
        trusted top) integrated adaptively.
    build_seconds : float
        Time taken to build the record [s].
    """

    def __init__(self, tables, theory, prim_h=None, prim_gl=None):
        t_start = time.perf_counter()
        tables._need(theory)
        self.theory = theory
        self.h_rms = float(tables.h_rms)
        self.tab = tables.kernel_data(theory)
        lo, hi = tables.p_range
        t_lo, t_hi = math.log(lo), math.log(hi)
        p_perc = float(tables.percolation_pressure(theory, 1.0))
        self.p_perc, self.p_top = p_perc, float(hi)
        t_perc = math.log(p_perc) if math.isfinite(p_perc) else math.inf
        # C¹ continuation of σ̄^(1/3) below the table: value and slope at the edge
        d = 0.02
        f = np.cbrt(np.ravel(tables.sigma_bar(lo * np.exp(d * np.arange(3.0)), 1.0, theory)))
        b1 = -(-3.0 * f[0] + 4.0 * f[1] - f[2]) / (2.0 * d)
        u_lo = float(np.ravel(tables.mean_separation(np.array([lo]), 1.0))[0]) / self.h_rms
        c_u = float(tables.info["asymptote_u0_over_h"])
        t_top = min(t_hi, t_perc)
        _, t_trust, sig_trust = verified_top(tables, theory)
        t_trust = min(t_trust, t_top)
        self.pi_trust = math.exp(t_trust)
        nret = int(math.floor((t_top - t_lo) / RETAB_H)) + 1
        lns, dlns = _sigma.retabulate(self.tab, t_lo, RETAB_H, nret)
        sh = PRIM_H if prim_h is None else float(prim_h)
        glx, glw = gauss_legendre(PRIM_GL if prim_gl is None else int(prim_gl))
        P0 = np.zeros((2, _sigma.P_COLS))
        rec = SealRecord(t_lo, t_hi, t_perc, float(f[0]), float(b1), u_lo, c_u, t_lo, RETAB_H,
                         lns, dlns, np.ones(nret - 1, dtype=np.bool_), t_lo, sh, t_top,
                         t_trust, self.pi_trust, sig_trust, P0, np.zeros(2, dtype=np.int64),
                         np.ascontiguousarray(glx), np.ascontiguousarray(glw), P0, P0,
                         np.zeros(2, dtype=np.int64),
                         _sigma.hot_scalars(**dict.fromkeys(_sigma.HS_FIELDS, 0)), P0, self.h_rms,
                         p_perc, float(hi))
        ok, worst = _sigma.verify_cells(self.tab, rec, RETAB_TOL)
        rec = rec._replace(ok=ok)
        # nodes: spacing sh up to the trusted top (cells bisected until verified), then the
        # unverified tail up to t_top at sh / TAIL_SPLIT (adaptive where unverified)
        nS = int(math.floor((t_trust - t_lo) / sh * (1.0 - 1e-12)))
        tn = np.append(t_lo + sh * np.arange(nS + 1), t_trust)
        if tn[-2] >= tn[-1] - 1e-3 * sh and tn.size > 2:
            tn = np.delete(tn, -2)
        n_ver = tn.size - 1
        if t_top > t_trust:
            fh = sh / TAIL_SPLIT
            tail = t_trust + fh * np.arange(1, int(math.ceil((t_top - t_trust) / fh)) + 1)
            tn = np.concatenate((tn, tail[tail < t_top - 1e-3 * fh], [t_top]))
        P = _sigma.build_primitive(self.tab, rec, np.ascontiguousarray(tn), n_ver, PRIM_DEPTH)
        tab = self.tab
        HS = _sigma.hot_scalars(rt0=rec.rt0, rh=rec.rh, t_lo=t_lo, b0=rec.b0, b1=rec.b1,
                                t_perc=t_perc, st0=t_lo, sh=sh, tq_lo=tab.bp_lo,
                                tq_dz=tab.bp_dz, n_open=tab.n_open, lnp_perc=tab.lnp_perc,
                                ish=1.0 / sh)
        self.rec = rec._replace(
            P=P, B=_bucket_map(np.ascontiguousarray(P[:, _sigma.P_T]), t_lo, sh),
            R=np.ascontiguousarray(np.column_stack((lns, dlns, np.append(ok, False)))),
            TQ=np.ascontiguousarray(np.column_stack((tab.lnp, tab.lnsig, tab.dlnsig,
                                                     tab.d2lnsig))),
            TQB=np.ascontiguousarray(tab.bp_idx, dtype=np.int64), HS=HS,
            G=np.ascontiguousarray(np.vstack((glx, glw))))
        below = P[:-1, _sigma.P_T] < t_trust
        self.retab_worst = float(worst)
        self.retab_fallback_cells = int((~ok).sum())
        self.prim_fallback_cells = int((P[:-1, _sigma.P_OK][below] == 0.0).sum())
        self.alpha_table = float(tables.options.get("alpha_cj", 1.0))
        self.a_perc = float(tables.options.get("a_perc", 0.5))
        self.hertz = None            # the O-ring table (fastcontact.seal.hertz), built lazily
        self.hertz_piezo = {}        # O-ring tables of Barus fluids by α̃ = α E* (the same)
        self.hertz_pb = None         # the O-ring table for p_b > 0 (hertz.HertzPbTable holder)
        self.hertz_pb_piezo = {}     # its tables of Barus/Roelands fluids (the same keys)
        self.hertz_beta = None       # Barus O-rings, p_b = 0, α per row (hertz.table_W_beta)
        self.build_seconds = time.perf_counter() - t_start


_CONTEXTS = PerObjectCache()


def peak_past_trust(pi_trust, live, p_max, p_a, E):
    """Profile rows (of ``live``) whose largest contact pressure lies past ``pi_trust`` (the
    reduced pressure of the tables' last verified σ̄: σ̄ above their floor, just below
    percolation): the zone's resistance W = ∫dx/σ̄ is then dominated by unverified σ̄, so Q has
    no verified value ("near_percolation"). The largest contact pressure p_max - p_f(peak) is at
    least p_max - p_a (p_f <= p_a): a row flagged here certainly reaches the unverified σ̄; a
    row with p_max - p_a <= π_trust E* < p_max - p_b may reach it too, depending on p_f at the
    peak, and is solved as before. Used by the base, Barus and Roelands O-rings and the
    sampled profiles."""
    return live & ((p_max - p_a) / E > pi_trust * (1 + 1e-13))


def seal_context(tables, theory) -> SealContext:
    """The cached :class:`SealContext` of (tables, theory); built on first use.

    Parameters
    ----------
    tables : fastcontact.tables.Tables
        Precomputed tables holding ``theory``.
    theory : str
        "critical_junction", "emt" or "average".

    Returns
    -------
    SealContext
    """
    check_theory(theory)
    tables._need(theory)
    return _CONTEXTS.get(tables, theory, lambda: SealContext(tables, theory))


# =========================================================================== soft-seal solver
#: rows with p_a within this fraction of max p0 below lift-off are solved at the lift-off
#: equality's tight panel tolerance: Q has a square-root limit there and the panel indicator
#: under-estimates the error of the inlet end (at the default tolerance 1e-3 an O-ring with
#: p_b > 0 was off by 2.3e-6 at p_a = p_H (1 - 1e-7), 7e-7 at 1e-5, 3e-8 at 1e-3 against the
#: independent collocation reference of the tests; 1.5e-9 at the tight tolerance)
NEAR_LIFT_OFF = 1e-4
#: panel tolerance at the exact lift-off point p_a = max p0 and within NEAR_LIFT_OFF below it
#: (degenerate inlet end, where the Legendre-tail indicator under-estimates the error)
EQUALITY_TOL = 1e-9
#: soft-seal solver knobs (non-uniform profiles): Gauss–Legendre nodes per panel, initial
#: panels, grading order of the end map, panel error tolerance (Legendre tail of the
#: resistance density relative to the total), maximum panels, Newton iterations per mesh;
#: ``table``: O-rings from the verified tables of W (:mod:`.hertz`; p_b = 0 and, where
#: completing the table for them costs no more solves than those rows, p_b > 0).
SOLVER_DEFAULTS = dict(nodes=10, panels=4, grading=2, tol=1e-3, max_panels=128, max_newton=60,
                       table=True)


class PanelRule(NamedTuple):
    """Flat record of the soft-seal solver's knobs and its n-point panel matrices.

    Attributes
    ----------
    m : int
        Grading order of the end map.
    n : int
        Gauss–Legendre nodes per panel.
    P0, PMAX : int
        Initial and maximum number of panels.
    tol : float
        Panel error tolerance (Legendre tail of r relative to W).
    maxit : int
        Newton iterations per mesh.
    zl, wl : ndarray
        Nodes and weights on [-1, 1].
    At : ndarray
        At[i, k] = ∫_{z_i}^{1} ℓ_k (tail integration of the Lagrange basis).
    Lp : ndarray
        Legendre projection, a_j = Σ_k Lp[j, k] f_k.
    """

    m: int
    n: int
    P0: int
    PMAX: int
    tol: float
    maxit: int
    zl: np.ndarray
    wl: np.ndarray
    At: np.ndarray
    Lp: np.ndarray


class RowsOut(NamedTuple):
    """Per-row outputs of the soft-seal solver (flat record of arrays)."""

    W: np.ndarray
    status: np.ndarray
    panels: np.ndarray
    err: np.ndarray
    xs: np.ndarray
    xe: np.ndarray

    @classmethod
    def empty(cls, n):
        """Arrays for n rows (W NaN, status 0)."""
        return cls(np.full(n, np.nan), np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64),
                   np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan))


_GL_CACHE = {}


def _gl_matrices(n):
    """Gauss–Legendre nodes/weights on [-1, 1], the tail-integration matrix and the Legendre
    projection matrix of an n-point panel (cached)."""
    if n not in _GL_CACHE:
        Lg = np.polynomial.legendre
        z, w = gauss_legendre(n)
        V = Lg.legvander(z, n - 1)
        Vi = np.linalg.inv(V)
        At = np.empty((n, n))
        for k in range(n):
            ic = Lg.legint(Vi[:, k], lbnd=-1)
            At[:, k] = Lg.legval(1.0, ic) - Lg.legval(z, ic)      # ∫_{z_i}^{1} ℓ_k
        Lp = (np.arange(n)[:, None] + 0.5) * (V.T * w[None, :])   # a_j = Σ_k Lp[j,k] f_k
        _GL_CACHE[n] = tuple(np.ascontiguousarray(a) for a in (z, w, At, Lp))
    return _GL_CACHE[n]


def solver_options(options):
    """Validated solver knobs: SOLVER_DEFAULTS updated by ``options`` (dict or None)."""
    o = dict(SOLVER_DEFAULTS)
    for k, v in (options or {}).items():
        if k not in o:
            raise ValueError(f"solver option {k!r} is invalid: must be one of {sorted(o)}")
        o[k] = v
    checks = (("nodes", 2, 40), ("grading", 0, 8), ("max_panels", 1, 4096),
              ("max_newton", 1, 1000))
    for k, lo, hi in checks:
        if not (lo <= int(o[k]) <= hi):
            raise ValueError(f"{k} = {o[k]!r} is invalid: must be in [{lo}, {hi}]")
    if not (1 <= int(o["panels"]) <= int(o["max_panels"])):
        raise ValueError(f"panels = {o['panels']!r} is invalid: must be in [1, max_panels]")
    if not (0.0 < float(o["tol"]) < 1.0):
        raise ValueError(f"tol = {o['tol']!r} is invalid: must be in (0, 1)")
    if not isinstance(o["table"], (bool, np.bool_)):
        raise ValueError(f"table = {o['table']!r} is invalid: must be True or False")
    return o


def panel_rule(o, tol=None, max_panels=None):
    """The :class:`PanelRule` of validated options ``o`` (tol / max_panels overridden)."""
    n = int(o["nodes"])
    z, w, At, Lp = _gl_matrices(n)
    return PanelRule(int(o["grading"]), n, int(o["panels"]),
                     int(o["max_panels"] if max_panels is None else max_panels),
                     float(o["tol"] if tol is None else tol), int(o["max_newton"]), z, w, At, Lp)


def solve_profile_rows(sc, o, kind, xg, p0n, amp, pia, pib, idx, near, al=None, vis=None,
                       chain=False):
    """The soft-seal solver (:func:`._panels.solve_rows`) on rows ``idx`` into a fresh
    :class:`RowsOut`: rows with ``near`` (at or within NEAR_LIFT_OFF below lift-off) at the
    panel tolerance min(tol, EQUALITY_TOL) and at least 256 panels, the others with the
    options ``o`` as they are; ``al`` the rows' reduced Barus α̃ = α E* (None: 0, a constant
    viscosity), ``vis`` (rows, 3) their Roelands law (A, Z, π_r = p_r/E*) (None: none).
    ``chain`` (Hertz rows, kind 0): rows sharing π_H, π_b and the fluid are solved in chains of
    rising π_a, each row started on the previous one's solution
    (:func:`._panels.solve_rows_chained`, :func:`_chains`; W within ~1e-8 of a cold solve).
    Not the rows next to lift-off: Q has a square-root limit there and converges slowly in
    the tolerance, and a warm start left one 3e-8 from its cold solve."""
    out = RowsOut.empty(amp.size)
    al = np.zeros(amp.size) if al is None else np.ascontiguousarray(al, dtype=np.float64)
    vis = np.zeros((amp.size, 0)) if vis is None else np.ascontiguousarray(vis, dtype=np.float64)
    for sel, nr in ((idx[~near], False), (idx[near], True)):
        if not sel.size:
            continue
        rule = panel_rule(o, tol=min(o["tol"], EQUALITY_TOL) if nr else None,
                          max_panels=max(o["max_panels"], 256) if nr else None)
        if chain and kind == 0 and sel.size > 1 and not nr:  # not next to lift-off (below)
            order, starts = _chains(sel, amp, pia, pib, al, vis)
            _panels.solve_rows_chained(sc.tab, sc.rec, rule, xg, p0n, amp, pia, pib, al, vis,
                                       order, starts, out)
            continue
        _panels.solve_rows(sc.tab, sc.rec, rule, kind, xg, p0n, amp, pia, pib, al, vis,
                           spread_rows(sel), out)
    return out


def spread_rows(idx):
    """The row indices ``idx`` as contiguous int64 in the order of
    :func:`~fastcontact.kernels.balance.spread_order`. :func:`._panels.solve_rows` gives each
    thread one contiguous block of the rows; where they come sorted (grid lines of a table, a
    study ordered by load) one block would hold all the cheap rings and another all the costly
    ones. Each row's result is its own: the same whatever the order."""
    return np.asarray(idx, dtype=np.int64)[spread_order(idx.size)]


#: most rows per chain of :func:`._panels.solve_rows_chained`; a batch is cut into about one
#: chain per thread (chains run in parallel; each chain's first row is solved cold), no
#: shorter than CHAIN_MIN rows
CHAIN_MAX = 256
CHAIN_MIN = 8


def _chains(sel, amp, pia, pib, al, vis):
    """(rows, starts) of :func:`._panels.solve_rows_chained`: the rows ``sel`` sorted by
    π_H, π_b, α̃, the Roelands law and then π_a, cut where any of the first four changes and
    every L rows, L = sel.size / threads within [CHAIN_MIN, CHAIN_MAX]."""
    from numba import get_num_threads
    L = min(CHAIN_MAX, max(CHAIN_MIN, -(-sel.size // get_num_threads())))
    keys = [amp[sel], pib[sel], al[sel]] + [vis[sel, k] for k in range(vis.shape[1])]
    order = np.lexsort([pia[sel]] + keys[::-1])
    new = new_runs(keys, order)
    run = np.cumsum(new) - 1
    first = np.flatnonzero(new)
    pos = np.arange(sel.size) - first[run]
    starts = np.flatnonzero(new | (pos % L == 0))
    return spread_chains(np.asarray(sel[order], dtype=np.int64), np.append(starts, sel.size))


def spread_chains(rows, bounds):
    """(rows, bounds) with the chains rows[bounds[c]:bounds[c+1]] in the order of
    :func:`~fastcontact.kernels.balance.spread_order` (each chain's rows in their order). A
    parallel loop gives each thread one contiguous block of the chains; sorted by π_H, one
    thread would get the cheap rings and another the costly ones and the call would wait for
    the slowest, while every contiguous block of the spread order samples all π_H."""
    nc = bounds.size - 1
    perm = spread_order(nc)
    lens = np.diff(bounds)[perm]
    nb = np.zeros(nc + 1, dtype=np.int64)
    np.cumsum(lens, out=nb[1:])
    pos = np.arange(rows.size) - np.repeat(nb[:-1], lens) + np.repeat(bounds[:-1][perm], lens)
    return rows[pos], nb


def new_runs(keys, order):
    """For the rows in ``order`` (sorted by the keys): True where a row's keys differ from the
    previous row's (and at the first row)."""
    new = np.zeros(order.size, dtype=bool)
    new[0] = True
    for k in keys:
        ks = k[order]
        new[1:] |= ks[1:] != ks[:-1]
    return new
