"""Unit strings: ``"0.2 MPa"``, ``"1 mPa s"``, ``"1000 kg/m^3"`` → SI floats.

A small explicit table of units (no eval, no pint needed). Conversion factors are exact
decimals, so ``"10 um"`` gives the double nearest to 1e-5. A value of the wrong dimension is
an error naming the key.
"""
from __future__ import annotations

import math
import re
from decimal import Decimal

__all__ = ["DIMENSIONS", "SI_UNITS", "UNIT_EXAMPLES", "UnitError", "parse_unit", "parse_quantity",
           "example_value"]

#: dimension vectors over (kg, m, s)
DIMENSIONS = {
    "pressure": (1, -1, -2), "length": (0, 1, 0), "wavevector": (0, -1, 0),
    "viscosity": (1, -1, -1), "density": (1, -3, 0), "time": (0, 0, 1),
    "velocity": (0, 1, -1), "force_per_length": (1, 0, -2), "dimensionless": (0, 0, 0),
    "inverse_pressure": (-1, 1, 2),
}
#: the SI unit string of each dimension (as written in result metadata)
SI_UNITS = {
    "pressure": "Pa", "length": "m", "wavevector": "1/m", "viscosity": "Pa s",
    "density": "kg/m^3", "time": "s", "velocity": "m/s", "force_per_length": "N/m",
    "dimensionless": "1", "inverse_pressure": "1/Pa",
}
#: units accepted for each dimension (for messages)
UNIT_EXAMPLES = {
    "pressure": "Pa, kPa, MPa, GPa, bar, psi", "length": "m, cm, mm, um, nm",
    "wavevector": "1/m, 1/mm, 1/um", "viscosity": "Pa s, mPa s, cP",
    "density": "kg/m^3, g/cm^3", "time": "s, ms, us, min", "velocity": "m/s, km/h",
    "force_per_length": "N/m, N/mm", "dimensionless": "no unit",
    "inverse_pressure": "1/Pa, 1/MPa, 1/GPa",
}
_EXAMPLE = {"pressure": "0.2 MPa", "length": "2 cm", "wavevector": "1e5 1/m",
            "viscosity": "1 mPa s", "density": "1000 kg/m^3", "time": "3 ms",
            "velocity": "30 m/s", "force_per_length": "1 N/mm", "dimensionless": "0.5",
            "inverse_pressure": "20 1/GPa"}

_D = Decimal
_BASE_UNITS = {
    "m": (_D(1), (0, 1, 0)), "s": (_D(1), (0, 0, 1)), "g": (_D("1e-3"), (1, 0, 0)),
    "Pa": (_D(1), (1, -1, -2)), "N": (_D(1), (1, 1, -2)), "bar": (_D("1e5"), (1, -1, -2)),
    "P": (_D("0.1"), (1, -1, -1)),            # poise (cP = 1 mPa s)
}
_EXACT_UNITS = {
    "min": (_D(60), (0, 0, 1)), "h": (_D(3600), (0, 0, 1)),
    "psi": (_D("6894.757293168361"), (1, -1, -2)), "1": (_D(1), (0, 0, 0)),
}
_PREFIXES = {"n": _D("1e-9"), "u": _D("1e-6"), "µ": _D("1e-6"), "μ": _D("1e-6"),
             "m": _D("1e-3"), "c": _D("1e-2"), "k": _D("1e3"), "M": _D("1e6"), "G": _D("1e9")}
_NUMBER = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*$")
_TOKEN = re.compile(r"^([A-Za-zµμ]+|1)(?:\^?([+-]?\d+)|([²³]))?$")


class UnitError(ValueError):
    """A unit string that cannot be read."""


def example_value(dim: str) -> str:
    """A typical value with a unit for dimension ``dim`` (for messages), e.g. ``"2 cm"``."""
    return _EXAMPLE[dim]


def _unit_token(tok):
    m = _TOKEN.match(tok)
    if not m:
        raise UnitError(f"cannot read unit {tok!r}")
    sym, exp, sup = m.group(1), m.group(2), m.group(3)
    power = int(exp) if exp else ({"²": 2, "³": 3}[sup] if sup else 1)
    if sym in _EXACT_UNITS:
        f, d = _EXACT_UNITS[sym]
    elif sym in _BASE_UNITS:
        f, d = _BASE_UNITS[sym]
    elif len(sym) > 1 and sym[0] in _PREFIXES and sym[1:] in _BASE_UNITS:
        f0, d = _BASE_UNITS[sym[1:]]
        f = _PREFIXES[sym[0]] * f0
    else:
        raise UnitError(f"unknown unit {sym!r}")
    return f ** power, tuple(power * x for x in d)


def parse_unit(text: str):
    """Factor to SI and dimension vector of a unit string.

    Parameters
    ----------
    text : str
        Unit such as ``"mPa s"``, ``"kg/m^3"``, ``"1/mm"`` (at most one ``/``; products by
        spaces, ``*`` or ``·``; powers as ``^3``, ``3`` or ``³``).

    Returns
    -------
    factor : decimal.Decimal
        Multiply a value in ``text`` units by this to get SI.
    dims : tuple of int
        Exponents of (kg, m, s).
    """
    text = text.replace("·", " ").replace("⋅", " ").replace("*", " ").strip()
    if text.count("/") > 1:
        raise UnitError(f"unit {text!r} has more than one '/'")
    num, slash, den = text.partition("/")
    factor, dims = _D(1), (0, 0, 0)
    for part, sign in ((num, 1), (den, -1)) if slash else ((num, 1),):
        toks = part.split()
        if sign == -1 and not toks:
            raise UnitError(f"unit {text!r} has nothing after '/'")
        for tok in toks:
            f, d = _unit_token(tok)
            factor *= f ** sign
            dims = tuple(a + sign * b for a, b in zip(dims, d))
    if slash and num.strip() == "":
        raise UnitError(f"unit {text!r} has nothing before '/' (write 1/{den.strip()})")
    return factor, dims


def parse_quantity(key: str, value, dim: str) -> float:
    """SI float of ``value``: a number (taken as SI) or a string with a unit.

    Parameters
    ----------
    key : str
        Name used in error messages (e.g. ``"geometry.R"``).
    value : int, float or str
        ``0.02`` or ``"2 cm"``. Booleans and other types are refused.
    dim : str
        One of :data:`DIMENSIONS`.

    Returns
    -------
    float
        The value in SI units (finite).

    Raises
    ------
    ValueError
        Naming ``key``, for non-numbers, unknown units, wrong dimensions, non-finite values.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError(f"{key} = {value!r}: must be a number"
                         + ("" if dim == "dimensionless" else
                            f" in SI units or a string with a unit ({UNIT_EXAMPLES[dim]})"))
    if isinstance(value, str):
        m = _NUMBER.match(value)
        if not m:
            raise ValueError(f"{key} = {value!r}: not a number with a unit "
                             f"(e.g. {example_value(dim)!r})")
        x, unit = _D(m.group(1)), m.group(2)
        if unit:
            try:
                factor, dims = parse_unit(unit)
            except UnitError as exc:
                raise ValueError(f"{key} = {value!r}: {exc} (a {dim.replace('_', ' ')} "
                                 f"takes {UNIT_EXAMPLES[dim]})") from None
            if dims != DIMENSIONS[dim]:
                raise ValueError(f"{key} = {value!r}: wrong unit {unit!r}, {key} is a "
                                 f"{dim.replace('_', ' ')} ({UNIT_EXAMPLES[dim]})")
            x *= factor
        x = float(x)
    else:
        x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{key} = {value!r}: must be finite")
    return x
