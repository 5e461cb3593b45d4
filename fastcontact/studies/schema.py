"""The scene schema: every key a scene may hold, its dimension, bounds and study kinds."""
from __future__ import annotations

import dataclasses
import difflib

from .._core.units import SI_UNITS, parse_quantity
from .._core.vocab import CONVENTIONS, DEFAULT_THEORY

__all__ = ["STUDY_KINDS", "Key", "SCHEMA", "SURFACE_KEYS", "TOP_KEYS", "AXIS_KEYS", "RANGE_KEYS",
           "SELF_AFFINE_KEYS", "MAX_CASES", "did_you_mean", "input_units", "parse_scalar",
           "check_bounds", "try_parse"]

STUDY_KINDS = ("squeeze", "tire", "seal", "asperity")
#: largest study (cases x surfaces) a scene may ask for unless ``[outputs] max_cases`` or
#: ``fastcontact run --max-cases`` raises it; counted before anything is allocated
MAX_CASES = 20_000_000


@dataclasses.dataclass(frozen=True)
class Key:
    """One scene key.

    Parameters
    ----------
    kind : str
        ``"num"``, ``"str"``, ``"choice"``, ``"list_num"``, ``"profile"``, ``"theory"``,
        ``"strlist"``.
    dim : str
        Dimension of a numeric key (see :data:`fastcontact._core.units.DIMENSIONS`).
    axis : bool
        Whether the key may be a list or range (a sweep axis).
    studies : tuple of str
        Study kinds that use the key.
    lo, hi : float or None
        Bounds (inclusive unless ``lo_open`` / ``hi_open``).
    choices : tuple
        Allowed strings of a ``"choice"`` key.
    """

    kind: str
    dim: str = "dimensionless"
    axis: bool = False
    studies: tuple = STUDY_KINDS
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple = ()
    doc: str = ""


_K = Key
SCHEMA = {
    "study": {
        "kind": _K("choice", choices=STUDY_KINDS, doc="study kind"),
        "theory": _K("theory", axis=True,
                     doc=f"flow-conductivity theory (default {DEFAULT_THEORY!r})"),
        "p0": _K("num", "pressure", axis=True, lo=0, lo_open=True, doc="nominal pressure"),
        "u_start": _K("num", "length", axis=True, studies=("squeeze", "tire"), lo=0,
                      lo_open=True, doc="initial mean separation"),
        "ratios": _K("list_num", studies=("squeeze", "tire"), lo=1, lo_open=True,
                     doc="ū/ū∞ targets"),
        "du": _K("list_num", "length", studies=("squeeze",), lo=0, lo_open=True,
                 doc="Δu targets"),
        "times": _K("list_num", "time", studies=("squeeze",), lo=0, lo_open=True,
                    doc="times for ū(t)"),
        "footprint_length": _K("num", "length", axis=True, studies=("tire",), lo=0,
                               lo_open=True),
        "speed": _K("num", "velocity", axis=True, studies=("tire",), lo=0, lo_open=True),
        "pressure_profile": _K("profile", studies=("tire",)),
        "pressure_model": _K("choice", studies=("tire",), choices=("mean", "peak")),
        "du_complete": _K("num", "length", studies=("tire",), lo=0, lo_open=True),
        "dp": _K("num", "pressure", axis=True, studies=("seal",), lo=0),
        "p_b": _K("num", "pressure", axis=True, studies=("seal",), lo=0),
        "profile": _K("choice", studies=("seal",), choices=("uniform", "hertz")),
        "f_N": _K("num", "force_per_length", axis=True, studies=("seal",), lo=0, lo_open=True),
        "alpha_cj": _K("num", axis=True, studies=("seal",), lo=0, lo_open=True,
                       doc="critical-junction factor on u1 (σ scales with α_cj³)"),
        # issue 14 extensions (a scene that does not name them computes nothing extra)
        "alpha_pv": _K("num", "inverse_pressure", axis=True, studies=("squeeze", "tire", "seal"),
                       lo=0, doc="pressure–viscosity coefficient α (Barus; Roelands: initial "
                       "slope), η = η0 exp(α p_f)"),
        "viscosity": _K("choice", studies=("seal",), choices=("barus", "roelands"),
                        doc="pressure–viscosity law of alpha_pv"),
        "roelands_z": _K("num", axis=True, studies=("seal",), lo=0,
                         doc="Roelands pressure–viscosity index Z (default: from alpha_pv)"),
        "roelands_p_r": _K("num", "pressure", studies=("seal",), lo=0, lo_open=True,
                           doc="Roelands reference pressure (default 1/5.1e-9 Pa)"),
        "roelands_eta_inf": _K("num", "viscosity", studies=("seal",), lo=0, lo_open=True,
                               doc="Roelands limiting viscosity (default exp(-9.67) Pa s)"),
        "direction": _K("choice", studies=("seal",), choices=("x", "y"),
                        doc="flow along ('x') or across ('y') the long correlation length "
                            "(tables.anisotropy)"),
        "level_ratio": _K("num", studies=("asperity",), lo=1, lo_open=True,
                          doc="ratio of successive magnification levels (asperity cascade)"),
        "zeta_max": _K("num", studies=("asperity",), lo=1,
                       doc="highest magnification level (default ζ1/10)"),
    },
    "material": {
        "E": _K("num", "pressure", axis=True, lo=0, lo_open=True),
        "nu": _K("num", axis=True, lo=0, hi=0.5),
        "E_star": _K("num", "pressure", axis=True, lo=0, lo_open=True),
        "E2": _K("num", "pressure", axis=True, lo=0, lo_open=True),
        "nu2": _K("num", axis=True, lo=0, hi=0.5),
        "name": _K("str"),
    },
    "fluid": {
        "eta": _K("num", "viscosity", axis=True, lo=0, lo_open=True),
        "rho": _K("num", "density", axis=True, lo=0, lo_open=True),
        "name": _K("str"),
    },
    "geometry": {
        "R": _K("num", "length", axis=True, lo=0, lo_open=True),
        "L": _K("num", "length", axis=True, studies=("seal",), lo=0, lo_open=True),
        "L_y": _K("num", "length", axis=True, studies=("seal",), lo=0, lo_open=True),
    },
    "tables": {
        "gamma": _K("num", lo=0, hi=1, lo_open=True),
        "a_perc": _K("num", lo=0, hi=1, lo_open=True, hi_open=True),
        "alpha_cj": _K("num", lo=0, lo_open=True),
        "cache_dir": _K("str"),
        "calibration": _K("str", doc="calibration TOML file (fastcontact bem calibrate), "
                          "relative to the scene: sets gamma, a_perc, alpha_cj, emt_threshold"),
        "anisotropy": _K("num", lo=1, doc="Peklenik number γ_T = ξ_x/ξ_y >= 1 of the tables "
                         "(issue 14; 1 = isotropic; needs theory 'emt')"),
    },
    "outputs": {
        "columns": _K("strlist"),
        "figures": _K("strlist"),
        "max_cases": _K("num", lo=1, doc="largest study allowed (default MAX_CASES)"),
    },
    "sweep": {
        "combine": _K("choice", choices=("product", "zip")),
    },
}
SELF_AFFINE_KEYS = ("h_rms", "hurst", "q0", "q1", "q_roll")
SURFACE_KEYS = {
    "table": _K("str"), "psd": _K("str"), "convention": _K("choice", choices=tuple(CONVENTIONS)),
    "h_rms": _K("num", "length", lo=0, lo_open=True),
    "hurst": _K("num", lo=0, hi=1, lo_open=True, hi_open=True),
    "q0": _K("num", "wavevector", lo=0, lo_open=True),
    "q1": _K("num", "wavevector", lo=0, lo_open=True),
    "q_roll": _K("num", "wavevector", lo=0, lo_open=True),
    "label": _K("str"),
}
TOP_KEYS = ("title", "description", "study", "surfaces", *[s for s in SCHEMA if s != "study"])
#: every axis parameter (case column name → section), in schema order
AXIS_KEYS = {k: sec for sec, keys in SCHEMA.items() for k, spec in keys.items() if spec.axis}
RANGE_KEYS = ("start", "stop", "num", "log")


def input_units() -> dict:
    """SI unit of every axis column of the cases (``"1"`` for dimensionless, ``""`` for text)."""
    out = {}
    for sec, keys in SCHEMA.items():
        for k, spec in keys.items():
            if spec.axis:
                out[k] = SI_UNITS[spec.dim] if spec.kind == "num" else ""
    out.update(E_star="Pa", case_id="", surface="", surface_id="", error="")
    return out


def did_you_mean(word, choices) -> str:
    """`` (did you mean 'x'?)`` for the closest choice, else `` (allowed: ...)``."""
    choices = [str(c) for c in choices]
    close = difflib.get_close_matches(str(word), choices, n=1, cutoff=0.5)
    if not close:   # "Radius" → "R", "viscosity_eta" → "eta": prefix/containment, any case
        w = str(word).lower()
        close = [c for c in choices if w.startswith(c.lower()) or (len(c) > 2 and c.lower() in w)]
        close.sort(key=len, reverse=True)
    if close:
        return f" (did you mean {close[0]!r}?)"
    return f" (allowed: {', '.join(map(str, choices))})"


def check_bounds(key, x, spec):
    """Raise ValueError naming ``key`` if ``x`` is outside the bounds of ``spec``."""
    lo_ok = spec.lo is None or (x > spec.lo if spec.lo_open else x >= spec.lo)
    hi_ok = spec.hi is None or (x < spec.hi if spec.hi_open else x <= spec.hi)
    if not (lo_ok and hi_ok):
        parts = []
        if spec.lo is not None:
            parts.append(f"{'>' if spec.lo_open else '>='} {spec.lo:g}")
        if spec.hi is not None:
            parts.append(f"{'<' if spec.hi_open else '<='} {spec.hi:g}")
        raise ValueError(f"{key} = {x!r}: must be {' and '.join(parts)}"
                         + ("" if spec.dim == "dimensionless" else " [SI]"))


def parse_scalar(key, value, spec):
    """SI float of ``value`` for the key ``spec`` (unit, dimension and bounds checked)."""
    x = parse_quantity(key, value, spec.dim)
    check_bounds(key, x, spec)
    return x


def try_parse(problems, fn, *args):
    """fn(*args), or None with the ValueError's message appended to ``problems``."""
    try:
        return fn(*args)
    except ValueError as exc:
        problems.append(str(exc))
        return None
