"""Seal leak rate with a pressure-dependent (Barus) viscosity η = η0 exp(α (p_f - p_b)).

Steady 1-D flow across the seal width (paper Sec. 6, eqs. 25–33) with η(p_f): the flux per
unit length is q = -(σ0(p_cont)/e^{α(p_f - p_b)}) dp_f/dx = -σ0(p_cont) dψ/dx, with the
conductivity σ0 at the outlet viscosity η0 and the reduced pressure
ψ = (1 - e^{-α(p_f - p_b)})/α. If σ0 did not depend on p_f, Q would follow from
ψ(p_a) - ψ(p_b) alone — but p_cont = p0(x) - p_f couples it back (docs/theory/extensions.md §2):

* **uniform ring** (p0 fixed): dp_f/dx = -q e^{α(p_f - p_b)}/σ0(p0 - p_f) separates, and
  ``q L = ∫_{p_b}^{p_a} σ0(p0 - p) e^{-α(p - p_b)} dp`` exactly (α = 0: the paper's result
  ``q = (1/L)∫σ_eff dp``). Evaluated by Gauss–Legendre in ln p_cont on the tables. In
  x = ln(p_cont/E*) it is q L = E* e^{-α(p0 - p_b)} ∫_{x_a}^{x_b} σ̄ e^x e^{αE* e^x} dx: the
  weight does not depend on p0, so rings sharing α E* (but not p0) read one cumulative table
  of that integral (cells of 0.02 in x, prefix and suffix sums, the integrand's Legendre
  series on each cell) and evaluate only the two partial cells at their ends
  (:func:`_ring_cells`). The table is built by a call with enough such rings (~1 ms) and
  kept with the Tables object (the newest ``BETA_MEMO``), so later calls sharing α E*, short
  ones too, read it; a long Δp sweep of any law shares one such table of its run, and a
  short one adds each row's piece to the previous row's integral.
* **Hertz O-ring** (p0(x) = p_H √(1 - ((x-a)/a)²)): dψ/dx = -q/σ0(p0(x) - p_f(ψ)) has no
  closed form. Integrated from the outlet, ψ(x) = q ∫_x^{x_e} dx'/σ0, so with
  W = ∫_{x_s}^{x_e} dx/σ0 over the sealing zone p0(x) >= p_f, q = ψ_a/W and
  p_cont(x) = p0(x) - p_b - P(ψ_a R(x)/W), P(ψ) = -ln(1 - αψ)/α, R(x) = ∫_x^{x_e} dx'/σ0: the
  base engine's integral equation (eq. 33) with Δp ψ-weighted. It is solved by the base
  engine's adaptive Gauss–Legendre panel collocation and Newton
  (:mod:`fastcontact.seal._panels`, panel tolerance PIEZO_PANEL_TOL). With ``steps`` given,
  by shooting on q instead (RK4 in θ, x = a(1 - cos θ), on steps graded towards both zone
  ends; bracketed secant iteration on q, started from the root of a 25-step shooting).

In both, ``p_f(ψ) = p_b - ln(1 - αψ)/α``; ψ < 1/α always since ψ_a = ψ(p_a) < 1/α.

**Roelands** (``viscosity="roelands"``, :mod:`fastcontact.flow.piezoviscosity`):
ln(η/η0) = A[(1 + (p_f - p_b)/p_r)^Z - 1]. The reduced pressure ψ(p) = ∫η0/η dp is an
incomplete gamma function with no closed-form inverse, and p_cont = p0(x) - p_f needs
p_f(ψ). So

* uniform ring: the separated equation holds for any η(p),
  ``q L = ∫_{p_b}^{p_a} σ0(p0 - p) η0/η(p) dp`` (same quadrature, Roelands weight);
* Hertz O-ring: the same panel collocation in ψ as Barus, with ψ tabulated per row
  (:mod:`._roelands_psi`: quintic Hermite in ln(1 + p/p_r), exact to ~1e-13) and the
  residual written in ψ (no inverse inside the Newton); rows whose Newton fails (steep laws
  next to lift-off) are shot in p_f itself, dp_f/dθ = -k a sin θ (η(p_f)/η0)/σ̄((p_H sin θ -
  p_f)/E*), by the same graded RK4 and shooting on k, checked.

References: C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87;
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 31, 159 (2010), arXiv:0911.3019.
"""
from __future__ import annotations

import math
import threading
import weakref
from collections import OrderedDict

import numpy as np
import pandas as pd

from .._core.owned import own_columns
from .._core.validate import check_positive
from ..flow.piezoviscosity import ROELANDS_ETA_INF, check_law, roelands_parameters
from ..kernels.quadrature import gauss_legendre
from ..kernels.records import scalar_record
from ..kernels.readonly import readonly_fields
from . import _panels
from .context import (NEAR_LIFT_OFF, new_runs, peak_past_trust, seal_context,
                      solve_profile_rows, solver_options)
from ._piezo_kernels import (TAIL_CUT, HertzRows, Quad, RingCells, UniformRows, _cells_kernel,
                             _cells_rows, _hertz_kernel, _hertz_kernel_r, _uniform_sweep_kernel)
from ._roelands_psi import psi_drops, psi_drops_one_law

__all__ = ["HERTZ_STEPS", "TAIL_CUT", "seal_leak_piezo"]

#: RK4 steps across the Hertz sealing zone (graded; error <= ~1e-8 against an adaptive
#: DOP853 shooting reference, bench/bench_extensions.py): the O-ring shooting (given
#: ``steps``, and the fallback of rows whose panel Newton fails)
HERTZ_STEPS = 200
#: panel tolerance of the O-rings' collocation solve, Barus and Roelands (the base seal
#: engine's solver in ψ; relative Legendre tail of the resistance density per panel); at or within
#: NEAR_LIFT_OFF below the lift-off equality p_a = p_H, where Q has a square-root limit and
#: converges slowly in the tolerance, the base engine's EQUALITY_TOL
#: (bench/extensions_results.md). Against the DOP853 shooting (rtol 1e-13) on the four
#: embedded surfaces, both theories, p_H/E* = 0.01 and 0.05, two Barus and two Roelands laws
#: (oil-like and steep), p_a/p_H = 0.02–0.99, 448 O-rings solved cold: worst 1.07e-9 at 1e-6,
#: the same as at 1e-7, 1.5e-8 at 1e-5, 2.1e-6 at 1e-4; the same O-rings inside 67-row Δp
#: sweeps (solved in chains): 9.95e-9 at 1e-6, 1.07e-9 at 1e-7. 1e-6 is ×1.3–1.4 faster
PIEZO_PANEL_TOL = 1e-6
#: the default shooting of O-rings (rows whose panel Newton fails: Barus at α p_H >~ 5 next
#: to lift-off, steep Roelands laws) is checked (:func:`_checked_shooting`): (HERTZ_STEPS/2, HERTZ_STEPS) steps,
#: then rows whose two results differ by more than FALLBACK_RTOL (relative) with
#: (FALLBACK_STEPS/2, FALLBACK_STEPS), then "not_converged" (Q = NaN). Next to lift-off 200
#: steps were off by up to 3e-5 (Barus, against the DOP853 reference; Roelands, against 3200
#: steps) and 3200 by <= 5e-8 (bench/extensions_results.md); Barus rows start at the second
#: level (the panel rows that fail are all next to lift-off), Roelands rows at the first
FALLBACK_STEPS = 3200
FALLBACK_RTOL = 1e-6
CHECKED_LEVELS = ((HERTZ_STEPS // 2, HERTZ_STEPS), (FALLBACK_STEPS // 2, FALLBACK_STEPS))


# =========================================================================== API
def _uniform_near_percolation(tables, theory, v, kq, live):
    """Flat rings whose outlet end reaches past π_trust (p0 - p_b > π_trust E*, the tables'
    last verified σ̄, just below percolation) by enough to matter: the unverified part of
    q L = ∫ σ0(p0 - p) w(p) dp over p in [p_b, p_u], p_u = min(p_a, p0 - π_trust E*), lies in
    [0, σ̄(π_trust)(p_u - p_b)] (w <= 1 for both laws), and a row is "near_percolation" when
    that bound exceeds TAIL_RTOL (1e-9) of the computed k = 12 η0 q/h³ — the base flat ring's
    test (:mod:`._leak`), which the Barus/Roelands rings lacked (they reported "ok")."""
    from ._leak import TAIL_RTOL
    ctx = seal_context(tables, theory)
    E = v["E"]
    p_u = np.minimum(v["pa"], v["g1"] - ctx.pi_trust * E)
    over = np.maximum(p_u - v["p_b"], 0.0)
    bound = ctx.rec.sig_trust * over / v["g2"]     # [Pa/m], as kq
    return live & (v["dp"] > 0) & (over > 0) & (bound > TAIL_RTOL * kq)


def _scalars(tables, theory):
    """The record of (tables, theory) the kernels read (a record: it reaches prange bodies).

    Fields: ``x_lo`` = ln p̄ at the table bottom, ``u_lo`` = ū/h_rms there, ``du_lo`` =
    -dū/d ln p̄ /h_rms there, ``lnsig_lo`` = ln σ̄ there, ``x_hi`` = ln p̄ at the table top,
    ``x_perc`` = ln p̄ at percolation (inf: none)."""
    p_lo, p_hi = tables.p_range
    d = 1e-4
    v = tables.mean_separation(np.array([p_lo, p_lo * math.exp(d)]), 1.0) / tables.h_rms
    perc = tables.info["percolation_p_over_E"][theory]
    return scalar_record({"x_lo": math.log(p_lo), "u_lo": v[0], "du_lo": (v[0] - v[1]) / d,
                          "lnsig_lo": math.log(float(tables.sigma_bar(p_lo, 1.0, theory))),
                          "x_hi": math.log(p_hi),
                          "x_perc": math.log(perc) if np.isfinite(perc) else math.inf})


def seal_leak_piezo(tables, *, dp, L_y, E_star, eta, alpha_pv, theory="critical_junction",
                    alpha_cj=1.0, p_b=0.0, profile="uniform", p0=None, L=None, R=None, f_N=None,
                    quad_order=10, quad_width=0.5, steps=None, viscosity="barus",
                    roelands_z=None, roelands_p_r=None, roelands_eta_inf=None):
    """Leak rate Q [m³/s] of a seal with a Barus or Roelands fluid, uniform ring or O-ring.

    Parameters
    ----------
    tables : Tables
        Tables of the rough surface holding ``theory``.
    dp : array_like
        Pressure difference p_a - p_b [Pa], >= 0.
    L_y : array_like
        Seal length (circumference) [m].
    E_star : array_like
        Effective modulus [Pa].
    eta : array_like
        Viscosity η0 at the outlet pressure p_b [Pa·s].
    alpha_pv : array_like
        Pressure–viscosity coefficient α [1/Pa], >= 0; η = η0 exp(α (p_f - p_b)) (Barus).
        Roelands: the initial slope d ln η/dp at p_b, which sets Z = α p_r/ln(η0/η_∞) when
        ``roelands_z`` is None.
    theory : str
        Flow theory of σ_eff (must be in the tables).
    alpha_cj : array_like
        Critical-junction factor [-]: σ ∝ α_cj³, so Q is rescaled by (α_cj/α_table)³
        exactly (q is linear in σ in both profiles); ignored by the other theories.
    p_b : array_like
        Outlet gauge pressure [Pa], >= 0.
    profile : {"uniform", "hertz"}
        Flat ring (needs ``p0`` [Pa], ``L`` [m]) or O-ring (needs ``R`` [m], ``f_N`` [N/m]).
    quad_order, quad_width : int, float
        Gauss–Legendre order and panel width in ln p_cont (uniform ring). Rings that share
        p0, p_b, E* and the viscosity law (a Δp sweep of one seal) are integrated in order of
        p_a, each as the previous one's integral plus the piece between their inlet ends
        (pieces no wider than SHORT_WIDTH × quad_width with SHORT_ORDER points).
    steps : int or None
        RK4 steps of the O-ring shooting across the Hertz sealing zone. None (default): the
        O-ring by the base engine's panel collocation in ψ (Barus ~4× faster than 200 steps,
        Roelands ~3×; error against an adaptive DOP853 shooting in
        bench/extensions_results.md). Rows where its Newton fails are shot, checked against
        half as many steps: Barus with FALLBACK_STEPS, Roelands with HERTZ_STEPS, then, where
        the two differ by more than FALLBACK_RTOL, with FALLBACK_STEPS; "not_converged"
        (Q = NaN) where they still differ. An integer: shooting with that many steps,
        unchecked (both laws). At least TABLE_MIN_ROWS (500) O-rings of one fluid (α E*, or
        the Roelands law with p_r/E*; in a call of several fluids, each of the four largest
        such groups) read W from that fluid's verified O-ring tables
        (:mod:`fastcontact.seal.hertz`: p_b = 0 from the table of (π_H, π_a), p_b > 0 from the
        one of (π_H, π_a, π_b); built as far as needed and kept; ~1e-8 of the solver) where
        building what a table lacks costs fewer solves than its rows (Δp sweeps of a few
        O-rings, a large study, a table kept from an earlier call; for p_b > 0 ~25× more
        solves per O-ring p_H than for p_b = 0), and solves only the rows whose cells are not
        verified.
    viscosity : {"barus", "roelands"}
        Viscosity law (module docstring; :mod:`fastcontact.flow.piezoviscosity`). Roelands:
        ln(η/η0) = ln(η0/η_∞)[(1 + (p_f - p_b)/p_r)^Z - 1], its reduced pressure
        tabulated (no closed-form inverse).
    roelands_z : array_like or None
        Roelands pressure–viscosity index Z [-] >= 0 (None: from ``alpha_pv``).
    roelands_p_r : float or None
        Roelands reference pressure p_r [Pa] (None: 1/5.1e-9 ≈ 1.96e8, Hamrock & Dowson).
    roelands_eta_inf : float or None
        Roelands limiting viscosity η_∞ [Pa·s] (None: e^-9.67 ≈ 6.3e-5); ``eta`` must exceed it.

    Returns
    -------
    pandas.DataFrame
        ``Q`` [m³/s] (inf beyond lift-off, 0 if percolated or dp = 0), ``open_inlet``,
        ``open_outlet`` [m] (zones with p0 <= p_f; Hertz also ``L`` = 2a), ``lift_off``,
        ``percolated``, ``converged`` (Hertz solve), ``out_of_table`` (the largest
        contact pressure lies beyond the tables: Q = NaN), ``status`` ("ok", "lift_off"
        (p_a = max p0: finite limit), "open" (Q = inf), "percolated", "above_table",
        "near_percolation" (O-rings whose peak contact pressure p_H - p_a lies past the
        tables' last verified σ̄, just below percolation: Q = NaN), "not_converged"), and the
        inputs.
    """
    roelands, shape, v = _piezo_inputs(tables, theory, profile, dp, L_y, E_star, eta, alpha_pv,
                                       p_b, viscosity, roelands_z, p0, L, R, f_N, alpha_cj)
    law = _roelands_law(v, roelands_z, roelands_p_r, roelands_eta_inf) if roelands else None
    sc = _scalars(tables, theory)
    tab = tables.kernel_data(theory)
    if profile == "uniform":
        cols, rows = _uniform_rows(tab, sc, v, law, quad_order, quad_width, _beta_memo(tables),
                                   theory)
    else:
        cols, rows = _hertz_rows(tables, theory, tab, sc, v, law, steps)
    kq, conv, lift, perc, out_t, pmax, near = rows
    if profile == "uniform":
        near = _uniform_near_percolation(tables, theory, v, kq, ~lift & ~perc & ~out_t)
    scale = 1.0
    if theory == "critical_junction":
        scale = (v["alpha_cj"] / float(tables.options.get("alpha_cj", 1.0))) ** 3
    Q = scale * v["L_y"] * kq * float(tables.h_rms) ** 3 / (12.0 * v["eta"])
    Q = np.where(lift, math.inf, np.where(conv & ~out_t & ~near, Q, math.nan))
    # a NaN row says why before the lift-off equality's flag (its Q is finite when solved)
    from .api import STATUS  # the seal engine's status names (api imports this module)
    codes = np.select([lift, out_t, perc, near, ~conv, v["pa"] == pmax],
                      [STATUS.index(s) for s in ("open", "above_table", "percolated",
                                                 "near_percolation", "not_converged",
                                                 "lift_off")],
                      STATUS.index("ok")).astype(np.int8)
    status = pd.Categorical.from_codes(codes, categories=list(STATUS))
    cols.update({"p_a": v["pa"], "Q": Q, "lift_off": lift | (v["pa"] == pmax),
                 "percolated": perc, "converged": conv, "out_of_table": out_t, "status": status})
    return _piezo_frame(cols, law, theory, profile, shape, roelands_eta_inf)


def _piezo_inputs(tables, theory, profile, dp, L_y, E_star, eta, alpha_pv, p_b, viscosity,
                  roelands_z, p0, L, R, f_N, alpha_cj):
    """(roelands, shape, flat validated inputs by name) of :func:`seal_leak_piezo`; the profile
    inputs as ``g1``, ``g2`` (p0, L or R, f_N), ``z`` the Roelands index, ``pa`` = p_b + dp."""
    from ..tables import Tables
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables")
    tables._need(theory)
    if not (isinstance(profile, str) and profile in ("uniform", "hertz")):
        shown = profile if isinstance(profile, str) else "array(...)"
        raise ValueError(f"profile = {shown!r} is invalid with alpha_pv: must be 'uniform' or "
                         f"'hertz' (sampled profiles are not implemented for the Barus fluid)")
    dp = check_positive("dp", dp, "[Pa]", allow_zero=True)
    L_y = check_positive("L_y", L_y, "[m]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    eta = check_positive("eta", eta, "[Pa·s]")
    alpha_pv = check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True)
    p_b = check_positive("p_b", p_b, "[Pa]", allow_zero=True)
    roelands = check_law(viscosity) == "roelands"
    zz = np.array(math.nan) if roelands_z is None else check_positive(
        "roelands_z", roelands_z, "[-]", allow_zero=True)
    if profile == "uniform":
        if p0 is None or L is None or R is not None or f_N is not None:
            raise ValueError("profile = 'uniform' is invalid with these arguments: give p0 [Pa] "
                             "and L [m], not R / f_N")
        g1 = check_positive("p0", p0, "[Pa]")
        g2 = check_positive("L", L, "[m]")
    else:
        if R is None or f_N is None or p0 is not None or L is not None:
            raise ValueError("profile = 'hertz' is invalid with these arguments: give R [m] "
                             "and f_N [N/m], not p0 / L")
        g1 = check_positive("R", R, "[m]")
        g2 = check_positive("f_N", f_N, "[N/m]")
    a_cj = check_positive("alpha_cj", alpha_cj, "[-]")
    names = ("dp", "L_y", "E", "eta", "alpha_pv", "p_b", "g1", "g2", "z", "alpha_cj")
    vals = (dp, L_y, E_star, eta, alpha_pv, p_b, g1, g2, zz, a_cj)
    shape = np.broadcast(*vals).shape
    v = {k: np.ascontiguousarray(np.broadcast_to(x, shape).ravel(), dtype=np.float64)
         for k, x in zip(names, vals)}
    v["pa"] = v["p_b"] + v["dp"]
    return roelands, shape, v


def _roelands_law(v, roelands_z, roelands_p_r, roelands_eta_inf):
    """(A, Z, p_r) of the Roelands law per row (:func:`roelands_parameters`), A and Z
    contiguous; Z from ``alpha_pv`` when ``roelands_z`` is None."""
    A, Z, pr = roelands_parameters(v["eta"], v["alpha_pv"], None if roelands_z is None else
                                   v["z"], roelands_p_r, roelands_eta_inf)
    return (np.ascontiguousarray(A, dtype=np.float64), np.ascontiguousarray(Z, dtype=np.float64),
            pr)


#: rows per chunk of a run of :func:`_uniform_sweep_kernel` (each chunk integrates its first
#: row over the whole range: ~1.5 µs, shared by its rows)
SWEEP_CHUNK = 256
#: a sweep's piece no wider than SHORT_WIDTH × quad_width (in ln p_cont) takes SHORT_ORDER
#: Gauss points instead of quad_order (its error, ∝ width^(2n), is far below the full rule's)
SHORT_WIDTH = 0.04
SHORT_ORDER = 4


#: Flat rings that share the weight of their integral take a cumulative table of it
#: (:class:`RingCells`, :func:`_ring_cells`): cells of CELL_WIDTH in x = ln(p_cont/E*)
#: (TAIL_WIDTH in the ū³ tail) cut at the σ̄ table's nodes, each by the full rule, with the
#: integrand's Legendre series; a ring then costs the two partial cells at its ends, a
#: Legendre sum each (Gauss points where a cell's series is not trusted, next to
#: percolation; CELL_SHORT_ORDER of them for a ring inside one smooth cell). Barus
#: rings separate exactly, q L η0 = E* e^{-α(p0 - p_b)} ∫ σ̄ e^x e^{β e^x} dx with
#: β = α E*, so rings sharing β (BARUS_TABLE_ROWS of them or more; distinct p0 too)
#: share one table, kept for later calls (β·e^{x_top} above BARUS_BETA_TOP_MAX, weights below
#: e^-200 at the table's bottom, keeps the per-row integral); rings of any law sharing p0 - p_b, E* and the
#: law (a Δp sweep of SWEEP_TABLE_ROWS rings or more) share one table of their run. Shorter
#: sweeps add each ring's piece to the previous one's integral (:func:`_sweep_order`)
CELL_WIDTH = 0.02
TAIL_WIDTH = 0.2
CELL_SHORT_ORDER = 4
BARUS_TABLE_ROWS = 2048
SWEEP_TABLE_ROWS = 8192
BARUS_BETA_TOP_MAX = 200.0
#: β tables kept per Tables object (the newest): a loop of calls sharing α E* (one call per
#: seal geometry, each a Δp or p0 sweep) builds each once (~1 ms, ~0.1 MB each)
BETA_MEMO = 16
_BETA_TABLES = weakref.WeakKeyDictionary()
_BETA_LOCK = threading.Lock()


def _ring_cells(tab, sc, quad, x1, run=0, beta=0.0, E=0.0, P=0.0, A=0.0, Z=0.0, pr=0.0):
    """The :class:`RingCells` on x = ln(p_cont/E*) from TAIL_CUT below the tables' bottom
    (cells of TAIL_WIDTH in the smooth ū³ tail) to x1 (cells of CELL_WIDTH, cut at the σ̄
    table's nodes), each cell by the rule ``quad`` (the per-row integral's): a Barus table
    (run 0, β = α E* [-], top e^{x1}) or a run's (run 1: E* [Pa], P = (p0 - p_b)/E* [-] =
    e^{x1} and the law A, Z, pr of :func:`._piezo_kernels._ln_eta`)."""
    xm = float(sc[0]["x_lo"])
    x0 = xm - TAIL_CUT
    nt = int(math.ceil(TAIL_CUT / TAIL_WIDTH))
    nm = max(int(math.ceil((x1 - xm) / CELL_WIDTH)), 1)
    wm = (x1 - xm) / nm
    grid = xm + wm * np.arange(nm + 1)
    grid[-1] = x1
    # the grid cut at the σ̄ nodes inside it (a cut closer than 1e-9 to a bound is dropped)
    bm = np.union1d(grid, tab.lnp[(tab.lnp > xm) & (tab.lnp < x1)])
    bm = bm[np.concatenate(([True], np.diff(bm) > 1e-9))]
    bm[-1] = x1
    cs = np.ascontiguousarray(np.concatenate((x0 + (TAIL_CUT / nt) * np.arange(nt), bm)))
    first = np.ascontiguousarray(nt + np.searchsorted(bm, grid[:-1], side="right") - 1,
                                 dtype=np.int64)
    nc = cs.size - 1
    bc = RingCells(x0, TAIL_CUT / nt, nt, xm, wm, int(run), math.exp(x1), float(beta),
                   float(E), float(P), float(A), float(Z), float(pr), cs, first,
                   np.empty(nc + 1), np.empty(nc + 1), np.empty(nc), np.empty((nc, quad.x.size)),
                   np.empty(nc), *_legendre_recurrence(quad.x.size))
    lt, pmid = _legendre_transform(quad.x, quad.w)
    _cells_kernel(tab, sc, bc, quad, lt, pmid)
    bc.pre[0] = 0.0
    np.cumsum(bc.cells, out=bc.pre[1:])
    bc.suf[nc] = 0.0
    np.cumsum(bc.cells[::-1], out=bc.suf[nc - 1::-1])
    return bc


def _legendre_recurrence(m):
    """(ra, rb): P_{k+1}(u) = ra_k u P_k(u) - rb_k P_{k-1}(u), k < m (Bonnet)."""
    k = np.arange(m, dtype=np.float64)
    return (2 * k + 1) / (k + 1), k / (k + 1)


def _legendre_transform(x, w):
    """(lt, pmid): a_k = Σ_j lt[k, j] f_j are the Legendre coefficients of the polynomial
    through the values f_j at the Gauss–Legendre points x (weights w) (exact: the rule
    integrates P_k times that polynomial), pmid[k] = P_k(0)."""
    m = x.size
    P = np.polynomial.legendre.legvander(x, m - 1)  # P[j, k] = P_k(x_j)
    lt = np.ascontiguousarray(((2 * np.arange(m) + 1) / 2.0)[:, None] * (P * w[:, None]).T)
    pmid = np.ascontiguousarray(np.polynomial.legendre.legvander(np.zeros(1), m - 1)[0])
    return lt, pmid


def _table_rows(tab, sc, sub, idx, bc, quad, out, done):
    """Rings ``idx`` of the columns ``sub`` (None: all) from the table ``bc`` into ``out``
    (partial cells by CELL_SHORT_ORDER Gauss points where the integrand is smooth, else by
    the full rule ``quad``)."""
    xs, ws = gauss_legendre(CELL_SHORT_ORDER)
    short = Quad(xs, ws, CELL_WIDTH)
    if idx is None:
        _cells_rows(tab, sc, readonly_fields(UniformRows(*sub)), bc, short, quad, out)
        done[:] = True
        return
    o = np.empty(idx.size)
    _cells_rows(tab, sc, readonly_fields(UniformRows(*(a[idx] for a in sub))), bc, short,
                quad, o)
    out[idx] = o
    done[idx] = True


def _barus_groups(beta, top, kept, build):
    """[(β, rows)] of the Barus flat rings that take a cumulative table (rows None: all of
    them): β = α E* with β·top <= BARUS_BETA_TOP_MAX, and either a table kept from an earlier
    call (β in ``kept``: any number of rows) or, where ``build``, a group of at least
    BARUS_TABLE_ROWS rows sharing β."""
    n = beta.size
    if beta.min() == beta.max():
        b = float(beta[0])
        if b * top <= BARUS_BETA_TOP_MAX and (b in kept or (build and n >= BARUS_TABLE_ROWS)):
            return [(b, None)]
        return []
    if not kept and not (build and n >= BARUS_TABLE_ROWS):
        return []
    if n > BARUS_TABLE_ROWS and not _shares([beta], n):
        return []
    u, inv, cnt = np.unique(beta, return_inverse=True, return_counts=True)
    use = (u * top <= BARUS_BETA_TOP_MAX) & (np.isin(u, list(kept)) |
                                             (build & (cnt >= BARUS_TABLE_ROWS)))
    return [(float(u[g]), np.flatnonzero(inv == g)) for g in np.flatnonzero(use)]


def _barus_tabled(tab, sc, sub, quad, out, done, memo, theory):
    """Fill ``out`` for the Barus flat rings (columns ``sub`` as in :func:`_uniform_rows`) that
    share a β table (:func:`_barus_groups`), marking them in ``done``. The tables are kept in
    ``memo`` (:func:`_beta_memo`) and serve later calls with any number of rows; a new one is
    not built for a short Δp sweep (fewer than SWEEP_TABLE_ROWS rings), which keeps the sweep
    kernel: building a table costs more there."""
    p0, _L, _pa, pb, E, A, _Z = sub
    keys = [k for k in (E, p0, pb, A) if k.min() != k.max()]
    build = not ((not keys or _shares(keys, out.size)) and out.size < SWEEP_TABLE_ROWS)
    x1 = min(float(sc[0]["x_hi"]), float(sc[0]["x_perc"]))
    rule = (theory, quad.x.size, quad.width)
    with _BETA_LOCK:  # calls from several threads share the memo
        kept = {k[3] for k in memo if k[:3] == rule}
    for beta, idx in _barus_groups(A * E, math.exp(x1), kept, build):
        key = rule + (beta,)
        with _BETA_LOCK:
            bc = memo.get(key)
            if bc is not None:
                memo.move_to_end(key)
        if bc is None:
            bc = _ring_cells(tab, sc, quad, x1, 0, beta)
            with _BETA_LOCK:
                memo[key] = bc
                while len(memo) > BETA_MEMO:
                    memo.popitem(last=False)
        _table_rows(tab, sc, sub, idx, bc, quad, out, done)


def _beta_memo(tables):
    """The β tables kept for ``tables``: an OrderedDict by (theory, rule order, rule width, β),
    newest last, dropped with the Tables object."""
    with _BETA_LOCK:
        memo = _BETA_TABLES.get(tables)
        if memo is None:
            memo = _BETA_TABLES[tables] = OrderedDict()
        return memo


def _run_tabled(tab, sc, sub, pr, quad, out, done):
    """Fill ``out`` for the flat rings not ``done`` in runs of at least SWEEP_TABLE_ROWS rings
    sharing p0, p_b, E* and the law (a long Δp sweep), one table per run."""
    todo = np.flatnonzero(~done)
    if todo.size < SWEEP_TABLE_ROWS:
        return
    cols = sub if todo.size == out.size else [a[todo] for a in sub]
    p0, _L, _pa, pb, E, A, Z = cols
    order, new_run = _runs(cols, by_pa=False)
    if order is None:
        return
    first = np.flatnonzero(new_run)
    ends = np.append(first[1:], todo.size)
    x_lo = float(sc[0]["x_lo"])
    for f, e in zip(first, ends):
        if e - f < SWEEP_TABLE_ROWS:
            continue
        r = order[f]
        P = (p0[r] - pb[r]) / E[r]
        x1 = math.log(P)
        if not x1 > x_lo + CELL_WIDTH:  # the run lies in the ū³ tail: per-row integrals
            continue
        bc = _ring_cells(tab, sc, quad, x1, 1, 0.0, E[r], P, A[r], Z[r], pr)
        whole = e - f == out.size  # one sweep: every row, no gather
        _table_rows(tab, sc, sub, None if whole else todo[order[f:e]], bc, quad, out, done)


def _shares(keys, n, sample=2048):
    """Whether rows seem to share an integrand: any two of ~``sample`` evenly spaced rows with
    equal keys (a cheap guess that spares a batch of distinct rings the sort; a miss only
    costs speed)."""
    smp = [k[::max(1, n // sample)] for k in keys]
    return not new_runs(smp, np.lexsort(smp[::-1])).all()


def _runs(sub, by_pa=True):
    """(order, new_run) of the rows (p0, L, p_a, p_b, E*, A, Z): sorted into runs sharing E*,
    p0, p_b, A, Z (the integrand), ascending p_a within a run if ``by_pa``, and True at each
    run's first row; (None, None) where :func:`_shares` finds no shared integrand."""
    p0, _L, pa, pb, E, A, Z = sub
    keys = [k for k in (E, p0, pb, A, Z) if k.min() != k.max()]  # the ones that vary
    if keys and not _shares(keys, pa.size):
        return None, None
    if by_pa:  # one run (a Δp sweep of one seal) if no key varies
        order = np.lexsort([pa] + keys[::-1]) if keys else np.argsort(pa, kind="stable")
    else:
        order = np.lexsort(keys[::-1]) if keys else np.arange(pa.size)
    return order, new_runs(keys, order)


def _sweep_order(sub):
    """(order, starts) for :func:`_uniform_sweep_kernel`: the rows in :func:`_runs` order and
    the first row of each chunk (a run cut every SWEEP_CHUNK rows; the row count last). order
    None: the rows as they are, each its own run (:func:`_shares` found no shared one)."""
    n = sub[0].size
    order, new_run = _runs(sub)
    if order is None:  # every row its own integrand: rows as they are
        return None, np.arange(n + 1, dtype=np.int64)
    first = np.flatnonzero(new_run)
    # each run cut into chunks of SWEEP_CHUNK rows (they run in parallel)
    run_id = np.cumsum(new_run) - 1
    pos = np.arange(n) - first[run_id]
    starts = np.flatnonzero(new_run | (pos % SWEEP_CHUNK == 0))
    return order, np.append(starts, n).astype(np.int64)


def _uniform_rows(tab, sc, v, law, quad_order, quad_width, memo, theory):
    """(columns, (k, converged, lift, percolated, out_of_table, p_max)) of flat rings; k =
    12 η0 q / h³ [Pa/m] by the uniform-ring integral of every running row."""
    E, pa, pb, p0v, Lv = v["E"], v["pa"], v["p_b"], v["g1"], v["g2"]
    lift = pa > p0v
    perc = (p0v - pb >= math.exp(sc[0]["x_perc"]) * E) & ~lift
    out_t = (p0v - pb > math.exp(sc[0]["x_hi"]) * E) & ~perc & ~lift
    kq = np.zeros(E.size)
    run = ~lift & ~perc & ~out_t & (v["dp"] > 0)
    if np.any(run):
        x, w = gauss_legendre(int(quad_order))
        out = np.empty(int(run.sum()))
        A, Z, pr = law if law is not None else (v["alpha_pv"], np.zeros(E.size), 0.0)
        every = bool(run.all())  # no row to drop: no copies
        sub = [np.ascontiguousarray(a if every else a[run], dtype=np.float64)
               for a in (p0v, Lv, pa, pb, E, A, Z)]
        quad = Quad(x, w, float(quad_width))
        done = np.zeros(out.size, dtype=bool)
        if law is None:
            _barus_tabled(tab, sc, sub, quad, out, done, memo, theory)
        _run_tabled(tab, sc, sub, float(pr), quad, out, done)
        rest = np.flatnonzero(~done)
        if rest.size:
            if rest.size < out.size:
                sub = [np.ascontiguousarray(a[rest]) for a in sub]
            order, starts = _sweep_order(sub)
            rows = readonly_fields(UniformRows(*(sub if order is None else
                                                 (a[order] for a in sub))))
            xs, ws = gauss_legendre(SHORT_ORDER)
            o = np.empty(rest.size)
            _uniform_sweep_kernel(tab, sc, rows, float(pr), quad,
                                  Quad(xs, ws, SHORT_WIDTH * float(quad_width)), starts, o)
            out[rest if order is None else rest[order]] = o
        kq[run] = out
    cols = _base_columns(v)
    cols.update({"p0": p0v, "L": Lv, "open_inlet": np.where(pa > p0v, Lv, 0.0),
                 "open_outlet": np.zeros_like(Lv)})
    return cols, (kq, np.ones(E.size, dtype=bool), lift, perc, out_t, p0v,
                  np.zeros(E.size, dtype=bool))


def _hertz_rows(tables, theory, tab, sc, v, law, steps):
    """As :func:`_uniform_rows` for O-rings (Hertz line contact): the Barus fluid by the
    panel collocation (:func:`_barus_hertz_k`) unless ``steps`` is given, else (and for
    Roelands) shooting per running row."""
    E, pa, pb = v["E"], v["pa"], v["p_b"]
    a = np.sqrt(4.0 * v["g2"] * v["g1"] / (math.pi * E))
    pH = 2.0 * v["g2"] / (math.pi * a)
    lift = pa > pH
    perc = (pH - pa >= math.exp(sc[0]["x_perc"]) * E) & ~lift
    out_t = (pH - pb > math.exp(sc[0]["x_hi"]) * E) & ~perc & ~lift
    near = peak_past_trust(seal_context(tables, theory).pi_trust,
                           ~perc & ~lift & ~out_t & (v["dp"] > 0), pH, pa, E)
    kq = np.zeros(E.size)
    conv = np.ones(E.size, dtype=bool)
    run = ~lift & ~perc & ~out_t & ~near & (v["dp"] > 0)
    if np.any(run):
        k = np.empty(int(run.sum()))
        ok = np.empty(int(run.sum()), dtype=np.bool_)
        if law is not None:
            sub = [np.ascontiguousarray(x[run]) for x in (E, pH, a, pa, pb, law[0], law[1])]
            if steps is None:
                k, ok = _roelands_hertz_k_tabled(tables, theory, *sub, law[2])
                if not np.all(ok):   # Newton failed (steep laws next to lift-off): shooting
                    bad = np.flatnonzero(~ok)
                    k[bad], ok[bad] = _checked_shooting(
                        _shooter(_hertz_kernel_r, tab, sc, HertzRows(*(x[bad] for x in sub)),
                                 law[2]), bad.size, CHECKED_LEVELS)
            else:
                none = np.full(k.size, np.nan)
                _hertz_kernel_r(tab, sc, HertzRows(*sub), law[2], int(steps), none, none, k, ok,
                                np.empty(k.size))
        elif steps is None:
            sub = [np.ascontiguousarray(x[run]) for x in (E, pH, a, pa, pb, v["alpha_pv"])]
            k, ok = _barus_hertz_k_tabled(tables, theory, *sub)
            if not np.all(ok):   # Newton failed (α p_H >~ 5 next to lift-off): shooting
                bad = np.flatnonzero(~ok)
                k[bad], ok[bad] = _checked_shooting(
                    _shooter(_hertz_kernel, tab, sc, tuple(x[bad] for x in sub)), bad.size,
                    CHECKED_LEVELS[1:])
        else:
            sub = [np.ascontiguousarray(x[run]) for x in (E, pH, a, pa, pb, v["alpha_pv"])]
            none = np.full(k.size, np.nan)
            _hertz_kernel(tab, sc, *sub, int(steps), none, none, k, ok, np.empty(k.size))
        kq[run] = k
        conv[run] = ok
    cols = _base_columns(v)
    cols.update({"R": v["g1"], "f_N": v["g2"], "a": a, "p_max": pH, "L": 2 * a})
    with np.errstate(invalid="ignore"):
        sa = np.clip(pa / pH, 0.0, 1.0)
        sb = np.clip(pb / pH, 0.0, 1.0)
        cols["open_inlet"] = np.where(~lift, a * (1.0 - np.sqrt(1.0 - sa * sa)), 2 * a)
        cols["open_outlet"] = np.where(~lift, a * (1.0 - np.sqrt(1.0 - sb * sb)), 0.0)
    return cols, (kq, conv, lift, perc, out_t, pH, near)


def _checked_shooting(shoot, m, levels):
    """(k, converged) of m O-rings by a shooting ``shoot(n, idx, k_guess, slope_guess)`` ->
    (k, ok, slope) of rows idx with n steps, checked: at each level (n1, n2) of ``levels`` the
    rows still open are shot with n1 and n2 steps and keep k(n2) where the two agree within
    FALLBACK_RTOL (relative; the difference bounds the error of k(n2) for any order >= 1 of the
    RK4 next to the zone ends); the others go to the next level, and are not converged after
    the last. The n2 shooting starts from the n1 root and slope (one Newton step, then the
    secant, to the same 1e-13) instead of a coarse solve of its own."""
    k = np.full(m, np.nan)
    ok = np.zeros(m, dtype=bool)
    todo = np.arange(m)
    for n1, n2 in levels:
        none = np.full(todo.size, np.nan)
        k1, ok1, s1 = shoot(n1, todo, none, none)
        k2, ok2, _ = shoot(n2, todo, np.where(ok1, k1, np.nan), np.where(ok1, s1, np.nan))
        with np.errstate(invalid="ignore", divide="ignore"):
            agree = ok1 & ok2 & (np.abs(k1 / k2 - 1.0) <= FALLBACK_RTOL)
        k[todo] = k2
        ok[todo] = agree
        todo = todo[~agree]
        if not todo.size:
            break
    return k, ok


def _shooter(kernel, tab, sc, rows, *extra):
    """``shoot(n, idx, k_guess, slope_guess)`` of :func:`_checked_shooting` for a prange
    shooting kernel called as kernel(tab, sc, *rows[idx], *extra, n, k_guess, slope_guess, k,
    ok, slope) (``rows`` a tuple of arrays, or a HertzRows)."""
    def shoot(n, idx, k_guess, slope_guess):
        k = np.empty(idx.size)
        ok = np.empty(idx.size, dtype=np.bool_)
        slope = np.empty(idx.size)
        sub = [np.ascontiguousarray(x[idx], dtype=np.float64) for x in rows]
        args = (HertzRows(*sub),) if isinstance(rows, HertzRows) else tuple(sub)
        kernel(tab, sc, *args, *extra, int(n), np.ascontiguousarray(k_guess, dtype=np.float64),
               np.ascontiguousarray(slope_guess, dtype=np.float64), k, ok, slope)
        return k, ok, slope
    return shoot


def _panel_hertz_k(tables, theory, E, pH, a, pa, pb, psia, al=None, vis=None):
    """(k = 12 η0 q/h³ [Pa/m], converged) of O-rings (p_a <= p_H, Δp > 0) by the base seal
    engine's panel collocation in ψ (:mod:`._panels`, chained along Δp sweeps): k = ψ_a/(a W),
    ψ_a [Pa] the fluid's reduced pressure drop, W the reduced resistance of the sealing zone;
    ``al`` the Barus α̃ = α E* per row, ``vis`` (rows, 3) the Roelands law (A, Z, p_r/E*)."""
    o = solver_options({"tol": PIEZO_PANEL_TOL, "max_panels": 256})
    out = solve_profile_rows(seal_context(tables, theory), o, 0, np.zeros(2), np.zeros(2),
                             pH / E, pa / E, pb / E, np.arange(E.size),
                             pa >= (1.0 - NEAR_LIFT_OFF) * pH, al, vis, chain=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = psia / (a * out.W)
    ok = (out.status != _panels.ST_NEWTON_FAILED) & (out.status != _panels.ST_NO_ZONE) \
        & np.isfinite(k) & (k > 0.0)
    return np.where(ok, k, np.nan), ok


def _barus_hertz_k(tables, theory, E, pH, a, pa, pb, alpha):
    """:func:`_panel_hertz_k` of Barus O-rings (α̃ = α E*), ψ_a = (1 - e^{-αΔp})/α [Pa]."""
    dp = pa - pb
    with np.errstate(divide="ignore", invalid="ignore"):
        psia = np.where(alpha > 0.0, -np.expm1(-alpha * dp) / np.where(alpha > 0.0, alpha, 1.0),
                        dp)
    return _panel_hertz_k(tables, theory, E, pH, a, pa, pb, psia, al=alpha * E)


def _barus_hertz_k_tabled(tables, theory, E, pH, a, pa, pb, alpha):
    """:func:`_barus_hertz_k`, the rows of one Barus fluid on one rubber (one α̃ = α E* > 0, at
    least TABLE_MIN_ROWS of them: :func:`_by_fluid`) from the fluid's verified O-ring table
    where it pays (:func:`_hertz_k_tabled`)."""
    al = alpha * E
    args = (E, pH, a, pa, pb, alpha)

    def one_fluid(key, i):
        sub = [x[i] for x in args]
        with np.errstate(divide="ignore", invalid="ignore"):
            psia = -np.expm1(-sub[5] * (sub[3] - sub[4])) / sub[5]  # [Pa], α > 0 here
        return _hertz_k_tabled(tables, theory, *sub[:5], key[0], None, lambda j: psia[j],
                               lambda j: _barus_hertz_k(tables, theory, *(x[j] for x in sub)))
    return _by_fluid((al,), al > 0.0, one_fluid,
                     lambda i: _barus_hertz_k_any(tables, theory, *(x[i] for x in args)))


def _barus_hertz_k_any(tables, theory, E, pH, a, pa, pb, alpha):
    """:func:`_barus_hertz_k` of Barus O-rings whose fluids differ from row to row (none with
    a table of its own): the rows with p_b = 0 and 0 < α p_H <= B_MAX below lift-off, at
    least TABLE_MIN_ROWS of them, from the verified table of W(π_H, π_a, α p_H)
    (:func:`fastcontact.seal.hertz.table_W_beta`, kept with the seal context) where completing
    it costs no more solves than those rows; every other row, and the rows whose cells are
    not verified, by the solver."""
    from .hertz import B_MAX, table_W_beta
    elig = np.flatnonzero((pb == 0.0) & (alpha > 0.0) & (pa < pH) & (alpha * pH <= B_MAX))
    W = None
    if elig.size >= TABLE_MIN_ROWS:
        W = table_W_beta(seal_context(tables, theory), pH / E, pa / E, alpha * E, elig,
                         max_solves=elig.size)
    args = (E, pH, a, pa, pb, alpha)
    if W is None:
        return _barus_hertz_k(tables, theory, *args)
    return _k_from_W(W, a, lambda j: -np.expm1(-alpha[j] * (pa[j] - pb[j])) / alpha[j],
                     lambda j: _barus_hertz_k(tables, theory, *(x[j] for x in args)))


def _k_from_W(W, a, psia, solve):
    """(k [Pa/m], converged): k = ψ_a/(a W) on the rows with a finite tabled W, ``psia(j)`` the
    rows' ψ_a [Pa]; ``solve(j)`` -> (k, converged) of the others (NaN W: not tabled)."""
    fast = np.flatnonzero(np.isfinite(W))
    rest = np.flatnonzero(~np.isfinite(W))
    k = np.empty(W.size)
    ok = np.ones(W.size, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        k[fast] = psia(fast) / (a[fast] * W[fast])
    if rest.size:
        k[rest], ok[rest] = solve(rest)
    return k, ok


def _roelands_hertz_k_tabled(tables, theory, E, pH, a, pa, pb, A, Z, pr):
    """:func:`_roelands_hertz_k`, the rows of one Roelands fluid on one rubber (one law
    (A, Z, p_r/E*), at least TABLE_MIN_ROWS of them: :func:`_by_fluid`) from the fluid's
    verified O-ring table where it pays (:func:`_hertz_k_tabled`)."""
    n = E.size
    pr = np.broadcast_to(np.asarray(pr, dtype=np.float64), (n,))  # p_r: one or per row
    prn = pr / E
    args = (E, pH, a, pa, pb, A, Z, pr)

    def one_fluid(key, i):
        sub = [x[i] for x in args]

        def psia(j):  # E* ψ_a [Pa] from the law's tabulated ψ (one table for its rows)
            out = np.empty(j.size)
            psi_drops_one_law(*(float(x) for x in key), np.ascontiguousarray(
                (sub[3][j] - sub[4][j]) / sub[0][j], dtype=np.float64), out)
            return sub[0][j] * out
        return _hertz_k_tabled(tables, theory, *sub[:5], 0.0, key, psia,
                               lambda j: _roelands_hertz_k(tables, theory, *(x[j] for x in sub)))
    return _by_fluid((A, Z, prn), np.ones(n, dtype=bool), one_fluid,
                     lambda i: _roelands_hertz_k(tables, theory, *(x[i] for x in args)))


def _by_fluid(keys, eligible, one_fluid, solve):
    """(k [Pa/m], converged) of O-rings whose fluid is given per row by ``keys`` (arrays): the
    ``eligible`` rows of each fluid with at least TABLE_MIN_ROWS rows (at most PIEZO_TABLES
    fluids, the largest, as many as a seal context keeps tables of) by ``one_fluid(key,
    rows)``, every other row by ``solve(rows)``; each -> (k, converged) of those rows."""
    from .._core.groups import row_groups
    from .hertz import PIEZO_TABLES
    n = keys[0].size
    k = np.empty(n)
    ok = np.empty(n, dtype=bool)
    rest = np.ones(n, dtype=bool)
    pick = np.flatnonzero(eligible) if n >= TABLE_MIN_ROWS else np.zeros(0, dtype=np.int64)
    for key, rows in row_groups([x[pick] for x in keys], TABLE_MIN_ROWS, PIEZO_TABLES):
        i = pick[rows]
        k[i], ok[i] = one_fluid(key, i)
        rest[i] = False
    if rest.any():
        i = np.flatnonzero(rest)
        k[i], ok[i] = solve(i)
    return k, ok


def _hertz_k_tabled(tables, theory, E, pH, a, pa, pb, al, vis, psia, solve):
    """(k [Pa/m], converged) of O-rings of one fluid (Barus α̃ = ``al``, or the Roelands law
    ``vis``): the rows below lift-off from the fluid's verified O-ring tables
    (:func:`fastcontact.seal.hertz.tabled_W`: p_b = 0 from the table of (π_H, π_a), p_b > 0
    from the one of (π_H, π_a, π_b); ~1e-8 in Q of the solver), k = ψ_a/(a W), ``psia(i)``
    the rows' ψ_a [Pa]; where completing a table for its rows would take more solves than the
    rows themselves (a few hundred O-rings of scattered p_H; not a Δp sweep of a few O-rings, a
    large study, or rows a kept table covers) those rows, and the rows whose cells are not
    verified, by ``solve(i)`` -> (k, converged)."""
    from .hertz import tabled_W
    n = E.size
    W = tabled_W(seal_context(tables, theory), pH / E, pa / E, pb / E,
                 np.flatnonzero(pa < pH), pb == 0.0, al, vis, budget_zero=True)
    if W is None:
        return solve(np.arange(n))
    return _k_from_W(W, a, psia, solve)


#: fewest O-ring rows of one fluid (Barus or Roelands; in a call of several fluids, of each)
#: for which :func:`_hertz_k_tabled` is tried (the table used where it pays) instead of
#: solving each row (~70-100 µs a row)
TABLE_MIN_ROWS = 500


def _roelands_hertz_k(tables, theory, E, pH, a, pa, pb, A, Z, pr):
    """:func:`_panel_hertz_k` of Roelands O-rings, ψ = ∫η0/η dp tabulated per row
    (:mod:`._roelands_psi`; ψ_a from the same table the solver builds)."""
    prn = np.ascontiguousarray(pr / E, dtype=np.float64)
    psia = np.empty(E.size)
    psi_drops(np.ascontiguousarray(A), np.ascontiguousarray(Z), prn,
              np.ascontiguousarray((pa - pb) / E), psia)
    return _panel_hertz_k(tables, theory, E, pH, a, pa, pb, E * psia,
                          vis=np.column_stack((A, Z, prn)))


def _base_columns(v):
    """The input columns every profile reports first."""
    return {"dp": v["dp"], "L_y": v["L_y"], "E_star": v["E"], "eta": v["eta"],
            "alpha_pv": v["alpha_pv"], "p_b": v["p_b"]}


def _piezo_frame(cols, law, theory, profile, shape, roelands_eta_inf):
    """The result DataFrame of :func:`seal_leak_piezo`, with units, law and references."""
    roelands = law is not None
    if roelands:
        cols["roelands_z"] = law[1]
    from .api import INPUT_COLUMNS  # (api imports this module)
    df = pd.DataFrame(own_columns(cols, INPUT_COLUMNS), copy=False)
    refs = ["doi:10.2475/ajs.s3-45.266.87", "arXiv:0911.3019"]
    if roelands:
        refs = ["C.J.A. Roelands, PhD thesis, TU Delft (1966)",
                "B.J. Hamrock and D. Dowson, Ball Bearing Lubrication, Wiley (1981), eq. 4.5",
                "arXiv:0911.3019"]
    df.attrs.update({"units": {"Q": "m^3/s", "dp": "Pa", "p_a": "Pa", "p_b": "Pa", "p0": "Pa",
                               "L": "m", "L_y": "m", "E_star": "Pa", "eta": "Pa s",
                               "alpha_pv": "1/Pa", "R": "m", "f_N": "N/m", "a": "m",
                               "p_max": "Pa", "roelands_z": "1", "open_inlet": "m",
                               "open_outlet": "m"},
                     "theory": theory, "profile": profile,
                     "viscosity": "Roelands" if roelands else "Barus",
                     "shape": tuple(shape), "references": refs})
    if roelands:
        df.attrs.update(roelands_p_r=float(law[2]), roelands_eta_inf=float(
            ROELANDS_ETA_INF if roelands_eta_inf is None else roelands_eta_inf))
    return df
