"""Peak memory of ``fastcontact run`` against the number of cases (issue 15, bounded memory).

Each size runs in a fresh process: a squeeze study on one embedded table, N cases as the
product of a p0 axis (1000 values) and an η axis (N/1000 values) (the spline fast path),
streamed to Parquet in blocks of ``--chunk`` cases. Reported: wall and CPU time, peak
resident memory (``resource.getrusage(RUSAGE_SELF).ru_maxrss``) and that peak less the
process's peak after imports and table loading (the part that could grow with N).

    python bench/bench_run_memory.py --sizes 1e5 1e6 1e7 [--chunk 250000]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import json, resource, sys, time
from pathlib import Path
from fastcontact.studies.load import load_scene
from fastcontact.studies.run import run_scene
from fastcontact.tables.cache import obtain_tables
n, chunk, out = int(float(sys.argv[1])), int(sys.argv[2]), sys.argv[3]
scene = {
    "title": f"memory {n}",
    "study": {"kind": "squeeze", "theory": "average",
              "p0": {"start": "0.05 MPa", "stop": "1 MPa", "num": 1000, "log": True},
              "ratios": [1.1, 1.01], "du": ["1 um"]},
    "surfaces": {"a": {"table": "asphalt_024mm"}},
    "material": {"E": "10 MPa", "nu": 0.5},
    "fluid": {"eta": {"start": "1 mPa s", "stop": "1 Pa s", "num": n // 1000, "log": True}},
    "geometry": {"R": "2 cm"},
    "outputs": {"columns": ["u_inf", "t_star", "t_ratio_*", "t_du_*", "trapped"],
                "max_cases": 10**9},
}
sc = load_scene(scene)
obtain_tables(sc.surfaces["a"], sc.theories, dict(sc.table_options))
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0, c0 = time.perf_counter(), time.process_time()
res = run_scene(sc, out, chunk_size=chunk)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"cases": n, "rows": res.record["rows"], "wall_s": time.perf_counter() - t0,
                  "cpu_s": time.process_time() - c0, "peak_MB": peak / 1024,
                  "base_MB": base / 1024, "growth_MB": (peak - base) / 1024,
                  "file_MB": Path(out, "results.parquet").stat().st_size / 2**20}))
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=["1e5", "1e6", "1e7"])
    ap.add_argument("--chunk", type=int, default=100_000)
    ap.add_argument("--out", default=str(Path(__file__).with_name("run_memory_results.md")))
    a = ap.parse_args(argv)
    rows = []
    for s in a.sizes:
        with tempfile.TemporaryDirectory() as tmp:
            r = subprocess.run([sys.executable, "-c", CHILD, s, str(a.chunk), str(Path(tmp) / "o")],
                               capture_output=True, text=True, check=True)
            rows.append(json.loads(r.stdout.strip().splitlines()[-1]))
            print(rows[-1], flush=True)
    lines = ["# fastcontact run: peak memory against case count", "",
             f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores "
             f"(shared, noisy); Python {platform.python_version()}; block size {a.chunk:,} cases.",
             "Study: squeeze, one embedded table (asphalt_024mm), p0 (1000 values) x eta (N/1000 "
             "values), 7 result columns streamed to results.parquet "
             "(`bench/bench_run_memory.py`).", "",
             "| cases | wall [s] | CPU [s] | peak RSS [MB] | after set-up [MB] | growth [MB] | "
             "results.parquet [MB] |", "|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['cases']:.0e} | {r['wall_s']:.1f} | {r['cpu_s']:.1f} | "
                     f"{r['peak_MB']:.0f} | {r['base_MB']:.0f} | {r['growth_MB']:.0f} | "
                     f"{r['file_MB']:.1f} |")
    lines += ["", "Growth is the peak resident memory above the process after imports and "
              "table loading; bounded by the block size, not the case count, once N exceeds one "
              "block (memory grows with the sum of the axis lengths, not their product)."]
    Path(a.out).write_text("\n".join(lines) + "\n")
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
