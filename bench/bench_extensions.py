"""Benchmark of the issue-14 extensions: error against the independent references vs run
time, speed against the base engines measured in the same run, and "where it matters".

Writes ``bench/extensions_results.md`` and ``bench/extensions_asperity_tire.png``.
Run: ``python bench/bench_extensions.py [--quick]``.

* Barus squeeze-out: error of t(1.1 ū∞) vs Gauss–Legendre order/panel width against
  tests/reference/ext_reynolds.py (radial Reynolds with η(p), solve_ivp + brentq + quad);
  cases/s vs the base ``squeeze_out(method="quad")`` and ``"fast"``; a heavy steel block on oil.
* Barus seal: error of the O-ring (panel collocation, and shooting vs RK4 steps) against
  adaptive DOP853 shooting; rows/s vs the base ``seal_leak``; leak-rate reduction of a
  hydraulic ring at MPa pressures.
* Anisotropy: direct solver cost and error vs panels; table build and lookup cost,
  interpolation error; σ_xx/σ_iso, σ_yy/σ_iso and the leak rate along vs across grooves.
* Asperity cascade: t*(ζ) for the paper's tire case on both asphalt stand-ins, cascade
  totals for level ratio 2 and 4, and the figure.
* Barus tire footprint (``tire_footprint(alpha_pv=)``): error of t(1.1 ū∞), t_du and of ū at
  the exit (via the reference time to it) against tests/reference/ext_reynolds.py; cases/s
  vs the base ``tire_footprint``.
* Roelands seal (``seal_leak(viscosity="roelands")``): error against
  tests/reference/ext_roelands.py (solve_bvp / DOP853 shooting in p, Hamrock & Dowson's
  law written out); rows/s; Roelands vs Barus on a steel face seal at the same initial slope.
* Anisotropic tables (``precompute(anisotropy=)``, ``Tables.conductivity(direction=)``,
  ``seal_leak(direction=)``): build cost, lookup cost, error against the direct solver and
  a flat-ring quadrature of it; rows/s vs the isotropic tables.
* Asperity study (``asperity_summary``, the scene kind): cases/s once the level tables exist,
  agreement with ``asperity_levels`` and the one-level direct quadrature.

The summary table at the top is built from the numbers measured in the same run.
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path
from unittest import mock

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import fastcontact as fc  # noqa: E402
from fastcontact.flow.anisotropy import (directional_sigma_bar,  # noqa: E402
                                         precompute_directional)
from fastcontact.flow.conductivity import conductivity  # noqa: E402
from fastcontact.seal import seal_leak  # noqa: E402
from fastcontact.seal import viscosity as viscosity_mod  # noqa: E402
from fastcontact.seal.viscosity import SWEEP_TABLE_ROWS, seal_leak_piezo  # noqa: E402
from fastcontact.squeeze import squeeze_out  # noqa: E402
from fastcontact.figures.asperity_figures import plot_asperity_tstar  # noqa: E402
from fastcontact.squeeze.asperity import TIRE_CASE, asperity_levels  # noqa: E402
from fastcontact.squeeze.viscosity import squeeze_out_piezo  # noqa: E402
from results_notes import write_keeping_notes  # noqa: E402
from fastcontact.tables.defaults import default_surface  # noqa: E402
from machine_info import cpu_model  # noqa: E402
from reference.ext_reynolds import hertz_shoot, squeeze_time  # noqa: E402
from reference.ext_roelands import hertz_shoot as hertz_shoot_r  # noqa: E402
from reference.ext_roelands import roelands, seal_bvp  # noqa: E402

SURFACE = dict(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
E, ETA = 1e7, 1e-3


def _unchained(solve_profile_rows):
    """``solve_profile_rows`` with its chains along a sweep switched off (every row cold)."""
    def cold(*args, chain=False, **kwargs):
        return solve_profile_rows(*args, **kwargs)
    return cold


def timed(fn, repeats=5):
    """Median wall time [s] of ``repeats`` calls after one untimed call (a path's first call
    in a process pays its result arrays' fresh pages; bench/alloc_results.md). Calls that
    measure a cold state reset it themselves (``cold_sweep``)."""
    fn()
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def bench_squeeze(lines, tables, quick, summary):
    lines += ["## Barus viscosity — squeeze-out", ""]
    cases = [(1e5, 3e-6), (4e5, 1.5e-6), (4e5, 2e-6)]
    refs = {}
    for p0, al in cases:
        r = squeeze_out_piezo(tables, p0=p0, E_star=E, R=0.01, eta=ETA, alpha_pv=al,
                              theory="emt", ratios=(1.1,), method="quad").iloc[0]
        refs[(p0, al)] = (squeeze_time(tables, "emt", p0, E, 0.01, ETA, al, r.u_start,
                                       1.1 * r.u_inf, r.u_inf, rtol=1e-11), r)
    n = 2000 if quick else 10000
    lines += ["Error of t(1.1 ū∞) against the Reynolds reference (α p0 = 0.3, 0.6, 0.8) and "
              f"cost per case ({n} cases, α p0 up to 0.4, 2 cores): the per-case quadrature "
              "(`method=\"quad\"`) by Gauss–Legendre order and panel width, and the fast path "
              "(`\"fast\"`, the default: base primitive + tabulated Barus correction; "
              "α p0 > 0.6 by the quadrature):", "",
              "| method | GL order | panel width | max rel. error | µs/case |",
              "|---|---|---|---|---|"]
    rng = np.random.default_rng(1)
    p0s = np.exp(rng.uniform(math.log(2e4), math.log(4e5), n))
    per = {}
    for order, width in [(4, 2.0), (6, 1.0), (10, 1.0), (16, 0.5)]:
        err = 0.0
        for (p0, al), (ref, _r) in refs.items():
            got = squeeze_out_piezo(tables, p0=p0, E_star=E, R=0.01, eta=ETA, alpha_pv=al,
                                    theory="emt", ratios=(1.1,), quad_order=order,
                                    quad_width=width, method="quad")["t_ratio_1.1"][0]
            err = max(err, abs(got / ref - 1))
        dt = timed(lambda: squeeze_out_piezo(tables, p0=p0s, E_star=E, R=0.01, eta=ETA,
                                             alpha_pv=1e-6, theory="emt", quad_order=order,
                                             quad_width=width, method="quad"), 3)
        lines.append(f"| quad | {order} | {width} | {err:.1e} | {1e6 * dt / n:.2f} |")
        per[(order, width)] = (err, dt)
    nf = 50_000 if quick else 400_000
    p0f = np.exp(rng.uniform(math.log(2e4), math.log(4e5), nf))
    ef = {}
    for (p0, al), (ref, _r) in refs.items():
        got = squeeze_out_piezo(tables, p0=p0, E_star=E, R=0.01, eta=ETA, alpha_pv=al,
                                theory="emt", ratios=(1.1,))["t_ratio_1.1"][0]
        ef[p0 * al] = abs(got / ref - 1)
    squeeze_out_piezo(tables, p0=p0f[:10], E_star=E, R=0.01, eta=ETA, alpha_pv=1e-6,
                      theory="emt")
    tff = timed(lambda: squeeze_out_piezo(tables, p0=p0f, E_star=E, R=0.01, eta=ETA,
                                          alpha_pv=1e-6, theory="emt"), 3)
    lines.append(f"| fast | – | – | {max(ef.values()):.1e} (α p0 = 0.3: {ef[0.3]:.1e}, 0.6: "
                 f"{ef[0.6]:.1e}) | {1e6 * tff / nf:.3f} ({nf} cases) |")
    two = np.where(np.arange(nf) % 2 == 0, 1e-6, 0.8e-6)  # two oils: a G primitive each
    cont = 1e-6 * rng.uniform(0.8, 1.0, nf)  # every row its own α: the per-case kernel
    ef2 = {}
    for (p0, al), (ref, _r) in refs.items():
        got = squeeze_out_piezo(tables, p0=[p0, p0], E_star=E, R=0.01, eta=ETA,
                                alpha_pv=[al, 0.5 * al], theory="emt",
                                ratios=(1.1,))["t_ratio_1.1"][0]
        ef2[p0 * al] = abs(got / ref - 1)
    tff2 = timed(lambda: squeeze_out_piezo(tables, p0=p0f, E_star=E, R=0.01, eta=ETA,
                                           alpha_pv=two, theory="emt"), 3)
    tff3 = timed(lambda: squeeze_out_piezo(tables, p0=p0f, E_star=E, R=0.01, eta=ETA,
                                           alpha_pv=cont, theory="emt"), 3)
    lines.append(f"| fast, two oils (a G primitive each) | – | – | – | "
                 f"{1e6 * tff2 / nf:.3f} ({nf} cases) |")
    lines.append(f"| fast, α per case (every row its own; two-row calls for the error) | – | – "
                 f"| {max(ef2.values()):.1e} | {1e6 * tff3 / nf:.3f} ({nf} cases) |")
    # per-case starts, a Δu target and ū at three times: the paths the row tables do not serve
    base0 = squeeze_out(tables, p0=p0f, E_star=E, R=0.01, eta=ETA, theory="emt", ratios=())
    usf = base0["u_inf"].to_numpy() * np.exp(rng.uniform(0.1, 5.0, nf))
    gkw = dict(p0=p0f, E_star=E, R=0.01, eta=ETA, theory="emt", u_start=usf, du=(1e-7,),
               times=(1e-5, 1e-3, 1e-1))
    tg1 = timed(lambda: squeeze_out_piezo(tables, alpha_pv=1e-6, **gkw), 3)
    tg2 = timed(lambda: squeeze_out_piezo(tables, alpha_pv=two, **gkw), 3)
    tg3 = timed(lambda: squeeze_out_piezo(tables, alpha_pv=cont, **gkw), 3)
    tgb = timed(lambda: squeeze_out(tables, **gkw), 3)
    lines.append(f"| fast, given starts, Δu, ū at 3 times: one α / two oils / α per case / "
                 f"base | – | – | – | {1e6 * tg1 / nf:.3f} / {1e6 * tg2 / nf:.3f} / "
                 f"{1e6 * tg3 / nf:.3f} / {1e6 * tgb / nf:.3f} |")
    tq = timed(lambda: squeeze_out(tables, p0=p0s, E_star=E, R=0.01, eta=ETA, theory="emt",
                                   method="quad"), 3)
    tf = timed(lambda: squeeze_out(tables, p0=p0f, E_star=E, R=0.01, eta=ETA, theory="emt"), 3)
    lines += ["", f"Base engine, same cases: `method=\"quad\"` {1e6 * tq / n:.2f} µs/case, "
              f"`\"fast\"` {1e6 * tf / nf:.3f} µs/case ({nf} cases). A call of one α and one "
              f"E* (\"fast\") runs the base engine's kernel on the Barus time primitive "
              f"G = T + α p0 S (fastcontact/squeeze/_barus_time.py, built per (tables, theory, "
              f"α E*) in ~5-40 ms and kept): {tf / tff:.2f}× the base fast path's speed; a call "
              f"of two oils (each ≥ 20,000 rows) the same kernel on a primitive per oil: "
              f"{tf / tff2:.2f}×; with every row its own α the Barus kernel adds the correction "
              f"α p0 [S(ū) − S(ū_start)] per case, S a series of 1-D primitives in ū "
              f"(fastcontact/squeeze/_barus_primitive.py): {tf / tff3:.2f}×.", ""]
    e10, t10 = per[(10, 1.0)]
    summary.append(("Barus squeeze-out", f"fast {max(ef.values()):.1e} (α per case "
                    f"{max(ef2.values()):.1e}), quad {e10:.1e} "
                    f"(GL 10, width 1): t(1.1ū∞) vs radial Reynolds reference",
                    f"fast {nf / tff:.3g} cases/s ({tf / tff:.2f}× base; two oils "
                    f"{nf / tff2:.3g}, {tf / tff2:.2f}×; α per case {nf / tff3:.3g}, "
                    f"{tf / tff3:.2f}×), given starts + Δu + 3 times {nf / tg1:.3g} "
                    f"({tgb / tg1:.2f}× base; two oils {tgb / tg2:.2f}×; α per case "
                    f"{nf / tg3:.3g}, {tgb / tg3:.2f}×), quad {n / t10:.3g}; base quad "
                    f"{n / tq:.3g}, fast {nf / tf:.3g}"))
    # where it matters: a heavy steel block on oil
    steel = fc.SelfAffinePSD(h_rms=1e-6, hurst=0.8, q0=2e4, q1=1e8)
    ts = fc.precompute(steel, theories=("emt",))
    Es = 2.1e11 / (2 * (1 - 0.3 ** 2))
    p0 = np.array([1e6, 1e7, 3e7, 6e7, 9e7, 1.2e8])
    base = squeeze_out_piezo(ts, p0=p0, E_star=Es, R=0.01, eta=0.1, alpha_pv=0.0,
                             theory="emt", ratios=(1.1,), du=(1e-7,))
    oil = squeeze_out_piezo(ts, p0=p0, E_star=Es, R=0.01, eta=0.1, alpha_pv=1e-8,
                            theory="emt", ratios=(1.1,), du=(1e-7,))
    lines += ["Where it matters — steel block (R = 1 cm, E* = 115 GPa, h_rms = 1 µm) on oil "
              "(η0 = 0.1 Pa s, α = 1e-8 1/Pa):", "",
              "| p0 [MPa] | α p0 | g at start | t(ū∞+0.1 µm) Barus/const | t(1.1ū∞) Barus/const | t* Barus/const | piezo_limit |",
              "|---|---|---|---|---|---|---|"]
    for i in range(p0.size):
        r, b = oil.iloc[i], base.iloc[i]
        lines.append(f"| {p0[i] / 1e6:g} | {r.barus_number:.2f} | {r.rate_factor_start:.3f} | "
                     f"{r['t_du_1e-07'] / b['t_du_1e-07']:.3f} | {r['t_ratio_1.1'] / b['t_ratio_1.1']:.3f} | "
                     f"{r.t_star / b.t_star:.4f} | {bool(r.piezo_limit)} |")
    lines += ["", "The rate factor g ∈ (1/2, 1]: a rigid block at most doubles any time while "
              "α(p0 − p_cont) < 1; t* (the last 1 %) barely changes because p̄_f → 0 there; "
              "at α p0 ≥ 1 the quasi-static film cannot carry the load (EHL regime): flagged, NaN.",
              ""]


def bench_seal(lines, tables, quick, summary):
    lines += ["## Barus viscosity — seals", ""]
    R, fN, Ly = 1e-3, 3.0, 0.1
    a = math.sqrt(4 * fN * R / (math.pi * E))
    pH = 2 * fN / (math.pi * a)
    plo = tables.p_range[0] * E
    sig = lambda pc: tables.conductivity(np.maximum(pc, plo * 1.0000001), E, ETA, "emt")  # noqa: E731
    ref = {dp: hertz_shoot(sig, pH, a, dp, 0.0, 3e-5) * Ly for dp in (3e4, 6e4)}
    lines += ["O-ring (p_H = 98 kPa, α = 3e-5 1/Pa so that α p_H = 2.9): error against adaptive "
              "DOP853 shooting, cost per row (200 rows): the default panel collocation in ψ "
              "(the base engine's solver), and shooting with RK4 steps (`steps=`):", "",
              "| solver | max rel. error | ms/row |", "|---|---|---|"]
    dps = np.linspace(1e3, 9e4, 200 if not quick else 50)
    for steps in (None, 50, 100, 200, 400, 800):
        err = max(abs(seal_leak_piezo(tables, profile="hertz", R=R, f_N=fN, dp=dp, L_y=Ly,
                                      E_star=E, eta=ETA, alpha_pv=3e-5, theory="emt",
                                      steps=steps).Q[0] / q - 1) for dp, q in ref.items())
        dt = timed(lambda: seal_leak_piezo(tables, profile="hertz", R=R, f_N=fN, dp=dps, L_y=Ly,
                                           E_star=E, eta=ETA, alpha_pv=3e-5, theory="emt",
                                           steps=steps), 3)
        label = "panels (default)" if steps is None else f"{steps} RK4 steps"
        lines.append(f"| {label} | {err:.1e} | {1e3 * dt / dps.size:.3f} |")
        if steps is None:
            e_pan, t_pan = err, dt
        if steps == 200:
            t200 = dt
    # the default without the chains along the sweep (every row a cold panel solve), the
    # baseline of the chains in the same run
    cold_rows = _unchained(viscosity_mod.solve_profile_rows)
    with mock.patch.object(viscosity_mod, "solve_profile_rows", cold_rows):
        t_cold = timed(lambda: seal_leak_piezo(tables, profile="hertz", R=R, f_N=fN, dp=dps,
                                               L_y=Ly, E_star=E, eta=ETA, alpha_pv=3e-5,
                                               theory="emt"), 3)
    lines.append(f"| panels, every row cold (no chains along the sweep) | {e_pan:.1e} | "
                 f"{1e3 * t_cold / dps.size:.3f} |")
    tb = timed(lambda: seal_leak(tables, profile="hertz", R=R, f_N=fN, dp=dps, L_y=Ly, E_star=E,
                                 eta=ETA, theory="emt"), 3)
    tbd = timed(lambda: seal_leak(tables, profile="hertz", R=R, f_N=fN, dp=dps, L_y=Ly,
                                  E_star=E, eta=ETA, theory="emt", solver={"table": False}), 3)
    n = 20000 if quick else 200000
    dpu = np.linspace(0, 4.9e4, n)
    tu = timed(lambda: seal_leak_piezo(tables, p0=5e4, dp=dpu, L=5e-3, L_y=Ly, E_star=E,
                                       eta=ETA, alpha_pv=3e-5, theory="emt"), 3)

    def cold_sweep():  # the β table built in the call (no table kept from an earlier call)
        viscosity_mod._BETA_TABLES.clear()
        seal_leak_piezo(tables, p0=5e4, dp=dpu, L=5e-3, L_y=Ly, E_star=E, eta=ETA,
                        alpha_pv=3e-5, theory="emt")
    tu_cold = timed(cold_sweep, 3)
    dps_short = np.linspace(1e3, 4.9e4, 100)  # a short sweep: 100 rows per call
    t_short = timed(lambda: seal_leak_piezo(tables, p0=5e4, dp=dps_short, L=5e-3, L_y=Ly,
                                            E_star=E, eta=ETA, alpha_pv=3e-5, theory="emt"), 5)
    viscosity_mod._BETA_TABLES.clear()
    t_short_cold = timed(lambda: seal_leak_piezo(tables, p0=5e4, dp=dps_short, L=5e-3, L_y=Ly,
                                                 E_star=E, eta=ETA, alpha_pv=3e-5,
                                                 theory="emt"), 5)
    t_short_base = timed(lambda: seal_leak(tables, p0=5e4, dp=dps_short, L=5e-3, L_y=Ly,
                                           E_star=E, eta=ETA, theory="emt"), 5)
    tub = timed(lambda: seal_leak(tables, p0=5e4, dp=dpu, L=5e-3, L_y=Ly, E_star=E, eta=ETA,
                                  theory="emt"), 3)
    p0d = np.random.default_rng(4).uniform(3e4, 6e4, n)  # every ring its own integrand
    tud = timed(lambda: seal_leak_piezo(tables, p0=p0d, dp=0.5 * p0d, L=5e-3, L_y=Ly, E_star=E,
                                        eta=ETA, alpha_pv=3e-5, theory="emt"), 3)
    lines += ["", f"Base `seal_leak` O-ring: {1e3 * tb / dps.size:.3f} ms/row (its table), "
              f"{1e3 * tbd / dps.size:.3f} ms/row by its direct panel solver (the Barus default's "
              f"solver, same run). Flat ring, a Δp sweep of one seal ({n} rows): the base "
              f"{1e6 * tub / n:.3f} µs/row (tabulated primitive) vs "
              f"{1e6 * tu / n:.2f} µs/row with Barus α ({1e6 * tu_cold / n:.2f} where the call "
              f"builds its β table, see below; separates exactly, "
              f"q L = E* e^(-α(p0-p_b)) ∫σ̄ e^x e^(αE* e^x) dx: a cumulative table of that integral "
              f"per α E*, built by a call with enough such rings and kept with the Tables for "
              f"later calls, and per row two partial cells from their Legendre "
              f"series); rings of distinct p0 sharing α E* {1e6 * tud / n:.2f} µs/row (same "
              f"table). A Δp sweep of any law of at least {SWEEP_TABLE_ROWS} rows reads a table "
              f"of its run (the Roelands flat ring below); shorter ones add each row's piece to "
              f"the previous row's integral. Calls of 100 rows (a short Δp sweep): "
              f"{1e3 * t_short:.3f} ms/call reading a kept β table, {1e3 * t_short_cold:.3f} "
              f"ms/call by the sweep kernel (no table kept), base {1e3 * t_short_base:.3f} "
              f"ms/call.", ""]
    # a study of many O-rings of one fluid (p_b = 0): the fluid's verified table of W
    no, al_t = (4000 if quick else 20000), 3e-6
    rng = np.random.default_rng(7)
    pHo = np.exp(rng.uniform(math.log(2e-3), math.log(0.05), no)) * E
    ao = 2e-3 * 2.0 * pHo / E                      # R = 2 mm: p_H = E* a/(2R)
    okw = dict(profile="hertz", R=2e-3, f_N=math.pi * ao * pHo / 2.0,
               dp=rng.uniform(1e-3, 0.99, no) * pHo, L_y=Ly, E_star=E, eta=ETA, theory="emt")
    sc_o = viscosity_mod.seal_context(tables, "emt")
    sc_o.hertz_piezo.clear()
    t0 = time.perf_counter()
    q_tab = seal_leak_piezo(tables, alpha_pv=al_t, **okw).Q.to_numpy()
    t_first = time.perf_counter() - t0
    t_tab = timed(lambda: seal_leak_piezo(tables, alpha_pv=al_t, **okw), 3)
    with mock.patch.object(viscosity_mod, "TABLE_MIN_ROWS", 10 ** 12):
        t0 = time.perf_counter()
        q_dir = seal_leak_piezo(tables, alpha_pv=al_t, **okw).Q.to_numpy()
        t_dir = time.perf_counter() - t0
    t_base = timed(lambda: seal_leak(tables, **okw), 3)
    two_o = np.where(np.arange(no) % 2 == 0, al_t, 0.8 * al_t)  # two oils: a table each
    seal_leak_piezo(tables, alpha_pv=0.8 * al_t, **okw)  # the second oil's, by a call of its own
    t_two = timed(lambda: seal_leak_piezo(tables, alpha_pv=two_o, **okw), 3)
    t_two_solve = timed(lambda: seal_leak_piezo(tables, alpha_pv=two_o * (1.0 + 1e-9), **okw),
                        1)  # two oils without kept tables: 10,000 scattered O-rings each
    fin = np.isfinite(q_dir) & (q_dir > 0)
    e_tab = float(np.max(np.abs(q_tab[fin] / q_dir[fin] - 1)))
    e_ref = max(abs(q_tab[i] / (hertz_shoot(sig, pHo[i], ao[i], okw["dp"][i], 0.0, al_t) * Ly)
                    - 1) for i in (3, 11))
    lines += [f"O-rings of one fluid (p_b = 0; {no} O-rings, p_H/E* 2e-3…0.05, Δp/p_H "
              f"1e-3…0.99, α = {al_t:g} 1/Pa: α p_H up to {al_t * pHo.max():.2f}): W from the "
              f"fluid's verified table (fastcontact/seal/hertz.py, per α E*, built by a call "
              f"where that costs fewer solves than its rows, and kept): "
              f"{no / t_tab:.3g} rows/s (the call that builds it {no / t_first:.3g}), the "
              f"per-row solver {no / t_dir:.3g} rows/s, base `seal_leak` (its table) "
              f"{no / t_base:.3g}; Q within {e_tab:.1e} of the solver's, {e_ref:.1e} of the "
              f"DOP853 shooting (two rows). Two oils in one call (α = {al_t:g} and "
              f"{0.8 * al_t:g} 1/Pa alternating), each oil's table kept from a call of its own: "
              f"{no / t_two:.3g} rows/s; two other oils, no table kept ({no // 2} scattered "
              f"O-rings each do not pay for building one): {no / t_two_solve:.3g} rows/s.", ""]
    summary.append(("Barus seal", f"O-ring {e_pan:.1e} by panels (DOP853 shooting); one "
                    f"fluid's O-ring table {e_ref:.1e} (shooting), {e_tab:.1e} (solver)",
                    f"O-rings of one fluid from its table {no / t_tab:.3g} rows/s (base table "
                    f"{no / t_base:.3g}; the call that builds it {no / t_first:.3g}, per-row "
                    f"solver {no / t_dir:.3g}; two oils {no / t_two:.3g}); O-ring sweep {dps.size / t_pan:.3g} rows/s (rows cold, no chains "
                    f"{dps.size / t_cold:.3g}; 200-step shooting "
                    f"{dps.size / t200:.3g}; base table {dps.size / tb:.3g}, base direct "
                    f"{dps.size / tbd:.3g}); flat ring, Δp sweep "
                    f"{n / tu:.3g} rows/s (base {n / tub:.3g}; the call that builds its β "
                    f"table {n / tu_cold:.3g}), distinct p0 {n / tud:.3g}"))
    # where it matters: a metal face seal at tens of MPa on oil
    face = fc.SelfAffinePSD(h_rms=0.2e-6, hurst=0.8, q0=1e4, q1=1e8)
    th = fc.precompute(face, theories=("emt",))
    Eh, p0 = 2.1e11 / (2 * (1 - 0.3 ** 2)), 150e6
    dp = np.array([10e6, 30e6, 60e6, 100e6, 140e6])
    res = {al: seal_leak_piezo(th, p0=p0, dp=dp, L=2e-3, L_y=0.1, E_star=Eh, eta=0.05,
                               alpha_pv=al, theory="emt").Q.to_numpy() for al in (0.0, 1e-8, 2e-8)}
    lines += ["Where it matters — steel face seal (E* = 115 GPa, p0 = 150 MPa, L = 2 mm, "
              "h_rms = 0.2 µm) sealing oil (η0 = 0.05 Pa s):", "",
              "| Δp [MPa] | Q const [m³/s] | Q(α=1e-8)/Q const | Q(α=2e-8)/Q const | Δψ/Δp (α=1e-8) |",
              "|---|---|---|---|---|"]
    for i, d in enumerate(dp):
        lines.append(f"| {d / 1e6:g} | {res[0.0][i]:.3e} | {res[1e-8][i] / res[0.0][i]:.3f} | "
                     f"{res[2e-8][i] / res[0.0][i]:.3f} | {-math.expm1(-1e-8 * d) / (1e-8 * d):.3f} |")
    lines += ["", "Δψ/Δp = (1−e^{−αΔp})/(αΔp) is the naive factor (exact only for a prescribed "
              "gap). With contact feedback the reduction is larger: the high viscosity sits at "
              "the inlet, where p_cont is smallest and σ0 largest.", ""]


def bench_anisotropy(lines, quick, summary):
    lines += ["## Anisotropic roughness", ""]
    psd = fc.SelfAffinePSD(**SURFACE)
    p = np.array([1e2, 1e4, 1e5, 5e5, 1e6, 1.8e6])
    iso = conductivity(psd, p, E, 1 / 12, "emt", tol=1e-12)[0] / psd.h_rms ** 3
    lines += ["Direct solver at γ_T = 1 (forced anisotropic path) against the isotropic EMT, "
              "and cost per pressure:", "", "| panels | max rel. error | ms/pressure |",
              "|---|---|---|"]
    for n in (12, 24, 48, 96):
        directional_sigma_bar(psd, p[:1] / E, 1.0, n_panels=n)
        dt = timed(lambda: directional_sigma_bar(psd, p / E, 1.0, n_panels=n), 3)
        s1, _ = directional_sigma_bar(psd, p / E, 1.0, n_panels=n)
        lines.append(f"| {n} | {np.max(np.abs(s1 / iso - 1)):.1e} | {1e3 * dt / p.size:.1f} |")
        if n == 48:
            e48, t48 = float(np.max(np.abs(s1 / iso - 1))), dt / p.size
    directional_sigma_bar(psd, p[:1] / E, 1.0)
    dt = timed(lambda: directional_sigma_bar(psd, p / E, 1.0), 3)
    s1, _ = directional_sigma_bar(psd, p / E, 1.0)
    e_ad, t_ad = float(np.max(np.abs(s1 / iso - 1))), dt / p.size
    lines.append(f"| adaptive (default, tol 1e-8) | {e_ad:.1e} | {1e3 * t_ad:.1f} |")
    # adaptive and 48 fixed panels against 192 fixed panels on a synthetic road spectrum
    from fastcontact.surface.roaddb import synthetic_road_psd
    qr, Cr = synthetic_road_psd(np.random.default_rng(7))[-2:]
    road = fc.TabulatedPSD(qr, Cr)
    pcr = float(fc.contact.percolation_pressure(road, 1.0, 0.5))
    pr = pcr * np.geomspace(1e-6, 1.15, 24 if quick else 80)
    road_rows = []
    for form in ("self_consistent", "fixed"):
        ref = directional_sigma_bar(road, pr, 3.0, form=form, n_panels=192)
        errs = []
        for n_p in (None, 48):
            t0 = time.perf_counter()
            got = directional_sigma_bar(road, pr, 3.0, form=form, n_panels=n_p)
            dtr = time.perf_counter() - t0
            e = max(float(np.max(np.abs(g_[r_ > 1e-20] / r_[r_ > 1e-20] - 1)))
                    for g_, r_ in zip(got, ref))
            errs.append((e, 1e3 * dtr / pr.size))
        road_rows.append(f"| {form} | {errs[0][0]:.1e} | {errs[0][1]:.1f} | {errs[1][0]:.1e} | "
                         f"{errs[1][1]:.1f} |")
    lines += ["", f"Synthetic road spectrum (48-sample table, seed 7), γ_T = 3, {pr.size} "
              "pressures up to 1.15 × the percolation pressure, against 192 fixed panels "
              "(σ̄ > 1e-20):", "",
              "| form | adaptive: max rel. error | ms/pressure | 48 panels: max rel. error | "
              "ms/pressure |", "|---|---|---|---|---|"] + road_rows
    t = fc.precompute(psd, theories=("emt",))
    t0 = time.perf_counter()
    d = precompute_directional(t, 3.0)
    tb = time.perf_counter() - t0
    q = np.exp(np.random.default_rng(3).uniform(math.log(t.p_range[0] * E), math.log(1.8e6),
                                                200000 if not quick else 20000))
    tl = timed(lambda: d.sigma_bar(q, E, "x"), 3)
    tt = timed(lambda: t.sigma_bar(q, E, "emt"), 3)
    lines += ["", f"Table path (γ_T = 3, self-consistent): build {tb:.1f} s on {d.info['nodes']} "
              f"nodes ({d.info['refinement_rounds']} rounds), midpoint error "
              f"x {d.info['interpolation_error']['x']:.1e}, y {d.info['interpolation_error']['y']:.1e}; "
              f"lookup {1e9 * tl / q.size:.0f} ns/point (scipy spline, NumPy) vs the isotropic "
              f"tables {1e9 * tt / q.size:.0f} ns/point.", "",
              "σ relative to the isotropic EMT (h_rms = 5 µm, E* = 10 MPa):", "",
              "| p [Pa] | A/A0 | γ_T | σ_xx/σ_iso (self-cons.) | σ_yy/σ_iso | σ_xx/σ_iso (fixed) | σ_yy/σ_iso (fixed) |",
              "|---|---|---|---|---|---|---|"]
    summary.append(("anisotropy, direct solver and spline table", f"γ_T = 1 forced path "
                    f"{e_ad:.1e} (adaptive; 48 panels {e48:.1e}) vs isotropic EMT; spline "
                    f"midpoint ≤ {max(d.info['interpolation_error'].values()):.1e}",
                    f"{1e3 * t_ad:.1f} ms/pressure direct (48 panels {1e3 * t48:.1f}); spline "
                    f"build {tb:.1f} s, lookup "
                    f"{1e9 * tl / q.size:.0f} ns/point"))
    A = fc.contact.area_fraction(psd, p, E)
    for g in (3.0, 9.0):
        sx, sy = directional_sigma_bar(psd, p / E, g)
        fx, fy = directional_sigma_bar(psd, p / E, g, form="fixed")
        for i in range(p.size):
            lines.append(f"| {p[i]:g} | {A[i]:.3f} | {g:g} | {sx[i] / iso[i]:.3f} | "
                         f"{sy[i] / iso[i]:.3f} | {fx[i] / iso[i]:.3g} | {fy[i] / iso[i]:.3g} |")
    # leak rate of a flat ring along vs across the grooves: q L = ∫ σ dp (α = 0)
    p0, dp = 1.5e6, np.array([0.2e6, 0.8e6, 1.4e6])
    lines += ["", f"Flat ring, p0 = {p0 / 1e6:g} MPa, γ_T = 3: leak rate along (x) / across (y) the "
              "grooves, q L = ∫_{p0−p_a}^{p0} σ dp (GL, 400 nodes in ln p_cont):", "",
              "| Δp/p0 | Q_x/Q_iso | Q_y/Q_iso |", "|---|---|---|"]
    x, w = np.polynomial.legendre.leggauss(400)
    for d_ in dp:
        lo, hi = math.log(max(p0 - d_, t.p_range[0] * E)), math.log(p0)
        pc = np.exp(0.5 * (hi + lo) + 0.5 * (hi - lo) * x)
        ww = 0.5 * (hi - lo) * w * pc
        qi = np.sum(ww * t.sigma_bar(pc, E, "emt"))
        lines.append(f"| {d_ / p0:.2f} | {np.sum(ww * d.sigma_bar(pc, E, 'x')) / qi:.3f} | "
                     f"{np.sum(ww * d.sigma_bar(pc, E, 'y')) / qi:.3f} |")
    lines.append("")


def bench_asperity(lines, quick, summary):
    lines += ["## Asperity-scale squeeze-out — the paper's tire case (Sec. 5)", "",
              "Tread block R = 2 cm, p0 = 0.2 MPa, E = 10 MPa (ν = 0.5), water; the embedded "
              "self-affine asphalt stand-ins; theory EMT; region radius π/(2ζq0).", ""]
    results = {}
    for name in ("asphalt_072mm", "asphalt_024mm"):
        psd = default_surface(name)
        t0 = time.perf_counter()
        df = asperity_levels(psd, theory="emt", **TIRE_CASE)
        dt = time.perf_counter() - t0
        df4 = asperity_levels(psd, theory="emt", level_ratio=4.0, **TIRE_CASE)
        results[name] = df
        lines += [f"**{name}** ({dt:.0f} s for {len(df)} levels incl. one table build each; "
                  f"ζ_trap = {df.attrs['zeta_trap']:g}):", "",
                  "| ζ | A(ζ)/A0 | p(ζ) [MPa] | R(ζ) [mm] | h_rms(ζ) [µm] | A_ζ(ζ1) | ū∞ [µm] | t* [s] | Σ t* | max t* |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for _, r in df.iterrows():
            lines.append(f"| {r.zeta:g} | {r.area_fraction:.3f} | {r.p_zeta / 1e6:.3f} | "
                         f"{1e3 * r.R_zeta:.3g} | {1e6 * r.h_rms_zeta:.1f} | {r.area_restricted:.3f} | "
                         f"{1e6 * r.u_inf:.2f} | {r.t_star:.2e} | {r.t_sequential:.2e} | "
                         f"{r.t_parallel:.2e} |")
        lines += ["", f"Level ratio 4 instead of 2: Σ t* = {df4['t_sequential'].iloc[-1]:.2e} s "
                  f"(ratio 2: {df['t_sequential'].iloc[-1]:.2e} s), max t* = "
                  f"{df4['t_parallel'].iloc[-1]:.2e} s (ratio 2: {df['t_parallel'].iloc[-1]:.2e} s).",
                  ""]
    summary.append(("asperity levels, paper's tire case", "ζ = 1 ≡ base engine (test)",
                    f"{dt:.0f} s for {len(df)} levels (one table build each; memoised)"))
    fig = plot_asperity_tstar(results, HERE / "extensions_asperity_tire.png")
    del fig
    lines += ["Figure: `bench/extensions_asperity_tire.png`.", ""]


def bench_tire(lines, summary, tables, quick):
    from fastcontact.squeeze.tire import squeeze_method, tire_footprint
    lines += ["## Barus viscosity — tire footprint (`tire_footprint(alpha_pv=)`)", ""]
    al = 2.5e-6
    kw = dict(E_star=E, R=0.01, eta=ETA, footprint_length=0.1, theory="emt",
              u_start=20 * tables.h_rms)
    err_t = err_u = 0.0
    for p0, v in ((1e5, 1.0), (2e5, 3.0), (4e5, 0.3)):
        r = tire_footprint(tables, p0=p0, speed=v, alpha_pv=al, method="fast", **kw).iloc[0]
        ref = squeeze_time(tables, "emt", p0, E, 0.01, ETA, al, r.u_start, 1.1 * r.u_inf,
                           r.u_inf, rtol=1e-11)
        err_t = max(err_t, abs(r["t_ratio_1.1"] / ref - 1))
        if r.u_exit > 1.0001 * r.u_inf:
            te = squeeze_time(tables, "emt", p0, E, 0.01, ETA, al, r.u_start, r.u_exit,
                              r.u_inf, rtol=1e-11)
            err_u = max(err_u, abs(te / r.t_footprint - 1))
    n = 50_000 if quick else 400_000
    nq = 2000 if quick else 10000
    rng = np.random.default_rng(5)
    p0s = np.exp(rng.uniform(math.log(5e4), math.log(4e5), n))
    sp = np.exp(rng.uniform(math.log(0.3), math.log(30.0), n))
    kw2 = dict(kw, p0=p0s, speed=sp)
    kq = dict(kw, p0=p0s[:nq], speed=sp[:nq])
    al_f = 1e-6                       # α p0 up to 0.4: every row on the fast path
    tire_footprint(tables, alpha_pv=al_f, method="fast", **dict(kw2, p0=p0s[:4], speed=sp[:4]))
    tb = timed(lambda: tire_footprint(tables, **kw2), 3)
    tp = timed(lambda: tire_footprint(tables, alpha_pv=al_f, method="fast", **kw2), 3)
    tpq = timed(lambda: tire_footprint(tables, alpha_pv=al_f, method="quad", **kq), 3)
    tcols = ["t_star", "t_ratio_1.1", "t_du"]  # a study of target times only: no exit
    tpt = timed(lambda: tire_footprint(tables, alpha_pv=al_f, method="fast", columns=tcols,
                                       **kw2), 3)
    tbt = timed(lambda: tire_footprint(tables, columns=tcols, **kw2), 3)
    two = np.where(np.arange(n) % 2 == 0, al_f, 0.8 * al_f)  # two oils: a G primitive each
    cont = al_f * rng.uniform(0.8, 1.0, n)  # every row its own α: the per-case kernel
    tp2 = timed(lambda: tire_footprint(tables, alpha_pv=two, method="fast", **kw2), 3)
    tp3 = timed(lambda: tire_footprint(tables, alpha_pv=cont, method="fast", **kw2), 3)
    tpt2 = timed(lambda: tire_footprint(tables, alpha_pv=cont, method="fast", columns=tcols,
                                        **kw2), 3)
    fa = tire_footprint(tables, alpha_pv=al_f, method="fast", **kq)
    qa = tire_footprint(tables, alpha_pv=al_f, method="quad", **kq)
    d_u = np.max(np.abs((fa.u_exit - fa.u_inf) - (qa.u_exit - qa.u_inf))
                 / np.maximum(qa.u_exit - qa.u_inf, 1e-2 * qa.u_inf))
    d_t = np.max(np.abs(fa["t_ratio_1.1"] / qa["t_ratio_1.1"] - 1))
    lines += [f"α = {al:g} 1/Pa (α p0 up to 1): max relative error of t(1.1 ū∞) {err_t:.1e}; "
              f"of the footprint time to the engine's ū_exit {err_u:.1e} (reference: radial "
              f"Reynolds with η(p), quad rtol 1e-11; `method=\"fast\"`: α p0 = 0.25 and 0.5 "
              f"on the tables, 1.0 by the quadrature in the same call).", "",
              f"Speed, α = {al_f:g} 1/Pa (α p0 up to 0.4), random pressures and speeds, "
              f"ū(0) = 20 h_rms: fast {n / tp:.3g} cases/s ({n} cases), per-case quadrature "
              f"{nq / tpq:.3g} cases/s ({nq} cases), base `tire_footprint` {n / tb:.3g} cases/s "
              f"(method {squeeze_method(n)!r}). Fast against quadrature on the {nq} cases: "
              f"ū_exit − ū∞ within {d_u:.1e} (relative, floor 1 % of ū∞), t(1.1 ū∞) "
              f"{d_t:.1e}. Only what the columns need is computed: {tcols} alone (no "
              f"exit) fast {n / tpt:.3g} cases/s, base {n / tbt:.3g}. One α and one E* in "
              f"the call: the base engine's kernel on the Barus time primitive "
              f"(fastcontact/squeeze/_barus_time.py); two oils (α = {al_f:g} and "
              f"{0.8 * al_f:g} 1/Pa alternating): the same kernel on a primitive per oil, "
              f"{n / tp2:.3g} cases/s ({tb / tp2:.2f}× base); every row its own α (uniform in "
              f"0.8-1 × {al_f:g}): the per-case Barus kernel, {n / tp3:.3g} cases/s "
              f"({tb / tp3:.2f}× base; target columns only {n / tpt2:.3g}).", ""]
    summary.append(("Barus tire footprint", f"t(1.1ū∞) {err_t:.1e}, ū_exit (as time) "
                    f"{err_u:.1e}; α = 0 ≡ base bit for bit",
                    f"fast {n / tp:.3g} cases/s ({tb / tp:.2f}× base; two oils "
                    f"{n / tp2:.3g}, {tb / tp2:.2f}×; α per case {n / tp3:.3g}, "
                    f"{tb / tp3:.2f}×), quad {nq / tpq:.3g}; base {n / tb:.3g}; "
                    f"target columns only: fast {n / tpt:.3g} (α per case {n / tpt2:.3g}), "
                    f"base {n / tbt:.3g}"))


def bench_roelands(lines, summary, tables, quick):
    lines += ["## Roelands viscosity — seals (`seal_leak(viscosity=\"roelands\")`)", ""]
    c, z, Ly = 1e-5, 0.6, 0.1
    plo = tables.p_range[0] * E
    sig = lambda pc: tables.conductivity(np.maximum(pc, plo * 1.0000001), E, ETA, "emt")  # noqa: E731
    law = roelands(ETA, z, c)
    eu = 0.0
    for dp in (2e4, 4.5e4):
        q, _ = seal_bvp(sig, lambda x: 5e4 + 0 * x, 0.0, 5e-3, dp, 0.0, law)
        got = seal_leak(tables, p0=5e4, dp=dp, L=5e-3, L_y=Ly, E_star=E, eta=ETA, theory="emt",
                        viscosity="roelands", roelands_z=z, roelands_p_r=1 / c).Q[0]
        eu = max(eu, abs(got / (q * Ly) - 1))
    R, fN = 1e-3, 3.0
    a = math.sqrt(4 * fN * R / (math.pi * E))
    pH = 2 * fN / (math.pi * a)
    refs = {dp: hertz_shoot_r(sig, pH, a, dp, 0.0, law) * Ly for dp in (3e4, 6e4)}
    lines += [f"Test law: Z = {z}, p_r = {1 / c:g} Pa (nonlinear at soft-seal pressures). Flat "
              f"ring: max rel. error {eu:.1e} against solve_bvp. O-ring against adaptive DOP853 "
              f"shooting in p:", "", "| RK4 steps | max rel. error | ms/row |", "|---|---|---|"]
    dps = np.linspace(1e3, 9e4, 50 if quick else 200)
    eh200 = None
    for steps in (50, 100, 200, 400):
        e = max(abs(seal_leak_piezo(tables, profile="hertz", R=R, f_N=fN, dp=dp, L_y=Ly,
                                    E_star=E, eta=ETA, alpha_pv=0.0, theory="emt",
                                    viscosity="roelands", roelands_z=z, roelands_p_r=1 / c,
                                    steps=steps).Q[0] / q - 1) for dp, q in refs.items())
        dt = timed(lambda: seal_leak_piezo(tables, profile="hertz", R=R, f_N=fN, dp=dps, L_y=Ly,
                                           E_star=E, eta=ETA, alpha_pv=0.0, theory="emt",
                                           viscosity="roelands", roelands_z=z,
                                           roelands_p_r=1 / c, steps=steps), 3)
        lines.append(f"| {steps} | {e:.1e} | {1e3 * dt / dps.size:.3f} |")
        if steps == 200:
            eh200, th200 = e, dt
    # the default: the panel collocation in the tabulated ψ (rows whose Newton fails: the
    # checked shooting, 100/200 steps, rows that disagree by > FALLBACK_RTOL again at
    # 1600/3200, the previous default, timed here alone as the baseline); its error also next
    # to lift-off (p_a = p_H(1 - 1e-6)), against 12800 steps (the DOP853 reference is off by
    # up to 8e-6 there, tests/test_ext_roelands.py)
    rkw = dict(profile="hertz", R=R, f_N=fN, L_y=Ly, E_star=E, eta=ETA, alpha_pv=0.0,
               theory="emt", viscosity="roelands", roelands_z=z, roelands_p_r=1 / c)
    e_def = max(abs(seal_leak_piezo(tables, dp=dp, **rkw).Q[0] / q - 1) for dp, q in refs.items())
    t_def = timed(lambda: seal_leak_piezo(tables, dp=dps, **rkw), 3)

    def all_shot(tables, theory, E, *rest):   # every row to the checked shooting
        return np.full(E.size, np.nan), np.zeros(E.size, dtype=bool)
    with mock.patch.object(viscosity_mod, "_roelands_hertz_k", all_shot):
        e_chk = max(abs(seal_leak_piezo(tables, dp=dp, **rkw).Q[0] / q - 1)
                    for dp, q in refs.items())
        t_chk = timed(lambda: seal_leak_piezo(tables, dp=dps, **rkw), 3)
    near = [pH * (1 - 1e-3), pH * (1 - 1e-4), pH * (1 - 1e-6)]
    fine = seal_leak_piezo(tables, dp=near, steps=12800, **rkw).Q.to_numpy()
    e_near = {st: float(np.nanmax(np.abs(seal_leak_piezo(tables, dp=near, **kw_st, **rkw)
                                         .Q.to_numpy() / fine - 1)))
              for st, kw_st in (("default", {}), (200, {"steps": 200}))}
    lines.append(f"| default (panel collocation in ψ) | {e_def:.1e} | "
                 f"{1e3 * t_def / dps.size:.3f} |")
    lines.append(f"| checked shooting (its fallback; the default before) | {e_chk:.1e} | "
                 f"{1e3 * t_chk / dps.size:.3f} |")
    lines += ["", f"Next to lift-off (p_a = p_H(1 − ε), ε = 1e-3, 1e-4, 1e-6) against 12800 steps: "
              f"default {e_near['default']:.1e}, 200 steps {e_near[200]:.1e}."]
    tb = timed(lambda: seal_leak(tables, profile="hertz", R=R, f_N=fN, dp=dps, L_y=Ly, E_star=E,
                                 eta=ETA, theory="emt"), 3)
    n = 20000 if quick else 200000
    dpu = np.linspace(0, 4.9e4, n)
    tu = timed(lambda: seal_leak(tables, p0=5e4, dp=dpu, L=5e-3, L_y=Ly, E_star=E, eta=ETA,
                                 theory="emt", viscosity="roelands", roelands_z=z,
                                 roelands_p_r=1 / c), 3)
    tub = timed(lambda: seal_leak(tables, p0=5e4, dp=dpu, L=5e-3, L_y=Ly, E_star=E, eta=ETA,
                                  theory="emt"), 3)
    lines += ["", f"Flat ring (Δp sweep of one seal) {n / tu:.3g} rows/s (base {n / tub:.3g} "
              f"rows/s); O-ring "
              f"{dps.size / th200:.3g} rows/s at 200 steps, {dps.size / t_def:.3g} rows/s by the "
              f"default collocation, {dps.size / t_chk:.3g} by the checked shooting (base "
              f"{dps.size / tb:.3g} rows/s).", ""]
    # a study of many O-rings of one Roelands fluid (p_b = 0): the fluid's verified table
    no = 4000 if quick else 20000
    rng = np.random.default_rng(8)
    pHo = np.exp(rng.uniform(math.log(2e-3), math.log(0.05), no)) * E
    ao = 2e-3 * 2.0 * pHo / E
    okw = dict(profile="hertz", R=2e-3, f_N=math.pi * ao * pHo / 2.0,
               dp=rng.uniform(1e-3, 0.99, no) * pHo, L_y=Ly, E_star=E, eta=ETA, theory="emt",
               alpha_pv=4e-6, viscosity="roelands", roelands_z=0.6, roelands_p_r=2e5)
    viscosity_mod.seal_context(tables, "emt").hertz_piezo.clear()
    t0 = time.perf_counter()
    q_tab = seal_leak_piezo(tables, **okw).Q.to_numpy()
    t_rfirst = time.perf_counter() - t0
    t_rtab = timed(lambda: seal_leak_piezo(tables, **okw), 3)
    with mock.patch.object(viscosity_mod, "TABLE_MIN_ROWS", 10 ** 12):
        t0 = time.perf_counter()
        q_dir = seal_leak_piezo(tables, **okw).Q.to_numpy()
        t_rdir = time.perf_counter() - t0
    fin = np.isfinite(q_dir) & (q_dir > 0)
    e_rtab = float(np.max(np.abs(q_tab[fin] / q_dir[fin] - 1)))
    lines += [f"O-rings of one Roelands fluid (Z = 0.6, p_r = 2e5 Pa, α0 = 4e-6 1/Pa; p_b = 0; "
              f"{no} O-rings as in the Barus section): W from the fluid's verified table (per "
              f"law): {no / t_rtab:.3g} rows/s (the call that builds it {no / t_rfirst:.3g}), "
              f"the per-row solver {no / t_rdir:.3g}; Q within {e_rtab:.1e} of the solver's.",
              ""]
    # where it matters: steel face seal sealing oil, Roelands vs Barus at the same α0
    face = fc.SelfAffinePSD(h_rms=0.2e-6, hurst=0.8, q0=1e4, q1=1e8)
    th = fc.precompute(face, theories=("emt",))
    Eh, p0 = 2.1e11 / (2 * (1 - 0.3 ** 2)), 150e6
    dp = np.array([10e6, 60e6, 140e6])
    kw = dict(p0=p0, dp=dp, L=2e-3, L_y=0.1, E_star=Eh, eta=0.05, theory="emt")
    q0 = seal_leak(th, **kw).Q.to_numpy()
    qb = seal_leak(th, alpha_pv=2e-8, **kw).Q.to_numpy()
    qr = seal_leak(th, alpha_pv=2e-8, viscosity="roelands", **kw).Q.to_numpy()
    Zr = float(seal_leak(th, alpha_pv=2e-8, viscosity="roelands", **kw).roelands_z[0])
    lines += [f"Where it matters — steel face seal (as above), oil η0 = 0.05 Pa s with "
              f"α0 = 2e-8 1/Pa: Barus vs Roelands with the same initial slope (Z = {Zr:.3f}, "
              f"Hamrock–Dowson constants):", "",
              "| Δp [MPa] | Q Barus/const | Q Roelands/const |", "|---|---|---|"]
    for i, d in enumerate(dp):
        lines.append(f"| {d / 1e6:g} | {qb[i] / q0[i]:.3f} | {qr[i] / q0[i]:.3f} |")
    lines += ["", "Roelands (Z < 1) stiffens less than Barus at 100 MPa: the leak rate reduction "
              "is smaller. No reduced pressure exists in closed form for it: the flat ring uses "
              "the separated integral, the O-ring the panel collocation in a tabulated ψ.", ""]
    summary.append(("Roelands seal", f"flat ring {eu:.1e} (solve_bvp); O-ring {eh200:.1e} at "
                    f"200 steps, default (collocation in ψ) {e_def:.1e} (DOP853); next to "
                    f"lift-off "
                    f"default {e_near['default']:.1e}, 200 steps {e_near[200]:.1e} (vs 12800 steps)",
                    f"flat {n / tu:.3g} rows/s (base {n / tub:.3g}); O-ring default "
                    f"{dps.size / t_def:.3g} rows/s (checked shooting {dps.size / t_chk:.3g}), "
                    f"200 steps {dps.size / th200:.3g} (base {dps.size / tb:.3g}); O-rings of "
                    f"one fluid from its table {no / t_rtab:.3g} rows/s ({e_rtab:.1e} of the "
                    f"solver; per-row solver {no / t_rdir:.3g})"))


def bench_aniso_tables(lines, summary, quick):
    lines += ["## Anisotropic tables (`precompute(anisotropy=)`, `direction=`)", ""]
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e7)
    t0 = time.perf_counter()
    ti = fc.precompute(psd, theories=("average", "emt"))
    t_iso = time.perf_counter() - t0
    t0 = time.perf_counter()
    ta = fc.precompute(psd, theories=("average", "emt"), anisotropy=3.0)
    t_an = time.perf_counter() - t0
    one = fc.precompute(psd, theories=("average", "emt"), anisotropy=1.0)
    same = one.equals(ti) and one.options == ti.options
    rng = np.random.default_rng(11)
    pt = np.exp(rng.uniform(math.log(ta.p_range[0] * E), math.log(0.9e6), 12))
    sx, sy = directional_sigma_bar(psd, pt / E, 3.0)
    ex = np.max(np.abs(ta.sigma_bar(pt, E, "emt", "x") / sx - 1))
    ey = np.max(np.abs(ta.sigma_bar(pt, E, "emt", "y") / sy - 1))
    n = 20000 if quick else 200000
    q = np.exp(rng.uniform(math.log(ta.p_range[0] * E), math.log(0.9e6), n))
    ta.sigma_bar(q[:3], E, "emt", "x")
    tl = timed(lambda: ta.sigma_bar(q, E, "emt", "x"), 3)
    tt = timed(lambda: ta.sigma_bar(q, E, "emt"), 3)
    # flat ring along the grooves vs a quadrature of the direct solver
    p0, L, dp = 5e4, 5e-3, 3e4
    x, w = np.polynomial.legendre.leggauss(48)
    lo, hi = math.log(p0 - dp), math.log(p0)
    lp = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x
    es = 0.0
    for d, sd in zip(("x", "y"), directional_sigma_bar(psd, np.exp(lp) / E, 3.0)):
        ref = 0.1 / L * 0.5 * (hi - lo) * np.sum(w * sd * psd.h_rms ** 3 / (12 * ETA)
                                                 * np.exp(lp))
        got = seal_leak(ta, p0=p0, dp=dp, L=L, L_y=0.1, E_star=E, eta=ETA, theory="emt",
                        direction=d).Q[0]
        es = max(es, abs(got / ref - 1))
    dpu = np.linspace(0, 4.9e4, n)
    ts = timed(lambda: seal_leak(ta, p0=5e4, dp=dpu, L=5e-3, L_y=0.1, E_star=E, eta=ETA,
                                 theory="emt", direction="y"), 3)
    tsb = timed(lambda: seal_leak(ti, p0=5e4, dp=dpu, L=5e-3, L_y=0.1, E_star=E, eta=ETA,
                                  theory="emt"), 3)
    d = ta.info["directional"]
    lines += [f"Surface h_rms = 5 µm, H = 0.8, q1 = 1e7 1/m, γ_T = 3 (self-consistent): build "
              f"{t_an:.1f} s vs {t_iso:.1f} s isotropic ({d['nodes']} directional nodes, "
              f"{d['refinement_rounds']} rounds, midpoint error x {d['interpolation_error']['x']:.1e}, "
              f"y {d['interpolation_error']['y']:.1e}); γ_T = 1 tables identical to isotropic: "
              f"{same}.", "",
              f"Tables.sigma_bar(direction=) against the direct solver: x {ex:.1e}, y {ey:.1e}; "
              f"lookup {1e9 * tl / n:.0f} ns/point vs {1e9 * tt / n:.0f} ns/point isotropic.", "",
              f"seal_leak(direction=) flat ring against a 48-point GL quadrature of the direct "
              f"σ_xx, σ_yy: {es:.1e}; {n / ts:.3g} rows/s vs {n / tsb:.3g} rows/s on isotropic "
              f"tables (same engine, the directional view is cached).", ""]
    summary.append(("anisotropic tables, seal direction",
                    f"σ lookup {max(ex, ey):.1e}, flat-ring Q {es:.1e} vs direct solver; "
                    f"γ_T = 1 identical: {same}",
                    f"build {t_an:.1f} s (isotropic {t_iso:.1f} s); seal {n / ts:.3g} rows/s "
                    f"(isotropic {n / tsb:.3g})"))


def bench_asperity_study(lines, summary, quick):
    from fastcontact.contact import contact_pressure, mean_separation
    from fastcontact.squeeze.asperity import asperity_summary
    from scipy import integrate
    lines += ["## Asperity study (`asperity_summary`, scene kind \"asperity\")", ""]
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e7)
    T = fc.precompute(psd, theories=("average",))
    t0 = time.perf_counter()
    asperity_summary(T, p0=2e5, E_star=E, R=5e-3, eta=ETA, theory="average")
    t_first = time.perf_counter() - t0
    n = 2000 if quick else 20000
    p0 = np.exp(np.random.default_rng(2).uniform(math.log(5e4), math.log(5e5), n))
    tc = timed(lambda: asperity_summary(T, p0=p0, E_star=E, R=5e-3, eta=ETA,
                                        theory="average"), 3)
    lv = asperity_levels(tables=T, p0=2e5, E_star=E, R=5e-3, eta=ETA, theory="average",
                         zetas=[1.0, 4.0])
    row = lv.iloc[1]
    sub = psd.restricted(4.0 * psd.q0)
    pz, Rz = row.p_zeta, row.R_zeta
    u_inf = float(mean_separation(sub, pz, E))
    u_start = float(mean_separation(sub, 1e-3 * pz, E))

    def integrand(w):
        u = u_inf + math.exp(w)
        rate = 2 * u ** 3 * (pz - float(contact_pressure(sub, u, E))) / (3 * ETA * Rz ** 2)
        return math.exp(w) / rate

    t_ref, _ = integrate.quad(integrand, math.log(0.01 * u_inf), math.log(u_start - u_inf),
                              epsrel=1e-10, limit=200)
    e1 = abs(row.t_star / t_ref - 1)
    lines += [f"Level ζ = 4 against a direct quadrature of dū/dt with the contact core (no "
              f"tables): {e1:.1e}. First call (builds and memoises the level tables): "
              f"{t_first:.1f} s; then {n / tc:.3g} cases/s ({n} cases, all levels, one "
              f"vectorised squeeze_out per level).", ""]
    summary.append(("asperity study (scene kind)", f"level ζ = 4 {e1:.1e} vs direct "
                    f"quadrature; ζ = 1 ≡ base", f"{n / tc:.3g} cases/s after a one-time "
                    f"{t_first:.1f} s of level tables"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only", default="squeeze,tire,seal,roelands,anisotropy,aniso_tables,"
                                      "asperity,asperity_study")
    args = ap.parse_args()
    import numba

    lines = ["# Extensions (issue 14): accuracy and speed", "",
             f"Machine: {cpu_model()}, {os.cpu_count()} cores, numba threads "
             f"{numba.get_num_threads()} (shared, noisy: medians of repeats). "
             f"Generated by `bench/bench_extensions.py{' --quick' if args.quick else ''}`.", ""]
    tables = fc.precompute(fc.SelfAffinePSD(**SURFACE), theories=("average", "critical_junction", "emt"))
    only = args.only.split(",")
    summary = []
    body = []
    if "squeeze" in only:
        bench_squeeze(body, tables, args.quick, summary)
    if "tire" in only:
        bench_tire(body, summary, tables, args.quick)
    if "seal" in only:
        bench_seal(body, tables, args.quick, summary)
    if "roelands" in only:
        bench_roelands(body, summary, tables, args.quick)
    if "anisotropy" in only:
        bench_anisotropy(body, args.quick, summary)
    if "aniso_tables" in only:
        bench_aniso_tables(body, summary, args.quick)
    if "asperity" in only:
        bench_asperity(body, args.quick, summary)
    if "asperity_study" in only:
        bench_asperity_study(body, summary, args.quick)
    if summary:
        lines += ["## Summary (this run)", "",
                  "| extension | accuracy (vs independent reference) | speed |", "|---|---|---|"]
        lines += [f"| {a} | {b} | {c} |" for a, b, c in summary]
        lines += ["", "Speeds are measured in the same run as their base engines (the machine "
                  "is shared: absolute times are noisy, ratios are the meaningful numbers). "
                  "The Barus squeeze-out and tire footprint run on tables (α p0 <= 0.6); the "
                  "seal η(p) engines solve per row: quadrature (flat rings: Barus rings "
                  "sharing α E* read a cumulative table kept with the Tables, long Δp sweeps "
                  "one per call, short "
                  "sweeps add each row's piece to the previous row's integral), the base engine's panel "
                  "collocation in ψ (O-rings; Roelands: ψ tabulated per row, shooting where its "
                  "Newton fails).",
                  ""]
    lines += body
    out = HERE / ("extensions_results.md" if args.only == ap.get_default("only")
                  else f"extensions_results_{args.only.replace(',', '_')}.md")
    write_keeping_notes(out, "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
