"""Input validation shared by every public function: type, units, range — in one line.

Every check raises ``ValueError`` whose one-line message names the parameter, the offending
value, the valid range and the unit, e.g.
``E_star = -1.0 is invalid: must be a finite number > 0 [Pa]``.

What a numeric parameter accepts
--------------------------------
* real numbers and arrays of real numbers (Python, NumPy, pandas) — in SI units;
* objects that carry units (pint ``Quantity``; anything with ``.magnitude``/``.units`` and
  ``.to``, or astropy/unyt-like ``.unit``/``.units`` with ``.to``/``.value``): converted to the
  parameter's SI unit, or refused when the dimension is wrong or the expected unit is not
  known — never stripped. pint is never imported here (duck typing);
* masked arrays without masked elements (a masked element is refused, never unmasked).

Refused by name: booleans (``True`` is not 1.0), ``np.bool_``, dates, times and timedeltas,
complex numbers, strings, ``None``, missing values (``pd.NA``) and other objects.
"""
from __future__ import annotations

import datetime as _dt
import decimal
import math
import numbers
import re

import numpy as np

__all__ = ["as_float_array", "check_positive", "check_range", "check_finite", "check_int",
           "check_choice", "align_inputs", "unit_label"]

#: SI unit (as written in the brackets of a ``unit`` argument) → (pint spelling, astropy spelling)
_SI = {
    "Pa": ("Pa", "Pa"), "m": ("m", "m"), "1/m": ("1/m", "1 / m"), "N/m": ("N/m", "N / m"),
    "Pa·s": ("Pa*s", "Pa s"), "Pa s": ("Pa*s", "Pa s"), "Pa*s": ("Pa*s", "Pa s"),
    "kg/m^3": ("kg/m**3", "kg / m3"), "m/s": ("m/s", "m / s"), "m^3/s": ("m**3/s", "m3 / s"),
    "m^2": ("m**2", "m2"), "m^3": ("m**3", "m3"), "m^4": ("m**4", "m4"), "s": ("s", "s"),
    "N": ("N", "N"), "J": ("J", "J"), "K": ("K", "K"), "1/s": ("1/s", "1 / s"),
    "1/Pa": ("1/Pa", "1 / Pa"), "Pa^-1": ("1/Pa", "1 / Pa"), "m^2/s": ("m**2/s", "m2 / s"),
    "kg": ("kg", "kg"), "W": ("W", "W"), "1/K": ("1/K", "1 / K"), "rad": ("rad", "rad"),
    "-": ("dimensionless", ""), "": ("dimensionless", ""),
}
#: exact types taken without further checks (bool is not among them)
_FAST_SCALARS = frozenset({float, int, np.float64, np.float32, np.float16, np.int64, np.int32,
                           np.int16, np.int8, np.uint64, np.uint32, np.uint16, np.uint8})
_BRACKET = re.compile(r"\[([^\]]*)\]")
_MAX_SHOWN = 80


# ============================================================================ formatting
def unit_label(unit: str) -> str:
    """The unit as shown in messages: ``"Pa"`` and ``"[Pa]"`` both give ``"[Pa]"``."""
    unit = (unit or "").strip()
    if not unit or "[" in unit:
        return unit
    return f"[{unit}]"


def _short(text: str) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= _MAX_SHOWN else text[:_MAX_SHOWN - 3] + "..."


def _fmt(value) -> str:
    try:
        arr = np.asarray(value)
    except Exception:  # noqa: BLE001 - anything unprintable as an array
        return _short(repr(value))
    if arr.ndim == 0:
        if arr.dtype.kind in "fiu":
            return repr(arr.item())
        return _short(repr(value))
    if arr.dtype.kind in "fiu":
        flat = arr.ravel().astype(np.float64)
        fin = flat[np.isfinite(flat)]
        if fin.size:
            return f"array(shape={arr.shape}, min={float(fin.min())!r}, max={float(fin.max())!r})"
        return f"array(shape={arr.shape}, no finite value)"
    return _short(f"array(shape={arr.shape}, dtype={arr.dtype})")


def _fail(name: str, value, requirement: str, unit: str = "", bad=None) -> None:
    u = f" {unit_label(unit)}" if unit else ""
    shown = _fmt(value) if bad is None else repr(float(bad))
    raise ValueError(f"{name} = {shown} is invalid: must be {requirement}{u}")


def _refuse(name: str, value, why: str, unit: str = "") -> None:
    u = unit_label(unit)
    want = f"a real number or array of real numbers{(' in ' + u) if u else ''}"
    raise ValueError(f"{name} = {_short(repr(value))} is invalid: must be {want}; {why}")


# ============================================================================ units
def _expected_unit(unit: str):
    """(pint spelling, astropy spelling) of the SI unit named in ``unit``, or None when the
    unit is relative/unknown (e.g. ``"[h_rms]"``)."""
    unit = unit or ""
    m = _BRACKET.search(unit)
    key = (m.group(1) if m else unit).strip()
    return _SI.get(key)


def _unit_attr(value):
    """The units of a unit-carrying object, or None for plain data."""
    for attr in ("units", "unit"):
        try:
            u = getattr(value, attr, None)
        except Exception:  # noqa: BLE001 - a property that raises: not a quantity
            u = None
        if u is not None and hasattr(value, "to"):
            return u
    return None


def _strip_units(name: str, value, unit: str):
    """Magnitude of ``value`` in the SI unit named by ``unit`` (a unit-carrying object), or
    raise naming ``name``."""
    units = _unit_attr(value)
    target = _expected_unit(unit)
    if target is None:
        target = _SI["-"]
        hint = (f"only a dimensionless quantity can be taken here (the parameter is in units "
                f"of {unit_label(unit) or 'SI'}); pass a plain number")
    else:
        hint = f"its dimension must be that of {unit_label(unit) or '[-]'}"
    pint_like = hasattr(value, "magnitude")
    try:
        conv = value.to(target[0] if pint_like else target[1])
    except Exception as exc:  # noqa: BLE001 - DimensionalityError, UnitConversionError, ...
        raise ValueError(f"{name} = {_short(str(value))} is invalid: must be a number in "
                         f"{unit_label(unit) or 'SI'} or a quantity convertible to it; its units "
                         f"({_short(str(units))}) cannot be converted: {hint} "
                         f"({type(exc).__name__})") from None
    for attr in ("magnitude", "value", "v"):
        mag = getattr(conv, attr, None)
        if mag is not None:
            return mag
    raise ValueError(f"{name} = {_short(str(value))} is invalid: a quantity whose magnitude "
                     f"cannot be read; pass a plain number in {unit_label(unit) or 'SI'}")


# ============================================================================ types
_TIME_TYPES = (_dt.date, _dt.time, _dt.timedelta, np.datetime64, np.timedelta64)


def _element_problem(x):
    """Why the scalar ``x`` is not a real number, or None when it is."""
    if isinstance(x, (bool, np.bool_)):
        return "is a boolean, not a number (True is not 1.0)"
    if isinstance(x, _TIME_TYPES):
        return "is a date/time, not a number"
    if isinstance(x, (str, bytes)):
        return "is a string; pass a number (with units: a pint Quantity)"
    if isinstance(x, (complex, np.complexfloating)):
        return "is a complex number"
    if x is None:
        return "is a missing value (None)"
    if _unit_attr(x) is not None:
        return ("carries units inside a sequence; pass one quantity with an array magnitude "
                "(e.g. Q_([1, 2], 'MPa')) or plain numbers in SI")
    if isinstance(x, (numbers.Real, decimal.Decimal)):
        return None
    if type(x).__name__ in ("NAType", "NaTType"):
        return "is a missing value (pd.NA / NaT)"
    return f"is of type {type(x).__name__}, not a real number"


def _kind_problem(arr: np.ndarray):
    """Why an array of this dtype is not real numbers (phrased for a scalar or an array)."""
    what = {"b": ("a boolean", "booleans"), "M": ("a date/time", "dates/times"),
            "m": ("a timedelta", "timedeltas"), "c": ("a complex number", "complex numbers"),
            "U": ("a string", "strings"), "S": ("a byte string", "byte strings"),
            "V": ("a raw record", "raw records")}.get(arr.dtype.kind)
    if what is None:
        return None
    extra = " (True is not 1.0)" if arr.dtype.kind == "b" else ""
    return (f"it is {what[0]}, not a number{extra}" if arr.ndim == 0
            else f"it holds {what[1]}, not numbers{extra}")


def _plain(name: str, value, unit: str):
    """``value`` as plain numeric data (units converted, masks checked, types refused)."""
    if value is None:
        _refuse(name, value, "it is a missing value (None)", unit)
    if _unit_attr(value) is not None:
        value = _strip_units(name, value, unit)
    problem = None if isinstance(value, (np.ndarray, list, tuple)) else _element_problem(value)
    if problem is not None and not hasattr(value, "__array__") and not hasattr(value, "__len__"):
        _refuse(name, value, "it " + problem, unit)
    if isinstance(value, np.ma.MaskedArray):
        n_masked = int(np.ma.count_masked(value))
        if n_masked:
            first = np.argwhere(np.ma.getmaskarray(value))[0]
            raise ValueError(f"{name} = {_fmt(np.ma.getdata(value))} is invalid: must have no "
                             f"masked values; {n_masked} masked value(s), first at index "
                             f"{tuple(int(i) for i in first)}: fill or remove them (masks are "
                             f"never dropped silently)")
        value = np.ma.getdata(value)
    if isinstance(value, (list, tuple)):
        try:
            obj = np.asarray(value, dtype=object)
        except ValueError:
            _refuse(name, value, "a ragged sequence (rows of different lengths)", unit)
        for x in obj.ravel():
            if type(x) is float or type(x) is int:
                continue
            why = _element_problem(x)
            if why is not None:
                _refuse(name, value, f"element {_short(repr(x))} {why}", unit)
    try:
        arr = np.asarray(value)
    except Exception:  # noqa: BLE001 - a ragged nested sequence, an odd object
        _refuse(name, value, "cannot be read as an array of numbers", unit)
    why = _kind_problem(arr)
    if why is not None:
        _refuse(name, value, why, unit)
    if arr.dtype.kind == "O":
        for x in arr.ravel():
            w = _element_problem(x)
            if w is not None:
                _refuse(name, value, f"element {_short(repr(x))} {w}", unit)
    return arr


def as_float_array(name: str, value, unit: str = "", *, allow_nan: bool = True) -> np.ndarray:
    """``value`` as a contiguous float64 array, or raise ``ValueError`` naming ``name``.

    Parameters
    ----------
    name : str
        Parameter name shown in messages.
    value : array_like or quantity
        Real numbers in SI units, or a unit-carrying object (converted to ``unit``).
    unit : str, optional
        Expected SI unit, e.g. ``"[Pa]"`` or ``"Pa"``; ``"[-]"`` for dimensionless. Without
        it a unit-carrying value is refused unless it is dimensionless.
    allow_nan : bool, optional
        Accept NaN (default True: the numeric checks below decide).

    Returns
    -------
    numpy.ndarray
        float64, C-contiguous (a 0-d array for a scalar).
    """
    if type(value) in _FAST_SCALARS:                    # fast path: a plain real number
        arr = np.asarray(value, dtype=np.float64)
    elif type(value) is np.ndarray and value.dtype.kind in "fiu":
        arr = np.asarray(value, dtype=np.float64)
    else:
        raw = _plain(name, value, unit)
        try:
            arr = np.asarray(raw, dtype=np.float64)
        except (TypeError, ValueError, OverflowError):
            _refuse(name, value, "cannot be converted to floating point", unit)
    if arr.ndim and not arr.flags.c_contiguous:
        arr = np.ascontiguousarray(arr)
    if not allow_nan and np.isnan(arr).any():
        _fail(name, value, "a number (not NaN)", unit, bad=np.nan)
    return arr


def check_finite(name: str, value, unit: str = "") -> np.ndarray:
    """Every element finite; returns the float64 array (units converted to ``unit``)."""
    arr = as_float_array(name, value, unit)
    if not np.all(np.isfinite(arr)):
        bad = arr[~np.isfinite(arr)].ravel()[0]
        _fail(name, value, "finite", unit, bad=bad)
    return arr


def check_positive(name: str, value, unit: str = "", allow_zero: bool = False,
                   allow_inf: bool = False) -> np.ndarray:
    """Every element finite (unless ``allow_inf``) and > 0 (>= 0 with ``allow_zero``).

    ``unit`` names the SI unit (``"[Pa]"`` or ``"Pa"``): it is shown in messages and a
    unit-carrying value (pint Quantity, ...) is converted to it. Returns float64.
    """
    arr = as_float_array(name, value, unit)
    if arr.size:  # two reductions decide the usual case (NaN propagates through min and max)
        lo, hi = arr.min(), arr.max()
        if (lo >= 0.0 if allow_zero else lo > 0.0) and (allow_inf or hi < math.inf):
            return arr
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
    """Every element finite and within [lo, hi] (open ends as requested); float64."""
    arr = as_float_array(name, value, unit)
    if arr.size:  # two reductions decide the usual case (NaN propagates through min and max)
        a, b = arr.min(), arr.max()
        if (a > lo if lo_open else a >= lo) and (b < hi if hi_open else b <= hi) \
                and math.isfinite(a) and math.isfinite(b):
            return arr
    ok = np.isfinite(arr)
    ok &= (arr > lo) if lo_open else (arr >= lo)
    ok &= (arr < hi) if hi_open else (arr <= hi)
    if not np.all(ok):
        bad = arr[~ok].ravel()[0]
        interval = ("(" if lo_open else "[") + f"{lo:g}, {hi:g}" + (")" if hi_open else "]")
        _fail(name, value, f"in {interval}", unit, bad=bad)
    return arr


def check_int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """An integer (Python or NumPy, not bool, not float) within [lo, hi]."""
    ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if ok and (lo is None or value >= lo) and (hi is None or value <= hi):
        return int(value)
    rng = ("" if lo is None else f" >= {lo}") + ("" if hi is None else f" and <= {hi}")
    raise ValueError(f"{name} = {_short(repr(value))} is invalid: must be an integer{rng}")


def check_choice(name: str, value, choices):
    """``value`` if it is one of ``choices`` (compared with ==, strings exactly)."""
    for c in choices:
        if value is None or c is None:
            if value is c:
                return value
        elif isinstance(value, str) == isinstance(c, str) and \
                isinstance(value, (bool, np.bool_)) == isinstance(c, bool) and value == c:
            return c
    raise ValueError(f"{name} = {_short(repr(value))} is invalid: must be one of "
                     f"{list(choices)}")


# ============================================================================ pandas
def _is_series(x) -> bool:
    return hasattr(x, "index") and hasattr(x, "to_numpy") and getattr(x, "ndim", 0) == 1


def align_inputs(**named):
    """Pair pandas Series by index label, never by position.

    Parameters
    ----------
    **named
        The inputs of one call, by parameter name. Values that are not 1-D pandas objects
        are returned unchanged (NumPy broadcasting pairs them by position, as documented).

    Returns
    -------
    dict
        The same names; every Series reordered to the labels of the first Series.

    Raises
    ------
    ValueError
        When two Series hold different index labels, or duplicated labels (naming both
        parameters and the labels that differ).
    """
    series = [(k, v) for k, v in named.items() if _is_series(v)]
    if len(series) < 2:
        return dict(named)
    ref_name, ref = series[0]
    out = dict(named)
    for k, v in series:
        if not v.index.is_unique:
            raise ValueError(f"{k} is invalid: its pandas index has duplicated labels "
                             f"({_short(list(v.index[v.index.duplicated()][:5]))}); pairing by "
                             f"label would be ambiguous")
        if v.index.equals(ref.index):
            continue
        only_ref = ref.index.difference(v.index)
        only_k = v.index.difference(ref.index)
        if len(only_ref) or len(only_k):
            raise ValueError(
                f"{ref_name} and {k} are pandas Series whose index labels disagree (only in "
                f"{ref_name}: {_short(list(only_ref[:5]))}; only in {k}: "
                f"{_short(list(only_k[:5]))}): align them first (e.g. {ref_name}.align({k}, "
                f"join='inner')) or pass plain arrays to pair by position")
        out[k] = v.reindex(ref.index)
    return out
