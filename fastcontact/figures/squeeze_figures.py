"""Figures of the general squeeze-out theory on tables — the paper's Figs. 4, 5 and 6.

``make_squeeze_figures(outdir)`` writes

* ``squeeze_copper_u_of_t.png`` (paper Fig. 4): ū(t) on log–log axes for a rubber block
  (E = 2.3 MPa, ν = 0.5, R = 1.5 cm) on a copper-like surface (h_rms = 0.12 mm) at
  p0 = 0.2 and 1.4 MPa: curve 1 average-separation theory, curve 2 critical-junction theory,
  thin grey the flat substrate (Stefan law from the same ū(0)).
* ``squeeze_copper_pcont.png`` (paper Fig. 5): p_cont(t)/p0 against log10 t, same cases.
* ``squeeze_copper_flow_factor.png`` (paper Fig. 6): pressure flow factor φ_p against ū,
  Bruggeman effective medium, contact pressures up to and past percolation (p0 = 1 MPa
  marked).

The copper surface of the paper is a measured spectrum (its ref. "HeatTransfer"); the
stand-in here is self-affine, H = 0.8, q0 = 1.15e3 1/m, q1 = 1e6 1/m, h_rms = 0.12 mm:
q0 reproduces the paper's κ = p0/(βE*) ≈ 1.5 and 10.3 (β = 0.044), and q1 sets the rms
slope (1.03) so that the contact percolates at 1.07 MPa, between the two pressures — the
paper's finding that at 1.4 MPa fluid stays trapped and carries > 10 % of the load. The
viscosity (not given in the paper) is water's, 1e-3 Pa·s. ū(0): p_cont = 1e-3 p0.

Rendering uses the Agg canvas directly (no pyplot); every PNG is written under a
temporary name in ``outdir`` and renamed into place (atomic).

Run as a script: ``python -m fastcontact.figures.squeeze_figures [outdir]``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ..squeeze import squeeze_history
from ..surface.psd import SelfAffinePSD
from ..tables import precompute
from .canvas import new_figure as _new_figure, save_png as _save_atomic

__all__ = ["make_squeeze_figures", "copper_surface", "COPPER"]

COPPER = dict(h_rms=1.2e-4, hurst=0.8, q0=1.15e3, q1=1e6)
E_YOUNG = 2.3e6
POISSON = 0.5
E_STAR = E_YOUNG / (1.0 - POISSON ** 2)
RADIUS = 0.015
ETA = 1e-3
PRESSURES = (0.2e6, 1.4e6)
THEORY_LABEL = {"average": "1: average separation", "critical_junction": "2: critical junction"}


def copper_surface():
    return SelfAffinePSD(**COPPER)


def _histories(tables, t):
    out = {}
    for p0 in PRESSURES:
        for th in ("average", "critical_junction"):
            out[(p0, th)] = squeeze_history(tables, p0, E_STAR, RADIUS, ETA, th, t=t)
    return out


def _fig_u(hist, t, path):
    fig = _new_figure(figsize=(6.6, 4.9))
    ax = fig.subplots()
    colors = {"average": "tab:blue", "critical_junction": "tab:red"}
    for p0 in PRESSURES:
        flat = hist[(p0, "average")]["u_flat"].to_numpy()
        ax.plot(t, flat * 1e6, color="0.55", lw=1.0)
        for th in ("average", "critical_junction"):
            h = hist[(p0, th)]
            ax.plot(t, h["u"] * 1e6, color=colors[th], lw=1.6)
            a = h.attrs
            if a["trapped"]:
                ax.axhline(a["u_trap"] * 1e6, color=colors[th], lw=0.7, ls="--")
            elif np.isfinite(a["t_star"]) and a["t_star"] < t[-1]:
                ax.plot(a["t_star"], 1.01 * a["u_inf"] * 1e6, "o", mfc="none", mec="k", ms=5)
        ax.annotate(f"p0 = {p0 / 1e6:g} MPa", xy=(t[-1], hist[(p0, 'average')]["u"].iloc[-1] * 1e6),
                    xytext=(-4, 4), textcoords="offset points", ha="right", fontsize=9)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(t[0], t[-1])
    ax.set_xlabel("time t [s]")
    ax.set_ylabel(r"separation $\bar u$ [$\mu$m]")
    ax.plot([], [], color="tab:blue", label=THEORY_LABEL["average"])
    ax.plot([], [], color="tab:red", label=THEORY_LABEL["critical_junction"])
    ax.plot([], [], color="0.55", label="flat substrate (Stefan)")
    ax.plot([], [], color="tab:red", ls="--", lw=0.7, label=r"$\bar u_{\rm trap}$ (fluid trapped)")
    ax.plot([], [], "o", mfc="none", mec="k", ms=5, label=r"$t^*$: $\bar u = 1.01\bar u_\infty$")
    ax.legend(fontsize=8, loc="lower left", frameon=False)
    ax.set_title("Rubber block on copper-like surface (paper Fig. 4): "
                 f"E = {E_YOUNG / 1e6:g} MPa, R = {RADIUS * 100:g} cm, "
                 r"$h_{\rm rms}$ = 0.12 mm", fontsize=9)
    ax.grid(True, which="major", lw=0.3, alpha=0.5)
    return _save_atomic(fig, path)


def _fig_p(hist, t, path):
    fig = _new_figure(figsize=(6.6, 4.9))
    ax = fig.subplots()
    colors = {"average": "tab:blue", "critical_junction": "tab:red"}
    styles = {PRESSURES[0]: "-", PRESSURES[1]: "-."}
    lt = np.log10(t)
    for p0 in PRESSURES:
        for th in ("average", "critical_junction"):
            h = hist[(p0, th)]
            ax.plot(lt, h["p_cont_over_p0"], color=colors[th], ls=styles[p0], lw=1.6,
                    label=f"{THEORY_LABEL[th]}, p0 = {p0 / 1e6:g} MPa")
            if h.attrs["trapped"]:
                ax.axhline(1 - h.attrs["fluid_load_fraction"], color=colors[th], lw=0.7, ls=":")
                ax.annotate(f"fluid keeps {100 * h.attrs['fluid_load_fraction']:.0f} % of the load",
                            xy=(lt[-1], 1 - h.attrs["fluid_load_fraction"]), xytext=(-4, 4),
                            textcoords="offset points", ha="right", va="bottom", fontsize=8,
                            color=colors[th])
    ax.set_xlim(lt[0], lt[-1])
    ax.set_ylim(0, 1.05)
    ax.set_xlabel(r"$\log_{10}$ (time t / s)")
    ax.set_ylabel(r"$p_{\rm cont}(t)/p_0$")
    ax.legend(fontsize=8, loc="upper left", frameon=False)
    ax.set_title("Normalised contact pressure (paper Fig. 5), same system as Fig. 4", fontsize=9)
    ax.grid(True, lw=0.3, alpha=0.5)
    return _save_atomic(fig, path)


def _fig_phi(tables, path):
    p_perc = tables.percolation_pressure("emt", E_STAR)
    p = np.geomspace(1e2, 1.12e6, 500)
    u = tables.mean_separation(p, E_STAR)
    phi = tables.flow_factor(p, E_STAR, "emt")
    fig = _new_figure(figsize=(6.4, 4.6))
    ax = fig.subplots()
    ax.plot(u * 1e6, phi, color="tab:green", lw=1.8, label="Bruggeman effective medium")
    u_perc = float(np.ravel(tables.mean_separation(p_perc, E_STAR))[0])
    u_1mpa = float(np.ravel(tables.mean_separation(1e6, E_STAR))[0])
    ax.axvline(u_perc * 1e6, color="k", lw=0.7, ls="--")
    ax.annotate(f"percolation\n(p = {p_perc / 1e6:.2f} MPa)", xy=(u_perc * 1e6, 0.5),
                xytext=(4, 0), textcoords="offset points", fontsize=8)
    ax.axvline(u_1mpa * 1e6, color="0.5", lw=0.7, ls=":")
    ax.annotate("p = 1 MPa", xy=(u_1mpa * 1e6, 0.85), xytext=(4, 0), textcoords="offset points",
                fontsize=8, color="0.4")
    ax.set_xscale("log")
    ax.set_ylim(-0.02, 1.05)
    ax.set_xlabel(r"average separation $\bar u$ [$\mu$m]")
    ax.set_ylabel(r"pressure flow factor $\phi_p = 12\eta\sigma_{\rm eff}/\bar u^3$")
    ax.set_title(r"Flow factor on the copper-like surface (paper Fig. 6), $E$ = 2.3 MPa, "
                 r"$h_{\rm rms}$ = 0.12 mm", fontsize=9)
    ax.legend(fontsize=8, loc="lower right", frameon=False)
    ax.grid(True, which="major", lw=0.3, alpha=0.5)
    return _save_atomic(fig, path)


def make_squeeze_figures(outdir, tables=None) -> list[Path]:
    """Write the three PNGs into ``outdir`` (created if needed); return their paths.

    ``tables``: optional precomputed tables of :func:`copper_surface` holding "average",
    "critical_junction" and "emt" (built here otherwise, ~10 s).
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    if tables is None:
        tables = precompute(copper_surface())
    t = np.geomspace(1e-6, 1e8, 400)
    hist = _histories(tables, t)
    return [_fig_u(hist, t, outdir / "squeeze_copper_u_of_t.png"),
            _fig_p(hist, t, outdir / "squeeze_copper_pcont.png"),
            _fig_phi(tables, outdir / "squeeze_copper_flow_factor.png")]


if __name__ == "__main__":  # pragma: no cover
    for p in make_squeeze_figures(sys.argv[1] if len(sys.argv) > 1 else "figures"):
        print(p)
