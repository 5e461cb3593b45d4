"""Figures of the reduced (asymptotic) squeeze-out model — the paper's Figs. 2 and 3.

``make_reduced_figures(outdir)`` writes

* ``reduced_u_of_t.png`` (paper Fig. 2): ū(t) [h_rms] against t [τ] for several κ, rough
  surface (red, eqs. 8 and 10) beside the flat surface (blue, Stefan law) started from the
  same ū(0); α = 0.5, β = 1. Dotted lines mark ū∞, open circles the squeeze-out time t*.
* ``reduced_tstar.png`` (paper Fig. 3): t* [τ] (with ū(t*) = 1.01 ū∞) and ū(t*) [h_rms]
  against log10 κ.

ū(0) is the module default of :mod:`fastcontact.reduced`, p_cont(0) = 1e-3 p0.

Rendering uses the Agg canvas directly (no pyplot, no global backend change); each PNG is
written to a temporary name in ``outdir`` and renamed into place (atomic).

Run as a script: ``python -m fastcontact.figures.reduced_figures [outdir]``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib.ticker
import numpy as np

from ..squeeze.reduced import flat_separation_reduced, squeeze_out_reduced, u_of_t_reduced
from .canvas import new_figure as _new_figure, save_png as _save_atomic

__all__ = ["make_reduced_figures"]

ALPHA = 0.5
BETA = 1.0
KAPPAS_FIG2 = (1e-4, 1e-3, 1e-2, 1e-1)
RATIO = 1.01


def _figure_u_of_t(path: Path) -> Path:
    fig = _new_figure(figsize=(6.4, 4.8))
    ax = fig.subplots()
    cases = squeeze_out_reduced(np.asarray(KAPPAS_FIG2), ALPHA, ratio=RATIO)
    t = np.logspace(-6, 1, 600)
    for row in cases.itertuples():
        u_rough = u_of_t_reduced(row.kappa, row.alpha, t, u_start=row.u_start)
        u_flat = flat_separation_reduced(row.u_start, t, row.alpha)
        ax.plot(t, u_flat, color="tab:blue", lw=1.2, zorder=2)
        ax.plot(t, u_rough, color="tab:red", lw=1.6, zorder=3)
        ax.axhline(row.u_inf, color="tab:red", lw=0.6, ls=":")
        ax.plot(row.t_star, row.u_star, "o", mfc="none", mec="k", ms=5)
        ax.annotate(rf"$\kappa = 10^{{{np.log10(row.kappa):.0f}}}$",
                    xy=(t[-1], row.u_inf), xytext=(-4, 3), textcoords="offset points",
                    ha="right", va="bottom", fontsize=9, color="tab:red")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(t[0], t[-1])
    ax.set_ylim(1.0, 50.0)
    ax.yaxis.set_major_locator(matplotlib.ticker.FixedLocator([1, 2, 5, 10, 20, 50]))
    ax.yaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel(r"time $t$ (units of $\tau = 3\eta R^2/(2\alpha h_{\rm rms}^2 p_0)$)")
    ax.set_ylabel(r"separation $\bar u$ (units of $h_{\rm rms}$)")
    ax.plot([], [], color="tab:red", label="rough (eqs. 8, 10)")
    ax.plot([], [], color="tab:blue", label="flat (Stefan law)")
    ax.plot([], [], color="tab:red", lw=0.6, ls=":", label=r"$\bar u_\infty$")
    ax.plot([], [], "o", mfc="none", mec="k", ms=5, label=rf"$t^*$: $\bar u = {RATIO}\,\bar u_\infty$")
    ax.legend(loc="lower left", fontsize=9, frameon=False)
    ax.set_title(rf"Squeeze-out, asymptotic model ($\alpha = {ALPHA}$, $\beta = {BETA:g}$, "
                 r"$p_{\rm cont}(0) = 10^{-3} p_0$)", fontsize=10)
    ax.grid(True, which="major", lw=0.3, alpha=0.5)
    return _save_atomic(fig, path)


def _figure_tstar(path: Path) -> Path:
    log_kappa = np.linspace(-8.0, -0.05, 300)
    res = squeeze_out_reduced(10.0**log_kappa, ALPHA, ratio=RATIO)
    fig = _new_figure(figsize=(6.4, 6.4))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(log_kappa, res.t_star, color="tab:red", lw=1.6)
    ax1.set_yscale("log")
    ax1.set_ylabel(r"squeeze-out time $t^*$ (units of $\tau$)")
    ax1.set_title(rf"$\bar u(t^*) = {RATIO}\,\bar u_\infty$, $\alpha = {ALPHA}$, "
                  rf"$\beta = {BETA:g}$, $p_{{\rm cont}}(0) = 10^{{-3}} p_0$", fontsize=10)
    ax2.plot(log_kappa, res.u_star, color="tab:red", lw=1.6)
    small = ~res.large_separation.to_numpy()
    if small.any():
        for ax in (ax1, ax2):
            ax.axvspan(log_kappa[small].min(), log_kappa[-1], color="0.85", lw=0)
        ax2.text(log_kappa[small].min() - 0.1, ax2.get_ylim()[1] * 0.9,
                 r"$\bar u_\infty < 2 h_{\rm rms}$: law (3) outside its range",
                 ha="right", va="top", fontsize=8, color="0.35")
    ax2.set_ylabel(r"final separation $\bar u(t^*)$ (units of $h_{\rm rms}$)")
    ax2.set_xlabel(r"$\log_{10} \kappa$,  $\kappa = p_0/(\beta E^*)$")
    ax2.set_ylim(bottom=0.0)
    for ax in (ax1, ax2):
        ax.grid(True, which="major", lw=0.3, alpha=0.5)
    ax2.set_xlim(log_kappa[0], 0.0)
    return _save_atomic(fig, path)


def make_reduced_figures(outdir) -> list[Path]:
    """Write the paper's Figs. 2 and 3 (reduced model) as PNGs into ``outdir``; return paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    return [_figure_u_of_t(outdir / "reduced_u_of_t.png"),
            _figure_tstar(outdir / "reduced_tstar.png")]


if __name__ == "__main__":  # pragma: no cover
    for p in make_reduced_figures(sys.argv[1] if len(sys.argv) > 1 else "."):
        print(p)
