"""Command-line interface: ``fastcontact <command> ...``.

Commands
--------
``fastcontact run SCENE -o OUTDIR``            run a scene (a TOML file or a shipped example name)
``fastcontact run --default -o OUTDIR``        run the default scene on the embedded tables
``fastcontact validate SCENE``                 check a scene, write nothing
``fastcontact scenes [NAME]``                  list the shipped example scenes (or print one)
``fastcontact tables build ... -o OUT.parquet``  tabulate a surface (self-affine or PSD file)
``fastcontact tables info FILE``               show a table file's metadata
``fastcontact sweep DB -o OUT --scene S.toml [--scheduler ADDR] [--workers N]``
``fastcontact roaddb generate PATH --n N --seed S``  synthetic road database
``fastcontact roaddb info PATH``               summary of a road database
``fastcontact figures -o OUTDIR``              regenerate every paper figure
``fastcontact compile [GROUP ...] [--scene S] [-j N]``  compile the kernels ahead of a study

Bad input (invalid scene, missing file, wrong option) exits with code 2 and a one-line
message on stderr, no traceback.

This module holds the entry point :func:`main` and the command runners; the argument parser
(:func:`build_parser`, re-exported here) is built in :mod:`fastcontact.cli_parser`.
"""
from __future__ import annotations

import atexit
import gc
import importlib
import importlib.util
import json
import math
import os
import sys
import threading
from pathlib import Path

from .cli_parser import CLIError, build_parser
from ._core.vocab import CONVENTIONS
from .studies.progress import Progress

__all__ = ["main", "build_parser"]

EXIT_BAD_INPUT = 2
#: optional packages and the extra that installs them
_EXTRAS = {"dask": "distributed", "distributed": "distributed", "SurfaceTopography": "topography",
           "ContactMechanics": "bem", "matplotlib": "plots"}


# ============================================================================ commands
def _figure_maker(err):
    """The scene figure maker, or None with a one-line note if matplotlib is missing."""
    if importlib.util.find_spec("matplotlib") is None:
        print("note: matplotlib is not installed: figures skipped (pip install matplotlib)",
              file=err)
        return None
    from .figures.scene import make_scene_figure
    return make_scene_figure


def _cmd_run(a, out, err):
    from .studies.examples import example_scene_path
    from .studies.load import load_scene
    from .studies.run import run_scene
    if a.default and a.scene:
        raise CLIError("fastcontact run: give a scene or --default, not both")
    if not a.default and not a.scene:
        raise CLIError("fastcontact run: give a scene file (or --default)")
    if Path(a.outdir).exists() and not Path(a.outdir).is_dir():
        raise CLIError(f"fastcontact run: -o {a.outdir!r} is a file, not a folder")
    scene = load_scene(example_scene_path("default") if a.default else a.scene,
                       max_cases=a.max_cases)
    log = (lambda m: None) if a.quiet else (lambda m: print(m, file=err))
    maker = None if (a.no_figures or not scene.figures) else _figure_maker(err)
    res = run_scene(scene, a.outdir, cache_dir=a.cache_dir, log=log, make_figures=maker,
                    progress=not a.quiet, progress_file=err)
    print(f"results: {res.results_path} ({res.record['rows']} rows)", file=out)
    print(f"summary: {res.summary_path}", file=out)
    print(f"build record: {res.build_record_path}", file=out)
    for p in res.figures:
        print(f"figure: {p}", file=out)
    nerr = res.record["failed_rows"]
    if nerr:
        print(f"warning: {nerr} case(s) failed; see the 'error' column", file=err)
    return 0


def _cmd_validate(a, out, err):
    from .studies.load import load_scene
    sc = load_scene(a.scene, max_cases=a.max_cases)
    print(f"{sc.source}: valid {sc.kind} scene, {len(sc.surfaces)} surface(s) x {sc.n_cases} "
          f"case(s), theories {', '.join(sc.theories)}", file=out)
    return 0


def _cmd_scenes(a, out, err):
    from .studies.examples import example_scene_path, list_example_scenes
    if a.name:
        print(example_scene_path(a.name).read_text(), file=out, end="")
        return 0
    for n in list_example_scenes():
        text = example_scene_path(n).read_text()
        first = text.splitlines()[0] if text else ""
        print(f"{n:24s} {first.lstrip('# ').strip()}", file=out)
    return 0


def _split_theories(vals):
    out = []
    for v in vals:
        out.extend(x for x in v.split(",") if x)
    return out


def _existing_file(path, option):
    """``path`` if it is a file, else CLIError naming the option."""
    if not Path(path).is_file():
        raise CLIError(f"fastcontact tables build: {option} {str(path)!r}: file not found")
    return Path(path)


def _cmd_tables_build(a, out, err):
    from .tables import precompute
    sa = {"--h-rms": a.h_rms, "--hurst": a.hurst, "--q0": a.q0, "--q1": a.q1}
    if a.psd is not None:
        if any(v is not None for v in list(sa.values()) + [a.q_roll]):
            raise CLIError("fastcontact tables build: give either --psd FILE --convention X or "
                           "--h-rms --hurst --q0 --q1 [--q-roll], not both")
        if a.convention is None:
            raise CLIError("fastcontact tables build: --psd needs --convention "
                           + "|".join(CONVENTIONS))
        from .surface.topography import read_psd
        psd = read_psd(a.psd, a.convention)
    else:
        missing = [k for k, v in sa.items() if v is None]
        if missing:
            raise CLIError(f"fastcontact tables build: missing {', '.join(missing)} "
                           f"(or give --psd FILE --convention X)")
        if a.convention is not None:
            raise CLIError("fastcontact tables build: --convention is only used with --psd")
        from .surface.psd import SelfAffinePSD
        psd = SelfAffinePSD(a.h_rms, a.hurst, a.q0, a.q1, a.q_roll)
    if not str(a.output).endswith(".parquet"):
        raise CLIError(f"fastcontact tables build: -o {a.output!r} must end in .parquet")
    theories = _split_theories(a.theories)
    print(f"building tables for {psd!r}, theories {theories} ...", file=err)
    with Progress(1, True, err) as prog:
        prog.step("tabulating")
        cal = None
        if a.calibration is not None:
            from .validation.calibration import Calibration
            cal = Calibration.from_toml(_existing_file(a.calibration, "--calibration"))
        T = precompute(psd, theories=theories, gamma=a.gamma, a_perc=a.a_perc,
                       alpha_cj=a.alpha_cj, emt_threshold=a.emt_threshold, calibration=cal,
                       anisotropy=a.anisotropy, anisotropy_form=a.anisotropy_form)
        prog.advance()
    T.to_parquet(a.output)
    print(f"wrote {a.output} ({T.info['nodes']} nodes, {T.info['build_seconds']:.2f} s)", file=out)
    return 0


def _fmt_dict(d):
    return ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}" for k, v in d.items())


def tables_info_text(path):
    """Readable summary of a tables file's metadata (validated by Tables.from_parquet)."""
    from .tables import Tables
    T = Tables.from_parquet(path)
    m = T.metadata()
    s, info = T.surface, T.info
    g = T.grid
    lines = [f"file: {path}",
             f"surface: {s!r}",
             f"  kind: {m['surface'].get('kind')}; h_rms = {s.h_rms:.6g} m; q0 = {s.q0:.6g} 1/m; "
             f"q1 = {s.q1:.6g} 1/m; rms slope = {s.rms_slope:.6g}",
             f"  surface hash: {m['surface_hash']}",
             f"theories: {', '.join(T.theories)}",
             f"options: {_fmt_dict(T.options)}",
             f"grid: p/E* from {T.p_range[0]:.4g} to {T.p_range[1]:.4g} ({info.get('nodes')} nodes; "
             f"base grid 10^{g.log10_min:g}..10^{g.log10_max:g} with {g.n} nodes, "
             f"{info.get('refinement_rounds')} refinement rounds)",
             f"  u/h_rms from {T.u_range[0]:.4g} to {T.u_range[1]:.4g}"]
    err = info.get("interpolation_error", {})
    if err:
        lines.append("interpolation errors (max relative, interval midpoints): " + _fmt_dict(err))
    tol = info.get("tolerance")
    if tol:
        lines.append("tolerances: " + _fmt_dict(tol))
    perc = info.get("percolation_p_over_E", {})
    if perc:
        lines.append("percolation pressure p/E*: " + ", ".join(
            f"{k} = {'never' if not math.isfinite(v) else format(v, '.6g')}" for k, v in perc.items()))
    d = info.get("directional")
    if d:                                              # issue 14: anisotropic tables
        lines.append(f"anisotropy: gamma_T = {d.get('anisotropy')}, form {d.get('form')}; "
                     f"percolation p/E*: {_fmt_dict(d.get('percolation_p_over_E', {}))}; "
                     f"interpolation errors: {_fmt_dict(d.get('interpolation_error', {}))}")
    if "asymptote_u0_over_h" in info:
        lines.append(f"asymptote (eq. 3): u0/h_rms = {info['asymptote_u0_over_h']:.6g}, "
                     f"beta = {info['asymptote_beta']:.6g}")
    bs = info.get("build_seconds")
    lines.append(f"build time: {bs:.3f} s" if isinstance(bs, (int, float)) else "build time: ?")
    lines.append(f"fastcontact version: {m['fastcontact_version']} (schema {m['schema_version']})")
    lines.append(f"columns sha256: {m['columns_sha256']}")
    lines.append("references:")
    lines.extend(f"  - {r}" for r in m.get("references", []))
    return "\n".join(lines) + "\n"


def _cmd_tables_info(a, out, err):
    if a.json:
        from .tables import Tables
        print(json.dumps(Tables.from_parquet(a.file).metadata(), indent=1, sort_keys=True,
                         default=str), file=out)
    else:
        print(tables_info_text(a.file), file=out, end="")
    return 0


def _cmd_tables_defaults(a, out, err):
    from .tables.defaults import build_default_tables, default_outdirs
    dirs = a.output_dir
    if not dirs:
        try:
            dirs = [str(d) for d in default_outdirs()]
        except ValueError:
            raise CLIError("fastcontact tables defaults: not in a source checkout; give the "
                           "folder to write to with -o DIR (the installed package is never "
                           "written)") from None
    print(f"building the default tables into {', '.join(dirs)} ...", file=err)
    built = build_default_tables(dirs)
    for name, t in built.items():
        e = t.info["interpolation_error"]
        print(f"{name}: {t.info['nodes']} nodes, built in {t.info['build_seconds']:.2f} s, "
              f"max interpolation error {max(e.values()):.1e}", file=out)
    return 0


#: after a sweep, one line on stderr per non-empty manifest list: (manifest key, line with
#: ``{}`` for the number of surfaces)
_SWEEP_NOTES = (
    ("surfaces_with_error_rows",
     "warning: {} surface(s) have error rows (see the 'error' column and the manifest)"),
    ("surfaces_with_notes",
     "note: {} surface(s) have table notes (e.g. a fallback build; see 'partitions' in the "
     "manifest)"),
)


def _cmd_sweep(a, out, err):
    from .studies.sweep import run_sweep
    man = run_sweep(a.database, a.outdir, a.scene, scheduler=a.scheduler, workers=a.workers,
                    convention=a.convention, cache_dir=a.cache_dir,
                    progress=not a.no_progress, log=lambda m: print(m, file=err))
    print(f"sweep {man['status']}: {len(man['partitions'])}/{man['n_surfaces']} surfaces, "
          f"{man['rows']} rows in {a.outdir}/data (manifest {a.outdir}/manifest.json)", file=out)
    if man["failed"]:
        print(f"error: {len(man['failed'])} surface task(s) crashed, e.g. "
              f"{next(iter(man['failed'].items()))}; rerun to retry", file=err)
        return 1
    for key, line in _SWEEP_NOTES:
        if man[key]:
            print(line.format(len(man[key])), file=err)
    return 0


FIGURE_MODULES = (
    ("fastcontact.figures.reduced_figures", "make_reduced_figures"),
    ("fastcontact.figures.squeeze_figures", "make_squeeze_figures"),
    ("fastcontact.figures.tire_figures", "make_tire_figures"),
    ("fastcontact.figures.seal_figures", "make_seal_figures"),
)


def _cmd_figures(a, out, err):
    outdir = Path(a.outdir)
    funcs = []
    for mod, fn in FIGURE_MODULES:   # import all first: a missing module fails before any work
        try:
            m = importlib.import_module(mod)
        except ModuleNotFoundError as exc:
            if exc.name and mod.startswith(exc.name):
                raise SystemExit(f"fastcontact figures: figure module {mod} is missing "
                                 f"({exc}); cannot regenerate every paper figure") from None
            raise   # an optional dependency (matplotlib): main() reports it in one line
        if not hasattr(m, fn):
            raise SystemExit(f"fastcontact figures: {mod} has no {fn}()")
        funcs.append((mod, getattr(m, fn)))
    n = 0
    with Progress(len(funcs), True, err) as prog:
        for mod, fn in funcs:
            prog.step(mod.rsplit(".", 1)[-1])
            print(f"{mod} ...", file=err)
            for p in fn(outdir) or []:
                print(f"figure: {p}", file=out)
                n += 1
            prog.advance()
    print(f"{n} figures in {outdir}", file=out)
    return 0


def _cmd_compile(a, out, err):
    from .warm import GROUPS, numba_cache_dir, scene_groups, warm
    bad = [g for g in a.groups if g not in GROUPS]
    if bad:
        raise CLIError(f"fastcontact compile: group {bad[0]!r} is invalid: must be one of "
                       f"{', '.join(GROUPS)}")
    groups = list(a.groups)
    if a.scene:
        from .studies.load import load_scene
        groups += scene_groups(load_scene(a.scene))
    groups = list(dict.fromkeys(groups)) or list(GROUPS)
    print(f"compiling {', '.join(groups)} ({a.jobs} at a time; kernels already in the cache "
          "load in milliseconds) ...", file=err)
    try:
        secs = warm(groups, jobs=a.jobs, log=lambda m: print(m, file=err))
    except RuntimeError as exc:  # a group's process failed: its last error line
        print(f"fastcontact compile: error: {exc}", file=err)
        return 1
    print("compiled: " + ", ".join(f"{g} {s:.1f} s" for g, s in secs.items())
          + f"; numba cache: {numba_cache_dir()}", file=out)
    return 0


def _cmd_roaddb_generate(a, out, err):
    from .surface.roaddb import generate_road_database, N_Q
    p = generate_road_database(a.path, a.n, a.seed, n_q=a.n_q or N_Q, convention=a.convention)
    print(f"wrote road database {p} ({a.n} surfaces, seed {a.seed})", file=out)
    return 0


def _cmd_roaddb_info(a, out, err):
    from .surface.roaddb import open_road_database
    db = open_road_database(a.path, a.convention)
    import numpy as np
    h = []
    for sid in db.ids:
        q, C = db.spectrum(sid)
        h.append(math.sqrt(2 * math.pi * np.sum(0.5 * (q[1:] * C[1:] + q[:-1] * C[:-1]) * np.diff(q))))
    h = np.array(h)
    print(f"{db.path}: {len(db)} surfaces ({db.ids[0]} ... {db.ids[-1]}); h_rms (trapezoid) "
          f"{h.min() * 1e3:.3g}..{h.max() * 1e3:.3g} mm; fingerprint {db.fingerprint[:16]}", file=out)
    return 0


def _dispatch(a):
    if a.command == "tables":
        return {"build": _cmd_tables_build, "info": _cmd_tables_info,
                "defaults": _cmd_tables_defaults}.get(a.tables_command)
    if a.command == "roaddb":
        return {"generate": _cmd_roaddb_generate, "info": _cmd_roaddb_info}.get(a.roaddb_command)
    if a.command == "bem":
        return getattr(a, "bem_func", None)
    return {"run": _cmd_run, "validate": _cmd_validate, "scenes": _cmd_scenes,
            "sweep": _cmd_sweep, "figures": _cmd_figures, "compile": _cmd_compile}[a.command]


#: first-generation threshold of Python's cycle collector while a command runs: its lazy
#: imports allocate millions of objects and free few, and the default (700) makes the
#: collector traverse them hundreds of times (~0.25 s of a 2 s run); cycles are still
#: collected, every 1e5 allocations
GC_THRESHOLD = 100_000
#: commands that, run from the command line, end the process as soon as they are done
#: (:func:`_leave`); not ``sweep`` and ``bem`` (Dask clusters and workers shut down normally)
_LEAVE_AT_ONCE = frozenset({"run", "validate", "scenes", "tables", "figures", "roaddb",
                            "compile"})


def _leave(code):
    """End the process with ``code`` now: the exit handlers run and the standard streams
    are flushed, but the interpreter's teardown is skipped (it spends ~0.3 s CPU freeing
    numba's and LLVM's objects after a kernel has run). Returns (does nothing) while any
    other non-daemon thread is alive or a profiler, tracer or debugger is attached (cProfile,
    coverage, pdb write or finish after ``main`` returns)."""
    if sys.getprofile() is not None or sys.gettrace() is not None:
        return
    if any(t is not threading.main_thread() and t.is_alive() and not t.daemon
           for t in threading.enumerate()):
        return
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)


def main(argv=None, out=None, err=None):
    """Entry point; returns the exit code (0 ok, 1 failure, 2 bad input, 130 interrupted).

    Bad input (SceneError, ValueError, a missing file, an unwritable folder) is reported in
    one line on ``err``, never as a traceback. Called with no arguments (the ``fastcontact``
    command, ``python -m fastcontact``), a finished ``run``, ``figures``, ``tables``, ...
    leaves the process at once with its exit code (:func:`_leave`).
    """
    command = [None]
    threshold = gc.get_threshold()
    gc.set_threshold(GC_THRESHOLD, *threshold[1:])
    try:
        code = _main(argv, out, err, command)
    finally:
        gc.set_threshold(*threshold)
    if argv is None and out is None and err is None and command[0] in _LEAVE_AT_ONCE:
        _leave(code)
    return code


def _main(argv, out, err, command):
    out = out or sys.stdout
    err = err or sys.stderr
    parser = build_parser()
    try:
        a = parser.parse_args(argv)
        command[0] = a.command
        if a.command is None:
            parser.print_help(out)
            return EXIT_BAD_INPUT
        cmd = _dispatch(a)
        if cmd is None:
            raise CLIError(f"fastcontact {a.command}: give a subcommand (see --help)")
        return cmd(a, out, err)
    except (ValueError, OSError) as exc:
        # bad input: SceneError, SweepError, CLIError, TableRangeError, a ValueError from
        # validation, a missing file or an unwritable folder — one line, no traceback
        msg = " ".join(str(exc).split())
        prefix = "" if msg.startswith("fastcontact") else "fastcontact: error: "
        print(prefix + msg, file=err)
        return EXIT_BAD_INPUT
    except ModuleNotFoundError as exc:
        # an optional part that is not installed: one line naming what to install
        top = (exc.name or "").split(".")[0]
        if top == "fastcontact" or not top:
            raise
        extra = _EXTRAS.get(top)
        hint = f"pip install 'fastcontact[{extra}]'" if extra else f"pip install {top}"
        print(f"fastcontact: error: this needs the optional package {top!r}, which is not "
              f"installed ({hint})", file=err)
        return 1
    except KeyboardInterrupt as exc:
        # a sweep's SweepInterrupted carries a one-line message and 130 (SIGINT) / 143 (SIGTERM)
        print(f"fastcontact: {exc}" if str(exc) else "fastcontact: interrupted", file=err)
        return getattr(exc, "exit_code", 130)


def _entry():  # pragma: no cover
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
