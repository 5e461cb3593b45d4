"""Profiles across the seal width of one case: :func:`seal_profile` (Lorenz & Persson 2010,
Sec. 6, eqs. 25–33): p_cont(x), p_fluid(x), ū(x) and σ_eff(x)."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .._core.validate import check_range
from . import _mesh, _panels, _sigma
from ._inputs import (alpha_scale, check_tables, check_theory_for, common_inputs, hertz_contact,
                      profile_kind, scalar)
from .api import EQUALITY_TOL, REFERENCES, seal_leak
from .context import panel_rule, seal_context, solver_options

__all__ = ["seal_profile"]


def seal_profile(tables, *, p0=None, dp, L=None, L_y, E_star, eta, theory="critical_junction",
                 alpha_cj=1.0, p_b=0.0, profile="uniform", R=None, f_N=None, x=None,
                 a_perc=None, n=201, solver=None):
    """Profiles across the seal width of one case: p_cont(x), p_fluid(x), ū(x), σ_eff(x).

    Same arguments as :func:`seal_leak` (scalars only) plus ``n``, the number of output points,
    uniformly spaced on [0, L] (inlet at x = 0; an array profile's own x[0] is kept).

    Returns a DataFrame with ``x`` [m], ``p0`` [Pa] (nominal), ``p_cont`` [Pa], ``p_fluid`` [Pa],
    ``u`` [m] (mean separation), ``sigma_eff`` [m³/(Pa·s)], ``open`` (the surfaces are separated
    there: p_cont = 0, u = σ_eff = inf — a fluid-filled gap the soft-seal model does not size)
    and ``trapped`` (percolated band: fluid isolated, its pressure undetermined → NaN).
    ``df.attrs`` holds ``Q`` [m³/s], ``lift_off``, ``percolated``, ``x_s``/``x_e`` (sealing zone).
    """
    check_tables(tables)
    alpha = scalar("alpha_cj", check_theory_for(tables, theory, alpha_cj, a_perc))
    kind, p0x, xarr = profile_kind(profile, x)
    com = {k: scalar(k, v) for k, v in common_inputs(dp, L_y, E_star, eta, p_b).items()}
    n = int(check_range("n", n, 2, 1e7, "[-] (output points)"))
    sc = seal_context(tables, theory)
    leak = seal_leak(tables, p0=p0, dp=com["dp"], L=L, L_y=com["L_y"], E_star=com["E_star"],
                     eta=com["eta"], theory=theory, alpha_cj=alpha, p_b=com["p_b"],
                     profile=profile, R=R, f_N=f_N, x=x, a_perc=a_perc, solver=solver)
    row = leak.iloc[0]
    E, eta_, dpv, pb = com["E_star"], com["eta"], com["dp"], com["p_b"]
    pa = pb + dpv
    scale = float(alpha_scale(sc, theory, np.array([alpha]))[0])
    o = solver_options(solver)
    if kind == "uniform":
        p0v = scalar("p0", p0)
        Lv = scalar("L", L)
        xo = np.linspace(0.0, Lv, n)
        p0o = np.full(n, p0v)
        pf = _uniform_fluid(sc, p0v, pa, pb, dpv, E, xo / Lv, bool(row.lift_off),
                            bool(row.percolated))
        x_s, x_e = (0.0, Lv) if p0v >= pa else (Lv, Lv)
    else:
        if kind == "hertz":
            a, pH = (float(v) for v in hertz_contact(scalar("R", R), scalar("f_N", f_N), E))
            Lv = 2 * a
            xo = np.linspace(0.0, Lv, n)
            with np.errstate(invalid="ignore"):
                p0o = pH * np.sqrt(np.clip(1.0 - (xo / a - 1.0) ** 2, 0.0, 1.0))
            geo = ("hertz", a, pH)
        else:
            Lv = float(xarr[-1] - xarr[0])
            xo = np.linspace(xarr[0], xarr[-1], n)
            p0o = np.interp(xo, xarr, p0x)
            geo = ("array", xarr, p0x)
        pf, x_s, x_e = _general_fluid(sc, geo, pa, pb, dpv, E, xo, row, o)
    with np.errstate(invalid="ignore"):
        open_ = np.isfinite(pf) & (p0o - pf <= 0.0)
        pc = np.where(open_, 0.0, p0o - pf)
    trapped = np.isnan(pf)
    cred = np.ascontiguousarray(np.where(trapped, 1.0, pc / E))
    sig = np.empty(n)
    ub = np.empty(n)
    _sigma.sigma_rows(sc.tab, sc.rec, cred, sig)
    _sigma.ubar_rows(sc.tab, sc.rec, cred, ub)
    sig = np.where(trapped, np.nan, sig * scale * sc.h_rms ** 3 / (12.0 * eta_))
    u = np.where(trapped, np.nan, ub * sc.h_rms)
    pc = np.where(trapped, np.nan, pc)
    df = pd.DataFrame({"x": xo, "p0": p0o, "p_cont": pc, "p_fluid": pf, "u": u,
                       "sigma_eff": sig, "open": open_ & ~trapped, "trapped": trapped})
    df.attrs.update({"Q": float(row.Q), "lift_off": bool(row.lift_off),
                     "percolated": bool(row.percolated), "x_s": float(x_s), "x_e": float(x_e),
                     "theory": theory, "profile": kind, "references": list(REFERENCES),
                     "units": {"x": "m", "p0": "Pa", "p_cont": "Pa", "p_fluid": "Pa", "u": "m",
                               "sigma_eff": "m^3/(Pa s)", "open": "", "trapped": "",
                               "Q": "m^3/s", "x_s": "m", "x_e": "m"}})
    return df


def _uniform_fluid(sc, p0, pa, pb, dp, E, frac_x, lift_off, percolated):
    """p_f at fractions x/L of a flat ring (inverting the primitive)."""
    n = frac_x.size
    if pa > p0:                       # open everywhere: the fluid stands at p_a up to the outlet
        pf = np.full(n, pa)
        pf[-1] = pb
        return pf
    if percolated:                    # blocked at the outlet edge (zero-width barrier)
        pf = np.full(n, pa)
        pf[frac_x >= 1.0] = pb
        return pf
    if dp == 0.0:
        return np.full(n, pa)
    hi = (p0 - pb) / E
    w = min(dp / E, hi)
    total = _sigma.leak_integral(sc.tab, sc.rec, hi, w)
    pf = np.empty(n)
    for i, f in enumerate(frac_x):
        if f <= 0.0:
            pf[i] = pa
        elif f >= 1.0:
            pf[i] = pb
        else:
            # fraction f of the flow resistance lies in [0, x]: ∫_{c_lo}^{c(x)} σ̄ = f · total
            pf[i] = p0 - E * math.exp(_sigma.invert_uniform(sc.tab, sc.rec, hi, w, f, total))
    return pf


def _general_fluid(sc, geo, pa, pb, dp, E, xo, row, o):
    """p_f at the output positions for a Hertz or array profile (solving once more)."""
    n_out = xo.size
    if bool(np.isinf(row.Q)):
        pf = np.full(n_out, pa)
        pf[-1] = pb
        return pf, xo[-1], xo[-1]
    if geo[0] == "hertz":
        a, pH = geo[1], geo[2]
        p0_at = lambda xx: pH * np.sqrt(np.clip(1.0 - (xx / a - 1.0) ** 2, 0.0, 1.0))  # noqa: E731
        x0, x1 = 0.0, 2 * a
    else:
        xarr, p0x = geo[1], geo[2]
        p0_at = lambda xx: np.interp(xx, xarr, p0x)  # noqa: E731
        x0, x1 = xarr[0], xarr[-1]
    if bool(row.percolated):
        pc_perc = sc.p_perc * E
        fine = np.linspace(x0, x1, 20001) if geo[0] == "hertz" else np.union1d(geo[1], xo)
        p0f = p0_at(fine)
        i1 = np.flatnonzero(p0f - pa >= pc_perc)
        i2 = np.flatnonzero(p0f - pb >= pc_perc)
        xb1 = fine[i1[0]] if i1.size else x1
        xb2 = fine[i2[-1]] if i2.size else x1
        pf = np.where(xo < xb1, pa, np.where(xo > xb2, pb, np.nan))
        if not i1.size and not i2.size:
            pf[-1] = pb
        return pf, xb1, xb2
    x_s, x_e = row.open_inlet + x0, x1 - row.open_outlet
    if dp == 0.0:
        pf = np.full(n_out, pa)
        return pf, x_s, x_e
    eq = pa == (pH if geo[0] == "hertz" else float(np.max(p0x)))
    rule = panel_rule(o, tol=min(o["tol"], EQUALITY_TOL) if eq else None,
                      max_panels=max(o["max_panels"], 256) if eq else None)
    if geo[0] == "hertz":
        kind, ell, base = 0, a, np.array([pH / E])
        xg = pg = p0n = np.zeros(2)
        amp = pH / E
    else:
        L = x1 - x0
        kind, ell = 1, L
        xg = np.ascontiguousarray((xarr - x0) / L)
        pg = base = np.ascontiguousarray(p0x / E)
        p0n, amp = np.ascontiguousarray(p0x, dtype=np.float64), 1.0 / E
    mesh = _panels.Mesh(np.empty(rule.PMAX + 1), np.empty(rule.PMAX * rule.n),
                        np.empty(rule.PMAX * rule.n))
    W, _, P, _, _, _ = _panels.solve_row(sc.tab, sc.rec, rule, kind, xg, p0n, amp, pa / E,
                                         pb / E, 0.0, np.zeros(0), mesh)
    gp = np.empty(3)
    _mesh.zone_params(kind, base, xg, pg, pa / E, pb / E, gp)
    frac = np.empty(n_out)
    _mesh.remaining_at(kind, gp, xo, x0, ell, rule, mesh.pan, P, mesh.r, float(W), frac)
    pf = pb + dp * frac
    pf = np.where(xo <= x_s, pa, np.where(xo >= x_e, pb, pf))
    return pf, x_s, x_e
