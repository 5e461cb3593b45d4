"""The issue-14 extensions in scenes: pressure-dependent viscosity, anisotropic tables, the
asperity cascade — checked at load time and evaluated beside the base engines.

A scene that names none of the keys below runs exactly the base engines (nothing extra is
computed, no column changes):

* ``[study] alpha_pv`` (axis, 1/Pa; squeeze, tire, seal) — Barus fluid; rows with α = 0 run
  the base engine, the others the reduced-pressure engines
  (:mod:`fastcontact.squeeze.viscosity`, :mod:`fastcontact.squeeze.tire_piezo`,
  :mod:`fastcontact.seal.viscosity`); columns those engines do not produce are NaN there.
* ``[study] viscosity = "roelands"`` with ``roelands_z`` (axis), ``roelands_p_r``,
  ``roelands_eta_inf`` (seal) — Roelands fluid, solved numerically.
* ``[tables] anisotropy`` (γ_T >= 1) — tables built with ``precompute(anisotropy=γ_T)``
  (recorded in their options, cache key and provenance); ``[study] direction = "x"|"y"``
  (seal) reads σ_xx or σ_yy. A direction on isotropic tables gives the isotropic result.
* ``kind = "asperity"`` with ``level_ratio``, ``zeta_max`` — the asperity-scale cascade
  (:func:`fastcontact.squeeze.asperity.asperity_summary`), one row per case.
"""
from __future__ import annotations

import numpy as np

from .._core.vocab import column_name

__all__ = ["check", "squeeze_evaluate", "seal_evaluate", "tire_kwargs", "ASPERITY_DEFAULTS",
           "asperity_infer", "asperity_columns", "asperity_evaluate"]

ROELANDS_KEYS = ("roelands_z", "roelands_p_r", "roelands_eta_inf")


def _given(axes, given, sec, key):
    return key in axes or (sec, key) in given


def check(kind, axes, fixed, given, problems):
    """Load-time checks of the extension keys of a ``kind`` study (appended to ``problems``)."""
    theories = list(axes.get("theory", ()))
    aniso = fixed.get("anisotropy", 1.0)
    if aniso is not None and aniso != 1.0 and theories and "emt" not in theories:
        problems.append(f"tables.anisotropy = {aniso!r}: the directional conductivities are the "
                        f"effective medium's; add 'emt' to study.theory (has {theories})")
    if fixed.get("direction") is not None and aniso not in (None, 1.0):
        bad = [t for t in theories if t == "critical_junction"]
        if bad:
            problems.append("study.direction: anisotropic tables hold directional conductivities "
                            "for theory 'emt' only ('average' has no direction); remove "
                            "'critical_junction' from study.theory")
    law = fixed.get("viscosity", "barus")
    named = [k for k in ROELANDS_KEYS if _given(axes, given, "study", k)]
    if law != "roelands" and named:
        problems.append(f"study.{named[0]}: only used with study.viscosity = 'roelands'")
    if law == "roelands" and not (_given(axes, given, "study", "alpha_pv")
                                  or _given(axes, given, "study", "roelands_z")):
        problems.append("study.viscosity = 'roelands' needs study.roelands_z (the pressure–"
                        "viscosity index) or study.alpha_pv (its initial slope)")


def _col(rows, name):
    return rows[name].to_numpy(float)


def _split(rows, mask, base, ext, columns):
    """Evaluate rows[~mask] with ``base`` and rows[mask] with ``ext`` (each rows → dict) and
    merge; a column one side does not produce is NaN there."""
    if not np.any(mask):
        return base(rows)
    if np.all(mask):
        parts = [(np.ones(len(rows), bool), ext(rows))]
    else:
        parts = [(~mask, base(rows[~mask].reset_index(drop=True))),
                 (mask, ext(rows[mask].reset_index(drop=True)))]
    out = {}
    for c in list(columns) + ["_error"]:
        full = np.full(len(rows), "" if c == "_error" else np.nan, dtype=object)
        for m, res in parts:
            if c in res:
                full[m] = np.asarray(res[c], dtype=object)
        out[c] = full
    return out


def _errors(status, message):
    err = np.full(len(status), "", dtype=object)
    err[np.asarray(status) == "piezo_limit"] = message
    return err


# =========================================================================== squeeze
def squeeze_evaluate(tables, rows, theory, fixed, columns, scale, base):
    """``base`` on rows without ``alpha_pv`` (or α = 0); the Barus engine on the others."""
    if "alpha_pv" not in rows:
        return base(tables, rows, theory, fixed, columns, scale)
    from ..squeeze.tire import squeeze_method
    from ..squeeze.viscosity import squeeze_out_piezo
    from .kinds import _below_errors, _out_of_table_errors

    def ext(r):
        ratios = tuple(x for x in fixed["ratios"] if column_name("t_ratio", x) in columns)
        du = tuple(d for d in fixed["du"] if column_name("t_du", d) in columns)
        times = tuple(t for t in fixed["times"] if column_name("u_at", t) in columns)
        sq = squeeze_out_piezo(tables, p0=_col(r, "p0"), E_star=_col(r, "E_star"),
                               R=_col(r, "R"), eta=_col(r, "eta"), alpha_pv=_col(r, "alpha_pv"),
                               theory=theory,
                               u_start=_col(r, "u_start") if "u_start" in r else None,
                               ratios=ratios, du=du, times=times,
                               method=squeeze_method(round(len(rows) * scale)))
        out = {c: sq[c].to_numpy() for c in columns if c in sq}
        err = _out_of_table_errors(tables, r, sq["out_of_table"].to_numpy(bool))
        pz = _errors(sq["status"], "piezo_limit: alpha_pv (p0 - p_cont) >= 1 at the start: "
                     "no quasi-static squeeze-out (rigid film cannot carry the load)")
        out["_error"] = _below_errors(sq["status"], np.where(pz != "", pz, err))
        return out

    mask = _col(rows, "alpha_pv") > 0.0
    return _split(rows, mask, lambda r: base(tables, r, theory, fixed, columns, scale), ext,
                  columns)


# =========================================================================== tire
def tire_kwargs(rows):
    """Extension keywords of ``tire_footprint`` for these rows (empty: none asked)."""
    return {"alpha_pv": _col(rows, "alpha_pv")} if "alpha_pv" in rows else {}


# =========================================================================== seal
def seal_evaluate(tables, rows, theory, fixed, columns, base):
    """``base(tables, rows, theory, fixed, columns, **kw)`` (the seal kind's evaluation) for
    rows with a constant viscosity, and with the η(p) keywords for the others; the scene's
    ``direction`` applies to both."""
    dkw = {"direction": fixed["direction"]} if fixed.get("direction") is not None else {}
    law = fixed.get("viscosity", "barus")
    has_a, has_z = "alpha_pv" in rows, "roelands_z" in rows
    if not (has_a or has_z):
        return base(tables, rows, theory, fixed, columns, **dkw)
    alpha = _col(rows, "alpha_pv") if has_a else np.zeros(len(rows))
    mask = alpha > 0.0
    if law == "roelands" and has_z:
        mask = _col(rows, "roelands_z") > 0.0
    extra = dict(dkw, viscosity=law)
    if law == "roelands":
        extra.update({k: fixed[k] for k in ("roelands_p_r", "roelands_eta_inf") if k in fixed})

    def ext(r):
        return base(tables, r, theory, fixed, columns,
                    alpha_pv=_col(r, "alpha_pv") if has_a else 0.0,
                    roelands_z=_col(r, "roelands_z") if has_z else None, **extra)

    return _split(rows, mask, lambda r: base(tables, r, theory, fixed, columns, **dkw), ext,
                  columns)


# =========================================================================== asperity
ASPERITY_DEFAULTS = {"theory": "emt", "level_ratio": 2.0}


def asperity_infer(axes, fixed, given, problems):
    """An asperity study needs the block radius R; level_ratio defaults to 2 (octaves)."""
    if "R" not in axes and ("geometry", "R") not in given:
        problems.append("geometry.R is missing: the block radius, e.g. R = \"2 cm\"")
    fixed.setdefault("level_ratio", ASPERITY_DEFAULTS["level_ratio"])
    check("asperity", axes, fixed, given, problems)


def asperity_columns(fixed):
    """Result columns of an asperity study (:func:`asperity_summary`)."""
    from ..squeeze.asperity import SUMMARY_UNITS
    return list(SUMMARY_UNITS)


def asperity_evaluate(tables, rows, theory, fixed, columns, scale=1.0):
    """One :func:`~fastcontact.squeeze.asperity.asperity_summary` call for the block."""
    from ..squeeze.asperity import asperity_summary
    df = asperity_summary(tables, p0=_col(rows, "p0"), E_star=_col(rows, "E_star"),
                          R=_col(rows, "R"), eta=_col(rows, "eta"), theory=theory,
                          level_ratio=fixed.get("level_ratio", 2.0),
                          zeta_max=fixed.get("zeta_max"))
    out = {c: df[c].to_numpy() for c in columns}
    err = np.full(len(df), "", dtype=object)
    err[df["out_of_table"].to_numpy(bool)] = "out_of_table: a level's pressure p(ζ) is beyond " \
                                             "its tables"
    out["_error"] = err
    return out
