"""Shared figure plumbing: pyplot-free Agg figures and atomic PNG writes."""
from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .._core.io import atomic_path

__all__ = ["new_figure", "save_png"]


def new_figure(layout="constrained", **kw):
    """A pyplot-free Figure on the Agg canvas (no global backend switch, no figure manager).

    ``layout=None`` skips the constrained layout (faster; place the axes with
    ``fig.subplots_adjust``)."""
    fig = Figure(layout=layout, **kw)
    FigureCanvasAgg(fig)
    return fig


def save_png(fig, path, dpi=150) -> Path:
    """Write ``fig`` as a PNG (``dpi`` dots per inch) atomically (temporary name, then rename)."""
    with atomic_path(path, suffix=".png.tmp") as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return Path(path)
