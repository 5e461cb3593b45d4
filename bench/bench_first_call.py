"""Benchmark: the first squeeze_out call on newly loaded tables (issue 11.3: ≤ 50 ms per theory).

Writes ``bench/first_call_results.md``. Run:
``python bench/bench_first_call.py --baseline <checkout of the commit before> [--pairs 3]``.

A road-database sweep pays this on every surface: the call builds the time primitive of its
theory (the kernels are compiled and loaded from numba's cache). Per surface (the four embedded
tables, a synthetic road spectrum of 48 samples and a self-affine spectrum of 5 decades, the
latter two built once here and read by both checkouts) and theory: the median of 5 calls, each
on a freshly loaded Tables object, after one untimed call that loads the kernels. Each checkout
runs in its own fresh processes with its own numba cache, this checkout and the baseline
alternating (``--pairs`` processes each); the table gives the medians over the processes and
their ratio. The primitive's grid (rows × z nodes) and its measured interpolation error of T at
cell centres (``build(check=True)``) come from the same processes.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from checkouts import run_job  # noqa: E402
from machine_info import cpu_model  # noqa: E402
from results_notes import write_keeping_notes  # noqa: E402

THEORIES = ("average", "critical_junction", "emt")
REPEATS = 5

_JOB = r"""
import json, sys, time
import numpy as np
from fastcontact.squeeze import squeeze_model, squeeze_out
from fastcontact.squeeze import primitive as prim
from fastcontact.tables import Tables
path, repeats = sys.argv[1], int(sys.argv[2])
res = {}
for th in ("average", "critical_junction", "emt"):
    kw = dict(p0=1e5, E_star=13e6, R=0.02, eta=1e-3, theory=th, times=(1.0,), du=(1e-6,))
    squeeze_out(Tables.from_parquet(path), **kw)  # loads (or compiles) the kernels
    ts = []
    for _ in range(repeats):
        T = Tables.from_parquet(path)
        t0 = time.perf_counter()
        squeeze_out(T, **kw)
        ts.append(time.perf_counter() - t0)
    T = Tables.from_parquet(path)  # held: the model refers to its tables weakly
    pr, info = prim.build(squeeze_model(T, th), check=True)
    res[th] = {"ms": 1e3 * float(np.median(ts)), "nx": info["nx"], "nz": info["nz"],
               "err": info["max_rel_err_T"]}
print(json.dumps(res))
"""


def surfaces(tmp):
    """{name: Parquet path}: the embedded tables and two built here (read by both checkouts)."""
    import fastcontact as fc
    from fastcontact.roaddb import synthetic_road_psd
    from fastcontact.tables import precompute
    from fastcontact.tables.defaults import DEFAULT_SURFACES, default_table_path

    out = {n: str(default_table_path(n)) for n in sorted(DEFAULT_SURFACES)}
    _, q, C = synthetic_road_psd(np.random.default_rng(0))
    for name, psd in ((f"synthetic road ({q.size} samples)", fc.TabulatedPSD(q, C)),
                      ("S1 (H = 0.8, 5 decades)", fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e9))):
        path = Path(tmp) / f"{len(out)}.parquet"
        precompute(psd).to_parquet(path)
        out[name] = str(path)
    return out


def main(baseline, pairs):
    here = HERE.parent
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        caches = {"before": tmp / "cache_before", "after": tmp / "cache_after"}
        for c in caches.values():
            c.mkdir()
        paths = surfaces(tmp)
        rows = {}
        for name, path in paths.items():
            runs = {"before": [], "after": []}
            for _ in range(pairs):
                runs["before"].append(run_job(_JOB, baseline, caches["before"], path, str(REPEATS)))
                runs["after"].append(run_job(_JOB, here, caches["after"], path, str(REPEATS)))
            rows[name] = runs
            print(name, {k: [r["average"]["ms"] for r in v] for k, v in runs.items()}, flush=True)
    write(rows, baseline, pairs, load0, os.getloadavg())


def _label(checkout):
    """``<short commit> (<path>)`` of a checkout (the path alone where git cannot tell)."""
    import subprocess

    r = subprocess.run(["git", "-C", str(checkout), "rev-parse", "--short", "HEAD"],
                       capture_output=True, text=True)
    return f"{r.stdout.strip()} ({checkout})" if r.returncode == 0 else str(checkout)


def write(rows, baseline, pairs, load0, load1):
    L = ["## First call on new tables (issue 11.3) — `bench/bench_first_call.py`", "",
         f"Machine: {cpu_model()}, {os.cpu_count()} cores. Load average at start "
         f"({', '.join(f'{x:.2f}' for x in load0)}), at end ({', '.join(f'{x:.2f}' for x in load1)}).",
         "",
         "The first `squeeze_out` call on a freshly loaded Tables object (kernels compiled; the "
         "call builds its theory's time primitive), median of 5 calls per process, median over "
         f"{pairs} fresh processes per checkout, this checkout ({_label(HERE.parent)}) and "
         f"the baseline ({_label(baseline)}) alternating. Error: the primitive's measured maximum relative error "
         "of T at cell centres.", "",
         "| surface | theory | rows × z nodes (before → after) | before [ms] | after [ms] | "
         "after / before | max rel. err of T (before → after) |",
         "|---|---|---|---|---|---|---|"]
    for name, runs in rows.items():
        for th in THEORIES:
            b = statistics.median(r[th]["ms"] for r in runs["before"])
            a = statistics.median(r[th]["ms"] for r in runs["after"])
            rb, ra = runs["before"][0][th], runs["after"][0][th]
            L.append(f"| {name} | {th} | {rb['nx']} × {rb['nz']} → {ra['nx']} × {ra['nz']} | "
                     f"{b:.1f} | {a:.1f} | {a / b:.2f} | {rb['err']:.1e} → {ra['err']:.1e} |")
    write_keeping_notes(HERE / "first_call_results.md", "\n".join(L) + "\n")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True, help="checkout of the commit to compare with")
    ap.add_argument("--pairs", type=int, default=3)
    a = ap.parse_args()
    main(Path(a.baseline).resolve(), a.pairs)
