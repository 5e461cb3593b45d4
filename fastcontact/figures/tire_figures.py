"""Tire tread block on a wet road — the paper's Sec. 5 figures (two asphalt surfaces).

``make_tire_figures(outdir, tables=None)`` writes

* ``tire_u_of_t.png``: ū(t) against t, log–log, for the two asphalt roads (h_rms = 0.72 mm,
  surface 1; 0.24 mm, surface 2), with vertical lines where ū/ū∞ = 1.1, 1.01, 1.001 and thin
  lines for perfectly flat surfaces (Stefan law from the same ū(0));
* ``tire_du_of_t.png``: Δu = ū(t) - ū∞ against t, log–log, with the 1 µm level and the
  footprint time (0.1 m at 30 m/s) marked.

Parameters (paper Sec. 5): p0 = 0.2 MPa, E = 10 MPa with ν = 0.5 (rubber; E* = E/(1-ν²) =
13.3 MPa), R = 2 cm, water η = 1 mPa·s, average-separation theory, ū(0) = 1 cm.
The roads are the embedded stand-in tables ``asphalt_072mm`` and ``asphalt_024mm`` (see
:mod:`fastcontact.defaults`) unless ``tables`` = {label: Tables} is given.

Rendering uses the Agg canvas directly (no pyplot); PNGs are written atomically.
Run as a script: ``python -m fastcontact.figures.tire_figures [outdir]``.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib
import numpy as np

from .._core.vocab import DEFAULT_THEORY, column_name
from ..contact.elasticity import effective_modulus
from ..squeeze import squeeze_out
from ..squeeze.reduced import flat_separation
from ..tables import Tables
from ..tables.defaults import default_table_path
from .canvas import log_axis, new_figure as _new_figure, save_png as _save_atomic

__all__ = ["make_tire_figures", "tire_curve", "tire_curves", "plot_tire_curves",
           "draw_tire_curves", "PAPER"]

PAPER = dict(p0=0.2e6, E=10e6, nu=0.5, R=0.02, eta=1e-3, rho=1000.0, u_start=1e-2,
             footprint_length=0.1, speed=30.0, theory="average", ratios=(1.1, 1.01, 1.001),
             du_complete=1e-6)
ROADS = (("asphalt_072mm", r"surface 1: $h_{\rm rms}$ = 0.72 mm"),
         ("asphalt_024mm", r"surface 2: $h_{\rm rms}$ = 0.24 mm"))
COLORS = ("tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown",
          "tab:pink", "tab:olive")


def tire_curve(tables, *, p0, E_star, R, eta, theory=DEFAULT_THEORY, u_start=PAPER["u_start"],
               ratios=PAPER["ratios"], du=PAPER["du_complete"], label="", n=400):
    """ū(t), Δu(t), flat-surface ū(t), ū∞ and the ratio/Δu times of one tread-block case.

    The time axis spans from well before the film starts to thin to 10× the last ratio time
    (or to 1e3× the first if the fluid is trapped). One case of :func:`tire_curves`.
    """
    return tire_curves(tables, p0=[p0], E_star=[E_star], R=[R], eta=[eta], theory=theory,
                       u_start=None if u_start is None else [u_start], ratios=ratios, du=du,
                       labels=[label], n=n)[0]


def _time_span(t_r, t_du, u0, p0, eta, R):
    """(t_lo, t_hi) [s] of one case's curve: from well before the film starts to thin
    (4 u0² p0 t/(3ηR²) ~ 1, the flat-surface law) to 10× the last finite target time."""
    finite = [t for t in list(t_r) + [t_du] if math.isfinite(t) and t > 0]
    t_hi = 10.0 * max(finite) if finite else 1.0
    t_thin = 3.0 * eta * R ** 2 / (4.0 * u0 ** 2 * p0)
    return min(t_thin * 1e-2, (min(finite) if finite else t_hi) * 1e-3), t_hi


def tire_curves(tables, *, p0, E_star, R, eta, theory=DEFAULT_THEORY, u_start=None,
                ratios=PAPER["ratios"], du=PAPER["du_complete"], labels=None, n=400):
    """The curves of :func:`tire_curve` for many cases of one surface and theory at once.

    Parameters
    ----------
    tables : Tables
    p0, E_star, R, eta : array_like
        One value per case: pressure [Pa], effective modulus [Pa], radius [m], viscosity
        [Pa·s].
    theory : str
    u_start : array_like or None
        Initial separations [m] (one per case), or None: the engine's default start.
    ratios, du :
        Targets ū/ū∞ (vertical lines) and the Δu level [m].
    labels : list of str, optional
    n : int
        Samples per curve (log-spaced over the case's own time span; the cases share one
        log grid of at least this density).

    Returns
    -------
    list of dict
        Per case: ``label``, ``t`` [s], ``u``, ``du``, ``flat`` [m] (Stefan law from the same
        start), ``u_inf``, ``u_start`` [m], ``t_ratios`` {ratio: t [s]}, ``t_du`` [s],
        ``du_level`` [m], ``trapped``, ``u_trap`` [m].

    Two calls of :func:`fastcontact.squeeze.squeeze_out` (``method="quad"``) for all cases:
    the target times, then ū on the shared time grid. A case the engine does not run
    (status other than "ok" or "trapped", e.g. a start below ū∞) gets an empty curve.
    """
    p0, E_star, R, eta = (np.atleast_1d(np.asarray(v, float)) for v in (p0, E_star, R, eta))
    m = p0.size
    labels = [""] * m if labels is None else list(labels)
    us = None if u_start is None else np.atleast_1d(np.asarray(u_start, float))
    kw = dict(p0=p0, E_star=E_star, R=R, eta=eta, theory=theory, u_start=us, method="quad")
    sq = squeeze_out(tables, ratios=tuple(ratios), du=(du,), times=(), **kw)
    t_r = np.array([sq[_column(sq, "t_ratio", r)].to_numpy(float) for r in ratios]).reshape(
        len(ratios), m)
    t_du = sq[_column(sq, "t_du", du)].to_numpy(float)
    u_inf = sq["u_inf"].to_numpy(float)
    u0 = sq["u_start"].to_numpy(float)
    with np.errstate(invalid="ignore"):
        spans = np.log10([_time_span(t_r[:, i], t_du[i], u0[i], p0[i], eta[i], R[i])
                          for i in range(m)]).reshape(m, 2)
    lo, hi = spans[:, 0], spans[:, 1]
    ok = (np.isfinite(lo) & np.isfinite(hi)        # not: a start at or below ū∞, overflow
          & sq["status"].isin(("ok", "trapped")).to_numpy(bool))
    grid, U = np.zeros(0), np.zeros((m, 0))
    if ok.any():
        per_decade = (n - 1) / max(float(np.min(hi[ok] - lo[ok])), 1e-9)
        n_grid = int(min(max(n, math.ceil(per_decade * (hi[ok].max() - lo[ok].min())) + 1),
                         8 * n))
        grid = np.logspace(lo[ok].min(), hi[ok].max(), n_grid)
        hist = squeeze_out(tables, ratios=(), du=(), times=tuple(grid), **kw)
        U = hist[[c for c in hist.columns if c.startswith("u_at_")]].to_numpy(float)
        if U.shape != (m, n_grid):
            raise RuntimeError(f"squeeze_out returned ū at {U.shape[1]} of {n_grid} times")
    trapped = sq["trapped"].to_numpy(bool)
    u_trap = sq["u_trap"].to_numpy(float)
    curves = []
    for i in range(m):
        keep = ((grid >= 10 ** lo[i] * (1 - 1e-12)) & (grid <= 10 ** hi[i] * (1 + 1e-12))
                if ok[i] else np.zeros(grid.size, bool))
        t, u = grid[keep], U[i, keep]
        flat = (np.asarray(flat_separation(u0[i], t, p0[i], eta[i], R[i]), float) if ok[i]
                else np.zeros(0))
        curves.append(dict(label=labels[i], t=t, u=u, du=u - u_inf[i], flat=flat,
                           u_inf=float(u_inf[i]), u_start=float(u0[i]),
                           t_ratios=dict(zip(ratios, map(float, t_r[:, i]))),
                           t_du=float(t_du[i]), du_level=du, trapped=bool(trapped[i]),
                           u_trap=float(u_trap[i])))
    return curves


def _column(frame, prefix, value):
    """The squeeze_out column of a numbered output (column_name; former %g spelling)."""
    name = column_name(prefix, value)
    return name if name in frame else f"{prefix}_{float(value):g}"


def _curve_colors(n):
    """Distinct colours for up to len(COLORS) curves, else a viridis ramp."""
    if n <= len(COLORS):
        return list(COLORS[:n])
    cmap = matplotlib.colormaps["viridis"]
    return [cmap(x) for x in np.linspace(0.0, 0.9, n)]


def _draw_curve(ax, c, col, quantity, label):
    """One case: ū(t) or Δu(t) [mm, µm], the flat-surface law, ū∞ and, if the fluid is
    trapped, its end state ū_trap (dash-dotted). Returns (ymin, ymax) of the curve."""
    t = c["t"]
    if quantity == "u":
        y = c["u"] * 1e3
        ax.plot(t, c["flat"] * 1e3, color=col, lw=0.6, alpha=0.8)
        ax.axhline(c["u_inf"] * 1e3, color=col, lw=0.5, ls=":", alpha=0.7)
        level = c.get("u_trap", math.nan) * 1e3
    else:
        y = c["du"] * 1e6
        level = (c.get("u_trap", math.nan) - c["u_inf"]) * 1e6
    ok = np.isfinite(y) & (y > 0)
    ax.plot(t[ok], y[ok], color=col, lw=1.8 if label else 1.0, label=label or None)
    if c.get("trapped") and np.isfinite(level) and level > 0:
        ax.axhline(level, color=col, lw=1.0, ls="-.")
        labelled = ax.__dict__.setdefault("_fastcontact_trap_levels", set())
        key = round(math.log10(level), 2)
        if key not in labelled:                       # one label per distinct level
            labelled.add(key)
            ax.annotate(f"trapped: ū_trap = {c['u_trap'] * 1e6:.3g} µm",
                        xy=(0.98, level), xycoords=("axes fraction", "data"), xytext=(0, 3),
                        textcoords="offset points", ha="right", fontsize=7, color="0.15")
    styles = ("--", "-.", ":")
    for j, tr in enumerate(c["t_ratios"].values()):
        if math.isfinite(tr):
            ax.axvline(tr, color=col, lw=0.8, ls=styles[j % 3], alpha=0.9)
    if not ok.any():
        return np.inf, 0.0
    return y[ok].min(), y[ok].max()


def draw_tire_curves(ax, curves, quantity="u", t_mark=None, t_mark_label=None, labels=True):
    """Draw ū(t) (``quantity="u"``) or Δu(t) (``"du"``) of ``curves`` on ``ax`` (log–log).

    Vertical lines at the ratio times (1.1, 1.01, 1.001 from left to right), thin lines for
    flat surfaces (ū plot), ū_trap of trapped cases, the Δu level (Δu plot) and optional
    time marks (e.g. the footprint time).
    """
    ymin, ymax = np.inf, 0.0
    for c, col in zip(curves, _curve_colors(len(curves))):
        lo, hi = _draw_curve(ax, c, col, quantity, c["label"] if labels else "")
        ymin, ymax = min(ymin, lo), max(ymax, hi)
    if quantity == "du":
        lvl = curves[0]["du_level"] * 1e6 if curves else 1.0
        ax.axhline(lvl, color="k", lw=0.8, ls=":")
        ax.annotate(f"Δu = {lvl:g} µm", xy=(0.02, lvl), xycoords=("axes fraction", "data"),
                    xytext=(0, 3), textcoords="offset points", fontsize=8)
        ymin = max(min(ymin, lvl / 10), lvl * 1e-4)
        ax.set_ylabel("Δu = ū(t) − ū(∞) (µm)")
    else:
        ax.set_ylabel("separation ū (mm)")
    marks = [] if t_mark is None else list(np.atleast_1d(t_mark))
    for tm in marks:
        ax.axvline(tm, color="0.3", lw=1.2)
        ax.annotate(f"{t_mark_label or ''} {tm * 1e3:.3g} ms", xy=(tm, 0.97),
                    xycoords=("data", "axes fraction"), xytext=(-3, 0),
                    textcoords="offset points", ha="right", va="top", fontsize=8, color="0.3",
                    rotation=90)
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_axis(ax.xaxis, minor_labels=False)
    log_axis(ax.yaxis)
    if np.isfinite(ymin) and ymax > 0:
        ax.set_ylim(ymin / 1.5, ymax * 1.5)
    if marks:
        lo, hi = ax.get_xlim()
        ax.set_xlim(lo, max(hi, 2.0 * max(marks)))
    ax.set_xlabel("squeeze time t (s)")
    ax.grid(True, which="major", lw=0.3, alpha=0.5)


def plot_tire_curves(curves, path, quantity="u", title="", t_mark=None, t_mark_label=None):
    """Log–log plot of ū(t) (``quantity="u"``) or Δu(t) (``"du"``) for several curves
    (see :func:`draw_tire_curves`), written atomically to ``path``."""
    fig = _new_figure(figsize=(6.4, 4.8))
    ax = fig.subplots()
    draw_tire_curves(ax, curves, quantity, t_mark, t_mark_label)
    ax.plot([], [], color="0.4", lw=0.8, ls="--", label="ū/ū(∞) = 1.1, 1.01, 1.001 (- -, -., :)")
    if quantity == "u":
        ax.plot([], [], color="0.4", lw=0.6, label="flat surfaces")
    ax.legend(loc="lower left", fontsize=8, frameon=False)
    if title:
        ax.set_title(title, fontsize=9)
    return _save_atomic(fig, path)


def make_tire_figures(outdir, tables=None) -> list[Path]:
    """Write the paper's two tire figures (Sec. 5) into ``outdir``; return the paths.

    ``tables``: optional {label: Tables}; default the embedded asphalt tables.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    if tables is None:
        tables = {label: Tables.from_parquet(default_table_path(name)) for name, label in ROADS}
    E_star = effective_modulus(PAPER["E"], PAPER["nu"])
    curves = [tire_curve(T, p0=PAPER["p0"], E_star=E_star, R=PAPER["R"], eta=PAPER["eta"],
                         theory=PAPER["theory"], u_start=PAPER["u_start"], label=label)
              for label, T in tables.items()]
    t_fp = PAPER["footprint_length"] / PAPER["speed"]
    title = ("tread block on wet asphalt (paper Sec. 5)\n"
             r"$p_0$ = 0.2 MPa, $E$ = 10 MPa ($\nu$ = 0.5), $R$ = 2 cm, water, "
             r"average-separation $\sigma_{\rm eff}$")
    return [plot_tire_curves(curves, outdir / "tire_u_of_t.png", "u", title),
            plot_tire_curves(curves, outdir / "tire_du_of_t.png", "du", title, t_mark=t_fp,
                             t_mark_label="footprint 0.1 m at 30 m/s:")]


if __name__ == "__main__":  # pragma: no cover
    for p in make_tire_figures(sys.argv[1] if len(sys.argv) > 1 else "."):
        print(p)
