"""Input validation shared by every public function.

Each check raises ``ValueError`` whose message names the parameter, the offending value
and the valid range, e.g. ``E_star = -1.0 is invalid: must be a finite number > 0 [Pa]``.
"""
from __future__ import annotations

import numpy as np

__all__ = ["as_float_array", "check_positive", "check_range", "check_finite"]


def _fmt(value) -> str:
    arr = np.asarray(value)
    if arr.ndim == 0:
        return repr(arr.item()) if arr.dtype.kind in "fiub" else repr(value)
    bad = arr.ravel()
    return f"array(shape={arr.shape}, min={np.nanmin(bad) if bad.size else 'n/a'}, max={np.nanmax(bad) if bad.size else 'n/a'})"


def _fail(name: str, value, requirement: str, unit: str = "", bad=None) -> None:
    u = f" {unit}" if unit else ""
    shown = _fmt(value) if bad is None else repr(float(bad))
    raise ValueError(f"{name} = {shown} is invalid: must be {requirement}{u}")


def as_float_array(name: str, value) -> np.ndarray:
    """Return ``value`` as a contiguous float64 array, or raise naming ``name``."""
    try:
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim and not arr.flags.c_contiguous:
            arr = np.ascontiguousarray(arr)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} is invalid: must be a real number or array of real numbers") from None
    return arr


def check_finite(name: str, value, unit: str = "") -> np.ndarray:
    arr = as_float_array(name, value)
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)].ravel()[0]
        _fail(name, value, "finite", unit, bad=bad)
    return arr


def check_positive(name: str, value, unit: str = "", allow_zero: bool = False,
                   allow_inf: bool = False) -> np.ndarray:
    """Every element finite (unless ``allow_inf``) and > 0 (>= 0 with ``allow_zero``)."""
    arr = as_float_array(name, value)
    ok = arr >= 0 if allow_zero else arr > 0
    if not allow_inf:
        ok &= np.isfinite(arr)
    ok &= ~np.isnan(arr)
    if not np.all(ok):
        bad = arr[~ok].ravel()[0]
        req = ("a finite number" if not allow_inf else "a number") + (" >= 0" if allow_zero else " > 0")
        _fail(name, value, req, unit, bad=bad)
    return arr


def check_range(name: str, value, lo: float, hi: float, unit: str = "",
                lo_open: bool = False, hi_open: bool = False) -> np.ndarray:
    """Every element finite and within [lo, hi] (open ends as requested)."""
    arr = as_float_array(name, value)
    ok = np.isfinite(arr)
    ok &= (arr > lo) if lo_open else (arr >= lo)
    ok &= (arr < hi) if hi_open else (arr <= hi)
    if not np.all(ok):
        bad = arr[~ok].ravel()[0]
        interval = ("(" if lo_open else "[") + f"{lo:g}, {hi:g}" + (")" if hi_open else "]")
        _fail(name, value, f"in {interval}", unit, bad=bad)
    return arr
