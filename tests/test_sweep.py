"""Issue #6: sweeps over a road database on Dask — partitions, manifest, resume after SIGKILL."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fastcontact.roaddb import generate_road_database
from fastcontact.sweep import SweepError, read_sweep, run_sweep

SCENE = """
title = "sweep test"
[study]
kind = "squeeze"
theory = "average"
p0 = ["0.1 MPa", "0.2 MPa", "0.4 MPa"]
ratios = [1.1, 1.01]
du = ["1 um"]
[material]
E = "10 MPa"
nu = 0.5
[fluid]
eta = ["1 mPa s", "5 mPa s"]
[geometry]
R = "2 cm"
[outputs]
columns = ["u_inf", "t_star", "t_ratio_*", "t_du_*", "trapped"]
"""
N_CASES = 6


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    base = tmp_path_factory.mktemp("sweep")
    db = generate_road_database(base / "db", 14, seed=3, surfaces_per_part=5)
    scene = base / "scene.toml"
    scene.write_text(SCENE)
    clean = base / "clean"
    man = run_sweep(db, clean, scene, workers=2, progress=False)
    return base, db, scene, clean, man


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[1]) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def test_clean_sweep_complete(setup):
    base, db, scene, clean, man = setup
    assert man["status"] == "complete" and man["n_surfaces"] == 14
    assert man["cases_per_surface"] == N_CASES and man["rows"] == 14 * N_CASES
    assert man["cluster"]["local_workers"] == 2
    assert man["cluster"]["env"]["NUMBA_THREADING_LAYER"] == "workqueue"
    files = sorted((clean / "data").glob("part-*.parquet"))
    assert len(files) == 14                                   # one partition per surface
    df = read_sweep(clean)
    assert len(df) == 14 * N_CASES
    assert not df.duplicated(["surface_id", "case_id"]).any()
    assert (df.error == "").all()
    assert {"u_inf", "t_star", "t_ratio_1.1", "t_ratio_1.01", "t_du_1e-06", "trapped"} <= set(df.columns)
    # the whole folder reads as one dataset too
    assert len(pd.read_parquet(clean / "data")) == 14 * N_CASES


def test_sweep_rows_equal_direct_evaluation(setup):
    """A partition holds exactly what evaluating the scene on that surface gives."""
    from fastcontact.roaddb import open_road_database
    from fastcontact.scene import build_tables, evaluate_cases, load_scene
    base, db, scene, clean, man = setup
    d = open_road_database(db)
    sc = load_scene(scene, for_sweep=True)
    sid = d.ids[4]
    T, _ = build_tables(d.psd(sid), sc.theories, sc.table_options)
    assert T.theories == ("average",)
    ref = evaluate_cases(sc.kind, T, sc.cases(), sc.fixed, sc.columns)
    got = read_sweep(clean).query("surface_id == @sid").reset_index(drop=True)
    for c in ("u_inf", "t_star", "t_du_1e-06"):
        assert np.array_equal(got[c].to_numpy(float), ref[c].to_numpy(float)), c


def test_rerun_skips_everything(setup, tmp_path):
    base, db, scene, clean, man = setup
    before = {p.name: p.stat().st_mtime_ns for p in (clean / "data").glob("*.parquet")}
    m2 = run_sweep(db, clean, scene, workers=1, progress=False)
    assert m2["computed_this_run"] == 0 and m2["resumed_with_completed"] == 14
    assert m2["status"] == "complete"
    after = {p.name: p.stat().st_mtime_ns for p in (clean / "data").glob("*.parquet")}
    assert before == after


def test_other_scene_into_same_outdir_refused(setup, tmp_path):
    base, db, scene, clean, man = setup
    other = tmp_path / "other.toml"
    other.write_text(SCENE.replace('"0.4 MPa"', '"0.5 MPa"'))
    with pytest.raises(SweepError, match="different sweep"):
        run_sweep(db, clean, other, workers=1, progress=False)


def test_damaged_partition_recomputed(setup, tmp_path):
    import shutil
    base, db, scene, clean, man = setup
    out = tmp_path / "dmg"
    shutil.copytree(clean, out)
    victim = sorted((out / "data").glob("part-*.parquet"))[3]
    victim.write_bytes(victim.read_bytes()[:200])           # truncated
    (out / "data" / ".part-x.parquet.123.tmp").write_bytes(b"junk")   # stale temp file
    m = run_sweep(db, out, scene, workers=1, progress=False)
    assert m["computed_this_run"] == 1 and m["status"] == "complete"
    assert not list((out / "data").glob(".*.tmp"))
    a, b = read_sweep(out), read_sweep(clean)
    pd.testing.assert_frame_equal(a, b)


def test_kill_and_resume(setup, tmp_path):
    """SIGKILL a running sweep after some partitions exist; rerun the same command; every
    (surface, case) appears exactly once and the values equal a clean run."""
    base, db, scene, clean, man = setup
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "fastcontact.cli", "sweep", str(db), "-o", str(out),
           "--scene", str(scene), "--workers", "1"]
    proc = subprocess.Popen(cmd, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        deadline = time.time() + 240
        n = 0
        while time.time() < deadline:
            n = len(list((out / "data").glob("part-*.parquet"))) if (out / "data").exists() else 0
            if n >= 3 or proc.poll() is not None:
                break
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)       # the sweep, its cluster and workers
        proc.wait(timeout=60)
    done_at_kill = len(list((out / "data").glob("part-*.parquet")))
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()[-2000:]
    assert 0 < done_at_kill < 14, f"{done_at_kill} partitions at kill time"
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["status"] == "running"
    # rerun the same command
    r = subprocess.run(cmd + ["--no-progress"], env=_env(), capture_output=True, timeout=600)
    assert r.returncode == 0, r.stderr.decode()[-3000:]
    m2 = json.loads((out / "manifest.json").read_text())
    assert m2["status"] == "complete"
    assert m2["resumed_with_completed"] >= done_at_kill
    assert m2["computed_this_run"] == 14 - m2["resumed_with_completed"]
    got = read_sweep(out)
    assert len(got) == 14 * N_CASES
    assert not got.duplicated(["surface_id", "case_id"]).any()
    pairs = set(zip(got.surface_id, got.case_id))
    ref = read_sweep(clean)
    assert pairs == set(zip(ref.surface_id, ref.case_id))
    pd.testing.assert_frame_equal(got, ref)


def test_sweep_cli_bad_input(setup, tmp_path):
    from fastcontact.cli import main
    base, db, scene, clean, man = setup
    import io
    err = io.StringIO()
    assert main(["sweep", str(tmp_path / "nodb"), "-o", str(tmp_path / "o"), "--scene", str(scene)],
                err=err) == 2
    assert "nodb" in err.getvalue() and len(err.getvalue().strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()
    bad = tmp_path / "bad.toml"
    bad.write_text(SCENE.replace('eta = ["1 mPa s", "5 mPa s"]', 'eta = "5 mPa"'))
    err = io.StringIO()
    assert main(["sweep", str(db), "-o", str(tmp_path / "o2"), "--scene", str(bad)], err=err) == 2
    assert "fluid.eta" in err.getvalue() and "wrong unit" in err.getvalue()
    assert not (tmp_path / "o2").exists()


def test_broken_surface_gets_error_rows_and_external_scheduler(setup, tmp_path):
    """A surface whose spectrum is unusable yields one error row per case (never missing rows);
    ``scheduler=`` runs on an existing cluster."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    from distributed import LocalCluster
    from fastcontact.roaddb import CONVENTION_KEY
    base, db, scene, clean, man = setup
    good = pd.read_parquet(db)
    first = good[good.surface_id == good.surface_id.iloc[0]][["surface_id", "q", "C"]]
    bad = first.assign(surface_id="broken", C=np.where(np.arange(len(first)) == 5, 0.0, first.C))
    dbx = tmp_path / "dbx"
    dbx.mkdir()
    t = pa.Table.from_pandas(pd.concat([first, bad]), preserve_index=False)
    pq.write_table(t.replace_schema_metadata({CONVENTION_KEY: b"persson"}), dbx / "x.parquet")
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        m = run_sweep(dbx, tmp_path / "o", scene, scheduler=cluster.scheduler_address,
                      progress=False)
    assert m["status"] == "complete" and m["cluster"] == {"scheduler": cluster.scheduler_address}
    assert m["surfaces_with_error_rows"] == ["broken"]
    df = read_sweep(tmp_path / "o")
    assert len(df) == 2 * N_CASES
    b = df[df.surface_id == "broken"]
    assert (b.error.str.contains("C = 0.0")).all() and b.t_star.isna().all()
    assert b.trapped.isna().all()
    g = df[df.surface_id != "broken"]
    assert (g.error == "").all() and np.isfinite(g.t_star).all()
    # partitions share one schema: the folder reads as one dataset
    assert len(pd.read_parquet(tmp_path / "o" / "data")) == 2 * N_CASES


# ============================================================== issue 15.6: signals and lock
def _wait_for_partitions(proc, out, n, timeout=240):
    deadline = time.time() + timeout
    while time.time() < deadline:
        k = len(list((out / "data").glob("part-*.parquet"))) if (out / "data").exists() else 0
        if k >= n or proc.poll() is not None:
            return k
        time.sleep(0.02)
    return -1


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
def test_signal_ends_sweep_cleanly_and_resume_is_exact(setup, tmp_path, sig, code):
    """A real signal — SIGINT to the whole process group as a terminal's Ctrl-C sends it
    (workers included), SIGTERM to the CLI process — gives one line on stderr and no worker
    traceback, exit 130 / 143, manifest "interrupted", lock released; the rerun completes
    exactly."""
    base, db, scene, clean, man = setup
    out = tmp_path / "sig"
    cmd = [sys.executable, "-m", "fastcontact.cli", "sweep", str(db), "-o", str(out),
           "--scene", str(scene), "--workers", "1", "--no-progress"]
    proc = subprocess.Popen(cmd, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        k = _wait_for_partitions(proc, out, 2)
        assert proc.poll() is None and 0 < k < 14, f"{k} partitions"
        if sig == signal.SIGINT:
            os.killpg(proc.pid, sig)            # a terminal's Ctrl-C: the whole process group
        else:
            proc.send_signal(sig)               # `kill PID`: the driver only
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=60)
    err = stderr.decode().strip()
    assert proc.returncode == code, err[-3000:]
    last = err.splitlines()[-1]
    assert last.startswith(f"fastcontact: sweep interrupted by {signal.Signals(sig).name}")
    assert "Traceback" not in err
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["status"] == "interrupted"
    assert not (out / ".sweep.lock").exists()
    listed = set(manifest["partitions"])
    on_disk = {p.name for p in (out / "data").glob("part-*.parquet")}
    assert {manifest["partitions"][s]["file"] for s in listed} <= on_disk
    r = subprocess.run(cmd, env=_env(), capture_output=True, timeout=600)
    assert r.returncode == 0, r.stderr.decode()[-3000:]
    got = read_sweep(out)
    assert not got.duplicated(["surface_id", "case_id"]).any()
    pd.testing.assert_frame_equal(got, read_sweep(clean))


def test_second_sweep_on_same_folder_refused(setup, tmp_path):
    """A live lock (this process) refuses; a lock of a dead pid on this host is taken over."""
    import socket
    from fastcontact.studies.sweep import LOCK_NAME
    base, db, scene, clean, man = setup
    out = tmp_path / "locked"
    out.mkdir()
    lock = out / LOCK_NAME
    lock.write_text(json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                                "since": "2026-01-01T00:00:00+00:00", "heartbeat": time.time()}))
    with pytest.raises(SweepError, match=r"is in use by another sweep \(pid \d+ on .*wait for "
                                         r"it to finish or use another -o"):
        run_sweep(db, out, scene, workers=1, progress=False)
    assert lock.exists() and not (out / "manifest.json").exists()
    # a dead process: a child that has exited
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    lock.write_text(json.dumps({"pid": int(dead), "host": socket.gethostname(),
                                "since": "2026-01-01T00:00:00+00:00", "heartbeat": 0.0}))
    notes = []
    import shutil
    shutil.copytree(clean / "data", out / "data")
    shutil.copy(clean / "manifest.json", out / "manifest.json")
    m = run_sweep(db, out, scene, workers=1, progress=False, log=notes.append)
    assert m["status"] == "complete" and m["computed_this_run"] == 0
    assert any("stale lock" in n for n in notes)
    assert not lock.exists()
    # another host: stale only without a recent heartbeat
    lock.write_text(json.dumps({"pid": 1, "host": "elsewhere", "since": "x",
                                "heartbeat": time.time()}))
    with pytest.raises(SweepError, match="in use by another sweep"):
        run_sweep(db, out, scene, workers=1, progress=False)
    lock.write_text(json.dumps({"pid": 1, "host": "elsewhere", "since": "x", "heartbeat": 0.0}))
    assert run_sweep(db, out, scene, workers=1, progress=False)["status"] == "complete"


def test_local_cluster_workers_are_fork_safe_and_not_oversubscribed():
    """The fixture-style cluster: spawned workers, 1 Dask thread each, numba's workqueue
    layer and cores // workers numba threads (checked inside the workers)."""
    from distributed import Client
    from fastcontact.studies.sweep import local_cluster

    def probe():
        import multiprocessing
        import numba
        return (os.environ.get("NUMBA_THREADING_LAYER"), numba.config.NUMBA_NUM_THREADS,
                multiprocessing.current_process().name, os.environ.get("OMP_NUM_THREADS"))

    cluster, info = local_cluster(2)
    try:
        with Client(cluster) as client:
            got = client.run(probe)
            threads = client.nthreads()
    finally:
        cluster.close()
    cores = os.cpu_count() or 1
    assert set(threads.values()) == {1}
    for layer, nthreads, _, omp in got.values():
        assert layer == "workqueue" and nthreads == max(1, cores // 2) and omp == "1"
    assert info["numba_threads_per_worker"] == max(1, cores // 2)


def test_worker_preload_drops_only_the_lost_heartbeat():
    """The workers' preload (run in a child: it changes the process's SIGINT and logging)
    ignores SIGINT and drops the heartbeat failure a worker logs, with a traceback, when the
    driver's scheduler closes first; any other worker error still reaches stderr."""
    code = (
        "import logging, signal\n"
        "from fastcontact.studies.sweep import dask_setup\n"
        "logging.basicConfig(level=logging.ERROR)\n"
        "dask_setup(None)\n"
        "log = logging.getLogger('distributed.worker')\n"
        "try:\n"
        "    raise OSError('Stream is closed')\n"
        "except OSError:\n"
        "    log.exception('Failed to communicate with scheduler during heartbeat.')\n"
        "    log.exception('Compute Failed')\n"
        "print(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=_env(), timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "True"
    assert "heartbeat" not in r.stderr
    assert "Compute Failed" in r.stderr and "OSError: Stream is closed" in r.stderr


def test_held_interrupt_waits_for_the_dask_call_then_raises_once():
    """A signal during a held Dask call (``Future.result``) raises when the call has
    returned, not inside distributed's wait (where its cancel callback can fail with a
    traceback); a second signal while held raises at once; outside a hold, at once."""
    import threading
    from distributed import Client
    from fastcontact.studies.sweep_control import (SweepInterrupted, _held_interrupts,
                                                   _interrupts)

    def later(sig, seconds):
        threading.Timer(seconds, os.kill, (os.getpid(), sig)).start()

    got = []
    with Client(processes=False, n_workers=1, threads_per_worker=1,
                dashboard_address=None) as client, _interrupts():
        fut = client.submit(time.sleep, 1.0, pure=False)
        later(signal.SIGINT, 0.2)
        with pytest.raises(SweepInterrupted) as exc:
            with _held_interrupts():
                fut.result()
                got.append(fut.status)
        assert got == ["finished"] and exc.value.exit_code == 130
        with pytest.raises(SweepInterrupted) as exc:      # a second signal: at once
            with _held_interrupts():
                later(signal.SIGTERM, 0.0)
                later(signal.SIGTERM, 0.3)
                time.sleep(5.0)
                got.append("slept")
        assert got == ["finished"] and exc.value.exit_code == 143
        with pytest.raises(SweepInterrupted):                # not held: at once
            later(signal.SIGINT, 0.0)
            time.sleep(5.0)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
