"""Scenes: a complete study (surfaces, material, fluid, geometry, parameter grid, outputs)
described in a TOML file, validated up front and run end to end (``fastcontact run``).

A scene is plain data: it is parsed with :mod:`tomllib` and nothing in it is evaluated.

Schema
------
Top level: ``title``, ``description`` (strings) and the tables below. Every numeric value is
either an SI number or a string with a unit from a small explicit table (``"0.2 MPa"``,
``"2 cm"``, ``"1 mPa s"``, ``"30 m/s"``, ``"1000 kg/m^3"``; see :data:`UNIT_EXAMPLES`). A value of the
wrong dimension is an error naming the key.

``[study]``
    ``kind`` = ``"squeeze"`` | ``"tire"`` | ``"seal"`` (required); ``theory`` (any of
    ``"average"``, ``"critical_junction"``, ``"emt"``; default ``"average"`` for squeeze and tire,
    ``"critical_junction"`` for seal); ``p0`` nominal (applied) pressure.
    squeeze: ``u_start`` (initial ū, optional), ``ratios`` (ū/ū∞ for t_ratio columns),
    ``du`` (Δu values for t_du columns), ``times`` (times for u_at columns).
    tire: ``footprint_length``, ``speed``, ``pressure_profile`` (``"uniform"``,
    ``"parabolic"`` or a list of relative values at equally spaced stations),
    ``pressure_model`` (``"mean"`` | ``"peak"``), ``du_complete`` (default 1 µm), ``ratios``,
    ``u_start`` (default: 1 cm, the paper's u(0)).
    seal: ``dp`` (pressure difference p_a - p_b), ``p_b``, ``alpha_cj`` (junction factor,
    σ_cj ∝ α_cj³; the paper's experiment: 0.54), ``profile`` (``"uniform"``: needs ``p0`` and
    ``geometry.L`` | ``"hertz"``: needs ``geometry.R`` and ``f_N``, load per unit length;
    p0 and L then follow from the Hertz contact), ``geometry.L_y``.
``[surfaces.<name>]``
    exactly one of ``table = "file.parquet"`` (a table file: relative to the scene file, else
    one of the embedded default tables, see :func:`default_table_path`), ``psd = "file.csv"``
    with ``convention`` (``"persson"`` | ``"surface_topography"``), or self-affine parameters
    ``h_rms``, ``hurst``, ``q0``, ``q1`` [, ``q_roll``]; optional ``label``.
``[material]``
    ``E_star``, or ``E`` and ``nu`` (optionally a second solid ``E2``, ``nu2``).
``[fluid]``
    ``eta`` (required), ``rho`` (tire: default 1000 kg/m³), ``name``.
``[geometry]``
    ``R`` (block radius; squeeze, tire; O-ring radius for a Hertz seal), ``L`` (seal width),
    ``L_y`` (seal length).
``[tables]``
    ``gamma``, ``a_perc``, ``alpha_cj`` (options of :func:`fastcontact.tables.precompute`;
    a seal study takes α_cj in ``[study]``), ``cache_dir``.
``[outputs]``
    ``columns`` (result columns wanted, ``*`` patterns allowed; default all),
    ``figures`` (figure names wanted; default none).
``[sweep]``
    ``combine`` = ``"product"`` (default: every combination of the axes) | ``"zip"``.

Sweep axes: every parameter marked *axis* in :data:`AXIS_KEYS` may be a scalar, a list
(``p0 = ["0.1 MPa", "0.2 MPa"]``) or a range table ``{start, stop, num, log = true}``;
``theory`` may be a list. The cases are the product (or zip) of all axes, evaluated on every
surface.

Running (:func:`run_scene`) tabulates only the theories the study asks for, reuses tables from a
cache keyed by the surface fingerprint and the table options (atomic writes), computes only
the requested columns and figures, and writes ``results.parquet`` (scene and provenance in the
key-value metadata under ``fastcontact``), ``summary.txt``, ``build_record.json`` and
``figures/*.png``.
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import difflib
from decimal import Decimal
import fnmatch
import hashlib
import itertools
import json
import math
import os
import re
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

__all__ = [
    "SceneError", "Scene", "SurfaceSpec", "load_scene", "parse_quantity", "default_table_path",
    "example_scene_path", "list_example_scenes", "table_cache_dir", "obtain_tables",
    "run_scene", "evaluate_cases", "available_columns", "available_figures", "STUDY_KINDS",
    "PAPER_REFERENCE",
]

STUDY_KINDS = ("squeeze", "tire", "seal")
PAPER_REFERENCE = ("B. Lorenz and B.N.J. Persson, Fluid squeeze-out between solids with rough "
                   "surfaces, Eur. Phys. J. E 32, 281 (2010)")
THEORY_NAMES = ("average", "critical_junction", "emt")
CONVENTION_NAMES = ("persson", "surface_topography")


class SceneError(ValueError):
    """An invalid scene: ``problems`` lists every problem found (each names its key)."""

    def __init__(self, source, problems):
        self.source = str(source)
        self.problems = list(problems)
        n = len(self.problems)
        head = f"scene {self.source} is invalid ({n} problem{'s' if n != 1 else ''})"
        super().__init__(head + ": " + "; ".join(self.problems))


# =========================================================================== units
# dimension vectors over (kg, m, s)
DIMENSIONS = {
    "pressure": (1, -1, -2), "length": (0, 1, 0), "wavevector": (0, -1, 0),
    "viscosity": (1, -1, -1), "density": (1, -3, 0), "time": (0, 0, 1),
    "velocity": (0, 1, -1), "force_per_length": (1, 0, -2), "dimensionless": (0, 0, 0),
}
UNIT_EXAMPLES = {
    "pressure": "Pa, kPa, MPa, GPa, bar, psi", "length": "m, cm, mm, um, nm",
    "wavevector": "1/m, 1/mm, 1/um", "viscosity": "Pa s, mPa s, cP",
    "density": "kg/m^3, g/cm^3", "time": "s, ms, us, min", "velocity": "m/s, km/h",
    "force_per_length": "N/m, N/mm", "dimensionless": "no unit",
}
# factors are exact decimals, so that "10 um" is the double nearest to 1e-5
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
    pass


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


def parse_unit(text):
    """(factor to SI, dimension vector) of a unit string such as ``"mPa s"`` or ``"kg/m^3"``."""
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


# km/h is common for speeds: 'h' is an exact unit, 'km' prefixed metre
def parse_quantity(key, value, dim):
    """SI float of ``value`` (number, or string with a unit of dimension ``dim``).

    Raises ValueError naming ``key`` for non-numbers, unknown units and wrong dimensions.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError(f"{key} = {value!r}: must be a number"
                         + ("" if dim == "dimensionless" else
                            f" in SI units or a string with a unit ({UNIT_EXAMPLES[dim]})"))
    if isinstance(value, str):
        m = _NUMBER.match(value)
        if not m:
            raise ValueError(f"{key} = {value!r}: not a number with a unit "
                             f"(e.g. {_example(dim)!r})")
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


def _example(dim):
    return {"pressure": "0.2 MPa", "length": "2 cm", "wavevector": "1e5 1/m",
            "viscosity": "1 mPa s", "density": "1000 kg/m^3", "time": "3 ms",
            "velocity": "30 m/s", "force_per_length": "1 N/mm", "dimensionless": "0.5"}[dim]


# =========================================================================== schema
@dataclasses.dataclass(frozen=True)
class _Key:
    kind: str                      # "num", "str", "choice", "list_num", "profile", "theory", "bool"
    dim: str = "dimensionless"
    axis: bool = False
    studies: tuple = STUDY_KINDS   # study kinds that use the key
    lo: float | None = None        # bounds (inclusive unless *_open)
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple = ()
    doc: str = ""


_ALL = STUDY_KINDS
SCHEMA = {
    "study": {
        "kind": _Key("choice", choices=STUDY_KINDS, doc="study kind"),
        "theory": _Key("theory", axis=True, doc="flow-conductivity theory"),
        "p0": _Key("num", "pressure", axis=True, lo=0, lo_open=True, doc="nominal pressure"),
        "u_start": _Key("num", "length", axis=True, studies=("squeeze", "tire"), lo=0,
                        lo_open=True, doc="initial mean separation"),
        "ratios": _Key("list_num", studies=("squeeze", "tire"), lo=1, lo_open=True,
                       doc="ū/ū∞ targets"),
        "du": _Key("list_num", "length", studies=("squeeze",), lo=0, lo_open=True,
                   doc="Δu targets"),
        "times": _Key("list_num", "time", studies=("squeeze",), lo=0, lo_open=True,
                      doc="times for ū(t)"),
        "footprint_length": _Key("num", "length", axis=True, studies=("tire",), lo=0,
                                 lo_open=True),
        "speed": _Key("num", "velocity", axis=True, studies=("tire",), lo=0, lo_open=True),
        "pressure_profile": _Key("profile", studies=("tire",)),
        "pressure_model": _Key("choice", studies=("tire",), choices=("mean", "peak")),
        "du_complete": _Key("num", "length", studies=("tire",), lo=0, lo_open=True),
        "dp": _Key("num", "pressure", axis=True, studies=("seal",), lo=0),
        "p_b": _Key("num", "pressure", axis=True, studies=("seal",), lo=0),
        "profile": _Key("choice", studies=("seal",), choices=("uniform", "hertz")),
        "f_N": _Key("num", "force_per_length", axis=True, studies=("seal",), lo=0, lo_open=True),
        "alpha_cj": _Key("num", axis=True, studies=("seal",), lo=0, lo_open=True,
                         doc="critical-junction factor on u1 (σ scales with α_cj³)"),
    },
    "material": {
        "E": _Key("num", "pressure", axis=True, lo=0, lo_open=True),
        "nu": _Key("num", axis=True, lo=0, hi=0.5),
        "E_star": _Key("num", "pressure", axis=True, lo=0, lo_open=True),
        "E2": _Key("num", "pressure", axis=True, lo=0, lo_open=True),
        "nu2": _Key("num", axis=True, lo=0, hi=0.5),
        "name": _Key("str"),
    },
    "fluid": {
        "eta": _Key("num", "viscosity", axis=True, lo=0, lo_open=True),
        "rho": _Key("num", "density", axis=True, lo=0, lo_open=True),
        "name": _Key("str"),
    },
    "geometry": {
        "R": _Key("num", "length", axis=True, lo=0, lo_open=True),
        "L": _Key("num", "length", axis=True, studies=("seal",), lo=0, lo_open=True),
        "L_y": _Key("num", "length", axis=True, studies=("seal",), lo=0, lo_open=True),
    },
    "tables": {
        "gamma": _Key("num", lo=0, hi=1, lo_open=True),
        "a_perc": _Key("num", lo=0, hi=1, lo_open=True, hi_open=True),
        "alpha_cj": _Key("num", lo=0, lo_open=True),
        "cache_dir": _Key("str"),
    },
    "outputs": {
        "columns": _Key("strlist"),
        "figures": _Key("strlist"),
    },
    "sweep": {
        "combine": _Key("choice", choices=("product", "zip")),
    },
}
SURFACE_KEYS = {
    "table": _Key("str"), "psd": _Key("str"), "convention": _Key("choice", choices=CONVENTION_NAMES),
    "h_rms": _Key("num", "length", lo=0, lo_open=True),
    "hurst": _Key("num", lo=0, hi=1, lo_open=True, hi_open=True),
    "q0": _Key("num", "wavevector", lo=0, lo_open=True),
    "q1": _Key("num", "wavevector", lo=0, lo_open=True),
    "q_roll": _Key("num", "wavevector", lo=0, lo_open=True),
    "label": _Key("str"),
}
TOP_KEYS = ("title", "description", "study", "surfaces", *[s for s in SCHEMA if s != "study"])
#: every axis parameter (case column name → section)
AXIS_KEYS = {k: sec for sec, keys in SCHEMA.items() for k, spec in keys.items() if spec.axis}
RANGE_KEYS = ("start", "stop", "num", "log")

FIGURES = {
    "squeeze": ("u_of_t", "t_star"),
    "tire": ("u_of_t", "du_of_t"),
    "seal": ("leak_rate", "profiles"),
}
DEFAULTS = {
    "squeeze": {"theory": "average", "ratios": (1.1, 1.01, 1.001), "du": (1e-6,), "times": ()},
    "tire": {"theory": "average", "ratios": (1.1, 1.01, 1.001), "pressure_profile": "uniform",
             "pressure_model": "mean", "du_complete": 1e-6, "u_start": 1e-2, "rho": 1000.0},
    "seal": {"theory": "critical_junction", "p_b": 0.0, "profile": "uniform", "alpha_cj": 1.0},
}


def _did_you_mean(word, choices):
    choices = [str(c) for c in choices]
    close = difflib.get_close_matches(str(word), choices, n=1, cutoff=0.5)
    if not close:   # "Radius" → "R", "viscosity_eta" → "eta": prefix/containment, any case
        w = str(word).lower()
        close = [c for c in choices if w.startswith(c.lower()) or (len(c) > 2 and c.lower() in w)]
        close.sort(key=len, reverse=True)
    if close:
        return f" (did you mean {close[0]!r}?)"
    return f" (allowed: {', '.join(map(str, choices))})"


# =========================================================================== files
def _package_dir() -> Path:
    return Path(__file__).resolve().parent.parent


def default_table_path(name) -> Path:
    """Path of an embedded default table (``asphalt_072mm``, ``pmma_34um`` ...).

    Looks in the package data ``fastcontact/data/`` first, then the repository's ``tables/``
    folder. ``name`` may omit the ``.parquet`` suffix. Raises FileNotFoundError listing the
    available names.
    """
    name = str(name)
    if not name.endswith(".parquet"):
        name += ".parquet"
    if "/" in name or "\\" in name or name.startswith("."):
        raise FileNotFoundError(f"table {name!r} is not a default table name")
    dirs = [_package_dir() / "data", _package_dir().parent / "tables"]
    for d in dirs:
        p = d / name
        if p.is_file():
            return p
    avail = sorted({p.name for d in dirs if d.is_dir() for p in d.glob("*.parquet")})
    raise FileNotFoundError(f"table {name!r} is neither a file nor an embedded default table "
                            f"(available: {', '.join(avail) or 'none'})")


def list_example_scenes():
    """Names of the example scenes shipped in ``fastcontact/scenes``."""
    return sorted(p.stem for p in (_package_dir() / "scenes").glob("*.toml"))


def example_scene_path(name) -> Path:
    p = _package_dir() / "scenes" / (name if str(name).endswith(".toml") else f"{name}.toml")
    if not p.is_file():
        raise FileNotFoundError(f"scene {name!r} is neither a file nor a shipped example scene"
                                + _did_you_mean(name, list_example_scenes()))
    return p


def table_cache_dir(explicit=None) -> Path:
    """Table cache: ``explicit``, else $FASTCONTACT_CACHE_DIR, else ~/.cache/fastcontact/tables."""
    if explicit:
        return Path(explicit).expanduser()
    env = os.environ.get("FASTCONTACT_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "fastcontact" / "tables"


def _read_table_metadata(path):
    """The fastcontact metadata of a tables file (schema only; the data are not read)."""
    import pyarrow.parquet as pq
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
        raise ValueError(f"cannot read {str(path)!r} as Parquet ({type(exc).__name__})") from None
    raw = (schema.metadata or {}).get(b"fastcontact")
    if raw is None:
        raise ValueError(f"{str(path)!r} is not a fastcontact tables file (no metadata)")
    try:
        return json.loads(raw)
    except ValueError:
        raise ValueError(f"{str(path)!r} has corrupted fastcontact metadata") from None


# =========================================================================== scene
@dataclasses.dataclass
class SurfaceSpec:
    """One surface of a scene: a table file, a PSD file or self-affine parameters."""

    name: str
    source: str                 # "table" | "psd" | "self_affine" | "inline"
    path: Path | None = None
    convention: str | None = None
    params: dict = dataclasses.field(default_factory=dict)
    label: str | None = None
    psd_obj: object = None      # an already-built PSD (sweeps)

    def psd(self):
        """The surface's PSD (not for ``source == "table"``)."""
        if self.psd_obj is not None:
            return self.psd_obj
        if self.source == "self_affine":
            from ..surface.psd import SelfAffinePSD
            self.psd_obj = SelfAffinePSD(self.params["h_rms"], self.params["hurst"],
                                         self.params["q0"], self.params["q1"],
                                         self.params.get("q_roll"))
        elif self.source == "psd":
            from ..surface.topography import read_psd
            self.psd_obj = read_psd(self.path, self.convention)
        else:
            raise ValueError(f"surface {self.name!r} is given as a table file")
        return self.psd_obj

    def describe(self):
        if self.source == "table":
            return {"table": str(self.path)}
        if self.source == "psd":
            return {"psd": str(self.path), "convention": self.convention}
        if self.source == "self_affine":
            return {"self_affine": dict(self.params)}
        return {"inline": self.psd().to_dict()}


@dataclasses.dataclass
class Scene:
    """A validated scene (see the module docstring). Build with :func:`load_scene`."""

    source: str
    base_dir: Path
    text: str
    data: dict
    title: str
    kind: str
    surfaces: dict
    axes: dict           # axis name → list of values (SI floats; theory: strings)
    fixed: dict          # non-axis study parameters (ratios, du, times, profile ...)
    table_options: dict  # gamma, a_perc, alpha_cj (as given; defaults filled)
    table_options_given: dict
    cache_dir: str | None
    columns: list
    figures: list
    combine: str

    @property
    def theories(self):
        """The theories the study needs, in canonical order."""
        ths = set(self.axes["theory"])
        return tuple(t for t in THEORY_NAMES if t in ths)

    @property
    def sha256(self):
        return hashlib.sha256(self.text.encode()).hexdigest()

    def cases(self):
        """DataFrame of the cases (one row each, ``case_id`` 0..n-1), SI units; adds E_star."""
        import pandas as pd
        names = list(self.axes)
        if self.combine == "zip":
            n = max(len(v) for v in self.axes.values())
            rows = [tuple(self.axes[k][i if len(self.axes[k]) > 1 else 0] for k in names)
                    for i in range(n)]
        else:
            rows = list(itertools.product(*(self.axes[k] for k in names)))
        df = pd.DataFrame(rows, columns=names)
        if "E_star" not in self.axes:
            from ..contact.elasticity import effective_modulus
            kw = {}
            if "E2" in df:
                kw = dict(E2=df["E2"].to_numpy(float), nu2=df["nu2"].to_numpy(float))
            df["E_star"] = np.asarray(effective_modulus(df["E"].to_numpy(float),
                                                        df["nu"].to_numpy(float), **kw), float)
        df.insert(0, "case_id", np.arange(len(df), dtype=np.int64))
        return df

    def normalized(self):
        """JSON-serialisable resolved scene (SI values), for provenance."""
        return {
            "title": self.title, "kind": self.kind,
            "surfaces": {k: s.describe() for k, s in self.surfaces.items()},
            "axes": self.axes, "fixed": {k: (list(v) if isinstance(v, tuple) else v)
                                         for k, v in self.fixed.items()},
            "table_options": self.table_options, "columns": self.columns,
            "figures": self.figures, "combine": self.combine,
        }


def _check_bounds(key, x, spec):
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


def _parse_scalar(key, value, spec):
    x = parse_quantity(key, value, spec.dim)
    _check_bounds(key, x, spec)
    return x


def _parse_axis(key, value, spec, problems):
    """List of SI floats for an axis value (scalar, list or range table)."""
    if isinstance(value, dict):
        unknown = [k for k in value if k not in RANGE_KEYS]
        for k in unknown:
            problems.append(f"{key}.{k}: unknown key in a range table" + _did_you_mean(k, RANGE_KEYS))
        missing = [k for k in ("start", "stop", "num") if k not in value]
        for k in missing:
            problems.append(f"{key}: range table needs '{k}' (keys: start, stop, num, log)")
        if missing:
            return None
        ok = not unknown
        try:
            a = _parse_scalar(f"{key}.start", value["start"], spec)
        except ValueError as exc:
            problems.append(str(exc)); ok = False
        try:
            b = _parse_scalar(f"{key}.stop", value["stop"], spec)
        except ValueError as exc:
            problems.append(str(exc)); ok = False
        num, log = value["num"], value.get("log", False)
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            problems.append(f"{key}.num = {num!r}: must be an integer >= 1"); ok = False
        if not isinstance(log, bool):
            problems.append(f"{key}.log = {log!r}: must be true or false"); ok = False
        if not ok:
            return None
        if log:
            if a <= 0 or b <= 0:
                problems.append(f"{key}: a log range needs start and stop > 0")
                return None
            return [float(x) for x in np.geomspace(a, b, num)]
        return [float(x) for x in np.linspace(a, b, num)]
    if isinstance(value, list):
        if not value:
            problems.append(f"{key} = []: an axis needs at least one value")
            return None
        out = []
        for i, v in enumerate(value):
            try:
                out.append(_parse_scalar(f"{key}[{i}]", v, spec))
            except ValueError as exc:
                problems.append(str(exc))
        return out if len(out) == len(value) else None
    try:
        return [_parse_scalar(key, value, spec)]
    except ValueError as exc:
        problems.append(str(exc))
        return None


def _parse_list_num(key, value, spec, problems):
    vals = value if isinstance(value, list) else [value]
    out = []
    for i, v in enumerate(vals):
        try:
            out.append(_parse_scalar(f"{key}[{i}]" if isinstance(value, list) else key, v, spec))
        except ValueError as exc:
            problems.append(str(exc))
    return tuple(out) if len(out) == len(vals) else None


def _parse_strlist(key, value, problems):
    vals = value if isinstance(value, list) else [value]
    if not all(isinstance(v, str) for v in vals):
        problems.append(f"{key} = {value!r}: must be a list of strings")
        return None
    return list(vals)


def load_scene(scene, *, for_sweep=False, base_dir=None):
    """Parse and validate a scene; return a :class:`Scene` or raise :class:`SceneError`.

    ``scene`` is a path to a TOML file, the name of a shipped example scene, or a dict (the
    parsed TOML). Every problem is collected (unknown keys with did-you-mean, wrong types,
    units and ranges, missing or unusable files) and reported together. With ``for_sweep``
    the surfaces come from a road database, so ``[surfaces]`` is optional.
    """
    problems = []
    if isinstance(scene, dict):
        data, text, source = scene, json.dumps(scene, sort_keys=True, default=str), "<dict>"
        base = Path(base_dir or ".").resolve()
    else:
        path = Path(scene)
        if not path.is_file():
            try:
                path = example_scene_path(scene)
            except FileNotFoundError as exc:
                raise SceneError(scene, [f"scene file {str(scene)!r} does not exist"
                                         + (str(exc)[str(exc).find(" (did"):]
                                            if "(did" in str(exc) else "")]) from None
        source = str(path)
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise SceneError(source, [f"cannot read scene file: {exc}"]) from None
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise SceneError(source, [f"not valid TOML: {exc}"]) from None
        base = Path(base_dir).resolve() if base_dir else path.resolve().parent

    for k in data:
        if k not in TOP_KEYS:
            problems.append(f"{k}: unknown top-level key" + _did_you_mean(k, TOP_KEYS))
    for k in ("title", "description"):
        if k in data and not isinstance(data[k], str):
            problems.append(f"{k} = {data[k]!r}: must be a string")
    sections = {}
    for sec in ("study", "material", "fluid", "geometry", "tables", "outputs", "sweep", "surfaces"):
        v = data.get(sec, {})
        if not isinstance(v, dict):
            problems.append(f"[{sec}] must be a table (section), got {type(v).__name__}")
            v = {}
        sections[sec] = v

    study = sections["study"]
    kind = study.get("kind")
    if kind is None:
        problems.append(f"study.kind is missing: one of {', '.join(STUDY_KINDS)}")
    elif kind not in STUDY_KINDS:
        problems.append(f"study.kind = {kind!r}: unknown study kind" + _did_you_mean(kind, STUDY_KINDS))
        kind = None
    defaults = DEFAULTS.get(kind, {})

    axes, fixed, given = {}, {}, {}
    for sec, keys in SCHEMA.items():
        secd = sections[sec]
        for k, v in secd.items():
            key = f"{sec}.{k}"
            spec = keys.get(k)
            if spec is None:
                problems.append(f"{key}: unknown key" + _did_you_mean(k, list(keys)))
                continue
            if kind is not None and kind not in spec.studies:
                problems.append(f"{key}: not used by a {kind!r} study (used by: "
                                f"{', '.join(spec.studies)})")
                continue
            given[(sec, k)] = v
            if spec.kind == "num":
                if spec.axis:
                    vals = _parse_axis(key, v, spec, problems)
                    if vals is not None:
                        axes[k] = vals
                else:
                    try:
                        fixed[k] = _parse_scalar(key, v, spec)
                    except ValueError as exc:
                        problems.append(str(exc))
            elif spec.kind == "theory":
                vals = v if isinstance(v, list) else [v]
                ok = True
                for t in vals:
                    if not isinstance(t, str) or t not in THEORY_NAMES:
                        problems.append(f"{key} = {t!r}: unknown theory" + _did_you_mean(t, THEORY_NAMES))
                        ok = False
                if not vals:
                    problems.append(f"{key} = []: name at least one theory"); ok = False
                if ok:
                    axes[k] = list(dict.fromkeys(vals))
            elif spec.kind == "choice":
                if not isinstance(v, str) or v not in spec.choices:
                    if k != "kind":
                        problems.append(f"{key} = {v!r}: must be one of {', '.join(spec.choices)}"
                                        + (_did_you_mean(v, spec.choices) if isinstance(v, str) else ""))
                elif k != "kind":
                    fixed[k] = v
            elif spec.kind == "str":
                if not isinstance(v, str):
                    problems.append(f"{key} = {v!r}: must be a string")
                else:
                    fixed[k] = v
            elif spec.kind == "list_num":
                vals = _parse_list_num(key, v, spec, problems)
                if vals is not None:
                    fixed[k] = vals
            elif spec.kind == "strlist":
                vals = _parse_strlist(key, v, problems)
                if vals is not None:
                    fixed[f"{sec}.{k}"] = vals
            elif spec.kind == "profile":
                if isinstance(v, str):
                    if v not in ("uniform", "parabolic"):
                        problems.append(f"{key} = {v!r}: must be 'uniform', 'parabolic' or a list of "
                                        f"relative pressures" + _did_you_mean(v, ("uniform", "parabolic")))
                    else:
                        fixed[k] = v
                elif isinstance(v, list) and len(v) >= 2:
                    vals = _parse_list_num(key, v, _Key("num", lo=0), problems)
                    if vals is not None:
                        if sum(vals) <= 0:
                            problems.append(f"{key}: the relative pressures must not all be 0")
                        else:
                            fixed[k] = tuple(vals)
                else:
                    problems.append(f"{key} = {v!r}: must be 'uniform', 'parabolic' or a list of "
                                    f">= 2 relative pressures along the footprint")

    # ------------------------------------------------------------ required / defaults
    if kind is not None:
        hertz = kind == "seal" and fixed.get("profile") == "hertz"
        if "p0" not in axes and ("study", "p0") not in given and not hertz:
            problems.append("study.p0 is missing: the nominal pressure, e.g. p0 = \"0.2 MPa\"")
        if "theory" not in axes and ("study", "theory") not in given:
            axes["theory"] = [defaults["theory"]]
        for k in ("ratios", "du", "times", "pressure_profile", "pressure_model", "du_complete",
                  "profile"):
            if k in defaults and k not in fixed and ("study", k) not in given:
                fixed[k] = defaults[k]
        if kind in ("squeeze", "tire") and "R" not in axes and ("geometry", "R") not in given:
            problems.append("geometry.R is missing: the block radius, e.g. R = \"2 cm\"")
        if kind == "tire":
            for k in ("footprint_length", "speed"):
                if k not in axes and ("study", k) not in given:
                    problems.append(f"study.{k} is missing (tire study)")
            if "u_start" not in axes and ("study", "u_start") not in given:
                axes["u_start"] = [defaults["u_start"]]
            if "rho" not in axes and ("fluid", "rho") not in given:
                axes["rho"] = [defaults["rho"]]
        if kind == "seal":
            for k in ("dp",):
                if k not in axes and ("study", k) not in given:
                    problems.append(f"study.{k} is missing (seal study): the pressure difference")
            for k in (("L_y",) if fixed.get("profile") == "hertz" else ("L", "L_y")):
                if k not in axes and ("geometry", k) not in given:
                    problems.append(f"geometry.{k} is missing (seal study)")
            for k in ("p_b", "alpha_cj"):
                if k not in axes and ("study", k) not in given:
                    axes[k] = [defaults[k]]
            if fixed.get("profile") == "hertz":
                for k, sec in (("R", "geometry"), ("f_N", "study")):
                    if k not in axes and (sec, k) not in given:
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
    if ("fluid", "eta") not in given:
        problems.append("fluid.eta is missing: the viscosity, e.g. eta = \"1 mPa s\"")
    mat_given = {k for (s, k) in given if s == "material"}
    if "E_star" in mat_given:
        for k in ("E", "nu", "E2", "nu2"):
            if k in mat_given:
                problems.append(f"material.{k}: give either E_star or E and nu, not both")
    else:
        for k in ("E", "nu"):
            if k not in mat_given:
                problems.append(f"material.{k} is missing: give E and nu (E* = E/(1-nu^2)) or E_star")
        if ("E2" in mat_given) != ("nu2" in mat_given):
            problems.append("material.E2/nu2: give both the second solid's E2 and nu2, or neither")

    # ------------------------------------------------------------ table options
    topts = {"gamma": 1.0, "a_perc": 0.5, "alpha_cj": 1.0}
    topts_given = {k: fixed.pop(k) for k in ("gamma", "a_perc", "alpha_cj") if k in fixed}
    if kind == "seal" and ("tables", "alpha_cj") in given:
        problems.append("tables.alpha_cj: for a seal study give the junction factor as "
                        "study.alpha_cj (it rescales σ_cj by α_cj³ on tables built with α_cj = 1)")
    topts.update(topts_given)
    cache_dir = fixed.pop("cache_dir", None)
    if cache_dir is not None:
        cache_dir = str((base / Path(cache_dir).expanduser()))
    for k in ("name",):
        fixed.pop(k, None)

    # ------------------------------------------------------------ surfaces
    theories = tuple(t for t in THEORY_NAMES if t in axes.get("theory", ()))
    surfaces = {}
    sdict = sections["surfaces"]
    if not sdict and not for_sweep:
        problems.append("[surfaces] is missing: define at least one [surfaces.<name>]")
    for name, sd in sdict.items():
        pre = f"surfaces.{name}"
        if not isinstance(sd, dict):
            problems.append(f"{pre} must be a table: [surfaces.{name}] with table/psd/h_rms... keys")
            continue
        spec = _parse_surface(pre, name, sd, base, theories, topts_given, problems)
        if spec is not None:
            surfaces[name] = spec

    # ------------------------------------------------------------ outputs
    columns, figures = [], []
    if kind is not None:
        avail = available_columns(kind, fixed)
        want = fixed.pop("outputs.columns", None)
        if want is None:
            columns = list(avail)
        else:
            for w in want:
                hit = [c for c in avail if fnmatch.fnmatchcase(c, w)]
                if not hit:
                    problems.append(f"outputs.columns: unknown column {w!r} for a {kind!r} study"
                                    + _did_you_mean(w, avail))
                columns.extend(c for c in hit if c not in columns)
        favail = FIGURES[kind]
        fwant = fixed.pop("outputs.figures", None) or []
        for f in fwant:
            if f not in favail:
                problems.append(f"outputs.figures: unknown figure {f!r} for a {kind!r} study"
                                + _did_you_mean(f, favail))
            elif f not in figures:
                figures.append(f)
    combine = fixed.pop("combine", "product")
    if combine == "zip":
        lens = {k: len(v) for k, v in axes.items() if len(v) > 1}
        if len(set(lens.values())) > 1:
            problems.append(f"sweep.combine = 'zip': the list axes have different lengths {lens}")

    if problems:
        raise SceneError(source, problems)
    # canonical axis order: schema order
    order = [k for k in AXIS_KEYS if k in axes]
    axes = {k: axes[k] for k in order}
    title = data.get("title") or (Path(source).stem if source != "<dict>" else "scene")
    return Scene(source=source, base_dir=base, text=text, data=data, title=title, kind=kind,
                 surfaces=surfaces, axes=axes, fixed=fixed, table_options=topts,
                 table_options_given=topts_given, cache_dir=cache_dir, columns=columns,
                 figures=figures, combine=combine)


def _resolve_table_file(value, base):
    p = Path(value).expanduser()
    cand = p if p.is_absolute() else base / p
    if cand.is_file():
        return cand
    return default_table_path(value)


def _parse_surface(pre, name, sd, base, theories, topts_given, problems):
    n0 = len(problems)
    for k in sd:
        if k not in SURFACE_KEYS:
            problems.append(f"{pre}.{k}: unknown key" + _did_you_mean(k, list(SURFACE_KEYS)))
    sa_keys = ("h_rms", "hurst", "q0", "q1", "q_roll")
    has = [s for s in ("table", "psd") if s in sd] + (["h_rms/hurst/q0/q1"] if any(k in sd for k in sa_keys) else [])
    if len(has) != 1:
        problems.append(f"{pre}: give exactly one of table = \"file.parquet\", psd = \"file.csv\" "
                        f"(+ convention) or h_rms, hurst, q0, q1 [, q_roll]"
                        + (f" (got {', '.join(has)})" if has else ""))
        return None
    label = sd.get("label")
    if label is not None and not isinstance(label, str):
        problems.append(f"{pre}.label = {label!r}: must be a string")
    if "table" in sd:
        v = sd["table"]
        if "convention" in sd:
            problems.append(f"{pre}.convention: only used with psd = ...")
        if not isinstance(v, str):
            problems.append(f"{pre}.table = {v!r}: must be a file name")
            return None
        try:
            path = _resolve_table_file(v, base)
        except FileNotFoundError as exc:
            problems.append(f"{pre}.table = {v!r}: file not found ({str(exc)[str(exc).find('(') + 1:-1]})"
                            if "(" in str(exc) else f"{pre}.table = {v!r}: file not found")
            return None
        try:
            meta = _read_table_metadata(path)
        except ValueError as exc:
            problems.append(f"{pre}.table = {v!r}: {exc}")
            return None
        missing = [t for t in theories if t not in meta.get("theories", [])]
        if missing:
            problems.append(f"{pre}.table = {v!r}: the table holds theories {meta.get('theories')} "
                            f"but the study needs {missing} (rebuild it with `fastcontact tables "
                            f"build --theories ...`, or use a psd/self-affine surface)")
        for k, val in topts_given.items():
            have = meta.get("options", {}).get(k)
            if have is not None and not math.isclose(have, val, rel_tol=1e-12):
                problems.append(f"{pre}.table = {v!r}: built with {k} = {have!r} but "
                                f"tables.{k} = {val!r}")
        if len(problems) > n0:
            return None
        return SurfaceSpec(name, "table", path=path, label=label)
    if "psd" in sd:
        v, conv = sd["psd"], sd.get("convention")
        if not isinstance(v, str):
            problems.append(f"{pre}.psd = {v!r}: must be a file name")
            return None
        if conv is None:
            problems.append(f"{pre}.convention is missing: psd files need convention = 'persson' "
                            f"or 'surface_topography' (contact.engineering)")
        elif conv not in CONVENTION_NAMES:
            problems.append(f"{pre}.convention = {conv!r}: must be one of {', '.join(CONVENTION_NAMES)}"
                            + _did_you_mean(conv, CONVENTION_NAMES))
        p = Path(v).expanduser()
        p = p if p.is_absolute() else base / p
        if not p.is_file():
            problems.append(f"{pre}.psd = {v!r}: file not found ({p})")
        if len(problems) > n0:
            return None
        spec = SurfaceSpec(name, "psd", path=p, convention=conv, label=label)
        try:
            spec.psd()
        except ValueError as exc:
            problems.append(f"{pre}.psd = {v!r}: {exc}")
            return None
        return spec
    params = {}
    for k in sa_keys:
        if k in sd:
            try:
                params[k] = _parse_scalar(f"{pre}.{k}", sd[k], SURFACE_KEYS[k])
            except ValueError as exc:
                problems.append(str(exc))
        elif k != "q_roll":
            problems.append(f"{pre}.{k} is missing (self-affine surface: h_rms, hurst, q0, q1)")
    if "convention" in sd:
        problems.append(f"{pre}.convention: only used with psd = ...")
    if len(problems) > n0:
        return None
    spec = SurfaceSpec(name, "self_affine", params=params, label=label)
    try:
        spec.psd()
    except ValueError as exc:
        problems.append(f"{pre}: {exc}")
        return None
    return spec


# =========================================================================== columns
def available_columns(kind, fixed):
    """Result columns a study of ``kind`` can produce with the study parameters ``fixed``."""
    if kind == "squeeze":
        from_sq = _squeeze_columns(fixed.get("ratios", DEFAULTS["squeeze"]["ratios"]),
                                   fixed.get("du", DEFAULTS["squeeze"]["du"]),
                                   fixed.get("times", DEFAULTS["squeeze"]["times"]))
        return from_sq
    if kind == "tire":
        from ..squeeze.tire import tire_columns
        return tire_columns(fixed.get("ratios", DEFAULTS["tire"]["ratios"]))
    if kind == "seal":
        return list(SEAL_COLUMNS) + (list(SEAL_HERTZ_COLUMNS) if fixed.get("profile") == "hertz" else [])
    raise ValueError(f"kind = {kind!r} is invalid")


def _num_name(x):
    return f"{float(x):.6g}"


def squeeze_columns(ratios, du, times):
    """Result columns of a squeeze study (names independent of the engine's formatting)."""
    return (["u_start", "u_inf", "t_star"] + [f"t_ratio_{_num_name(r)}" for r in ratios]
            + [f"t_du_{_num_name(d)}" for d in du] + [f"u_at_{_num_name(t)}" for t in times]
            + list(SQUEEZE_TAIL))


#: further squeeze_out columns offered by squeeze studies
SQUEEZE_TAIL = ("tau0", "t_relax", "trapped", "percolated", "u_trap", "t_trap",
                "fluid_load_fraction", "out_of_table")


#: boolean result columns (typed as nullable booleans when a case fails)
BOOL_COLUMNS = frozenset({"trapped", "percolated", "out_of_table", "squeeze_complete",
                          "lift_off", "converged"})
SEAL_COLUMNS = ("Q", "lift_off", "percolated", "p_a", "open_inlet", "open_outlet")
SEAL_HERTZ_COLUMNS = ("a", "L", "p_max", "converged", "error_estimate")


def _squeeze_columns(ratios, du, times):
    return squeeze_columns(ratios, du, times)


def available_figures(kind):
    return list(FIGURES[kind])


# =========================================================================== tables
def _canonical_theories(theories):
    ths = set(theories)
    return tuple(t for t in THEORY_NAMES if t in ths)


def table_key(psd, theories, options) -> str:
    """Cache key: surface fingerprint + theories + table options + table schema version."""
    from .. import __version__
    from ..tables import SCHEMA_VERSION
    blob = json.dumps({"surface": psd.fingerprint(), "theories": list(_canonical_theories(theories)),
                       "options": {k: float(v) for k, v in sorted(options.items())},
                       "schema": SCHEMA_VERSION, "version": __version__},
                      sort_keys=True).encode()
    return hashlib.sha256(blob).hexdigest()


def build_tables(psd, theories, options):
    """precompute(...) with the study's theories and options; returns (Tables, note).

    If the adaptive refinement cannot resolve ū(p) as strictly decreasing (seen for some
    tabulated spectra whose quadrature noise exceeds the refinement tolerance), the build is
    retried on the base grid without refinement and ``note`` says so; the interpolation
    errors actually achieved are in ``Tables.info["interpolation_error"]``.
    """
    from ..tables import precompute
    theories = _canonical_theories(theories)
    try:
        return precompute(psd, theories=theories, **options), None
    except ValueError as exc:
        if "strictly decreasing" not in str(exc):
            raise
        t = precompute(psd, theories=theories, refine=False, **options)
        err = t.info.get("interpolation_error", {})
        worst = max(err.values()) if err else float("nan")
        return t, (f"adaptive refinement failed ({exc}); built on the base grid without "
                   f"refinement, worst interpolation error {worst:.2g}")


def obtain_tables(spec, theories, options, cache_dir=None):
    """Tables for one surface: load a table file, reuse the cache or build (and cache).

    Returns (Tables, record) with record = {surface, action ("loaded" | "reused" | "built"),
    path, theories, options, surface_hash, columns_sha256, seconds, note}.
    """
    from ..tables import Tables
    t0 = time.perf_counter()
    theories = _canonical_theories(theories)
    note = None
    if spec.source == "table":
        T = Tables.from_parquet(spec.path)
        action, path = "loaded", spec.path
    else:
        psd = spec.psd()
        key = table_key(psd, theories, options)
        T = None
        path = None
        if cache_dir is not None:
            cdir = Path(cache_dir)
            path = cdir / f"{psd.fingerprint()[:16]}-{key[:16]}.parquet"
            if path.is_file():
                try:
                    T = Tables.from_parquet(path)
                    ok = (T.surface.fingerprint() == psd.fingerprint()
                          and tuple(T.theories) == theories
                          and all(math.isclose(T.options.get(k, math.nan), v) for k, v in options.items()))
                    if not ok:
                        T, note = None, "cache file did not match: rebuilt"
                except ValueError as exc:
                    T, note = None, f"cache file unusable ({exc}): rebuilt"
        if T is not None:
            action = "reused"
        else:
            T, bnote = build_tables(psd, theories, options)
            note = "; ".join(x for x in (note, bnote) if x) or None
            action = "built"
            if path is not None:
                T.to_parquet(path)
    meta = T.metadata()
    rec = {"surface": spec.name, "action": action, "path": str(path) if path else None,
           "theories": list(T.theories), "options": T.options,
           "surface_hash": meta["surface_hash"], "columns_sha256": meta["columns_sha256"],
           "nodes": T.info.get("nodes"), "seconds": round(time.perf_counter() - t0, 4),
           "build_seconds": T.info.get("build_seconds"), "note": note}
    return T, rec


# =========================================================================== evaluation
_ROW_ERRORS = (ValueError, RuntimeError, ArithmeticError)


def _col(rows, name):
    return rows[name].to_numpy(float)


def _eval_squeeze(tables, rows, theory, fixed, columns):
    from ..squeeze import squeeze_out
    from ..squeeze.tire import _pick, squeeze_method
    ratios = [r for r in fixed["ratios"] if f"t_ratio_{_num_name(r)}" in columns]
    du = [d for d in fixed["du"] if f"t_du_{_num_name(d)}" in columns]
    times = [t for t in fixed["times"] if f"u_at_{_num_name(t)}" in columns]
    kw = dict(p0=_col(rows, "p0"), E_star=_col(rows, "E_star"), R=_col(rows, "R"),
              eta=_col(rows, "eta"), theory=theory,
              u_start=_col(rows, "u_start") if "u_start" in rows else None,
              ratios=tuple(ratios) if ratios else (1.01,), du=tuple(du), times=tuple(times),
              method=squeeze_method(len(rows)))
    sq = squeeze_out(tables, **kw).reset_index(drop=True)
    if len(sq) != len(rows):
        raise RuntimeError(f"squeeze_out returned {len(sq)} rows for {len(rows)} cases")
    out = {}
    for name in ("u_start", "u_inf", "t_star", *SQUEEZE_TAIL):
        if name in columns:
            out[name] = sq[name].to_numpy()
    for prefix, vals in (("t_ratio_", ratios), ("t_du_", du), ("u_at_", times)):
        if vals:
            for v, c in zip(vals, _pick(sq, prefix, vals)):
                out[f"{prefix}{_num_name(v)}"] = sq[c].to_numpy()
    out["_error"] = _out_of_table_errors(tables, rows, sq["out_of_table"].to_numpy(bool))
    return out


def _out_of_table_errors(tables, rows, oot):
    err = np.full(len(rows), "", dtype=object)
    if np.any(oot):
        lo, hi = tables.p_range
        pb = _col(rows, "p0") / _col(rows, "E_star")
        for i in np.flatnonzero(oot):
            err[i] = (f"out_of_table: p0/E_star = {pb[i]:.6g} is outside the tables' range "
                      f"[{lo:.6g}, {hi:.6g}]")
    return err


def _eval_tire(tables, rows, theory, fixed, columns):
    from ..squeeze.tire import tire_footprint
    df = tire_footprint(tables, p0=_col(rows, "p0"), E_star=_col(rows, "E_star"), R=_col(rows, "R"),
                        eta=_col(rows, "eta"), footprint_length=_col(rows, "footprint_length"),
                        speed=_col(rows, "speed"), rho=_col(rows, "rho"), theory=theory,
                        pressure_profile=fixed["pressure_profile"],
                        pressure_model=fixed["pressure_model"], u_start=_col(rows, "u_start"),
                        du_complete=fixed["du_complete"], ratios=fixed["ratios"],
                        columns=list(dict.fromkeys(list(columns) + ["out_of_table"])))
    out = {c: df[c].to_numpy() for c in columns}
    out["_error"] = _out_of_table_errors(tables, rows, df["out_of_table"].to_numpy(bool))
    return out


def _eval_seal(tables, rows, theory, fixed, columns):
    from ..seal import seal_leak
    hertz = fixed.get("profile") == "hertz"
    kw = dict(dp=_col(rows, "dp"), L_y=_col(rows, "L_y"), E_star=_col(rows, "E_star"),
              eta=_col(rows, "eta"), theory=theory, alpha_cj=_col(rows, "alpha_cj"),
              p_b=_col(rows, "p_b"), profile=fixed.get("profile", "uniform"))
    if hertz:
        kw.update(R=_col(rows, "R"), f_N=_col(rows, "f_N"))
    else:
        kw.update(p0=_col(rows, "p0"), L=_col(rows, "L"))
    df = seal_leak(tables, **kw).reset_index(drop=True)
    if len(df) != len(rows):
        raise RuntimeError(f"seal_leak returned {len(df)} rows for {len(rows)} cases")
    out = {c: df[c].to_numpy() for c in columns}
    err = np.full(len(rows), "", dtype=object)
    if "converged" in df:
        bad = ~df["converged"].to_numpy(bool)
        err[bad] = "seal solver did not converge (see error_estimate)"
    out["_error"] = err
    return out


_ENGINES = {"squeeze": _eval_squeeze, "tire": _eval_tire, "seal": _eval_seal}


def evaluate_cases(kind, tables, cases, fixed, columns):
    """Evaluate every case (rows of ``cases``) on one surface's ``tables``.

    Returns a DataFrame aligned with ``cases`` holding ``columns`` plus ``error`` ("" where
    the case evaluated; otherwise the engine's message, and NaN results). Cases are grouped
    by theory and evaluated vectorised; if a group fails, its cases are evaluated one by one
    so that one bad case does not sink the others.
    """
    import pandas as pd
    engine = _ENGINES[kind]
    n = len(cases)
    res = {c: np.full(n, np.nan, dtype=object) for c in columns}
    err = np.full(n, "", dtype=object)
    cases = cases.reset_index(drop=True)
    for theory, idx in cases.groupby("theory", sort=False).indices.items():
        rows = cases.iloc[idx].reset_index(drop=True)
        try:
            out = engine(tables, rows, theory, fixed, columns)
            for c in columns:
                res[c][idx] = out[c]
            if "_error" in out:
                err[idx] = out["_error"]
            continue
        except Exception:  # noqa: BLE001 - fall back to one case at a time (errors kept per row)
            pass
        for k, i in enumerate(idx):
            row = rows.iloc[[k]].reset_index(drop=True)
            try:
                out = engine(tables, row, theory, fixed, columns)
                for c in columns:
                    res[c][i] = np.ravel(out[c])[0]
                if "_error" in out:
                    err[i] = np.ravel(out["_error"])[0]
            except _ROW_ERRORS as exc:
                err[i] = f"{type(exc).__name__}: {exc}"
    # an output that is also an input column (e.g. u_start given in the scene) is not repeated
    df = pd.DataFrame({c: _tidy(res[c], c) for c in columns if c not in cases.columns})
    df["error"] = pd.Series(err, dtype=str)
    return df


def empty_results(columns, n, exclude=()):
    """Typed all-missing result columns (NaN floats, NA booleans) for ``n`` failed cases."""
    import pandas as pd
    return pd.DataFrame({c: (pd.array([None] * n, dtype="boolean") if c in BOOL_COLUMNS
                             else np.full(n, np.nan)) for c in columns if c not in exclude})


def _tidy(a, name=None):
    """object array of results → float or bool array where possible."""
    if name in BOOL_COLUMNS:
        import pandas as pd
        return pd.array([None if (v is None or (isinstance(v, float) and math.isnan(v)))
                         else bool(v) for v in a], dtype="boolean") \
            if any(v is None or (isinstance(v, float) and math.isnan(v)) for v in a) \
            else a.astype(bool)
    vals = [v for v in a if not (v is None or (isinstance(v, float) and math.isnan(v)))]
    if vals and all(isinstance(v, (bool, np.bool_)) for v in vals):
        if len(vals) == len(a):
            return a.astype(bool)
        return np.array([None if not isinstance(v, (bool, np.bool_)) else bool(v) for v in a], dtype=object)
    try:
        return a.astype(float)
    except (TypeError, ValueError):
        return a


# =========================================================================== outputs
def _atomic_write_bytes(path: Path, data: bytes):
    from .._core.io import write_bytes_atomic
    return write_bytes_atomic(path, data)


def write_parquet_atomic(df, path: Path, metadata: dict | None = None):
    """Write ``df`` to ``path`` atomically (temporary file + os.replace) with JSON ``metadata``
    under the key-value metadata key ``fastcontact``."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    from .._core.io import atomic_path
    path = Path(path)
    table = pa.Table.from_pandas(df, preserve_index=False)
    meta = dict(table.schema.metadata or {})
    if metadata is not None:
        meta[b"fastcontact"] = json.dumps(metadata, sort_keys=True, default=_json_default).encode()
    table = table.replace_schema_metadata(meta)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (Path,)):
        return str(o)
    if isinstance(o, tuple):
        return list(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def provenance(scene, table_records):
    """The key-value metadata stored with results: scene, version, table hashes, reference."""
    from .. import __version__
    return {
        "fastcontact_version": __version__,
        "paper_reference": PAPER_REFERENCE,
        "study": scene.kind,
        "scene_source": scene.source,
        "scene_sha256": scene.sha256,
        "scene_toml": scene.text,
        "scene": scene.normalized(),
        "tables": {r["surface"]: {k: r[k] for k in ("surface_hash", "columns_sha256", "theories",
                                                   "options", "action", "note")}
                   for r in table_records},
        "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "python": sys.version.split()[0],
    }


def _summary_text(scene, results, records, files, seconds):
    lines = [f"fastcontact run: {scene.title}",
             f"scene: {scene.source} (sha256 {scene.sha256[:12]})",
             f"study: {scene.kind}; theories: {', '.join(scene.theories)}; "
             f"{len(scene.surfaces)} surface(s) x {len(results) // max(len(scene.surfaces), 1)} case(s) "
             f"= {len(results)} rows in {seconds:.2f} s"]
    axes = {k: v for k, v in scene.axes.items() if len(v) > 1}
    if axes:
        lines.append("axes: " + ", ".join(f"{k} ({len(v)} values)" for k, v in axes.items()))
    for r in records:
        lines.append(f"tables {r['surface']}: {r['action']} ({', '.join(r['theories'])}; "
                     f"{r['nodes']} nodes)" + (f" [{r['note']}]" if r.get("note") else ""))
    nerr = int((results["error"] != "").sum())
    if nerr:
        first = results.loc[results["error"] != "", "error"].iloc[0]
        lines.append(f"WARNING: {nerr} case(s) failed, e.g. {first}")
    num = [c for c in scene.columns if c in results and results[c].dtype.kind == "f"]
    boo = [c for c in scene.columns if c in results and results[c].dtype.kind == "b"]
    if num or boo:
        lines.append("")
        lines.append("per surface: min / median / max (SI units)")
    for name, g in results.groupby("surface", sort=False):
        lines.append(f"  [{name}]")
        for c in num:
            v = g[c].to_numpy(float)
            v = v[np.isfinite(v)]
            if v.size:
                lines.append(f"    {c:24s} {v.min():.4g} / {np.median(v):.4g} / {v.max():.4g}")
            else:
                lines.append(f"    {c:24s} (no finite value)")
        for c in boo:
            lines.append(f"    {c:24s} true in {int(g[c].sum())} of {len(g)} cases")
    lines.append("")
    lines.append("files:")
    lines.extend(f"  {f}" for f in files)
    return "\n".join(lines) + "\n"


def run_scene(scene, outdir, *, cache_dir=None, log=None):
    """Run a validated :class:`Scene`; write results, summary, build record and figures.

    Returns a dict with the paths written and the results DataFrame (``"results"``).
    Nothing is written before tables and results exist; every file is written atomically.
    """
    import pandas as pd
    t0 = time.perf_counter()
    log = log or (lambda msg: None)
    outdir = Path(outdir)
    cdir = table_cache_dir(cache_dir or scene.cache_dir)
    theories = scene.theories
    options = dict(scene.table_options)
    tables, records = {}, []
    for name, spec in scene.surfaces.items():
        T, rec = obtain_tables(spec, theories, options, cdir)
        log(f"tables {name}: {rec['action']} ({', '.join(rec['theories'])}) in {rec['seconds']:.2f} s")
        tables[name] = T
        records.append(rec)
    cases = scene.cases()
    frames = []
    for name, T in tables.items():
        res = evaluate_cases(scene.kind, T, cases, scene.fixed, scene.columns)
        df = pd.concat([pd.DataFrame({"surface": name}, index=cases.index), cases, res], axis=1)
        frames.append(df)
    results = pd.concat(frames, ignore_index=True)
    outdir.mkdir(parents=True, exist_ok=True)
    meta = provenance(scene, records)
    written = [write_parquet_atomic(results, outdir / "results.parquet", meta)]
    fig_paths = []
    for fig in scene.figures:
        p = _make_scene_figure(scene, fig, tables, results, outdir / "figures")
        fig_paths.append(p)
        log(f"figure {fig}: {p}")
    written += fig_paths
    seconds = time.perf_counter() - t0
    record = {
        "scene": scene.source, "scene_sha256": scene.sha256, "study": scene.kind,
        "theories_requested": list(theories), "table_options": options,
        "tables": records,
        "outputs": {"columns": list(scene.columns), "figures": list(scene.figures),
                    "files": [str(p) for p in written]},
        "cases_per_surface": len(cases), "rows": len(results),
        "failed_rows": int((results["error"] != "").sum()), "seconds": round(seconds, 3),
    }
    rec_path = outdir / "build_record.json"
    summary_path = outdir / "summary.txt"
    files = [str(p) for p in written] + [str(rec_path), str(summary_path)]
    _atomic_write_bytes(rec_path, json.dumps(record, indent=2, sort_keys=True,
                                             default=_json_default).encode())
    _atomic_write_bytes(summary_path, _summary_text(scene, results, records, files,
                                                    seconds).encode())
    return {"results": results, "results_path": outdir / "results.parquet",
            "summary_path": summary_path, "build_record_path": rec_path, "figures": fig_paths,
            "record": record}


# =========================================================================== figures
_MAX_CURVES = 8


_SQUEEZE_KEYS = ("theory", "p0", "E", "nu", "E2", "nu2", "E_star", "eta", "R", "u_start")
_SI_UNIT = {"p0": "Pa", "E": "Pa", "E_star": "Pa", "E2": "Pa", "eta": "Pa s", "R": "m",
            "u_start": "m", "dp": "Pa", "p_b": "Pa", "L": "m", "L_y": "m", "rho": "kg/m^3",
            "speed": "m/s", "footprint_length": "m", "f_N": "N/m", "nu": "-", "nu2": "-",
            "alpha_cj": "-"}
_UNIT_LABEL = {"p0": (1e6, "MPa"), "E": (1e6, "MPa"), "E_star": (1e6, "MPa"), "eta": (1e-3, "mPa s"),
               "R": (1e-2, "cm"), "u_start": (1e-3, "mm"), "dp": (1e3, "kPa"), "L": (1e-3, "mm")}


def _fig_cases(scene, results, distinct=None):
    """Up to _MAX_CURVES (surface, row) pairs: every surface, first cases (distinct in the
    ``distinct`` columns, e.g. the squeeze parameters, which the footprint speed is not)."""
    g_all = results[results["error"] == ""]
    if distinct:
        g_all = g_all.drop_duplicates(subset=["surface"] + [c for c in distinct if c in g_all])
    per = max(1, _MAX_CURVES // max(g_all["surface"].nunique(), 1))
    out = []
    for name, g in g_all.groupby("surface", sort=False):
        out.extend((name, r) for _, r in g.head(per).iterrows())
    return out[:_MAX_CURVES]


def _case_label(scene, name, row, keys=None):
    parts = [scene.surfaces[name].label or name] if name in scene.surfaces else [name]
    for k, v in scene.axes.items():
        if len(v) > 1 and (keys is None or k in keys):
            if k == "theory":
                parts.append(str(row[k]))
            elif k in _UNIT_LABEL:
                f, u = _UNIT_LABEL[k]
                parts.append(f"{k} = {float(row[k]) / f:.3g} {u}")
            else:
                parts.append(f"{k} = {float(row[k]):.3g}")
    return ", ".join(parts)


def _sweep_axis(scene):
    for k, v in scene.axes.items():
        if k != "theory" and len(v) > 1:
            return k
    return None


def _make_scene_figure(scene, fig, tables, results, figdir):
    figdir = Path(figdir)
    figdir.mkdir(parents=True, exist_ok=True)
    path = figdir / f"{scene.kind}_{fig}.png"
    if scene.kind == "tire" or (scene.kind == "squeeze" and fig == "u_of_t"):
        from ..figures.tire_figures import plot_tire_curves, tire_curve
        curves = []
        for name, row in _fig_cases(scene, results, _SQUEEZE_KEYS):
            p_eval = float(row["p_eval"]) if "p_eval" in row else float(row["p0"])
            if scene.kind == "tire" and "p_eval" not in row:
                from ..squeeze.tire import profile_factors
                peak = profile_factors(scene.fixed["pressure_profile"])[1]
                p_eval = float(row["p0"]) * (peak if scene.fixed["pressure_model"] == "peak" else 1.0)
            ratios = scene.fixed.get("ratios") or (1.1, 1.01, 1.001)
            du = scene.fixed.get("du_complete") or (scene.fixed.get("du") or (1e-6,))[0]
            curves.append(tire_curve(tables[name], p0=p_eval, E_star=float(row["E_star"]),
                                     R=float(row["R"]), eta=float(row["eta"]),
                                     theory=row["theory"],
                                     u_start=float(row["u_start"]) if "u_start" in row and
                                     np.isfinite(float(row["u_start"])) else None,
                                     ratios=ratios, du=du,
                                     label=_case_label(scene, name, row, _SQUEEZE_KEYS)))
        t_mark = None
        if scene.kind == "tire":
            t_mark = sorted(set((results["footprint_length"] / results["speed"]).round(12)))
        quantity = "du" if fig == "du_of_t" else "u"
        return plot_tire_curves(curves, path, quantity, scene.title, t_mark=t_mark,
                                t_mark_label="time in footprint:" if t_mark else None)
    from ..figures.canvas import new_figure as _new_figure, save_png as _save_atomic
    f = _new_figure(figsize=(6.4, 4.8))
    ax = f.subplots()
    ok = results[results["error"] == ""]
    if scene.kind == "squeeze":   # t_star
        x = _sweep_axis(scene) or "p0"
        for k, ((name, theory), g) in enumerate(ok.groupby(["surface", "theory"], sort=False)):
            gg = g.sort_values(x)
            y = gg["t_star"].to_numpy(float)
            lab = scene.surfaces[name].label if name in scene.surfaces and scene.surfaces[name].label else name
            ax.plot(gg[x].to_numpy(float), y, "o-", ms=3, label=f"{lab} ({theory})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"{x} ({_SI_UNIT.get(x, 'SI')})")
        ax.set_ylabel(r"squeeze-out time $t^*$ (s), $\bar u(t^*) = 1.01\,\bar u_\infty$")
    elif fig == "leak_rate":
        others = [k for k, v in scene.axes.items() if len(v) > 1 and k != "dp"]
        for (name, *key), g in ok.groupby(["surface", *others], sort=False):
            gg = g.sort_values("dp")
            Q = gg["Q"].to_numpy(float)
            m = np.isfinite(Q) & (Q > 0)
            lab = _case_label(scene, name, gg.iloc[0], others)
            pref = _seal_p_ref(scene, gg)
            ax.plot((gg["dp"].to_numpy(float) / pref)[m], Q[m], "o-", ms=3, label=lab)
        ax.set_yscale("log")
        ax.set_xlabel(r"$\Delta p / p_0$" + (r" ($p_0$: Hertz peak pressure)"
                                             if scene.fixed.get("profile") == "hertz" else ""))
        ax.set_ylabel(r"leak rate $Q$ (m$^3$/s)")
    elif fig == "profiles":
        from ..seal import seal_profile
        name, row = _fig_cases(scene, results)[0]
        T = tables[name]
        ax2 = ax.twinx()
        for j, frac in enumerate((0.0, 0.5, 0.9)):
            dp = frac * float(_seal_p_ref(scene, row.to_frame().T)[0])
            prof = seal_profile(T, **_seal_profile_kwargs(scene, row, dp))
            x = prof["x"].to_numpy(float) * 1e3
            ax.plot(x, prof["p_cont"].to_numpy(float) / 1e3, color=COLORS_SEAL[j],
                    label=rf"$p_{{\rm cont}}$, $\Delta p/p_0$ = {frac:g}")
            ucol = "u" if "u" in prof else [c for c in prof.columns if c.startswith("u")][0]
            ax2.plot(x, prof[ucol].to_numpy(float) * 1e6, color=COLORS_SEAL[j], ls="--")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel(r"contact pressure $p_{\rm cont}$ (kPa)")
        ax2.set_ylabel(r"separation $\bar u$ (µm), dashed")
    ax.legend(fontsize=8, frameon=False, loc="upper center" if fig == "profiles" else "best")
    ax.set_title(scene.title, fontsize=9)
    ax.grid(True, which="major", lw=0.3, alpha=0.5)
    return _save_atomic(f, path)


COLORS_SEAL = ("tab:blue", "tab:orange", "tab:red")


def _seal_p_ref(scene, rows):
    """p0 of a flat ring, or the Hertz peak pressure, for each row [Pa]."""
    if scene.fixed.get("profile") == "hertz":
        from ..seal import hertz_contact
        return np.asarray(hertz_contact(rows["R"].to_numpy(float), rows["f_N"].to_numpy(float),
                                        rows["E_star"].to_numpy(float))[1], float).ravel()
    return rows["p0"].to_numpy(float)


def _seal_profile_kwargs(scene, row, dp):
    kw = dict(dp=dp, L_y=float(row["L_y"]), E_star=float(row["E_star"]), eta=float(row["eta"]),
              theory=row["theory"], alpha_cj=float(row["alpha_cj"]), p_b=float(row["p_b"]),
              profile=scene.fixed.get("profile", "uniform"))
    if scene.fixed.get("profile") == "hertz":
        kw.update(R=float(row["R"]), f_N=float(row["f_N"]))
    else:
        kw.update(p0=float(row["p0"]), L=float(row["L"]))
    return kw
