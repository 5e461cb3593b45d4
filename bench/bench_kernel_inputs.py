"""Read-only kernel inputs (kernels/readonly.py): per-call cost and the recompile it removes.

Alternates this checkout and a baseline checkout (``--baseline PATH``, e.g. a ``git worktree``
of the commit before) in fresh processes, each with its own warm numba cache, and reports the
median CPU time per case of the paths whose inputs changed (squeeze_out with the default start,
tire_footprint with every column; 1e6 cases of distinct pressures and radii on the embedded
asphalt_024mm tables), then, in one fresh process per checkout, how long a squeeze_out call with
an array p0 takes after one with a scalar (a compile where each kind of input has its own
signature). Writes bench/kernel_inputs_results.md.

    python bench/bench_kernel_inputs.py --baseline /tmp/wt_old
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from pathlib import Path

from checkouts import run_job

HERE = Path(__file__).resolve().parent

JOB = r"""
import json, math, sys, time
import numpy as np
from fastcontact.tables import Tables
from fastcontact.tables.defaults import default_table_path
from fastcontact.squeeze import squeeze_out
from fastcontact.tire import tire_footprint
what, n = sys.argv[1], int(float(sys.argv[2]))
T = Tables.from_parquet(default_table_path("asphalt_024mm"))
E, ETA = 13e6, 1e-3
rng = np.random.default_rng(1)
p0 = np.exp(rng.uniform(math.log(2e3), math.log(3e5), n))
R = rng.uniform(0.005, 0.03, n)
if what == "recompile":
    out = {}
    for label, p in (("scalar", 2e5), ("array", p0)):
        t = time.perf_counter()
        squeeze_out(T, p0=p, E_star=E, R=0.02, eta=ETA, theory="average")
        out[label] = time.perf_counter() - t
    print(json.dumps(out))
    sys.exit()
if what == "squeeze":
    job = lambda: squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory="average")
else:
    fl, sp = rng.uniform(0.05, 0.2, n), rng.uniform(5.0, 40.0, n)
    job = lambda: tire_footprint(T, p0=p0, E_star=E, R=R, eta=ETA, theory="average",
                                 footprint_length=fl, speed=sp)
job()
cpu = []
for _ in range(5):
    c = time.process_time(); job(); cpu.append(time.process_time() - c)
print(json.dumps({"cpu_ns": float(np.median(cpu)) / n * 1e9}))
"""


def run(src, cache, *args):
    return run_job(JOB, src, cache, *args)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", required=True, help="checkout of the commit before")
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--n", type=float, default=1e6)
    ap.add_argument("--caches", nargs=2, metavar=("THIS", "BASELINE"),
                    help="numba cache directories to reuse (default: new, empty ones)")
    a = ap.parse_args()
    here, base = HERE.parent, Path(a.baseline).resolve()
    tmp = Path(tempfile.mkdtemp(prefix="fc_bench_inputs_"))
    caches = dict(zip((here, base), map(Path, a.caches or (tmp / "new", tmp / "old"))))
    recompile = {s: run(s, tmp / f"fresh_{k}", "recompile", "1000")
                 for k, s in (("new", here), ("old", base))}
    for s in (here, base):  # warm each checkout's cache
        for what in ("squeeze", "tire"):
            run(s, caches[s], what, "1000")
    res = {(s, w): [] for s in (here, base) for w in ("squeeze", "tire")}
    for _ in range(a.pairs):
        for s in (base, here):
            for w in ("squeeze", "tire"):
                res[(s, w)].append(run(s, caches[s], w, str(a.n))["cpu_ns"])
    load = os.getloadavg()[0]
    lines = ["## Kernel inputs read-only: per-call cost and the recompile removed", "",
             f"Machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}; load average "
             f"{load:.1f} at the end. `bench/bench_kernel_inputs.py`: this checkout against the "
             f"commit before (baseline), alternating fresh processes, {a.pairs} pairs, median "
             f"of 5 calls each, {a.n:.0e} cases (embedded asphalt_024mm, average theory, "
             "distinct p0 and R). CPU time per case (both threads).", "",
             "| path | baseline CPU [ns/case] | after CPU [ns/case] | ratio after/baseline |",
             "|---|---|---|---|"]
    for w, label in (("squeeze", "squeeze_out, default start"),
                     ("tire", "tire_footprint, every column")):
        b, h = statistics.median(res[(base, w)]), statistics.median(res[(here, w)])
        lines.append(f"| {label} | {b:.0f} | {h:.0f} | {h / b:.2f} |")
    lines += ["", "A fresh process and a fresh numba cache, squeeze_out (1,000 cases) called "
              "first with a scalar p0, then with an array p0:", "",
              "| checkout | first call, scalar p0 [s] | then array p0 [s] |", "|---|---|---|"]
    for k, s in (("baseline", base), ("after", here)):
        r = recompile[s]
        lines.append(f"| {k} | {r['scalar']:.1f} | {r['array']:.2f} |")
    (HERE / "kernel_inputs_results.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
