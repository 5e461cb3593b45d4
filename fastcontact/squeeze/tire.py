"""Tire tread block crossing a wet-road footprint — paper Sec. 5 (SPEC §5).

A tread block (cylinder of radius R, effective modulus E*) enters the tire–road footprint
(length L_f) at rolling speed v, so it spends ``t_footprint = L_f / v`` in it (0.1 m at
30 m/s → 3.3 ms). It starts with a water film ū(0) = ``u_start`` and squeezes the fluid
(viscosity η, density ρ) out against the road's roughness (a :class:`~fastcontact.tables.Tables`
of the road surface). The hysteresis friction is unaffected only if the film has come within
~1 µm of its equilibrium, Δu = ū - ū∞ ≤ ``du_complete`` (default 1 µm), before the exit;
contaminated water (larger η) can leave the squeeze-out incomplete (viscous hydroplaning).

Pressure along the footprint — the approximation
------------------------------------------------
The nominal pressure varies along the footprint, p0(s) = p0 · f(s/L_f) with f of mean 1
(``"uniform"``: f = 1; ``"parabolic"``: f(x) = 6x(1-x), peak 1.5 p0; or relative values at
equally spaced stations, linearly interpolated and normalised to mean 1). The squeeze-out
ODE (SPEC §4, eqs. 18–19) is solved at a **constant** nominal pressure p_eval for the whole
time in the footprint:

* ``pressure_model = "mean"`` (default): p_eval = footprint mean = p0. Since a block crosses
  the footprint at constant speed, this is the time-averaged load it carries; exact for a
  uniform profile.
* ``pressure_model = "peak"``: p_eval = peak of the profile — the fastest squeeze-out and the
  smallest ū∞ any station sees (a bound, not an average).

The time dependence of the load (loading at the entry, unloading at the exit) is not
resolved; the paper's Sec. 5 uses one constant p0 = 0.2 MPa.

Per case (:func:`tire_footprint`): ``t_footprint``, the times to Δu = du_complete
(``t_du``) and to ū/ū∞ = 1.1, 1.01, 1.001 (``t_ratio_<r>``), ū at exit (``u_exit``),
``du_exit``, ``squeeze_complete`` (Δu at exit ≤ du_complete; never true if fluid is trapped
above ū∞ + du_complete), ``trapped``, ``u_trap``, and beside the viscous result the
inertia-limited estimate of Sec. 5 (no viscosity, flat surfaces, plug flow):
τ' = (D²ρ/(64 p_eval))^{1/2} with D = 2R (``tau_inertia``) and
t*_inertia = τ' ln(ū(0)/h_rms) (``t_star_inertia``).

Default ū(0): 1 cm, the paper's Sec. 5 example (u(0) = 1 cm). It must lie within (or above,
where the squeeze module extends it) the road table's separation range.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .._core.validate import as_float_array, check_positive

__all__ = ["tire_footprint", "tire_history", "tire_columns", "profile_factors",
           "pressure_profile", "PAPER_TIRE"]

#: the paper's Sec. 5 parameters (SI)
PAPER_TIRE = dict(p0=0.2e6, E=10e6, R=0.02, eta=1e-3, rho=1000.0, footprint_length=0.1,
                  speed=30.0, u_start=1e-2)

#: below this many distinct squeeze cases per call the per-case quadrature of squeeze_out
#: (``method="quad"``, ~40 µs/case) beats its spline fast path, whose one-off set-up costs
#: ~2 s per (tables, theory) plus ~0.5 s per Δu target (measured on the embedded tables)
QUAD_BELOW = 50_000


def squeeze_method(n):
    """"quad" for fewer than QUAD_BELOW cases, else "fast" (see QUAD_BELOW)."""
    return "quad" if n < QUAD_BELOW else "fast"


TIRE_BASE = ("p_eval", "p_peak", "t_footprint", "u_start", "u_inf", "t_du")
TIRE_TAIL = ("t_star", "u_exit", "du_exit", "squeeze_complete", "trapped", "u_trap",
             "fluid_load_fraction", "tau_inertia", "t_star_inertia", "out_of_table")


def _ratio_name(r):
    return f"t_ratio_{float(r):.6g}"


def tire_columns(ratios=(1.1, 1.01, 1.001)):
    """Names of the result columns of :func:`tire_footprint` for these ``ratios``."""
    return list(TIRE_BASE) + [_ratio_name(r) for r in ratios] + list(TIRE_TAIL)


def _profile_samples(profile):
    if isinstance(profile, str):
        if profile == "uniform":
            return np.array([0.0, 1.0]), np.array([1.0, 1.0])
        if profile == "parabolic":
            x = np.linspace(0.0, 1.0, 201)
            return x, 6.0 * x * (1.0 - x)
        raise ValueError(f"pressure_profile = {profile!r} is invalid: must be 'uniform', "
                         f"'parabolic' or a sequence of >= 2 relative pressures >= 0")
    r = as_float_array("pressure_profile", profile).ravel()
    if r.size < 2 or not np.all(np.isfinite(r)) or np.any(r < 0) or not r.sum() > 0:
        raise ValueError(f"pressure_profile = {profile!r} is invalid: must be 'uniform', "
                         f"'parabolic' or a sequence of >= 2 finite relative pressures >= 0, "
                         f"not all 0")
    x = np.linspace(0.0, 1.0, r.size)
    mean = float(np.sum(0.5 * (r[1:] + r[:-1]) * np.diff(x)))
    return x, r / mean


def pressure_profile(profile, s_over_L):
    """f(s/L_f): the nominal pressure along the footprint in units of its mean p0."""
    x, f = _profile_samples(profile)
    return np.interp(np.asarray(s_over_L, float), x, f)


def profile_factors(profile):
    """(mean, peak) of f: 1 and the peak-to-mean ratio of the profile."""
    x, f = _profile_samples(profile)
    return 1.0, float(f.max())


def _frame_rows(df, n):
    if len(df) != n:
        raise RuntimeError(f"squeeze_out returned {len(df)} rows for {n} cases")
    return df.reset_index(drop=True)


def _pick(df, prefix, values):
    """Columns of ``df`` starting with ``prefix``, one per requested value, in request order."""
    cols = [c for c in df.columns if c.startswith(prefix)]
    if len(cols) == len(values):
        # verify where the suffix is a number
        for c, v in zip(cols, values):
            try:
                s = float(c[len(prefix):])
            except ValueError:
                continue
            if not math.isclose(s, v, rel_tol=1e-6):
                break
        else:
            return cols
    out = []
    for v in values:
        hit = None
        for c in cols:
            try:
                if math.isclose(float(c[len(prefix):]), v, rel_tol=1e-6):
                    hit = c
                    break
            except ValueError:
                pass
        if hit is None:
            raise RuntimeError(f"squeeze_out returned no column {prefix}{v!r} (columns: {cols})")
        out.append(hit)
    return out


def tire_footprint(tables, *, p0, E_star, R, eta, footprint_length, speed, rho=1000.0,
                   theory="average", pressure_profile="uniform", pressure_model="mean",
                   u_start=PAPER_TIRE["u_start"], du_complete=1e-6, ratios=(1.1, 1.01, 1.001),
                   columns=None):
    """Squeeze-out of a tread block during its passage through the footprint (Sec. 5).

    Parameters (SI; the numeric ones broadcast against each other, one output row each)
    ----------
    tables : Tables            the road surface's tables (must hold ``theory``)
    p0 : mean nominal pressure over the footprint [Pa]
    E_star : effective modulus of the tread rubber [Pa]
    R : tread block radius [m] (D = 2R enters the inertia estimate)
    eta : fluid viscosity [Pa·s] (water 1e-3; contaminated water more)
    footprint_length : L_f [m];  speed : rolling speed v [m/s]
    rho : fluid density [kg/m³] (inertia estimate only)
    theory : flow-conductivity theory ("average" in the paper)
    pressure_profile : "uniform" | "parabolic" | relative pressures at equally spaced stations
    pressure_model : "mean" | "peak" — which constant pressure is used (module docstring)
    u_start : initial film ū(0) [m] (None: the squeeze module's default)
    du_complete : Δu threshold [m] for ``squeeze_complete`` and ``t_du``
    ratios : ū/ū∞ values of the ``t_ratio_<r>`` columns
    columns : names wanted (default all of :func:`tire_columns`); only those are computed

    Returns a DataFrame with the requested columns (see :func:`tire_columns`).
    """
    from . import squeeze_out
    from .reduced import inertia_time_constant

    if pressure_model not in ("mean", "peak"):
        raise ValueError(f"pressure_model = {pressure_model!r} is invalid: must be 'mean' or 'peak'")
    _, peak = profile_factors(pressure_profile)
    du_complete = float(check_positive("du_complete", du_complete, "[m]"))
    ratios = tuple(float(r) for r in ratios)
    for r in ratios:
        if not r > 1.0 or not math.isfinite(r):
            raise ValueError(f"ratios = {ratios!r} is invalid: each must be a finite number > 1")
    allc = tire_columns(ratios)
    if columns is None:
        columns = allc
    unknown = [c for c in columns if c not in allc]
    if unknown:
        raise ValueError(f"columns = {unknown!r} is invalid: tire columns are {allc}")
    want = set(columns)

    arrs = dict(p0=check_positive("p0", p0, "[Pa]"), E_star=check_positive("E_star", E_star, "[Pa]"),
                R=check_positive("R", R, "[m]"), eta=check_positive("eta", eta, "[Pa·s]"),
                footprint_length=check_positive("footprint_length", footprint_length, "[m]"),
                speed=check_positive("speed", speed, "[m/s]"), rho=check_positive("rho", rho, "[kg/m^3]"))
    if u_start is not None:
        arrs["u_start"] = check_positive("u_start", u_start, "[m]")
    b = dict(zip(arrs, (np.ravel(a) for a in np.broadcast_arrays(*arrs.values()))))
    n = b["p0"].size
    p_peak = b["p0"] * peak
    p_eval = b["p0"] if pressure_model == "mean" else p_peak
    t_fp = b["footprint_length"] / b["speed"]
    out = {"p_eval": p_eval, "p_peak": p_peak, "t_footprint": t_fp}

    need_exit = bool(want & {"u_exit", "du_exit", "squeeze_complete"})
    need_tdu = "t_du" in want
    need_ratios = [r for r in ratios if _ratio_name(r) in want]
    need_sq = need_exit or need_tdu or need_ratios or bool(
        want & {"u_inf", "t_star", "trapped", "u_trap", "fluid_load_fraction", "u_start",
                "t_star_inertia", "out_of_table"})
    u_used = b.get("u_start")
    if need_sq:
        # the squeeze-out depends on (p_eval, E*, R, η, ū(0)) only; the footprint time only
        # selects where ū(t) is read: one squeeze_out call per distinct squeeze case
        keycols = [p_eval, b["E_star"], b["R"], b["eta"]] + ([b["u_start"]] if u_start is not None else [])
        keys = np.stack(keycols, axis=1)
        uniq, inv = np.unique(keys, axis=0, return_inverse=True)
        inv = inv.ravel()
        kw = dict(p0=uniq[:, 0], E_star=uniq[:, 1], R=uniq[:, 2], eta=uniq[:, 3], theory=theory,
                  u_start=(uniq[:, 4] if u_start is not None else None),
                  ratios=tuple(need_ratios) if need_ratios else (1.01,),
                  du=(du_complete,) if need_tdu else (), times=(),
                  method=squeeze_method(len(uniq)))
        sq = _frame_rows(squeeze_out(tables, **kw), len(uniq))
        u_inf = sq["u_inf"].to_numpy(float)[inv]
        out["u_inf"] = u_inf
        u_used = sq["u_start"].to_numpy(float)[inv]
        out["u_start"] = u_used
        if need_tdu:
            out["t_du"] = sq[_pick(sq, "t_du_", [du_complete])[0]].to_numpy(float)[inv]
        for r, c in zip(need_ratios, _pick(sq, "t_ratio_", need_ratios) if need_ratios else []):
            out[_ratio_name(r)] = sq[c].to_numpy(float)[inv]
        out["t_star"] = sq["t_star"].to_numpy(float)[inv]
        out["trapped"] = sq["trapped"].to_numpy(bool)[inv]
        out["u_trap"] = sq["u_trap"].to_numpy(float)[inv]
        out["fluid_load_fraction"] = sq["fluid_load_fraction"].to_numpy(float)[inv]
        out["out_of_table"] = sq["out_of_table"].to_numpy(bool)[inv]
        if need_exit:
            # ū at the exit: one call per distinct footprint time, on the cases that have it
            u_exit = np.full(n, np.nan)
            for tv in np.unique(t_fp):
                rows = np.flatnonzero(t_fp == tv)
                cases = np.unique(inv[rows])
                kw_t = dict(kw, p0=uniq[cases, 0], E_star=uniq[cases, 1], R=uniq[cases, 2],
                            eta=uniq[cases, 3],
                            u_start=(uniq[cases, 4] if u_start is not None else None),
                            ratios=(), du=(), times=(float(tv),), method="quad")
                st = _frame_rows(squeeze_out(tables, **kw_t), cases.size)
                ucol = [c for c in st.columns if c.startswith("u_at_")]
                if len(ucol) != 1:
                    raise RuntimeError(f"squeeze_out returned u_at columns {ucol} for one time")
                lookup = dict(zip(cases.tolist(), st[ucol[0]].to_numpy(float)))
                u_exit[rows] = [lookup[c] for c in inv[rows].tolist()]
            out["u_exit"] = u_exit
            out["du_exit"] = u_exit - u_inf
            out["squeeze_complete"] = (u_exit - u_inf) <= du_complete
    if want & {"tau_inertia", "t_star_inertia"}:
        tau = np.asarray(inertia_time_constant(2.0 * b["R"], b["rho"], p_eval), float) * np.ones(n)
        out["tau_inertia"] = tau
        h = tables.h_rms
        u0 = np.asarray(u_used if u_used is not None else np.full(n, np.nan), float) * np.ones(n)
        with np.errstate(invalid="ignore", divide="ignore"):
            out["t_star_inertia"] = np.where(u0 > h, tau * np.log(u0 / h), np.nan)
    df = pd.DataFrame({c: np.asarray(out[c]) for c in columns if c in out})
    for c in columns:
        if c not in df:
            df[c] = np.nan
    return df[list(columns)]


def tire_history(tables, *, p0, E_star, R, eta, t, theory="average", u_start=PAPER_TIRE["u_start"]):
    """ū(t) [m] of one tread block at constant nominal pressure ``p0`` (p_eval) over times t [s].

    Returns a DataFrame with ``t``, ``u``, ``du`` (= ū - ū∞) and ``u_inf``.
    """
    from . import squeeze_history, squeeze_out
    t = check_positive("t", t, "[s]", allow_zero=True).ravel()
    h = squeeze_history(tables, p0, E_star, R, eta, theory, t, u_start=u_start)
    u = h["u"].to_numpy(float)
    sq = squeeze_out(tables, p0=p0, E_star=E_star, R=R, eta=eta, theory=theory, u_start=u_start,
                     ratios=(1.01,), du=(), times=(), method="quad")
    u_inf = float(np.ravel(sq["u_inf"].to_numpy(float))[0])
    return pd.DataFrame({"t": h["t"].to_numpy(float) if "t" in h else t, "u": u,
                         "du": u - u_inf, "u_inf": u_inf})
