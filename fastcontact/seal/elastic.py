"""Stiff seals: the macroscopic elastic deformation coupled to the flow (Lorenz & Persson 2010,
eq. 30): :func:`seal_elastic`, one case, boundary elements with exact log-kernel panels."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from .._core.validate import check_positive, check_range
from . import _sigma
from ._inputs import alpha_scale, check_tables, check_theory_for, common_inputs, hertz_contact, scalar
from .api import REFERENCES
from .context import seal_context

__all__ = ["seal_elastic"]


def _hertz_gap(xi):
    """Hertz line-contact gap outside the contact in units of a²/(2R), ξ = |x|/a >= 1."""
    s = np.sqrt(np.maximum(xi * xi - 1.0, 0.0))
    return xi * s - np.log(xi + s)


def _log_kernel(x, d):
    """K[i, j] = ∫_{panel j} ln|x_i − x'| dx' for panels of width d centred at x (exact)."""
    def G(s):
        a = np.abs(s)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(a > 0, s * np.log(a) - s, 0.0)
    dx = x[:, None] - x[None, :]
    return G(dx + 0.5 * d) - G(dx - 0.5 * d)


def seal_elastic(tables, *, R, f_N, dp, L_y, E_star, eta, theory="critical_junction",
                 alpha_cj=1.0, p_b=0.0, a_perc=None, n=400, gap=40.0, x_extent=None,
                 steps=None, tol=1e-10, max_iter=80):
    """Stiff seal (paper eq. 30): the macroscopic elastic deformation responds to contact and
    fluid pressure. One case (scalars), cylinder of radius ``R`` [m] pressed with ``f_N`` [N/m].

    Unknowns on ``n`` piecewise-constant pressure panels over x ∈ [−X, X] (x from the cylinder
    axis; fluid inlet at −X with p_a = p_b + dp, outlet at +X with p_b), solved together:

    * ū(x) = u_c + x²/(2R) − (2/(πE*)) ∫ p0(x') ln|x − x'| dx'    (eq. 30; its ln|x'| term is
      a constant and is absorbed in u_c) — exact panel integrals of the log kernel;
    * p_cont(x) = p_cont(ū(x)) from the tables (the rough-contact law; asymptote beyond them);
    * p_f(x) from the flow, eq. (27): p_f = p_a − dp s(x)/s(X), s = ∫ dx/σ_eff(p_cont);
    * p0 = p_cont + p_f (eq. 28) and ∫ p0 dx = f_N (eq. 29, per unit length).

    Newton on (ū at the panel centres, u_c) with a dense Jacobian and backtracking, started
    from the dry Hertz solution and continued in dp. The domain half-width X is where the dry
    Hertz gap reaches ``gap``·h_rms (at most 3a), unless ``x_extent`` [m] is given: the fluid
    pressure loads the interface only inside [−X, X] (beyond it the surfaces are far apart and
    the fluid acts on the free surface, not modelled). Percolated contact (σ_eff = 0 on a
    panel) stops the flow: Q = 0, p_f = p_a upstream and p_b downstream of the blocked panels,
    and the trapped fluid in them is taken at p_b (an assumption: its pressure is undetermined).

    Returns a DataFrame per panel: ``x`` [m] from the inlet, ``x_center`` [m] from the axis,
    ``p0``, ``p_cont``, ``p_fluid``, ``p_hertz`` (dry Hertz, for comparison) [Pa], ``u`` [m],
    ``sigma_eff`` [m³/(Pa·s)]; ``df.attrs``: ``Q`` [m³/s], ``u_c`` [m], ``converged``,
    ``iterations``, ``percolated``, ``lift_off`` (the contact carries < 0.1 % of f_N at some
    continuation step, or Newton fails right after a step where it carried < 5 %: Q = inf and
    the profiles are those of the last converged step), ``dp_reached`` (the dp of the profiles),
    ``contact_load_fraction``, ``X``, ``a``, ``p_hertz_max``.
    """
    check_tables(tables)
    alpha = scalar("alpha_cj", check_theory_for(tables, theory, alpha_cj, a_perc))
    com = {k: scalar(k, v) for k, v in common_inputs(dp, L_y, E_star, eta, p_b).items()}
    Rv = scalar("R", check_positive("R", R, "[m]"))
    fN = scalar("f_N", check_positive("f_N", f_N, "[N/m]"))
    n = int(check_range("n", n, 8, 5000, "[-] (panels)"))
    gap = float(check_positive("gap", gap, "[-] (multiples of h_rms)"))
    E, eta_, dpv, pb = com["E_star"], com["eta"], com["dp"], com["p_b"]
    sc = seal_context(tables, theory)
    h = sc.h_rms
    a, pH = (float(v) for v in hertz_contact(Rv, fN, E))
    if x_extent is None:
        target = gap * h / (a * a / (2 * Rv))
        if _hertz_gap(3.0) <= target:
            X = 3.0 * a
        else:
            X = a * brentq(lambda z: _hertz_gap(z) - target, 1.0, 3.0, xtol=1e-14)
    else:
        X = float(scalar("x_extent", check_positive("x_extent", x_extent, "[m]")))
    d = 2 * X / n
    xc = -X + d * (np.arange(n) + 0.5)
    K = _log_kernel(xc, d)
    Ke = (2.0 / (math.pi * E * h)) * K            # (per h_rms) displacement per Pa
    xq = xc * xc / (2 * Rv * h)
    phz = pH * np.sqrt(np.clip(1.0 - (xc / a) ** 2, 0.0, 1.0))
    scale = float(alpha_scale(sc, theory, np.array([alpha]))[0])
    lnp = np.empty(n)
    dlnp = np.empty(n)
    sg = np.empty(n)
    dls = np.empty(n)

    M = np.tril(np.ones((n, n)), -1) + 0.5 * np.eye(n)   # cumulative midpoint rule
    KeM = Ke @ M                                          # once: the flow part is rank-structured

    def state(v, dpk):
        _sigma.contact_of_u(sc.tab, sc.rec, np.ascontiguousarray(v), lnp, dlnp, sg, dls)
        if not np.all(np.isfinite(lnp)):
            return None
        pc = E * np.exp(lnp)
        blocked = ~(sg > 0)
        J = np.empty((n + 1, n + 1))
        if blocked.any():
            i1 = np.flatnonzero(blocked)[0]
            pf = np.full(n, pb)
            pf[:i1] = pb + dpk
            W = np.inf
            colsum = pc * dlnp
            J[:n, :n] = np.eye(n) + Ke * colsum[None, :]
        else:
            rho = d / sg
            S = np.cumsum(rho) - 0.5 * rho
            W = rho.sum()
            pf = (pb + dpk) - dpk * S / W
            drho = -rho * dls * dlnp                 # ∂ρ_k/∂v_k
            # ∂p_f/∂v = −dp (M/W − S 1ᵀ/W²) diag(∂ρ/∂v)
            KS = Ke @ S
            J[:n, :n] = (np.eye(n) + Ke * (pc * dlnp)[None, :]
                         - dpk * (KeM / W - KS[:, None] / W ** 2) * drho[None, :])
            colsum = pc * dlnp - dpk * (M.sum(axis=0) / W - S.sum() / W ** 2) * drho
        p0 = pc + pf
        G = np.empty(n + 1)
        G[:n] = v - v_c[0] - xq + Ke @ p0
        G[n] = (d * p0.sum() - fN) / fN * 10.0
        J[:n, n] = -1.0
        J[n, :n] = d * colsum / fN * 10.0
        J[n, n] = 0.0
        return G, J, pc, pf, p0, W, blocked.any()

    # dry Hertz start: rough-contact separation at the Hertz pressure plus the Hertz gap
    pg = np.maximum(phz, 1e-4 * pH)
    v = np.asarray(tables.mean_separation(pg, E), dtype=float).reshape(n) / h
    out_ = np.abs(xc) > a
    v[out_] += _hertz_gap(np.abs(xc[out_]) / a) * a * a / (2 * Rv * h)
    v_c = np.zeros(1)
    _sigma.contact_of_u(sc.tab, sc.rec, np.ascontiguousarray(v), lnp, dlnp, sg, dls)
    p0g = E * np.exp(lnp) + pb
    v_c[0] = float(np.mean(v - xq + Ke @ p0g))
    if steps is not None:
        nsteps = int(steps)
    else:
        nsteps = 1 if dpv == 0 else max(2, int(math.ceil(6 * dpv / pH)))
    its = 0
    converged = True
    lifted = False
    st = None
    for k in (range(1, nsteps + 1) if dpv > 0 else [0]):
        dpk = dpv * k / nsteps if dpv > 0 else 0.0
        prev = (v.copy(), v_c[0], st)
        st = state(v, dpk)
        if st is None:
            converged = False
            break
        ok = False
        for it in range(max_iter):
            G, J, pc, pf, p0, W, perc = st
            gn = np.max(np.abs(G))
            if gn < tol * max(1.0, np.max(np.abs(v))):
                ok = True
                break
            its += 1
            try:
                delta = np.linalg.solve(J, -G)
            except np.linalg.LinAlgError:
                break
            lam = 1.0
            acc = False
            while lam > 1e-6:
                vt = v + lam * delta[:n]
                if np.all(vt > 0):
                    vc0 = v_c[0]
                    v_c[0] = vc0 + lam * delta[n]
                    stt = state(vt, dpk)
                    if stt is not None and np.max(np.abs(stt[0])) < (1 - 1e-4 * lam) * gn:
                        v, st, acc = vt, stt, True
                        break
                    v_c[0] = vc0
                lam *= 0.5
            if not acc:
                ok = gn < 1e3 * tol * max(1.0, np.max(np.abs(v)))
                break
        if not ok:
            # a failure right after a step that left the contact nearly unloaded is lift-off
            if prev[2] is not None and d * prev[2][2].sum() / fN < 0.05:
                v, v_c[0], st = prev[0], prev[1], prev[2]
                lifted = True
            else:
                converged = False
            break
        if d * st[2].sum() / fN < 1e-3:          # the contact carries nothing: lifted off
            lifted = True
            break
    G, J, pc, pf, p0, W, perc = st
    frac = float(d * pc.sum() / fN)
    lift = bool(lifted or (converged and frac < 1e-3))
    if perc:
        Q = 0.0
    elif lift:
        Q = math.inf                       # the contact no longer carries the load: open
    else:
        Q = com["L_y"] * dpv * h ** 3 / (12.0 * eta_ * W) * scale
    sig = sg * scale * h ** 3 / (12.0 * eta_)
    df = pd.DataFrame({"x": xc + X, "x_center": xc, "p0": p0, "p_cont": pc, "p_fluid": pf,
                       "p_hertz": phz, "u": v * h, "sigma_eff": sig})
    df.attrs.update({"Q": float(Q) if (converged or lift) else math.nan, "u_c": float(v_c[0] * h),
                     "converged": bool(converged), "iterations": its, "percolated": bool(perc),
                     "lift_off": lift,
                     "contact_load_fraction": frac, "X": X, "a": a, "p_hertz_max": pH,
                     "dp_reached": float(pf[0] - pb) if np.isfinite(pf[0]) else math.nan,
                     "theory": theory, "profile": "elastic", "references": list(REFERENCES),
                     "units": {"x": "m", "x_center": "m", "p0": "Pa", "p_cont": "Pa",
                               "p_fluid": "Pa", "p_hertz": "Pa", "u": "m",
                               "sigma_eff": "m^3/(Pa s)", "Q": "m^3/s", "u_c": "m"}})
    return df
