"""Running a scene end to end: tables → cases (in blocks) → engines → files.

:func:`run_scene` only wires: the tables come from :mod:`fastcontact.tables.cache`, the
columns and evaluation from :data:`fastcontact.studies.kinds.KINDS`, the files from
:mod:`fastcontact.studies.output`, and the figures from the ``make_figures`` callable the
caller passes in (the CLI passes :func:`fastcontact.figures.scene.make_scene_figure`).
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

from .. import __version__
from .._core.io import write_bytes_atomic
from .._core.vocab import REFERENCES, reference_list
from ..tables.cache import obtain_tables, table_cache_dir
from .evaluate import evaluate_cases
from .kinds import column_units
from .output import ParquetStream, column_summary, write_json_atomic
from .progress import Progress
from .scene import DEFAULT_CHUNK, Scene
from .schema import input_units

__all__ = ["run_scene", "RunResult", "provenance", "PAPER_REFERENCE", "FIGURE_MAX_ROWS",
           "PRIMITIVE_FOLDER"]

PAPER_REFERENCE = reference_list(["lorenz_persson_2010_squeeze"])[0]
#: figures are drawn only for studies of at most this many rows (all surfaces)
FIGURE_MAX_ROWS = 200_000
#: results are returned in memory (``RunResult.results``) up to this many rows
KEEP_MAX_ROWS = 200_000
#: sub-folder of the table cache that keeps the squeeze time primitives of squeeze and tire
#: studies (:func:`fastcontact.squeeze.primitive.set_primitive_cache`): built once per
#: (surface, theory), read by later runs
PRIMITIVE_FOLDER = "squeeze_primitives"


@dataclasses.dataclass
class RunResult:
    """What :func:`run_scene` wrote.

    Attributes
    ----------
    results : pandas.DataFrame or None
        All rows (``attrs["units"]``: the SI unit of every column); None for a study larger
        than ``KEEP_MAX_ROWS`` (read ``results_path`` instead; ``result["results"]`` does).
    results_path, summary_path, build_record_path : pathlib.Path
    figures : list of pathlib.Path
    record : dict
        The build record (also in ``build_record.json``).
    """

    results: pd.DataFrame | None
    results_path: Path
    summary_path: Path
    build_record_path: Path
    figures: list
    record: dict

    def __getitem__(self, key):
        if key == "results" and self.results is None:
            return pd.read_parquet(self.results_path)
        return getattr(self, key)


def provenance(scene, table_records) -> dict:
    """The key-value metadata stored with results: scene, version, table hashes, references."""
    return {
        "fastcontact_version": __version__,
        "paper_reference": PAPER_REFERENCE,
        "references": reference_list(list(REFERENCES)),
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


def _units(scene) -> dict:
    units = input_units()
    units.update(column_units(scene.columns))
    return units


def _check_outdir(outdir, scene):
    if outdir.exists() and not outdir.is_dir():
        raise ValueError(f"outdir = {str(outdir)!r} is invalid: it is a file, not a folder")
    n = scene.n_cases * max(len(scene.surfaces), 1)
    if n > scene.max_cases:
        raise ValueError(f"the study has {n:,} cases, more than max_cases = "
                         f"{scene.max_cases:,} (raise it with [outputs] max_cases or --max-cases)")


def _obtain_all(scene, cdir, log, prog):
    tables, records = {}, []
    for name, spec in scene.surfaces.items():
        prog.step(f"tables {name}")
        T, rec = obtain_tables(spec, scene.theories, dict(scene.table_options), cdir)
        where = f"; cached in {rec.path}" if rec.action == "built" and rec.path else ""
        log(f"tables {name}: {rec.action} ({', '.join(rec.theories)}) in {rec.seconds:.2f} s{where}")
        tables[name], records = T, records + [rec]
        prog.advance()
    return tables, records


def _primitive_cache(scene, tables, cdir):
    """Keep the squeeze time primitives of a squeeze or tire study in ``cdir``'s
    :data:`PRIMITIVE_FOLDER`; returns the folder and the primitive files already there."""
    if scene.kind not in ("squeeze", "tire"):
        return None, set()
    from ..squeeze.primitive import set_primitive_cache
    folder = Path(cdir) / PRIMITIVE_FOLDER
    for T in tables.values():
        set_primitive_cache(T, folder)
    return folder, set(folder.glob("*.parquet")) if folder.is_dir() else set()


def _log_new_primitives(folder, before, log):
    if folder is not None and folder.is_dir():
        for p in sorted(set(folder.glob("*.parquet")) - before):
            log(f"squeeze time primitive cached in {p}")


def _evaluate_all(scene, tables, path, meta, chunk, prog):
    """Evaluate and stream every (surface, block of cases) into ``path``.

    Returns (results DataFrame or None, failed row count, first error, row ranges).
    """
    stream = ParquetStream(path, meta, _units(scene))
    keep = scene.n_cases * len(tables) <= KEEP_MAX_ROWS
    frames, failed, first_error, groups = [], 0, "", []
    try:
        for name, T in tables.items():
            start = stream.rows
            for cases in scene.chunks(chunk):
                prog.step(f"{scene.kind} {name} {int(cases.case_id.iloc[0]) if len(cases) else 0}"
                          f"/{scene.n_cases}")
                res = evaluate_cases(scene.kind, T, cases, scene.fixed, scene.columns,
                                     scale=scene.n_cases / max(len(cases), 1))
                df = pd.concat([pd.DataFrame({"surface": name}, index=cases.index), cases, res],
                               axis=1)
                bad = df["error"] != ""
                if bad.any():
                    failed += int(bad.sum())
                    first_error = first_error or df.loc[bad, "error"].iloc[0]
                stream.write(df)
                if keep:
                    frames.append(df)
                prog.advance()
            groups.append((name, start, stream.rows))
        stream.close()
    except BaseException:
        stream.abort()
        raise
    results = None
    if keep:
        results = pd.concat(frames, ignore_index=True)
        results.attrs["units"] = {c: _units(scene).get(c, "") for c in results.columns}
    return results, failed, first_error, groups


def _figures(scene, tables, results, figdir, make_figures, log, prog):
    """Paths of the figures made (names as in the final folder) and a note if skipped."""
    if not scene.figures:
        return [], None
    if make_figures is None:
        note = "figures requested but not made: no figure maker given (the CLI makes them)"
    elif results is None or len(results) > FIGURE_MAX_ROWS:
        note = (f"figures skipped: the study has more than {FIGURE_MAX_ROWS:,} rows; plot from "
                f"results.parquet")
    else:
        paths = []
        for fig in scene.figures:
            prog.step(f"figure {fig}")
            paths.append(Path(make_figures(scene, fig, tables, results, figdir)))
            prog.advance()
        return paths, None
    log(note)
    return [], note


def _publish(staging, outdir):
    """Move the finished files of ``staging`` into ``outdir`` (a rename if it is new)."""
    if not outdir.exists():
        os.rename(staging, outdir)
        return
    for src in sorted(staging.rglob("*")):
        if src.is_file():
            dst = outdir / src.relative_to(staging)
            dst.parent.mkdir(parents=True, exist_ok=True)
            os.replace(src, dst)
    shutil.rmtree(staging, ignore_errors=True)


def _fmt(x):
    return f"{x:.4g}"


def _summary_text(scene, nrows, records, failed, first_error, stats, files, seconds):
    units = _units(scene)
    lines = [f"fastcontact run: {scene.title}",
             f"scene: {scene.source} (sha256 {scene.sha256[:12]})",
             f"study: {scene.kind}; theories: {', '.join(scene.theories)}; "
             f"{len(scene.surfaces)} surface(s) x {scene.n_cases} case(s) = {nrows} rows in "
             f"{seconds:.2f} s"]
    axes = {k: v for k, v in scene.axes.items() if len(v) > 1}
    if axes:
        lines.append("axes: " + ", ".join(
            f"{k} ({len(v)} values" + (f", [{units[k]}])" if units.get(k) else ")")
            for k, v in axes.items()))
    for r in records:
        lines.append(f"tables {r['surface']}: {r['action']} ({', '.join(r['theories'])}; "
                     f"{r['nodes']} nodes)" + (f" [{r['note']}]" if r.get("note") else ""))
    if failed:
        lines.append(f"WARNING: {failed} case(s) failed, e.g. {first_error}")
    if any(stats.values()):
        lines += ["", "per surface: min / median / max [SI unit]; flags: true count"
                  + ("; medians from an even sample of 1e6 values per surface"
                     if scene.n_cases > 1_000_000 else "")]
    for name, entries in stats.items():
        lines.append(f"  [{name}]")
        for c, kind, v in entries:
            unit = f" [{units.get(c) or '1'}]"
            if kind == "bool":
                lines.append(f"    {c:24s} true in {v[0]} of {v[1]} cases")
            elif v is None:
                lines.append(f"    {c:24s} (no finite value){unit}")
            else:
                lines.append(f"    {c:24s} {_fmt(v[0])} / {_fmt(v[1])} / {_fmt(v[2])}{unit}")
    lines += ["", "files:"] + [f"  {f}" for f in files]
    return "\n".join(lines) + "\n"


def _build_record(scene, records, files, nrows, failed, seconds, figure_note):
    return {
        "scene": scene.source, "scene_sha256": scene.sha256, "study": scene.kind,
        "theories_requested": list(scene.theories), "table_options": dict(scene.table_options),
        "tables": [r.to_dict() for r in records],
        "outputs": {"columns": list(scene.columns), "figures": list(scene.figures),
                    "files": [str(p) for p in files], "units": column_units(scene.columns)},
        "figures_note": figure_note,
        "cases_per_surface": scene.n_cases, "rows": nrows, "failed_rows": failed,
        "seconds": round(seconds, 3), "fastcontact_version": __version__,
    }


def run_scene(scene: Scene, outdir, *, cache_dir=None, log=None, make_figures=None,
              progress=False, progress_file=None, chunk_size=DEFAULT_CHUNK) -> RunResult:
    """Run a validated scene; write results, summary, build record and figures.

    Parameters
    ----------
    scene : Scene
        From :func:`fastcontact.studies.load.load_scene`.
    outdir : path-like
        Output folder. Everything is written into a temporary folder beside it first and
        moved in at the end: a failed run leaves no half-written folder.
    cache_dir : path-like, optional
        Table cache (default: the scene's ``tables.cache_dir``, else
        :func:`fastcontact.tables.cache.table_cache_dir`).
    log : callable, optional
        ``log(message)`` for one-line progress notes.
    make_figures : callable, optional
        ``make_figures(scene, name, tables, results, folder) -> path`` draws one figure; None:
        no figures (the build record says so).
    progress : bool
        Show a progress bar (tqdm) for runs longer than ~2 s.
    progress_file : file-like, optional
        Where the bar is drawn (default stderr).
    chunk_size : int
        Cases evaluated and written per block (bounds the memory of large studies).

    Returns
    -------
    RunResult
    """
    t0 = time.perf_counter()
    log = log or (lambda msg: None)
    outdir = Path(outdir)
    _check_outdir(outdir, scene)
    cdir = table_cache_dir(cache_dir or scene.cache_dir)
    outdir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{outdir.name}.", suffix=".tmp", dir=outdir.parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(staging, 0o777 & ~umask)
    n_chunks = -(-scene.n_cases // int(chunk_size))
    steps = len(scene.surfaces) * (1 + n_chunks) + len(scene.figures)
    try:
        with Progress(steps, progress, progress_file) as prog:
            tables, records = _obtain_all(scene, cdir, log, prog)
            pfolder, pbefore = _primitive_cache(scene, tables, cdir)
            results, failed, first_error, groups = _evaluate_all(
                scene, tables, staging / "results.parquet", provenance(scene, records),
                chunk_size, prog)
            figs, fig_note = _figures(scene, tables, results, staging / "figures", make_figures,
                                      log, prog)
            _log_new_primitives(pfolder, pbefore, log)
        nrows = groups[-1][2] if groups else 0
        final = [outdir / "results.parquet"] + [outdir / "figures" / p.name for p in figs]
        files = [str(p) for p in final] + [str(outdir / "build_record.json"),
                                           str(outdir / "summary.txt")]
        seconds = time.perf_counter() - t0
        record = _build_record(scene, records, final, nrows, failed, seconds, fig_note)
        write_json_atomic(staging / "build_record.json", record)
        stats = column_summary(staging / "results.parquet", scene.columns, groups)
        write_bytes_atomic(staging / "summary.txt", _summary_text(
            scene, nrows, records, failed, first_error, stats, files, seconds).encode())
        _publish(staging, outdir)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return RunResult(results=results, results_path=outdir / "results.parquet",
                     summary_path=outdir / "summary.txt",
                     build_record_path=outdir / "build_record.json",
                     figures=final[1:], record=record)
