"""Sweeps: one scene's parameter grid evaluated on every surface of a road database, on Dask.

``fastcontact sweep DB -o OUT --scene S.toml [--scheduler ADDR] [--workers N]``

Per surface (one Dask task each): build the surface's tables with only the theories the scene
needs (or reuse them from ``--cache-dir``), evaluate every case of the scene, and write the
rows as one Parquet partition ``OUT/data/part-<surface>.parquet`` — to a temporary name in the
same folder, then ``os.replace`` (atomic: a partition is either complete or absent). The
driver keeps ``OUT/manifest.json`` (atomic rewrites) with the sweep's identity and the
completed partitions.

Resuming: rerunning the same command skips every partition that exists, reads back, belongs
to this sweep (same scene, database content and table options: ``sweep_key`` in its metadata)
and has one row per case; everything else is (re)computed. Since partitions are written whole
and atomically, an interrupted sweep (even SIGKILL) neither loses nor duplicates a row. An
output folder holding a *different* sweep is refused.

Cluster: by default a ``distributed.LocalCluster`` of worker processes (started with the
'spawn' method, never forked) with ``threads_per_worker=1`` — the numba kernels hold the GIL,
so a second Dask thread would add no throughput, and numba's ``workqueue`` layer aborts when
two threads enter parallel kernels at once — and the cores left to each worker given to
numba: ``NUMBA_NUM_THREADS`` = cores // workers. ``NUMBA_THREADING_LAYER=workqueue`` (the
default OpenMP layer is not fork-safe), ``OMP/MKL/OPENBLAS_NUM_THREADS=1``. With
``--scheduler ADDR`` an existing cluster is used; its workers' environment and thread count
are theirs to set (use 1 thread per worker, or the 'tbb'/'omp' layer with spawned workers).

Read the results with :func:`read_sweep` (or ``pandas.read_parquet(OUT / "data")``).
"""
from __future__ import annotations

import datetime as _dt
import hashlib
import json
import logging
import math
import os
import re
import sys
import time
from pathlib import Path


__all__ = ["run_sweep", "read_sweep", "sweep_key", "worker_environment", "SweepError"]

DATA_DIR = "data"
MANIFEST = "manifest.json"
META_KEY = b"fastcontact"


class SweepError(ValueError):
    """Bad sweep input (the CLI reports it in one line, exit code 2)."""


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
    from .. import __version__
    blob = json.dumps({"scene": scene.sha256, "db": db_fingerprint,
                       "options": scene.table_options, "theories": list(scene.theories),
                       "version": __version__}, sort_keys=True).encode()
    return hashlib.sha256(blob).hexdigest()


# ============================================================================ the task
def _surface_task(sid, q, C, scene, outpath, key, cache_dir):
    """Build tables for one surface, evaluate all cases, write the partition atomically."""
    import pandas as pd
    from ..surface.psd import TabulatedPSD
    from .scene import (SurfaceSpec, empty_results, evaluate_cases, obtain_tables,
                        write_parquet_atomic)
    t0 = time.perf_counter()
    cases = scene.cases()
    note, table_meta, t_tab = None, {}, math.nan
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
    n_err = int((df["error"] != "").sum())
    meta = {"sweep_key": key, "surface_id": sid, "rows": len(df), "table": table_meta,
            "note": note, "error_rows": n_err, "table_seconds": t_tab,
            "seconds": time.perf_counter() - t0}
    write_parquet_atomic(df, outpath, meta)
    return {"surface_id": sid, "rows": len(df), "seconds": time.perf_counter() - t0,
            "table_seconds": t_tab, "note": note, "error_rows": n_err,
            "file": Path(outpath).name}


# ============================================================================ driver
def _read_partition_meta(path):
    import pyarrow.parquet as pq
    try:
        pf = pq.ParquetFile(path)
        raw = (pf.schema_arrow.metadata or {}).get(META_KEY)
        meta = json.loads(raw) if raw else None
        if meta is not None and pf.metadata.num_rows != meta.get("rows"):
            return None
        return meta
    except Exception:  # noqa: BLE001 - unreadable → recompute
        return None


def _atomic_json(path, obj):
    from .scene import _atomic_write_bytes, _json_default
    _atomic_write_bytes(Path(path), json.dumps(obj, indent=1, sort_keys=True,
                                               default=_json_default).encode())


class _Progress:
    def __init__(self, total, done0, cases, enabled, stream=None):
        self.total, self.done, self.cases = total, done0, cases
        self.enabled = enabled
        self.stream = stream or sys.stderr
        self.t0 = time.perf_counter()
        self.n0 = done0
        self.last = 0.0
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def update(self, force=False):
        if not self.enabled:
            return
        now = time.perf_counter()
        if not force and now - self.last < (0.5 if self.tty else 5.0):
            return
        self.last = now
        dt = now - self.t0
        new = self.done - self.n0
        rate = new / dt if dt > 0 else 0.0
        left = self.total - self.done
        eta = f"{left / rate:.0f} s" if rate > 0 else "?"
        msg = (f"sweep: {self.done}/{self.total} surfaces ({self.done * self.cases} cases) done, "
               f"{rate:.2f} surfaces/s, {rate * self.cases:.0f} cases/s, ETA {eta}")
        if self.tty:
            self.stream.write("\r" + msg + " " * 4)
        else:
            self.stream.write(msg + "\n")
        self.stream.flush()

    def finish(self):
        if self.enabled:
            self.update(force=True)
            if self.tty:
                self.stream.write("\n")
            self.stream.flush()


def _start_cluster(workers, scheduler):
    import dask
    from distributed import Client, LocalCluster
    if scheduler:
        return Client(scheduler, timeout="30s"), None, {"scheduler": scheduler}
    cores = os.cpu_count() or 1
    n = int(workers) if workers else cores
    # one task at a time per worker process: numba kernels hold the GIL (more Dask threads
    # would not add throughput) and the workqueue layer must not be entered by two threads
    # at once; the cores a worker has to itself go to numba's parallel kernels instead
    numba_threads = max(1, cores // n)
    env = worker_environment(numba_threads)
    with dask.config.set({"distributed.worker.multiprocessing-method": "spawn",
                          "distributed.worker.daemon": False}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None, env=env, silence_logs=logging.ERROR)
    client = Client(cluster)
    return client, cluster, {"local_workers": n, "threads_per_worker": 1,
                             "numba_threads_per_worker": numba_threads, "env": env}


def run_sweep(db, outdir, scene, *, scheduler=None, workers=None, convention=None,
              cache_dir=None, progress=True, log=None):
    """Evaluate ``scene``'s cases on every surface of the road database ``db``.

    Parameters
    ----------
    db : path of the road database (see :mod:`fastcontact.roaddb`)
    outdir : output folder (``data/part-*.parquet`` + ``manifest.json``)
    scene : path of a scene TOML (or a loaded Scene); its [surfaces] are not used
    scheduler : address of an existing Dask scheduler (default: start a LocalCluster)
    workers : number of local worker processes (default: cores)
    convention : C convention for database files that do not record one
    cache_dir : reuse/keep tables there (default: none, tables are built in the workers)
    progress : print a progress line to stderr

    Returns the manifest dict. Raises SceneError / SweepError on bad input (before any file is
    written).
    """
    from .. import __version__
    from ..surface.roaddb import open_road_database
    from .scene import Scene, load_scene
    log = log or (lambda m: None)
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
        nm = partition_path(outdir, sid).name
        if nm in names:
            raise SweepError(f"surface ids {names[nm]!r} and {sid!r} map to the same partition file")
        names[nm] = sid
    key = sweep_key(sc, fingerprint)
    outdir = Path(outdir)
    mpath = outdir / MANIFEST
    if mpath.exists():
        try:
            old = json.loads(mpath.read_text())
        except ValueError:
            old = {}
        if old.get("sweep_key") not in (None, key):
            raise SweepError(f"output folder {str(outdir)!r} holds a different sweep (scene, "
                             f"database or options changed): use another -o")
    elif outdir.exists() and any(outdir.iterdir()):
        raise SweepError(f"output folder {str(outdir)!r} exists, is not empty and holds no "
                         f"sweep manifest: use another -o")
    cases = sc.cases()
    n_cases = len(cases)
    (outdir / DATA_DIR).mkdir(parents=True, exist_ok=True)
    for tmp in (outdir / DATA_DIR).glob(".*.tmp"):   # leftovers of an interrupted writer
        try:
            tmp.unlink()
        except OSError:
            pass
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
    todo = [sid for sid in ids if sid not in done]
    manifest = {
        "sweep_key": key, "fastcontact_version": __version__, "scene": sc.source,
        "scene_sha256": sc.sha256, "scene_toml": sc.text, "study": sc.kind,
        "theories": list(sc.theories), "table_options": sc.table_options,
        "columns": sc.columns, "database": str(Path(db).resolve()),
        "database_fingerprint": fingerprint, "n_surfaces": len(ids),
        "cases_per_surface": n_cases, "status": "running",
        "started_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "resumed_with_completed": len(done), "partitions": done, "failed": {},
    }
    _atomic_json(mpath, manifest)
    log(f"sweep: {len(ids)} surfaces x {n_cases} cases; {len(done)} partitions already complete, "
        f"{len(todo)} to compute")
    prog = _Progress(len(ids), len(done), n_cases, progress)
    t0 = time.perf_counter()
    cluster_info = {}
    if todo:
        from distributed import as_completed
        client, cluster, cluster_info = _start_cluster(workers, scheduler)
        manifest["cluster"] = cluster_info
        try:
            # the scene (a few kB) travels with each task; the cases are rebuilt from it there
            # (nothing is scattered, so a lost worker loses no shared data)
            cdir = str(Path(cache_dir).resolve()) if cache_dir else None
            futs = {}
            for sid in todo:
                q, C = spectra[sid]
                f = client.submit(_surface_task, sid, q, C, sc,
                                  str(partition_path(outdir, sid).resolve()), key, cdir,
                                  key=f"surface-{key[:8]}-{_safe_name(sid)}", pure=False)
                futs[f] = sid
            last_write = time.perf_counter()
            for fut in as_completed(list(futs)):
                sid = futs[fut]
                try:
                    info = fut.result()
                    done[sid] = info
                except Exception as exc:  # noqa: BLE001 - a task crashed: record, go on
                    manifest["failed"][sid] = f"{type(exc).__name__}: {exc}"
                prog.done = len(done)
                prog.update()
                if time.perf_counter() - last_write > 2.0:
                    _atomic_json(mpath, manifest)
                    last_write = time.perf_counter()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    prog.finish()
    manifest["partitions"] = done
    manifest["seconds_this_run"] = round(time.perf_counter() - t0, 3)
    manifest["computed_this_run"] = len(todo) - len(manifest["failed"])
    manifest["status"] = "complete" if len(done) == len(ids) else "incomplete"
    manifest["rows"] = int(sum(d["rows"] for d in done.values()))
    manifest["surfaces_with_error_rows"] = sorted(sid for sid, d in done.items()
                                                  if d.get("error_rows"))
    manifest["surfaces_with_notes"] = sorted(sid for sid, d in done.items() if d.get("note"))
    manifest["finished_utc"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    _atomic_json(mpath, manifest)
    return manifest


def read_sweep(outdir):
    """All rows of a sweep as one DataFrame (sorted by surface_id, case_id)."""
    import pandas as pd
    d = Path(outdir) / DATA_DIR
    files = sorted(p for p in d.glob("part-*.parquet"))
    if not files:
        raise ValueError(f"outdir = {str(outdir)!r} is invalid: no sweep partitions in {d}")
    df = pd.concat([pd.read_parquet(p) for p in files], ignore_index=True)
    return df.sort_values(["surface_id", "case_id"], kind="stable").reset_index(drop=True)
