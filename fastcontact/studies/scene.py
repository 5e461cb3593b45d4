"""A scene: one complete study (surfaces, material, fluid, geometry, parameter axes, outputs).

:class:`Scene` and :class:`SurfaceSpec` are plain frozen records built by
:func:`fastcontact.studies.load.load_scene`; :meth:`Scene.cases` enumerates the cases (every
combination, or the zip, of the axes) in chunks of bounded size. The scene file format is
described in :mod:`fastcontact.studies.load`.

This module is also the historical home of the scene API (``fastcontact.scene``): the names
``load_scene``, ``run_scene``, ``parse_quantity``, ``default_table_path``, ... resolve, on
first use, to their modules in :mod:`fastcontact.studies`, :mod:`fastcontact.tables.cache` and
:mod:`fastcontact._core.units`.
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
from pathlib import Path

import numpy as np
import pandas as pd

from .._core.lazy import lazy_getattr
from .._core.vocab import THEORIES
from ..contact.elasticity import effective_modulus
from ..surface.psd import SelfAffinePSD
from .schema import MAX_CASES

__all__ = ["Scene", "SurfaceSpec", "SceneError", "DEFAULT_CHUNK"]

#: cases evaluated (and written) per block by :func:`fastcontact.studies.run.run_scene`
DEFAULT_CHUNK = 100_000


class SceneError(ValueError):
    """An invalid scene: ``problems`` lists every problem found (each names its key)."""

    def __init__(self, source, problems):
        self.source = str(source)
        self.problems = list(problems)
        n = len(self.problems)
        head = f"scene {self.source} is invalid ({n} problem{'s' if n != 1 else ''})"
        super().__init__(head + ": " + "; ".join(self.problems))


@dataclasses.dataclass(frozen=True)
class SurfaceSpec:
    """One surface of a scene.

    Attributes
    ----------
    name : str
        Key of the surface in ``[surfaces]``.
    source : str
        ``"table"`` (a table file), ``"psd"`` (a PSD file), ``"self_affine"`` (parameters)
        or ``"inline"`` (an already-built PSD, e.g. from a road database).
    path : pathlib.Path or None
        Table or PSD file.
    convention : str or None
        C convention of a PSD file (``"persson"`` | ``"surface_topography"``).
    params : dict
        Self-affine parameters ``h_rms`` [m], ``hurst``, ``q0``, ``q1``, ``q_roll`` [1/m].
    label : str or None
        Legend label.
    psd_obj : PSD or None
        The surface's PSD, when already built.
    """

    name: str
    source: str
    path: Path | None = None
    convention: str | None = None
    params: dict = dataclasses.field(default_factory=dict)
    label: str | None = None
    psd_obj: object = None

    def psd(self):
        """The surface's PSD (built once; a table surface has one only if it was described)."""
        if self.psd_obj is not None:
            return self.psd_obj
        if self.source == "self_affine":
            obj = SelfAffinePSD(self.params["h_rms"], self.params["hurst"], self.params["q0"],
                                self.params["q1"], self.params.get("q_roll"))
        elif self.source == "psd":
            from ..surface.topography import read_psd   # here: table-only runs stay light
            obj = read_psd(self.path, self.convention)
        else:
            raise ValueError(f"surface {self.name!r} is given as a table file")
        object.__setattr__(self, "psd_obj", obj)
        return obj

    def describe(self) -> dict:
        """JSON-serialisable description (for provenance and messages)."""
        if self.source == "table":
            return {"table": str(self.path)}
        if self.source == "psd":
            return {"psd": str(self.path), "convention": self.convention}
        if self.source == "self_affine":
            return {"self_affine": dict(self.params)}
        return {"inline": self.psd().to_dict()}


@dataclasses.dataclass(frozen=True)
class Scene:
    """A validated scene. Build with :func:`fastcontact.studies.load.load_scene`.

    Attributes
    ----------
    axes : dict
        Axis name → list of values (SI floats; ``theory``: strings), in schema order.
    fixed : dict
        Non-axis study parameters (ratios, du, times, profile, ...), SI.
    table_options : dict
        ``gamma``, ``a_perc``, ``alpha_cj`` of the tables (defaults filled in).
    columns, figures : list of str
        Result columns and figures requested.
    combine : str
        ``"product"`` (every combination of the axes) or ``"zip"``.
    max_cases : int
        Largest study (cases x surfaces) the scene may run.
    """

    source: str
    base_dir: Path
    text: str
    data: dict
    title: str
    kind: str
    surfaces: dict
    axes: dict
    fixed: dict
    table_options: dict
    table_options_given: dict
    cache_dir: str | None
    columns: list
    figures: list
    combine: str
    max_cases: int = MAX_CASES

    @property
    def theories(self) -> tuple:
        """The theories the study needs, in canonical order."""
        ths = set(self.axes["theory"])
        return tuple(t for t in THEORIES if t in ths)

    @property
    def sha256(self) -> str:
        """SHA-256 of the scene text."""
        return hashlib.sha256(self.text.encode()).hexdigest()

    @property
    def n_cases(self) -> int:
        """Number of cases per surface (counted, nothing allocated)."""
        return count_cases(self.axes, self.combine)

    def cases(self, start=0, stop=None) -> pd.DataFrame:
        """The cases ``start``..``stop`` (default all): one row each, ``case_id``, SI units.

        Cases are enumerated by index arithmetic (C order of the axes, the last axis fastest;
        or the zip), so a block costs memory in proportion to its own length. ``E_star`` is
        added from ``E``, ``nu`` (and ``E2``, ``nu2``) when not given.
        """
        n = self.n_cases
        stop = n if stop is None else min(int(stop), n)
        idx = np.arange(int(start), stop, dtype=np.int64)
        names = list(self.axes)
        if self.combine == "zip":
            pos = [idx if len(self.axes[k]) > 1 else np.zeros_like(idx) for k in names]
        else:
            pos = np.unravel_index(idx, [len(self.axes[k]) for k in names]) if names else []
        cols = {}
        for k, p in zip(names, pos):
            vals = self.axes[k]
            arr = np.asarray(vals, dtype=object if k == "theory" else float)
            cols[k] = arr[p]
        df = pd.DataFrame(cols, index=pd.RangeIndex(len(idx)))
        if "E_star" not in self.axes and len(df):
            kw = {}
            if "E2" in df:
                kw = dict(E2=df["E2"].to_numpy(float), nu2=df["nu2"].to_numpy(float))
            df["E_star"] = np.asarray(effective_modulus(df["E"].to_numpy(float),
                                                        df["nu"].to_numpy(float), **kw), float)
        elif "E_star" not in self.axes:
            df["E_star"] = np.zeros(0)
        df.insert(0, "case_id", idx)
        return df

    def chunks(self, size=DEFAULT_CHUNK):
        """Yield the cases in blocks of at most ``size`` rows (see :meth:`cases`)."""
        n = self.n_cases
        for start in range(0, max(n, 1), int(size)):
            yield self.cases(start, start + int(size))

    def normalized(self) -> dict:
        """JSON-serialisable resolved scene (SI values), for provenance."""
        return {
            "title": self.title, "kind": self.kind,
            "surfaces": {k: s.describe() for k, s in self.surfaces.items()},
            "axes": {k: list(v) if isinstance(v, tuple) else v for k, v in self.axes.items()},
            "fixed": {k: (list(v) if isinstance(v, tuple) else v)
                                         for k, v in self.fixed.items()},
            "table_options": self.table_options, "columns": self.columns,
            "figures": self.figures, "combine": self.combine,
        }


def count_cases(axes, combine="product") -> int:
    """Number of cases of ``axes`` (lengths multiplied, or the longest for ``"zip"``)."""
    lens = [len(v) for v in axes.values()]
    if not lens:
        return 1
    return max(lens) if combine == "zip" else math.prod(lens)


# ------------------------------------------------------------------ the former scene API
#: new module -> the names of the former scene API it now holds
_LEGACY_HOMES = {
    "fastcontact.studies.load": ("load_scene", "available_figures"),
    "fastcontact.studies.schema": ("STUDY_KINDS", "SCHEMA", "SURFACE_KEYS", "AXIS_KEYS"),
    "fastcontact._core.units": ("parse_quantity", "parse_unit", "UnitError", "DIMENSIONS",
                                "UNIT_EXAMPLES"),
    "fastcontact.studies.examples": ("default_table_path", "example_scene_path",
                                     "list_example_scenes"),
    "fastcontact.tables.cache": ("table_cache_dir", "obtain_tables", "build_tables", "table_key"),
    "fastcontact.studies.run": ("run_scene", "RunResult", "provenance", "PAPER_REFERENCE"),
    "fastcontact.studies.evaluate": ("evaluate_cases", "empty_results"),
    "fastcontact.studies.kinds": ("available_columns", "squeeze_columns", "BOOL_COLUMNS",
                                  "SEAL_COLUMNS", "SEAL_HERTZ_COLUMNS", "SQUEEZE_TAIL"),
    "fastcontact.studies.output": ("write_parquet_atomic", "_atomic_write_bytes",
                                   "_json_default"),
}
_LEGACY = {name: mod for mod, names in _LEGACY_HOMES.items() for name in names}


#: the former scene API, resolved from its new module on first use
__getattr__ = lazy_getattr(__name__, _LEGACY)


def __dir__():
    return sorted(set(globals()) | set(_LEGACY))
