"""Fuzz benchmark of the engines' invariants (issue 15.2): >= 1e7 cases per engine.

Squeeze-out: the 4 embedded tables x 3 theories, random p0/E* over each table's range and a
decade beyond it (plus its edges), E* 1e5-1e11 Pa, R 1 µm-10 m (2 % at 1e308 and 1e-300 m),
eta 1e-6-1e4 Pa·s; paths: the default fast path (most cases), ``method="quad"`` (also compared
with the fast path), a given ``u_start`` (above the default start, between the targets, just
above ū∞, +inf, and 2 % at or below ū∞), ``du`` targets and ``times`` columns, the exact
t ∝ eta R² scaling on re-evaluated pairs, and the Barus engines (``squeeze_out`` and
``tire_footprint`` with ``alpha_pv``, :func:`check_barus`). Seal: uniform ring over p0 (to 1.5x the percolation
pressure; "average" up to the table top), dp/(p0 - p_b) from 1e-15 to past lift-off, p_b, L,
L_y, eta, E*, with paired re-evaluations (p0 up, dp up, dp split in two, E*-scaling, the dp -> 0
limit of eq. 32), and the Hertz O-ring over R, f_N and dp. Every invariant is the function of
``tests/test_invariants.py`` that the unit tests use; this script counts the rows violating each.

Accuracy: the worst relative error against the independent references
(``tests/reference/squeeze_reference.py``, ``tests/reference/seal_reference.py``: the direct
contact core + scipy quad, no tables) on a random subsample, and of the Barus squeeze-out
against ``tests/reference/ext_reynolds.py`` (the radial Reynolds equation with η(p)).

Memory is bounded: cases are generated, evaluated and checked in chunks (``--chunk``); only
counters are kept. Results go to a ``--label`` section of ``bench/fuzz_results.md``.

    python bench/bench_fuzz.py --label before                 # full run (1e7 + 1e7 cases)
    python bench/bench_fuzz.py --quick --label quick          # 1e5 cases per engine, 12 refs
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import re
import subprocess
import sys
import time
import traceback
from collections import Counter
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "tests"))

from machine_info import cpu_model  # noqa: E402
import test_invariants as inv  # noqa: E402

from fastcontact.seal import seal_leak  # noqa: E402
from fastcontact.squeeze import squeeze_out  # noqa: E402
from fastcontact._core.vocab import column_name  # noqa: E402
from fastcontact.tables import Tables  # noqa: E402
from fastcontact.tire import tire_footprint  # noqa: E402

NAMES = inv.NAMES
THEORIES = inv.THEORIES
RATIOS = inv.FAST_RATIOS
TIMES = (0.0, 1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e9, math.inf)


def machine():
    import numba
    import pandas
    rev = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                         capture_output=True, text=True).stdout.strip()
    return (f"{cpu_model()}, {os.cpu_count()} cores, numba threads {numba.get_num_threads()}; "
            f"Python {platform.python_version()}, numpy {np.__version__}, pandas "
            f"{pandas.__version__}, numba {numba.__version__}; git {rev}")


class Tally:
    """Violation counters per (engine, path, invariant), case counts and errors."""

    def __init__(self):
        self.viol = Counter()
        self.cases = Counter()
        self.evals = Counter()
        self.seconds = Counter()
        self.examples = {}
        self.errors = Counter()

    def add(self, engine, path, v, df=None, inputs=None):
        for name, mask in v.items():
            m = np.asarray(mask, bool)
            if m.ndim == 0:
                m = np.full(len(df) if df is not None else 1, bool(m))
            k = int(m.sum())
            key = (engine, path, name)
            self.viol[key] += k
            if k and key not in self.examples and df is not None:
                i = int(np.flatnonzero(m)[0])
                row = df.iloc[i].to_dict() if i < len(df) else {}
                self.examples[key] = {**(inputs or {}), **{c: row[c] for c in list(row)[:14]}}

    def exception(self, engine, path, exc, n, inputs):
        key = (engine, path, f"raised {type(exc).__name__}")
        self.viol[key] += n
        self.errors[key] += 1
        if key not in self.examples:
            self.examples[key] = {**inputs, "message": " ".join(str(exc).split())[:300]}


# =============================================================================== squeeze
def _u_inf_start(tab, theory, kw, method="fast"):
    # the method's own ū∞: the primitive's and the quadrature's differ by up to ~4e-9
    d = squeeze_out(tab, theory=theory, ratios=(), method=method, **kw)
    return d["u_inf"].to_numpy(float), d["u_start"].to_numpy(float), d


def squeeze_chunk(tally, tab, name, theory, rng, n, path):
    kw = inv.squeeze_cases(tab, rng, n)
    inputs = dict(table=name, theory=theory)
    du = inv._du_targets(tab)
    t0 = time.perf_counter()
    evals = 0
    try:
        if path == "fast":
            df = squeeze_out(tab, theory=theory, ratios=RATIOS, du=du, **kw)
            evals += len(df)
            v = inv.check_squeeze(df, ratios=RATIOS, du=du)
            v.update(inv.check_u_inf_monotone(df))
            # scaling pair on a tenth of the rows (R clipped so R*m stays finite)
            m = max(1, n // 10)
            sub = {k: x[:m].copy() for k, x in kw.items()}
            sub["R"] = np.clip(sub["R"], 1e-6, 10.0)
            k_, m_ = 10 ** rng.uniform(-3, 3), 10 ** rng.uniform(-2, 2)
            a = squeeze_out(tab, theory=theory, ratios=RATIOS, du=du, **sub)
            b = squeeze_out(tab, theory=theory, ratios=RATIOS, du=du,
                            **dict(sub, eta=sub["eta"] * k_, R=sub["R"] * m_))
            evals += 2 * m
            sc = np.zeros(len(df), bool)
            sc[:m] = inv.compare_times(a, b, inv.time_columns(a) + ["t_relax", "tau0"], 1e-10,
                                       scale=k_ * m_ * m_)
            v["scaling_eta_R2"] = sc
        elif path == "quad":
            df = squeeze_out(tab, theory=theory, ratios=RATIOS, du=du, method="quad", **kw)
            f = squeeze_out(tab, theory=theory, ratios=RATIOS, du=du, **kw)
            evals += 2 * len(df)
            v = inv.check_squeeze(df, ratios=RATIOS, du=du)
            for c in inv.time_columns(df):
                v[f"fast_vs_quad_1e-6[{c}]"] = inv.compare_paths(df, f, [c], inv.ACC)
        elif path == "times":
            method = "quad" if rng.random() < 0.5 else "fast"
            df = squeeze_out(tab, theory=theory, ratios=RATIOS, times=TIMES, method=method, **kw)
            evals += len(df)
            v = inv.check_squeeze(df, ratios=RATIOS, times=TIMES)
        elif path == "u_start":
            method = "quad" if rng.random() < 0.5 else "fast"
            kw["R"] = np.clip(kw["R"], 1e-6, 10.0)
            u_inf, ud, _ = _u_inf_start(tab, theory, kw, method)
            evals += n
            ok = np.isfinite(u_inf)
            kw = {k: x[ok] for k, x in kw.items()}
            u_inf, ud = u_inf[ok], ud[ok]
            m = u_inf.size
            pick = rng.random(m)
            us = u_inf + rng.uniform(0, 1, m) * (ud - u_inf)                # between
            us = np.where(pick < 0.2, ud * 10 ** rng.uniform(0, 4, m), us)   # above default
            us = np.where((pick >= 0.2) & (pick < 0.3), u_inf * (1 + 10 ** rng.uniform(-12, -3, m)), us)
            us = np.where((pick >= 0.3) & (pick < 0.33), np.inf, us)
            below = (pick >= 0.33) & (pick < 0.35)
            us = np.where(below, u_inf * rng.uniform(0.0, 1.0, m), us)
            us = np.where(below & (rng.random(m) < 0.3), u_inf, us)
            us = np.where(us > 0, us, u_inf * 0.5)
            below = us <= u_inf
            try:
                df = squeeze_out(tab, theory=theory, ratios=RATIOS, method=method, u_start=us, **kw)
                evals += m
            except ValueError as exc:
                # issue 11.6: one bad row must not sink the batch
                tally.exception("squeeze", "u_start", exc, int(below.sum()), inputs)
                keep = ~below
                kw = {k: x[keep] for k, x in kw.items()}
                us = us[keep]
                below = below[keep]
                df = squeeze_out(tab, theory=theory, ratios=RATIOS, method=method, u_start=us, **kw)
                evals += int(keep.sum())
            v = inv.check_squeeze(df, ratios=RATIOS, u_start_given=True)
            st = inv._status_bad(df)
            t = df["t_star"].to_numpy(float)
            v["start_below_u_inf_not_status_nan"] = below & ~(st & np.isnan(t))
        elif path == "barus":
            # issue 14.2: the Barus engines, squeeze-out and tire, both methods, one fluid or
            # an α per row (α = 0 on a tenth of the rows: the base primitive's group)
            method = "quad" if rng.random() < 0.3 else "fast"
            al = (10 ** rng.uniform(-12, -6.5, n) if rng.random() < 0.5
                  else np.full(n, 10 ** rng.uniform(-10, -7)))
            al[rng.random(n) < 0.1] = 0.0
            df = squeeze_out(tab, theory=theory, ratios=RATIOS, du=du, times=TIMES,
                             alpha_pv=al, method=method, **kw)
            ft = tire_footprint(tab, theory=theory, alpha_pv=al, method=method,
                                footprint_length=rng.uniform(0.01, 0.3, n),
                                speed=rng.uniform(1.0, 60.0, n), **kw)
            evals += 2 * n
            v = check_barus(df, ft)
        else:
            raise ValueError(path)
    except Exception as exc:  # noqa: BLE001 - a crash is a violation of "never crash"
        tally.exception("squeeze", path, exc, n, inputs)
        traceback.print_exc(limit=2)
        tally.cases[("squeeze", path)] += n
        return
    tally.seconds[("squeeze", path)] += time.perf_counter() - t0
    tally.cases[("squeeze", path)] += len(df)
    tally.evals[("squeeze", path)] += evals
    tally.add("squeeze", path, v, df, inputs)


#: status names of the Barus squeeze-out and tire rows
BARUS_STATUS = {"ok", "trapped", "out_of_table", "piezo_limit", "start_below_equilibrium",
                "overflow"}


def check_barus(df, ft):
    """Invariants of a Barus squeeze-out frame ``df`` (targets RATIOS, du, TIMES) and tire
    frame ``ft`` of the same rows: no unknown status; every time >= 0; on "ok" rows every
    time and ū finite, ū(t) within [ū∞, ū(0)] and non-increasing in t, ū(0) at t = 0 and ū∞
    at t = inf; the tire's ū at the exit within [ū∞, ū(0)] on its "ok" rows."""
    v = {}
    n = len(df)
    st = df["status"].astype(str).to_numpy()
    sf = ft["status"].astype(str).to_numpy()
    v["status_unknown"] = ~np.isin(st, list(BARUS_STATUS)) | ~np.isin(sf, list(BARUS_STATUS))
    ok = st == "ok"
    tcols = [c for c in df.columns if c.startswith("t_")]
    ucols = [column_name("u_at", t) for t in TIMES]
    T = df[tcols].to_numpy(float)
    U = df[ucols].to_numpy(float)
    ui, us = df["u_inf"].to_numpy(float), df["u_start"].to_numpy(float)
    with np.errstate(invalid="ignore"):
        v["time_negative"] = (T < 0).any(axis=1) | (ft[[c for c in ft.columns if
                                                        c.startswith("t_")]].to_numpy(float)
                                                     < 0).any(axis=1)
        v["nonfinite_unflagged"] = ok & ~(np.isfinite(T).all(axis=1) & np.isfinite(U).all(axis=1)
                                          & np.isfinite(ui))
        band = 1e-12
        v["u_t_outside_film"] = ok & ((U < ui[:, None] * (1 - band)).any(axis=1)
                                      | (U > us[:, None] * (1 + band)).any(axis=1))
        v["u_t_increasing"] = ok & (np.diff(U, axis=1) > band * us[:, None]).any(axis=1)
        v["u_t0_not_start"] = ok & (U[:, 0] != us)
        v["u_tinf_not_u_inf"] = ok & (U[:, -1] != ui)
        okt = sf == "ok"
        ue, ui_t, us_t = (ft[c].to_numpy(float) for c in ("u_exit", "u_inf", "u_start"))
        v["tire_exit_outside_film"] = okt & ~((ue >= ui_t * (1 - band))
                                              & (ue <= us_t * (1 + band)))
    assert len(v["u_t0_not_start"]) == n
    return v


# =============================================================================== seal
def seal_uniform_chunk(tally, tab, name, theory, rng, n, pairs):
    kw = inv.seal_uniform_cases(tab, theory, rng, n)
    inputs = dict(table=name, theory=theory)
    t0 = time.perf_counter()
    evals = 0
    try:
        df = seal_leak(tab, theory=theory, **kw)
        evals += n
        v = inv.check_seal(df)
        v.update(inv.check_unique_columns(df))
        Q = df["Q"].to_numpy(float)
        if pairs:
            lo, hi = tab.p_range
            # p0 up by a random factor (same dp, p_b): Q must not increase
            f = np.exp(rng.uniform(0, 1, n) * 10 ** rng.uniform(-12, 0, n))
            p0u = kw["p0"] * f
            if theory == "average":
                p0u = np.minimum(p0u, hi * kw["E_star"])
            Qu = seal_leak(tab, theory=theory, **dict(kw, p0=p0u))["Q"].to_numpy(float)
            v["Q_increasing_in_p0"] = inv.monotone_violations(np.stack([Q, Qu], 1), False, 1e-9)
            # dp up (clip below the p0 so both sides are below or at lift-off)
            dpu = kw["dp"] * np.exp(10 ** rng.uniform(-12, 0, n))
            Qd = seal_leak(tab, theory=theory, **dict(kw, dp=dpu))["Q"].to_numpy(float)
            v["Q_decreasing_in_dp"] = inv.monotone_violations(np.stack([Q, Qd], 1), True, 1e-9)
            # dp split in two
            s = rng.uniform(0, 1, n)
            q1 = seal_leak(tab, theory=theory, **dict(kw, dp=s * kw["dp"]))["Q"].to_numpy(float)
            q2 = seal_leak(tab, theory=theory, **dict(kw, dp=(1 - s) * kw["dp"],
                                                      p_b=kw["p_b"] + s * kw["dp"]))["Q"].to_numpy(float)
            # below lift-off, as in tests/test_invariants.py: not within 4 ulp of the lift-off
            # equality (p_a = p_b + dp is rounded; a split piece can round past it, Q = inf)
            below = ((kw["p_b"] + kw["dp"] < kw["p0"]) & ~df["percolated"].to_numpy(bool)
                     & ~inv._near_lift_off(kw["p_b"] + kw["dp"], kw["p0"]))
            with np.errstate(invalid="ignore"):
                v["Q_not_additive_in_dp_1e-7"] = below & (np.abs(q1 + q2 - Q) > 1e-7 * Q)
            # scaling (p0, dp, p_b, E*) -> k(...)
            kk = 10 ** rng.uniform(-1, 1)
            Qs = seal_leak(tab, theory=theory, **dict(kw, p0=kw["p0"] * kk, dp=kw["dp"] * kk,
                                                      p_b=kw["p_b"] * kk,
                                                      E_star=kw["E_star"] * kk))["Q"].to_numpy(float)
            near = np.abs(kw["p_b"] + kw["dp"] - kw["p0"]) <= 1e-14 * kw["p0"]
            v["Q_scaling_pressures_E_1e-9"] = ~near & inv._rel_mismatch(Q * kk, Qs, 1e-9)
            # dp -> 0 limit (eq. 32) at dp = 1e-12 (p0 - p_b), inside the table
            c = kw["p0"] - kw["p_b"]
            dps = 1e-12 * c
            ql = seal_leak(tab, theory=theory, **dict(kw, dp=dps))["Q"].to_numpy(float)
            inr = (c / kw["E_star"] >= lo) & (c / kw["E_star"] <= hi) & \
                (c < tab.percolation_pressure(theory, 1.0) * kw["E_star"])
            sig = np.full(n, np.nan)
            sig[inr] = tab.conductivity(c[inr], kw["E_star"][inr], kw["eta"][inr], theory)
            want = kw["L_y"] / kw["L"] * sig * dps
            with np.errstate(invalid="ignore"):
                v["Q_small_dp_limit_eq32_1e-6"] = inr & (np.abs(ql - want) > inv.ACC * want)
            evals += 5 * n
    except Exception as exc:  # noqa: BLE001
        tally.exception("seal", "uniform", exc, n, inputs)
        traceback.print_exc(limit=2)
        tally.cases[("seal", "uniform")] += n
        return
    tally.seconds[("seal", "uniform")] += time.perf_counter() - t0
    tally.cases[("seal", "uniform")] += n
    tally.evals[("seal", "uniform")] += evals
    tally.add("seal", "uniform", v, df, inputs)


def seal_hertz_chunk(tally, tab, name, theory, rng, n):
    inputs = dict(table=name, theory=theory)
    lo, hi = tab.p_range
    top = hi if theory == "average" else 1.3 * min(hi, tab.percolation_pressure(theory, 1.0))
    E = 10 ** rng.uniform(5, 10, n)
    R = 10 ** rng.uniform(-4, -1, n)
    pH = np.exp(rng.uniform(math.log(lo), math.log(top), n)) * E
    if theory == "average":
        pH = np.minimum(pH, 0.999 * hi * E)
    fN = math.pi * R * pH ** 2 / E
    g = 10 ** rng.uniform(-15, 0, n)
    pick = rng.random(n)
    g = np.where(pick < 0.05, 1.0, g)
    g = np.where((pick >= 0.05) & (pick < 0.08), 1.0 + 10 ** rng.uniform(-9, 0, n), g)
    g = np.where((pick >= 0.08) & (pick < 0.1), 0.0, g)
    p_b = np.where(rng.random(n) < 0.3, rng.uniform(0, 0.5, n) * pH, 0.0)
    dp = g * (pH - p_b)
    kw = dict(R=R, f_N=fN, dp=dp, p_b=p_b, E_star=E, L_y=10 ** rng.uniform(-3, 0, n),
              eta=10 ** rng.uniform(-5, 2, n), profile="hertz")
    t0 = time.perf_counter()
    try:
        df = seal_leak(tab, theory=theory, **kw)
        v = inv.check_seal(df)
        Q = df["Q"].to_numpy(float)
        dpu = dp * np.exp(10 ** rng.uniform(-9, 0, n))
        Qd = seal_leak(tab, theory=theory, **dict(kw, dp=dpu))["Q"].to_numpy(float)
        v["Q_decreasing_in_dp_1e-6"] = inv.monotone_violations(np.stack([Q, Qd], 1), True, 1e-6)
        fu = fN * np.exp(rng.uniform(0, 0.5, n))
        if theory == "average":
            fu = np.minimum(fu, fN * (0.999 * hi * E / pH) ** 2)
        Qf = seal_leak(tab, theory=theory, **dict(kw, f_N=fu))["Q"].to_numpy(float)
        v["Q_increasing_in_f_N_1e-6"] = inv.monotone_violations(np.stack([Q, Qf], 1), False, 1e-6)
    except Exception as exc:  # noqa: BLE001
        tally.exception("seal", "hertz", exc, n, inputs)
        traceback.print_exc(limit=2)
        tally.cases[("seal", "hertz")] += n
        return
    tally.seconds[("seal", "hertz")] += time.perf_counter() - t0
    tally.cases[("seal", "hertz")] += n
    tally.evals[("seal", "hertz")] += 3 * n
    tally.add("seal", "hertz", v, df, inputs)


# =============================================================================== references
def _ref_draws(n_ref, budget):
    """(k, theory, table name) of the reference draws: the 3 theories × 4 tables in turn, at
    most ``n_ref`` of them, until ``budget`` seconds have passed."""
    t_end = time.perf_counter() + budget
    k = 0
    while k < n_ref and time.perf_counter() < t_end:
        yield k, THEORIES[k % 3], NAMES[(k // 3) % 4]
        k += 1


def squeeze_refs(tables, rng, n_ref, budget):
    """Worst relative error of t_ratio_1.1 / t_ratio_1.01 (fast path, default and given
    start) against SqueezeReference (direct core + scipy quad)."""
    from reference.squeeze_reference import SqueezeReference, tau0
    from fastcontact.tables.defaults import default_surface
    worst = {}
    done = Counter()
    for _k, theory, name in _ref_draws(n_ref, budget):
        tab = tables[name]
        lo, hi = tab.p_range
        top = min(hi, 0.9 * tab.percolation_pressure(theory, 1.0))
        pbar = math.exp(rng.uniform(math.log(lo) + 1.0, math.log(top)))
        E = 10 ** rng.uniform(6, 8)
        R, eta = 10 ** rng.uniform(-3, -1), 10 ** rng.uniform(-4, 0)
        given = rng.random() < 0.4
        try:
            df = squeeze_out(tab, p0=pbar * E, E_star=E, R=R, eta=eta, theory=theory,
                             ratios=(1.1, 1.01))
            if bool(df["trapped"].iloc[0]):
                continue
            us = None
            if given:
                u_inf = float(df["u_inf"].iloc[0])
                us = u_inf * (1.2 + 3 * rng.random())
                df = squeeze_out(tab, p0=pbar * E, E_star=E, R=R, eta=eta, theory=theory,
                                 ratios=(1.1, 1.01), u_start=us)
            ref = SqueezeReference(default_surface(name), E, theory, pbar * E)
            vs = None if us is None else us / tab.h_rms
            t0 = tau0(eta, R, tab.h_rms, pbar * E)
            for r in (1.1, 1.01):
                want = ref.t_ratio(r, vs) * t0
                got = float(df[f"t_ratio_{r:g}"].iloc[0]) if f"t_ratio_{r:g}" in df else \
                    float(df[[c for c in df.columns if c.startswith("t_ratio_")][0 if r == 1.1 else 1]].iloc[0])
                if want > 0:
                    e = abs(got / want - 1)
                else:
                    e = abs(got)
                key = (theory, "given u_start" if given else "default start")
                if e > worst.get(key, (-1,))[0]:
                    worst[key] = (e, dict(table=name, p0=pbar * E, E_star=E, R=R, eta=eta,
                                          u_start=us, ratio=r, got=got, ref=want))
            # the tire's ū at its footprint exit (an inversion): the reference time from the
            # start to that ū is the footprint time
            u0 = float(df["u_start"].iloc[0])
            t_fp = 0.5 * float(df["t_ratio_1.1"].iloc[0])
            ft = tire_footprint(tab, p0=pbar * E, E_star=E, R=R, eta=eta, theory=theory,
                                footprint_length=t_fp, speed=1.0, u_start=u0)
            ue = float(ft["u_exit"].iloc[0])
            e = abs(ref.time(ue / tab.h_rms, u0 / tab.h_rms) * t0 / t_fp - 1)
            key = (theory, "tire exit (time to u_exit)")
            if e > worst.get(key, (-1,))[0]:
                worst[key] = (e, dict(table=name, p0=pbar * E, E_star=E, R=R, eta=eta,
                                      u_start=u0, t_footprint=t_fp, u_exit=ue))
            done[theory] += 1
        except Exception as exc:  # noqa: BLE001
            worst[(theory, "error")] = (math.inf, dict(table=name, pbar=pbar, error=str(exc)[:200]))
    return worst, done


#: rows of a Barus reference call that shares α E* (the one-fluid time primitive serves a group
#: of at least this many rows, fastcontact/squeeze/_barus_time.py MIN_GROUP_ROWS)
BARUS_GROUP = 20_000


def barus_refs(tables, rng, n_ref, budget):
    """Worst relative error of the Barus squeeze-out's t_ratio_1.1 from the default start
    (or, where that lies above the tables, 0.9 of their top separation; method="fast")
    against the radial Reynolds equation with η(p) integrated directly
    (``tests/reference/ext_reynolds.py``: solve_ivp + brentq + quad, no reduced pressure),
    α p0 log-uniform in [1e-4, 0.6]: alternately a row of its own α (the per-case kernel) and
    a row among BARUS_GROUP sharing α E* (the one-fluid time primitive)."""
    from reference.ext_reynolds import squeeze_time
    worst = {}
    done = Counter()
    for k, theory, name in _ref_draws(n_ref, budget):
        group = (k // 12) % 2 == 1
        tab = tables[name]
        lo, hi = tab.p_range
        top = min(hi, 0.9 * tab.percolation_pressure(theory, 1.0))
        E = 10 ** rng.uniform(6, 8)
        pbar = math.exp(rng.uniform(math.log(lo) + 1.0, math.log(top)))
        p0 = pbar * E
        R, eta = 10 ** rng.uniform(-3, -1), 10 ** rng.uniform(-4, 0)
        alpha = 10 ** rng.uniform(-4, math.log10(0.6)) / p0
        path = "barus, one fluid" if group else "barus, alpha per row"
        try:
            # a group shares α E* (its G primitive); otherwise a second row of another α
            # keeps both in the per-case kernel (a call of one fluid always builds its G)
            n = BARUS_GROUP if group else 2
            p0s = p0 * np.exp(rng.uniform(-0.5, 0.0, n))
            p0s[0] = p0
            al = alpha if group else np.array([alpha, 0.5 * alpha])
            # the reference reads the tables' p_cont(ū): a start inside them (the default
            # start where it is, else 0.9 of the tables' top separation if that is above 1.2 ū∞)
            base = squeeze_out(tab, p0=p0, E_star=E, R=R, eta=eta, theory=theory, ratios=())
            u_top = 0.9 * tab.u_range[1] * tab.h_rms
            us = None if float(base["u_start"].iloc[0]) < u_top else u_top
            if us is not None and us < 1.2 * float(base["u_inf"].iloc[0]):
                continue
            df = squeeze_out(tab, p0=p0s, E_star=E, R=R, eta=eta, theory=theory,
                             alpha_pv=al, ratios=(1.1,), u_start=us, method="fast")
            r = df.iloc[0]
            served = sum(g["cases_served"] for g in df.attrs.get("barus_time_primitive") or ()
                         if g["primitive"] == "Barus G")
            if served != (n if group else 0):  # the path this draw is about
                raise RuntimeError(f"{served} of {n} rows on a G primitive ({path})")
            if r["status"] != "ok":
                continue
            u0, ui = float(r["u_start"]), float(r["u_inf"])
            want = squeeze_time(tab, theory, p0, E, R, eta, alpha, u0, 1.1 * ui, ui, rtol=1e-10)
            got = float(r["t_ratio_1.1"])
            e = abs(got / want - 1) if want > 0 else abs(got)
            # the footprint exit of the same rows (an inversion on the same path): the
            # reference time from the start to the engine's ū_exit is the footprint time
            ft = tire_footprint(tab, p0=p0s, E_star=E, R=R, eta=eta, theory=theory,
                                alpha_pv=al, footprint_length=0.5 * got, speed=1.0,
                                u_start=u0, method="fast")
            ue = float(ft["u_exit"].iloc[0])
            e_exit = abs(squeeze_time(tab, theory, float(ft["p_eval"].iloc[0]), E, R, eta,
                                      alpha, u0, ue, ui, rtol=1e-10) / (0.5 * got) - 1)
            for key, err in (((theory, path), e), ((theory, path + ", tire exit"), e_exit)):
                if err > worst.get(key, (-1,))[0]:
                    worst[key] = (err, dict(table=name, p0=p0, E_star=E, alpha_p0=alpha * p0,
                                            got=got, ref=want))
                done[key] += 1
        except Exception as exc:  # noqa: BLE001
            worst[(theory, "barus error")] = (math.inf, dict(table=name, p0=p0,
                                                             error=str(exc)[:200]))
    return worst, done


def uniform_ref_exact_width(psd, *, p0, dp, L, L_y, E_star, eta, theory, p_b=0.0):
    """Q of a flat ring with the interval [c - dp, c], c = p0 - p_b, of exact width dp.

    ``tests/reference/seal_reference.uniform_reference`` forms the lower limit as
    p0 - (p_b + dp), which loses the width to cancellation when dp/p0 is below ~1e-8 (its
    relative error is ~1e-16 p0/dp). For dp <= 1e-3 c this integrates σ_eff directly on
    Gauss–Legendre nodes c - dp (1 - z)/2 (16 nodes, the width enters only as the factor
    dp/2; σ_eff is smooth on such a short interval), σ_eff from the direct core."""
    from reference.seal_reference import sigma_direct, uniform_reference
    c = p0 - p_b
    if dp == 0:
        return 0.0
    if dp > 1e-3 * c:
        return uniform_reference(psd, p0=p0, dp=dp, L=L, L_y=L_y, E_star=E_star, eta=eta,
                                 theory=theory, p_b=p_b)[0]
    z, w = np.polynomial.legendre.leggauss(16)
    p = c - 0.5 * dp * (1.0 - z)
    s = sigma_direct(psd, p, E_star, eta, theory)
    return L_y / L * 0.5 * dp * float(np.sum(w * s))


def seal_refs(tables, rng, n_ref, budget):
    from reference.seal_reference import SigmaInterp, hertz_reference
    from fastcontact.tables.defaults import default_surface
    worst = {}
    done = Counter()
    for k, theory, name in _ref_draws(n_ref, budget):
        hertz = k % 5 == 4 and theory != "emt"
        tab = tables[name]
        lo, hi = tab.p_range
        top = min(0.999 * hi, 0.999 * tab.percolation_pressure(theory, 1.0))
        E = 10 ** rng.uniform(6, 8)
        eta, L_y = 1e-3, 0.1
        psd = default_surface(name)
        try:
            if not hertz:
                p0 = math.exp(rng.uniform(math.log(lo) + 2, math.log(top))) * E
                rel = 10 ** rng.uniform(-13, 0) if rng.random() < 0.8 else 1.0
                p_b = rng.uniform(0, 0.3) * p0 if rng.random() < 0.3 else 0.0
                dp = rel * (p0 - p_b)
                L = 1e-3
                got = float(seal_leak(tab, p0=p0, dp=dp, L=L, L_y=L_y, E_star=E, eta=eta,
                                      theory=theory, p_b=p_b)["Q"].iloc[0])
                want = uniform_ref_exact_width(psd, p0=p0, dp=dp, L=L, L_y=L_y, E_star=E,
                                               eta=eta, theory=theory, p_b=p_b)
                key = (theory, "uniform")
                info = dict(table=name, p0=p0, dp=dp, p_b=p_b, E_star=E, got=got, ref=want)
            else:
                R = 10 ** rng.uniform(-3.5, -2)
                pH = math.exp(rng.uniform(math.log(lo) + 3, math.log(top))) * E
                fN = math.pi * R * pH ** 2 / E
                dp = rng.uniform(0.05, 0.95) * pH
                # the reference clips σ below p_lo: keep p_lo far below the contact's p_H
                # (p_lo = 1e-16 E* put the 2026-11-25 reference 1.9e-6 off at p_H = 2.4e-13 E*)
                si = SigmaInterp(psd, E_star=E, eta=eta, theory=theory,
                                 p_lo=min(1e-16, 1e-6 * pH / E) * E, p_hi=pH)
                want, _, _ = hertz_reference(si, R=R, f_N=fN, dp=dp, L_y=L_y, E_star=E)
                got = float(seal_leak(tab, R=R, f_N=fN, dp=dp, L_y=L_y, E_star=E, eta=eta,
                                      theory=theory, profile="hertz")["Q"].iloc[0])
                key = (theory, "hertz")
                info = dict(table=name, R=R, f_N=fN, dp=dp, E_star=E, got=got, ref=want)
            e = abs(got / want - 1) if want > 0 else abs(got)
            if e > worst.get(key, (-1,))[0]:
                worst[key] = (e, info)
            done[key] += 1
        except Exception as exc:  # noqa: BLE001
            worst[(theory, "error")] = (math.inf, dict(table=name, error=str(exc)[:200]))
    return worst, done


# =============================================================================== driver
def _split(total, parts):
    base = [total // parts] * parts
    for i in range(total - sum(base)):
        base[i] += 1
    return base


def run(args):
    rng = np.random.default_rng(args.seed)
    tdir = Path(args.tables_dir) if args.tables_dir else ROOT / "tables"
    tables = {n: Tables.from_parquet(tdir / f"{n}.parquet") for n in NAMES}
    tally = Tally()
    combos = [(n, th) for n in NAMES for th in THEORIES]
    t_all = time.perf_counter()
    # squeeze paths
    fr = dict(quad=args.frac_quad, u_start=args.frac_start, times=args.frac_times,
              barus=args.frac_barus)
    fr["fast"] = 1.0 - sum(fr.values())
    for path, f in fr.items():
        total = int(round(args.n_squeeze * f))
        for (name, theory), nc in zip(combos, _split(total, len(combos))):
            left = nc
            while left > 0:
                m = min(args.chunk, left)
                squeeze_chunk(tally, tables[name], name, theory, rng, m, path)
                left -= m
        print(f"squeeze {path}: {tally.cases[('squeeze', path)]} cases, "
              f"{tally.seconds[('squeeze', path)]:.1f} s", flush=True)
    # seal
    for (name, theory), nc in zip(combos, _split(args.n_seal, len(combos))):
        left = nc
        while left > 0:
            m = min(args.chunk, left)
            seal_uniform_chunk(tally, tables[name], name, theory, rng, m,
                               pairs=rng.random() < args.frac_pairs)
            left -= m
    print(f"seal uniform: {tally.cases[('seal', 'uniform')]} cases, "
          f"{tally.seconds[('seal', 'uniform')]:.1f} s", flush=True)
    t_h = time.perf_counter() + args.hertz_budget
    for (name, theory), nc in zip(combos, _split(args.n_hertz, len(combos))):
        left = nc
        t_c = time.perf_counter() + args.hertz_budget / len(combos)
        while left > 0 and time.perf_counter() < min(t_c, t_h):
            m = min(50, left)
            seal_hertz_chunk(tally, tables[name], name, theory, rng, m)
            left -= m
    print(f"seal hertz: {tally.cases[('seal', 'hertz')]} cases, "
          f"{tally.seconds[('seal', 'hertz')]:.1f} s", flush=True)
    t_fuzz = time.perf_counter() - t_all
    t0 = time.perf_counter()
    sq_ref = squeeze_refs(tables, rng, args.n_ref_squeeze, args.ref_budget)
    se_ref = seal_refs(tables, rng, args.n_ref_seal, args.ref_budget)
    ba_ref = barus_refs(tables, rng, args.n_ref_barus, args.ref_budget)
    t_ref = time.perf_counter() - t0
    return tally, sq_ref, se_ref, ba_ref, t_fuzz, t_ref


def _fmt(x):
    if isinstance(x, float):
        return f"{x:.6g}"
    return str(x)


def render(args, tally, sq_ref, se_ref, ba_ref, t_fuzz, t_ref):
    L = [f"## {args.label}", ""]
    import fastcontact
    L.append(f"Run {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {machine()}; "
             f"fastcontact from `{Path(fastcontact.__file__).parent.parent}`.")
    L.append(f"Command: `python bench/bench_fuzz.py {' '.join(sys.argv[1:])}`; "
             f"fuzz {t_fuzz:.0f} s, references {t_ref:.0f} s.")
    L.append("")
    L.append("| engine | path | cases | evaluations (incl. paired) | time [s] | evaluations/s | violations (all invariants) |")
    L.append("|---|---|---|---|---|---|---|")
    for key in sorted(tally.cases):
        nv = sum(v for k, v in tally.viol.items() if k[:2] == key)
        s = tally.seconds[key]
        ev = tally.evals[key]
        L.append(f"| {key[0]} | {key[1]} | {tally.cases[key]:,} | {ev:,} | {s:.1f} | "
                 f"{(ev / s if s else 0):.3g} | {nv:,} |")
    for eng in ("squeeze", "seal"):
        tot = sum(v for k, v in tally.cases.items() if k[0] == eng)
        L.append(f"| **{eng}** | all | **{tot:,}** | | | | "
                 f"**{sum(v for k, v in tally.viol.items() if k[0] == eng):,}** |")
    L.append("")
    L.append("Violations per invariant (rows; 0 = holds on every case fuzzed; invariants not "
             "listed for a path were checked and held):")
    L.append("")
    L.append("| engine | path | invariant | rows violating | first example |")
    L.append("|---|---|---|---|---|")
    any_v = False
    for key in sorted(tally.viol):
        if tally.viol[key]:
            any_v = True
            ex = tally.examples.get(key, {})
            exs = ", ".join(f"{k}={_fmt(v)}" for k, v in ex.items())
            L.append(f"| {key[0]} | {key[1]} | {key[2]} | {tally.viol[key]:,} | {exs} |")
    if not any_v:
        L.append("| — | — | none | 0 | |")
    checked = sorted({k[2] for k in tally.viol})
    L.append("")
    L.append(f"Invariants checked: {', '.join(checked)}.")
    L.append("")
    L.append("Worst relative error against the independent references (random subsample):")
    L.append("")
    L.append("| engine | theory | path | cases | worst rel. error | case |")
    L.append("|---|---|---|---|---|---|")
    worst, done = sq_ref
    for key in sorted(worst):
        e, info = worst[key]
        L.append(f"| squeeze | {key[0]} | {key[1]} | {done[key[0]]} | {e:.2e} | "
                 f"{', '.join(f'{k}={_fmt(v)}' for k, v in info.items())} |")
    for eng, (worst, done) in (("seal", se_ref), ("squeeze", ba_ref)):
        for key in sorted(worst):
            e, info = worst[key]
            L.append(f"| {eng} | {key[0]} | {key[1]} | {done[key]} | {e:.2e} | "
                     f"{', '.join(f'{k}={_fmt(v)}' for k, v in info.items())} |")
    L.append("")
    return "\n".join(L)


HEADER = """# Fuzz benchmark of the engines' invariants (issue 15.2)

Written by `bench/bench_fuzz.py` (see its docstring for the domain fuzzed); the invariants
are the functions of `tests/test_invariants.py` and are stated for users in
`docs/invariants.md`. Each section is one run; "before" is the code before the issue-11/15
engine fixes, "after" the code once they landed.
"""


def write_section(path, label, text):
    path = Path(path)
    old = path.read_text() if path.exists() else HEADER
    parts = re.split(r"(?m)^(?=## )", old)
    head, secs = parts[0], parts[1:]
    secs = [s for s in secs if not s.startswith(f"## {label}\n")]
    secs.append(text.rstrip() + "\n\n")
    tmp = path.with_suffix(".tmp")
    tmp.write_text(head.rstrip() + "\n\n" + "".join(secs))
    os.replace(tmp, path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-squeeze", type=float, default=1e7)
    ap.add_argument("--n-seal", type=float, default=1e7)
    ap.add_argument("--n-hertz", type=float, default=1e5)
    ap.add_argument("--hertz-budget", type=float, default=120.0,
                    help="seconds for the Hertz O-ring cases (shared by the 12 table x theory "
                         "combinations; the O-ring solver is slow on the old code)")
    ap.add_argument("--frac-quad", type=float, default=0.004)
    ap.add_argument("--frac-start", type=float, default=0.006)
    ap.add_argument("--frac-times", type=float, default=0.002)
    ap.add_argument("--frac-barus", type=float, default=0.002,
                    help="fraction of squeeze cases through the Barus engines (squeeze + tire)")
    ap.add_argument("--frac-pairs", type=float, default=0.5,
                    help="fraction of seal chunks re-evaluated in pairs (monotonicity etc.)")
    ap.add_argument("--chunk", type=int, default=200_000)
    ap.add_argument("--n-ref-squeeze", type=int, default=60)
    ap.add_argument("--n-ref-seal", type=int, default=60)
    ap.add_argument("--n-ref-barus", type=int, default=24,
                    help="Barus squeeze-out references (radial Reynolds with η(p))")
    ap.add_argument("--ref-budget", type=float, default=600.0, help="seconds per reference set")
    ap.add_argument("--seed", type=int, default=20261123)
    ap.add_argument("--label", default="run")
    ap.add_argument("--tables-dir", default=None,
                    help="folder of the 4 embedded tables (default: the repository's tables/); "
                         "with PYTHONPATH=<old checkout> this fuzzes older code")
    ap.add_argument("--out", default=str(HERE / "fuzz_results.md"))
    ap.add_argument("--quick", action="store_true", help="1e5 cases per engine, 12 references")
    args = ap.parse_args(argv)
    if args.quick:
        args.n_squeeze, args.n_seal, args.n_hertz = 1e5, 1e5, 600
        args.hertz_budget = min(args.hertz_budget, 60.0)
        args.ref_budget = min(args.ref_budget, 120.0)
        args.n_ref_squeeze = args.n_ref_seal = args.n_ref_barus = 12
        args.chunk = min(args.chunk, 20_000)
        args.frac_quad, args.frac_start, args.frac_times, args.frac_barus = 0.1, 0.1, 0.05, 0.05
    args.n_squeeze, args.n_seal, args.n_hertz = int(args.n_squeeze), int(args.n_seal), int(args.n_hertz)
    res = run(args)
    text = render(args, *res)
    print(text)
    write_section(args.out, args.label, text)


if __name__ == "__main__":
    main()
