"""Error against cost of the precomputed tables (issue #3, item 5).

For several surfaces, build the three-theory tables
  (a) on uniform grids of 4, 8, 16, 32 points per decade without refinement, and
  (b) with adaptive refinement at 100, 10, 1 (the default, TOLERANCE) and 0.1 times the
      default tolerances,
and report the build time (median of repeats, warm numba cache) and the maximum relative
interpolation error of ū, p_cont(ū) and σ̄ of each theory. With ``--speed BASELINE_DIR``
(a checkout of an earlier fastcontact, e.g. ``git archive 7f7ec20 fastcontact | tar -x -C DIR``)
it instead times the default three-theory precompute of each surface in this checkout and in
the baseline (separate processes, alternating, wall and CPU medians) and records both. Errors are measured against the
direct quadrature at 200 random log-uniform pressures per surface that are neither nodes
nor refinement midpoints (σ̄: only where A(ζ1)/A0 <= 0.4, "away from percolation", and
σ̄ > 1e-24). Writes bench/tables_results.md; bench/RESULTS.md collects the fragments.

    python bench/bench_tables.py [--repeats 3] [--quick] [--speed BASELINE_DIR | --accuracy]
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import re
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import fastcontact as fc
from fastcontact import contact
from fastcontact.flow.conductivity import sigma_bar
from fastcontact.tables import (DEFAULT_POINTS_PER_DECADE, SIGMA_FLOOR, TOLERANCE, default_grid,
                                precompute)
from fastcontact.tables.defaults import DEFAULT_SURFACES, default_surface

THEORIES = ("average", "critical_junction", "emt")


from machine_info import cpu_model  # noqa: E402  (bench/ is on sys.path when run)


def machine():
    model = cpu_model()
    return f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}, numpy {np.__version__}"


def reference_points(psd, n=200, seed=0):
    g = default_grid(psd)
    rng = np.random.default_rng(seed)
    edge = 0.3 * math.log(10.0)  # stay 0.3 decade inside every grid variant's range
    p = np.exp(rng.uniform(g.ln_lo + edge, g.ln_lo + g.dln * (g.n - 1) - edge, n))
    u = contact.mean_separation(psd, p, 1.0) / psd.h_rms
    A = contact.area_fraction(psd, p, 1.0)
    sel = A <= 0.4
    sig = {th: sigma_bar(psd, p[sel], th, tol=1e-11)[0] for th in THEORIES}
    return p, u, sel, sig


def errors(t, ref):
    p, u, sel, sig = ref
    out = {"u": float(np.max(np.abs(t.mean_separation(p, 1.0) / t.h_rms / u - 1)))}
    out["p_of_u"] = float(np.max(np.abs(t.contact_pressure(u * t.h_rms, 1.0) / p - 1)))
    for th in THEORIES:
        ok = sig[th] > 1e-24
        est = t.sigma_bar(p[sel][ok], 1.0, th)
        out[th] = float(np.max(np.abs(est / sig[th][ok] - 1)))
    return out


def near_percolation_errors(psd, t, n=100, seed=1):
    """Max relative errors of σ̄ (critical junction, effective medium) at n random pressures
    with 0.4 < A(ζ1)/A0 < 0.5 against the direct quadrature (tol = 1e-11), in the verified
    intervals (below the last node with σ̄ > SIGMA_FLOOR: the interval that straddles the floor,
    where σ̄ < 1e-21, is not interpolated to tolerance by design)."""
    lo, hi = t.p_range
    rng = np.random.default_rng(seed)
    p = np.exp(rng.uniform(math.log(lo), math.log(hi), 40 * n))
    A = contact.area_fraction(psd, p, 1.0)
    p = p[(A > 0.4) & (A < 0.5)][:n]
    out = {}
    for th in ("critical_junction", "emt"):
        ref = sigma_bar(psd, p, th, tol=1e-11).sigma_bar
        s = t.data[f"sigma_{th}"]
        ok = p <= t.data["p_over_E"][s > SIGMA_FLOOR].max()
        out[th] = float(np.max(np.abs(t.sigma_bar(p[ok], 1.0, th) / ref[ok] - 1))) if ok.any() \
            else float("nan")
    return out


_TIMER = r"""
import json, sys, time
import numpy as np
import fastcontact as fc
from fastcontact.defaults import default_surface
from fastcontact.tables import precompute
name = sys.argv[1]
if name == "S1":
    psd = fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e9)
elif name == "synthetic road":  # a tabulated spectrum: a kink at each of its 48 samples
    from fastcontact.roaddb import synthetic_road_psd
    _, q, C = synthetic_road_psd(np.random.default_rng(0))
    psd = fc.TabulatedPSD(q, C)
else:
    psd = default_surface(name)
precompute(fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e6))  # numba cache loaded, kernels compiled
t0, c0 = time.perf_counter(), time.process_time()
t = precompute(psd)
print(json.dumps({"wall": time.perf_counter() - t0, "cpu": time.process_time() - c0,
                  "nodes": t.info["nodes"]}))
"""


def _time_in(pythonpath, name):
    """One warm precompute of surface ``name`` in a fresh process importing ``pythonpath``."""
    env = dict(os.environ, PYTHONPATH=str(pythonpath))
    out = subprocess.run([sys.executable, "-c", _TIMER, name], env=env, capture_output=True,
                         text=True, check=True, cwd="/")
    return json.loads(out.stdout.strip().splitlines()[-1])


def speed(baseline, repeats):
    """Markdown lines: precompute times here and in ``baseline``, alternating, per surface."""
    here = Path(__file__).resolve().parent.parent
    names = ["S1"] + sorted(DEFAULT_SURFACES) + ["synthetic road"]
    lines = ["## Tables: three-theory precompute time (issue 11.3)", "",
             f"Machine: {machine()}; load average at start {os.getloadavg()[0]:.1f}. Each number "
             f"is the median of {repeats} warm builds (numba cache loaded, kernels compiled), "
             f"each in a fresh process, this checkout and the baseline ({baseline}) alternating. "
             "CPU = process CPU time (both threads), which is less sensitive to other load "
             "than wall time.", "",
             "| surface | nodes | before wall [s] | after wall [s] | wall ratio | before CPU [s] | "
             "after CPU [s] | CPU ratio |", "|---|---|---|---|---|---|---|---|"]
    for name in names:
        runs = {"before": [], "after": []}
        for _ in range(repeats):
            runs["before"].append(_time_in(baseline, name))
            runs["after"].append(_time_in(here, name))
        med = {k: {m: statistics.median(r[m] for r in v) for m in ("wall", "cpu")}
               for k, v in runs.items()}
        b, a = med["before"], med["after"]
        lines.append(f"| {name} | {runs['after'][0]['nodes']} | {b['wall']:.2f} | {a['wall']:.2f} | "
                     f"{a['wall'] / b['wall']:.2f} | {b['cpu']:.2f} | {a['cpu']:.2f} | "
                     f"{a['cpu'] / b['cpu']:.2f} |")
        print(lines[-1], flush=True)
    return lines + [""]


def _write(sections):
    """Write bench/tables_results.md: replace the ``## `` sections rerun (by title), keep the rest."""
    out = Path(__file__).with_name("tables_results.md")
    old = out.read_text() if out.is_file() else ""
    blocks = [b for b in re.split(r"(?m)^(?=## )", old) if b.startswith("## ")]
    new = {ln[0]: "\n".join(ln) + "\n" for ln in sections}
    text = "".join(new.pop(b.splitlines()[0], b) for b in blocks) + "".join(new.values())
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text(text)
    os.replace(tmp, out)
    print(f"wrote {out}")


def accuracy(repeats):
    """Markdown lines: errors of the default build of each surface against direct quadrature."""
    lines = ["## Tables: accuracy of the default three-theory build", "",
             f"Machine: {machine()}. Maximum relative errors at 200 random log-uniform pressures "
             "(not nodes, not midpoints) against the direct quadrature (σ̄: tol = 1e-11, where "
             "A(ζ1)/A0 ≤ 0.4 and σ̄ > 1e-24); next to percolation: 100 random pressures with "
             "0.4 < A(ζ1)/A0 < 0.5 below the last node with σ̄ > 1e-24 (the one interval "
             "that straddles this floor, where σ̄ < 1e-21, is not verified by design); build = median wall time of the warm builds.",
             "", "| surface | nodes | build [s] | err ū | err p(ū) | err σ̄ avg | err σ̄ CJ | "
             "err σ̄ EMT | err σ̄ CJ, A > 0.4 | err σ̄ EMT, A > 0.4 |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, psd in _surfaces(False).items():
        dt, t = timed_build(psd, repeats)
        e = errors(t, reference_points(psd))
        en = near_percolation_errors(psd, t)
        lines.append(f"| {name} | {t.info['nodes']} | {dt:.2f} | {e['u']:.1e} | {e['p_of_u']:.1e} | "
                     f"{e['average']:.1e} | {e['critical_junction']:.1e} | {e['emt']:.1e} | "
                     f"{en['critical_junction']:.1e} | {en['emt']:.1e} |")
        print(lines[-1], flush=True)
    return lines + [""]


def _surfaces(quick):
    surfaces = {"S1 (H=0.8, 5 decades)": fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e9)}
    surfaces.update({n: default_surface(n) for n in DEFAULT_SURFACES})
    from fastcontact.roaddb import synthetic_road_psd
    _, q, C = synthetic_road_psd(np.random.default_rng(0))
    surfaces[f"synthetic road (TabulatedPSD, {q.size} samples)"] = fc.TabulatedPSD(q, C)
    return dict(list(surfaces.items())[:2]) if quick else surfaces


def timed_build(psd, repeats, **kw):
    times = []
    t = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        t = precompute(psd, theories=THEORIES, **kw)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="two surfaces, fewer configurations")
    ap.add_argument("--speed", metavar="BASELINE_DIR", help="time precompute against a baseline")
    ap.add_argument("--accuracy", action="store_true", help="only the default build's errors")
    args = ap.parse_args()
    if args.speed:
        _write([speed(Path(args.speed).resolve(), args.repeats)])
        return
    if args.accuracy:
        _write([accuracy(args.repeats)])
        return
    surfaces = _surfaces(args.quick)
    ppd0 = DEFAULT_POINTS_PER_DECADE
    configs = [("uniform", ppd, None) for ppd in (4, 8, 16, 32)]
    configs += [("adaptive", ppd, 1.0) for ppd in (2, 3, 4, 6, 8, 12) if ppd != ppd0]
    configs += [("adaptive", ppd0, scale) for scale in (100.0, 10.0, 1.0, 0.1)]
    if args.quick:
        configs = [c for c in configs if c[1] in (8, 16) or c[0] == "adaptive"]
    # warm the numba cache
    precompute(fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e6), theories=THEORIES)
    lines = ["## Tables: interpolation error against build cost", "",
             f"Machine: {machine()}. Build times are medians of {args.repeats} warm builds "
             f"(numba cache loaded), all three theories; errors are maximum relative errors at "
             f"200 random pressures against the direct quadrature (σ̄ where A(ζ1)/A0 ≤ 0.4; "
             f"\"A > 0.4\": 100 random pressures next to percolation, as in the accuracy "
             f"section). Ratio = build time / the default configuration's (base grid "
             f"{ppd0} points per decade, default tolerances), same run. Default tolerances: "
             f"{TOLERANCE} (relative, at interval midpoints).", ""]
    for name, psd in surfaces.items():
        ref = reference_points(psd)
        rows = []
        for kind, ppd, tol in configs:
            kw = {"points_per_decade": ppd}
            if kind == "uniform":
                kw["refine"] = False
            else:
                kw["tolerance"] = {k: v * tol for k, v in TOLERANCE.items()}
            dt, t = timed_build(psd, args.repeats, **kw)
            e = errors(t, ref)
            e.update({f"near_{k}": v for k, v in near_percolation_errors(psd, t).items()})
            rows.append((kind, ppd, tol, dt, t.info["nodes"], e))
            print(name, kind, ppd, tol, f"{dt:.2f}s", t.info["nodes"], {k: f"{v:.1e}" for k, v in e.items()}, flush=True)
        base = next(r[3] for r in rows if r[0] == "adaptive" and r[2] == 1.0 and r[1] == ppd0)
        lines += [f"### {name}", "",
                  "| grid | base ppd | tolerance × default | nodes | build [s] | ratio | err ū | "
                  "err p(ū) | err σ̄ avg | err σ̄ CJ | err σ̄ EMT | err σ̄ CJ, A > 0.4 | "
                  "err σ̄ EMT, A > 0.4 |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for kind, ppd, tol, dt, nodes, e in rows:
            lines.append(f"| {kind} | {ppd} | {tol if tol else '-'} | {nodes} | {dt:.2f} | {dt / base:.2f} | "
                         f"{e['u']:.1e} | {e['p_of_u']:.1e} | {e['average']:.1e} | "
                         f"{e['critical_junction']:.1e} | {e['emt']:.1e} | "
                         f"{e['near_critical_junction']:.1e} | {e['near_emt']:.1e} |")
        lines.append("")
    _write([lines])


if __name__ == "__main__":
    main()
