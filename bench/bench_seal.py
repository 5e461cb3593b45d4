"""Benchmark of fastcontact.seal: error against run time, uniform rings and O-rings, against
baselines measured in the same run on this machine.

Writes ``bench/seal_results.md`` (a Markdown fragment for bench/collect.py).
Run: ``python bench/bench_seal.py [--quick] [--only-pb] [--only-oils]`` (``--only-pb``: only
the O-rings with p_b > 0, ``--only-oils``: only the Barus O-rings of one oil per row; their
block of the results file replaced).

* error: max relative error of Q against ``tests/reference/seal_reference.py`` (direct contact
  core, no tables): flat rings by composite Gauss–Legendre of direct σ_eff over the interval
  width itself (dp/p0 from 1e-12 up to the lift-off point, p0 up to 0.999 of the percolation
  pressure; rows the engine flags "near_percolation", Q = NaN, are listed, not compared);
  O-rings by an independent graded-panel Newton solution of eq. (33) on a Chebyshev
  interpolant of direct σ.
* cost: median over repeats of the end-to-end wall time of ``seal_leak`` (validation, flags,
  DataFrame) for N random cases; the first call on fresh tables (uniform: the seal context
  is built; O-ring: table rows solved and cells verified on demand); the CPU time of one
  uniform call (the rate 2 uncontended cores would give).
* baselines (same run): the reference's own cost per case; for O-rings also the direct panel
  solver (``solver=dict(table=False)``: today's per-case Newton, now on a ``prange`` driver).
* O-rings with p_b > 0: the p_b > 0 table (steady state, the call that builds it) against
  the per-row solver on the same rows, and the max rel. error of Q against it.
* Barus O-rings of one oil per row (p_b = 0): the table of W(π_H, π_a, α p_H) likewise, and a
  call too small to pay for building it.
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import fastcontact as fc  # noqa: E402
import fastcontact.seal.hertz  # noqa: E402,F401
from machine_info import cpu_model  # noqa: E402
from results_notes import write_keeping_notes  # noqa: E402
from reference.seal_reference import (  # noqa: E402
    SigmaInterp, hertz_reference, uniform_reference)

SURFACE = dict(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
E = 1e7
ETA = 1e-3
L, L_Y, R = 5e-3, 0.1, 1e-3
ALPHA = 0.54
RATIOS = [1e-12, 1e-9, 1e-4, 1e-2, 0.1, 0.5, 0.9, 0.999, 1.0]
P_NEAR = 2e6


def machine():
    import numba

    return (f"{cpu_model()}, {os.cpu_count()} cores, numba threads {numba.get_num_threads()}; "
            f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}")


def median_time(fn, repeats):
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def uniform_section(tables, psd, quick, repeats):
    pp = float(tables.percolation_pressure("critical_junction", E))
    cases = [(th, p0, r) for th in ("average", "critical_junction")
             for p0 in (5e3, 5e4, 5e5) for r in RATIOS]
    cases += [("critical_junction", f * pp, r) for f in (0.9, 0.99, 0.999) for r in (1e-9, 0.5)]
    if quick:
        cases = cases[::3]
    err, t_ref, zero, flagged = 0.0, [], [], []
    for th, p0, r in cases:
        a = ALPHA if th == "critical_junction" else 1.0
        t0 = time.perf_counter()
        q, est = uniform_reference(psd, p0=p0, dp=r * p0, L=L, L_y=L_Y, E_star=E, eta=ETA,
                                   theory=th, alpha_cj=a, width=0.05 if p0 > 0.5 * pp else 0.25)
        t_ref.append(time.perf_counter() - t0)
        row = fc.seal_leak(tables, p0=p0, dp=r * p0, L=L, L_y=L_Y, E_star=E, eta=ETA,
                           theory=th, alpha_cj=a)
        Q, status = float(row.Q[0]), str(row.status[0])
        if status == "near_percolation":      # flagged, Q = NaN: not a number to compare
            flagged.append((th, round(p0 / pp, 4), r, f"{q:.2e}"))
        elif q > 0:
            err = max(err, abs(Q / q - 1)) if np.isfinite(Q) else math.inf
        else:
            zero.append((th, p0 / pp, r, Q))
    rng = np.random.default_rng(1)
    N = 200_000 if quick else 2_000_000
    p0 = 10 ** rng.uniform(3, 6, N)
    dp = rng.uniform(0, 1, N) * p0
    kw = dict(L=L, L_y=L_Y, E_star=E, eta=ETA, alpha_cj=ALPHA)
    fresh = fc.Tables.from_parquet(TABLE_FILE)            # first call: builds the context
    t0 = time.perf_counter()
    fc.seal_leak(fresh, p0=p0, dp=dp, **kw)
    t_first = time.perf_counter() - t0
    te = median_time(lambda: fc.seal_leak(tables, p0=p0, dp=dp, **kw), repeats)
    c0 = time.process_time()
    fc.seal_leak(tables, p0=p0, dp=dp, **kw)
    cpu = time.process_time() - c0
    # near percolation: p0 = 2 MPa (0.95 p_perc), dp/p0 uniform in [0, 1], α_cj = 1
    kp = dict(kw, alpha_cj=1.0)
    dpp = rng.uniform(0, 1, N) * P_NEAR
    tp = median_time(lambda: fc.seal_leak(tables, p0=P_NEAR, dp=dpp, **kp), repeats)
    n_flag = int((fc.seal_leak(tables, p0=P_NEAR, dp=dpp, **kp).status
                  == "near_percolation").sum())
    if zero:
        print("reference Q = 0 (direct σ percolated) at", zero)
    return dict(cases=len(cases) - len(zero) - len(flagged), err=err,
                base=statistics.median(t_ref), N=N, t=te, t_first=t_first, cpu=cpu, tp=tp,
                n_flag=n_flag, zero=zero, flagged=flagged, pp=pp)


def hertz_section(tables, psd, quick, repeats):
    p_hi = 1.02 * 0.1 * E
    interp = SigmaInterp(psd, E_star=E, eta=ETA, theory="critical_junction", p_lo=1e-16 * E,
                         p_hi=p_hi, alpha_cj=ALPHA, degree=120)
    assert interp.max_error < 1e-9, interp.max_error
    cases = [(pr, r) for pr in (0.008, 0.025, 0.08) for r in RATIOS[2:]]
    if quick:
        cases = cases[::3]
    t_ref, err_t, err_d = [], 0.0, 0.0
    for pr, r in cases:
        f_N = math.pi * R * (pr * E) ** 2 / E
        pH = float(fc.hertz_contact(R, f_N, E)[1])     # the p_H both sides use: r = 1 exact
        t0 = time.perf_counter()
        q, est, _ = hertz_reference(interp, R=R, f_N=f_N, dp=r * pH, L_y=L_Y, E_star=E,
                                    panels=6, nodes=10)
        t_ref.append(time.perf_counter() - t0)
        for table, key in ((True, "t"), (False, "d")):
            Q = fc.seal_leak(tables, profile="hertz", R=R, f_N=f_N, dp=r * pH, L_y=L_Y,
                             E_star=E, eta=ETA, alpha_cj=ALPHA, solver=dict(table=table)).Q[0]
            if key == "t":
                err_t = max(err_t, abs(Q / q - 1))
            else:
                err_d = max(err_d, abs(Q / q - 1))
    rng = np.random.default_rng(2)
    N = 20_000 if quick else 300_000
    piH = 10 ** rng.uniform(-3, -1, N)
    pH = piH * E
    kw = dict(profile="hertz", R=R, f_N=math.pi * R * pH ** 2 / E,
              dp=rng.uniform(1e-4, 0.999, N) * pH, L_y=L_Y, E_star=E, eta=ETA, alpha_cj=ALPHA)
    tables_fresh = fc.Tables.from_parquet(TABLE_FILE)       # first call: builds its table
    fc.seal_leak(tables_fresh, p0=5e4, dp=1e3, L=L, L_y=L_Y, E_star=E, eta=ETA)
    t0 = time.perf_counter()
    first = fc.seal_leak(tables_fresh, **kw)
    t_first = time.perf_counter() - t0
    t_table = median_time(lambda: fc.seal_leak(tables_fresh, **kw), repeats)
    fallback = float(np.mean(first.error_estimate.to_numpy() != fc.seal.hertz.VERIFY_TOL))
    Nd = 2000 if quick else 10_000
    kd = {k: (v[:Nd] if isinstance(v, np.ndarray) else v) for k, v in kw.items()}
    t_direct = median_time(lambda: fc.seal_leak(tables_fresh, **kd, solver=dict(table=False)),
                           max(1, repeats - 2))
    return dict(cases=len(cases), err_t=err_t, err_d=err_d, base=statistics.median(t_ref),
                N=N, t_first=t_first, t_table=t_table, Nd=Nd, t_direct=t_direct,
                fallback=fallback)


#: O-rings with p_b > 0: p_H/E* log-uniform in PB_PH (a band narrow enough for 200,000 rows
#: to pay for the table they need: a call builds it only where that takes no more solves than
#: its rows), p_a/p_H uniform in [1e-3, 0.999], p_b/p_a uniform in [0, 0.9]
PB_N = 200_000
PB_PH = (0.01, 0.03)
PB_HEAD = "### Hertz O-rings with an outlet pressure p_b > 0 (`--only-pb`)"


def hertz_pb_section(repeats):
    """Rows/s of O-rings with p_b > 0 from the p_b > 0 table (steady state and the call that
    builds it) against the per-row solver, and the max rel. error of Q against it."""
    rng = np.random.default_rng(3)
    pH = np.exp(rng.uniform(math.log(PB_PH[0]), math.log(PB_PH[1]), PB_N)) * E
    pa = rng.uniform(1e-3, 0.999, PB_N) * pH
    pb = rng.uniform(0.0, 0.9, PB_N) * pa
    kw = dict(profile="hertz", R=R, f_N=math.pi * R * pH ** 2 / E, dp=pa - pb, p_b=pb,
              L_y=L_Y, E_star=E, eta=ETA, alpha_cj=ALPHA)
    fresh = fc.Tables.from_parquet(TABLE_FILE)
    fc.seal_leak(fresh, p0=5e4, dp=1e3, L=L, L_y=L_Y, E_star=E, eta=ETA)   # the context
    t0 = time.perf_counter()
    first = fc.seal_leak(fresh, **kw)
    t_first = time.perf_counter() - t0
    t_table = median_time(lambda: fc.seal_leak(fresh, **kw), repeats)
    t0 = time.perf_counter()
    ref = fc.seal_leak(fresh, **kw, solver=dict(table=False))
    t_solver = time.perf_counter() - t0
    ht = fastcontact.seal.hertz.hertz_pb_table(fc.seal.context.seal_context(
        fresh, "critical_junction")).rec
    ok = (ref.status == "ok").to_numpy()
    tab = ok & (first.error_estimate.to_numpy() == fc.seal.hertz.VERIFY_TOL)
    err = float(np.max(np.abs(first.Q[ok] / ref.Q[ok] - 1))) if ok.any() else math.nan
    return dict(t_first=t_first, t_table=t_table, t_solver=t_solver, err=err,
                served=float(tab.sum() / max(ok.sum(), 1)), ok=int(ok.sum()),
                **_table_stats(ht))


def _table_stats(ht):
    """Grid lines solved, cells verified (and failed) and solves of a lazily built O-ring
    table record (p_b > 0 or one oil per row)."""
    lines, cells = int(ht.built.sum()), int((ht.cell > 0).sum())
    return dict(lines=lines, cells=cells, failed=int((ht.cell == 2).sum()),
                solves=lines * (fastcontact.seal.hertz.NY + 1) + cells)


def hertz_pb_lines(p):
    """The Markdown block of :func:`hertz_pb_section`."""
    n = PB_N
    return [
        PB_HEAD,
        "",
        f"{n:,} O-rings, p_H/E* log-uniform in {list(PB_PH)}, p_a/p_H uniform in [1e-3, 0.999], "
        f"p_b/p_a uniform in [0, 0.9] (critical junction, α_cj = {ALPHA}); {p['ok']:,} rows "
        f"status \"ok\", {p['served'] * 100:.2f} % of them served by the table. Table built by "
        f"the first call: {p['lines']:,} grid lines (ln π_H, z) of {fastcontact.seal.hertz.NY + 1} "
        f"nodes and {p['cells']:,} cells verified ({p['failed']:,} failed: solver), "
        f"{p['solves']:,} solves at the table tolerance.",
        "",
        *_table_rows(n, p, "`solver=dict(table=False)`"),
        "",
    ]


def _table_rows(n, p, solver):
    """The Markdown table of a kept-table section: its header, the steady-state and
    first-call rows and the per-row solver's (``solver``: how it was forced)."""
    return [
        "| path | end-to-end rows/s | × solver | max rel. error of Q vs solver |",
        "|---|---|---|---|",
        f"| table (steady state, table kept) | {n / p['t_table']:.3g} | "
        f"{p['t_solver'] / p['t_table']:.3g} | {p['err']:.1e} |",
        f"| table, first call (builds it: lines + verification) | {n / p['t_first']:.3g} | "
        f"{p['t_solver'] / p['t_first']:.3g} | same rows |",
        f"| per-row solver ({solver}, prange) | {n / p['t_solver']:.3g} | 1 | – |"]


#: Barus O-rings, one oil per row: as PB_N/PB_PH, p_b = 0, α p_H log-uniform in OIL_B
OIL_N = 200_000
OIL_B = (1e-3, 1.5)
OIL_HEAD = "### Barus O-rings, one oil per row (`--only-oils`)"


def oils_section(repeats):
    """Rows/s of Barus O-rings (p_b = 0) whose α differs on every row, from the table of
    W(π_H, π_a, α p_H) (steady state, the call that builds it, a call too small to pay for it)
    against the per-row solver, and the max rel. error of Q against it."""
    import fastcontact.seal.viscosity as sv
    rng = np.random.default_rng(5)
    pH = np.exp(rng.uniform(math.log(PB_PH[0]), math.log(PB_PH[1]), OIL_N)) * E
    pa = rng.uniform(1e-3, 0.999, OIL_N) * pH
    alpha = np.exp(rng.uniform(math.log(OIL_B[0]), math.log(OIL_B[1]), OIL_N)) / pH
    kw = dict(profile="hertz", R=R, f_N=math.pi * R * pH ** 2 / E, dp=pa, L_y=L_Y,
              E_star=E, eta=ETA, alpha_cj=ALPHA, alpha_pv=alpha)
    fresh = fc.Tables.from_parquet(TABLE_FILE)
    fc.seal_leak(fresh, p0=5e4, dp=1e3, L=L, L_y=L_Y, E_star=E, eta=ETA)   # the context
    small = {**kw, **{k: kw[k][:20_000] for k in ("f_N", "dp", "alpha_pv")}}
    t0 = time.perf_counter()
    fc.seal_leak(fresh, **small)
    t_small = time.perf_counter() - t0
    sc = fc.seal.context.seal_context(fresh, "critical_junction")
    small_built = bool(fastcontact.seal.hertz.hertz_beta_table(sc).rec.built.any())
    t0 = time.perf_counter()
    first = fc.seal_leak(fresh, **kw)
    t_first = time.perf_counter() - t0
    t_table = median_time(lambda: fc.seal_leak(fresh, **kw), repeats)
    keep = sv.TABLE_MIN_ROWS
    sv.TABLE_MIN_ROWS = 10 ** 12             # every row solved
    try:
        t0 = time.perf_counter()
        ref = fc.seal_leak(fresh, **kw)
        t_solver = time.perf_counter() - t0
    finally:
        sv.TABLE_MIN_ROWS = keep
    base = median_time(lambda: fc.seal_leak(fresh, **{k: v for k, v in kw.items()
                                                      if k != "alpha_pv"}), repeats)
    ht = fastcontact.seal.hertz.hertz_beta_table(sc).rec
    ok = (ref.status == "ok").to_numpy()
    same = ok & (first.Q.to_numpy() == ref.Q.to_numpy())      # rows the solver gave
    err = float(np.max(np.abs(first.Q[ok] / ref.Q[ok] - 1))) if ok.any() else math.nan
    return dict(t_first=t_first, t_table=t_table, t_solver=t_solver, t_small=t_small,
                small_built=small_built, base=base, err=err,
                served=1.0 - float(same.sum() / max(ok.sum(), 1)), ok=int(ok.sum()),
                **_table_stats(ht))


def oils_lines(p):
    """The Markdown block of :func:`oils_section`."""
    n = OIL_N
    return [
        OIL_HEAD,
        "",
        f"{n:,} Barus O-rings, each of its own oil: α p_H log-uniform in {list(OIL_B)}, p_H/E* "
        f"log-uniform in {list(PB_PH)}, p_a/p_H uniform in [1e-3, 0.999], p_b = 0 (critical "
        f"junction, α_cj = {ALPHA}); {p['ok']:,} rows status \"ok\", {p['served'] * 100:.2f} % "
        f"of them served by the table of W(π_H, π_a, α p_H) "
        f"(`fastcontact.seal.hertz.table_W_beta`, α p_H <= {fastcontact.seal.hertz.B_MAX}). "
        f"Table built by the first call: {p['lines']:,} grid lines (ln π_H, α p_H) of "
        f"{fastcontact.seal.hertz.NY + 1} nodes and {p['cells']:,} cells verified "
        f"({p['failed']:,} failed: solver), {p['solves']:,} solves at the table tolerance.",
        "",
        *_table_rows(n, p, "`TABLE_MIN_ROWS` raised"),
        f"| base fluid (α = 0) on the same O-rings, its table | {n / p['base']:.3g} | "
        f"{p['t_solver'] / p['base']:.3g} | – |",
        "",
        f"A first call of 20,000 of these rows (fresh tables) "
        f"{'built the table' if p['small_built'] else 'did not build the table (it would take more solves than the rows: solved per row)'}"
        f": {20_000 / p['t_small']:.3g} rows/s.",
        "",
    ]


def splice_block(path, head, block):
    """Replace the block from ``head`` to the next generated block head (### that is one of
    PB_HEAD, OIL_HEAD) or the end of the generated part of the results file at ``path`` by
    ``block`` (appended when absent), keeping the rest (:func:`write_keeping_notes` keeps
    the notes)."""
    from results_notes import NOTES_MARK
    text = Path(path).read_text() if Path(path).is_file() else ""
    lines = text.splitlines()
    end = next((i for i, ln in enumerate(lines) if ln.startswith(NOTES_MARK)), len(lines))
    gen = lines[:end]
    if head in gen:
        i = gen.index(head)
        j = next((k for k in range(i + 1, len(gen)) if gen[k] in (PB_HEAD, OIL_HEAD)),
                 len(gen))
        gen = gen[:i] + gen[j:]
    return "\n".join(gen).rstrip() + "\n\n" + "\n".join(block)


TABLE_FILE = str(Path(os.environ.get("TMPDIR", "/tmp")) / "fastcontact_bench_seal_tables.parquet")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only-pb", action="store_true",
                    help="run only the O-rings with p_b > 0 and replace their block in "
                         "seal_results.md (the other sections are kept as they are)")
    ap.add_argument("--only-oils", action="store_true",
                    help="run only the Barus O-rings of one oil per row and replace their "
                         "block in seal_results.md")
    args = ap.parse_args()
    repeats = 3 if args.quick else 5
    load0 = os.getloadavg()
    psd = fc.SelfAffinePSD(**SURFACE)
    t0 = time.perf_counter()
    tables = fc.precompute(psd)
    t_pre = time.perf_counter() - t0
    tables.to_parquet(TABLE_FILE)
    for flag, head, run in ((args.only_pb, PB_HEAD, lambda: hertz_pb_lines(
            hertz_pb_section(repeats))), (args.only_oils, OIL_HEAD,
                                          lambda: oils_lines(oils_section(repeats)))):
        if flag:
            block = run()
            block[2] += (f" {machine()}; load average {tuple(round(x, 2) for x in load0)} at "
                         f"the start, {tuple(round(x, 2) for x in os.getloadavg())} at the end.")
            write_keeping_notes(HERE / "seal_results.md",
                                splice_block(HERE / "seal_results.md", head, block))
            print("\n".join(block))
    if args.only_pb or args.only_oils:
        return
    u = uniform_section(tables, psd, args.quick, repeats)
    h = hertz_section(tables, psd, args.quick, repeats)
    pb = hertz_pb_lines(hertz_pb_section(repeats)) + oils_lines(oils_section(repeats))
    load1 = os.getloadavg()
    md = [
        "## Seal leak rate — `bench/bench_seal.py`",
        "",
        f"Machine: {machine()}. Shared/noisy machine: medians of {repeats} repeats; ratios "
        f"measured in the same run. Load average at start {tuple(round(x, 2) for x in load0)}, "
        f"at end {tuple(round(x, 2) for x in load1)} (2 cores: > 2 means other processes "
        f"competed). Surface {SURFACE}, E* = {E:g} Pa, η = {ETA:g} Pa·s, critical junction "
        f"α_cj = {ALPHA} unless stated; tables built in {t_pre:.1f} s.",
        "",
        "| path | cases (error) | max rel. error of Q vs reference | cases (timing) | "
        "end-to-end cases/s | baseline | × baseline |",
        "|---|---|---|---|---|---|---|",
        f"| uniform ring (primitive, short intervals direct) | {u['cases']} (average, CJ; "
        f"dp/p0 1e-12…1, p0 up to 0.999 p_perc) | {u['err']:.1e} | {u['N']:,} | "
        f"{u['N'] / u['t']:.3g} | reference {u['base'] * 1e3:.1f} ms/case | "
        f"{u['base'] * u['N'] / u['t']:.3g} |",
        f"| uniform ring, first call (fresh tables: context built) | – | – | {u['N']:,} | "
        f"{u['N'] / u['t_first']:.3g} | reference | {u['base'] * u['N'] / u['t_first']:.3g} |",
        f"| uniform ring near percolation (p0 = {P_NEAR:g} Pa = {P_NEAR / u['pp']:.3f} p_perc, "
        f"α_cj = 1, dp/p0 uniform in [0, 1]) | – | "
        f"– | {u['N']:,} | {u['N'] / u['tp']:.3g} | reference | "
        f"{u['base'] * u['N'] / u['tp']:.3g} |",
        f"| Hertz O-ring, table (steady state) | {h['cases']} (p_H/E* 0.008–0.08, dp/p_H "
        f"1e-4…1) | {h['err_t']:.1e} | {h['N']:,} | {h['N'] / h['t_table']:.3g} | direct "
        f"{h['t_direct'] / h['Nd'] * 1e6:.1f} µs/case | "
        f"{h['t_direct'] / h['Nd'] * h['N'] / h['t_table']:.3g} |",
        f"| Hertz O-ring, table (first call: rows + verification) | – | – | {h['N']:,} | "
        f"{h['N'] / h['t_first']:.3g} | direct | "
        f"{h['t_direct'] / h['Nd'] * h['N'] / h['t_first']:.3g} |",
        f"| Hertz O-ring, direct solver (prange) | same | {h['err_d']:.1e} | {h['Nd']:,} | "
        f"{h['Nd'] / h['t_direct']:.3g} | reference {h['base'] * 1e3:.1f} ms/case | "
        f"{h['base'] * h['Nd'] / h['t_direct']:.3g} |",
        "",
        f"O-ring timing set: p_H/E* log-uniform in [1e-3, 0.1], dp/p_H uniform in [1e-4, 0.999],"
        f" p_b = 0; {h['fallback'] * 100:.1f} % of its rows fell back to the direct solver "
        f"(cells not verified: next to lift-off or with a steep σ̄). Uniform timing set: p0 "
        f"log-uniform in [1e3, 1e6] Pa, dp/p0 uniform in [0, 1]; one steady call took "
        f"{u['cpu']:.3f} s of CPU time ({u['N'] / u['cpu'] * 2:.3g} cases/s on 2 uncontended "
        f"cores) and the first call on fresh tables {u['t_first']:.3f} s. Near percolation "
        f"{u['n_flag']:,} of {u['N']:,} rows are status \"near_percolation\" (Q = NaN: the "
        f"tables' σ̄ is unverified there). Uniform error cases flagged \"near_percolation\" "
        f"(not counted; their direct reference Q in m³/s): {u['flagged']}. Uniform cases "
        f"whose direct reference is already percolated (not counted): {u['zero']}.",
        "",
    ] + pb
    write_keeping_notes(HERE / "seal_results.md", "\n".join(md))
    print("\n".join(md))


if __name__ == "__main__":
    main()
