"""Figures of a scene run (``fastcontact run``): every case drawn, small multiples when many.

:func:`make_scene_figure` is the figure maker the CLI hands to
:func:`fastcontact.studies.run.run_scene`. ū(t) and Δu(t) figures (squeeze and tire studies)
draw one panel per surface and one curve per distinct case, with trapped cases' end state
ū_trap; ``t_star`` and ``leak_rate`` draw one line per combination of the other axes, trapped
or sealed cases marked at the panel edge. One style for every figure (:func:`_finish`).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..squeeze.tire import profile_factors
from .canvas import log_axis, new_figure, save_png
from .tire_figures import _curve_colors, draw_tire_curves, tire_curves

__all__ = ["make_scene_figure", "MAX_CURVES_PER_PANEL", "UNIT_LABELS"]

#: panels show at most this many curves each; more cases are thinned evenly and the panel
#: title says "n of m cases"
MAX_CURVES_PER_PANEL = 60
#: time samples per ū(t) curve (log-spaced; ~10 per decade)
CURVE_POINTS = 60
#: resolution of the run figures [dots per inch]
DPI = 120
#: display scale and unit of the case parameters in labels
UNIT_LABELS = {"p0": (1e6, "MPa"), "E": (1e6, "MPa"), "E_star": (1e6, "MPa"),
               "E2": (1e6, "MPa"), "eta": (1e-3, "mPa s"), "R": (1e-2, "cm"),
               "u_start": (1e-3, "mm"), "dp": (1e3, "kPa"), "L": (1e-3, "mm"),
               "L_y": (1e-3, "mm"), "p_b": (1e3, "kPa"), "speed": (1.0, "m/s"),
               "footprint_length": (1e-3, "mm"), "f_N": (1e3, "N/mm"), "rho": (1.0, "kg/m^3")}
_SI_UNIT = {"p0": "Pa", "E": "Pa", "E_star": "Pa", "E2": "Pa", "eta": "Pa s", "R": "m",
            "u_start": "m", "dp": "Pa", "p_b": "Pa", "L": "m", "L_y": "m", "rho": "kg/m^3",
            "speed": "m/s", "footprint_length": "m", "f_N": "N/m"}
_SQUEEZE_KEYS = ("theory", "p0", "E", "nu", "E2", "nu2", "E_star", "eta", "R", "u_start")
_SEAL_COLORS = ("tab:blue", "tab:orange", "tab:red")


# =========================================================================== helpers
def _surface_label(scene, name):
    spec = scene.surfaces.get(name)
    return (spec.label if spec is not None and spec.label else name)


def _case_label(scene, row, keys=None):
    """The varying parameters of a case, with units (``p0 = 0.2 MPa, emt``)."""
    parts = []
    for k, v in scene.axes.items():
        if len(v) > 1 and (keys is None or k in keys):
            if k == "theory":
                parts.append(str(row[k]))
            elif k in UNIT_LABELS:
                f, u = UNIT_LABELS[k]
                parts.append(f"{k} = {float(row[k]) / f:.3g} {u}")
            else:
                parts.append(f"{k} = {float(row[k]):.3g}")
    return ", ".join(parts)


def _grid(fig, n):
    """``n`` axes in a grid of up to 3 columns (small multiples)."""
    ncols = 1 if n == 1 else min(3, n)
    nrows = math.ceil(n / ncols)
    axs = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    for ax in axs[n:]:
        ax.set_visible(False)
    return axs[:n]


def _figure(n_panels):
    """A figure sized for ``n_panels`` panels (fixed margins: no layout solver, fast)."""
    ncols = 1 if n_panels == 1 else min(3, n_panels)
    nrows = math.ceil(n_panels / ncols)
    w, h = (6.4 if ncols == 1 else 4.6 * ncols), (4.8 if nrows == 1 else 3.8 * nrows)
    fig = new_figure(layout=None, figsize=(w, h))
    fig.subplots_adjust(left=0.75 / w, right=1 - 0.55 / w, bottom=0.55 / h, top=1 - 0.5 / h,
                        wspace=0.35, hspace=0.45)
    return fig


def _thin(items, limit=None):
    """``items`` evenly thinned to ``limit`` (default :data:`MAX_CURVES_PER_PANEL`; first and
    last kept) and the original count."""
    limit = MAX_CURVES_PER_PANEL if limit is None else limit
    if len(items) <= limit:
        return items, len(items)
    idx = np.unique(np.linspace(0, len(items) - 1, limit).round().astype(int))
    return [items[i] for i in idx], len(items)


def _finish(fig, axs, title, legend_loc="best"):
    """The one style of every run figure: small legends, light grid, title on top."""
    for ax in axs:
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, frameon=False, loc=legend_loc)
        ax.grid(True, which="major", lw=0.3, alpha=0.5)
    fig.suptitle(title, fontsize=9)


def _sweep_axis(scene, candidates=None):
    for k, v in scene.axes.items():
        if k != "theory" and len(v) > 1 and (candidates is None or k in candidates):
            return k
    return None


# =========================================================================== ū(t), Δu(t)
def _p_eval(scene, row):
    if "p_eval" in row:
        return float(row["p_eval"])
    if scene.kind == "tire":
        peak = profile_factors(scene.fixed["pressure_profile"])[1]
        return float(row["p0"]) * (peak if scene.fixed["pressure_model"] == "peak" else 1.0)
    return float(row["p0"])


def _curves(scene, T, rows):
    """The ū(t) curves of ``rows`` (cases of one surface), batched per theory and start."""
    ratios = scene.fixed.get("ratios") or (1.1, 1.01, 1.001)
    du = scene.fixed.get("du_complete") or (scene.fixed.get("du") or (1e-6,))[0]
    groups = {}
    for i, row in enumerate(rows):
        u0 = float(row["u_start"]) if "u_start" in row else math.nan
        groups.setdefault((row["theory"], bool(np.isfinite(u0))), []).append(i)
    curves = [None] * len(rows)
    for (theory, has_start), idx in groups.items():
        sel = [rows[i] for i in idx]
        out = tire_curves(
            T, p0=[_p_eval(scene, r) for r in sel], E_star=[float(r["E_star"]) for r in sel],
            R=[float(r["R"]) for r in sel], eta=[float(r["eta"]) for r in sel], theory=theory,
            u_start=[float(r["u_start"]) for r in sel] if has_start else None, ratios=ratios,
            du=du, labels=[_case_label(scene, r, _SQUEEZE_KEYS) for r in sel], n=CURVE_POINTS)
        for i, c in zip(idx, out):
            curves[i] = c
    return curves


def _history_figure(scene, fig_name, tables, results, path):
    ok = results[results["error"] == ""]
    keys = ["surface"] + [c for c in _SQUEEZE_KEYS if c in ok]
    ok = ok.drop_duplicates(subset=keys)
    names = list(dict.fromkeys(ok["surface"]))
    fig = _figure(max(len(names), 1))
    axs = _grid(fig, max(len(names), 1))
    quantity = "du" if fig_name == "du_of_t" else "u"
    t_mark = None
    if scene.kind == "tire":
        t_mark = sorted(set((results["footprint_length"] / results["speed"]).round(12)))
    any_trapped = False
    for ax, name in zip(axs, names):
        rows, total = _thin([r for _, r in ok[ok["surface"] == name].iterrows()])
        curves = _curves(scene, tables[name], rows)
        any_trapped = any_trapped or any(c["trapped"] for c in curves)
        draw_tire_curves(ax, curves, quantity, t_mark,
                         "time in footprint:" if t_mark else None, labels=len(curves) <= 8)
        title = _surface_label(scene, name)
        if len(curves) > 8:
            title += (f"\n{len(curves)}" + (f" of {total}" if total > len(rows) else "")
                      + f" cases, purple → yellow: {_case_label(scene, rows[0], _SQUEEZE_KEYS)}"
                      f" → {_case_label(scene, rows[-1], _SQUEEZE_KEYS)}")
        elif total > len(rows):
            title += f" ({len(rows)} of {total} cases)"
        ax.set_title(title, fontsize=8)
    ax0 = axs[0]
    ax0.plot([], [], color="0.4", lw=0.8, ls="--",
             label="ū/ū(∞) = 1.1, 1.01, 1.001 (- -, -., :)")
    if any_trapped:
        ax0.plot([], [], color="0.4", lw=1.0, ls="-.", label="trapped: ū_trap")
    if quantity == "u":
        ax0.plot([], [], color="0.4", lw=0.6, label="flat surfaces")
    _finish(fig, axs, scene.title, legend_loc="upper right")
    return save_png(fig, path, dpi=DPI)


# =========================================================================== t*(x)
def _t_star_figure(scene, results, path):
    ok = results[results["error"] == ""]
    x = _sweep_axis(scene) or "p0"
    others = [k for k, v in scene.axes.items() if len(v) > 1 and k not in (x,)]
    fig = _figure(1)
    ax = fig.subplots()
    groups = list(ok.groupby(["surface", *others], sort=False))
    colors = _curve_colors(len(groups))
    top = np.nanmax(ok["t_star"].to_numpy(float)[np.isfinite(ok["t_star"].to_numpy(float))],
                    initial=1.0)
    for col, ((name, *_), g) in zip(colors, groups):
        gg = g.sort_values(x)
        xv, y = gg[x].to_numpy(float), gg["t_star"].to_numpy(float)
        fin = np.isfinite(y) & (y > 0)
        lab = ", ".join(s for s in (_surface_label(scene, name),
                                    _case_label(scene, gg.iloc[0], others)) if s)
        ax.plot(xv[fin], y[fin], "o-", ms=3, color=col, label=lab if len(groups) <= 12 else None)
        if (~fin).any():
            ax.plot(xv[~fin], np.full((~fin).sum(), top * 3), "^", mfc="none", color=col, ms=6)
    if (~np.isfinite(ok["t_star"].to_numpy(float))).any():
        ax.plot([], [], "^", mfc="none", color="0.3", label="trapped (t* = ∞)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    log_axis(ax.xaxis)
    log_axis(ax.yaxis)
    ax.set_xlabel(f"{x} ({_SI_UNIT.get(x, '-')})")
    ax.set_ylabel("squeeze-out time t* (s), ū(t*) = 1.01 ū(∞)")
    _finish(fig, [ax], scene.title)
    return save_png(fig, path, dpi=DPI)


# =========================================================================== seals
def _seal_p_ref(scene, rows):
    """p0 of a flat ring, or the Hertz peak pressure, for each row [Pa]."""
    if scene.fixed.get("profile") == "hertz":
        from ..seal import hertz_contact   # seal engine only for seal scenes
        return np.asarray(hertz_contact(rows["R"].to_numpy(float), rows["f_N"].to_numpy(float),
                                        rows["E_star"].to_numpy(float))[1], float).ravel()
    return rows["p0"].to_numpy(float)


def _leak_figure(scene, results, path):
    ok = results[results["error"] == ""]
    others = [k for k, v in scene.axes.items() if len(v) > 1 and k != "dp"]
    fig = _figure(1)
    ax = fig.subplots()
    groups = list(ok.groupby(["surface", *others], sort=False))
    sealed = False
    for col, ((name, *_), g) in zip(_curve_colors(len(groups)), groups):
        gg = g.sort_values("dp")
        Q = gg["Q"].to_numpy(float)
        m = np.isfinite(Q) & (Q > 0)
        x = gg["dp"].to_numpy(float) / _seal_p_ref(scene, gg)
        lab = ", ".join(s for s in (_surface_label(scene, name),
                                    _case_label(scene, gg.iloc[0], others)) if s)
        ax.plot(x[m], Q[m], "o-", ms=3, color=col, label=lab if len(groups) <= 12 else None)
        if (~m).any():
            sealed = True
            ax.plot(x[~m], np.full((~m).sum(), np.nanmin(Q[m], initial=1e-20) / 3), "v",
                    mfc="none", color=col, ms=6)
    if sealed:
        ax.plot([], [], "v", mfc="none", color="0.3", label="Q = 0 (percolated: sealed)")
    ax.set_yscale("log")
    log_axis(ax.yaxis)
    ax.set_xlabel("Δp / p₀" + (" (p₀: Hertz peak pressure)"
                                         if scene.fixed.get("profile") == "hertz" else ""))
    ax.set_ylabel("leak rate Q (m³/s)")
    _finish(fig, [ax], scene.title)
    return save_png(fig, path, dpi=DPI)


def _seal_profile_kwargs(scene, row, dp):
    kw = dict(dp=dp, L_y=float(row["L_y"]), E_star=float(row["E_star"]), eta=float(row["eta"]),
              theory=row["theory"], alpha_cj=float(row["alpha_cj"]), p_b=float(row["p_b"]),
              profile=scene.fixed.get("profile", "uniform"))
    if scene.fixed.get("profile") == "hertz":
        kw.update(R=float(row["R"]), f_N=float(row["f_N"]))
    else:
        kw.update(p0=float(row["p0"]), L=float(row["L"]))
    return kw


def _profiles_figure(scene, tables, results, path):
    from ..seal import seal_profile   # seal engine only for seal scenes
    ok = results[results["error"] == ""]
    names = list(dict.fromkeys(ok["surface"]))
    fig = _figure(max(len(names), 1))
    axs = _grid(fig, max(len(names), 1))
    for ax, name in zip(axs, names):
        row = ok[ok["surface"] == name].iloc[0]
        ax2 = ax.twinx()
        for j, frac in enumerate((0.0, 0.5, 0.9)):
            dp = frac * float(_seal_p_ref(scene, row.to_frame().T)[0])
            prof = seal_profile(tables[name], **_seal_profile_kwargs(scene, row, dp))
            x = prof["x"].to_numpy(float) * 1e3
            ax.plot(x, prof["p_cont"].to_numpy(float) / 1e3, color=_SEAL_COLORS[j],
                    label=f"p_cont, Δp/p₀ = {frac:g}")
            ucol = "u" if "u" in prof else [c for c in prof.columns if c.startswith("u")][0]
            ax2.plot(x, prof[ucol].to_numpy(float) * 1e6, color=_SEAL_COLORS[j], ls="--")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("contact pressure p_cont (kPa)")
        ax2.set_ylabel("separation ū (µm), dashed")
        ax.set_title(f"{_surface_label(scene, name)}: {_case_label(scene, row) or 'first case'}",
                     fontsize=8)
    _finish(fig, axs, scene.title, legend_loc="upper center")
    return save_png(fig, path, dpi=DPI)


# =========================================================================== entry
def make_scene_figure(scene, fig, tables, results, figdir) -> Path:
    """Draw figure ``fig`` of a scene run into ``figdir/<kind>_<fig>.png``.

    Parameters
    ----------
    scene : fastcontact.studies.scene.Scene
    fig : str
        One of the kind's figures: ``u_of_t``, ``t_star`` (squeeze), ``u_of_t``,
        ``du_of_t`` (tire), ``leak_rate``, ``profiles`` (seal).
    tables : dict
        Surface name → Tables.
    results : pandas.DataFrame
        The run's rows (every surface).
    figdir : path-like

    Returns
    -------
    pathlib.Path
        The PNG written (atomically).
    """
    figdir = Path(figdir)
    figdir.mkdir(parents=True, exist_ok=True)
    path = figdir / f"{scene.kind}_{fig}.png"
    if fig in ("u_of_t", "du_of_t"):
        return _history_figure(scene, fig, tables, results, path)
    if fig == "t_star":
        return _t_star_figure(scene, results, path)
    if fig == "leak_rate":
        return _leak_figure(scene, results, path)
    if fig == "profiles":
        return _profiles_figure(scene, tables, results, path)
    raise ValueError(f"fig = {fig!r} is invalid: no such scene figure")
