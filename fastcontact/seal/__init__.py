"""Leak rate of static seals with fluid-pressure feedback (SPEC §6, paper Sec. 6, eqs. 25–33).

Public entry points
-------------------
:func:`seal_leak`     leak rate ``Q`` [m³/s] of many cases (NumPy broadcasting), with flags
:func:`seal_profile`  p_cont(x), p_fluid(x), ū(x), σ_eff(x) of one case
:func:`seal_elastic`  the stiff-material problem (eq. 30): macroscopic elastic deformation
                      driven by contact + fluid pressure, solved together with the flow
                      (``fastcontact.seal.seal_elastic``; one case)

Batches run on a thread pool (numba ``nogil`` kernels, one chunk per thread) — numba's
``prange`` cannot take the tables' kernel tuple. Nothing compiles at import.

Geometry and conventions
------------------------
Across the seal width x ∈ [0, L] the fluid flows from the high-pressure side x = 0
(``p_a = p_b + dp``) to the low-pressure side x = L (``p_b``); ``L_y`` is the seal length
(the mean circumference of a ring). All pressures are gauge pressures (ambient = 0), ``p_b >= 0``.
Nominal pressure p0(x) = p_cont(x) + p_f(x) (eq. 28); steady flow per unit length
q = −σ_eff(p_cont) dp_f/dx is constant (eqs. 25–26) and Q = L_y q (eq. 31).

Profiles (soft materials: p0(x) is the dry contact pressure, unchanged by the fluid):

``profile="uniform"``  flat ring: p0(x) = ``p0``; needs ``p0``, ``L``. Closed form (SPEC §6)
    q = (1/L) ∫_{p0−p_a}^{p0−p_b} σ_eff(p) dp, evaluated from a tabulated primitive
    S(π) = ∫_0^π σ̄ dπ' (one per Tables/theory, built lazily; a case costs two lookups, and
    a short interval — small dp — is integrated directly, never as a difference).
``profile="hertz"``    O-ring (cylinder radius ``R``, load per unit length ``f_N``) on a flat:
    a² = 4 f_N R/(π E*), p0(x) = (2 f_N/(π a²)) √(a² − (x − a)²) on x ∈ [0, 2a] (L = 2a is
    derived; do not pass ``p0`` or ``L``). Needs ``R``, ``f_N``.
an array               p0 sampled at the positions ``x`` (strictly increasing, inlet at x[0],
    L = x[-1] − x[0]); linear between the samples. Do not pass ``p0`` or ``L``.

Edges of the sealing zone (Hertz and arrays). Where p0(x) < p_f the surfaces separate
(fluid-filled gap, negligible flow resistance), so the fluid pressure is constant there.
On the inlet side the fluid stands at p_a up to the first point x_s where p0(x_s) = p_a; on
the outlet side it is at p_b beyond the last point x_e where p0(x_e) = p_b (for p_b = 0 and a
Hertz profile x_e = L). The sealing zone is [x_s, x_e] with p_cont = 0 at both of its ends
(σ_eff → ∞ logarithmically there: integrable), and the open lengths ``open_inlet = x_s − x[0]``
and ``open_outlet = L − x_e`` are reported. Inside it the problem
dp_f/dx = −q/σ_eff(p0 − p_f), p_f(x_s) = p_a, p_f(x_e) = p_b is solved as eq. (33) on
adaptive Gauss–Legendre panels by damped Newton (see :mod:`fastcontact.seal_kernels`); a
place inside the zone where p0 dips below p_f is an open pocket (zero resistance). Close to
percolation (ln σ̄ falls by ~10³ per unit ln p there) the Newton is continued in p_a from an
easier problem; within ~1e-5 (relative) of the percolation threshold — where Q has already
dropped by tens of orders of magnitude — it may still fail, and then ``Q = NaN`` with
``converged = False`` (never a silent number).

Stiff materials (eq. 30): :func:`seal_elastic` solves the coupled problem for an elastic
cylinder (boundary elements with piecewise-constant pressure panels and exact log-kernel
integrals, Newton on ū and u_c, continuation in dp). Its dry limit is Hertz up to the
roughness (deviation ∝ R h_rms/a²), and for a²/(R h_rms) → ∞ at moderate dp it tends to the
soft Hertz result; at large dp the fluid unloads the contact and the seal lifts off earlier
than the soft model predicts.

Flags and limits (never a silent number)
----------------------------------------
``lift_off``   no sealing zone is left: max p0 <= p_a (uniform: ``dp + p_b >= p0``; Hertz:
               dp + p_b >= p_H = 2 f_N/(π a)). At the
               equality itself the seal is on the verge of opening: ``Q`` is the finite limit
               p_a → max p0⁻ (the inlet contact pressure is 0 there, ū → ∞, and Q has an
               infinite slope in dp). Beyond it ``Q = inf``: the gap is open everywhere and the
               leak is not limited by the contact (not modelled here).
``percolated`` the contact percolates somewhere across the width (critical junction / EMT):
               σ_eff(p_cont) = 0 on a line that every flow path crosses, the flow stops,
               ``Q = 0``. With p_f decreasing from p_a to p_b this happens exactly when
               max p0 − p_a >= p_perc or p0(L) − p_b >= p_perc (uniform: p0 − p_b >= p_perc),
               p_perc = ``tables.percolation_pressure(theory, E_star)``. For a uniform ring Q
               drops from a finite value to 0 at this boundary (the percolated line sits at
               the outlet edge); for a Hertz profile Q → 0 continuously.
dp → 0         Q = (L_y/L) σ_eff(p0 − p_b) dp (uniform; eq. 32), Q = L_y dp / ∫ dx/σ_eff(p0 − p_b)
               over the sealing zone in general. ``dp = 0`` gives Q = 0 exactly.

Conductivities come from the tables (reduced σ̄ = 12ησ_eff/h_rms³ against p̄ = p/E*). Below
the table's lowest pressure (ū ≳ 32 h_rms) the large-separation asymptote is used explicitly:
p ≈ βE*e^{−ū/u0}, ū linear in ln p with slope u0, and σ̄^(1/3) continued linearly in ln p from
the table edge (C¹); this matters only where p_cont → 0 (zone ends, lift-off) and contributes
< 1e-10 of Q in the cases tested. For ``theory="critical_junction"`` σ carries α_cj³ exactly,
so a table built with α_T serves any ``alpha_cj`` through the factor (alpha_cj/α_T)³;
``a_perc`` is fixed by the table. ``alpha_cj`` is ignored by the other theories.
"""
from __future__ import annotations

import math
import os
import threading
import weakref
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd

from .._core.validate import as_float_array, check_positive, check_range
from ..flow.conductivity import check_theory

__all__ = ["seal_leak", "seal_profile", "seal_elastic", "hertz_contact", "SOLVER_DEFAULTS",
           "seal_context"]

#: soft-seal solver knobs (non-uniform profiles): Gauss–Legendre nodes per panel, initial
#: panels, grading order of the end map, panel error tolerance (Legendre tail of the
#: resistance density relative to the total), maximum panels, Newton iterations per mesh.
#: Defaults chosen with bench/bench_seal.py (error <= ~3e-8 against the solver's own
#: converged limit; well inside the tables' 5e-7).
SOLVER_DEFAULTS = dict(nodes=10, panels=4, grading=2, tol=1e-3, max_panels=128, max_newton=60)

#: re-tabulation of ln σ̄ (uniform in ln p̄): spacing and the per-cell verification tolerance
RETAB_H = 1.0 / 64.0
RETAB_TOL = 1e-9
#: primitive S: node spacing in ln p̄ (quintic Hermite in between) and the Gauss–Legendre
#: order of intervals shorter than one cell (integrated directly, no cancellation)
PRIM_H = 1.0 / 32.0
PRIM_GL = 6
#: rows per thread below which a batch runs on the calling thread
_MIN_CHUNK = {"uniform": 20000, "profile": 16}

_CONTEXTS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_CTX_LOCK = threading.Lock()
_POOL = None


# =========================================================================== plumbing
def _threads():
    try:
        import numba
        return max(1, int(numba.get_num_threads()))
    except Exception:  # noqa: BLE001
        return max(1, os.cpu_count() or 1)


def _run_chunks(fn, n_rows, kind):
    """fn(start, stop) over [0, n_rows) in contiguous chunks on a thread pool (nogil kernels)."""
    global _POOL
    nth = min(_threads(), max(1, n_rows // _MIN_CHUNK[kind]))
    if nth <= 1:
        fn(0, n_rows)
        return
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=_threads(), thread_name_prefix="fastcontact-seal")
    cuts = np.linspace(0, n_rows, 4 * nth + 1).astype(np.int64)
    futs = [_POOL.submit(fn, int(cuts[k]), int(cuts[k + 1])) for k in range(cuts.size - 1)]
    for f in futs:
        f.result()


def _gl_data(n):
    """Gauss–Legendre nodes/weights on [-1, 1], the tail-integration matrix and the
    Legendre projection matrix of an n-point panel."""
    from numpy.polynomial import legendre as Lg

    z, w = Lg.leggauss(n)
    V = Lg.legvander(z, n - 1)
    Vi = np.linalg.inv(V)
    At = np.empty((n, n))
    for k in range(n):
        ic = Lg.legint(Vi[:, k], lbnd=-1)
        At[:, k] = Lg.legval(1.0, ic) - Lg.legval(z, ic)      # ∫_{z_i}^{1} ℓ_k
    Lp = (np.arange(n)[:, None] + 0.5) * (V.T * w[None, :])     # a_j = Σ_k Lp[j,k] f_k
    return (np.ascontiguousarray(z), np.ascontiguousarray(w), np.ascontiguousarray(At),
            np.ascontiguousarray(Lp))


_GL_CACHE = {}


def _gl(n):
    if n not in _GL_CACHE:
        _GL_CACHE[n] = _gl_data(n)
    return _GL_CACHE[n]


class SealContext:
    """Everything a seal kernel needs for one Tables object and theory (built once).

    Attributes: ``ctx`` (the kernels' tuple), ``S``/``sp`` (primitive), ``glx``/``glw``,
    ``p_perc`` (reduced percolation pressure, inf for "average"), ``p_top`` (table top),
    ``alpha_table``, ``h_rms``, ``retab_worst`` (largest verified re-tabulation error) and
    ``retab_fallback_cells`` (cells that call the table kernel directly).
    """

    def __init__(self, tables, theory):
        from . import _kernels as sk

        tables._need(theory)
        self.theory = theory
        self.h_rms = float(tables.h_rms)
        tab = tables.kernel_data(theory)
        lo, hi = tables.p_range
        t_lo, t_hi = math.log(lo), math.log(hi)
        p_perc = float(tables.percolation_pressure(theory, 1.0))
        self.p_perc = p_perc
        self.p_top = float(hi)
        t_perc = math.log(p_perc) if math.isfinite(p_perc) else math.inf
        # C¹ continuation of σ̄^(1/3) below the table: value and slope at the edge
        d = 0.02
        f = np.cbrt(np.ravel(tables.sigma_bar(lo * np.exp(d * np.arange(3.0)), 1.0, theory)))
        b1 = -(-3.0 * f[0] + 4.0 * f[1] - f[2]) / (2.0 * d)
        u_lo = float(np.ravel(tables.mean_separation(np.array([lo]), 1.0))[0]) / self.h_rms
        c_u = float(tables.info["asymptote_u0_over_h"])
        t_top = min(t_hi, t_perc)
        nret = int(math.floor((t_top - t_lo) / RETAB_H)) + 1
        ext = np.array([t_lo, t_hi, t_perc, f[0], b1, u_lo, c_u, t_lo, RETAB_H])
        lns, dlns = sk.retabulate(tab, ext, t_lo, RETAB_H, nret)
        ok, worst = sk.verify_cells(tab, ext, lns, dlns, RETAB_TOL)
        self.ctx = (tab, ext, lns, dlns, ok)
        self.retab_worst = float(worst)
        self.retab_fallback_cells = int((~ok).sum())
        self.alpha_table = float(tables.options.get("alpha_cj", 1.0))
        self.a_perc = float(tables.options.get("a_perc", 0.5))
        self.glx, self.glw = np.polynomial.legendre.leggauss(PRIM_GL)
        glx8, glw8 = np.polynomial.legendre.leggauss(10)
        nS = int(math.floor((t_top - t_lo) / PRIM_H)) + 1
        self.S = sk.build_primitive(self.ctx, t_lo, PRIM_H, nS, glx8, glw8)
        self.sp = np.array([t_lo, PRIM_H, t_lo + (nS - 1) * PRIM_H])
        self.t_top = t_top


def seal_context(tables, theory) -> SealContext:
    """The cached :class:`SealContext` of (tables, theory); built on first use."""
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


# =========================================================================== validation
def _check_tables(tables):
    from ..tables import Tables

    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables object "
                         f"(fastcontact.precompute(...) or Tables.from_parquet(...))")
    return tables


def _check_theory_for(tables, theory, alpha_cj, a_perc):
    check_theory(theory)
    tables._need(theory)
    if a_perc is not None:
        a = float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
        have = float(tables.options.get("a_perc", 0.5))
        if theory == "critical_junction" and a != have:
            raise ValueError(f"a_perc = {a!r} is invalid for these tables: they were built with "
                             f"a_perc = {have!r} (rebuild with precompute(..., a_perc={a!r}))")
    return check_positive("alpha_cj", alpha_cj, "[-]")


def _alpha_scale(sc, theory, alpha_cj):
    if theory != "critical_junction":
        return np.ones_like(alpha_cj)
    return (alpha_cj / sc.alpha_table) ** 3


def _profile_kind(profile, x):
    if isinstance(profile, str):
        if profile not in ("uniform", "hertz"):
            raise ValueError(f"profile = {profile!r} is invalid: must be 'uniform', 'hertz' or an "
                             f"array of p0(x) [Pa] sampled at x")
        if x is not None:
            raise ValueError(f"x = array(...) is invalid with profile = {profile!r}: x gives the "
                             f"positions of an array profile only")
        return profile, None, None
    p = as_float_array("profile", profile)
    if p.ndim != 1 or p.size < 2:
        raise ValueError(f"profile = array(shape={p.shape}) is invalid: must be 'uniform', 'hertz' "
                         f"or a 1-D array of at least 2 values of p0(x) [Pa]")
    check_positive("profile", p, "[Pa] (p0(x) samples)", allow_zero=True)
    if x is None:
        raise ValueError("x = None is invalid with an array profile: give the positions x [m] "
                         "of the p0(x) samples")
    xa = as_float_array("x", x)
    if xa.shape != p.shape:
        raise ValueError(f"x = array(shape={xa.shape}) is invalid: must have the profile's shape "
                         f"{p.shape}")
    if not np.all(np.isfinite(xa)):
        raise ValueError("x = array(...) is invalid: must be finite [m]")
    if np.any(np.diff(xa) <= 0):
        i = int(np.argmax(np.diff(xa) <= 0)) + 1
        raise ValueError(f"x = {xa[i]!r} at index {i} is invalid: x must be strictly "
                         f"increasing [m]")
    return "array", p, xa


def hertz_contact(R, f_N, E_star):
    """Half-width a [m] and peak pressure p_H [Pa] of a cylinder (line load f_N [N/m]) on a
    flat: a² = 4 f_N R/(π E*), p_H = 2 f_N/(π a)."""
    R = check_positive("R", R, "[m]")
    f_N = check_positive("f_N", f_N, "[N/m]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    a = np.sqrt(4.0 * f_N * R / (math.pi * E_star))
    return a, 2.0 * f_N / (math.pi * a)


def _common_inputs(dp, L_y, E_star, eta, p_b):
    return dict(dp=check_positive("dp", dp, "[Pa]", allow_zero=True),
                L_y=check_positive("L_y", L_y, "[m]"),
                E_star=check_positive("E_star", E_star, "[Pa]"),
                eta=check_positive("eta", eta, "[Pa·s]"),
                p_b=check_positive("p_b", p_b, "[Pa] (gauge)", allow_zero=True))


def _forbid(kind, **given):
    for name, v in given.items():
        if v is not None:
            raise ValueError(f"{name} = {v!r} is invalid with profile = {kind!r}: "
                             + ("the Hertz profile derives p0(x) and L = 2a from R and f_N"
                                if kind == "hertz" else
                                "an array profile takes p0(x) from the array and L from x"))


def _require(kind, **given):
    for name, v in given.items():
        if v is None:
            raise ValueError(f"{name} = None is invalid: profile = {kind!r} requires {name}")


# =========================================================================== uniform
def _uniform_q_reduced(sc, c_lo, c_hi):
    """∫_{c_lo}^{c_hi} σ̄ dπ per row (reduced, contiguous arrays)."""
    from . import _kernels as sk

    out = np.empty(c_lo.size)
    _run_chunks(lambda a, b: sk.uniform_kernel(sc.ctx, sc.S, sc.sp, sc.glx, sc.glw, c_lo, c_hi,
                                               out, a, b), c_lo.size, "uniform")
    return out


def _table_top_check(sc, name, value_pa, E):
    """Average theory only: contact pressures above the table (A > 0.999) cannot be evaluated."""
    bad = value_pa / E > sc.p_top * (1 + 1e-13)
    if np.any(bad):
        v = float(np.broadcast_to(value_pa, bad.shape)[bad].ravel()[0])
        e = float(np.broadcast_to(E, bad.shape)[bad].ravel()[0])
        raise ValueError(f"{name} = {v!r} is invalid: the contact pressure would exceed the "
                         f"table, which reaches p/E* = {sc.p_top:.6g} ({sc.p_top * e:.6g} Pa at "
                         f"E* = {e:g} Pa; A(ζ1)/A0 = 0.999)")


def _leak_uniform(tables, sc, theory, p0, L, dp, L_y, E_star, eta, p_b, alpha_cj):
    p0 = check_positive("p0", p0, "[Pa]")
    L = check_positive("L", L, "[m]")
    arrs = np.broadcast_arrays(p0, L, dp, L_y, E_star, eta, p_b, alpha_cj)
    shape = arrs[0].shape
    p0, L, dp, L_y, E, eta, p_b, alpha_cj = (np.ascontiguousarray(a, dtype=np.float64).ravel()
                                              for a in arrs)
    p_a = p_b + dp
    lift = p_a >= p0
    contact = ~(p_a > p0)
    c_hi = p0 - p_b
    perc = contact & (c_hi >= sc.p_perc * E)
    if theory == "average":
        _table_top_check(sc, "p0", np.where(contact, c_hi, 0.0), E)
    solve = contact & ~perc & (dp > 0)
    c_lo = np.where(solve, (p0 - p_a) / E, np.nan)
    c_hi_r = np.where(solve, c_hi / E, np.nan)
    I = _uniform_q_reduced(sc, np.ascontiguousarray(c_lo), np.ascontiguousarray(c_hi_r))
    scale = _alpha_scale(sc, theory, alpha_cj)
    Q = np.where(solve, L_y * sc.h_rms ** 3 * E / (12.0 * eta * L) * I * scale, 0.0)
    Q = np.where(~contact, np.inf, Q)
    df = pd.DataFrame({
        "Q": Q, "lift_off": lift, "percolated": perc,
        "p0": p0, "dp": dp, "p_a": p_a, "p_b": p_b, "L": L, "L_y": L_y, "E_star": E,
        "eta": eta, "alpha_cj": alpha_cj,
        "open_inlet": np.where(contact, 0.0, L), "open_outlet": np.zeros_like(L),
    })
    return df, shape


# =========================================================================== profiles
def _solver_opts(options):
    o = dict(SOLVER_DEFAULTS)
    for k, v in (options or {}).items():
        if k not in o:
            raise ValueError(f"solver option {k!r} is invalid: must be one of {sorted(o)}")
        o[k] = v
    if not (2 <= int(o["nodes"]) <= 40):
        raise ValueError(f"nodes = {o['nodes']!r} is invalid: must be in [2, 40]")
    if not (1 <= int(o["panels"]) <= int(o["max_panels"])):
        raise ValueError(f"panels = {o['panels']!r} is invalid: must be in [1, max_panels]")
    if not (0 <= int(o["grading"]) <= 8):
        raise ValueError(f"grading = {o['grading']!r} is invalid: must be in [0, 8]")
    if not (0.0 < float(o["tol"]) < 1.0):
        raise ValueError(f"tol = {o['tol']!r} is invalid: must be in (0, 1)")
    return o


#: panel tolerance used at the exact lift-off point p_a = max p0, where the inlet end of the
#: sealing zone is degenerate (p0' = 0 there, p_cont ~ exp(-K δ^(-1/3))) and the Legendre-tail
#: indicator under-estimates the error (bench: 3e-5 at tol 1e-3, 1e-7 at 1e-9)
EQUALITY_TOL = 1e-9


def _solve_rows(sc, kind, xg, p0n, amp, pia, pib, o, keep=False):
    """Run the soft-seal row kernel (threads); returns W, status, panels, error, ξ_s, ξ_e
    (and, with keep, the single row's mesh and resistance density)."""
    from . import _kernels as sk

    n = int(o["nodes"])
    z, w, At, Lp = _gl(n)
    M = amp.size
    PMAX = int(o["max_panels"])
    out = [np.empty(M), np.empty(M, dtype=np.int64), np.empty(M, dtype=np.int64), np.empty(M),
           np.empty(M), np.empty(M)]
    pan_keep = np.zeros(PMAX + 1)
    r_keep = np.zeros(PMAX * n)
    args = (sc.ctx, kind, np.ascontiguousarray(xg, dtype=np.float64),
            np.ascontiguousarray(p0n, dtype=np.float64), np.ascontiguousarray(amp),
            np.ascontiguousarray(pia), np.ascontiguousarray(pib), int(o["grading"]), n,
            int(o["panels"]), PMAX, float(o["tol"]), int(o["max_newton"]), z, w, At, Lp,
            *out, pan_keep, r_keep)
    if keep:
        sk.solve_rows(*args, 0, M)
        return (*out, pan_keep, r_keep)
    _run_chunks(lambda a, b: sk.solve_rows(*args, a, b), M, "profile")
    return tuple(out)


def _hertz_rows(sc, piH, pia, pib, o):
    W, st, P, e, _, _ = _solve_rows(sc, 0, np.zeros(2), np.zeros(2), piH, pia, pib, o)
    return W, st, P, e


def _array_rows(sc, xi, p0, E, pia_pa, pib_pa, o):
    """Array profile rows (same p0 samples [Pa], per-row E*, p_a, p_b [Pa])."""
    return _solve_rows(sc, 1, xi, p0, 1.0 / E, pia_pa / E, pib_pa / E, o)


def _leak_hertz(tables, sc, theory, R, f_N, dp, L_y, E_star, eta, p_b, alpha_cj, o):
    R = check_positive("R", R, "[m]")
    f_N = check_positive("f_N", f_N, "[N/m]")
    arrs = np.broadcast_arrays(R, f_N, dp, L_y, E_star, eta, p_b, alpha_cj)
    shape = arrs[0].shape
    R, f_N, dp, L_y, E, eta, p_b, alpha_cj = (np.ascontiguousarray(a, dtype=np.float64).ravel()
                                              for a in arrs)
    a, pH = hertz_contact(R, f_N, E)
    p_a = p_b + dp
    lift = p_a >= pH
    contact = ~(p_a > pH)
    perc = contact & (pH - p_a >= sc.p_perc * E)
    if theory == "average":
        _table_top_check(sc, "f_N", np.where(contact, pH - p_b, 0.0), E)
    solve = contact & ~perc & (dp > 0)
    idx = np.flatnonzero(solve)
    Wr = np.full(R.size, np.nan)
    conv = np.ones(R.size, dtype=bool)
    err = np.zeros(R.size)
    for sel in (idx[p_a[idx] != pH[idx]], idx[p_a[idx] == pH[idx]]):
        if not sel.size:
            continue
        oo = o if p_a[sel[0]] != pH[sel[0]] else dict(o, tol=min(o["tol"], EQUALITY_TOL),
                                                     max_panels=max(o["max_panels"], 256))
        W, st, P, e = _hertz_rows(sc, np.ascontiguousarray(pH[sel] / E[sel]),
                                  np.ascontiguousarray(p_a[sel] / E[sel]),
                                  np.ascontiguousarray(p_b[sel] / E[sel]), oo)
        Wr[sel] = np.where(st == 2, np.nan, W)         # Newton failed: no number
        conv[sel] = st == 0
        err[sel] = np.where(st == 2, np.nan, e)
    scale = _alpha_scale(sc, theory, alpha_cj)
    with np.errstate(invalid="ignore", divide="ignore"):
        Q = L_y * sc.h_rms ** 3 * E / (12.0 * eta * a) * (dp / E) / Wr * scale
    Q = np.where(solve, Q, 0.0)
    Q = np.where(~contact, np.inf, Q)
    # open lengths: x_s = a(1 − cos θ_s) with sin θ_s = p_a/p_H; x_e likewise from p_b
    with np.errstate(invalid="ignore"):
        sa = np.clip(p_a / pH, 0.0, 1.0)
        sb = np.clip(p_b / pH, 0.0, 1.0)
        open_in = a * (1.0 - np.sqrt(1.0 - sa * sa))
        open_out = a * (1.0 - np.sqrt(1.0 - sb * sb))
    open_in = np.where(contact, open_in, 2 * a)
    open_out = np.where(contact, open_out, 0.0)
    df = pd.DataFrame({
        "Q": Q, "lift_off": lift, "percolated": perc,
        "R": R, "f_N": f_N, "a": a, "L": 2 * a, "p_max": pH, "dp": dp, "p_a": p_a, "p_b": p_b,
        "L_y": L_y, "E_star": E, "eta": eta, "alpha_cj": alpha_cj,
        "open_inlet": open_in, "open_outlet": open_out,
        "converged": conv, "error_estimate": err,
    })
    return df, shape


def _array_flags(p0, p_a, p_b, E, p_perc):
    pmax = float(np.max(p0))
    lift = p_a >= pmax
    contact = ~(p_a > pmax)
    perc = contact & ((pmax - p_a >= p_perc * E) | (p0[-1] - p_b >= p_perc * E))
    return pmax, lift, contact, perc


def _leak_array(tables, sc, theory, p0x, x, dp, L_y, E_star, eta, p_b, alpha_cj, o):
    arrs = np.broadcast_arrays(dp, L_y, E_star, eta, p_b, alpha_cj)
    shape = arrs[0].shape
    dp, L_y, E, eta, p_b, alpha_cj = (np.ascontiguousarray(a, dtype=np.float64).ravel()
                                      for a in arrs)
    L = float(x[-1] - x[0])
    xi = np.ascontiguousarray((x - x[0]) / L)
    p_a = p_b + dp
    pmax, lift, contact, perc = _array_flags(p0x, p_a, p_b, E, sc.p_perc)
    if theory == "average":
        _table_top_check(sc, "profile", np.where(contact, pmax - p_b, 0.0), E)
    solve = contact & ~perc & (dp > 0)
    idx = np.flatnonzero(solve)
    Wr = np.full(E.size, np.nan)
    conv = np.ones(E.size, dtype=bool)
    err = np.zeros(E.size)
    xs = np.where(contact, 0.0, 1.0)
    xe = np.ones(E.size)
    for sel in (idx[p_a[idx] != pmax], idx[p_a[idx] == pmax]):
        if not sel.size:
            continue
        oo = o if p_a[sel[0]] != pmax else dict(o, tol=min(o["tol"], EQUALITY_TOL),
                                               max_panels=max(o["max_panels"], 256))
        W, st, P, e, s_, e_ = _array_rows(sc, xi, np.ascontiguousarray(p0x),
                                          np.ascontiguousarray(E[sel]),
                                          np.ascontiguousarray(p_a[sel]),
                                          np.ascontiguousarray(p_b[sel]), oo)
        Wr[sel] = np.where(st == 2, np.nan, W)         # Newton failed: no number
        conv[sel] = (st == 0) | (st == 3)
        err[sel] = np.where(st == 2, np.nan, e)
        xs[sel] = s_
        xe[sel] = e_
    # a zone of zero length (only at the lift-off equality): the seal is open
    Wr = np.where(solve & (Wr == 0.0), np.nan, Wr)
    scale = _alpha_scale(sc, theory, alpha_cj)
    with np.errstate(invalid="ignore", divide="ignore"):
        Q = L_y * sc.h_rms ** 3 * E / (12.0 * eta * L) * (dp / E) / Wr * scale
    Q = np.where(solve, Q, 0.0)
    Q = np.where(~contact, np.inf, Q)
    df = pd.DataFrame({
        "Q": Q, "lift_off": lift, "percolated": perc, "p_max": np.full(E.size, pmax),
        "L": np.full(E.size, L), "dp": dp, "p_a": p_a, "p_b": p_b, "L_y": L_y, "E_star": E,
        "eta": eta, "alpha_cj": alpha_cj, "open_inlet": xs * L, "open_outlet": (1.0 - xe) * L,
        "converged": conv, "error_estimate": err,
    })
    return df, shape


def seal_leak(tables, *, p0=None, dp, L=None, L_y, E_star, eta, theory="critical_junction",
              alpha_cj=1.0, p_b=0.0, profile="uniform", R=None, f_N=None, x=None, a_perc=None,
              solver=None):
    """Leak rate of a static seal, Q = L_y q [m³/s], for many cases at once (SPEC §6).

    Parameters (arrays broadcast against each other; one row per broadcast element)
    ----------
    tables : Tables        precomputed tables of the rough surface (must hold ``theory``)
    p0 : float or array    nominal contact pressure of a flat ring [Pa] (``profile="uniform"``)
    dp : float or array    pressure difference p_a − p_b across the seal [Pa], >= 0
    L : float or array     seal width [m] (``profile="uniform"``)
    L_y : float or array   seal length, e.g. the mean circumference of a ring [m]
    E_star : float or array  effective modulus [Pa]
    eta : float or array   fluid viscosity [Pa·s]
    theory : str           "critical_junction" (default), "emt" or "average" (in the tables)
    alpha_cj : float or array  critical-junction factor (σ ∝ α_cj³; rescales the table's α)
    p_b : float or array   gauge pressure on the low-pressure side [Pa], >= 0
    profile : "uniform", "hertz" or array   nominal pressure profile (module docstring)
    R, f_N : float or array   O-ring cross-section radius [m] and load per unit length [N/m]
                           (``profile="hertz"``; then L = 2a, p0 and L must not be given)
    x : array              positions [m] of an array profile's samples (inlet at x[0])
    a_perc : float, optional  if given it must equal the tables' a_perc (fixed at precompute)
    solver : dict, optional   knobs of the non-uniform solver (see SOLVER_DEFAULTS)

    Returns
    -------
    pandas.DataFrame, one row per case (C order of the broadcast shape, ``df.attrs["shape"]``):
    ``Q`` [m³/s] (inf beyond lift-off, 0 if percolated or dp = 0), ``lift_off``, ``percolated``,
    the inputs, ``p_a`` [Pa], ``open_inlet``/``open_outlet`` [m] (open lengths of the sealing
    zone), and for non-uniform profiles ``converged`` and ``error_estimate`` (the solver's
    estimated relative error of the resistance integral), Hertz: ``a``, ``L``, ``p_max`` [m, m, Pa].
    """
    _check_tables(tables)
    alpha_cj = _check_theory_for(tables, theory, alpha_cj, a_perc)
    kind, p0x, xarr = _profile_kind(profile, x)
    com = _common_inputs(dp, L_y, E_star, eta, p_b)
    sc = seal_context(tables, theory)
    if kind == "uniform":
        _require(kind, p0=p0, L=L)
        if R is not None or f_N is not None:
            raise ValueError(f"{'R' if R is not None else 'f_N'} = {R if R is not None else f_N!r} "
                             f"is invalid with profile = 'uniform': R and f_N define the Hertz "
                             f"profile (profile='hertz')")
        df, shape = _leak_uniform(tables, sc, theory, p0, L, com["dp"], com["L_y"],
                                  com["E_star"], com["eta"], com["p_b"], alpha_cj)
    elif kind == "hertz":
        _forbid(kind, p0=p0, L=L)
        _require(kind, R=R, f_N=f_N)
        df, shape = _leak_hertz(tables, sc, theory, R, f_N, com["dp"], com["L_y"], com["E_star"],
                                com["eta"], com["p_b"], alpha_cj, _solver_opts(solver))
    else:
        _forbid("array", p0=p0, L=L, R=R, f_N=f_N)
        df, shape = _leak_array(tables, sc, theory, p0x, xarr, com["dp"], com["L_y"],
                                com["E_star"], com["eta"], com["p_b"], alpha_cj,
                                _solver_opts(solver))
    df.attrs["shape"] = tuple(shape)
    df.attrs["theory"] = theory
    df.attrs["profile"] = kind
    df.attrs["units"] = {"Q": "m^3/s", "p0": "Pa", "dp": "Pa", "p_a": "Pa", "p_b": "Pa",
                         "L": "m", "L_y": "m", "E_star": "Pa", "eta": "Pa s", "R": "m",
                         "f_N": "N/m", "a": "m", "p_max": "Pa", "open_inlet": "m",
                         "open_outlet": "m"}
    return df


# =========================================================================== one profile
def _scalar(name, v):
    a = np.asarray(v, dtype=np.float64)
    if a.ndim != 0 and a.size != 1:
        raise ValueError(f"{name} = array(shape={a.shape}) is invalid: seal_profile takes one "
                         f"case (scalars); use seal_leak for many")
    return float(a.ravel()[0]) if a.ndim else float(a)


def seal_profile(tables, *, p0=None, dp, L=None, L_y, E_star, eta, theory="critical_junction",
                 alpha_cj=1.0, p_b=0.0, profile="uniform", R=None, f_N=None, x=None,
                 a_perc=None, n=201, solver=None):
    """Profiles across the seal width of one case: p_cont(x), p_fluid(x), ū(x), σ_eff(x).

    Same arguments as :func:`seal_leak` (scalars only) plus ``n``, the number of output points,
    uniformly spaced on [0, L] (inlet at x = 0; an array profile's own x[0] is kept).

    Returns a DataFrame with ``x`` [m], ``p0`` [Pa] (nominal), ``p_cont`` [Pa], ``p_fluid`` [Pa],
    ``u`` [m] (mean separation), ``sigma_eff`` [m³/(Pa·s)], ``open`` (the surfaces are separated
    there: p_cont = 0, u = σ_eff = inf — a fluid-filled gap the soft-seal model does not size)
    and ``trapped`` (percolated band: fluid isolated, its pressure undetermined → NaN).
    ``df.attrs`` holds ``Q`` [m³/s], ``lift_off``, ``percolated``, ``x_s``/``x_e`` (sealing zone).
    """
    _check_tables(tables)
    alpha = _scalar("alpha_cj", _check_theory_for(tables, theory, alpha_cj, a_perc))
    kind, p0x, xarr = _profile_kind(profile, x)
    com = {k: _scalar(k, v) for k, v in _common_inputs(dp, L_y, E_star, eta, p_b).items()}
    n = int(check_range("n", n, 2, 1e7, "[-] (output points)"))
    sc = seal_context(tables, theory)
    leak = seal_leak(tables, p0=p0, dp=com["dp"], L=L, L_y=com["L_y"], E_star=com["E_star"],
                     eta=com["eta"], theory=theory, alpha_cj=alpha, p_b=com["p_b"],
                     profile=profile, R=R, f_N=f_N, x=x, a_perc=a_perc, solver=solver)
    row = leak.iloc[0]
    E, eta_, dpv, pb = com["E_star"], com["eta"], com["dp"], com["p_b"]
    pa = pb + dpv
    scale = float(_alpha_scale(sc, theory, np.array([alpha]))[0])
    o = _solver_opts(solver)
    if kind == "uniform":
        p0v = _scalar("p0", p0)
        Lv = _scalar("L", L)
        xo = np.linspace(0.0, Lv, n)
        p0o = np.full(n, p0v)
        pf = _uniform_fluid(sc, p0v, pa, pb, dpv, E, xo / Lv, bool(row.lift_off),
                            bool(row.percolated))
        x_s, x_e = (0.0, Lv) if p0v >= pa else (Lv, Lv)
    else:
        if kind == "hertz":
            a, pH = (float(v) for v in hertz_contact(_scalar("R", R), _scalar("f_N", f_N), E))
            Lv = 2 * a
            xo = np.linspace(0.0, Lv, n)
            with np.errstate(invalid="ignore"):
                p0o = pH * np.sqrt(np.clip(1.0 - (xo / a - 1.0) ** 2, 0.0, 1.0))
            geo = ("hertz", a, pH)
        else:
            Lv = float(xarr[-1] - xarr[0])
            xo = np.linspace(xarr[0], xarr[-1], n)
            p0o = np.interp(xo, xarr, p0x)
            geo = ("array", xarr, p0x)
        pf, x_s, x_e = _general_fluid(sc, geo, pa, pb, dpv, E, xo, row, o)
    with np.errstate(invalid="ignore"):
        open_ = np.isfinite(pf) & (p0o - pf <= 0.0)
        pc = np.where(open_, 0.0, p0o - pf)
    trapped = np.isnan(pf)
    from . import _kernels as sk

    cred = np.ascontiguousarray(np.where(trapped, 1.0, pc / E))
    sig = np.empty(n)
    ub = np.empty(n)
    sk.sigma_c_kernel(sc.ctx, cred, sig, 0, n)
    sk.ubar_c_kernel(sc.ctx, cred, ub, 0, n)
    sig = np.where(trapped, np.nan, sig * scale * sc.h_rms ** 3 / (12.0 * eta_))
    u = np.where(trapped, np.nan, ub * sc.h_rms)
    pc = np.where(trapped, np.nan, pc)
    df = pd.DataFrame({"x": xo, "p0": p0o, "p_cont": pc, "p_fluid": pf, "u": u,
                       "sigma_eff": sig, "open": open_ & ~trapped, "trapped": trapped})
    df.attrs.update({"Q": float(row.Q), "lift_off": bool(row.lift_off),
                     "percolated": bool(row.percolated), "x_s": float(x_s), "x_e": float(x_e),
                     "theory": theory, "profile": kind,
                     "units": {"x": "m", "p0": "Pa", "p_cont": "Pa", "p_fluid": "Pa", "u": "m",
                               "sigma_eff": "m^3/(Pa s)", "Q": "m^3/s"}})
    return df


def _uniform_fluid(sc, p0, pa, pb, dp, E, frac_x, lift_off, percolated):
    """p_f at fractions x/L of a flat ring (inverting the primitive)."""
    from . import _kernels as sk

    n = frac_x.size
    if pa > p0:                       # open everywhere: the fluid stands at p_a up to the outlet
        pf = np.full(n, pa)
        pf[-1] = pb
        return pf
    if percolated:                    # blocked at the outlet edge (zero-width barrier)
        pf = np.full(n, pa)
        pf[frac_x >= 1.0] = pb
        return pf
    if dp == 0.0:
        return np.full(n, pa)
    lo = (p0 - pa) / E
    hi = (p0 - pb) / E
    ta = math.log(lo) if lo > 0 else -math.inf
    tb = math.log(hi)
    total = sk.integral_sigma(sc.ctx, sc.S, sc.sp, ta, tb, sc.glx, sc.glw)
    pf = np.empty(n)
    for i, f in enumerate(frac_x):
        if f <= 0.0:
            pf[i] = pa
        elif f >= 1.0:
            pf[i] = pb
        else:
            # fraction f of the flow resistance lies in [0, x]: ∫_{c_lo}^{c(x)} σ̄ = f · total
            pf[i] = p0 - E * math.exp(sk.invert_uniform(sc.ctx, sc.S, sc.sp, sc.glx, sc.glw, ta,
                                                        tb, f, total))
    return pf


def _general_fluid(sc, geo, pa, pb, dp, E, xo, row, o):
    """p_f at the output positions for a Hertz or array profile (solving once more)."""
    from . import _kernels as sk

    n_out = xo.size
    if bool(np.isinf(row.Q)):
        pf = np.full(n_out, pa)
        pf[-1] = pb
        return pf, xo[-1], xo[-1]
    if geo[0] == "hertz":
        a, pH = geo[1], geo[2]
        p0_at = lambda xx: pH * np.sqrt(np.clip(1.0 - (xx / a - 1.0) ** 2, 0.0, 1.0))  # noqa: E731
        x0, x1 = 0.0, 2 * a
    else:
        xarr, p0x = geo[1], geo[2]
        p0_at = lambda xx: np.interp(xx, xarr, p0x)  # noqa: E731
        x0, x1 = xarr[0], xarr[-1]
    if bool(row.percolated):
        pc_perc = sc.p_perc * E
        fine = np.linspace(x0, x1, 20001) if geo[0] == "hertz" else np.union1d(geo[1], xo)
        p0f = p0_at(fine)
        i1 = np.flatnonzero(p0f - pa >= pc_perc)
        i2 = np.flatnonzero(p0f - pb >= pc_perc)
        xb1 = fine[i1[0]] if i1.size else x1
        xb2 = fine[i2[-1]] if i2.size else x1
        pf = np.where(xo < xb1, pa, np.where(xo > xb2, pb, np.nan))
        if not i1.size and not i2.size:
            pf[-1] = pb
        return pf, xb1, xb2
    x_s, x_e = row.open_inlet + x0, x1 - row.open_outlet
    if dp == 0.0:
        pf = np.full(n_out, pa)
        return pf, x_s, x_e
    n = int(o["nodes"])
    z, w, At, Lp = _gl(n)
    PMAX = int(o["max_panels"])
    if pa == (pH if geo[0] == "hertz" else float(np.max(p0x))):
        o = dict(o, tol=min(o["tol"], EQUALITY_TOL))
        PMAX = max(PMAX, 256)
    o = dict(o, max_panels=PMAX)
    if geo[0] == "hertz":
        base = np.array([pH / E])
        xg = pg = np.zeros(2)
        kind = 0
        ell = a
        W, st, P, est, _, _, pan, rr = _solve_rows(sc, 0, xg, pg, base, np.array([pa / E]),
                                                    np.array([pb / E]), o, keep=True)
    else:
        L = x1 - x0
        xg = np.ascontiguousarray((xarr - x0) / L)
        pg = np.ascontiguousarray(p0x / E)
        base = pg
        kind = 1
        ell = L
        W, st, P, est, _, _, pan, rr = _solve_rows(sc, 1, xg, p0x, np.array([1.0 / E]),
                                                    np.array([pa / E]), np.array([pb / E]), o,
                                                    keep=True)
    W, P = float(W[0]), int(P[0])
    gp = np.empty(3)
    sk._zone_params(kind, base, xg, pg, pa / E, pb / E, gp)
    frac = np.empty(n_out)
    sk.remaining_at(kind, gp, xo, x0, ell, int(o["grading"]), pan, P, n, rr, W, Lp, frac)
    pf = pb + dp * frac
    pf = np.where(xo <= x_s, pa, np.where(xo >= x_e, pb, pf))
    return pf, x_s, x_e


# =========================================================================== stiff seals
def _hertz_gap(xi):
    """Hertz line-contact gap outside the contact in units of a²/(2R), ξ = |x|/a >= 1."""
    s = np.sqrt(np.maximum(xi * xi - 1.0, 0.0))
    return xi * s - np.log(xi + s)


def _log_kernel(x, d):
    """K[i, j] = ∫_{panel j} ln|x_i − x'| dx' for panels of width d centred at x (exact)."""
    def G(s):
        a = np.abs(s)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(a > 0, s * np.log(a) - s, 0.0)
    dx = x[:, None] - x[None, :]
    return G(dx + 0.5 * d) - G(dx - 0.5 * d)


def seal_elastic(tables, *, R, f_N, dp, L_y, E_star, eta, theory="critical_junction",
                 alpha_cj=1.0, p_b=0.0, a_perc=None, n=400, gap=40.0, x_extent=None,
                 steps=None, tol=1e-10, max_iter=80):
    """Stiff seal (paper eq. 30): the macroscopic elastic deformation responds to contact and
    fluid pressure. One case (scalars), cylinder of radius ``R`` [m] pressed with ``f_N`` [N/m].

    Unknowns on ``n`` piecewise-constant pressure panels over x ∈ [−X, X] (x from the cylinder
    axis; fluid inlet at −X with p_a = p_b + dp, outlet at +X with p_b), solved together:

    * ū(x) = u_c + x²/(2R) − (2/(πE*)) ∫ p0(x') ln|x − x'| dx'    (eq. 30; its ln|x'| term is
      a constant and is absorbed in u_c) — exact panel integrals of the log kernel;
    * p_cont(x) = p_cont(ū(x)) from the tables (the rough-contact law; asymptote beyond them);
    * p_f(x) from the flow, eq. (27): p_f = p_a − dp s(x)/s(X), s = ∫ dx/σ_eff(p_cont);
    * p0 = p_cont + p_f (eq. 28) and ∫ p0 dx = f_N (eq. 29, per unit length).

    Newton on (ū at the panel centres, u_c) with a dense Jacobian and backtracking, started
    from the dry Hertz solution and continued in dp. The domain half-width X is where the dry
    Hertz gap reaches ``gap``·h_rms (at most 3a), unless ``x_extent`` [m] is given: the fluid
    pressure loads the interface only inside [−X, X] (beyond it the surfaces are far apart and
    the fluid acts on the free surface, not modelled). Percolated contact (σ_eff = 0 on a
    panel) stops the flow: Q = 0, p_f = p_a upstream and p_b downstream of the blocked panels,
    and the trapped fluid in them is taken at p_b (an assumption: its pressure is undetermined).

    Returns a DataFrame per panel: ``x`` [m] from the inlet, ``x_center`` [m] from the axis,
    ``p0``, ``p_cont``, ``p_fluid``, ``p_hertz`` (dry Hertz, for comparison) [Pa], ``u`` [m],
    ``sigma_eff`` [m³/(Pa·s)]; ``df.attrs``: ``Q`` [m³/s], ``u_c`` [m], ``converged``,
    ``iterations``, ``percolated``, ``lift_off`` (the contact carries < 0.1 % of f_N at some
    continuation step, or Newton fails right after a step where it carried < 5 %: Q = inf and
    the profiles are those of the last converged step), ``dp_reached`` (the dp of the profiles),
    ``contact_load_fraction``, ``X``, ``a``, ``p_hertz_max``.
    """
    from . import _kernels as sk

    _check_tables(tables)
    alpha = _scalar("alpha_cj", _check_theory_for(tables, theory, alpha_cj, a_perc))
    com = {k: _scalar(k, v) for k, v in _common_inputs(dp, L_y, E_star, eta, p_b).items()}
    Rv = _scalar("R", check_positive("R", R, "[m]"))
    fN = _scalar("f_N", check_positive("f_N", f_N, "[N/m]"))
    n = int(check_range("n", n, 8, 5000, "[-] (panels)"))
    gap = float(check_positive("gap", gap, "[-] (multiples of h_rms)"))
    E, eta_, dpv, pb = com["E_star"], com["eta"], com["dp"], com["p_b"]
    sc = seal_context(tables, theory)
    h = sc.h_rms
    a, pH = (float(v) for v in hertz_contact(Rv, fN, E))
    if x_extent is None:
        target = gap * h / (a * a / (2 * Rv))
        if _hertz_gap(3.0) <= target:
            X = 3.0 * a
        else:
            from scipy.optimize import brentq
            X = a * brentq(lambda z: _hertz_gap(z) - target, 1.0, 3.0, xtol=1e-14)
    else:
        X = float(_scalar("x_extent", check_positive("x_extent", x_extent, "[m]")))
    d = 2 * X / n
    xc = -X + d * (np.arange(n) + 0.5)
    K = _log_kernel(xc, d)
    Ke = (2.0 / (math.pi * E * h)) * K            # (per h_rms) displacement per Pa
    xq = xc * xc / (2 * Rv * h)
    phz = pH * np.sqrt(np.clip(1.0 - (xc / a) ** 2, 0.0, 1.0))
    scale = float(_alpha_scale(sc, theory, np.array([alpha]))[0])
    lnp = np.empty(n)
    dlnp = np.empty(n)
    sg = np.empty(n)
    dls = np.empty(n)

    M = np.tril(np.ones((n, n)), -1) + 0.5 * np.eye(n)   # cumulative midpoint rule
    KeM = Ke @ M                                          # once: the flow part is rank-structured

    def state(v, dpk):
        sk.contact_of_u(sc.ctx, np.ascontiguousarray(v), lnp, dlnp, sg, dls)
        if not np.all(np.isfinite(lnp)):
            return None
        pc = E * np.exp(lnp)
        blocked = ~(sg > 0)
        J = np.empty((n + 1, n + 1))
        if blocked.any():
            i1 = np.flatnonzero(blocked)[0]
            pf = np.full(n, pb)
            pf[:i1] = pb + dpk
            W = np.inf
            colsum = pc * dlnp
            J[:n, :n] = np.eye(n) + Ke * colsum[None, :]
        else:
            rho = d / sg
            S = np.cumsum(rho) - 0.5 * rho
            W = rho.sum()
            pf = (pb + dpk) - dpk * S / W
            drho = -rho * dls * dlnp                 # ∂ρ_k/∂v_k
            # ∂p_f/∂v = −dp (M/W − S 1ᵀ/W²) diag(∂ρ/∂v)
            KS = Ke @ S
            J[:n, :n] = (np.eye(n) + Ke * (pc * dlnp)[None, :]
                         - dpk * (KeM / W - KS[:, None] / W ** 2) * drho[None, :])
            colsum = pc * dlnp - dpk * (M.sum(axis=0) / W - S.sum() / W ** 2) * drho
        p0 = pc + pf
        G = np.empty(n + 1)
        G[:n] = v - v_c[0] - xq + Ke @ p0
        G[n] = (d * p0.sum() - fN) / fN * 10.0
        J[:n, n] = -1.0
        J[n, :n] = d * colsum / fN * 10.0
        J[n, n] = 0.0
        return G, J, pc, pf, p0, W, blocked.any()

    # dry Hertz start: rough-contact separation at the Hertz pressure plus the Hertz gap
    pg = np.maximum(phz, 1e-4 * pH)
    v = np.asarray(tables.mean_separation(pg, E), dtype=float).reshape(n) / h
    out_ = np.abs(xc) > a
    v[out_] += _hertz_gap(np.abs(xc[out_]) / a) * a * a / (2 * Rv * h)
    v_c = np.zeros(1)
    sk.contact_of_u(sc.ctx, np.ascontiguousarray(v), lnp, dlnp, sg, dls)
    p0g = E * np.exp(lnp) + pb
    v_c[0] = float(np.mean(v - xq + Ke @ p0g))
    if steps is not None:
        nsteps = int(steps)
    else:
        nsteps = 1 if dpv == 0 else max(2, int(math.ceil(6 * dpv / pH)))
    its = 0
    converged = True
    lifted = False
    st = None
    for k in (range(1, nsteps + 1) if dpv > 0 else [0]):
        dpk = dpv * k / nsteps if dpv > 0 else 0.0
        prev = (v.copy(), v_c[0], st)
        st = state(v, dpk)
        if st is None:
            converged = False
            break
        ok = False
        for it in range(max_iter):
            G, J, pc, pf, p0, W, perc = st
            gn = np.max(np.abs(G))
            if gn < tol * max(1.0, np.max(np.abs(v))):
                ok = True
                break
            its += 1
            try:
                delta = np.linalg.solve(J, -G)
            except np.linalg.LinAlgError:
                break
            lam = 1.0
            acc = False
            while lam > 1e-6:
                vt = v + lam * delta[:n]
                if np.all(vt > 0):
                    vc0 = v_c[0]
                    v_c[0] = vc0 + lam * delta[n]
                    stt = state(vt, dpk)
                    if stt is not None and np.max(np.abs(stt[0])) < (1 - 1e-4 * lam) * gn:
                        v, st, acc = vt, stt, True
                        break
                    v_c[0] = vc0
                lam *= 0.5
            if not acc:
                ok = gn < 1e3 * tol * max(1.0, np.max(np.abs(v)))
                break
        if not ok:
            # a failure right after a step that left the contact nearly unloaded is lift-off
            if prev[2] is not None and d * prev[2][2].sum() / fN < 0.05:
                v, v_c[0], st = prev[0], prev[1], prev[2]
                lifted = True
            else:
                converged = False
            break
        if d * st[2].sum() / fN < 1e-3:          # the contact carries nothing: lifted off
            lifted = True
            break
    G, J, pc, pf, p0, W, perc = st
    frac = float(d * pc.sum() / fN)
    lift = bool(lifted or (converged and frac < 1e-3))
    if perc:
        Q = 0.0
    elif lift:
        Q = math.inf                       # the contact no longer carries the load: open
    else:
        Q = com["L_y"] * dpv * h ** 3 / (12.0 * eta_ * W) * scale
    sig = sg * scale * h ** 3 / (12.0 * eta_)
    df = pd.DataFrame({"x": xc + X, "x_center": xc, "p0": p0, "p_cont": pc, "p_fluid": pf,
                       "p_hertz": phz, "u": v * h, "sigma_eff": sig})
    df.attrs.update({"Q": float(Q) if (converged or lift) else math.nan, "u_c": float(v_c[0] * h),
                     "converged": bool(converged), "iterations": its, "percolated": bool(perc),
                     "lift_off": lift,
                     "contact_load_fraction": frac, "X": X, "a": a, "p_hertz_max": pH,
                     "dp_reached": float(pf[0] - pb) if np.isfinite(pf[0]) else math.nan,
                     "theory": theory, "profile": "elastic",
                     "units": {"x": "m", "x_center": "m", "p0": "Pa", "p_cont": "Pa",
                               "p_fluid": "Pa", "p_hertz": "Pa", "u": "m",
                               "sigma_eff": "m^3/(Pa s)", "Q": "m^3/s", "u_c": "m"}})
    return df
