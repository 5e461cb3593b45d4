"""The argument parser of ``fastcontact`` (:func:`build_parser`): every command, its options
and their defaults, and the option types that check a value as it is read.

Only :mod:`argparse` at import: the commands' own modules are imported by the runners in
:mod:`fastcontact.cli` when a command runs (CLI start-up time).
"""
from __future__ import annotations

import argparse

from ._core.vocab import CONVENTIONS, THEORIES

__all__ = ["build_parser", "CLIError"]


class CLIError(ValueError):
    """Bad command-line input."""


class _Help(argparse.ArgumentDefaultsHelpFormatter):
    """Shows an option's default where it has one (not for flags and open options)."""

    def _get_help_string(self, action):
        if action.default in (None, False) or action.default is argparse.SUPPRESS:
            return action.help
        return super()._get_help_string(action)


class _Parser(argparse.ArgumentParser):
    """One-line errors (exit 2) and every option's default shown in its help."""

    def __init__(self, *args, **kw):
        kw.setdefault("formatter_class", _Help)
        super().__init__(*args, **kw)

    def error(self, message):  # one line, exit 2
        raise CLIError(f"{self.prog}: {message}")


def _quantity(dim):
    """Option type: a quantity of dimension ``dim`` in SI units (a number, or e.g. '0.72 mm')."""
    def conv(text):
        from ._core.units import parse_quantity
        try:
            return parse_quantity("value", text, dim)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc).replace("value = ", "")) from None
    conv.__name__ = dim
    return conv


def _count(text):
    """A positive whole number, also written as 2e7."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (x >= 1 and x == int(x)):
        raise argparse.ArgumentTypeError(f"{text!r} must be a whole number >= 1")
    return int(x)


def _add_tables_parser(sub):
    """The ``tables`` command and its subcommands."""
    t = sub.add_parser("tables", help="build or inspect contact/flow tables")
    tsub = t.add_subparsers(dest="tables_command", metavar="SUBCOMMAND", parser_class=_Parser)
    tb = tsub.add_parser("build", help="tabulate one surface")
    tb.add_argument("--h-rms", type=_quantity("length"), help="rms roughness (m, or e.g. '0.72 mm')")
    tb.add_argument("--hurst", type=float, help="Hurst exponent H")
    tb.add_argument("--q0", type=_quantity("wavevector"), help="smallest wavevector [1/m]")
    tb.add_argument("--q1", type=_quantity("wavevector"), help="largest wavevector [1/m]")
    tb.add_argument("--q-roll", type=_quantity("wavevector"), help="roll-off wavevector [1/m]")
    tb.add_argument("--psd", help="PSD file (.csv or .parquet with columns q, C)")
    tb.add_argument("--convention", choices=tuple(CONVENTIONS),
                    help="normalisation of the PSD file's C")
    tb.add_argument("--theories", nargs="+", default=list(THEORIES),
                    help="flow theories to tabulate (space or comma separated)")
    tb.add_argument("--gamma", type=float, default=1.0, help="Yang-Persson factor (1 = paper)")
    tb.add_argument("--a-perc", type=float, default=0.5, help="percolation threshold A/A0")
    tb.add_argument("--alpha-cj", type=float, default=1.0, help="critical-junction factor")
    tb.add_argument("--emt-threshold", type=float, default=0.5,
                    help="effective-medium percolation threshold A/A0 (0.5 = 2-D Bruggeman)")
    tb.add_argument("--calibration", help="calibration TOML file (fastcontact bem calibrate): "
                                          "sets gamma, a_perc, alpha_cj, emt_threshold")
    tb.add_argument("--anisotropy", type=float, default=1.0,
                    help="Peklenik number gamma_T >= 1 (roughness stretched along x; needs emt): "
                         "also tabulate sigma_xx, sigma_yy")
    tb.add_argument("--anisotropy-form", choices=("self_consistent", "fixed"),
                    default="self_consistent", help="depolarization form of the anisotropic medium")
    tb.add_argument("-o", "--output", required=True, help="output .parquet file")
    ti = tsub.add_parser("info", help="show a table file's metadata")
    ti.add_argument("file", help="tables .parquet file")
    ti.add_argument("--json", action="store_true", help="print the raw metadata as JSON")
    td = tsub.add_parser("defaults", help="rebuild the embedded default tables")
    td.add_argument("-o", "--output-dir", action="append",
                    help="folder to write to (repeatable; default: fastcontact/data and "
                         "tables/ of a source checkout; never an installed package)")


def build_parser():
    """The ``fastcontact`` argument parser: every command, subcommand and option."""
    p = _Parser(prog="fastcontact", description="Persson contact mechanics, fluid squeeze-out "
                "and seal leakage between rough surfaces (Lorenz & Persson 2010).")
    from . import __version__
    p.add_argument("--version", action="version", version=f"fastcontact {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    r = sub.add_parser("run", help="run a scene (TOML) and write results, summary and figures")
    r.add_argument("scene", nargs="?", help="scene file or shipped example name")
    r.add_argument("--default", action="store_true", help="run the default scene (embedded tables)")
    r.add_argument("-o", "--outdir", required=True,
                   help="output folder (created; files in an existing folder are replaced)")
    r.add_argument("--cache-dir", help="cache folder of tables and squeeze time primitives "
                   "(default: $FASTCONTACT_CACHE_DIR, else the user cache folder from "
                   "platformdirs, + /tables)")
    r.add_argument("--max-cases", type=_count, default=None,
                   help="largest study allowed, cases x surfaces (default: the scene's "
                        "[outputs] max_cases, else 2e7)")
    r.add_argument("--no-figures", action="store_true", help="do not draw the scene's figures")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress messages or bar")

    v = sub.add_parser("validate", help="validate a scene; report every problem; write nothing")
    v.add_argument("scene", help="scene file or shipped example name")
    v.add_argument("--max-cases", type=_count, default=None,
                   help="largest study allowed (default: the scene's, else 2e7)")

    s = sub.add_parser("scenes", help="list the shipped example scenes, or print one")
    s.add_argument("name", nargs="?", help="example scene to print")

    _add_tables_parser(sub)

    w = sub.add_parser("sweep", help="evaluate a scene on every surface of a road database (Dask)")
    w.add_argument("database", help="road database (Parquet dataset or folder of PSD files)")
    w.add_argument("-o", "--outdir", required=True, help="output folder (data/ + manifest.json)")
    w.add_argument("--scene", required=True, help="scene file or shipped example name")
    w.add_argument("--scheduler", help="address of an existing Dask scheduler")
    w.add_argument("--workers", type=int, help="local worker processes (default: cores)")
    w.add_argument("--convention", choices=tuple(CONVENTIONS),
                   help="C convention of database files that record none")
    w.add_argument("--cache-dir", help="keep/reuse the tables there (default: not kept)")
    w.add_argument("--no-progress", action="store_true", help="no progress line")

    c = sub.add_parser("compile", help="compile the engines' kernels ahead of a study "
                       "(numba's disk cache; tens of seconds per group on a new machine)")
    c.add_argument("groups", nargs="*", metavar="GROUP",
                   help="tables, squeeze, tire, seal, viscosity (default: every group, or "
                        "those of --scene)")
    c.add_argument("--scene", help="compile the groups this scene needs (file or shipped "
                   "example name)")
    c.add_argument("-j", "--jobs", type=_count, default=1,
                   help="groups compiled at once, each in its own process")

    f = sub.add_parser("figures", help="regenerate every paper figure the engine makes")
    f.add_argument("-o", "--outdir", required=True, help="output folder for the PNG files")

    d = sub.add_parser("roaddb", help="road databases")
    dsub = d.add_subparsers(dest="roaddb_command", metavar="SUBCOMMAND", parser_class=_Parser)
    dg = dsub.add_parser("generate", help="write a synthetic road database")
    dg.add_argument("path", help="output Parquet dataset folder")
    dg.add_argument("-n", "--n", dest="n", type=int, required=True, help="number of surfaces")
    dg.add_argument("--seed", type=int, required=True, help="random seed")
    dg.add_argument("--n-q", type=int, default=None,
                    help="samples per spectrum (default: the roaddb module's N_Q)")
    dg.add_argument("--convention", choices=tuple(CONVENTIONS), default="persson",
                    help="C convention written to the files")
    di = dsub.add_parser("info", help="summarise a road database")
    di.add_argument("path", help="road database (Parquet dataset or folder of PSD files)")
    di.add_argument("--convention", choices=tuple(CONVENTIONS),
                    help="C convention of files that record none")
    from .validation.cli import add_bem_commands  # `fastcontact bem` (issue 13)
    add_bem_commands(sub, _comparison_figure)
    return p


def _comparison_figure(comparison, path):
    """``fastcontact bem compare --figure``: matplotlib is imported on use, by the figures."""
    from .figures.validation_figures import comparison_figure
    return comparison_figure(comparison, path)
