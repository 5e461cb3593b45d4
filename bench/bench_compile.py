"""First call of each engine path on a new machine (kernel compiling) and its speed after.

For each path — squeeze_out with the default start, squeeze_out with per-case starts and three
times, tire_footprint with every column, squeeze_history, the Barus squeeze-out and tire
(``alpha_pv``), and seal_leak's flat ring and Hertz O-ring — runs one fresh process with an
empty numba cache per checkout (this one and ``--baseline PATH``, e.g. a ``git worktree`` of the
commit before) and times the path's first call (1,000 cases, ``method="fast"``: what a user
waits for the first time on a new machine; tire_footprint picks the per-case quadrature below
2,000 cases unless told), then the per-case CPU time of the same path with the cache warm,
alternating the checkouts in fresh processes. Writes bench/compile_results.md.

    python bench/bench_compile.py --baseline /tmp/wt_old
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from checkouts import run_job
from results_notes import write_keeping_notes

HERE = Path(__file__).resolve().parent

PATHS = {
    "squeeze": "squeeze_out, default start",
    "times": "squeeze_out, per-case start, 3 times",
    "tire": "tire_footprint, every column",
    "history": "squeeze_history (points)",
    "barus": "squeeze_out, alpha_pv (Barus)",
    "barus_tire": "tire_footprint, alpha_pv (Barus)",
    "ring": "seal_leak, flat ring (rows)",
    "oring": "seal_leak, Hertz O-ring (rows)",
}

JOB = r"""
import json, math, sys, time
t_start = time.perf_counter()
import numpy as np
from fastcontact.tables import Tables
from fastcontact.tables.defaults import default_table_path
from fastcontact.squeeze import squeeze_out, squeeze_history
from fastcontact.tire import tire_footprint
from fastcontact.seal import seal_leak
what, mode, n = sys.argv[1], sys.argv[2], int(float(sys.argv[3]))
T = Tables.from_parquet(default_table_path("asphalt_024mm"))
E, ETA, TH = 13e6, 1e-3, "emt"
rng = np.random.default_rng(1)
p0 = np.exp(rng.uniform(math.log(5e4), math.log(4e5), n))
R = rng.uniform(0.005, 0.02, n)
fl, sp = rng.uniform(0.05, 0.2, n), rng.uniform(5.0, 40.0, n)
kw = dict(E_star=E, R=R, eta=ETA, theory=TH)
if what == "squeeze":
    job = lambda: squeeze_out(T, p0=p0, **kw)
elif what == "times":
    us = rng.uniform(1e-5, 1e-4, n)
    job = lambda: squeeze_out(T, p0=p0, u_start=us, times=[1e-4, 1e-3, 1e-2], **kw)
elif what == "tire":
    job = lambda: tire_footprint(T, p0=p0, footprint_length=fl, speed=sp, method="fast", **kw)
elif what == "history":
    t = np.geomspace(1e-6, 10.0, n)
    job = lambda: squeeze_history(T, 2e5, E, 0.01, ETA, theory=TH, t=t)
elif what == "barus":
    job = lambda: squeeze_out(T, p0=p0, alpha_pv=1e-6, **kw)
elif what == "barus_tire":
    job = lambda: tire_footprint(T, p0=p0, footprint_length=fl, speed=sp, alpha_pv=1e-6,
                                 method="fast", **kw)
elif what == "ring":
    job = lambda: seal_leak(T, p0=p0, dp=0.5 * p0, L=1e-3, L_y=0.1, E_star=E, eta=ETA,
                            theory="critical_junction", alpha_cj=0.54)
else:
    fN = rng.uniform(20.0, 200.0, min(n, 2000))  # the O-ring solves rows: fewer of them
    job = lambda: seal_leak(T, profile="hertz", R=2e-3, f_N=fN, dp=1e4, L_y=0.1, E_star=E,
                            eta=ETA, theory="critical_junction")
t_ready = time.perf_counter()
if mode == "first":
    job()
    print(json.dumps({"first_s": time.perf_counter() - t_ready,
                      "import_s": t_ready - t_start}))
    sys.exit()
job()
cpu = []
for _ in range(5):
    c = time.process_time(); job(); cpu.append(time.process_time() - c)
cases = fN.size if what == "oring" else n
print(json.dumps({"cpu_ns": float(np.median(cpu)) / cases * 1e9}))
"""


def run(src, cache, *args):
    return run_job(JOB, src, cache, *args)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", required=True, help="checkout of the commit before")
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--n", type=float, default=3e5)
    ap.add_argument("--paths", nargs="+", default=list(PATHS), choices=list(PATHS))
    a = ap.parse_args()
    here, base = HERE.parent, Path(a.baseline).resolve()
    tmp = Path(tempfile.mkdtemp(prefix="fc_bench_compile_"))
    t0 = time.time()
    first = {}
    for w in a.paths:
        for k, s in (("old", base), ("new", here)):
            cache = tmp / f"fresh_{k}_{w}"
            first[(s, w)] = run(s, cache, w, "first", "1000")["first_s"]
            shutil.rmtree(cache, ignore_errors=True)
            print(k, w, f"{first[(s, w)]:.1f} s", flush=True)
    caches = {here: tmp / "warm_new", base: tmp / "warm_old"}
    for s in (here, base):
        for w in a.paths:
            run(s, caches[s], w, "first", "1000")
    res = {(s, w): [] for s in (here, base) for w in a.paths}
    for _ in range(a.pairs):
        for s in (base, here):
            for w in a.paths:
                res[(s, w)].append(run(s, caches[s], w, "speed", str(a.n))["cpu_ns"])
    load = os.getloadavg()
    lines = ["## Kernel compiling: the first call of each path on a new machine", "",
             f"Machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}; load average "
             f"{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} at the end, {time.time() - t0:.0f} s "
             "in all. `bench/bench_compile.py`: this checkout against the commit before "
             "(baseline). First call: a fresh process with an empty numba cache per path and "
             "checkout, 1,000 cases (embedded asphalt_024mm, EMT, method \"fast\"), the kernels it "
             "compiles "
             "included (imports and table loading not). Speed: the same path with the cache warm, "
             f"alternating fresh processes, {a.pairs} pairs, median of 5 calls each, {a.n:.0e} "
             "cases (points for the history; 2,000 O-rings), CPU time per case (both threads).", "",
             "| path | first call before [s] | after [s] | ratio | CPU before [ns/case] | "
             "after [ns/case] | ratio |", "|---|---|---|---|---|---|---|"]
    for w in a.paths:
        fb, fh = first[(base, w)], first[(here, w)]
        b, h = statistics.median(res[(base, w)]), statistics.median(res[(here, w)])
        lines.append(f"| {PATHS[w]} | {fb:.1f} | {fh:.1f} | {fh / fb:.2f} | {b:.0f} | {h:.0f} "
                     f"| {h / b:.2f} |")
    write_keeping_notes(HERE / "compile_results.md", "\n".join(lines) + "\n")
    shutil.rmtree(tmp, ignore_errors=True)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
