"""Sweeps: one scene's parameter grid evaluated on every surface of a road database, on Dask.

``fastcontact sweep DB -o OUT --scene S.toml [--scheduler ADDR] [--workers N]``

One task per surface builds its tables, evaluates every case and writes
``OUT/data/part-<surface>.parquet`` atomically (complete or absent); ``OUT/manifest.json``
records the sweep (``status``: running, complete, incomplete, interrupted). Rerunning the same
command resumes exactly (partitions of this ``sweep_key`` with one row per case are kept; no
row is lost or duplicated, even after SIGKILL). SIGINT / SIGTERM stop the cluster, mark the
manifest "interrupted" and raise :class:`SweepInterrupted` (CLI: one line, exit 130 / 143).
``OUT/.sweep.lock`` keeps a second sweep out of a folder in use; the lock of a dead run (same
host: pid gone; other host: no heartbeat for :data:`LOCK_STALE_SECONDS`) is taken over (the
lock, the signal handling and the errors live in :mod:`.sweep_control`).
Workers: :func:`local_cluster` (spawned processes, numba's fork-safe threading set-up).
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import re
import signal
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
from tqdm import tqdm

from .. import __version__
from .._core.vocab import METADATA_KEY
from ..surface.psd import TabulatedPSD
from ..surface.roaddb import open_road_database
from ..tables.cache import obtain_tables
from .evaluate import empty_results, evaluate_cases
from .load import load_scene
from .output import write_json_atomic, write_parquet_atomic
from .scene import Scene, SurfaceSpec
from .sweep_control import (LOCK_NAME, LOCK_STALE_SECONDS, SweepError, SweepInterrupted,
                            _held_interrupts, _ignore_signals, _interrupts, _Lock,
                            _utc_now)

__all__ = ["run_sweep", "read_sweep", "sweep_key", "worker_environment", "local_cluster",
           "SweepError", "SweepInterrupted", "LOCK_NAME", "LOCK_STALE_SECONDS"]

DATA_DIR = "data"
MANIFEST = "manifest.json"
META_KEY = METADATA_KEY


def worker_environment(threads_per_worker=1):
    """Environment of each worker process: no oversubscription, fork-safe numba layer."""
    t = str(int(threads_per_worker))
    return {"NUMBA_NUM_THREADS": t, "NUMBA_THREADING_LAYER": "workqueue",
            "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def _safe_name(sid):
    if re.fullmatch(r"[A-Za-z0-9._+-]{1,120}", sid) and not sid.startswith("."):
        return sid
    return "h" + hashlib.sha256(sid.encode()).hexdigest()[:32]


def partition_path(outdir, sid):
    return Path(outdir) / DATA_DIR / f"part-{_safe_name(sid)}.parquet"


def sweep_key(scene, db_fingerprint):
    """Identity of a sweep: scene text, database content, table options, version."""
    blob = json.dumps({"scene": scene.sha256, "db": db_fingerprint,
                       "options": scene.table_options, "theories": list(scene.theories),
                       "version": __version__}, sort_keys=True).encode()
    return hashlib.sha256(blob).hexdigest()


# ============================================================================ the task
def _surface_task(sid, q, C, scene, outpath, key, cache_dir):
    """Build tables for one surface, evaluate all cases, write the partition atomically."""
    t0 = time.perf_counter()
    cases = scene.cases()
    note, table_meta, t_tab = None, {}, float("nan")
    try:
        psd = TabulatedPSD(q, C, convention="persson")
        spec = SurfaceSpec(sid, "inline", psd_obj=psd)
        T, rec = obtain_tables(spec, scene.theories, dict(scene.table_options), cache_dir)
        t_tab = time.perf_counter() - t0
        note = rec["note"]
        table_meta = {k: rec[k] for k in ("surface_hash", "columns_sha256", "theories", "nodes",
                                          "build_seconds", "action")}
        res = evaluate_cases(scene.kind, T, cases, scene.fixed, scene.columns)
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        # the surface itself is unusable: every case gets the error (rows still exist once)
        note = f"{type(exc).__name__}: {exc}"
        res = empty_results(scene.columns, len(cases), exclude=cases.columns)
        res["error"] = note
    df = pd.concat([pd.DataFrame({"surface_id": sid}, index=cases.index), cases, res], axis=1)
    df.attrs = dict(res.attrs)
    n_err = int((df["error"] != "").sum())
    meta = {"sweep_key": key, "surface_id": sid, "rows": len(df), "table": table_meta,
            "note": note, "error_rows": n_err, "table_seconds": t_tab,
            "seconds": time.perf_counter() - t0}
    write_parquet_atomic(df, outpath, meta)
    return {"surface_id": sid, "rows": len(df), "seconds": time.perf_counter() - t0,
            "table_seconds": t_tab, "note": note, "error_rows": n_err,
            "file": Path(outpath).name}


def _read_partition_meta(path):
    try:
        pf = pq.ParquetFile(path)
        raw = (pf.schema_arrow.metadata or {}).get(META_KEY)
        meta = json.loads(raw) if raw else None
        if meta is not None and pf.metadata.num_rows != meta.get("rows"):
            return None
        return meta
    except Exception:  # noqa: BLE001 - unreadable → recompute
        return None


# ============================================================================ cluster
#: what a worker of :func:`local_cluster` logs when a heartbeat meets a closed scheduler
_HEARTBEAT_LOST = "Failed to communicate with scheduler during heartbeat"


def _not_heartbeat_lost(record):
    """Logging filter of :func:`dask_setup`: False for the heartbeat-failure record."""
    return not record.getMessage().startswith(_HEARTBEAT_LOST)


def dask_setup(worker):
    """Worker preload of :func:`local_cluster`.

    A terminal's Ctrl-C reaches the whole process group; the driver handles it (and stops
    the workers), so the workers ignore SIGINT instead of printing a KeyboardInterrupt
    traceback each. The scheduler of a local cluster lives in the driver: a worker's
    heartbeat that meets it closed (the driver is stopping, interrupted or not) is dropped
    from the worker's log instead of printing a traceback (distributed itself treats it as
    transient, ``Worker.heartbeat``); the driver reports why it stopped."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    logging.getLogger("distributed.worker").addFilter(_not_heartbeat_lost)


def local_cluster(workers=None):
    """A ``distributed.LocalCluster`` set up for fastcontact's numba kernels.

    Spawned worker processes (never forked: numba's threading layers are not fork-safe),
    one Dask thread each, ``worker_environment(cores // workers)``.

    Returns
    -------
    (cluster, info)
        ``info`` records workers, threads and the environment (kept in the manifest).
    """
    import dask
    from distributed import LocalCluster
    cores = os.cpu_count() or 1
    n = int(workers) if workers else cores
    numba_threads = max(1, cores // n)
    env = worker_environment(numba_threads)
    with dask.config.set({"distributed.worker.multiprocessing-method": "spawn",
                          "distributed.worker.daemon": False,
                          "distributed.worker.preload": [__name__]}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None, env=env, silence_logs=logging.ERROR)
    return cluster, {"local_workers": n, "threads_per_worker": 1,
                     "numba_threads_per_worker": numba_threads, "env": env}


# ============================================================================ driver steps
def _open_inputs(db, scene, convention, workers, log):
    """(Scene, ids, spectra, fingerprint) or SweepError/SceneError before any file is written."""
    sc = scene if isinstance(scene, Scene) else load_scene(scene, for_sweep=True)
    if sc.surfaces:
        log(f"note: the scene's [surfaces] ({', '.join(sc.surfaces)}) are not used by a sweep; "
            f"the surfaces come from the database")
    if sc.figures:
        log("note: outputs.figures are not made by a sweep")
    if workers is not None and (isinstance(workers, bool) or int(workers) < 1):
        raise SweepError(f"workers = {workers!r} is invalid: must be an integer >= 1")
    try:
        database = open_road_database(db, convention)
        ids = list(database.ids)
        spectra = {sid: database.spectrum(sid) for sid in ids}
        fingerprint = database.fingerprint
    except (ValueError, KeyError) as exc:
        raise SweepError(str(exc)) from None
    names = {}
    for sid in ids:
        nm = partition_path(".", sid).name
        if nm in names:
            raise SweepError(f"surface ids {names[nm]!r} and {sid!r} map to the same partition file")
        names[nm] = sid
    return sc, ids, spectra, fingerprint


def _check_outdir(outdir, key):
    """Refuse a folder that holds something else, or a different sweep."""
    mpath = outdir / MANIFEST
    if mpath.exists():
        try:
            old = json.loads(mpath.read_text())
        except ValueError:
            old = {}
        if old.get("sweep_key") not in (None, key):
            raise SweepError(f"output folder {str(outdir)!r} holds a different sweep (scene, "
                             f"database or options changed): use another -o")
    elif outdir.exists() and any(p.name != LOCK_NAME for p in outdir.iterdir()):
        raise SweepError(f"output folder {str(outdir)!r} exists, is not empty and holds no "
                         f"sweep manifest: use another -o")


def _completed(outdir, ids, key, n_cases):
    """Partitions already complete (validated), after removing leftovers and strays."""
    data = outdir / DATA_DIR
    data.mkdir(parents=True, exist_ok=True)
    for tmp in data.glob(".*.tmp"):                  # leftovers of an interrupted writer
        with contextlib.suppress(OSError):
            tmp.unlink()
    done = {}
    for sid in ids:
        p = partition_path(outdir, sid)
        if p.is_file():
            meta = _read_partition_meta(p)
            if meta and meta.get("sweep_key") == key and meta.get("rows") == n_cases \
                    and meta.get("surface_id") == sid:
                done[sid] = {"surface_id": sid, "rows": n_cases, "file": p.name,
                             "seconds": meta.get("seconds"), "note": meta.get("note"),
                             "error_rows": meta.get("error_rows", 0)}
            else:
                p.unlink()
    return done


def _compute(todo, spectra, sc, outdir, key, cache_dir, client, manifest, done, bar, mpath):
    """Submit one task per surface and record them as they complete."""
    from distributed import as_completed
    cdir = str(Path(cache_dir).resolve()) if cache_dir else None
    futs = {}
    for sid in todo:
        q, C = spectra[sid]
        # the scene (a few kB) travels with each task; nothing is scattered, so a lost worker
        # loses no shared data
        f = client.submit(_surface_task, sid, q, C, sc, str(partition_path(outdir, sid).resolve()),
                          key, cdir, key=f"surface-{key[:8]}-{_safe_name(sid)}", pure=False)
        futs[f] = sid
    last_write = time.perf_counter()
    for fut in as_completed(list(futs)):
        sid = futs[fut]
        try:
            with _held_interrupts():
                done[sid] = fut.result()
        except Exception as exc:  # noqa: BLE001 - a task crashed: record, go on
            manifest["failed"][sid] = f"{type(exc).__name__}: {exc}"
        bar.update(1)
        if time.perf_counter() - last_write > 2.0:
            write_json_atomic(mpath, manifest)
            last_write = time.perf_counter()


def _finish(manifest, done, ids, todo, t0, status=None):
    manifest["partitions"] = done
    manifest["seconds_this_run"] = round(time.perf_counter() - t0, 3)
    manifest["computed_this_run"] = max(0, len(done) - manifest["resumed_with_completed"])
    manifest["status"] = status or ("complete" if len(done) == len(ids) else "incomplete")
    manifest["rows"] = int(sum(d["rows"] for d in done.values()))
    manifest["surfaces_with_error_rows"] = sorted(s for s, d in done.items() if d.get("error_rows"))
    manifest["surfaces_with_notes"] = sorted(s for s, d in done.items() if d.get("note"))
    manifest["finished_utc"] = _utc_now()
    return manifest


def run_sweep(db, outdir, scene, *, scheduler=None, workers=None, convention=None,
              cache_dir=None, progress=True, log=None):
    """Evaluate ``scene``'s cases on every surface of the road database ``db``.

    Parameters
    ----------
    db : path-like
        Road database (see :mod:`fastcontact.surface.roaddb`).
    outdir : path-like
        Output folder (``data/part-*.parquet``, ``manifest.json``, the lock while running).
    scene : path-like or Scene
        Scene TOML (or a loaded Scene); its [surfaces] are not used.
    scheduler : str, optional
        Address of an existing Dask scheduler (default: start :func:`local_cluster`).
    workers : int, optional
        Local worker processes (default: cores).
    convention : str, optional
        C convention for database files that do not record one.
    cache_dir : path-like, optional
        Reuse / keep tables there (default: tables are built in the workers).
    progress : bool
        Show a progress bar (tqdm) on stderr.
    log : callable, optional
        Receives one-line notes.

    Returns
    -------
    dict
        The manifest.

    Raises
    ------
    SweepError, SceneError
        Bad input or a folder in use — before any file is written.
    SweepInterrupted
        SIGINT / SIGTERM (the manifest then says "interrupted"; rerun to resume).
    """
    log = log or (lambda m: None)
    sc, ids, spectra, fingerprint = _open_inputs(db, scene, convention, workers, log)
    key = sweep_key(sc, fingerprint)
    outdir = Path(outdir)
    _check_outdir(outdir, key)
    lock = _Lock(outdir, log).acquire()
    try:
        with _interrupts():
            return _run_locked(db, outdir, sc, ids, spectra, fingerprint, key, scheduler,
                               workers, cache_dir, progress, log)
    finally:
        lock.release()


def _run_locked(db, outdir, sc, ids, spectra, fingerprint, key, scheduler, workers, cache_dir,
                progress, log):
    n_cases = len(sc.cases())
    _check_outdir(outdir, key)                      # again, now that the folder is ours
    done = _completed(outdir, ids, key, n_cases)
    todo = [sid for sid in ids if sid not in done]
    mpath = outdir / MANIFEST
    manifest = {
        "sweep_key": key, "fastcontact_version": __version__, "scene": sc.source,
        "scene_sha256": sc.sha256, "scene_toml": sc.text, "study": sc.kind,
        "theories": list(sc.theories), "table_options": sc.table_options,
        "columns": sc.columns, "database": str(Path(db).resolve()),
        "database_fingerprint": fingerprint, "n_surfaces": len(ids),
        "cases_per_surface": n_cases, "status": "running", "started_utc": _utc_now(),
        "resumed_with_completed": len(done), "partitions": done, "failed": {},
    }
    write_json_atomic(mpath, manifest)
    log(f"sweep: {len(ids)} surfaces x {n_cases} cases; {len(done)} partitions already complete, "
        f"{len(todo)} to compute")
    t0 = time.perf_counter()
    client = cluster = None
    tty = bool(getattr(sys.stderr, "isatty", lambda: False)())
    bar = tqdm(total=len(ids), initial=len(done), unit="surface", disable=not progress,
               desc="sweep", dynamic_ncols=True, leave=False, delay=2.0,
               mininterval=0.1 if tty else 10.0)
    try:
        if todo:
            from distributed import Client
            with _held_interrupts():
                if scheduler:
                    client, info = Client(scheduler, timeout="30s"), {"scheduler": scheduler}
                else:
                    cluster, info = local_cluster(workers)
                    client = Client(cluster)
            manifest["cluster"] = info
            _compute(todo, spectra, sc, outdir, key, cache_dir, client, manifest, done, bar,
                     mpath)
    except SweepInterrupted as exc:
        _finish(manifest, done, ids, todo, t0, status="interrupted")
        manifest["interrupted_by"] = str(exc)
        write_json_atomic(mpath, manifest)
        on_disk = len(list((outdir / DATA_DIR).glob("part-*.parquet")))
        raise SweepInterrupted(
            f"sweep interrupted by {exc}: {max(on_disk, len(done))}/{len(ids)} surfaces complete "
            f"in {outdir}; rerun the same command to resume", exc.exit_code) from None
    finally:
        bar.close()
        with contextlib.suppress(Exception), _ignore_signals():
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()
    _finish(manifest, done, ids, todo, t0)
    write_json_atomic(mpath, manifest)
    return manifest



def read_sweep(outdir):
    """All rows of a sweep as one DataFrame (sorted by surface_id, case_id)."""
    d = Path(outdir) / DATA_DIR
    files = sorted(p for p in d.glob("part-*.parquet"))
    if not files:
        raise ValueError(f"outdir = {str(outdir)!r} is invalid: no sweep partitions in {d}")
    df = pd.concat([pd.read_parquet(p) for p in files], ignore_index=True)
    return df.sort_values(["surface_id", "case_id"], kind="stable").reset_index(drop=True)
