"""The embedded default surfaces and their precomputed tables.

The paper's measured spectra are not published as data, so each surface is a documented
**self-affine stand-in** with the paper's h_rms and parameters typical of its kind, chosen so
that the paper's stated regimes hold:

================  =======  ====  ==============  ==============  =======  =====================
name              h_rms    H     q0 [1/m]        q_roll [1/m]    q1       why
================  =======  ====  ==============  ==============  =======  =====================
asphalt_072mm     0.72 mm  0.8   2π/5 cm         2π/8 mm         1e6      Sec. 5 road 1; ū > 2 h_rms at p0 = 0.2 MPa, E = 10 MPa
asphalt_024mm     0.24 mm  0.8   2π/2 cm         2π/3 mm         1e6      Sec. 5 road 2; ū > 2 h_rms there too
copper_012mm      0.12 mm  0.8   1150            (none)          1e6      Sec. 3; κ = p0/(βE*) = 1.48 and 10.3 at 0.2 and 1.4 MPa (paper: 1.5, 10.3), E = 2.3 MPa, ν = 0.5; percolates (A(ζ1)/A0 = 0.5) below 1.4 MPa
pmma_34um         34 µm    0.8   2π/1 cm         2π/2 mm         1e7      Secs. 7–8 sand-blasted PMMA; ū ≈ 2 h_rms at p0 = 11.8 kPa
================  =======  ====  ==============  ==============  =======  =====================

All tables hold the three flow theories with the paper's defaults (γ = 1, a_perc = 0.5,
α_cj = 1; the seal experiment rescales σ_cj by α_cj³ = 0.54³). Rebuild all of them with
``fastcontact tables defaults`` (or :func:`build_default_tables`) in a source checkout; the
test-suite rebuilds them and compares with the shipped files.
"""
from __future__ import annotations

import math
from pathlib import Path

from .._core.vocab import THEORIES
from ..surface.psd import SelfAffinePSD
from .build import precompute
from .store import Tables

__all__ = ["DEFAULT_SURFACES", "UnknownDefaultTable", "default_surface", "default_table_path", "load_default_tables",
           "build_default_tables", "default_outdirs"]

DEFAULT_SURFACES = {
    "asphalt_072mm": dict(h_rms=0.72e-3, hurst=0.8, q0=2 * math.pi / 0.05,
                          q_roll=2 * math.pi / 0.008, q1=1e6),
    "asphalt_024mm": dict(h_rms=0.24e-3, hurst=0.8, q0=2 * math.pi / 0.02,
                          q_roll=2 * math.pi / 0.003, q1=1e6),
    "copper_012mm": dict(h_rms=0.12e-3, hurst=0.8, q0=1150.0, q_roll=None, q1=1e6),
    "pmma_34um": dict(h_rms=34e-6, hurst=0.8, q0=2 * math.pi / 0.01, q_roll=2 * math.pi / 0.002,
                      q1=1e7),
}
DEFAULT_THEORIES = THEORIES

PACKAGE_DATA = Path(__file__).resolve().parent.parent / "data"
#: the repository root when fastcontact runs from a source checkout (None when installed)
_REPO = Path(__file__).resolve().parent.parent.parent
SOURCE_CHECKOUT = _REPO if (_REPO / "pyproject.toml").is_file() and (_REPO / "tables").is_dir() else None


def _check_name(name):
    if name not in DEFAULT_SURFACES:
        raise ValueError(f"surface = {name!r} is invalid: the embedded defaults are "
                         f"{sorted(DEFAULT_SURFACES)}")
    return name


def default_surface(name):
    """The SelfAffinePSD stand-in of an embedded default surface."""
    return SelfAffinePSD(**DEFAULT_SURFACES[_check_name(name)])


class UnknownDefaultTable(FileNotFoundError, ValueError):
    """A name that is not one of the embedded default tables (both a missing file and a bad value)."""


def default_table_path(name) -> Path:
    """Path of the shipped Parquet tables of an embedded default surface (the only definition).

    Parameters
    ----------
    name : str
        One of :data:`DEFAULT_SURFACES` (``"asphalt_072mm"``, ...); a ``.parquet`` suffix is
        allowed.

    Returns
    -------
    pathlib.Path
        The copy inside the package (``fastcontact/data``), else the source checkout's
        ``tables/``.

    Raises
    ------
    UnknownDefaultTable
        (a FileNotFoundError and a ValueError) naming the available tables.
    """
    stem = str(name)
    stem = stem[: -len(".parquet")] if stem.endswith(".parquet") else stem
    if stem not in DEFAULT_SURFACES:
        raise UnknownDefaultTable(f"table {str(name)!r} is not an embedded default table "
                                  f"(available: {', '.join(sorted(DEFAULT_SURFACES))})")
    for folder in (PACKAGE_DATA, Path(__file__).resolve().parent.parent.parent / "tables"):
        path = folder / f"{stem}.parquet"
        if path.is_file():
            return path
    raise FileNotFoundError(f"the embedded table {stem}.parquet is missing from {PACKAGE_DATA}: "
                            f"reinstall fastcontact or run `fastcontact tables defaults`")


def load_default_tables(name):
    """The shipped :class:`~fastcontact.tables.Tables` of an embedded default surface."""
    return Tables.from_parquet(default_table_path(name))


def default_outdirs():
    """The folders :func:`build_default_tables` writes by default: in a source checkout the
    package's ``fastcontact/data`` (what an install loads) and the repository's ``tables/``;
    ValueError for an installed package (never written into)."""
    if SOURCE_CHECKOUT is None:
        raise ValueError("outdirs = None is invalid for an installed fastcontact: the package "
                         "folder is not written into; give an output folder (e.g. "
                         "`fastcontact tables defaults -o DIR`)")
    return [PACKAGE_DATA, SOURCE_CHECKOUT / "tables"]


def build_default_tables(outdirs=None, names=None):
    """Rebuild the default tables and write them (atomically) to every folder in ``outdirs``.

    Parameters
    ----------
    outdirs : sequence of path-like, optional
        Folders to write ``<name>.parquet`` into. Default: only in a source checkout, the
        package's ``fastcontact/data`` and the repository's top-level ``tables/``; an installed
        package is never written into (pass an explicit folder instead).
    names : sequence of str, optional
        Surfaces to rebuild (default all of :data:`DEFAULT_SURFACES`).

    Returns
    -------
    dict
        {name: Tables}.
    """
    if outdirs is None:
        outdirs = default_outdirs()
    if isinstance(outdirs, (str, Path)):
        outdirs = [outdirs]
    built = {}
    for name in names or DEFAULT_SURFACES:
        t = precompute(default_surface(name), theories=DEFAULT_THEORIES)
        for d in outdirs:
            t.to_parquet(Path(d) / f"{name}.parquet")
        built[name] = t
    return built
