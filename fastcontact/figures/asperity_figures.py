"""Figure of the asperity-scale squeeze-out levels (issue 14): t*(ζ) and the cascade bounds.

The levels come from :func:`fastcontact.squeeze.asperity.asperity_levels` (Lorenz & Persson
2010, end of Sec. 3; arXiv:1004.1037); docs/theory/extensions.md §1 states the cascade.
"""
from __future__ import annotations

import numpy as np

from .validation_figures import _plt

__all__ = ["plot_asperity_tstar"]


def plot_asperity_tstar(results, path=None, title=None):
    """Figure: t*(ζ) of each level and the two cascade bounds, one curve set per surface.

    Parameters
    ----------
    results : dict
        Label -> frame of :func:`fastcontact.squeeze.asperity.asperity_levels` (columns
        ``zeta`` [-], ``t_star``, ``t_sequential``, ``t_parallel`` [s], ``trapped``).
    path : str or Path, optional
        Write the figure there (PNG/PDF by suffix).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    for k, (label, df) in enumerate(results.items()):
        col = f"C{k}"
        ok = ~df["trapped"].to_numpy()
        ax.loglog(df["zeta"][ok], df["t_star"][ok], "o-", color=col, label=f"{label}: t*(ζ)")
        ax.loglog(df["zeta"], df["t_sequential"], "--", color=col, label=f"{label}: Σ t* (sequential)")
        ax.loglog(df["zeta"], df["t_parallel"], ":", color=col, label=f"{label}: max t* (parallel)")
        if np.isfinite(df.attrs.get("zeta_trap", np.inf)):
            ax.axvline(df.attrs["zeta_trap"], color=col, lw=0.8, alpha=0.6)
    ax.set_xlabel("magnification ζ [-]")
    ax.set_ylabel("squeeze-out time t* [s]")
    ax.set_title(title or "asperity-scale squeeze-out (tire tread block, Sec. 5)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig
