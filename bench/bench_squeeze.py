"""Benchmark of fastcontact.squeeze (issue #4): accuracy knobs vs cost, against a
solve_ivp baseline, in one run on this machine.

Writes ``bench/squeeze_results.md`` (a Markdown fragment) and
``bench/squeeze_error_vs_time.png``. Run: ``python bench/bench_squeeze.py [--quick]``.

* error: max relative error of t* (ū = 1.01 ū∞, default start p_cont = 1e-3 p0) against the
  independent direct-core reference ``tests/reference/squeeze_reference.py`` (scipy quad,
  no tables) over a few p0 per theory;
* cost: median over repeats of wall time per case of ``squeeze_out`` for N random cases
  (p0/E* log-uniform from 1e-9 to just below percolation, R, η random), default ratios
  (1.1, 1.01, 1.001), both kernel-only and end-to-end (validation + DataFrame);
* baseline: ``scipy.integrate.solve_ivp`` (LSODA, rtol 1e-10, terminal event at
  ū = 1.01 ū∞) per case with Python callables on the same tables (``Tables.contact_pressure``,
  ``Tables.sigma_bar``), as a physicist would write it;
* compile time: first call in a fresh process with an empty NUMBA_CACHE_DIR, minus the
  warm call; spline set-up (per tables × theory × target) reported separately.
"""
from __future__ import annotations

import math
import os
import platform
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

import fastcontact  # noqa: E402
import fastcontact.squeeze as sq  # noqa: E402
from fastcontact.squeeze import squeeze_model, squeeze_out  # noqa: E402
from fastcontact.tables import precompute  # noqa: E402
from reference.squeeze_reference import SqueezeReference, tau0  # noqa: E402

E = 1e7
ETA = 1e-3
R = 0.01
SURFACE = dict(h_rms=1e-5, hurst=0.8, q0=1e4, q1=1e8)
TIGHT = None  # the default table tolerances (quintic tables meet the 1e-6 t* target)
REF_PIS = {"average": [1e-9, 1e-5, 1e-2, 0.3, 1.5], "critical_junction": [1e-6, 1e-2, 0.2, 0.39],
           "emt": [1e-6, 0.1, 0.38]}
KNOBS = [(3, 2.0), (4, 2.0), (6, 1.0), (8, 1.0), (10, 1.0), (16, 0.5), (20, 0.25)]


from machine_info import cpu_model  # noqa: E402  (bench/ is on sys.path when run)


def machine():
    model = cpu_model()
    import numba
    return {"cpu": model, "cores": os.cpu_count(), "numba_threads": numba.get_num_threads(),
            "loadavg_start": os.getloadavg(),
            "python": platform.python_version(), "numpy": np.__version__,
            "numba": numba.__version__}


def timed(fn, repeats):
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), ts


def kernel_timer():
    """Wrap the two kernels to time them alone (the wrapper is removed afterwards)."""
    rec = []
    orig = {k: getattr(sq, k) for k in ("_fast_kernel", "_quad_kernel")}

    def wrap(f):
        def w(*a):
            t = time.perf_counter()
            r = f(*a)
            rec.append(time.perf_counter() - t)
            return r
        return w

    for k, f in orig.items():
        setattr(sq, k, wrap(f))
    return rec, orig


def baseline_case(T, theory, pi0):
    """t* by solve_ivp with an event, Python callables on the tables (reduced units t̃)."""
    from scipy.integrate import solve_ivp

    h = T.h_rms
    u_inf = np.ravel(T.mean_separation(pi0 * E, E))[0] / h
    u_s = np.ravel(T.mean_separation(1e-3 * pi0 * E, E))[0] / h

    def rhs(t, y):
        u = y[0]
        p = np.ravel(T.contact_pressure(u * h, E))[0] / E
        s = np.ravel(T.sigma_bar(p * E, E, theory))[0]
        return [-s * (1.0 - p / pi0)]

    def ev(t, y):
        return y[0] - 1.01 * u_inf
    ev.terminal = True
    ev.direction = -1
    t_end = 1e30
    sol = solve_ivp(rhs, (0.0, t_end), [u_s], method="LSODA", events=ev, rtol=1e-10,
                    atol=1e-12 * u_inf)
    return float(sol.t_events[0][0]) if sol.t_events[0].size else math.inf


def compile_seconds():
    """First-call time in a fresh process with an empty numba cache, and the warm call."""
    code = textwrap.dedent(f"""
        import time, pickle, sys
        sys.path.insert(0, {str(ROOT)!r})
        T = pickle.load(open(sys.argv[1], 'rb'))
        from fastcontact.squeeze import squeeze_out, squeeze_model
        for th in T.theories:
            squeeze_model(T, th)._fast_nodes()  # not timed below: set-up, measured apart
        t = time.perf_counter()
        squeeze_out(T, p0=1e3, E_star=1e7, R=0.01, eta=1e-3, method='quad')
        t1 = time.perf_counter() - t
        t = time.perf_counter()
        squeeze_out(T, p0=1e3, E_star=1e7, R=0.01, eta=1e-3, method='fast')
        t2 = time.perf_counter() - t
        t = time.perf_counter()
        squeeze_out(T, p0=1e3, E_star=1e7, R=0.01, eta=1e-3, method='fast')
        squeeze_out(T, p0=1e3, E_star=1e7, R=0.01, eta=1e-3, method='quad')
        t3 = time.perf_counter() - t
        print(t1, t2, t3)
    """)
    return code


def main(quick=False):
    info = machine()
    print(info, flush=True)
    psd = fastcontact.SelfAffinePSD(**SURFACE)
    t = time.perf_counter()
    T = precompute(psd, tolerance=TIGHT)
    t_tables = time.perf_counter() - t
    # -- compile time (fresh process, empty numba cache; set-up excluded)
    import pickle
    with tempfile.TemporaryDirectory() as tmp:
        pk = Path(tmp) / "T.pkl"
        pickle.dump(T, open(pk, "wb"))
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        # warm the *tables* kernels' cache in that dir first, so only squeeze compiles count
        warm = ("import pickle,sys; T=pickle.load(open(sys.argv[1],'rb')); "
                "T.sigma_bar(1e3,1e7,'average'); T.mean_separation(1e3,1e7); "
                "T.contact_pressure(1e-5,1e7)")
        subprocess.run([sys.executable, "-c", warm, str(pk)], env=env, check=True)
        out = subprocess.run([sys.executable, "-c", compile_seconds(), str(pk)], env=env,
                             capture_output=True, text=True, check=True).stdout.split()
        t_quad_first, t_fast_first, t_warm = (float(x) for x in out)
    compile_s = t_quad_first + t_fast_first - t_warm
    print("compile", compile_s, flush=True)
    # -- set-up of the fast path (per theory, default targets)
    setup = {}
    for th in T.theories:
        t = time.perf_counter()
        m = squeeze_model(T, th)
        m._fast_nodes()
        for r in (1.1, 1.001):
            m.target_coef("ratio", r)
        setup[th] = (time.perf_counter() - t, m._fast["xn"].size)
    # -- reference
    ref = {}
    t = time.perf_counter()
    for th, pis in REF_PIS.items():
        for pi in (pis[:2] if quick else pis):
            ref[(th, pi)] = SqueezeReference(psd, E, th, pi * E).t_ratio(1.01)
    t_ref = time.perf_counter() - t
    print("reference", t_ref, flush=True)

    def err_of(method, **kw):
        e = {th: 0.0 for th in T.theories}
        for (th, pi), want in ref.items():
            df = squeeze_out(T, p0=pi * E, E_star=E, R=R, eta=ETA, theory=th, method=method, **kw)
            got = df["t_star"].iloc[0] / tau0(ETA, R, T.h_rms, pi * E)
            e[th] = max(e[th], abs(got / want - 1.0))
        return e

    rng = np.random.default_rng(0)
    n_fast = 2_000_000
    n_quad = 2_000 if quick else 5_000
    reps = 3 if quick else 5
    rows = []
    rec, orig = kernel_timer()
    try:
        for th in T.theories:
            m = squeeze_model(T, th)
            top = min(math.exp(m.x_trap), T.p_range[1]) * 0.999
            for label, method, kw, n in ([("fast", "fast", {}, n_fast)]
                                         + [(f"quad GL{o} w={w:g}", "quad",
                                             dict(quad_order=o, quad_width=w), n_quad)
                                            for o, w in KNOBS]):
                pis = np.exp(rng.uniform(math.log(1e-9), math.log(top), n))
                Rs = rng.uniform(1e-3, 1.0, n)
                etas = 10 ** rng.uniform(-4, 3, n)
                call = lambda: squeeze_out(T, p0=pis * E, E_star=E, R=Rs, eta=etas, theory=th,  # noqa: E731
                                           method=method, **kw)
                call()
                rec.clear()
                med, _ = timed(call, reps)
                kmed = float(np.median(rec))
                err = err_of(method, **kw)[th]
                rows.append(dict(theory=th, knob=label, n=n, ns_case=med / n * 1e9,
                                 kernel_ns_case=kmed / n * 1e9, err=err))
                print(rows[-1], flush=True)
    finally:
        for k, f in orig.items():
            setattr(sq, k, f)
    # -- baseline
    base = {}
    for th in T.theories:
        pis = REF_PIS[th][:2] if quick else REF_PIS[th][:3]
        ts, errs = [], []
        for pi in pis:
            t = time.perf_counter()
            tb = baseline_case(T, th, pi)
            ts.append(time.perf_counter() - t)
            want = ref.get((th, pi))
            if want is None:
                want = SqueezeReference(psd, E, th, pi * E).t_ratio(1.01)
            errs.append(abs(tb / want - 1.0))
        base[th] = dict(ns_case=float(np.median(ts)) * 1e9, err=float(max(errs)), n=len(pis))
        print("baseline", th, base[th], flush=True)
    info["loadavg_end"] = os.getloadavg()
    write(info, T, t_tables, compile_s, setup, t_ref, rows, base, quick)


def write(info, T, t_tables, compile_s, setup, t_ref, rows, base, quick):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 5.0))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(111)
    colors = {"average": "tab:blue", "critical_junction": "tab:red", "emt": "tab:green"}
    for th in T.theories:
        rs = [r for r in rows if r["theory"] == th]
        x = [r["ns_case"] for r in rs]
        y = [max(r["err"], 1e-16) for r in rs]
        ax.plot(x[1:], y[1:], "o-", color=colors[th], label=f"{th}: quad knobs (GL order, width)")
        ax.plot(x[:1], y[:1], "*", ms=16, color=colors[th], label=f"{th}: fast (spline)")
        for r in (rs[1:] if th == "average" else []):
            ax.annotate(r["knob"].replace("quad ", ""), (r["ns_case"], max(r["err"], 1e-16)),
                        fontsize=6, color=colors[th], xytext=(3, 3), textcoords="offset points")
        b = base[th]
        ax.plot([b["ns_case"]], [max(b["err"], 1e-16)], "s", ms=9, mfc="none", color=colors[th],
                label=f"{th}: solve_ivp LSODA baseline")
    ax.axhline(1e-6, color="k", ls=":", lw=1)
    ax.text(ax.get_xlim()[0] if False else 30, 1.3e-6, "target 1e-6", fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per case [ns] (end-to-end squeeze_out, median; 2 threads)")
    ax.set_ylabel("max relative error of t* vs direct-core reference")
    ax.set_title("fastcontact.squeeze: accuracy vs cost (default ratios 1.1/1.01/1.001)",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6.5, loc="upper right")
    fig.tight_layout()
    png = HERE / "squeeze_error_vs_time.png"
    tmp = png.with_name(".squeeze_error_vs_time.png.tmp")
    fig.savefig(tmp, format="png", dpi=130)
    os.replace(tmp, png)

    lines = [
        "## Squeeze-out (issue #4) — `bench/bench_squeeze.py`" + (" (--quick)" if quick else ""),
        "",
        f"Machine: {info['cpu']}, {info['cores']} cores, numba threads {info['numba_threads']}; "
        f"Python {info['python']}, numpy {info['numpy']}, numba {info['numba']}. Shared/noisy "
        "machine: medians of repeats; ratios measured in the same run. Load average "
        f"(1/5/15 min) at start {tuple(round(x, 2) for x in info['loadavg_start'])}, at end "
        f"{tuple(round(x, 2) for x in info['loadavg_end'])} (2 cores: > 2 means other "
        "processes competed for them).",
        "",
        f"Surface {SURFACE}, tables with the default tolerances {T.info['tolerance']} ({T.info['nodes']} nodes, built in "
        f"{t_tables:.1f} s). Reference: direct core + scipy quad ({len(REF_PIS)} theories, "
        f"{t_ref:.0f} s in total).",
        "",
        f"Compile time (fresh process, empty numba cache, both kernels): **{compile_s:.1f} s** "
        "(once per machine; cached on disk afterwards).",
        "",
        "Fast-path set-up per theory (spline nodes + 3 ratio targets, once per tables × "
        "theory × target, cached): "
        + ", ".join(f"{th} {s:.2f} s ({n} nodes)" for th, (s, n) in setup.items()) + ".",
        "",
        "| theory | knob | cases | end-to-end ns/case | kernel ns/case | cases/s (end-to-end) | max rel. err t* | × baseline (cases/s) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        b = base[r["theory"]]
        lines.append(f"| {r['theory']} | {r['knob']} | {r['n']:,} | {r['ns_case']:.1f} | "
                     f"{r['kernel_ns_case']:.1f} | {1e9 / r['ns_case']:.3g} | {r['err']:.1e} | "
                     f"{b['ns_case'] / r['ns_case']:.3g} |")
    for th, b in base.items():
        lines.append(f"| {th} | solve_ivp LSODA + event (baseline, Python callables on tables) | "
                     f"{b['n']} | {b['ns_case']:.3g} | – | {1e9 / b['ns_case']:.3g} | "
                     f"{b['err']:.1e} | 1 |")
    lines += ["", "![t* error vs cost](squeeze_error_vs_time.png)", ""]
    (HERE / "squeeze_results.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
