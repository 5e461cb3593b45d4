"""Evaluating a block of cases on one surface's tables, one row per case, never all-or-nothing."""
from __future__ import annotations

import numpy as np
import pandas as pd

from .kinds import BOOL_COLUMNS, KINDS, column_units

__all__ = ["evaluate_cases", "empty_results"]

_ROW_ERRORS = (ValueError, RuntimeError, ArithmeticError)


def _tidy(a, name=None):
    """Object array of results → float, bool or nullable-boolean array where possible."""
    missing = np.asarray(pd.isna(a), bool)
    if name in BOOL_COLUMNS:
        if not missing.any():
            return a.astype(bool)
        out = pd.array(np.zeros(len(a), bool), dtype="boolean")
        out[~missing] = a[~missing].astype(bool)
        out[missing] = pd.NA
        return out
    present = a[~missing]
    if present.size and all(isinstance(v, (bool, np.bool_)) for v in present):
        if not missing.any():
            return a.astype(bool)
        return np.array([None if m else bool(v) for v, m in zip(a, missing)], dtype=object)
    try:
        return a.astype(float)
    except (TypeError, ValueError):
        return a


def _one_by_one(engine, tables, rows, idx, theory, fixed, columns, res, err, scale):
    """Evaluate the cases ``idx`` one at a time (a failed group): errors stay per row."""
    for k, i in enumerate(idx):
        row = rows.iloc[[k]].reset_index(drop=True)
        try:
            out = engine(tables, row, theory, fixed, columns, scale)
            for c in columns:
                res[c][i] = np.ravel(out[c])[0]
            if "_error" in out:
                err[i] = np.ravel(out["_error"])[0]
        except _ROW_ERRORS as exc:
            err[i] = f"{type(exc).__name__}: {exc}"


def evaluate_cases(kind, tables, cases, fixed, columns, scale=1.0) -> pd.DataFrame:
    """Evaluate every case (rows of ``cases``) of a ``kind`` study on one surface's ``tables``.

    Parameters
    ----------
    kind : str
        ``"squeeze"``, ``"tire"`` or ``"seal"``.
    tables : fastcontact.tables.Tables
    cases : pandas.DataFrame
        One row per case (:meth:`fastcontact.studies.scene.Scene.cases`), SI units.
    fixed : dict
        The study's non-axis parameters.
    columns : list of str
        Result columns wanted.
    scale : float
        Study size / ``len(cases)`` when ``cases`` is one block of a larger study (the engines
        choose size-dependent methods from the study's size, not the block's).

    Returns
    -------
    pandas.DataFrame
        Aligned with ``cases``: ``columns`` (those not already input columns) plus ``error``
        (``""`` where the case evaluated, else the engine's message and NaN results);
        ``attrs["units"]`` gives the SI unit of every column. Cases are grouped by theory and
        evaluated vectorised; a group that fails is retried case by case.
    """
    engine = KINDS[kind].evaluate
    n = len(cases)
    res = {c: np.full(n, np.nan, dtype=object) for c in columns}
    err = np.full(n, "", dtype=object)
    cases = cases.reset_index(drop=True)
    for theory, idx in cases.groupby("theory", sort=False).indices.items():
        rows = cases.iloc[idx].reset_index(drop=True)
        try:
            out = engine(tables, rows, theory, fixed, columns, scale)
        except Exception:  # noqa: BLE001 - fall back to one case at a time (errors kept per row)
            _one_by_one(engine, tables, rows, idx, theory, fixed, columns, res, err, scale)
            continue
        for c in columns:
            res[c][idx] = out[c]
        if "_error" in out:
            err[idx] = out["_error"]
    # an output that is also an input column (e.g. u_start given in the scene) is not repeated
    df = pd.DataFrame({c: _tidy(res[c], c) for c in columns if c not in cases.columns})
    df["error"] = pd.Series(err, dtype=str)
    df.attrs["units"] = column_units(df.columns)
    return df


def empty_results(columns, n, exclude=()) -> pd.DataFrame:
    """Typed all-missing result columns (NaN floats, NA booleans) for ``n`` failed cases."""
    df = pd.DataFrame({c: (pd.array([None] * n, dtype="boolean") if c in BOOL_COLUMNS
                           else np.full(n, np.nan)) for c in columns if c not in exclude})
    df.attrs["units"] = column_units(df.columns)
    return df
