"""Public squeeze-out functions: :func:`squeeze_out` (millions of cases per call),
:func:`squeeze_history` (one case on a time array) and :func:`columns` (names and units).

Lorenz & Persson, Eur. Phys. J. E 32, 281 (2010), eqs. (17)–(19), (23);
arXiv:1004.1037.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .._core.owned import own
from .._core.validate import align_inputs, as_float_array, check_positive
from .._core.vocab import DEFAULT_THEORY, REFERENCES, column_name
from ..tables import Tables
from . import _kernels as qk
from . import _trap_primitive as tpm
from ._fastpath import fast_kernel, history_kernel, one_case_primitive, quad_kernel, row_targets
from .model import DEFAULT_P_START, squeeze_model
from .primitive import fast_limit, verified_top
from ._columns import history_columns, status_flags
from ..kernels.quadrature import gauss_legendre
from ..kernels.readonly import readonly_fields

__all__ = ["squeeze_out", "squeeze_history", "columns", "register_extension", "QUAD_ORDER",
           "QUAD_WIDTH", "STATUS_NAMES"]

#: default per-case Gauss–Legendre order and panel width in w = ln(v - v∞) (method="quad")
QUAD_ORDER = 10
QUAD_WIDTH = 1.0
STATUS_NAMES = qk.STATUS_NAMES

#: units of the result columns (numbered columns take the unit of their prefix)
UNITS = {
    "p0": "Pa", "E_star": "Pa", "R": "m", "eta": "Pa s", "u_start": "m", "u_inf": "m",
    "t_star": "s", "t_ratio": "s", "t_du": "s", "u_at": "m", "tau0": "s", "t_relax": "s",
    "trapped": "bool", "percolated": "bool", "u_trap": "m", "t_trap": "s",
    "fluid_load_fraction": "1", "out_of_table": "bool", "status": "category",
}
_REF_KEYS = ("lorenz_persson_2010_squeeze", "persson_2001")

#: keyword extensions of squeeze_out: name -> callable(tables, kwargs, value) returning a
#: DataFrame (registered by extension modules, e.g. a pressure-dependent viscosity)
_EXTENSIONS: dict = {}


def register_extension(keyword, handler):
    """Register ``handler(tables, kwargs, value) -> DataFrame`` for ``squeeze_out(keyword=...)``."""
    _EXTENSIONS[str(keyword)] = handler


def columns(ratios=(1.1, 1.01, 1.001), du=(), times=()):
    """Names of the :func:`squeeze_out` result columns, in order, for these targets."""
    return (["p0", "E_star", "R", "eta", "u_start", "u_inf", "t_star"]
            + _numbered("t_ratio", ratios) + _numbered("t_du", du) + _numbered("u_at", times)
            + ["tau0", "t_relax", "trapped", "percolated", "u_trap", "t_trap",
               "fluid_load_fraction", "out_of_table", "status"])


def _numbered(prefix, values):
    names = [column_name(prefix, v) for v in np.atleast_1d(np.asarray(values, float)).ravel()]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise ValueError(f"{prefix} targets are invalid: {dup} requested more than once "
                         f"(each target gives one column)")
    return names


def units_of(cols):
    """{column: unit} for result columns (numbered ones by prefix)."""
    out = {}
    for c in cols:
        key = c if c in UNITS else c.rsplit("_", 1)[0]
        out[c] = UNITS.get(key, "")
    return out


def _targets(ratios, du, times):
    ratios = np.atleast_1d(as_float_array("ratios", ratios)).ravel()
    if ratios.size and not np.all(np.isfinite(ratios) & (ratios > 1.0)):
        bad = ratios[~(np.isfinite(ratios) & (ratios > 1.0))][0]
        raise ValueError(f"ratios = {float(bad)!r} is invalid: every ratio must be a finite "
                         f"number > 1 [-] (target u/u_inf)")
    du = np.atleast_1d(as_float_array("du", du, "[m]")).ravel()
    if du.size:
        check_positive("du", du, "[m]")
    times = np.atleast_1d(as_float_array("times", times, "[s]")).ravel()
    if times.size:
        check_positive("times", times, "[s]", allow_zero=True, allow_inf=True)
    return ratios, du, times


def _check_method(method, quad_order, quad_width, sigma_trap):
    if method not in ("fast", "quad"):
        raise ValueError(f"method = {method!r} is invalid: must be 'fast' or 'quad'")
    qo = float(as_float_array("quad_order", quad_order))
    if not (math.isfinite(qo) and qo == int(qo) and 2 <= qo <= 64):
        raise ValueError(f"quad_order = {quad_order!r} is invalid: must be an integer in [2, 64]")
    qw = float(check_positive("quad_width", quad_width, "[-] (panel width in ln(u-u_inf))"))
    if sigma_trap is not None:
        sigma_trap = float(check_positive("sigma_trap", sigma_trap,
                                          "[-] (reduced conductivity floor)"))
    glx, glw = gauss_legendre(int(qo))
    return qk.Quad(glx, glw, qw), sigma_trap


def _cases(p0, E_star, R, eta, u_start):
    arrs = [check_positive("p0", p0, "[Pa]"), check_positive("E_star", E_star, "[Pa]"),
            check_positive("R", R, "[m]"), check_positive("eta", eta, "[Pa·s]"),
            np.array(np.nan) if u_start is None
            else check_positive("u_start", u_start, "[m]", allow_inf=True)]
    try:
        shape = np.broadcast_shapes(*(np.shape(a) for a in arrs))
    except ValueError:
        raise ValueError(f"p0, E_star, R, eta, u_start are invalid: shapes "
                         f"{[np.shape(a) for a in arrs]} do not broadcast") from None
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape).ravel(), dtype=np.float64)
            for a in arrs]
    return readonly_fields(qk.Cases(*flat))


def run_cases(model, cs, ratios, dvs, times2d, method, quad, timescales=True):
    """Evaluate the cases ``cs`` (reduced targets) into a fresh :data:`SqOut` record.

    ``times2d`` has shape (n_times, 1) (shared, ascending) or (n_times, n) (per case,
    ascending along axis 0). The case arrays E, R, eta and us of ``cs`` hold n values or one
    shared by every case. ``timescales=False``: a caller that reports none of t_relax, t_trap
    and tau0 (the fast path then neither computes nor writes them: an interpolation per case and
    24 MB per million rows); they come back as None."""
    n = cs.p0.size
    for name in ("E", "R", "eta", "us"):
        size = getattr(cs, name).size
        if size not in (1, n):  # the kernels index them by case or read their one value
            raise ValueError(f"cases: {name} has {size} values, p0 {n} (must be {n} or 1)")
    nt = 1 + ratios.size + dvs.size
    out = qk.SqOut(np.empty((nt, n)), np.empty((times2d.shape[0], n)), *(np.empty(n) for _ in
                   range(7)), qk.new_status(n))
    tg = readonly_fields(qk.Targets(np.ascontiguousarray(ratios, dtype=np.float64),
                                    np.ascontiguousarray(dvs, dtype=np.float64),
                                    np.ascontiguousarray(times2d, dtype=np.float64)))
    if method == "quad":
        quad_kernel(model.tab, model.mp, cs, model.h_rms, tg, quad, out)
    else:
        pr, x_fast = _equilibrium_side(model, cs)
        us = cs.us
        # one start for all (NaN: never equal; a size-1 start is shared by every case)
        shared = n > 1 and (us.size == 1 or us.min() == us.max())
        rt = row_targets(pr, tg.ratios, tg.dvs, us[0] / model.h_rms if shared else math.nan)
        tp = _trapped_side(model, cs)
        fast_kernel(model.tab, model.mp, pr, rt, x_fast, tp.lo, tp.hi, tp.rows, cs,
                    model.h_rms, tg, quad, out, bool(timescales))
    qk.check_computed(out.status, "squeeze_out")
    if not timescales:  # not written on the rows the fast path serves: nothing to read
        out = out._replace(t_relax=None, t_trap=None, tau0=None)
    return out


def _equilibrium_side(model, cs):
    """(primitive, x_fast): the time primitive of ``model`` and the largest ln(p0/E*) it serves,
    or, where every case of ``cs`` lies above that (trapped, or next to the trap pressure),
    an empty record of the same type that serves none (x_fast = -inf): such a study builds
    no primitive it would not use."""
    x_fast = fast_limit(model)
    if cs.p0.size > 0:
        lo = np.min(cs.p0) / np.max(cs.E)  # a bound below every case's p0/E*: two reductions
        if lo > 0.0 and math.log(lo) > x_fast:
            return tpm.empty().lo, -math.inf
    return model.primitive(), x_fast


def _trapped_side(model, cs):
    """The trapped side's primitive of ``model`` if a case of ``cs`` lies where it serves
    (built then, on first use), else the empty one: a study that never traps builds none."""
    if not math.isfinite(model.x_trap) or cs.p0.size == 0:
        return tpm.empty()
    x_first = model.x_trap + math.exp(tpm.S_MIN)
    p_max = np.max(cs.p0)
    pe = p_max / np.min(cs.E)  # a bound: two reductions, no temporary array per call
    if pe > 0.0 and math.log(pe) >= x_first and cs.E.size > 1:
        pe = np.max(cs.p0 / cs.E)  # the exact largest p0/E* only where the bound says maybe
    return model.trap_primitive() if math.log(pe) >= x_first else tpm.empty()


def status_column(codes):
    """The readable ``status`` column (categorical) of int8 status codes."""
    return pd.Categorical.from_codes(codes, categories=list(STATUS_NAMES))


def attrs(model, cols, method):
    """The ``DataFrame.attrs`` of a squeeze-out result: units, theory, references, decisions."""
    xt, xp = model.x_trap, model.x_perc
    return {
        "units": units_of(cols), "theory": model.theory, "method": method,
        "references": [f"{REFERENCES[k][0]}, doi:{REFERENCES[k][1]}" for k in _REF_KEYS],
        "h_rms_m": model.h_rms,
        "time_unit": "tau0 = 3 eta R^2 / (2 h_rms^2 p0) [s]",
        "default_u_start": f"p_cont(u_start) = {DEFAULT_P_START:g} p0",
        "trap_criterion": (f"sigma_bar < sigma_trap = {model.sigma_trap:g} is treated as 0 "
                           f"(p/E* >= {math.exp(xt) if np.isfinite(xt) else math.inf:.8g}; "
                           f"exact percolation at p/E* = "
                           f"{math.exp(xp) if np.isfinite(xp) else math.inf:.8g})"),
        "tail": _tail_text(model),
        "sigma_verified": _verified_text(model),
        "status": {"ok": "computed", "trapped": "fluid trapped above u_inf (u_trap, t_trap)",
                   "out_of_table": "p0/E_star outside the tables: NaN",
                   "start_below_equilibrium": "u_start <= u_inf: NaN",
                   "overflow": "tau0 or a time not representable in float64 (inf or 0)"},
    }


def _verified_text(model):
    """Provenance text: up to which p/E* the tables' σ̄ is verified (their last node above the
    tables' σ̄ floor), and what rows beyond it get."""
    xv = verified_top(model)
    if not math.isfinite(model.x_trap):
        return "sigma_bar verified by the table build over the whole table"
    if xv >= model.x_trap:
        return "sigma_bar verified by the table build up to the trap pressure"
    return (f"sigma_bar verified by the table build up to p/E* = {math.exp(xv):.8g} (the tables' "
            f"last node with sigma_bar above their floor); rows from there to the trap pressure "
            f"use the tables' unverified sigma_bar (status ok; films there drain over ~1/sigma_bar "
            f"tau0: treat them as trapped in practice)")


def _tail_text(model):
    """Provenance text of the model's analytic tail above the table top."""
    t, mp = model.tail, model.mp
    head = f"u > {model.v_top:.6g} h_rms: p = p_top exp(-(u-u_top)/{model.u0:.6g} h_rms), "
    far = f"sigma_bar = y^3 - {mp.c:.6g} y, y = u/h_rms + {mp.d:.6g}"
    if "fit_error" not in t:
        return head + far + " (matched to the table top in value and slope)"
    g = ", ".join(f"{t[k]:.6g}" for k in ("g1", "g2", "g3", "g4", "g5"))
    return (head + f"sigma_bar^(1/3) = u/h_rms + {mp.d:.6g} + g(h_rms/u), g = polynomial "
            f"with coefficients ({g}) fitted to the tables' tail samples (worst residual "
            f"{t['fit_error']:.2g}); above u = {mp.v_ext:.6g} h_rms " + far)


def squeeze_out(tables, *, p0, E_star, R, eta, theory=DEFAULT_THEORY, u_start=None,
                ratios=(1.1, 1.01, 1.001), du=(), times=(), method="fast",
                quad_order=QUAD_ORDER, quad_width=QUAD_WIDTH, sigma_trap=None, **extensions):
    """Squeeze-out of a flat cylindrical block against the tables' rough surface.

    One row per broadcast case of (p0, E_star, R, eta, u_start) (numpy broadcasting, C order).
    The film obeys dū/dt = -(8σ_eff/R²)(p0 - p_cont(ū)) (eqs. (17)–(19)); every time is a
    difference of the tabulated time primitive (``method="fast"``) or a per-case quadrature
    (``method="quad"``).

    Parameters
    ----------
    tables : Tables
        Precomputed surface tables holding ``theory``.
    p0 : array_like
        Nominal squeezing pressure [Pa], > 0.
    E_star : array_like
        Effective modulus E* [Pa], > 0.
    R : array_like
        Block radius [m], > 0.
    eta : array_like
        Fluid viscosity η [Pa·s], > 0.
    theory : str, default DEFAULT_THEORY ("critical_junction")
        Flow-conductivity theory ("average", "critical_junction", "emt").
    u_start : array_like or None, default None
        Initial separation [m] (+inf allowed). None: where p_cont = 1e-3 p0. A start at or
        below ū∞ gives NaN and ``status = "start_below_equilibrium"`` on that row.
    ratios : sequence of float, default (1.1, 1.01, 1.001)
        Targets ū/ū∞ > 1 → columns ``t_ratio_<r>`` [s].
    du : sequence of float, default ()
        Targets ū - ū∞ [m] > 0 → columns ``t_du_<Δu>`` [s].
    times : sequence of float, default ()
        Times [s] ≥ 0 → columns ``u_at_<t>`` (ū at that time) [m].
    method : {"fast", "quad"}, default "fast"
        Time primitive (default) or per-case Gauss–Legendre quadrature.
    quad_order, quad_width : int, float
        Gauss–Legendre order and panel width in ln(ū - ū∞) of the quadrature (``"quad"`` and
        the fall-back rows of ``"fast"``; on trapped rows in ln(ū - ū_trap), panels a third
        of the width).
    sigma_trap : float or None
        Conductivity floor of the trap criterion [-] (default: the tables' ``sigma_floor``).
    **extensions
        Keywords registered with :func:`register_extension`.

    Returns
    -------
    pandas.DataFrame
        Columns :func:`columns`: the inputs; ``u_start``, ``u_inf`` [m]; ``t_star`` (to
        ū = 1.01 ū∞), ``t_ratio_<r>``, ``t_du_<Δu>`` [s] (exactly 0 where the film is already
        below the target at t = 0; +inf where trapped above it); ``u_at_<t>`` [m];
        ``tau0`` = 3ηR²/(2h_rms²p0) [s]; ``t_relax`` e-folding time of the final approach
        [s]; ``trapped``, ``percolated``, ``u_trap`` [m], ``t_trap`` [s],
        ``fluid_load_fraction`` [-]; ``out_of_table``; ``status`` (categorical: "ok",
        "trapped", "out_of_table", "start_below_equilibrium", "overflow"). ``attrs`` holds
        ``units``, ``theory``, ``references`` and the model decisions.

    Notes
    -----
    Accuracy: times within 1e-6 relative of an independent quadrature of eqs. (18)–(19)
    (measured ≤ 2.5e-8), ū at a time within 1e-6 relative in ū - ū∞ (or 1e-8 ū∞). One
    conditioning limit: a target that lies only a little below the start inherits the
    error of ū∞ itself (≤ 5e-9 relative; the fast path interpolates ln ū∞ across its rows),
    amplified by ū_target/(ū_start - ū_target), because the target ū = r ū∞ or ū∞ + Δu moves
    with it. A start 2e-4 above the target gives up to ~1e-5 relative (the absolute error
    stays ≤ 1e-9 t*); the same target with ``method="quad"`` is exact to its quadrature.

    Trapped rows (p0 above the trap pressure, ``status = "trapped"``): the film drains
    towards ū_trap, the separation where σ̄ collapses to the trap floor ``sigma_trap``
    (default the tables' ``sigma_floor``, 1e-24), not towards ū∞. With ``method="fast"``
    their times and ū at times come from a second time primitive of the trapped side, built
    on first need (~10 ms; a study without trapped cases builds none), at 1e6 cases/s;
    cases less than 1e-8 above the trap pressure in ln(p0/E*), and non-trapped ones within
    4.4 % below it, take the per-case quadrature. The same 1e-6 bounds hold (measured ≤ 1e-7
    for times to targets above ū_trap, fast and quad, against a quadrature with panels
    broken at the tables' nodes; before 2026-12-04 the quadrature's unit panels missed them
    by up to 3.8e-6 on tables whose last open node lies below the trap pressure). ``t_trap`` is the time to reach ū_trap; it scales as 1/sigma_trap:
    3e19–1e22 τ0 on the four embedded surfaces (critical junction and EMT, ln π0 0.02–0.7
    above ln π_trap) — read it as "never drains", not as a drainage time. Within 1e-6 of a
    converged quadrature (measured ≤ 7e-8 fast, ≤ 7e-9 quad; before 2026-12-03 the
    quadrature's panels straddled the tables' last open node, where d ln σ̄/d ln π jumps
    ~20x, and missed t_trap by up to 4e-3 and the times to targets just above ū_trap by up
    to 6e-2).

    References
    ----------
    B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
    """
    al = align_inputs(p0=p0, E_star=E_star, R=R, eta=eta, u_start=u_start)  # pandas: by label
    p0, E_star, R, eta, u_start = (al[k] for k in ("p0", "E_star", "R", "eta", "u_start"))
    if extensions:
        name = next(iter(extensions))
        if name not in _EXTENSIONS:
            raise TypeError(f"squeeze_out() got an unexpected keyword argument {name!r}")
        kw = dict(p0=p0, E_star=E_star, R=R, eta=eta, theory=theory, u_start=u_start,
                  ratios=ratios, du=du, times=times, method=method, quad_order=quad_order,
                  quad_width=quad_width, sigma_trap=sigma_trap, **extensions)
        return _EXTENSIONS[name](tables, kw, extensions[name])
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables")
    quad, sigma_trap = _check_method(method, quad_order, quad_width, sigma_trap)
    model = squeeze_model(tables, theory, sigma_trap)
    cs = _cases(p0, E_star, R, eta, u_start)
    ratios, du, times = _targets(ratios, du, times)
    names = columns(ratios, du, times)
    order = np.argsort(times, kind="stable")
    out = run_cases(model, cs, ratios, du / model.h_rms, times[order][:, None], method, quad)
    return frame(model, cs, out, ratios, du, times, order, names, method)


def frame(model, cs, out, ratios, du, times, order, names, method):
    """The result DataFrame of :func:`squeeze_out` from the kernel outputs."""
    status = out.status
    trapped, perc, oot = status_flags(status, out.u_trap, cs.p0, cs.E, model.x_perc)
    # the input columns are views of the caller's arrays where no conversion was needed
    cols = {"p0": own(cs.p0), "E_star": own(cs.E), "R": own(cs.R), "eta": own(cs.eta),
            "u_start": out.u_start,
            "u_inf": out.u_inf, "t_star": out.T[0]}
    k = 1
    for name in names[7:7 + ratios.size + du.size]:
        cols[name] = out.T[k]
        k += 1
    inv = np.empty_like(order)
    inv[order] = np.arange(order.size)
    for j, name in enumerate(names[7 + ratios.size + du.size:7 + ratios.size + du.size + times.size]):
        cols[name] = out.U[inv[j]]
    cols.update({"tau0": out.tau0, "t_relax": out.t_relax, "trapped": trapped,
                 "percolated": perc, "u_trap": out.u_trap, "t_trap": out.t_trap,
                 "fluid_load_fraction": out.flf, "out_of_table": oot,
                 "status": status_column(status)})
    df = pd.DataFrame(cols, copy=False)
    df.attrs.update(attrs(model, names, method))
    return df


def _history_error(row, help_, p0, E_star, u_start, p_range):
    """The ValueError text of a history whose one case has no history (its squeeze_out status
    is neither ok nor trapped): the parameter, its value and the valid range where one applies."""
    st = row["status"]
    case = f"p0 = {float(p0)!r} Pa, E_star = {float(E_star)!r} Pa"
    if st == "start_below_equilibrium":
        return (f"u_start = {u_start!r} m is invalid for {case}: must be > u_inf = "
                f"{float(row['u_inf'])!r} m (the film must start above its equilibrium "
                f"separation; status {st!r})")
    if st == "out_of_table":
        return (f"p0 = {float(p0)!r} Pa is invalid for E_star = {float(E_star)!r} Pa: p0/E* = "
                f"{float(p0) / float(E_star):.6g}, must be in [{p_range[0]:.6g}, {p_range[1]:.6g}] "
                f"(the tables' range; status {st!r})")
    return f"{case}, u_start = {u_start!r} m are invalid for this case: status {st!r} ({help_[st]})"


def squeeze_history(tables, p0, E_star, R, eta, theory=DEFAULT_THEORY, t=None, u_start=None, *,
                    quad_order=16, quad_width=0.5, sigma_trap=None):
    """ū(t), p_cont(t)/p0 and the mean fluid pressure of ONE case on a time array.

    Parameters
    ----------
    tables, p0, E_star, R, eta, theory, u_start, sigma_trap
        As :func:`squeeze_out`, but scalars.
    t : array_like
        Times [s] ≥ 0 (+inf allowed), any order.
    quad_order, quad_width
        Quadrature of the fall-back cases: p0 within 4.4 % below the trap pressure, or less
        than 1e-8 above it in ln(p0/E*). Other cases come from a time primitive: the
        equilibrium side's, or for a trapped case (p0 above the trap pressure) the trapped
        side's (ū at each time within the 1e-6 of :func:`squeeze_out`'s ū at a time).

    Returns
    -------
    pandas.DataFrame
        ``t`` [s], ``u`` [m], ``p_cont_over_p0`` [-], ``p_fluid_mean`` [Pa] (= p0 - p_cont,
        the nominal fluid pressure p̄_f of eq. (19); the profile is 2p̄_f(1 - r²/R²)),
        ``u_flat`` [m] (Stefan law for a flat substrate from the same start), in the order
        of ``t``. ``attrs``: units, theory, references, and the case's scalar results.
    """
    for name, val in (("p0", p0), ("E_star", E_star), ("R", R), ("eta", eta)):
        if np.ndim(val) != 0:
            raise ValueError(f"{name} = {val!r} is invalid: squeeze_history takes one case "
                             f"(scalars); use squeeze_out for many")
    if t is None:
        raise ValueError("t = None is invalid: give an array of times [s] >= 0")
    t = np.ascontiguousarray(np.atleast_1d(check_positive("t", t, "[s]", allow_zero=True,
                                                          allow_inf=True)).ravel())
    df = squeeze_out(tables, p0=p0, E_star=E_star, R=R, eta=eta, theory=theory,
                     u_start=u_start, ratios=(), quad_order=quad_order, quad_width=quad_width,
                     sigma_trap=sigma_trap)
    row = df.iloc[0]
    model = squeeze_model(tables, theory, sigma_trap)
    if row["status"] != "ok" and row["status"] != "trapped":
        raise ValueError(_history_error(row, df.attrs["status"], p0, E_star, u_start,
                                        (math.exp(model.mp.x_min), math.exp(model.mp.x_max))))
    h = model.h_rms
    x0 = math.log(float(p0) / float(E_star))
    u = np.empty(t.size)
    vs = math.nan if u_start is None else float(u_start) / h
    tp = model.trap_primitive() if row["status"] == "trapped" else None
    if row["status"] == "ok" and x0 <= fast_limit(model):
        history_kernel(*one_case_primitive(model.primitive(), x0), vs, float(row["tau0"]), h, t, u)
    elif tp is not None and tp.rows.x_lo <= x0 <= tp.rows.x_hi:
        tpm.trap_history_kernel(model.tab, model.mp, tp.lo, tp.hi, tp.rows, x0, vs,
                                float(row["tau0"]), h, t, u)
    else:
        order = np.argsort(t, kind="stable")
        quad, _ = _check_method("quad", quad_order, quad_width, sigma_trap)
        cs = _cases(p0, E_star, R, eta, u_start)
        out = run_cases(model, cs, np.zeros(0), np.zeros(0), t[order][:, None], "quad", quad)
        u[order] = out.U[:, 0]
    ratio, p_fluid, flat = history_columns(model, u, t, p0, E_star, eta, R,
                                           float(row["u_start"]))
    out = pd.DataFrame({"t": own(t), "u": u, "p_cont_over_p0": ratio, "p_fluid_mean": p_fluid,
                        "u_flat": flat}, copy=False)
    out.attrs.update(df.attrs)
    out.attrs["units"] = {"t": "s", "u": "m", "p_cont_over_p0": "1", "p_fluid_mean": "Pa",
                          "u_flat": "m"}
    for k in ("u_inf", "u_start", "t_star", "trapped", "u_trap", "fluid_load_fraction",
              "tau0", "t_relax"):
        out.attrs[k] = row[k].item() if hasattr(row[k], "item") else row[k]
    return out
