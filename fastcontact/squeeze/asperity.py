"""Asperity-scale squeeze-out at magnification ζ and the simplest cascade over ζ (paper, end of
Sec. 3; derivation and choices in docs/theory/extensions.md §1).

At magnification ζ the apparent contact consists of asperity contact regions; the paper
applies the squeeze-out theory to one such region with

* the local squeezing pressure p(ζ) = p0 A0/A(ζ)            (A1 of the full spectrum),
* the roughness restricted to q >= ζ q0                       (:meth:`PSD.restricted`),
* a region radius R(ζ) — not given by the paper. Choice made here (``region="half_wavelength"``):
  the regions seen at ζ are the contact patches of the shortest resolved roughness, of
  wavelength λ(ζ) = 2π/(ζq0); a patch cannot be wider than the crest half of that wavelength,
  so its diameter is λ(ζ)/2 and R(ζ) = π/(2ζq0) (Persson's picture of the contact regions
  at magnification ζ as asperities of size ~λ/2; B.N.J. Persson, Surf. Sci. Rep. 61, 201
  (2006), doi:10.1016/j.surfrep.2006.04.001). Any other rule can be passed as a function;
  t* ∝ R², so a factor 2 in R is a factor 4 in every level's time.

Level ζ = 1 is the macroscopic block (radius ``R``), i.e. exactly the base squeeze-out.
Trapping: fluid is sealed off in the asperity regions of level ζ when the restricted
contact percolates at p(ζ): A_ζ(ζ1)/A_ζ(ζ) >= the percolation area fraction of the flow
theory *as the level's tables record it* (:meth:`Tables.percolation_area`:
``options["a_perc"]`` for the critical junction, ``options["emt_threshold"]`` — 0.5 unless a
calibration set it — for the effective medium, never for "average"), or the squeeze
engine's trap criterion triggers; the first such ζ is ``zeta_trap``. Given ``tables`` (the
full surface's), every level's tables are built with *their* options (γ, a_perc, α_cj,
emt_threshold, ...), so a calibration carries through the cascade.

Cascade (the paper leaves it undeveloped): the fluid around a region of level ζ_k is at
the external pressure only once level ζ_{k-1} has drained. Levels are octaves,
ζ_k = r^k (``level_ratio`` r = 2: a new set of regions each time the resolved wavelength
halves). Two bounds on the time to drain every level up to ζ_K are reported:
``t_sequential`` = Σ_k t*(ζ_k) (each level starts when the level below has drained — the
simplest consistent cascade) and ``t_parallel`` = max_k t*(ζ_k) (all levels start at
once at the external pressure, the paper's independent-level picture); the truth lies in
between. Both are +inf from the first trapped level on.
"""
from __future__ import annotations

import math
import threading
from collections import OrderedDict

import numpy as np
import pandas as pd
from scipy.special import erf

from .._core.validate import check_positive
from ..contact import area_fraction
from ..tables import Tables, precompute
from . import squeeze_out

__all__ = ["TIRE_CASE", "LEVEL_OPTIONS", "asperity_levels", "asperity_summary",
           "region_radius"]

#: the paper's Sec. 5 tread block: R = 2 cm, p0 = 0.2 MPa, E = 10 MPa (ν = 0.5), water
TIRE_CASE = dict(R=0.02, p0=0.2e6, E_star=10e6 / 0.75, eta=1e-3)
#: the table options a level inherits from the full surface's tables
LEVEL_OPTIONS = ("gamma", "a_perc", "alpha_cj", "emt_tol", "emt_almqvist", "emt_threshold")
#: level tables kept in memory (they depend on the surface, ζ and options, not on the case)
_LEVEL_CACHE_SIZE = 64
_LEVEL_CACHE: "OrderedDict" = OrderedDict()
_LEVEL_LOCK = threading.Lock()


def _level_tables(sub, theory, kwargs):
    """precompute(sub, (theory,), **kwargs), memoised on the restricted surface and options."""
    key = (sub.fingerprint(), theory, repr(sorted(kwargs.items())))
    with _LEVEL_LOCK:
        if key in _LEVEL_CACHE:
            _LEVEL_CACHE.move_to_end(key)
            return _LEVEL_CACHE[key]
    tabs = precompute(sub, theories=(theory,), **kwargs)
    with _LEVEL_LOCK:
        _LEVEL_CACHE[key] = tabs
        while len(_LEVEL_CACHE) > _LEVEL_CACHE_SIZE:
            _LEVEL_CACHE.popitem(last=False)
    return tabs


def _surface_and_options(psd, tables, theory, tables_kwargs):
    """(psd, base tables or None, precompute kwargs of the levels) of the arguments."""
    if tables is not None:
        if not isinstance(tables, Tables):
            raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables")
        tables._need(theory)
        if psd is None:
            psd = tables.surface
        else:
            tables.check_surface(psd, "psd")
        kw = {k: tables.options[k] for k in LEVEL_OPTIONS if k in tables.options}
    elif psd is None:
        raise ValueError("psd = None is invalid without tables: give the surface's PSD or its "
                         "Tables")
    else:
        kw = {}
    kw.update(tables_kwargs or {})
    return psd, kw


def region_radius(zeta, q0):
    """Radius [m] of an asperity contact region at magnification ζ: R(ζ) = π/(2 ζ q0)."""
    return math.pi / (2.0 * np.asarray(zeta, dtype=np.float64) * q0)


def _levels(psd, level_ratio, zeta_max):
    zmax = min(zeta_max if zeta_max is not None else psd.zeta1 / 10.0, psd.zeta1 / 10.0)
    n = int(math.floor(math.log(zmax) / math.log(level_ratio) + 1e-9)) + 1
    return level_ratio ** np.arange(max(n, 1))


def _check_levels(psd, level_ratio, zetas, zeta_max):
    lr = float(check_positive("level_ratio", level_ratio, "[-]"))
    if not lr > 1.0:
        raise ValueError(f"level_ratio = {level_ratio!r} is invalid: must be > 1 [-]")
    zs = _levels(psd, lr, zeta_max) if zetas is None else np.asarray(zetas, dtype=np.float64)
    if zs[0] != 1.0 or np.any(np.diff(zs) <= 0) or zs[-1] >= psd.zeta1:
        raise ValueError(f"zetas = {zs.tolist()!r} is invalid: must ascend from 1 and stay "
                         f"below ζ1 = {psd.zeta1:g}")
    return lr, zs


def _level_results(psd, base, kw, z, p0, E_star, R, eta, theory, region, ratios):
    """Columns of level ζ = z for the cases (arrays p0, E_star, R, eta)."""
    area = np.asarray(area_fraction(psd, p0, E_star, z), dtype=np.float64) if z > 1.0 \
        else np.ones(p0.size)
    pz = p0 / area
    sub = psd if z == 1.0 else psd.restricted(z * psd.q0)
    Rz = R if z == 1.0 else np.full(p0.size, float(region(z, psd.q0)))
    G1 = psd.moment(3.0, psd.q0, psd.q1)
    Gr = G1 - float(psd.moment(3.0, psd.q0, z * psd.q0))          # restricted G/(π E*²/4)
    with np.errstate(over="ignore"):
        a_r = erf(pz / (E_star * 2.0 * math.sqrt(0.25 * math.pi * Gr)))
    tabs = base if (z == 1.0 and base is not None) else _level_tables(sub, theory, kw)
    df = squeeze_out(tabs, p0=pz, E_star=E_star, R=Rz, eta=eta, theory=theory,
                     ratios=tuple(ratios))
    a_thr = tabs.percolation_area(theory)
    return {"zeta": np.full(p0.size, z), "q_min": np.full(p0.size, z * psd.q0),
            "area_fraction": area, "p_zeta": pz, "R_zeta": np.asarray(Rz, dtype=np.float64),
            "h_rms_zeta": np.full(p0.size, sub.h_rms), "area_restricted": a_r,
            "area_threshold": np.full(p0.size, a_thr),
            "trapped": (a_r >= a_thr) | df["trapped"].to_numpy(bool), "frame": df}


def _level_row(res):
    """One row of :func:`asperity_levels` from the single-case columns of
    :func:`_level_results` (its squeeze-out frame's times [s] and separations [m] included)."""
    r = res.pop("frame").iloc[0]
    row = {k: (bool(v[0]) if k == "trapped" else float(v[0])) for k, v in res.items()}
    row.update({"u_inf": r["u_inf"], "u_start": r["u_start"], "t_star": r["t_star"]})
    for c in r.index:
        if c.startswith("t_ratio_"):
            row[c] = r[c]
    row.update({"t_relax": r["t_relax"], "out_of_table": bool(r["out_of_table"])})
    return row


def _level_units(columns):
    """Units of the :func:`asperity_levels` columns (every ``t_*`` column in s)."""
    units = {"zeta": "1", "q_min": "1/m", "area_fraction": "1", "p_zeta": "Pa", "R_zeta": "m",
             "h_rms_zeta": "m", "area_restricted": "1", "area_threshold": "1", "u_inf": "m",
             "u_start": "m"}
    units.update({c: "s" for c in columns if c.startswith("t_")})
    return units


def asperity_levels(psd=None, *, p0, E_star, R, eta, theory="emt", level_ratio=2.0,
                    zetas=None, zeta_max=None, region=None, ratios=(1.1,), tables_kwargs=None,
                    tables=None):
    """Squeeze-out of the asperity contact regions at each magnification level ζ, and the
    cascade totals (module docstring).

    Parameters
    ----------
    psd : PSD, optional
        Full roughness spectrum of the substrate (Persson convention); optional if
        ``tables`` is given.
    p0 : float
        Nominal squeezing pressure of the block [Pa].
    E_star : float
        Effective modulus [Pa].
    R : float
        Block radius [m] (level ζ = 1).
    eta : float
        Fluid viscosity [Pa·s].
    theory : str
        Flow theory of every level ("emt", "critical_junction" or "average").
    level_ratio : float
        Ratio of successive levels ζ_{k+1}/ζ_k (> 1; default 2, octaves).
    zetas : array_like, optional
        Explicit levels (ascending, first = 1); overrides ``level_ratio``.
    zeta_max : float, optional
        Highest level (default and maximum ζ1/10: the restricted spectrum keeps a decade).
    region : callable, optional
        ``region(zeta, q0) -> R(ζ) [m]`` for ζ > 1 (default :func:`region_radius`).
    ratios : sequence
        Extra targets ū/ū∞ passed to :func:`squeeze_out`.
    tables_kwargs : dict, optional
        Extra arguments of :func:`~fastcontact.tables.precompute` for each level (they
        override the options taken from ``tables``).
    tables : Tables, optional
        The full surface's tables: level ζ = 1 runs on them, and every level inherits their
        options (:data:`LEVEL_OPTIONS`: γ, a_perc, α_cj, emt_threshold, ...), hence their
        percolation thresholds.

    Returns
    -------
    pandas.DataFrame
        One row per level: ``zeta``, ``q_min`` [1/m], ``area_fraction`` A(ζ)/A0,
        ``p_zeta`` [Pa], ``R_zeta`` [m], ``h_rms_zeta`` [m], ``area_restricted`` (the
        restricted contact's A(ζ1)/A(ζ) at p(ζ)), ``area_threshold`` (its percolation value
        from the level's tables), ``trapped``, ``u_inf``, ``u_start`` [m], ``t_star`` [s]
        and ``t_ratio_<r>`` [s], ``t_relax`` [s], ``t_sequential``, ``t_parallel`` [s],
        ``out_of_table``; ``attrs["zeta_trap"]`` the first trapped level (inf: none).
    """
    psd, kw = _surface_and_options(psd, tables, theory, tables_kwargs)
    p0 = float(check_positive("p0", p0, "[Pa]"))
    E_star = float(check_positive("E_star", E_star, "[Pa]"))
    R = float(check_positive("R", R, "[m]"))
    eta = float(check_positive("eta", eta, "[Pa·s]"))
    lr, zs = _check_levels(psd, level_ratio, zetas, zeta_max)
    region = region_radius if region is None else region
    rows = []
    for z in zs:
        rows.append(_level_row(_level_results(
            psd, tables, kw, float(z), np.array([p0]), np.array([E_star]), np.array([R]),
            np.array([eta]), theory, region, ratios)))
    out = pd.DataFrame(rows)
    t = np.where(out["trapped"], np.inf, out["t_star"].to_numpy(dtype=float))
    out["t_sequential"] = np.cumsum(t)
    out["t_parallel"] = np.maximum.accumulate(t)
    trapped = out["zeta"][out["trapped"]]
    out.attrs.update({"units": _level_units(out.columns), "theory": theory, "level_ratio": lr,
                      "zeta_trap": float(trapped.iloc[0]) if trapped.size else math.inf,
                      "region_rule": getattr(region, "__name__", repr(region)),
                      "level_options": dict(kw),
                      "references": ["arXiv:1004.1037",
                                     "doi:10.1016/j.surfrep.2006.04.001"]})
    return out


#: columns of :func:`asperity_summary` and their units
SUMMARY_UNITS = {"n_levels": "1", "zeta_top": "1", "zeta_trap": "1", "t_star_base": "s",
                 "t_star_top": "s", "t_sequential": "s", "t_parallel": "s",
                 "t_sequential_open": "s", "t_parallel_open": "s", "out_of_table": "bool"}


def asperity_summary(tables, *, p0, E_star, R, eta, theory="emt", level_ratio=2.0,
                     zeta_max=None, region=None):
    """The cascade of :func:`asperity_levels` for many cases at once, one row per case.

    The levels ζ_k = r^k depend on the surface only, so each level's tables are built once
    (and memoised) and every level runs one vectorised :func:`squeeze_out` over the cases.

    Parameters
    ----------
    tables : Tables
        The full surface's tables (level ζ = 1; the levels inherit their options).
    p0, E_star, R, eta : array_like
        Nominal pressure [Pa], effective modulus [Pa], block radius [m], viscosity [Pa·s];
        broadcast against each other.
    theory, level_ratio, zeta_max, region :
        As :func:`asperity_levels`.

    Returns
    -------
    pandas.DataFrame
        ``n_levels``, ``zeta_top`` (highest level) and ``zeta_trap`` (first trapped level, inf:
        none) [-]; ``t_star_base`` (ζ = 1) and ``t_star_top`` [s]; the cascade totals over
        all levels ``t_sequential``, ``t_parallel`` [s] (inf if any level traps) and over
        the levels below ``zeta_trap`` ``t_sequential_open``, ``t_parallel_open`` [s];
        ``out_of_table`` (some level's pressure beyond its tables: NaN times).
    """
    psd, kw = _surface_and_options(None, tables, theory, None)
    arrs = [check_positive(n, v, u) for n, v, u in (("p0", p0, "[Pa]"), ("E_star", E_star, "[Pa]"),
                                                  ("R", R, "[m]"), ("eta", eta, "[Pa·s]"))]
    shape = np.broadcast(*arrs).shape
    p0, E_star, R, eta = (np.ascontiguousarray(np.broadcast_to(a, shape).ravel(),
                                               dtype=np.float64) for a in arrs)
    n = p0.size
    _, zs = _check_levels(psd, level_ratio, None, zeta_max)
    region = region_radius if region is None else region
    t_seq = np.zeros(n)
    t_par = np.zeros(n)
    open_seq = np.zeros(n)
    open_par = np.zeros(n)
    z_trap = np.full(n, math.inf)
    oot = np.zeros(n, dtype=bool)
    t_base = t_top = None
    for z in zs:
        res = _level_results(psd, tables, kw, float(z), p0, E_star, R, eta, theory, region, ())
        df = res["frame"]
        t = df["t_star"].to_numpy(dtype=float)
        oot |= df["out_of_table"].to_numpy(bool)
        trapped = res["trapped"]
        tt = np.where(trapped, np.inf, t)
        t_seq += tt
        t_par = np.maximum(t_par, tt)
        still = ~np.isfinite(z_trap) & ~trapped
        open_seq = np.where(still, open_seq + t, open_seq)
        open_par = np.where(still, np.maximum(open_par, t), open_par)
        z_trap = np.where(~np.isfinite(z_trap) & trapped, z, z_trap)
        t_base = t if t_base is None else t_base
        t_top = t
    out = pd.DataFrame({"n_levels": np.full(n, zs.size), "zeta_top": np.full(n, zs[-1]),
                        "zeta_trap": z_trap, "t_star_base": t_base, "t_star_top": t_top,
                        "t_sequential": t_seq, "t_parallel": t_par,
                        "t_sequential_open": open_seq, "t_parallel_open": open_par,
                        "out_of_table": oot})
    out.attrs.update({"units": dict(SUMMARY_UNITS), "theory": theory,
                      "level_ratio": float(level_ratio), "zetas": zs.tolist(),
                      "level_options": dict(kw), "shape": tuple(shape)})
    return out
