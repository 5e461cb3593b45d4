"""Benchmark of fastcontact.seal (issue #5): accuracy knobs against cost, and against the
independent reference's cost, in one run on this machine.

Writes ``bench/seal_results.md`` (a Markdown fragment for bench/collect.py) and
``bench/seal_error_vs_time.png``. Run: ``python bench/bench_seal.py [--quick]``.

* error: max relative error of Q against ``tests/reference/seal_reference.py`` (direct
  contact core, no tables): flat rings by composite Gauss–Legendre of direct σ_eff; O-rings
  by an independent graded-panel Newton solution of eq. (33) on a Chebyshev interpolant of
  direct σ_eff. Cases: dp/p0 from 1e-4 up to and including the lift-off point.
* cost: median over repeats of the wall time per case for N random cases, kernel-only
  (reduced arrays in, W out) and end-to-end (``seal_leak``: validation, flags, DataFrame);
* knobs: uniform — node spacing of the tabulated primitive S and the Gauss–Legendre order of
  short intervals; Hertz — Gauss–Legendre nodes per panel ("ODE order": the collocation is
  exact for polynomials of degree 2n−1), the panel error tolerance (mesh density: "profile
  grid points" = panels × nodes, reported), and the grading order of the end map;
* baseline: the reference's own cost per case (measured here, same machine, same run).
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

import fastcontact as fc  # noqa: E402
import fastcontact.seal as seal  # noqa: E402
from reference.seal_reference import (  # noqa: E402
    SigmaInterp, hertz_geometry, hertz_reference, uniform_reference)

SURFACE = dict(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
E = 1e7
ETA = 1e-3
L, L_Y, R = 5e-3, 0.1, 1e-3
ALPHA = 0.54
RATIOS = [1e-4, 1e-3, 1e-2, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999, 1.0]


from machine_info import cpu_model  # noqa: E402  (bench/ is on sys.path when run)


def machine():
    model = cpu_model()
    import numba

    return (f"{model}, {os.cpu_count()} cores, numba threads {numba.get_num_threads()}; "
            f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}")


def median_time(fn, repeats):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def fresh_context(tables, theory, prim_h=None, prim_gl=None):
    """A SealContext built with non-default primitive knobs (bypassing the cache)."""
    old = seal.PRIM_H, seal.PRIM_GL
    try:
        if prim_h is not None:
            seal.PRIM_H = prim_h
        if prim_gl is not None:
            seal.PRIM_GL = prim_gl
        return seal.SealContext(tables, theory)
    finally:
        seal.PRIM_H, seal.PRIM_GL = old


# --------------------------------------------------------------------------- uniform
def uniform_section(tables, psd, quick, repeats):
    rows = []
    p0s = [5e3, 5e4, 5e5]
    cases = [(th, p0, r) for th in ("average", "critical_junction") for p0 in p0s for r in RATIOS]
    if quick:
        cases = cases[::3]
    ref = {}
    t_ref = []
    for th, p0, r in cases:
        t0 = time.perf_counter()
        q, est = uniform_reference(psd, p0=p0, dp=r * p0, L=L, L_y=L_Y, E_star=E, eta=ETA,
                                   theory=th, alpha_cj=ALPHA if th == "critical_junction" else 1.0)
        t_ref.append(time.perf_counter() - t0)
        ref[(th, p0, r)] = q
    base = statistics.median(t_ref)
    # random throughput set
    rng = np.random.default_rng(1)
    N = 200_000 if quick else 2_000_000
    p0 = 10 ** rng.uniform(3, 6, N)
    dp = rng.uniform(0, 1, N) * p0
    lo = np.ascontiguousarray((p0 - dp) / E)
    hi = np.ascontiguousarray(p0 / E)
    knobs = [(h, g) for h in (1 / 4, 1 / 8, 1 / 16, 1 / 32, 1 / 64) for g in (2, 4, 6)]
    if quick:
        knobs = [(1 / 8, 4), (1 / 32, 6)]
    for h, g in knobs:
        sc = {th: fresh_context(tables, th, h, g) for th in ("average", "critical_junction")}
        err = 0.0
        for (th, p0_, r), q in ref.items():
            c = sc[th]
            I = seal._uniform_q_reduced(c, np.array([(p0_ - r * p0_) / E]), np.array([p0_ / E]))[0]
            scale = (ALPHA / c.alpha_table) ** 3 if th == "critical_junction" else 1.0
            Q = L_Y * c.h_rms ** 3 * E / (12 * ETA * L) * I * scale
            err = max(err, abs(Q / q - 1))
        c = sc["critical_junction"]
        seal._uniform_q_reduced(c, lo[:100], hi[:100])
        tk = median_time(lambda: seal._uniform_q_reduced(c, lo, hi), repeats)
        rows.append(dict(knob=f"S nodes h = 1/{round(1 / h)}, short-interval GL{g}",
                         cases=N, ns_kernel=tk / N * 1e9, ns_e2e=math.nan, err=err,
                         default=(h == seal.PRIM_H and g == seal.PRIM_GL)))
    # end-to-end with the defaults
    seal_leak = fc.seal_leak
    seal_leak(tables, p0=p0[:10], dp=dp[:10], L=L, L_y=L_Y, E_star=E, eta=ETA)
    te = median_time(lambda: seal_leak(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E, eta=ETA,
                                       alpha_cj=ALPHA), repeats)
    for row in rows:
        if row["default"]:
            row["ns_e2e"] = te / N * 1e9
    return rows, base, len(cases)


# --------------------------------------------------------------------------- Hertz
def hertz_section(tables, psd, quick, repeats):
    interp = {}
    f_list = [2.0, 20.0, 200.0]
    p_hi = 1.02 * hertz_geometry(R, max(f_list), E)[1]
    t0 = time.perf_counter()
    for th in ("average", "critical_junction"):
        interp[th] = SigmaInterp(psd, E_star=E, eta=ETA, theory=th, p_lo=1e-16 * E, p_hi=p_hi,
                                 alpha_cj=ALPHA if th == "critical_junction" else 1.0, degree=120)
        assert interp[th].max_error < 1e-9, (th, interp[th].max_error)
    t_interp = time.perf_counter() - t0
    cases = [(th, f, r) for th in ("average", "critical_junction") for f in f_list for r in RATIOS]
    if quick:
        cases = cases[::3]
    ref, t_ref = {}, []
    for th, f, r in cases:
        a, pH = hertz_geometry(R, f, E)
        t0 = time.perf_counter()
        q, est, _ = hertz_reference(interp[th], R=R, f_N=f, dp=r * pH, L_y=L_Y, E_star=E,
                                    panels=6, nodes=10)
        t_ref.append(time.perf_counter() - t0)
        ref[(th, f, r)] = q
    base = statistics.median(t_ref)
    rng = np.random.default_rng(2)
    N = 1000 if quick else 5000
    piH = 10 ** rng.uniform(-3, -1, N)
    ra = 10 ** rng.uniform(-4, math.log10(0.999), N)
    pia = np.ascontiguousarray(ra * piH)
    pib = np.zeros(N)
    piH = np.ascontiguousarray(piH)
    sc = seal.seal_context(tables, "critical_junction")
    d = seal.SOLVER_DEFAULTS
    knobs = ([dict(nodes=k) for k in (6, 8, 10, 12, 16)]
             + [dict(tol=t) for t in (1e-1, 1e-2, 1e-4, 1e-6)]
             + [dict(grading=g) for g in (0, 1, 3)])
    if quick:
        knobs = [dict(nodes=10), dict(tol=1e-2)]
    rows = []
    for kn in knobs:
        o = dict(d, **kn)
        err = 0.0
        for (th, f, r), q in ref.items():
            Q = fc.seal_leak(tables, profile="hertz", R=R, f_N=f, dp=r * hertz_geometry(R, f, E)[1],
                             L_y=L_Y, E_star=E, eta=ETA, theory=th,
                             alpha_cj=ALPHA if th == "critical_junction" else 1.0, solver=o).Q[0]
            err = max(err, abs(Q / q - 1))
        seal._hertz_rows(sc, piH[:20], pia[:20], pib[:20], o)
        out = {}

        def run():
            out["r"] = seal._hertz_rows(sc, piH, pia, pib, o)
        tk = median_time(run, repeats)
        W, st, P, e = out["r"]
        label = ", ".join(f"{k} = {v}" for k, v in kn.items())
        rows.append(dict(knob=label, cases=N, ns_kernel=tk / N * 1e9, ns_e2e=math.nan, err=err,
                         points=float(np.mean(P) * o["nodes"]), failed=int(np.sum(st != 0)),
                         default=all(d[k] == v for k, v in kn.items())))
    # end-to-end, defaults, physical inputs
    f_N = math.pi * E / (4 * R) * (2 * R * piH) ** 2 / 1.0  # a = 2R p_H/E*, f_N = π a p_H/2
    f_N = math.pi / 2 * (2 * R * piH) * (piH * E)
    dp = ra * piH * E
    fc.seal_leak(tables, profile="hertz", R=R, f_N=f_N[:10], dp=dp[:10], L_y=L_Y, E_star=E,
                 eta=ETA)
    te = median_time(lambda: fc.seal_leak(tables, profile="hertz", R=R, f_N=f_N, dp=dp,
                                          L_y=L_Y, E_star=E, eta=ETA, alpha_cj=ALPHA), repeats)
    for row in rows:
        if row["default"]:
            row["ns_e2e"] = te / N * 1e9
    return rows, base, len(cases), t_interp


def compile_time():
    code = textwrap.dedent("""
        import time, numpy as np, fastcontact as fc
        T = fc.precompute(fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8),
                          theories=("critical_junction",), grid=(-14, 0, 15), refine=False)
        t0 = time.perf_counter()
        fc.seal_leak(T, p0=5e4, dp=1e4, L=5e-3, L_y=0.1, E_star=1e7, eta=1e-3)
        t1 = time.perf_counter()
        fc.seal_leak(T, profile="hertz", R=1e-3, f_N=20.0, dp=1e4, L_y=0.1, E_star=1e7, eta=1e-3)
        t2 = time.perf_counter()
        print(t1 - t0, t2 - t1)
    """)
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, cwd=str(ROOT))
    try:
        a, b = (float(v) for v in out.stdout.split())
        return a, b
    except ValueError:
        return math.nan, math.nan


# --------------------------------------------------------------------------- report
def plot(urows, hrows, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    a1, a2 = fig.subplots(1, 2)
    for r in urows:
        a1.plot(r["ns_kernel"], max(r["err"], 1e-16), "o", color="tab:red" if r["default"] else "tab:blue")
        a1.annotate(r["knob"].replace("S nodes ", "").replace("short-interval ", ""),
                    (r["ns_kernel"], max(r["err"], 1e-16)), fontsize=6, xytext=(3, 2),
                    textcoords="offset points")
    for r in hrows:
        a2.plot(r["ns_kernel"] / 1e3, max(r["err"], 1e-16), "o",
                color="tab:red" if r["default"] else "tab:blue")
        a2.annotate(r["knob"], (r["ns_kernel"] / 1e3, max(r["err"], 1e-16)), fontsize=6,
                    xytext=(3, 2), textcoords="offset points")
    for ax, title, unit in ((a1, "uniform ring", "ns"), (a2, "Hertz O-ring", "µs")):
        ax.set_yscale("log")
        ax.set_xscale("log")
        ax.axhline(1e-6, color="0.5", lw=0.8, ls="--")
        ax.set_xlabel(f"kernel time per case ({unit})")
        ax.set_ylabel("max relative error of Q vs reference")
        ax.set_title(f"{title} (red: default)", fontsize=10)
        ax.grid(True, lw=0.3, alpha=0.5)
    tmp = path.with_suffix(".png.tmp")
    fig.savefig(tmp, format="png", dpi=130)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    load0 = os.getloadavg()
    psd = fc.SelfAffinePSD(**SURFACE)
    t0 = time.perf_counter()
    tables = fc.precompute(psd)
    t_tab = time.perf_counter() - t0
    t0 = time.perf_counter()
    for th in tables.theories:
        seal.seal_context(tables, th)
    t_ctx = (time.perf_counter() - t0) / len(tables.theories)
    urows, ubase, un = uniform_section(tables, psd, args.quick, args.repeats)
    hrows, hbase, hn, t_interp = hertz_section(tables, psd, args.quick, max(3, args.repeats // 2))
    ct = (math.nan, math.nan) if args.quick else compile_time()
    load1 = os.getloadavg()
    lines = ["## Seal leak rate (issue #5) — `bench/bench_seal.py`", ""]
    lines.append(f"Machine: {machine()}. Shared/noisy machine: medians of repeats; ratios "
                 f"measured in the same run. Load average (1/5/15 min) at start "
                 f"{tuple(round(x, 2) for x in load0)}, at end {tuple(round(x, 2) for x in load1)} "
                 f"(2 cores: > 2 means other processes competed).")
    lines.append("")
    lines.append(f"Surface {SURFACE}, E* = {E:g} Pa, η = {ETA:g} Pa·s; tables (3 theories, "
                 f"{tables.info['nodes']} nodes) built in {t_tab:.1f} s; seal context per theory "
                 f"(re-tabulated σ̄, verified cells, primitive S) {t_ctx * 1e3:.0f} ms, once per "
                 f"tables × theory. Critical junction with α_cj = {ALPHA} (tables α = 1, rescaled).")
    lines.append("")
    if not math.isnan(ct[0]):
        lines.append(f"Compile time (fresh process, empty numba cache): uniform {ct[0]:.1f} s, "
                     f"Hertz {ct[1]:.1f} s (once per machine; cached on disk afterwards).")
        lines.append("")
    lines.append(f"### Uniform (flat ring): {un} reference cases (average, critical junction; "
                 f"p0 = 5 kPa … 0.5 MPa; dp/p0 = {RATIOS[0]:g} … 1 incl. the lift-off point)")
    lines.append("")
    lines.append(f"Baseline: the reference (composite Gauss–Legendre of direct σ_eff, "
                 f"≈ 300–3000 direct evaluations) costs **{ubase * 1e3:.1f} ms per case** (median).")
    lines.append("")
    lines.append("| knob | cases (timing) | kernel ns/case | end-to-end ns/case | cases/s (end-to-end) | max rel. err Q | × baseline |")
    lines.append("|---|---|---|---|---|---|---|")
    for r in urows:
        ns = r["ns_e2e"] if not math.isnan(r["ns_e2e"]) else r["ns_kernel"]
        tag = " **(default)**" if r["default"] else ""
        e2e = f"{r['ns_e2e']:.0f}" if not math.isnan(r["ns_e2e"]) else "–"
        rate = f"{1e9 / r['ns_e2e']:.3g}" if not math.isnan(r["ns_e2e"]) else f"({1e9 / r['ns_kernel']:.3g} kernel)"
        lines.append(f"| {r['knob']}{tag} | {r['cases']:,} | {r['ns_kernel']:.0f} | {e2e} | {rate} | "
                     f"{r['err']:.1e} | {ubase / (ns * 1e-9):.3g} |")
    lines.append("")
    lines.append(f"### Hertz O-ring: {hn} reference cases (average, critical junction; "
                 f"p_H/E* = 0.008, 0.025, 0.08; dp/p_H = {RATIOS[0]:g} … 1 incl. the lift-off point)")
    lines.append("")
    lines.append(f"Baseline: the reference (graded Gauss–Legendre panels, dense Newton, two meshes; "
                 f"σ from a Chebyshev interpolant of direct values built once in {t_interp * 1e3:.0f} ms) "
                 f"costs **{hbase * 1e3:.0f} ms per case** (median). Timing set: random p_H/E* "
                 f"in [1e-3, 0.1], dp/p_H in [1e-4, 0.999], critical junction.")
    lines.append("")
    lines.append("| knob | cases (timing) | mean points (panels × nodes) | kernel µs/case | end-to-end µs/case | cases/s (end-to-end) | max rel. err Q | not converged | × baseline |")
    lines.append("|---|---|---|---|---|---|---|---|---|")
    for r in hrows:
        ns = r["ns_e2e"] if not math.isnan(r["ns_e2e"]) else r["ns_kernel"]
        tag = " **(default)**" if r["default"] else ""
        e2e = f"{r['ns_e2e'] / 1e3:.1f}" if not math.isnan(r["ns_e2e"]) else "–"
        rate = f"{1e9 / r['ns_e2e']:.3g}" if not math.isnan(r["ns_e2e"]) else f"({1e9 / r['ns_kernel']:.3g} kernel)"
        lines.append(f"| {r['knob']}{tag} | {r['cases']:,} | {r['points']:.0f} | "
                     f"{r['ns_kernel'] / 1e3:.1f} | {e2e} | {rate} | {r['err']:.1e} | {r['failed']} | "
                     f"{hbase / (ns * 1e-9):.3g} |")
    lines.append("")
    lines.append("Error vs time per knob: `bench/seal_error_vs_time.png`. The error floor "
                 "(~1e-8 … 1e-10) is the tables' interpolation, not the seal solvers.")
    lines.append("")
    out = HERE / "seal_results.md"
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines))
    os.replace(tmp, out)
    plot(urows, hrows, HERE / "seal_error_vs_time.png")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
