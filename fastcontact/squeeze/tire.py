"""Tire tread block crossing a wet-road footprint — Lorenz & Persson (2010), Sec. 5.

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
ODE (eqs. (18)–(19)) is solved at a **constant** nominal pressure p_eval for the whole
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

from .._core.owned import own
from .._core.validate import as_float_array, check_positive
from .._core.vocab import DEFAULT_THEORY, column_name
from ..kernels.readonly import readonly_fields
from . import _kernels as qk
from .api import _check_method, attrs, run_cases, squeeze_history, squeeze_out, status_column
from .model import squeeze_model
from .primitive import fast_limit
from ._fastpath import history_kernel, one_case_primitive
from ._columns import exit_columns, inertia_columns, status_flags

__all__ = ["tire_footprint", "tire_history", "tire_columns", "profile_factors",
           "pressure_profile", "squeeze_method", "PAPER_TIRE"]

#: the paper's Sec. 5 parameters (SI)
PAPER_TIRE = dict(p0=0.2e6, E=10e6, R=0.02, eta=1e-3, rho=1000.0, footprint_length=0.1,
                  speed=30.0, u_start=1e-2)

#: below this many cases the per-case quadrature (~25 µs a case on 2 cores, ~200 µs with three
#: times; bench/squeeze_results.md) is cheaper than building the time primitive of a new
#: (tables, theory) (24-49 ms on 2 cores on six spectra, bench/first_call_results.md; once,
#: cached afterwards)
QUAD_BELOW = 2_000


def squeeze_method(n):
    """"quad" for fewer than QUAD_BELOW cases, else "fast" (see QUAD_BELOW)."""
    return "quad" if n < QUAD_BELOW else "fast"


TIRE_BASE = ("p_eval", "p_peak", "t_footprint", "u_start", "u_inf", "t_du")
TIRE_TAIL = ("t_star", "u_exit", "du_exit", "squeeze_complete", "trapped", "u_trap",
             "fluid_load_fraction", "tau_inertia", "t_star_inertia", "out_of_table", "status")
TIRE_UNITS = {"p_eval": "Pa", "p_peak": "Pa", "t_footprint": "s", "u_start": "m", "u_inf": "m",
              "t_du": "s", "t_ratio": "s", "t_star": "s", "u_exit": "m", "du_exit": "m",
              "squeeze_complete": "bool", "trapped": "bool", "u_trap": "m",
              "fluid_load_fraction": "1", "tau_inertia": "s", "t_star_inertia": "s",
              "out_of_table": "bool", "status": "category"}


def _ratio_names(ratios):
    names = [column_name("t_ratio", r) for r in ratios]
    if len(set(names)) != len(names):
        raise ValueError(f"ratios = {tuple(ratios)!r} is invalid: a ratio is requested more "
                         f"than once (each gives one column)")
    return names


def tire_columns(ratios=(1.1, 1.01, 1.001)):
    """Names of the result columns of :func:`tire_footprint` for these ``ratios``."""
    return list(TIRE_BASE) + _ratio_names(ratios) + list(TIRE_TAIL)


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


def _inputs(p0, E_star, R, eta, footprint_length, speed, rho, u_start, alpha_pv=0.0):
    arrs = dict(p0=check_positive("p0", p0, "[Pa]"), E_star=check_positive("E_star", E_star, "[Pa]"),
                R=check_positive("R", R, "[m]"), eta=check_positive("eta", eta, "[Pa·s]"),
                footprint_length=check_positive("footprint_length", footprint_length, "[m]"),
                speed=check_positive("speed", speed, "[m/s]"),
                rho=check_positive("rho", rho, "[kg/m^3]"),
                alpha_pv=check_positive("alpha_pv", alpha_pv, "[1/Pa]", allow_zero=True))
    if u_start is not None:
        arrs["u_start"] = check_positive("u_start", u_start, "[m]")
    try:
        shape = np.broadcast_shapes(*(np.shape(a) for a in arrs.values()))
    except ValueError:
        raise ValueError(f"{', '.join(arrs)} are invalid: shapes "
                         f"{[np.shape(a) for a in arrs.values()]} do not broadcast") from None
    # one value per case, contiguous (the kernel's inputs); E*, R, η, ū(0), ρ and α_pv given
    # as one number stay 0-d (no array of a million copies to write: 8 MB each per million
    # cases): NumPy broadcasts them, the squeeze-out kernels read one value for all, and the
    # Barus engine expands them (_full)
    return {k: a.reshape(()) if k in _SCALAR_OK and a.size == 1
            else np.ascontiguousarray(np.broadcast_to(a, shape).ravel(), dtype=np.float64)
            for k, a in arrs.items()}


#: inputs of _inputs that may stay 0-d
_SCALAR_OK = ("E_star", "R", "eta", "u_start", "rho", "alpha_pv")


def _full(b, n):
    """``b`` with every input one value per case (contiguous, n values)."""
    return {k: np.ascontiguousarray(np.broadcast_to(v, (n,)), dtype=np.float64)
            for k, v in b.items()}


#: the columns that need ū at the footprint exit (one inversion of the time primitive per case)
_EXIT_COLUMNS = frozenset(("u_exit", "du_exit", "squeeze_complete"))


def _squeeze_columns(tables, b, p_eval, t_fp, theory, ratios, du_complete, method, out,
                     want=None):
    """The squeeze-out columns of every case in one kernel pass (ū at each case's own exit).

    ``want`` (a set of column names; None: all) selects the targets the kernel computes: a
    ratio target only for its ``t_ratio_<r>`` column, the Δu target only for ``t_du``, the
    exit only for ``u_exit``, ``du_exit`` or ``squeeze_complete`` (t_star, ū∞, ū(0), the trap
    and the status always). Every computed column is the same whatever else is asked, to
    within the primitive's error (the exit's ū can differ by ~1e-8 relative where a near-start
    target changes which T(ū(0)) it pairs with)."""
    model = squeeze_model(tables, theory)
    us = b["u_start"] if "u_start" in b else np.nan  # NaN: the default start
    # E*, R, η and ū(0): one value per case or one for all (size 1, shared by every case)
    rest = (np.ascontiguousarray(a, dtype=np.float64).reshape(-1)
            for a in (b["E_star"], b["R"], b["eta"], us))
    cs = readonly_fields(qk.Cases(np.ascontiguousarray(p_eval), *rest))
    quad, _ = _check_method(method, 10, 1.0, None)
    names = _ratio_names(ratios)
    keep = [k for k, nm in enumerate(names) if want is None or nm in want]
    r = np.asarray(ratios, dtype=np.float64)[keep]
    du = want is None or "t_du" in want
    exit_ = want is None or bool(want & _EXIT_COLUMNS)
    sq = run_cases(model, cs, r, np.array([du_complete / model.h_rms] if du else []),
                   np.ascontiguousarray(t_fp[None, :]) if exit_ else np.zeros((0, 1)), method,
                   quad, timescales=False)
    trapped, _, oot = status_flags(sq.status, sq.u_trap)
    out.update(u_inf=sq.u_inf, u_start=sq.u_start, t_star=sq.T[0], trapped=trapped,
               u_trap=sq.u_trap, fluid_load_fraction=sq.flf, out_of_table=oot,
               status=status_column(sq.status))
    if du:
        out["t_du"] = sq.T[1 + r.size]
    if exit_:
        du_exit, complete = exit_columns(sq.U[0], sq.u_inf, du_complete)
        out.update(u_exit=sq.U[0], du_exit=du_exit, squeeze_complete=complete)
    for j, k in enumerate(keep):
        out[names[k]] = sq.T[1 + j]
    return model


def _check_options(pressure_profile, pressure_model, du_complete, ratios, columns):
    """Validated options of :func:`tire_footprint`: the profile's peak-to-mean ratio [-],
    du_complete [m], the ratios [-] as a tuple of floats and the list of wanted columns."""
    if pressure_model not in ("mean", "peak"):
        raise ValueError(f"pressure_model = {pressure_model!r} is invalid: must be 'mean' or 'peak'")
    _, peak = profile_factors(pressure_profile)
    du_complete = float(check_positive("du_complete", du_complete, "[m]"))
    ratios = tuple(float(r) for r in np.atleast_1d(as_float_array("ratios", ratios)).ravel())
    for r in ratios:
        if not r > 1.0 or not math.isfinite(r):
            raise ValueError(f"ratios = {ratios!r} is invalid: each must be a finite number > 1")
    allc = tire_columns(ratios)
    columns = allc if columns is None else list(columns)
    unknown = [c for c in columns if c not in allc]
    if unknown:
        raise ValueError(f"columns = {unknown!r} is invalid: tire columns are {allc}")
    return peak, du_complete, ratios, columns


def _viscous_columns(tables, b, p_eval, t_fp, theory, ratios, du_complete, method, out, want):
    """The squeeze-out columns into ``out``: the base engine, or the Barus fluid engine of
    :mod:`fastcontact.squeeze.tire_piezo` if any row has α > 0 (issue 14); either computes
    only the targets of the columns in ``want``. Returns the model."""
    if np.any(b["alpha_pv"] > 0.0):
        from .tire_piezo import barus_tire_columns
        b = _full(b, p_eval.size)
        return barus_tire_columns(
            tables, b, p_eval, t_fp, theory, ratios, _ratio_names(ratios), du_complete,
            b["alpha_pv"], out, lambda tb, bb, pe, tf, o: _squeeze_columns(
                tb, bb, pe, tf, theory, ratios, du_complete, method, o, want), method, want)
    return _squeeze_columns(tables, b, p_eval, t_fp, theory, ratios, du_complete, method, out,
                            want)


def _inertia_columns(b, p_eval, u_used, h_rms, out):
    """``tau_inertia`` τ' = (D²ρ/(64 p_eval))^{1/2} [s] (D = 2R) and ``t_star_inertia``
    τ' ln(ū(0)/h_rms) [s] (NaN where ū(0) is unknown or <= h_rms) into ``out`` — Sec. 5
    (one parallel pass; R ~ 1e308 m gives τ' = inf on a row flagged "overflow")."""
    out["tau_inertia"], out["t_star_inertia"] = inertia_columns(b["R"], b["rho"], p_eval,
                                                                u_used, h_rms)


def _footprint_frame(out, columns, n, model, method):
    """The result frame of :func:`tire_footprint` (NaN for columns not computed) with units,
    and the squeeze model's theory and references when one ran."""
    df = pd.DataFrame({c: out[c] if c in out else np.full(n, np.nan) for c in columns},
                      copy=False)
    df.attrs["units"] = {c: TIRE_UNITS.get(c, TIRE_UNITS.get(c.rsplit("_", 1)[0], ""))
                         for c in columns}
    if model is not None:
        a = attrs(model, [], method)
        a.pop("units")
        df.attrs.update({k: v for k, v in a.items() if k not in df.attrs})
    return df


def tire_footprint(tables, *, p0, E_star, R, eta, footprint_length, speed, rho=1000.0,
                   theory=DEFAULT_THEORY, pressure_profile="uniform", pressure_model="mean",
                   u_start=PAPER_TIRE["u_start"], du_complete=1e-6, ratios=(1.1, 1.01, 1.001),
                   columns=None, method=None, alpha_pv=0.0):
    """Squeeze-out of a tread block during its passage through the footprint (Sec. 5).

    Every case (its own pressure, speed and footprint length) costs a few interpolations of
    the time primitive, in one parallel pass.

    Parameters
    ----------
    tables : Tables
        The road surface's tables (must hold ``theory``).
    p0 : array_like
        Mean nominal pressure over the footprint [Pa].
    E_star : array_like
        Effective modulus of the tread rubber [Pa].
    R : array_like
        Tread block radius [m] (D = 2R enters the inertia estimate).
    eta : array_like
        Fluid viscosity [Pa·s] (water 1e-3).
    footprint_length : array_like
        Footprint length L_f [m].
    speed : array_like
        Rolling speed v [m/s]; the block spends t_footprint = L_f/v in the footprint.
    rho : array_like, default 1000
        Fluid density [kg/m³] (inertia estimate only).
    theory : str, default DEFAULT_THEORY ("critical_junction")
        Flow-conductivity theory.
    pressure_profile : {"uniform", "parabolic"} or sequence, default "uniform"
        Relative pressure along the footprint (module docstring).
    pressure_model : {"mean", "peak"}, default "mean"
        Which constant pressure p_eval is used.
    u_start : array_like or None, default 0.01
        Initial film ū(0) [m] (None: the squeeze-out default start).
    du_complete : float, default 1e-6
        Δu threshold [m] of ``squeeze_complete`` and ``t_du``.
    ratios : sequence of float, default (1.1, 1.01, 1.001)
        ū/ū∞ of the ``t_ratio_<r>`` columns.
    columns : list of str or None
        Columns wanted (default all of :func:`tire_columns`). Only what they need is computed:
        a ratio target for its ``t_ratio_<r>`` column, the Δu target for ``t_du``, ū at the
        exit for ``u_exit``, ``du_exit`` or ``squeeze_complete``, the squeeze-out itself only
        if a column beyond ``p_eval``, ``p_peak``, ``t_footprint`` and ``tau_inertia`` is
        asked (the Barus engine, ``alpha_pv`` > 0, computes every column).
    method : {"fast", "quad"} or None
        Squeeze-out engine (None: :func:`squeeze_method` of the case count).
    alpha_pv : array_like, default 0.0
        Barus pressure–viscosity coefficient α [1/Pa] >= 0, η = η0 exp(α p_f) (issue 14).
        Rows with α > 0 run the Barus engine (exact reduced-pressure rate factor): with
        ``method="fast"`` the rows of one α E* — every row of a call of one fluid on one
        rubber, groups of at least 20,000 rows (or with a kept primitive) of a call of
        several — the base engine's kernel on the Barus time primitive built for them
        (:mod:`fastcontact.squeeze._barus_time`, the base tire's speed); other rows (every
        row its own α or E*, small groups) the time primitive plus the tabulated Barus
        correction per case (:mod:`fastcontact.squeeze._barus_fast`); rows with
        α p_eval > 0.6 or next to the trap pressure by quadrature in the same pass; with
        "quad" the per-case quadrature
        of :mod:`fastcontact.squeeze.tire_piezo`; status "piezo_limit" with NaN results where
        α(p_eval − p_cont(ū(0))) >= 1. Rows with α = 0 are the base engine's, bit for bit.

    Returns
    -------
    pandas.DataFrame
        The requested columns (:func:`tire_columns`); ``attrs`` holds ``units``, ``theory``
        and ``references``. ``status`` explains every NaN/inf row ("ok", "trapped",
        "out_of_table", "start_below_equilibrium", "overflow").
    """
    peak, du_complete, ratios, columns = _check_options(
        pressure_profile, pressure_model, du_complete, ratios, columns)
    want = set(columns)
    b = _inputs(p0, E_star, R, eta, footprint_length, speed, rho, u_start, alpha_pv)
    n = b["p0"].size
    p_peak = b["p0"] * peak
    p_eval = b["p0"] if pressure_model == "mean" else p_peak
    t_fp = b["footprint_length"] / b["speed"]
    # p_eval is the caller's p0 itself for the mean pressure model: a column of its own
    out = {"p_eval": own(p_eval), "p_peak": p_peak, "t_footprint": t_fp}
    u_used = b.get("u_start")
    model = None
    if want - {"p_eval", "p_peak", "t_footprint", "tau_inertia"}:
        if method is None:
            method = squeeze_method(n)
        model = _viscous_columns(tables, b, p_eval, t_fp, theory, ratios, du_complete, method,
                                 out, want)
        if u_used is None:  # the default start: each row's own
            u_used = out["u_start"]
    if want & {"tau_inertia", "t_star_inertia"}:
        _inertia_columns(b, p_eval, u_used, tables.h_rms, out)
    return _footprint_frame(out, columns, n, model, method)


def tire_history(tables, *, p0, E_star, R, eta, t, theory=DEFAULT_THEORY,
                 u_start=PAPER_TIRE["u_start"]):
    """ū(t) [m] of one tread block at constant nominal pressure ``p0`` (p_eval) over times t.

    Parameters
    ----------
    tables, p0, E_star, R, eta, theory, u_start
        As :func:`tire_footprint`, scalars.
    t : array_like
        Times [s] ≥ 0, any order; +inf gives ū∞ (as :func:`squeeze_history`).

    Returns
    -------
    pandas.DataFrame
        ``t`` [s], ``u`` [m], ``du`` = ū - ū∞ [m], ``u_inf`` [m]; ``attrs`` with units.
    """
    t = np.ascontiguousarray(np.atleast_1d(check_positive("t", t, "[s]", allow_zero=True,
                                                          allow_inf=True)).ravel())
    one = squeeze_out(tables, p0=p0, E_star=E_star, R=R, eta=eta, theory=theory,
                      u_start=u_start, ratios=())
    row = one.iloc[0]
    u_inf = float(row["u_inf"])
    model = squeeze_model(tables, theory)
    x0 = math.log(float(p0) / float(E_star))
    if row["status"] == "ok" and x0 <= fast_limit(model):
        u = np.empty(t.size)
        vs = math.nan if u_start is None else float(u_start) / model.h_rms
        history_kernel(*one_case_primitive(model.primitive(), x0), vs, float(row["tau0"]),
                       model.h_rms, t, u)
    else:
        u = squeeze_history(tables, p0, E_star, R, eta, theory, t, u_start=u_start)["u"].to_numpy()
    df = pd.DataFrame({"t": own(t), "u": u, "du": u - u_inf, "u_inf": np.full(t.size, u_inf)},
                      copy=False)
    df.attrs.update(one.attrs)
    df.attrs["units"] = {"t": "s", "u": "m", "du": "m", "u_inf": "m"}
    return df
