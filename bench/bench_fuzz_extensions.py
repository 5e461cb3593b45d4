"""Fuzz of the extension paths that bench_fuzz.py does not draw: the Barus and Roelands seals,
the anisotropic seal, the squeeze and tire histories and the asperity cascade (issues 14, 15).

Random inputs over wide ranges (every theory of the embedded asphalt_024mm tables; moduli
1e5-1e10 Pa, pressures from 1e-9 E* to past percolation, α 1e-10-1e-6 1/Pa, outlet pressures,
O-ring radii and loads, R, η, starts and times over many decades). Counted per path:

* every output finite, or its row flagged by ``status`` (seals: not "ok"; histories: none
  may be non-finite); no negative leak rate or time;
* physics the engines must respect whatever their method: a pressure-dependent viscosity never
  raises the leak rate (Q(α > 0) <= Q(α = 0) on the same rows, relative slack 1e-9); flow along
  the long correlation length is at least the flow across it (Q_x >= Q_y, γ_T = 3); ū(t) never
  rises and never falls below ū∞; the cascade's parallel total <= its sequential total >= the
  base level's t*;
* anything raised: a ValueError whose text names a parameter and says "invalid" counts as a
  refused input, any other exception as a violation.

* a reference subsample (``--n-ref`` draws within ``--ref-budget`` s): Q of Barus and
  Roelands flat rings and O-rings (p_b = 0 and > 0; an O-ring alone and as row 0 of a call of
  one fluid) against the independent solutions of ``tests/reference/ext_reynolds.py`` and
  ``ext_roelands.py`` (η(p) integrated directly), off by more than the engines' stated
  accuracy counting as a violation.

    python bench/bench_fuzz_extensions.py [--n 4000] [--seed 20261202] [--n-ref 48]

Writes bench/fuzz_extensions_results.md (bench/collect.py gathers it into RESULTS.md).
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import subprocess
import sys
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

import fastcontact as fc
from fastcontact.defaults import default_surface
from fastcontact.squeeze.asperity import asperity_summary

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from machine_info import cpu_model  # noqa: E402

THEORIES = ("critical_junction", "emt", "average")
#: slack of Q(α > 0) <= Q(0): the engines' stated accuracy (flat ring <= 1e-7 against the
#: direct quadrature of σ̄; the O-rings' panel tolerance PIEZO_PANEL_TOL = 1e-6)
SLACK = {"uniform": 1e-7, "hertz": 1e-6}


def _pi_trust(tab, theory):
    """The largest p/E* at which the tables verify σ̄ (σ̄ above their floor; inf: "average")."""
    if theory == "average":
        return np.inf
    s = tab.data[f"sigma_{theory}"]
    return float(tab.data["p_over_E"][s > tab.info["sigma_floor"]].max())


class Tally:
    def __init__(self):
        self.rows = Counter()
        self.viol = Counter()
        self.refused = Counter()
        self.first = {}
        self.info = Counter()
        self.ref_worst = {}
        self.ref_failed = Counter()

    def check(self, path, name, bad, detail=""):
        k = int(np.count_nonzero(bad))
        self.viol[(path, name)] += k
        if k and (path, name) not in self.first:
            self.first[(path, name)] = detail


def _lu(rng, lo, hi, n):
    return np.exp(rng.uniform(np.log(lo), np.log(hi), n))


def _call(tally, path, f, **kw):
    try:
        return f(**kw)
    except ValueError as e:
        ok = "invalid" in str(e)
        tally.refused[path] += 1
        tally.check(path, "ValueError without 'invalid'", not ok, str(e)[:160])
    except Exception as e:  # noqa: BLE001 - counted, not swallowed silently
        tally.check(path, f"raised {type(e).__name__}", True, str(e)[:160])
    return None


def seal_piezo(tally, tab, rng, n):
    for theory in THEORIES:
        for profile in ("uniform", "hertz"):
            for visc in ("barus", "roelands"):
                path = f"seal {profile} {visc} {theory}"
                E = _lu(rng, 1e5, 1e10, n)
                p0 = E * _lu(rng, 1e-7, 3.0, n)
                kw = dict(dp=p0 * _lu(rng, 1e-6, 2.0, n), L_y=_lu(rng, 1e-3, 1.0, n), E_star=E,
                          eta=_lu(rng, 1e-4, 10.0, n), theory=theory,
                          p_b=np.where(rng.random(n) < 0.3, p0 * _lu(rng, 1e-4, 1.0, n), 0.0))
                if profile == "uniform":
                    kw.update(p0=p0, L=_lu(rng, 1e-4, 1e-1, n))
                else:
                    kw.update(profile="hertz", R=_lu(rng, 1e-3, 0.1, n), f_N=_lu(rng, 1e-2, 1e4, n))
                if visc == "barus":
                    kw["alpha_pv"] = _lu(rng, 1e-10, 1e-6, n)
                else:
                    kw.update(viscosity="roelands", roelands_z=rng.uniform(0.4, 0.8),
                              roelands_p_r=1.96e8)
                df = _call(tally, path, fc.seal_leak, tables=tab, **kw)
                base_kw = {k: v for k, v in kw.items() if not k.startswith(("alpha", "roel", "visc"))}
                base = _call(tally, path, fc.seal_leak, tables=tab, **base_kw)
                if df is None or base is None:
                    continue
                tally.rows[path] += n
                Q, st = df["Q"].to_numpy(float), df["status"].astype(str).to_numpy()
                tally.check(path, "non-finite Q with status ok", (st == "ok") & ~np.isfinite(Q))
                tally.check(path, "negative Q", np.isfinite(Q) & (Q < 0))
                Q0 = base["Q"].to_numpy(float)
                both = np.isfinite(Q) & np.isfinite(Q0) & (st == "ok")
                if profile == "hertz":
                    # the peak contact pressure p_H - p_f(peak) >= p_H - p_a past the tables'
                    # last verified σ̄ (σ̄ > sigma_floor): W is then dominated by unverified σ̄,
                    # the row must say "near_percolation" (Q ~ 1e-37 m3/s was reported "ok");
                    # with only p_H - p_b past it the peak may or may not reach it: not compared
                    pt = _pi_trust(tab, theory)
                    pH = df["p_max"].to_numpy(float)
                    sure = (pH - df["p_a"].to_numpy(float)) / E > pt
                    maybe = ~sure & ((pH - kw["p_b"]) / E > pt)
                    tally.check(path, "status ok with p_H - p_a past the verified sigma",
                                (st == "ok") & sure,
                                f"Q = {float(np.min(np.where((st == 'ok') & sure, Q, np.inf))):.3g} m3/s")
                    tally.check(path, "not near_percolation with p_H - p_a past the verified sigma",
                                sure & ~np.isin(st, ["near_percolation", "percolated", "open"]))
                    tally.info[path] = int(np.count_nonzero(maybe & (st == "ok")))
                    both &= ~(sure | maybe)
                bst = base["status"].astype(str).to_numpy()
                tally.check(path, "ok where the constant-viscosity engine is near_percolation",
                            (st == "ok") & (bst == "near_percolation"))
                slack = SLACK[profile]
                r = np.where(both & (Q0 > 0), Q / np.where(Q0 > 0, Q0, 1) - 1, 0)
                tally.check(path, f"Q(alpha) > Q(0) (1 + {slack:g})", both & (r > slack),
                            f"max Q/Q0 - 1 = {r.max():.2e}")


def seal_anisotropic(tally, tab_aniso, rng, n):
    for profile in ("uniform", "hertz"):
        path = f"seal {profile} anisotropic (gamma_T = 3)"
        E = _lu(rng, 1e5, 1e10, n)
        p0 = E * _lu(rng, 1e-7, 3.0, n)
        kw = dict(dp=p0 * _lu(rng, 1e-6, 2.0, n), L_y=_lu(rng, 1e-3, 1.0, n), E_star=E,
                  eta=_lu(rng, 1e-4, 10.0, n), theory="emt",
                  p_b=np.where(rng.random(n) < 0.3, p0 * _lu(rng, 1e-4, 1.0, n), 0.0),
                  alpha_pv=np.where(rng.random(n) < 0.5, 0.0, _lu(rng, 1e-10, 1e-7, n)))
        if profile == "uniform":
            kw.update(p0=p0, L=_lu(rng, 1e-4, 1e-1, n))
        else:
            kw.update(profile="hertz", R=_lu(rng, 1e-3, 0.1, n), f_N=_lu(rng, 1e-2, 1e4, n))
        out = {d: _call(tally, path, fc.seal_leak, tables=tab_aniso, direction=d, **kw)
               for d in ("x", "y")}
        if any(v is None for v in out.values()):
            continue
        tally.rows[path] += 2 * n
        for d, df in out.items():
            Q, st = df["Q"].to_numpy(float), df["status"].astype(str).to_numpy()
            tally.check(path, f"non-finite Q with status ok ({d})", (st == "ok") & ~np.isfinite(Q))
            tally.check(path, f"negative Q ({d})", np.isfinite(Q) & (Q < 0))
        qx, qy = (out[d]["Q"].to_numpy(float) for d in ("x", "y"))
        both = np.isfinite(qx) & np.isfinite(qy) & (out["x"]["status"].astype(str).to_numpy() == "ok")
        tally.check(path, "Q_x < Q_y", both & (qx < qy * (1 - 1e-9)))


def histories(tally, tab, rng, n):
    for k in range(n):
        theory = THEORIES[k % 3]
        E = float(_lu(rng, 1e5, 1e10, 1)[0])
        case = dict(p0=E * float(_lu(rng, 1e-12, 3.0, 1)[0]), E_star=E,
                    R=float(_lu(rng, 1e-6, 10.0, 1)[0]), eta=float(_lu(rng, 1e-5, 1e3, 1)[0]))
        t = np.concatenate([[0.0], _lu(rng, 1e-12, 1e12, 40)])  # tire_history: finite t
        us = float(_lu(rng, 1e-7, 1e-1, 1)[0]) if rng.random() < 0.6 else None
        for name in ("squeeze_history", "tire_history"):
            path = name
            if name == "squeeze_history":
                df = _call(tally, path, fc.squeeze_history, tables=tab, theory=theory, t=t,
                           u_start=us, **case)
            else:
                df = _call(tally, path, fc.tire_history, tables=tab, theory=theory, t=t,
                           u_start=0.01 if us is None else us, **case)
            if df is None:
                continue
            tally.rows[path] += t.size
            u = df["u"].to_numpy(float)[np.argsort(df["t"].to_numpy(float), kind="stable")]
            tally.check(path, "non-finite u", ~np.isfinite(u), str(case))
            tally.check(path, "u rises with t", np.diff(u) > 1e-12 * np.abs(u[:-1]), str(case))
            ui = df.attrs.get("u_inf", np.nan)
            if not df.attrs.get("trapped", False):
                tally.check(path, "u below u_inf", u < ui * (1 - 1e-9), str(case))


def asperity(tally, tab, rng, n):
    for theory in THEORIES:
        path = f"asperity_summary {theory}"
        E = _lu(rng, 1e5, 1e10, n)
        df = _call(tally, path, asperity_summary, tables=tab, p0=E * _lu(rng, 1e-9, 2.0, n),
                   E_star=E, R=_lu(rng, 1e-4, 1.0, n), eta=_lu(rng, 1e-4, 10.0, n), theory=theory)
        if df is None:
            continue
        tally.rows[path] += n
        oot = df["out_of_table"].to_numpy(bool)
        for c in ("t_star_base", "t_star_top", "t_sequential", "t_parallel", "t_sequential_open",
                  "t_parallel_open"):
            v = df[c].to_numpy(float)
            tally.check(path, f"{c} NaN or < 0 on a row in the tables", ~oot & (np.isnan(v) | (v < 0)))
        ts, tp, tb = (df[c].to_numpy(float) for c in ("t_sequential", "t_parallel", "t_star_base"))
        fin = ~oot & np.isfinite(ts)
        tally.check(path, "t_parallel > t_sequential", fin & (tp > ts * (1 + 1e-12)))
        tally.check(path, "t_star_base > t_sequential", fin & (tb > ts * (1 + 1e-12)))


#: relative error of Q against the independent references counted as a violation: the
#: engines' stated accuracy (O-ring panels PIEZO_PANEL_TOL = 1e-6; flat rings <= 1e-7)
REF_TOL = {"uniform": 1e-7, "hertz": 1e-6}
#: O-rings of one fluid per reference call: large enough that the fluid's verified O-ring table
#: pays for itself (the call builds and reads it); row 0 is the reference row
REF_BATCH = 2000


def seal_references(tally, tab, rng, n_ref, budget):
    """Q of random Barus and Roelands seals against the independent references of
    ``tests/reference/ext_reynolds.py`` / ``ext_roelands.py`` (η(p) integrated directly:
    solve_bvp for flat rings, adaptive DOP853 shooting for O-rings; no reduced pressure),
    σ0 from the tables' public ``conductivity``. Draws: each theory in turn, flat ring or
    O-ring, Barus or Roelands, p_b = 0 or up to 0.9 p_a; an O-ring draw is row 0 of a call of
    REF_BATCH O-rings of one fluid on one rubber (the fluid's table path) and, alone, of a call
    of its own (the per-row solver). Worst error per path into ``tally.info_ref``."""
    sys.path.insert(0, str(HERE.parent / "tests"))
    from reference import ext_reynolds as rb
    from reference import ext_roelands as rr
    from fastcontact.seal._inputs import hertz_contact
    t_end = time.perf_counter() + budget
    for k in range(n_ref):
        if time.perf_counter() > t_end:
            break
        theory = THEORIES[k % 3]
        profile = "hertz" if k % 2 == 0 else "uniform"
        visc = "barus" if (k // 2) % 2 == 0 else "roelands"
        E = float(_lu(rng, 1e6, 1e8, 1)[0])
        eta, L_y = 1e-3, 0.1
        pt = min(_pi_trust(tab, theory), 0.9 * tab.percolation_pressure(theory, 1.0),
                 tab.p_range[1])
        pH = E * float(_lu(rng, 1e-3, 0.9 * pt, 1)[0])
        p_a = pH * rng.uniform(0.05, 0.95)
        p_b = p_a * rng.uniform(0.0, 0.9) if rng.random() < 0.5 else 0.0
        alpha = float(_lu(rng, 1e-3, 3.0, 1)[0]) / pH
        # solve_bvp's iterates may leave the zone's contact pressures: σ0 clipped to the tables
        plo, phi = tab.p_range[0] * E * (1 + 1e-7), tab.p_range[1] * E * (1 - 1e-7)
        sigma0 = lambda pc: tab.conductivity(np.clip(pc, plo, phi), E, eta, theory)
        kw = dict(L_y=L_y, E_star=E, eta=eta, theory=theory, p_b=p_b, dp=p_a - p_b)
        if visc == "barus":
            kw["alpha_pv"] = alpha
            law = rb.barus(alpha)
        else:
            z = rng.uniform(0.4, 0.8)
            pr_ = 1.96e8
            kw.update(viscosity="roelands", roelands_z=z, roelands_p_r=pr_)
            A = math.log(eta) + 9.67
            law = lambda p, A=A, z=z, pr_=pr_: np.exp(A * ((1.0 + np.maximum(np.asarray(p) - p_b, 0.0) / pr_) ** z - 1.0))
        path = f"reference {profile} {visc} {theory}" + (" p_b > 0" if p_b > 0 else "")
        L = 1e-3
        R = float(_lu(rng, 1e-3, 1e-2, 1)[0])
        f_N = math.pi * R * pH ** 2 / E                   # p_H of the Hertz line contact
        try:  # the reference first: where it does not converge the draw is not counted
            if profile == "uniform":
                want = _flat_reference(rb, rr, visc, sigma0, pH, L, p_a, p_b, alpha, law)[0] * L_y
            else:
                a = float(hertz_contact(R, f_N, E)[0])
                shoot = rb.hertz_shoot if visc == "barus" else rr.hertz_shoot
                want = shoot(sigma0, pH, a, p_a, p_b, alpha if visc == "barus" else law) * L_y
        except Exception:  # noqa: BLE001 - scipy's solve_bvp / brentq gave up
            tally.ref_failed[path] += 1
            continue
        try:
            if profile == "uniform":
                rows = {"alone": fc.seal_leak(tab, p0=pH, L=L, **kw)}
            else:
                Rs = np.full(REF_BATCH, R)
                Rs[1:] *= np.exp(rng.uniform(-0.3, 0.3, REF_BATCH - 1))
                rows = {"alone": fc.seal_leak(tab, profile="hertz", R=R, f_N=f_N, **kw),
                        "batch": fc.seal_leak(tab, profile="hertz", R=Rs, f_N=f_N, **kw)}
        except Exception as e:  # noqa: BLE001 - counted
            tally.check(path, f"raised {type(e).__name__}", True, str(e)[:160])
            continue
        for how, df in rows.items():
            st = str(df["status"].iloc[0])
            tally.rows[path] += 1
            if st != "ok":
                tally.info[path] += 1
                continue
            err = abs(float(df["Q"].iloc[0]) / want - 1.0)
            key = (path, how)
            tally.ref_worst[key] = max(tally.ref_worst.get(key, 0.0), err)
            tally.check(path, f"Q ({how}) off the reference by > {REF_TOL[profile]:g}",
                        err > REF_TOL[profile], f"rel. err {err:.2e}, p_H/E* {pH / E:.3g}, "
                        f"p_a/p_H {p_a / pH:.3f}, p_b/p_a {p_b / p_a:.3f}, α p_H {alpha * pH:.3g}")


def _flat_reference(rb, rr, visc, sigma0, p0, L, p_a, p_b, alpha, law):
    """(q [m²/s], solution) of a flat ring by solve_bvp with η(p)."""
    if visc == "barus":
        return rb.seal_bvp(sigma0, lambda x: p0 + 0.0 * x, 0.0, L, p_a, p_b, alpha)
    return rr.seal_bvp(sigma0, lambda x: p0 + 0.0 * x, 0.0, L, p_a, p_b, law)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=4000, help="rows per seal and asperity path")
    ap.add_argument("--n-history", type=int, default=300, help="single cases per history path")
    ap.add_argument("--seed", type=int, default=20261202)
    ap.add_argument("--n-ref", type=int, default=48, help="seal reference draws")
    ap.add_argument("--ref-budget", type=float, default=300.0, help="seconds for them")
    ap.add_argument("--out", default=str(HERE / "fuzz_extensions_results.md"))
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    rng = np.random.default_rng(args.seed)
    tab = fc.load_default_tables("asphalt_024mm")
    t0 = time.perf_counter()
    tab_aniso = fc.precompute(default_surface("asphalt_024mm"), theories=("emt",), anisotropy=3.0)
    tally = Tally()
    seal_piezo(tally, tab, rng, args.n)
    seal_anisotropic(tally, tab_aniso, rng, args.n)
    histories(tally, tab, rng, args.n_history)
    asperity(tally, tab, rng, args.n)
    seal_references(tally, tab, rng, args.n_ref, args.ref_budget)
    dt = time.perf_counter() - t0
    rev = subprocess.run(["git", "-C", str(HERE.parent), "rev-parse", "--short", "HEAD"],
                         capture_output=True, text=True).stdout.strip()
    paths = sorted(set(tally.rows) | set(tally.refused) | {p for p, _ in tally.viol})
    lines = ["## Fuzz of the extension paths (`bench/bench_fuzz_extensions.py`)", "",
             f"Run {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}: `python "
             f"bench/bench_fuzz_extensions.py --n {args.n} --n-history {args.n_history} --seed "
             f"{args.seed} --n-ref {args.n_ref} --ref-budget {args.ref_budget:g}` at git {rev}; {cpu_model()}, {os.cpu_count()} cores, Python "
             f"{platform.python_version()}; {dt:.0f} s. Tables: embedded asphalt_024mm (every "
             f"theory) and its γ_T = 3 effective-medium build. Rows = outputs checked (histories: "
             f"time points); refused = calls that raised a ValueError naming the input.", "",
             "Hertz O-rings whose p_H - p_b (but not p_H - p_a) lies past the tables' last "
             "verified σ̄ may reach unverified σ̄ at the peak; they are counted (\"maybe "
             "unverified\") and left out of the Q(α) <= Q(0) comparison.", "",
             "| path | rows checked | refused calls | maybe unverified | violations |",
             "|---|---|---|---|---|"]
    for p in paths:
        v = {name: k for (pp, name), k in tally.viol.items() if pp == p and k}
        txt = "; ".join(f"{name}: {k} (first: {tally.first.get((p, name), '')})"
                        for name, k in v.items()) or "0"
        lines.append(f"| {p} | {tally.rows[p]:,} | {tally.refused[p]} | {tally.info[p]} | {txt} |")
    total = sum(tally.viol.values())
    lines += ["", f"Total violations: {total}.", "",
              "Worst relative error of Q against the independent references (reference paths "
              "above: rows = draws evaluated, \"maybe unverified\" column = draws not \"ok\"; "
              "alone = a call of its own, batch = row 0 of a call of "
              f"{REF_BATCH} O-rings of one fluid):", "",
              "| path | call | worst rel. error |", "|---|---|---|"]
    lines += [f"| {p} | {how} | {e:.2e} |" for (p, how), e in sorted(tally.ref_worst.items())]
    failed = sum(tally.ref_failed.values())
    lines += ["", f"Draws whose reference did not converge (scipy; not counted): {failed}"
              + (f" ({', '.join(f'{p}: {k}' for p, k in sorted(tally.ref_failed.items()))})"
                 if failed else "") + ".", ""]
    text = "\n".join(lines)
    out = Path(args.out)
    old = out.read_text() if out.is_file() else ""
    notes = old[old.index("\nNotes ("):] if "\nNotes (" in old else ""
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text(text + notes)
    os.replace(tmp, out)
    print(text)
    return 0 if total == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
