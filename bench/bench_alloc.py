"""What a million-case call spends outside the kernels: writing its result into fresh memory.

A ``squeeze_out`` or ``tire_footprint`` call of 1e6 cases returns 19–20 columns, ~110–125 MB,
in arrays it has just allocated. Large NumPy arrays come from fresh ``mmap`` pages (glibc's
allocator, above its mmap threshold), and the first write to each 4 KiB page is a page fault.
This bench measures that cost on the machine it runs on and how much of each fast path it is:

1. writing 8 float64 columns of 1e6 values into fresh arrays vs into the same arrays again;
2. each fast path (theory "emt", embedded ``asphalt_024mm``; the cases of
   ``bench_squeeze.py``) in child processes with glibc's default allocator settings and with
   ``MALLOC_MMAP_THRESHOLD_``/``MALLOC_TRIM_THRESHOLD_`` raised so that freed memory is kept
   and reused (no new pages after the first call) — alternating, median of the medians;
3. the bytes each call allocates (tracemalloc peak; the result is most of it).

The second setting is a process-wide allocator choice for a benchmark, not something
fastcontact sets for its users. Writes ``bench/alloc_results.md``.

Run: ``python bench/bench_alloc.py [--pairs 3]``.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from machine_info import cpu_model  # noqa: E402

N = 1_000_000
PATHS = ("default start", "given start", "times", "tire")
KEEP = {"MALLOC_MMAP_THRESHOLD_": "4294967296", "MALLOC_TRIM_THRESHOLD_": "8589934592"}

CHILD = r"""
import json, math, sys, time, tracemalloc
import numpy as np
from fastcontact.squeeze import squeeze_model, squeeze_out
from fastcontact.squeeze import primitive as prim
from fastcontact.tables import Tables
from fastcontact.tables.defaults import default_table_path
from fastcontact.tire import tire_footprint
E, ETA, th, n = 13e6, 1e-3, "emt", int(sys.argv[1])
T = Tables.from_parquet(default_table_path("asphalt_024mm"))
rng = np.random.default_rng(0)
m = squeeze_model(T, th)
top = min(math.exp(prim.fast_limit(m)), T.p_range[1]) * E
p0 = np.exp(rng.uniform(math.log(T.p_range[0] * E * 1.001), math.log(top), n))
R = rng.uniform(0.005, 0.03, n)
us = squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=th, ratios=())["u_inf"].to_numpy()
us = us * np.exp(rng.uniform(0.1, 5.0, n))
fl, sp = rng.uniform(0.05, 0.2, n), rng.uniform(5.0, 40.0, n)
jobs = {
    "default start": lambda: squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=th),
    "given start": lambda: squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=th,
                                       u_start=us, du=(1e-6,)),
    "times": lambda: squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=th, u_start=us,
                                 ratios=(), times=(1e-5, 1e-3, 1e-1)),
    "tire": lambda: tire_footprint(T, p0=p0, E_star=E, R=R, eta=ETA, theory=th,
                                   footprint_length=fl, speed=sp),
}
res = {}
for k, f in jobs.items():
    f()
    ts = []
    for _ in range(7):
        t = time.perf_counter(); f(); ts.append(time.perf_counter() - t)
    tracemalloc.start(); f(); peak = tracemalloc.get_traced_memory()[1]; tracemalloc.stop()
    res[k] = [float(np.median(ts)), peak]
print(json.dumps(res))
"""


def fresh_vs_reused(repeats=7):
    """(ms fresh, ms reused) to write 8 float64 columns of N values (parallel numba loop)."""
    from numba import njit, prange

    @njit(parallel=True)
    def write(a, b, c, d, e, f, g, h):
        for i in prange(a.size):
            a[i] = i
            b[i] = i
            c[i] = i
            d[i] = i
            e[i] = i
            f[i] = i
            g[i] = i
            h[i] = i

    arrs = [np.empty(N) for _ in range(8)]
    write(*arrs)
    fresh, reused = [], []
    for _ in range(repeats):
        t = time.perf_counter()
        arrs = [np.empty(N) for _ in range(8)]
        write(*arrs)
        fresh.append(time.perf_counter() - t)
        t = time.perf_counter()
        write(*arrs)
        reused.append(time.perf_counter() - t)
    return 1e3 * float(np.median(fresh)), 1e3 * float(np.median(reused))


def child(env_extra):
    env = dict(os.environ, **env_extra)
    out = subprocess.run([sys.executable, "-c", CHILD, str(N)], env=env, capture_output=True,
                         text=True, check=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(pairs):
    load0 = os.getloadavg()
    f_ms, r_ms = fresh_vs_reused()
    runs = {"default": [], "keep": []}
    for _ in range(pairs):
        runs["default"].append(child({}))
        runs["keep"].append(child(KEEP))
    load1 = os.getloadavg()
    mb = 8 * N * 8 / 1e6
    L = ["## Result memory: page faults of a million-row result — `bench/bench_alloc.py`", "",
         f"Machine: {cpu_model()}, {os.cpu_count()} cores; load average at start "
         f"{tuple(round(x, 2) for x in load0)}, at end {tuple(round(x, 2) for x in load1)}. "
         f"Theory emt, embedded `asphalt_024mm`, {N:,} cases (the cases of bench_squeeze.py); "
         f"each path the median of 7 calls in a child process, {pairs} child pairs alternating "
         f"(default allocator, then glibc keeping freed memory: {', '.join(f'{k}={v}' for k, v in KEEP.items())}); "
         "the table gives the median over the pairs.", "",
         f"Writing 8 float64 columns of {N:,} values ({mb:.0f} MB): into fresh arrays "
         f"{f_ms:.1f} ms, into the same arrays again {r_ms:.1f} ms — {(f_ms - r_ms) / mb:.2f} ms "
         "per MB of first-touch page faults on this machine.", "",
         "| path | result + temporaries [MB] | default allocator [cases/s] | memory kept [cases/s] | "
         "ratio | share of the call spent on fresh pages |",
         "|---|---|---|---|---|---|"]
    for p in PATHS:
        td = float(np.median([r[p][0] for r in runs["default"]]))
        tk = float(np.median([r[p][0] for r in runs["keep"]]))
        peak = runs["default"][0][p][1] / 1e6
        L.append(f"| {p} | {peak:.0f} | {N / td:.3g} | {N / tk:.3g} | {td / tk:.2f} | "
                 f"{max(0.0, 1 - tk / td):.0%} |")
    L += ["", "Reading: glibc serves large arrays from fresh mmap pages until its mmap threshold "
          "has adapted to freed blocks; after that a process mostly reuses heap memory. So the "
          "first million-row calls of a process pay the page faults (here the first path "
          "measured in each child, 'default start') and later calls little. The 'memory kept' "
          "column is the kernels' own throughput: where it is close to the default column, the "
          "path is bound by its kernel, not by the memory of its result. fastcontact does not "
          "change process-wide allocator settings.", ""]
    out = HERE / "alloc_results.md"
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text("\n".join(L))
    os.replace(tmp, out)
    print("\n".join(L))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pairs", type=int, default=3)
    main(ap.parse_args().pairs)
