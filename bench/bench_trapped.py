"""Benchmark of the trapped rows of squeeze-out (issue 11.1): error against run time of the
trapped side's time primitive, against the per-case quadrature measured in the same run.

Writes ``bench/trapped_results.md``. Run: ``python bench/bench_trapped.py [--quick]``.

Cases: p0 log-uniform in ln(p0/E*) - ln π_trap from 2e-8 to the tables' top, per-case starts
1.3–40 ū_trap, ratio targets 1.5 and 3, a Δu target, ū at one time. Error: max relative
error of the times to targets above ū_trap and of t_trap against the independent quadrature
of ``tests/reference/trapped_reference.py`` (panels broken at the tables' nodes). Speed: median
wall time of repeats (the primitive built before, and its build, its build with the error
check, and the first call of a 1,000-case trapped study on newly read tables timed separately).
A second table: the cases just below the trap pressure that the equilibrium side's primitive
serves since 2026-12-07 (before: the per-case quadrature), against the same run's quadrature
and the independent quadrature of the same tables.
"""
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))

from fastcontact._core.vocab import column_name  # noqa: E402
from fastcontact.squeeze import _trap_primitive as tpm  # noqa: E402
from fastcontact.squeeze import primitive as prim  # noqa: E402
from fastcontact.squeeze import squeeze_model, squeeze_out  # noqa: E402
from fastcontact.tables import Tables  # noqa: E402
from fastcontact.tables.defaults import default_table_path  # noqa: E402
from machine_info import cpu_model  # noqa: E402
from reference.trapped_reference import BelowTrapReference, TrappedReference  # noqa: E402
from results_notes import write_keeping_notes  # noqa: E402

SURFACES = ("asphalt_024mm", "asphalt_072mm")
THEORIES = ("critical_junction", "emt")
E, ETA, R = 1e7, 1e-3, 0.01


def cases(m, n, seed):
    rng = np.random.default_rng(seed)
    x0 = m.x_trap + np.exp(rng.uniform(math.log(2e-8), math.log(m.x_max - m.x_trap), n))
    vs = m.mp.v_trap * rng.uniform(1.3, 40.0, n)
    return dict(p0=np.exp(x0) * E, E_star=E, R=rng.uniform(0.005, 0.02, n), eta=ETA,
                theory=m.theory, u_start=vs * m.h_rms, ratios=(1.5, 3.0),
                du=(0.3 * m.mp.v_trap * m.h_rms,), times=(1e-3,))


def errors(T, m, method, n=10):
    """Max relative error of the finite times (targets above ū_trap) and of t_trap."""
    ref = TrappedReference(m)
    kw = cases(m, n, 11)
    df = squeeze_out(T, method=method, **kw)
    h = m.h_rms
    e_t = e_trap = 0.0
    for i in range(n):
        tau = df["tau0"].iloc[i]
        x0 = math.log(kw["p0"][i] / E)
        vs = kw["u_start"][i] / h
        vinf = df["u_inf"].iloc[i] / h
        for col, vt in (("t_ratio_1.5", 1.5 * vinf), ("t_ratio_3", 3.0 * vinf),
                        (column_name("t_du", kw["du"][0]), vinf + kw["du"][0] / h)):
            if m.mp.v_trap < vt < vs:
                e_t = max(e_t, abs(df[col].iloc[i] / tau / ref.time(x0, vs, vt) - 1.0))
        e_trap = max(e_trap, abs(df["t_trap"].iloc[i] / tau / ref.t_trap(x0, vs) - 1.0))
    return e_t, e_trap


#: the band below the trap pressure that the time primitive serves since 2026-12-07: from
#: OLD_MARGIN below min(trap pressure, tables' kink) (the fast path's limit before) to its limit
OLD_MARGIN = 0.045


def below_cases(m, n, seed):
    """Cases log-uniform in ln p0 over the band below the trap pressure that the primitive now
    serves (before 2026-12-07: the per-case quadrature), per-case starts 1.1–40 ū∞ (from a
    base call), ratio targets 1.01 and 1.001, ū at two times."""
    rng = np.random.default_rng(seed)
    top = min(m.x_trap, float(m.tab.lnp[int(m.tab.n_open) - 1]))
    x0 = rng.uniform(top - OLD_MARGIN, prim.fast_limit(m), n)
    return dict(p0=np.exp(x0) * E, E_star=E, R=rng.uniform(0.005, 0.02, n), eta=ETA,
                theory=m.theory, ratios=(1.01, 1.001), times=(1e6, 1e9))


def below_errors(T, m, method, n=10):
    """Max relative error of t*, t_ratio_1.001 and (as time, in t_relax) ū at t* + 2 t_relax
    on n cases of :func:`below_cases`, against the independent quadrature of the same tables
    (`tests/reference/trapped_reference.py`, BelowTrapReference)."""
    kw = below_cases(m, n, 13)
    df = squeeze_out(T, method=method, **kw)
    e_t = e_u = 0.0
    for i in range(n):
        p0 = kw["p0"][i]
        x0 = math.log(p0 / E)
        ref = BelowTrapReference(m, x0)
        row = df.iloc[i]
        tau = row["tau0"]
        e_t = max(e_t, abs(row["t_star"] / tau / ref.time(0.01 * ref.v_inf) - 1.0),
                  abs(row["t_ratio_1.001"] / tau / ref.time(1e-3 * ref.v_inf) - 1.0))
        t = row["t_star"] + 2.0 * row["t_relax"]
        one = squeeze_out(T, method=method, **{**kw, "p0": p0, "R": kw["R"][i],
                                               "times": (t,)}).iloc[0]
        dv = one[column_name("u_at", t)] / m.h_rms - ref.v_inf
        e_u = max(e_u, abs(tau * ref.time(dv) - t) / row["t_relax"])
    return e_t, e_u


def rate(T, kw, repeats):
    squeeze_out(T, **{k: v[:64] if isinstance(v, np.ndarray) else v for k, v in kw.items()})
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        squeeze_out(T, **kw)
        ts.append(time.perf_counter() - t0)
    return kw["p0"].size / float(np.median(ts))


def build_time(name, theory, repeats):
    """Medians of: the build alone, the build with its error check, and the first call of a
    1,000-case trapped study on newly read tables (the model's lazy build included)."""
    tb, tc, tf = [], [], []
    for _ in range(repeats):
        m = squeeze_model(Tables.from_parquet(default_table_path(name)), theory)
        t0 = time.perf_counter()
        tpm.build(m, check=False)
        t1 = time.perf_counter()
        tp, info = tpm.build(m, check=True)
        t2 = time.perf_counter()
        tb.append(t1 - t0)
        tc.append(t2 - t1)
        T = Tables.from_parquet(default_table_path(name))
        kw = cases(squeeze_model(T, theory), 1_000, 5)
        t0 = time.perf_counter()
        squeeze_out(T, **kw)
        tf.append(time.perf_counter() - t0)
    return float(np.median(tb)), float(np.median(tc)), float(np.median(tf)), info


def history(T, m, n_t, n_quad, repeats):
    """(points/s of squeeze_history, points/s of the per-case quadrature it replaced, max
    relative time error of its ū against the forward reference) for one trapped case."""
    from fastcontact.squeeze import squeeze_history
    from fastcontact.squeeze._kernels import state_gap
    from fastcontact.squeeze.api import _cases, _check_method, run_cases

    h, vb = m.h_rms, m.mp.v_trap
    x0 = m.x_trap + 0.2
    p0, us = math.exp(x0) * E, 25.0 * vb * h
    t = np.geomspace(1e-9, 1e3, n_t)
    squeeze_history(T, p0, E, R, ETA, m.theory, t=t[:64], u_start=us)
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        hist = squeeze_history(T, p0, E, R, ETA, m.theory, t=t, u_start=us)
        ts.append(time.perf_counter() - t0)
    # the route it replaced: one case's ū at sorted times by the per-case quadrature
    quad, _ = _check_method("quad", 16, 0.5, None)
    cs = _cases(p0, E, R, ETA, us)
    tq = np.ascontiguousarray(t[:: max(n_t // n_quad, 1)][:, None])
    tqs = []
    for _ in range(max(2, repeats - 2)):
        t0 = time.perf_counter()
        run_cases(m, cs, np.zeros(0), np.zeros(0), tq, "quad", quad)
        tqs.append(time.perf_counter() - t0)
    ref = TrappedReference(m)
    tau = hist.attrs["tau0"]
    u = hist["u"].to_numpy() / h
    err = 0.0
    for k in np.linspace(0, n_t - 1, 25).astype(int):
        if u[k] - vb < 1e-8 * vb or u[k] == us / h:
            continue
        dt = ref.time(x0, us / h, u[k]) - t[k] / tau
        sig, d = state_gap(m.tab, m.mp, x0, vb, u[k] - vb)
        # as a time error, or (where ū is that close to the floor) as ū's distance over ū - ū_trap
        err = max(err, min(abs(dt) / (t[k] / tau), abs(dt) * sig * d / (u[k] - vb)))
    return n_t / float(np.median(ts)), tq.shape[0] / float(np.median(tqs)), err


def main(quick=False):
    import numba

    n_fast, n_quad, rep = (50_000, 200, 2) if quick else (400_000, 1_000, 5)
    n_hist = 100_000 if quick else 1_000_000
    load0 = os.getloadavg()
    rows, hrows, brows = [], [], []
    for name in SURFACES:
        T = Tables.from_parquet(default_table_path(name))
        for th in THEORIES:
            m = squeeze_model(T, th)
            m.trap_primitive()
            kw = cases(m, n_fast, 3)
            kq = {**kw, "p0": kw["p0"][:n_quad], "R": kw["R"][:n_quad],
                  "u_start": kw["u_start"][:n_quad], "method": "quad"}
            f, q = rate(T, kw, rep), rate(T, kq, max(2, rep - 2))
            ef, eq = errors(T, m, "fast"), errors(T, m, "quad")
            b, bc, first, info = build_time(name, th, rep)
            rows.append((name, th, f, q, ef, eq, b, bc, first, info))
            hrows.append((name, th) + history(T, m, n_hist, n_quad, rep))
            kb = below_cases(m, n_fast, 7)
            kbq = {**kb, "p0": kb["p0"][:n_quad], "R": kb["R"][:n_quad], "method": "quad"}
            brows.append((name, th, rate(T, kb, rep), rate(T, kbq, max(2, rep - 2)),
                          below_errors(T, m, "fast"), below_errors(T, m, "quad")))
    load1 = os.getloadavg()
    L = ["## Trapped rows of squeeze-out (issue 11.1) — `bench/bench_trapped.py`", "",
         f"Machine: {cpu_model()}, {os.cpu_count()} cores, numba threads "
         f"{numba.get_num_threads()}. Load average at start {tuple(round(x, 2) for x in load0)}, "
         f"at end {tuple(round(x, 2) for x in load1)}.", "",
         f"Cases: {n_fast:,} (fast) and {n_quad:,} (quad) trapped cases, ln(p0/E*) - ln π_trap "
         "log-uniform from 2e-8 to the tables' top, per-case starts 1.3–40 ū_trap, targets "
         "1.5 ū∞, 3 ū∞, ū∞ + 0.3 ū_trap and ū at 1 ms. Errors against the independent "
         "quadrature of `tests/reference/trapped_reference.py` on 10 cases: times to targets "
         "above ū_trap, and t_trap.", "",
         "| tables | theory | fast: cases/s | quad: cases/s | fast / quad | fast: err t | "
         "fast: err t_trap | quad: err t | quad: err t_trap | build [ms] | build + error check "
         "[ms] | first call, 1,000 cases on new tables [ms] | rows × z nodes "
         "(lower + upper) | max rel. err of T at cell centres |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, th, f, q, ef, eq, b, bc, first, info in rows:
        L.append(f"| {name} | {th} | {f:.3g} | {q:.3g} | {f / q:.3g} | {ef[0]:.1e} | "
                 f"{ef[1]:.1e} | {eq[0]:.1e} | {eq[1]:.1e} | {1e3 * b:.1f} | {1e3 * bc:.1f} | "
                 f"{1e3 * first:.1f} | {info['rows']} × "
                 f"({info['nz_lo']} + {info['nz_hi']}) | {info['max_rel_err_T']:.1e} |")
    L += ["", f"History of one trapped case (ln π0 = ln π_trap + 0.2, start 25 ū_trap): "
          f"`squeeze_history` at {n_hist:,} times log-uniform in 1e-9–1e3 s, against the route "
          f"it replaced (per-case quadrature of the same case at {n_quad:,} sorted times, the "
          "same run). Error: the forward reference's time from the start to each returned ū "
          "(25 times), relative, or where ū is within reach of ū_trap its distance as a fraction "
          "of ū - ū_trap.", "",
          "| tables | theory | history: points/s | quad: points/s | history / quad | "
          "history: max err |", "|---|---|---|---|---|---|"]
    for name, th, fh, qh, eh in hrows:
        L.append(f"| {name} | {th} | {fh:.3g} | {qh:.3g} | {fh / qh:.3g} | {eh:.1e} |")
    L += ["", f"Just below the trap pressure (not trapped): {n_fast:,} (fast) and {n_quad:,} "
          f"(quad) cases, ln p0 uniform from {OLD_MARGIN} below min(trap pressure, the tables' "
          "last open node) to the fast path's limit (the band the primitive serves since "
          "2026-12-07; before, the per-case quadrature), default start, targets 1.01 ū∞ and "
          "1.001 ū∞, ū at two times. Errors on 10 cases against the independent quadrature of "
          "the same tables (BelowTrapReference: ū∞ and the start by brentq, panels broken at "
          "the tables' nodes): t* and t to 1.001 ū∞ relative; ū at t* + 2 t_relax as the "
          "reference time to it, in t_relax.", "",
          "| tables | theory | fast: cases/s | quad: cases/s | fast / quad | fast: err t | "
          "fast: err ū [t_relax] | quad: err t | quad: err ū [t_relax] |",
          "|---|---|---|---|---|---|---|---|---|"]
    for name, th, f, q, ef, eq in brows:
        L.append(f"| {name} | {th} | {f:.3g} | {q:.3g} | {f / q:.3g} | {ef[0]:.1e} | "
                 f"{ef[1]:.1e} | {eq[0]:.1e} | {eq[1]:.1e} |")
    L.append("")
    write_keeping_notes(HERE / "trapped_results.md", "\n".join(L) + "\n")
    print("\n".join(L))


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
