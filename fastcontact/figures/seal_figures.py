"""The paper's seal experiment (Secs. 7–8): leak rate against Δp and the profiles across the ring.

Set-up (paper Sec. 7): PDMS ring (Sylgard 184, E = 2.3 MPa, ν = 0.5 → E* = E/(1 − ν²) = 3.07 MPa),
inner/outer diameter 4/6 cm → seal width L = 1 cm and length L_y = π·5 cm (mean circumference),
nominal pressure p0 = 11.8 kPa (uniform: flat ring), water (η = 1.0 mPa·s) column up to
H = 1.2 m → Δp = ρgH up to 11.8 kPa = p0, p_b = 0, junction factor α_cj = 0.54.

Surface: sand-blasted PMMA, h_rms = 34 µm. Its measured spectrum is not published as data;
the stand-in is the embedded default ``pmma_34um`` (self-affine, H = 0.8, q0 = 2π/1 cm,
roll-off q_r = 2π/2 mm, q1 = 1e7 1/m; see :mod:`fastcontact.defaults`), whose tables carry
α_cj = 1: the critical-junction conductivity is rescaled by 0.54³ (exact, σ ∝ α_cj³).

``seal_experiment(outdir)`` writes

* ``seal_leak_rate.csv`` / ``.png`` (paper Fig. 11): Q [m³/s] against Δp [kPa] on a log axis,
  critical-junction (α_cj = 0.54) and effective-medium theories, plus the average-separation
  theory for comparison. The last point Δp = p0 is the lift-off equality (flagged): the inlet
  contact pressure is 0 there and Q is the finite limit Δp → p0⁻, reached with infinite slope;
  beyond it the ring is open (Q = ∞, not drawn).
* ``seal_profiles.csv`` and ``seal_contact_pressure.png`` / ``seal_separation.png`` (paper
  Figs. 12–13): p_cont(x) and ū(x) for Δp/p0 = 0, 0.5, 1 (critical junction). At Δp = p0 the
  inlet (x = 0) has p_cont = 0 and ū → ∞ (the inlet lifts off, flagged in the CSV).

``make_seal_figures(outdir, tables=None)`` runs the experiment and returns the written paths.
Every file is written to a temporary name in ``outdir`` and renamed into place (atomic).

Run as a script: ``python -m fastcontact.figures.seal_figures [outdir]``.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib.ticker
import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .._core.io import atomic_path
from ..seal import seal_leak, seal_profile
from ..tables.defaults import load_default_tables

__all__ = ["make_seal_figures", "seal_experiment", "EXPERIMENT"]

E_YOUNG = 2.3e6
NU = 0.5
EXPERIMENT = dict(
    E_star=E_YOUNG / (1.0 - NU ** 2),      # Pa
    p0=11.8e3,                             # Pa
    L=0.01,                                # m, (6 cm − 4 cm)/2
    L_y=math.pi * 0.05,                    # m, mean circumference
    eta=1.0e-3,                            # Pa s, water
    alpha_cj=0.54,
    p_b=0.0,
    rho=1000.0, g=9.81,                    # water column: Δp = ρ g H
)
SURFACE = "pmma_34um"
RATIOS = (0.0, 0.5, 1.0)
COLORS = {0.0: "tab:blue", 0.5: "tab:green", 1.0: "tab:red"}
THEORY_STYLE = {"critical_junction": ("tab:red", "-", r"critical junction ($\alpha = 0.54$)"),
                "emt": ("tab:blue", "--", "effective medium"),
                "average": ("0.5", ":", "average separation")}


# --------------------------------------------------------------------------- atomic writes
def _atomic(path: Path, write):
    with atomic_path(path, suffix=Path(path).suffix + ".tmp") as tmp:
        write(tmp)
    return Path(path)


def _save_png(fig, path):
    return _atomic(path, lambda tmp: fig.savefig(tmp, format="png", dpi=150))


def _save_csv(df, path, header_lines=()):
    def write(tmp):
        with open(tmp, "w", newline="") as fh:
            for line in header_lines:
                fh.write(f"# {line}\n")
            df.to_csv(fh, index=False, float_format="%.10g")
    return _atomic(path, write)


def _new_figure(**kw):
    fig = Figure(layout="constrained", **kw)
    FigureCanvasAgg(fig)
    return fig


def _tables(tables):
    if tables is not None:
        return tables
    return load_default_tables(SURFACE)


def _description(tables):
    s = tables.surface
    return (f"surface {s!r}; tables alpha_cj = {tables.options.get('alpha_cj')}, a_perc = "
            f"{tables.options.get('a_perc')}; E* = {EXPERIMENT['E_star']:.6g} Pa, p0 = "
            f"{EXPERIMENT['p0']:g} Pa, L = {EXPERIMENT['L']:g} m, L_y = {EXPERIMENT['L_y']:.6g} m, "
            f"eta = {EXPERIMENT['eta']:g} Pa s, alpha_cj = {EXPERIMENT['alpha_cj']:g}, p_b = 0")


# --------------------------------------------------------------------------- experiment
def _leak_table(tables):
    ex = EXPERIMENT
    p0 = ex["p0"]
    # dense towards Δp = p0, where Q rises steeply (infinite slope at the lift-off equality)
    frac = np.unique(np.concatenate([[0.0], np.logspace(-3, -2, 5), np.linspace(0.01, 0.9, 90),
                                     1.0 - np.logspace(-1, -6, 26), [1.0]]))
    dp = frac * p0
    out = {"dp_Pa": dp, "dp_over_p0": frac, "water_column_m": dp / (ex["rho"] * ex["g"])}
    for th in ("critical_junction", "emt", "average"):
        if th not in tables.theories:
            continue
        df = seal_leak(tables, p0=p0, dp=dp, L=ex["L"], L_y=ex["L_y"], E_star=ex["E_star"],
                       eta=ex["eta"], theory=th, alpha_cj=ex["alpha_cj"], p_b=ex["p_b"])
        out[f"Q_{th}_m3_per_s"] = df.Q.to_numpy()
        out[f"lift_off_{th}"] = df.lift_off.to_numpy()
        out[f"percolated_{th}"] = df.percolated.to_numpy()
    return pd.DataFrame(out)


def _profiles(tables, n=401):
    ex = EXPERIMENT
    frames = []
    for r in RATIOS:
        pr = seal_profile(tables, p0=ex["p0"], dp=r * ex["p0"], L=ex["L"], L_y=ex["L_y"],
                          E_star=ex["E_star"], eta=ex["eta"], theory="critical_junction",
                          alpha_cj=ex["alpha_cj"], p_b=ex["p_b"], n=n)
        frames.append(pd.DataFrame({
            "dp_over_p0": r, "x_m": pr.x, "p_cont_Pa": pr.p_cont, "p_fluid_Pa": pr.p_fluid,
            "u_m": pr.u, "u_over_h_rms": pr.u / tables.h_rms, "sigma_eff_m3_per_Pa_s": pr.sigma_eff,
            "open": pr.open, "lift_off": pr.attrs["lift_off"], "Q_m3_per_s": pr.attrs["Q"]}))
    return pd.concat(frames, ignore_index=True)


def _figure_leak(leak, tables, path):
    ex = EXPERIMENT
    fig = _new_figure(figsize=(6.4, 4.8))
    ax = fig.subplots()
    dpk = leak.dp_Pa.to_numpy() / 1e3
    for th, (col, ls, lab) in THEORY_STYLE.items():
        key = f"Q_{th}_m3_per_s"
        if key not in leak:
            continue
        Q = leak[key].to_numpy()
        ok = np.isfinite(Q) & (Q > 0)
        ax.plot(dpk[ok], Q[ok], color=col, ls=ls, lw=1.6, label=lab)
        lift = leak[f"lift_off_{th}"].to_numpy() & ok
        if lift.any():
            ax.plot(dpk[lift], Q[lift], "o", mfc="none", mec=col, ms=7)
    ax.plot([], [], "o", mfc="none", mec="k", ms=7,
            label=r"$\Delta p = p_0$: inlet lifts off (flag)")
    ax.set_yscale("log")
    ax.axvline(ex["p0"] / 1e3, color="0.6", lw=0.8, ls="-.")
    ax.text(ex["p0"] / 1e3, 0.03, r"$\Delta p = p_0$ ", color="0.4", va="bottom", ha="right",
            fontsize=9, transform=ax.get_xaxis_transform())
    ax.set_xlim(0.0, 12.5)
    ax.set_xlabel(r"fluid pressure difference $\Delta p = p_{\rm a} - p_{\rm b}$ (kPa)")
    ax.set_ylabel(r"leak rate $\dot Q$ (m$^3$/s)")
    fig.suptitle(rf"Seal leak rate: PDMS ring, $p_0 = {ex['p0'] / 1e3:g}$ kPa, on sand-blasted "
                 rf"PMMA ($h_{{\rm rms}} = {tables.h_rms * 1e6:.0f}\,\mu$m)", fontsize=10)
    ax.legend(loc="upper left", fontsize=9, frameon=False)
    ax.grid(True, which="major", lw=0.3, alpha=0.5)
    sec = ax.secondary_xaxis("top", functions=(lambda k: k * 1e3 / (ex["rho"] * ex["g"]),
                                               lambda H: H * ex["rho"] * ex["g"] / 1e3))
    sec.set_xlabel(r"water column $H$ (m)", fontsize=9)
    return _save_png(fig, path)


def _figure_profile(prof, tables, path, what):
    ex = EXPERIMENT
    fig = _new_figure(figsize=(6.4, 4.8))
    ax = fig.subplots()
    for r in RATIOS:
        sub = prof[prof.dp_over_p0 == r]
        x = sub.x_m.to_numpy() * 100.0
        if what == "p":
            y = sub.p_cont_Pa.to_numpy() / 1e3
        else:
            y = sub.u_m.to_numpy() * 1e6
        ok = np.isfinite(y)
        ax.plot(x[ok], y[ok], color=COLORS[r], lw=1.8,
                label=rf"$(p_{{\rm a}} - p_{{\rm b}})/p_0 = {r:g}$")
    if what == "p":
        ax.set_ylabel(r"contact pressure $p_{\rm cont}$ (kPa)")
        ax.set_ylim(0.0, 1.08 * ex["p0"] / 1e3)
        ax.annotate(r"$p_{\rm cont} = 0$ at the inlet: lift-off", xy=(0.0, 0.0),
                    xytext=(0.12, 2.0), fontsize=8, color=COLORS[1.0],
                    arrowprops=dict(arrowstyle="->", color=COLORS[1.0], lw=0.8))
        ax.set_title(rf"Contact pressure across the seal, $p_0 = {ex['p0'] / 1e3:g}$ kPa",
                     fontsize=10)
        ax.legend(loc="lower right", fontsize=9, frameon=False)
    else:
        sub = prof[prof.dp_over_p0 == 1.0]
        top = max(4.0 * float(np.nanmax(prof[prof.dp_over_p0 == 0.0].u_m)) * 1e6, 200.0)
        ax.set_ylim(0.0, top)
        xs = sub.x_m.to_numpy() * 100.0
        ys = sub.u_m.to_numpy() * 1e6
        x_exit = float(np.interp(-top, -ys[np.isfinite(ys)], xs[np.isfinite(ys)]))
        ax.annotate(r"$\bar u \to \infty$ at $x = 0$: the inlet lifts off", xy=(x_exit, top),
                    xytext=(0.28, 0.93 * top), fontsize=8, color=COLORS[1.0], va="center",
                    arrowprops=dict(arrowstyle="->", color=COLORS[1.0], lw=0.8))
        h = tables.h_rms * 1e6
        sec = ax.secondary_yaxis("right", functions=(lambda u: u / h, lambda v: v * h))
        sec.set_ylabel(r"$\bar u / h_{\rm rms}$")
        ax.set_ylabel(r"interfacial separation $\bar u$ ($\mu$m)")
        ax.set_title(rf"Interfacial separation across the seal, $h_{{\rm rms}} = "
                     rf"{tables.h_rms * 1e6:.0f}\,\mu$m", fontsize=10)
        ax.legend(loc="center right", fontsize=9, frameon=False)
    ax.set_xlim(0.0, ex["L"] * 100.0)
    ax.set_xlabel(r"distance from the high-pressure side $x$ (cm)")
    ax.xaxis.set_major_locator(matplotlib.ticker.MultipleLocator(0.2))
    ax.grid(True, which="major", lw=0.3, alpha=0.5)
    return _save_png(fig, path)


def seal_experiment(outdir, tables=None) -> list[Path]:
    """Compute the paper's seal experiment and write its CSV files and PNGs into ``outdir``."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    tables = _tables(tables)
    head = [_description(tables)]
    leak = _leak_table(tables)
    prof = _profiles(tables)
    paths = [
        _save_csv(leak, outdir / "seal_leak_rate.csv",
                  head + ["Q = inf would mean open (beyond lift-off); lift_off marks dp = p0"]),
        _save_csv(prof, outdir / "seal_profiles.csv",
                  head + ["critical junction; u = inf where p_cont = 0 (lift-off at the inlet)"]),
        _figure_leak(leak, tables, outdir / "seal_leak_rate.png"),
        _figure_profile(prof, tables, outdir / "seal_contact_pressure.png", "p"),
        _figure_profile(prof, tables, outdir / "seal_separation.png", "u"),
    ]
    return paths


def make_seal_figures(outdir, tables=None) -> list[Path]:
    """Write the seal-experiment figures (and their CSV data) into ``outdir``; return the paths.

    ``tables``: Tables of the PMMA stand-in (default: the embedded ``pmma_34um``) holding
    the critical-junction and effective-medium theories.
    """
    return seal_experiment(outdir, tables)


if __name__ == "__main__":  # pragma: no cover
    for p in make_seal_figures(sys.argv[1] if len(sys.argv) > 1 else "."):
        print(p)
