"""Error against cost of the precomputed tables (issue #3, item 5).

For several surfaces, build the three-theory tables
  (a) on uniform grids of 4, 8, 16, 32 points per decade without refinement, and
  (b) with adaptive refinement at 100, 10, 1 (the default, TOLERANCE) and 0.1 times the
      default tolerances,
and report the build time (median of repeats, warm numba cache) and the maximum relative
interpolation error of ū, p_cont(ū) and σ̄ of each theory. Errors are measured against the
direct quadrature at 200 random log-uniform pressures per surface that are neither nodes
nor refinement midpoints (σ̄: only where A(ζ1)/A0 <= 0.4, "away from percolation", and
σ̄ > 1e-24). Writes bench/tables_results.md; bench/RESULTS.md collects the fragments.

    python bench/bench_tables.py [--repeats 3] [--quick]
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

import fastcontact as fc
from fastcontact import contact
from fastcontact.conductivity import sigma_bar
from fastcontact.defaults import DEFAULT_SURFACES, default_surface
from fastcontact.tables import TOLERANCE, default_grid, precompute

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
    args = ap.parse_args()
    surfaces = {"S1 (SPEC §8, H=0.8, 5 decades)": fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e9)}
    surfaces.update({n: default_surface(n) for n in DEFAULT_SURFACES})
    from fastcontact.roaddb import synthetic_road_psd
    _, q, C = synthetic_road_psd(np.random.default_rng(0))
    surfaces[f"synthetic road (TabulatedPSD, {q.size} samples)"] = fc.TabulatedPSD(q, C)
    if args.quick:
        surfaces = dict(list(surfaces.items())[:2])
    configs = [("uniform", ppd, None) for ppd in (4, 8, 16, 32)]
    configs += [("adaptive", 8, scale) for scale in (100.0, 10.0, 1.0, 0.1)]
    if args.quick:
        configs = [c for c in configs if c[1] in (8, 16) or c[0] == "adaptive"]
    # warm the numba cache
    precompute(fc.SelfAffinePSD(1e-5, 0.8, 1e4, 1e6), theories=THEORIES)
    lines = ["## Tables: interpolation error against build cost", "",
             f"Machine: {machine()}. Build times are medians of {args.repeats} warm builds "
             f"(numba cache loaded), all three theories; errors are maximum relative errors at "
             f"200 random pressures against the direct quadrature (σ̄ where A(ζ1)/A0 ≤ 0.4). "
             f"Ratio = build time / the default configuration's, same run. Default tolerances: "
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
            rows.append((kind, ppd, tol, dt, t.info["nodes"], e))
            print(name, kind, ppd, tol, f"{dt:.2f}s", t.info["nodes"], {k: f"{v:.1e}" for k, v in e.items()}, flush=True)
        base = next(r[3] for r in rows if r[0] == "adaptive" and r[2] == 1.0)
        lines += [f"### {name}", "",
                  "| grid | base ppd | tolerance × default | nodes | build [s] | ratio | err ū | err p(ū) | err σ̄ avg | err σ̄ CJ | err σ̄ EMT |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for kind, ppd, tol, dt, nodes, e in rows:
            lines.append(f"| {kind} | {ppd} | {tol if tol else '-'} | {nodes} | {dt:.2f} | {dt / base:.2f} | "
                         f"{e['u']:.1e} | {e['p_of_u']:.1e} | {e['average']:.1e} | "
                         f"{e['critical_junction']:.1e} | {e['emt']:.1e} |")
        lines.append("")
    out = Path(__file__).with_name("tables_results.md")
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
