"""Benchmark of fastcontact.squeeze (issue 11): error against run time for every path, each
against baselines measured in the same run.

Writes ``bench/squeeze_results.md``. Run: ``python bench/bench_squeeze.py [--quick]``.

Paths (embedded road tables ``asphalt_024mm``, three theories):

* ``default start``: ratio targets from the default start (p_cont = 1e-3 p0);
* ``given start``: per-case ``u_start`` and a Δu target;
* ``times``: ū at three times from per-case starts;
* ``given start, Δu, one time``: per-case starts, a Δu target and ū at one time (the issue's
  "per-case u_start, du and times" with a single time: one inversion per case);
* ``tire``: ``tire_footprint`` with every column, distinct pressures, speeds and footprint
  lengths (ū at each case's own exit time); its error also covers a reference case inside a
  batch that shares its start (the start's T from the per-call row table);
* ``tire, exit columns``: the same cases asking only for the exit columns (EXIT_COLUMNS);
* ``history``: ``squeeze_history`` of one case at 1e6 times.

Each path runs with ``method="fast"`` (the time primitive), ``method="quad"`` (per-case
quadrature, the previous accurate engine) and, for the default start, ``scipy.integrate.
solve_ivp`` (LSODA with a terminal event, Python callables on the tables). Error: max relative
error of times (and of ū - ū∞) against the independent direct-core reference
(``tests/reference/squeeze_reference.py``: scipy quad + brentq, no tables) on a few cases.
Speed: median wall time of several repeats. First call on new tables: primitive build on a
freshly loaded Tables object (kernels compiled), median of repeats.
"""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(HERE))

from fastcontact._core.vocab import column_name  # noqa: E402
from fastcontact.squeeze import primitive as prim  # noqa: E402
from fastcontact.squeeze import squeeze_history, squeeze_model, squeeze_out  # noqa: E402
from fastcontact.tables import Tables  # noqa: E402
from fastcontact.tables.defaults import default_table_path  # noqa: E402
from fastcontact.tire import tire_footprint  # noqa: E402
from machine_info import cpu_model  # noqa: E402
from results_notes import write_keeping_notes  # noqa: E402
from reference.squeeze_reference import SqueezeReference, tau0  # noqa: E402

SURFACE = "asphalt_024mm"
E, ETA, R = 13e6, 1e-3, 0.02
#: the columns of a study that only asks whether the film has drained at the footprint exit
EXIT_COLUMNS = ("u_exit", "du_exit", "squeeze_complete", "status")
#: footprint pressures [Pa] of the "tire, tire pressures" row (log-uniform): 0.02–1 MPa
TIRE_P0 = (2e4, 1e6)
REF_P0 = {"average": [2e3, 0.2e6], "critical_junction": [0.2e6], "emt": [0.2e6]}


def timed(fn, repeats):
    """Median wall time [s] of ``repeats`` calls after one untimed call (the first call of a
    path in a process pays its output arrays' fresh pages; bench/alloc_results.md)."""
    fn()
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def ivp_t_star(T, theory, p0):
    """t* [τ0] by solve_ivp with an event, Python callables on the tables (baseline)."""
    from scipy.integrate import solve_ivp

    h = T.h_rms
    pi0 = p0 / E
    u_inf = float(np.ravel(T.mean_separation(p0, E))[0]) / h
    u_s = float(np.ravel(T.mean_separation(1e-3 * p0, E))[0]) / h

    def rhs(t, y):
        p = float(np.ravel(T.contact_pressure(y[0] * h, E))[0]) / E
        return [-float(np.ravel(T.sigma_bar(p * E, E, theory))[0]) * (1.0 - p / pi0)]

    def ev(t, y):
        return y[0] - 1.01 * u_inf
    ev.terminal = True
    ev.direction = -1
    sol = solve_ivp(rhs, (0.0, 1e30), [u_s], method="LSODA", events=ev, rtol=1e-10,
                    atol=1e-12 * u_inf)
    return float(sol.t_events[0][0]) if sol.t_events[0].size else math.inf


def references(T):
    """Per theory: list of (p0, ref, v_start, t* default, t* given start, ū-ū∞ at t)."""
    out = {}
    h = T.h_rms
    for th, p0s in REF_P0.items():
        rows = []
        for p0 in p0s:
            ref = SqueezeReference(T.surface, E, th, p0)
            vs = 3.0 * ref.v_inf
            t_def = ref.t_ratio(1.01)
            t_giv = ref.t_ratio(1.01, v_start=vs)
            t_at = 0.5 * t_giv
            dv_at = ref.v_at(t_at, v_start=vs) - ref.v_inf
            # a start 10 ū∞ shared by a batch (the tire's row-table start, z = ln 9 >= ZV_ROW)
            t_sh = 0.5 * ref.t_ratio(1.01, v_start=10.0 * ref.v_inf)
            dv_sh = ref.v_at(t_sh, v_start=10.0 * ref.v_inf) - ref.v_inf
            rows.append(dict(p0=p0, vs=vs * h, t_def=t_def, t_giv=t_giv, t_at=t_at,
                             dv_at=dv_at, v_inf=ref.v_inf, t_sh=t_sh, dv_sh=dv_sh))
        out[th] = rows
    return out


def path_errors(T, th, refs, method):
    """Max relative errors (default start, given start, times, tire exit) vs the reference."""
    h = T.h_rms
    e = {"default": 0.0, "given": 0.0, "times": 0.0, "tire": 0.0, "tire_exit": 0.0,
         "given_du_time": 0.0}
    for r in refs:
        tau = tau0(ETA, R, h, r["p0"])
        d = squeeze_out(T, p0=r["p0"], E_star=E, R=R, eta=ETA, theory=th, method=method)
        e["default"] = max(e["default"], abs(d["t_star"].iloc[0] / tau / r["t_def"] - 1))
        t_at = r["t_at"] * tau
        g = squeeze_out(T, p0=r["p0"], E_star=E, R=R, eta=ETA, theory=th, u_start=r["vs"],
                        times=(t_at,), method=method)
        e["given"] = max(e["given"], abs(g["t_star"].iloc[0] / tau / r["t_giv"] - 1))
        dv = (g[column_name("u_at", t_at)].iloc[0] - g["u_inf"].iloc[0]) / h
        e["times"] = max(e["times"], abs(dv / r["dv_at"] - 1))
        # Δu target and one time in one call: t to ū∞ + 0.01 ū∞ (= t_star) and ū at t_at
        dv_t = 0.01 * r["v_inf"] * h
        g = squeeze_out(T, p0=r["p0"], E_star=E, R=R, eta=ETA, theory=th, u_start=r["vs"],
                        ratios=(), du=(dv_t,), times=(t_at,), method=method)
        dv = (g[column_name("u_at", t_at)].iloc[0] - g["u_inf"].iloc[0]) / h
        e["given_du_time"] = max(e["given_du_time"], abs(dv / r["dv_at"] - 1),
                                 abs(g[column_name("t_du", dv_t)].iloc[0] / tau / r["t_giv"] - 1))
        for key, cols in (("tire", None), ("tire_exit", list(EXIT_COLUMNS) + ["u_inf"])):
            f = tire_footprint(T, p0=r["p0"], E_star=E, R=R, eta=ETA, theory=th,
                               footprint_length=t_at, speed=1.0, u_start=r["vs"],
                               method=method, columns=cols)
            dv = (f["u_exit"].iloc[0] - f["u_inf"].iloc[0]) / h
            e[key] = max(e[key], abs(dv / r["dv_at"] - 1))
            # the reference case inside a batch that shares its start (row-table start)
            p0s = r["p0"] * np.array([1.0, 0.9, 1.1])
            f = tire_footprint(T, p0=p0s, E_star=E, R=R, eta=ETA, theory=th,
                               footprint_length=r["t_sh"] * tau, speed=1.0,
                               u_start=10.0 * r["v_inf"] * h, method=method, columns=cols)
            dv = (f["u_exit"].iloc[0] - f["u_inf"].iloc[0]) / h
            e[key] = max(e[key], abs(dv / r["dv_sh"] - 1))
    return e


def speeds(T, th, n_fast, n_quad, repeats):
    """cases/s (points/s for history) per path and method."""
    rng = np.random.default_rng(0)
    m = squeeze_model(T, th)
    top = min(math.exp(prim.fast_limit(m)), T.p_range[1]) * E
    lo = T.p_range[0] * E * 1.001
    res = {}
    for method, n in (("fast", n_fast), ("quad", n_quad)):
        p0 = np.exp(rng.uniform(math.log(lo), math.log(top), n))
        Rr = rng.uniform(0.005, 0.03, n)
        base = squeeze_out(T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th, ratios=())
        us = base["u_inf"].to_numpy() * np.exp(rng.uniform(0.1, 5.0, n))
        fl, sp = rng.uniform(0.05, 0.2, n), rng.uniform(5.0, 40.0, n)
        jobs = {
            "default start": lambda: squeeze_out(T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th,
                                                 method=method),
            "given start": lambda: squeeze_out(T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th,
                                               u_start=us, du=(1e-6,), method=method),
            "times": lambda: squeeze_out(T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th,
                                         u_start=us, ratios=(), times=(1e-5, 1e-3, 1e-1),
                                         method=method),
            "given start, Δu, one time": lambda: squeeze_out(
                T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th, u_start=us, ratios=(),
                du=(1e-6,), times=(1e-3,), method=method),
            "tire": lambda: tire_footprint(T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th,
                                           footprint_length=fl, speed=sp, method=method),
            "tire, exit columns": lambda: tire_footprint(
                T, p0=p0, E_star=E, R=Rr, eta=ETA, theory=th, footprint_length=fl, speed=sp,
                method=method, columns=list(EXIT_COLUMNS)),
        }
        # a tire study's own pressures (TIRE_P0: footprint pressures of car and truck tires)
        p0t = np.exp(rng.uniform(math.log(max(lo, TIRE_P0[0])), math.log(min(top, TIRE_P0[1])),
                                 n))
        jobs["tire, tire pressures"] = lambda: tire_footprint(
            T, p0=p0t, E_star=E, R=Rr, eta=ETA, theory=th, footprint_length=fl, speed=sp,
            method=method)
        for name, job in jobs.items():
            res[(name, method)] = n / timed(job, repeats)
        t = np.geomspace(1e-7, 1e2, n)
        if method == "fast":
            res[("history", method)] = n / timed(
                lambda: squeeze_history(T, 2e5, E, R, ETA, th, t=t), repeats)
        else:
            res[("history", method)] = n / timed(
                lambda: squeeze_out(T, p0=2e5, E_star=E, R=R, eta=ETA, theory=th, ratios=(),
                                    times=t, method="quad"), repeats)
    return res


def first_call(th, repeats):
    """Seconds of the first squeeze_out on freshly loaded tables (primitive build)."""
    ts = []
    for _ in range(repeats):
        T = Tables.from_parquet(default_table_path(SURFACE))
        t0 = time.perf_counter()
        squeeze_out(T, p0=1e5, E_star=E, R=R, eta=ETA, theory=th)
        ts.append(time.perf_counter() - t0)
    info = prim.build(squeeze_model(T, th), check=True)[1]
    return float(np.median(ts)), info


def main(quick=False):
    T = Tables.from_parquet(default_table_path(SURFACE))
    n_fast, n_quad, rep = (100_000, 500, 2) if quick else (1_000_000, 2_000, 5)
    for th in REF_P0:  # compile and build (not timed)
        squeeze_out(T, p0=1e5, E_star=E, R=R, eta=ETA, theory=th, times=(1.0,), du=(1e-6,))
        tire_footprint(T, p0=2e5, E_star=E, R=R, eta=ETA, theory=th, footprint_length=0.1,
                       speed=30.0)
    load0 = os.getloadavg()
    t0 = time.perf_counter()
    refs = references(T)
    t_ref = time.perf_counter() - t0
    rows = {}
    for th in REF_P0:
        rows[th] = {"err_fast": path_errors(T, th, refs[th], "fast"),
                    "err_quad": path_errors(T, th, refs[th], "quad"),
                    "speed": speeds(T, th, n_fast, n_quad, rep),
                    "first": first_call(th, rep)}
        t0 = time.perf_counter()
        ivp = [ivp_t_star(T, th, r["p0"]) for r in refs[th][:2]]
        rows[th]["ivp_rate"] = len(ivp) / (time.perf_counter() - t0)
        rows[th]["ivp_err"] = max(abs(a / r["t_def"] - 1) for a, r in zip(ivp, refs[th]))
    write(rows, t_ref, load0, os.getloadavg(), n_fast, n_quad)


def write(rows, t_ref, load0, load1, n_fast, n_quad):
    import numba
    L = ["## Squeeze-out (issue 11) — `bench/bench_squeeze.py`", "",
         f"Machine: {cpu_model()}, {os.cpu_count()} cores, numba threads "
         f"{numba.get_num_threads()}. Load average at start {tuple(round(x, 2) for x in load0)}, "
         f"at end {tuple(round(x, 2) for x in load1)} (2 cores: > 2 means other processes "
         f"competed; every ratio below is measured in the same run).", "",
         f"Tables: embedded `{SURFACE}`. Reference: direct core + scipy quad/brentq, no tables "
         f"({t_ref:.0f} s). Cases: {n_fast:,} (fast) and {n_quad:,} (quad) with log-uniform "
         f"p0 over the table, R random, per-case starts 1.1–150 ū∞; tire: distinct pressures, "
         f"speeds and footprint lengths; history: one case at {n_fast:,} times.", "",
         "| theory | path | fast: cases/s | fast: max rel. err | quad: cases/s | quad: max rel. err | fast / quad speed |",
         "|---|---|---|---|---|---|---|"]
    emap = {"default start": "default", "given start": "given", "times": "times", "tire": "tire",
            "tire, exit columns": "tire_exit", "history": "times", "tire, tire pressures": "tire",
            "given start, Δu, one time": "given_du_time"}
    for th, r in rows.items():
        for path in ("default start", "given start", "times", "given start, Δu, one time",
                     "tire", "tire, exit columns", "tire, tire pressures", "history"):
            f, q = r["speed"][(path, "fast")], r["speed"][(path, "quad")]
            L.append(f"| {th} | {path} | {f:.3g} | {r['err_fast'][emap[path]]:.1e} | {q:.3g} | "
                     f"{r['err_quad'][emap[path]]:.1e} | {f / q:.3g} |")
        L.append(f"| {th} | default start, solve_ivp LSODA (baseline) | – | – | "
                 f"{r['ivp_rate']:.3g} | {r['ivp_err']:.1e} | "
                 f"{r['speed'][('default start', 'fast')] / r['ivp_rate']:.3g} |")
    L += ["", "Errors: t* (default and given start), ū - ū∞ at a time (times, history) and at "
          "the footprint exit (tire) against the reference; \"given start, Δu, one time\": "
          "the worse of t to ū∞ + 0.01 ū∞ (a Δu target) and ū - ū∞ at a time, in one call "
          "(its speed: a Δu target of 1 µm and ū at 1 ms per case). \"tire, exit columns\": "
          f"`tire_footprint(columns={list(EXIT_COLUMNS)})`, which computes only ū at the exit "
          "(no ratio or Δu targets), its error measured on that call. \"tire, tire "
          f"pressures\": the tire call with p0 log-uniform in {TIRE_P0[0]:.0e}–{TIRE_P0[1]:.0e} Pa "
          "(the footprint pressures of a tire study; the rows above span the whole table, where "
          "at low p0 the film has not drained at the exit and ū there costs a second "
          "inversion), its error the tire row's (same engine and reference cases). History cases/s are "
          "(case × time) "
          "points/s; its quad baseline is `squeeze_out(method='quad', times=...)`.", "",
          "First call on newly loaded tables (kernels compiled; builds the time primitive), "
          "median of repeats, and the primitive's measured interpolation error:", "",
          "| theory | first call [ms] | rows × z nodes | max rel. err of T at cell centres |",
          "|---|---|---|---|"]
    for th, r in rows.items():
        s, info = r["first"]
        err = info.get("max_rel_err_T", float("nan"))
        L.append(f"| {th} | {1e3 * s:.0f} | {info['nx']} × {info['nz']} | {err:.1e} |")
    L.append("")
    write_keeping_notes(HERE / "squeeze_results.md", "\n".join(L) + "\n")
    print("\n".join(L))


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
