"""Asperity-scale squeeze-out at magnification ζ and the simplest cascade over ζ (paper, end of
Sec. 3; derivation and choices in docs/theory/extensions.md §1).

At magnification ζ the apparent contact consists of asperity contact regions; the paper
applies the squeeze-out theory to one such region with

* the local squeezing pressure p(ζ) = p0 A0/A(ζ)            (A1 of the full spectrum),
* the roughness restricted to q >= ζ q0                       (:meth:`PSD.restricted`),
* a region radius R(ζ) — not given by the paper. Choice made here (``region="half_wavelength"``):
  the regions seen at ζ are the contact patches of the shortest resolved roughness, of
  wavelength λ(ζ) = 2π/(ζq0); a patch cannot be wider than the crest half of that wavelength,
  so its diameter is λ(ζ)/2 and R(ζ) = π/(2ζq0) (Persson's picture of the contact regions
  at magnification ζ as asperities of size ~λ/2; B.N.J. Persson, Surf. Sci. Rep. 61, 201
  (2006), doi:10.1016/j.surfrep.2006.04.001). Any other rule can be passed as a function;
  t* ∝ R², so a factor 2 in R is a factor 4 in every level's time.

Level ζ = 1 is the macroscopic block (radius ``R``), i.e. exactly the base squeeze-out.
Trapping: fluid is sealed off in the asperity regions of level ζ when the restricted
contact percolates at p(ζ): A_ζ(ζ1)/A_ζ(ζ) >= a_perc of the flow theory (0.5 for "emt"), or
the squeeze engine's trap criterion triggers; the first such ζ is ``zeta_trap``.

Cascade (the paper leaves it undeveloped): the fluid around a region of level ζ_k is at
the external pressure only once level ζ_{k-1} has drained. Levels are octaves,
ζ_k = r^k (``level_ratio`` r = 2: a new set of regions each time the resolved wavelength
halves). Two bounds on the time to drain every level up to ζ_K are reported:
``t_sequential`` = Σ_k t*(ζ_k) (each level starts when the level below has drained — the
simplest consistent cascade) and ``t_parallel`` = max_k t*(ζ_k) (all levels start at
once at the external pressure, the paper's independent-level picture); the truth lies in
between. Both are +inf from the first trapped level on.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .._core.validate import check_positive
from ..contact import area_fraction
from ..tables import precompute
from . import squeeze_out

__all__ = ["TIRE_CASE", "asperity_levels", "plot_asperity_tstar", "region_radius"]

#: the paper's Sec. 5 tread block: R = 2 cm, p0 = 0.2 MPa, E = 10 MPa (ν = 0.5), water
TIRE_CASE = dict(R=0.02, p0=0.2e6, E_star=10e6 / 0.75, eta=1e-3)
_A_PERC = {"emt": 0.5, "critical_junction": 0.5, "average": math.inf}


def region_radius(zeta, q0):
    """Radius [m] of an asperity contact region at magnification ζ: R(ζ) = π/(2 ζ q0)."""
    return math.pi / (2.0 * np.asarray(zeta, dtype=np.float64) * q0)


def _levels(psd, level_ratio, zeta_max):
    zmax = min(zeta_max if zeta_max is not None else psd.zeta1 / 10.0, psd.zeta1 / 10.0)
    n = int(math.floor(math.log(zmax) / math.log(level_ratio) + 1e-9)) + 1
    return level_ratio ** np.arange(max(n, 1))


def asperity_levels(psd, *, p0, E_star, R, eta, theory="emt", level_ratio=2.0, zetas=None,
                    zeta_max=None, region=None, ratios=(1.1,), tables_kwargs=None):
    """Squeeze-out of the asperity contact regions at each magnification level ζ, and the
    cascade totals (module docstring).

    Parameters
    ----------
    psd : PSD
        Full roughness spectrum of the substrate (Persson convention).
    p0 : float
        Nominal squeezing pressure of the block [Pa].
    E_star : float
        Effective modulus [Pa].
    R : float
        Block radius [m] (level ζ = 1).
    eta : float
        Fluid viscosity [Pa·s].
    theory : str
        Flow theory of every level ("emt", "critical_junction" or "average").
    level_ratio : float
        Ratio of successive levels ζ_{k+1}/ζ_k (> 1; default 2, octaves).
    zetas : array_like, optional
        Explicit levels (ascending, first = 1); overrides ``level_ratio``.
    zeta_max : float, optional
        Highest level (default and maximum ζ1/10: the restricted spectrum keeps a decade).
    region : callable, optional
        ``region(zeta, q0) -> R(ζ) [m]`` for ζ > 1 (default :func:`region_radius`).
    ratios : sequence
        Extra targets ū/ū∞ passed to :func:`squeeze_out`.
    tables_kwargs : dict, optional
        Extra arguments of :func:`~fastcontact.tables.precompute` for each level.

    Returns
    -------
    pandas.DataFrame
        One row per level: ``zeta``, ``q_min`` [1/m], ``area_fraction`` A(ζ)/A0,
        ``p_zeta`` [Pa], ``R_zeta`` [m], ``h_rms_zeta`` [m], ``area_restricted`` (the
        restricted contact's A(ζ1)/A(ζ) at p(ζ)), ``trapped``, ``u_inf``, ``u_start`` [m],
        ``t_star`` [s] and ``t_ratio_<r>`` [s], ``t_relax`` [s], ``t_sequential``,
        ``t_parallel`` [s], ``out_of_table``; ``attrs["zeta_trap"]`` the first trapped level
        (inf: none).
    """
    p0 = float(check_positive("p0", p0, "[Pa]"))
    E_star = float(check_positive("E_star", E_star, "[Pa]"))
    R = float(check_positive("R", R, "[m]"))
    eta = float(check_positive("eta", eta, "[Pa·s]"))
    lr = float(check_positive("level_ratio", level_ratio, "[-]"))
    if not lr > 1.0:
        raise ValueError(f"level_ratio = {level_ratio!r} is invalid: must be > 1 [-]")
    zs = _levels(psd, lr, zeta_max) if zetas is None else np.asarray(zetas, dtype=np.float64)
    if zs[0] != 1.0 or np.any(np.diff(zs) <= 0) or zs[-1] >= psd.zeta1:
        raise ValueError(f"zetas = {zs.tolist()!r} is invalid: must ascend from 1 and stay "
                         f"below ζ1 = {psd.zeta1:g}")
    region = region_radius if region is None else region
    a_perc = _A_PERC.get(theory, 0.5)
    G1 = psd.moment(3.0, psd.q0, psd.q1)
    rows = []
    for z in zs:
        area = float(area_fraction(psd, p0, E_star, z)) if z > 1.0 else 1.0
        pz = p0 / area
        sub = psd if z == 1.0 else psd.restricted(z * psd.q0)
        Rz = R if z == 1.0 else float(region(z, psd.q0))
        Gr = G1 - float(psd.moment(3.0, psd.q0, z * psd.q0))          # restricted G/(π E*²/4)
        a_r = math.erf(pz / (E_star * 2.0 * math.sqrt(0.25 * math.pi * Gr)))
        tabs = precompute(sub, theories=(theory,), **(tables_kwargs or {}))
        df = squeeze_out(tabs, p0=pz, E_star=E_star, R=Rz, eta=eta, theory=theory,
                         ratios=tuple(ratios))
        r = df.iloc[0]
        row = {"zeta": z, "q_min": z * psd.q0, "area_fraction": area, "p_zeta": pz,
               "R_zeta": Rz, "h_rms_zeta": sub.h_rms, "area_restricted": a_r,
               "trapped": bool(a_r >= a_perc or r["trapped"]), "u_inf": r["u_inf"],
               "u_start": r["u_start"], "t_star": r["t_star"]}
        for c in df.columns:
            if c.startswith("t_ratio_"):
                row[c] = r[c]
        row.update({"t_relax": r["t_relax"], "out_of_table": bool(r["out_of_table"])})
        rows.append(row)
    out = pd.DataFrame(rows)
    t = np.where(out["trapped"], np.inf, out["t_star"].to_numpy(dtype=float))
    out["t_sequential"] = np.cumsum(t)
    out["t_parallel"] = np.maximum.accumulate(t)
    trapped = out["zeta"][out["trapped"]]
    units = {"zeta": "1", "q_min": "1/m", "area_fraction": "1", "p_zeta": "Pa", "R_zeta": "m",
             "h_rms_zeta": "m", "area_restricted": "1", "u_inf": "m", "u_start": "m"}
    units.update({c: "s" for c in out.columns if c.startswith("t_")})
    out.attrs.update({"units": units, "theory": theory, "level_ratio": lr,
                      "zeta_trap": float(trapped.iloc[0]) if trapped.size else math.inf,
                      "region_rule": getattr(region, "__name__", repr(region)),
                      "references": ["arXiv:1004.1037",
                                     "doi:10.1016/j.surfrep.2006.04.001"]})
    return out


def plot_asperity_tstar(results, path=None, title=None):
    """Figure: t*(ζ) of each level and the two cascade bounds, one curve set per surface.

    ``results`` maps a label to a frame of :func:`asperity_levels`. matplotlib is imported
    here only (optional dependency). Returns the Figure (saved to ``path`` if given).
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
