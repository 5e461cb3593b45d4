"""Cost of the emt_threshold option in the shipped effective-medium kernel (issue 13.3).

Baseline, measured in the same run: the kernel module as it was before the option
(``git show 5040159:fastcontact/flow/_kernels.py``), loaded under a private name. Times the
Bruggeman σ̄ at 60 reduced pressures (A(ζ1)/A0 = 0.001..0.49) of a self-affine surface with
ζ1 = 1000; median of 9 runs each, interleaved. Also checks bit-identity at threshold 0.5.

Usage: NUMBA_CACHE_DIR=/tmp/nbcache_x python bench/bench_calibration_integration.py
"""
import importlib.util
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import fastcontact as fc
from fastcontact import contact
from fastcontact.contact._kernels import PANEL, psd_kernel
from fastcontact.flow import _kernels as newk
from fastcontact.flow import conductivity as cond
from fastcontact.kernels.quadrature import gauss_hermite, gauss_legendre
from fastcontact.kernels.special import k_table

BASELINE = "5040159"


def _old_kernels():
    root = Path(__file__).resolve().parents[1]
    src = subprocess.run(["git", "show", f"{BASELINE}:fastcontact/flow/_kernels.py"], cwd=root,
                         check=True, capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp()) / "old_kernels.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("fastcontact.flow._baseline_kernels", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def main(runs=9):
    old = _old_kernels()
    q0 = 2 * math.pi / 1e-3
    psd = fc.SelfAffinePSD(h_rms=1e-6, hurst=0.8, q0=q0, q1=1000 * q0, q_roll=4 * q0)
    pb = np.ascontiguousarray(contact.percolation_pressure(psd, 1.0, np.linspace(0.001, 0.49, 60)))
    glx, glw = gauss_legendre()
    ghx, ghw = gauss_hermite(cond.GH_ORDER)
    sk, kt = psd_kernel(psd), k_table()

    def run(mod, *threshold):
        sp = mod.EMTSpec(psd.h_rms, 1.0, glx, glw, float(PANEL), False, ghx, ghw,
                         cond.EMT_N_START, cond.EMT_TOL, *threshold)
        n = pb.size
        s, pc, e, ne = np.empty(n), np.empty(n, bool), np.empty(n), np.empty(n, np.int64)
        with cond._dynamic_schedule():
            mod.emt_kernel(sk, pb, kt, sp, s, pc, e, ne)
        return s

    cases = {"baseline": lambda: run(old),
             "threshold 0.5": lambda: run(newk, 0.5),
             "threshold 0.42": lambda: run(newk, 0.42)}
    out = {k: f() for k, f in cases.items()}  # compile / warm up
    print("bit-identical at 0.5:", np.array_equal(out["baseline"], out["threshold 0.5"]))
    times = {k: [] for k in cases}
    for _ in range(runs):
        for k, f in cases.items():
            t = time.perf_counter()
            f()
            times[k].append(time.perf_counter() - t)
    base = np.median(times["baseline"])
    for k, v in times.items():
        print(f"{k:16s} {np.median(v) * 1e3:8.1f} ms   ratio {np.median(v) / base:.3f}")


if __name__ == "__main__":
    main()
