"""The study kinds a scene can run (squeeze, tire, seal), each in one :class:`StudyKind` record.

A record says what the kind needs and offers: its defaults, how missing parameters are
inferred or reported (``infer``), which result columns its engine produces (``columns``, with
their SI units) and how a block of cases is evaluated (``evaluate``). The orchestrator
(:mod:`fastcontact.studies.run`) asks the engines for their columns only through
:data:`KINDS`.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

from .._core.vocab import DEFAULT_THEORY, column_name
from ..squeeze import columns as squeeze_engine_columns
from ..squeeze import squeeze_out
from ..squeeze.api import units_of as squeeze_units
from ..squeeze.tire import squeeze_method, tire_columns, tire_footprint
from . import extensions as _ext

__all__ = ["StudyKind", "KINDS", "BOOL_COLUMNS", "SQUEEZE_TAIL", "SEAL_COLUMNS",
           "SEAL_HERTZ_COLUMNS", "squeeze_columns", "available_columns", "column_units"]

#: the squeeze_out inputs it echoes (the cases hold them already)
_SQUEEZE_INPUTS = ("p0", "E_star", "R", "eta")
#: further squeeze_out columns offered by squeeze studies (as the engine lists them)
SQUEEZE_TAIL = tuple(c for c in squeeze_engine_columns((), (), ())
                     if c not in _SQUEEZE_INPUTS + ("u_start", "u_inf", "t_star"))
SEAL_COLUMNS = ("Q", "lift_off", "percolated", "p_a", "open_inlet", "open_outlet", "status")
SEAL_HERTZ_COLUMNS = ("a", "L", "p_max", "converged", "error_estimate")
#: boolean result columns (nullable booleans where a case failed)
BOOL_COLUMNS = frozenset({"trapped", "percolated", "out_of_table", "squeeze_complete",
                          "lift_off", "converged"})
#: SI unit of every fixed-name result column ("1": dimensionless, "bool": flag, "category":
#: status text; the squeeze engine's own units take precedence)
_UNITS = {**{c: "bool" for c in BOOL_COLUMNS}, "status": "category",
    "u_start": "m", "u_inf": "m", "t_star": "s", "tau0": "s", "t_relax": "s", "u_trap": "m",
    "t_trap": "s", "fluid_load_fraction": "1", "p_eval": "Pa", "p_peak": "Pa",
    "t_footprint": "s", "t_du": "s", "u_exit": "m", "du_exit": "m", "tau_inertia": "s",
    "t_star_inertia": "s", "Q": "m^3/s", "p_a": "Pa", "open_inlet": "m", "open_outlet": "m",
    "a": "m", "L": "m", "p_max": "Pa", "error_estimate": "1",
}
_PREFIX_UNITS = {"t_ratio_": "s", "t_du_": "s", "u_at_": "m"}


@dataclasses.dataclass(frozen=True)
class StudyKind:
    """What a study kind needs and offers.

    Attributes
    ----------
    name : str
        ``"squeeze"``, ``"tire"`` or ``"seal"``.
    defaults : dict
        Default study parameters (SI).
    figures : tuple of str
        Figure names a scene of this kind may request.
    infer : callable
        ``infer(axes, fixed, given, problems)``: fill inferable defaults, report missing keys.
    columns : callable
        ``columns(fixed) -> list[str]``: every result column the engine can produce.
    evaluate : callable
        ``evaluate(tables, rows, theory, fixed, columns, scale=1.0) -> dict`` of arrays (plus
        ``"_error"``: one message per row, ``""`` where the row evaluated); ``scale`` = study
        size / block size, so that a method chosen by size is the same in every block.
    """

    name: str
    defaults: dict
    figures: tuple
    infer: Callable
    columns: Callable
    evaluate: Callable


def column_units(columns) -> dict:
    """SI unit string of each result column (``"1"`` dimensionless, ``""`` flags)."""
    out = {}
    for c in columns:
        unit = _UNITS.get(c)
        if unit is None:
            unit = next((u for p, u in _PREFIX_UNITS.items() if c.startswith(p)), "")
        out[c] = unit
    return out


def _missing(axes, given, sec, key):
    return key not in axes and (sec, key) not in given


def _col(rows, name):
    return rows[name].to_numpy(float)


def _engine_column(frame, prefix, value):
    """The engine's column for ``value`` (column_name; the engines' former %g spelling)."""
    name = column_name(prefix, value)
    if name in frame:
        return name
    legacy = f"{prefix}_{float(value):g}"
    if legacy in frame:
        return legacy
    raise RuntimeError(f"engine returned no column {name!r} (columns: {list(frame.columns)})")


def _out_of_table_errors(tables, rows, oot):
    err = np.full(len(rows), "", dtype=object)
    if np.any(oot):
        lo, hi = tables.p_range
        pb = _col(rows, "p0") / _col(rows, "E_star")
        for i in np.flatnonzero(oot):
            err[i] = (f"out_of_table: p0/E_star = {pb[i]:.6g} is outside the tables' range "
                      f"[{lo:.6g}, {hi:.6g}]")
    return err


#: why a squeeze row whose engine status is below has NaN outputs
_BELOW_MESSAGE = ("start_below_equilibrium: u_start <= u_inf (the film starts at or below its "
                  "equilibrium separation: nothing to squeeze out)")


#: why a squeeze row whose engine status is "overflow" has times of 0 or inf
_OVERFLOW_MESSAGE = ("overflow: tau0 = 3 eta R^2/(2 h_rms^2 p0) or a time is not representable "
                     "in float64 (e.g. R = 1e-300 m or 1e308 m): its times are not results")


def _below_errors(status, err):
    """``err`` with the rows of engine status "start_below_equilibrium" and "overflow"
    explained."""
    st = np.asarray(status, dtype=object)
    err = np.where((st == "start_below_equilibrium") & (err == ""), _BELOW_MESSAGE, err)
    return np.where((st == "overflow") & (err == ""), _OVERFLOW_MESSAGE, err)


# =========================================================================== squeeze
def squeeze_columns(ratios, du, times) -> list:
    """Result columns of a squeeze study: the engine's catalogue without the inputs it echoes."""
    return [c for c in squeeze_engine_columns(ratios, du, times) if c not in _SQUEEZE_INPUTS]


def _squeeze_infer(axes, fixed, given, problems):
    if _missing(axes, given, "geometry", "R"):
        problems.append("geometry.R is missing: the block radius, e.g. R = \"2 cm\"")
    _ext.check("squeeze", axes, fixed, given, problems)


def _squeeze_evaluate(tables, rows, theory, fixed, columns, scale=1.0):
    if "alpha_pv" in rows:                                  # issue 14: Barus fluid
        return _ext.squeeze_evaluate(tables, rows, theory, fixed, columns, scale, _squeeze_base)
    return _squeeze_base(tables, rows, theory, fixed, columns, scale)


def _squeeze_base(tables, rows, theory, fixed, columns, scale=1.0):
    ratios = [r for r in fixed["ratios"] if column_name("t_ratio", r) in columns]
    du = [d for d in fixed["du"] if column_name("t_du", d) in columns]
    times = [t for t in fixed["times"] if column_name("u_at", t) in columns]
    sq = squeeze_out(tables, p0=_col(rows, "p0"), E_star=_col(rows, "E_star"), R=_col(rows, "R"),
                     eta=_col(rows, "eta"), theory=theory,
                     u_start=_col(rows, "u_start") if "u_start" in rows else None,
                     ratios=tuple(ratios) if ratios else (1.01,), du=tuple(du),
                     times=tuple(times),
                     method=squeeze_method(round(len(rows) * scale))).reset_index(drop=True)
    if len(sq) != len(rows):
        raise RuntimeError(f"squeeze_out returned {len(sq)} rows for {len(rows)} cases")
    out = {name: sq[name].to_numpy() for name in ("u_start", "u_inf", "t_star", *SQUEEZE_TAIL)
           if name in columns}
    for prefix, vals in (("t_ratio", ratios), ("t_du", du), ("u_at", times)):
        for v in vals:
            out[column_name(prefix, v)] = sq[_engine_column(sq, prefix, v)].to_numpy()
    out["_error"] = _below_errors(sq["status"], _out_of_table_errors(
        tables, rows, sq["out_of_table"].to_numpy(bool)))
    return out


# =========================================================================== tire
def _tire_infer(axes, fixed, given, problems):
    _squeeze_infer(axes, fixed, given, problems)
    for k in ("footprint_length", "speed"):
        if _missing(axes, given, "study", k):
            problems.append(f"study.{k} is missing (tire study)")
    if _missing(axes, given, "study", "u_start"):
        axes["u_start"] = [KINDS["tire"].defaults["u_start"]]
    if _missing(axes, given, "fluid", "rho"):
        axes["rho"] = [KINDS["tire"].defaults["rho"]]


def _tire_evaluate(tables, rows, theory, fixed, columns, scale=1.0):
    df = tire_footprint(tables, p0=_col(rows, "p0"), E_star=_col(rows, "E_star"), R=_col(rows, "R"),
                        eta=_col(rows, "eta"), footprint_length=_col(rows, "footprint_length"),
                        speed=_col(rows, "speed"), rho=_col(rows, "rho"), theory=theory,
                        pressure_profile=fixed["pressure_profile"],
                        pressure_model=fixed["pressure_model"], u_start=_col(rows, "u_start"),
                        du_complete=fixed["du_complete"], ratios=fixed["ratios"],
                        columns=list(dict.fromkeys(list(columns) + ["out_of_table", "status"])),
                        **_ext.tire_kwargs(rows))
    out = {c: df[c].to_numpy() for c in columns}
    out["_error"] = _below_errors(df["status"], _out_of_table_errors(
        tables, rows, df["out_of_table"].to_numpy(bool)))
    return out


# =========================================================================== seal
def _seal_infer(axes, fixed, given, problems):
    _ext.check("seal", axes, fixed, given, problems)
    hertz = fixed.get("profile") == "hertz"
    if _missing(axes, given, "study", "dp"):
        problems.append("study.dp is missing (seal study): the pressure difference")
    for k in (("L_y",) if hertz else ("L", "L_y")):
        if _missing(axes, given, "geometry", k):
            problems.append(f"geometry.{k} is missing (seal study)")
    for k in ("p_b", "alpha_cj"):
        if _missing(axes, given, "study", k):
            axes[k] = [KINDS["seal"].defaults[k]]
    if hertz:
        for k, sec in (("R", "geometry"), ("f_N", "study")):
            if _missing(axes, given, sec, k):
                problems.append(f"{sec}.{k} is missing: profile = 'hertz' needs the O-ring "
                                f"radius R and the load per unit length f_N")
        for k, sec in (("p0", "study"), ("L", "geometry")):
            if (sec, k) in given:
                problems.append(f"{sec}.{k}: not used with profile = 'hertz' (the Hertz "
                                f"contact sets the pressure profile and the width 2a)")
    elif ("geometry", "R") in given:
        problems.append("geometry.R: only used by a seal with profile = 'hertz'")
    elif ("study", "f_N") in given:
        problems.append("study.f_N: only used with profile = 'hertz'")


def _seal_columns(fixed):
    return list(SEAL_COLUMNS) + (list(SEAL_HERTZ_COLUMNS) if fixed.get("profile") == "hertz"
                                 else [])


def _seal_evaluate(tables, rows, theory, fixed, columns, scale=1.0):
    return _ext.seal_evaluate(tables, rows, theory, fixed, columns, _seal_base)


def _seal_base(tables, rows, theory, fixed, columns, **ext):
    kw = dict(dp=_col(rows, "dp"), L_y=_col(rows, "L_y"), E_star=_col(rows, "E_star"),
              eta=_col(rows, "eta"), theory=theory, alpha_cj=_col(rows, "alpha_cj"),
              p_b=_col(rows, "p_b"), profile=fixed.get("profile", "uniform"))
    if fixed.get("profile") == "hertz":
        kw.update(R=_col(rows, "R"), f_N=_col(rows, "f_N"))
    else:
        kw.update(p0=_col(rows, "p0"), L=_col(rows, "L"))
    from ..seal import seal_leak   # here: a squeeze run never imports the seal engine
    df = seal_leak(tables, **kw, **ext).reset_index(drop=True)
    if len(df) != len(rows):
        raise RuntimeError(f"seal_leak returned {len(df)} rows for {len(rows)} cases")
    out = {c: df[c].to_numpy() if c in df else np.full(len(df), np.nan) for c in columns}
    err = np.full(len(rows), "", dtype=object)
    if "converged" in df:
        err[~df["converged"].to_numpy(bool)] = "seal solver did not converge (see error_estimate)"
    out["_error"] = err
    return out


_RATIOS = (1.1, 1.01, 1.001)
KINDS = {
    "squeeze": StudyKind(
        "squeeze", {"theory": DEFAULT_THEORY, "ratios": _RATIOS, "du": (1e-6,), "times": ()},
        ("u_of_t", "t_star"), _squeeze_infer,
        lambda fixed: squeeze_columns(fixed.get("ratios", _RATIOS), fixed.get("du", (1e-6,)),
                                      fixed.get("times", ())),
        _squeeze_evaluate),
    "tire": StudyKind(
        "tire", {"theory": DEFAULT_THEORY, "ratios": _RATIOS, "pressure_profile": "uniform",
                 "pressure_model": "mean", "du_complete": 1e-6, "u_start": 1e-2, "rho": 1000.0},
        ("u_of_t", "du_of_t"), _tire_infer,
        lambda fixed: list(tire_columns(fixed.get("ratios", _RATIOS))), _tire_evaluate),
    "seal": StudyKind(
        "seal", {"theory": DEFAULT_THEORY, "p_b": 0.0, "profile": "uniform",
                 "alpha_cj": 1.0},
        ("leak_rate", "profiles"), _seal_infer, _seal_columns, _seal_evaluate),
    "asperity": StudyKind(                                  # issue 14: asperity cascade
        "asperity", dict(_ext.ASPERITY_DEFAULTS), (), _ext.asperity_infer,
        _ext.asperity_columns, _ext.asperity_evaluate),
}


def available_columns(kind, fixed) -> list:
    """Result columns a study of ``kind`` can produce with the study parameters ``fixed``."""
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r} is invalid: must be one of {', '.join(KINDS)}")
    return KINDS[kind].columns(fixed)
