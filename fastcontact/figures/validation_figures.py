"""Figures of a theory-vs-reference comparison (:func:`fastcontact.validation.compare_theories`;
the ``--figure`` of ``fastcontact bem compare``)."""
from __future__ import annotations

import numpy as np

__all__ = ["comparison_figure"]


def _plt():
    try:
        import matplotlib
        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError('figures need matplotlib: pip install "fastcontact[plots]"') from None
    return plt


def comparison_figure(comparison, path=None, *, title=None):
    """Four panels against the reference contact area: errors of A, ū, σ_eff and t*.

    Parameters
    ----------
    comparison : pandas.DataFrame
        Output of :func:`fastcontact.validation.compare_theories`.
    path : str or Path, optional
        Write the figure there (PNG/PDF by suffix); the figure is returned either way.
    title : str, optional
        Figure title.
    """
    plt = _plt()
    fig, axs = plt.subplots(2, 2, figsize=(10, 7.5), constrained_layout=True)
    panels = (("area_err", "A/A0: theory/ref - 1"), ("u_err", "ū: theory/ref - 1"),
              ("sigma_err", "σ_eff: theory/ref"), ("t_ratio", "t*: theory/ref"))
    x = "p0"
    for ax, (col, lab) in zip(axs.ravel(), panels):
        if col not in comparison:
            ax.set_visible(False)
            continue
        for label, g in comparison.groupby("label", sort=False):
            y = g[col].to_numpy(float)
            if col == "sigma_err":
                y = y + 1.0
            ok = np.isfinite(y) & (y > 0 if col in ("sigma_err", "t_ratio") else True)
            ls = "--" if label.endswith("+cal") else "-"
            ax.plot(g[x].to_numpy(float)[ok], y[ok], ls, marker="o", ms=3, label=label)
        if col in ("sigma_err", "t_ratio"):
            ax.set_yscale("log")
            ax.axhline(1.0, color="k", lw=0.6)
        else:
            ax.axhline(0.0, color="k", lw=0.6)
        ax.set_xscale("log")
        ax.set_xlabel("nominal pressure p0 [Pa]")
        ax.set_ylabel(lab)
    stop = comparison.attrs.get("flow_stop", {})
    ref_stop = next((v["reference"] for v in stop.values()), None)
    if ref_stop and np.isfinite(ref_stop):
        for ax in axs.ravel():
            ax.axvline(ref_stop, color="gray", ls=":", lw=0.8)
    axs[0, 0].legend(fontsize=7)
    if title:
        fig.suptitle(title)
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig
