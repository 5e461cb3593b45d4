"""The seal engine's per-(tables, theory) context: one flat record for every numba kernel.

:class:`SealRecord` is a flat namedtuple (arrays and scalars only), so it passes into
``prange`` drivers next to the table record ``tab``; :class:`SealContext` holds both with the
metadata the Python side needs. Built lazily, once per Tables object and theory, and cached.
"""
from __future__ import annotations

import math
import threading
import weakref
from typing import NamedTuple

import numpy as np

from ..flow.conductivity import check_theory
from . import _sigma

__all__ = ["SealRecord", "SealContext", "seal_context", "PanelRule", "RowsOut", "panel_rule",
           "solver_options", "SOLVER_DEFAULTS", "RETAB_H", "RETAB_TOL", "PRIM_H", "PRIM_GL"]

#: re-tabulation of ln σ̄ (uniform in ln π): spacing and per-cell verification tolerance
RETAB_H = 1.0 / 64.0
RETAB_TOL = 1e-9
#: primitive of σ̄: node spacing in ln π and the Gauss–Legendre order of direct intervals
PRIM_H = 1.0 / 64.0
PRIM_GL = 6
#: the steep part below percolation gets a primitive grid this many times finer
FINE_SPLIT = 16


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
    st0, sh, nc, fh, t_top : float, float, int, float, float
        Primitive grid: spacing sh from st0 up to node nc, spacing fh beyond (the steep
        part below percolation); the last cell ends at t_top = min(t_hi, t_perc).
    tn : ndarray
        The primitive's nodes (last one t_top).
    d1, d2 : ndarray
        S' = σ̄ e^t and S'' at the primitive nodes.
    cell : ndarray
        ∫ σ̄ e^t dt over each primitive cell.
    cell_ok : ndarray of bool
        Cells whose quintic Hermite partial integrals are verified (else adaptive).
    prefix, suffix : ndarray
        Σ cell[:k] and Σ cell[k:] (compensated sums).
    glx, glw : ndarray
        Gauss–Legendre rule of the direct intervals.
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
    nc: int
    fh: float
    t_top: float
    tn: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    cell: np.ndarray
    cell_ok: np.ndarray
    prefix: np.ndarray
    suffix: np.ndarray
    glx: np.ndarray
    glw: np.ndarray
    h_rms: float
    p_perc: float
    p_top: float


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
    alpha_table, a_perc : float
        Junction factor and percolation area fraction the tables were built with.
    retab_worst : float
        Largest verified re-tabulation error of σ̄ (relative).
    retab_fallback_cells, prim_fallback_cells : int
        Cells evaluated through the table kernel / integrated adaptively.
    """

    def __init__(self, tables, theory, prim_h=None, prim_gl=None):
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
        nret = int(math.floor((t_top - t_lo) / RETAB_H)) + 1
        lns, dlns = _sigma.retabulate(self.tab, t_lo, RETAB_H, nret)
        sh = PRIM_H if prim_h is None else float(prim_h)
        glx, glw = np.polynomial.legendre.leggauss(PRIM_GL if prim_gl is None else int(prim_gl))
        empty = np.zeros(1)
        rec = SealRecord(t_lo, t_hi, t_perc, float(f[0]), float(b1), u_lo, c_u, t_lo, RETAB_H,
                         lns, dlns, np.ones(nret - 1, dtype=np.bool_), t_lo, sh, 0, sh, t_top,
                         empty, empty, empty, empty, np.zeros(1, dtype=np.bool_), empty, empty,
                         np.ascontiguousarray(glx), np.ascontiguousarray(glw), self.h_rms,
                         p_perc, float(hi))
        ok, worst = _sigma.verify_cells(self.tab, rec, RETAB_TOL)
        rec = rec._replace(ok=ok)
        # coarse nodes, then FINE_SPLIT times finer from two cells before the first cell whose
        # Hermite fails verification (the steep fall of σ̄ towards percolation / full contact)
        nS = int(math.floor((t_top - t_lo) / sh))
        tn = np.append(t_lo + sh * np.arange(nS + 1), t_top) if t_lo + nS * sh < t_top else \
            t_lo + sh * np.arange(nS + 1)
        prim = _sigma.build_primitive(self.tab, rec, tn)
        bad = np.flatnonzero(~prim[3][1:]) + 1     # cell 0 touches the asymptote's C¹ join
        nc = tn.size - 1
        if bad.size:
            nc = max(int(bad[0]) - 2, 0)
            fh = sh / FINE_SPLIT
            nf = int(math.floor((t_top - tn[nc]) / fh))
            fine = tn[nc] + fh * np.arange(1, nf + 1)
            fine = fine[fine < t_top]
            tn = np.concatenate((tn[:nc + 1], fine, [t_top]))
            rec = rec._replace(nc=nc, fh=fh)
            prim = _sigma.build_primitive(self.tab, rec, tn)
        d1, d2, cell, cell_ok, prefix, suffix = prim
        self.rec = rec._replace(tn=tn, d1=d1, d2=d2, cell=cell, cell_ok=cell_ok, prefix=prefix,
                                suffix=suffix)
        self.retab_worst = float(worst)
        self.retab_fallback_cells = int((~ok).sum())
        self.prim_fallback_cells = int((~cell_ok).sum())
        self.alpha_table = float(tables.options.get("alpha_cj", 1.0))
        self.a_perc = float(tables.options.get("a_perc", 0.5))
        self.hertz = None            # the O-ring table (fastcontact.seal.hertz), built lazily


_CONTEXTS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_CTX_LOCK = threading.Lock()


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
    with _CTX_LOCK:
        per = _CONTEXTS.get(tables)
        if per is None:
            per = {}
            _CONTEXTS[tables] = per
        if theory not in per:
            per[theory] = SealContext(tables, theory)
        return per[theory]


# =========================================================================== soft-seal solver
#: soft-seal solver knobs (non-uniform profiles): Gauss–Legendre nodes per panel, initial
#: panels, grading order of the end map, panel error tolerance (Legendre tail of the
#: resistance density relative to the total), maximum panels, Newton iterations per mesh;
#: ``table``: O-rings with p_b = 0 from the verified table of W (:mod:`.hertz`).
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
        z, w = Lg.leggauss(n)
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
