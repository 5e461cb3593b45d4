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
    if x_extent is not None:
        x_extent = float(scalar("x_extent", check_positive("x_extent", x_extent, "[m]")))
    sc = seal_context(tables, theory)
    pr = _ElasticProblem(sc, Rv, fN, com["E_star"], com["p_b"], n, gap, x_extent)
    v, v_c = pr.dry_start(tables)
    dpv = com["dp"]
    if steps is not None:
        nsteps = int(steps)
    else:
        nsteps = 1 if dpv == 0 else max(2, int(math.ceil(6 * dpv / pr.pH)))
    its, converged, lifted, st = 0, True, False, None
    for k in (range(1, nsteps + 1) if dpv > 0 else [0]):
        dpk = dpv * k / nsteps if dpv > 0 else 0.0
        prev = (v.copy(), v_c, st)
        ok, v, v_c, st, it = pr.newton(v, v_c, dpk, tol, max_iter)
        its += it
        if st is None:                          # left the table: keep the last good step
            v, v_c, st = prev
            converged = False
            break
        if not ok:
            # a failure right after a step that left the contact nearly unloaded is lift-off
            if prev[2] is not None and pr.d * prev[2][2].sum() / fN < 0.05:
                v, v_c, st = prev
                lifted = True
            else:
                converged = False
            break
        if pr.d * st[2].sum() / fN < 1e-3:       # the contact carries nothing: lifted off
            lifted = True
            break
    scale = float(alpha_scale(sc, theory, np.array([alpha]))[0])
    return _elastic_frame(pr, com, theory, scale, v, v_c, st, converged, lifted, its)


def _elastic_frame(pr, com, theory, scale, v, v_c, st, converged, lifted, its):
    """The result DataFrame of :func:`seal_elastic` from the final state."""
    if st is None:
        raise ValueError("seal_elastic: the dry start lies outside the tables (contact pressure "
                         "above their top); reduce f_N or use tables reaching higher pressures")
    G, J, pc, pf, p0, W, perc = st
    pr._contact(v)                                  # σ̄ of the kept state
    h, eta_, pb = pr.h, com["eta"], com["p_b"]
    frac = float(pr.d * pc.sum() / pr.fN)
    lift = bool(lifted or (converged and frac < 1e-3))
    if perc:
        Q = 0.0
    elif lift:
        Q = math.inf                       # the contact no longer carries the load: open
    else:
        Q = com["L_y"] * com["dp"] * h ** 3 / (12.0 * eta_ * W) * scale
    sig = pr.sg * scale * h ** 3 / (12.0 * eta_)
    df = pd.DataFrame({"x": pr.xc + pr.X, "x_center": pr.xc, "p0": p0, "p_cont": pc,
                       "p_fluid": pf, "p_hertz": pr.phz, "u": v * h, "sigma_eff": sig})
    df.attrs.update({"Q": float(Q) if (converged or lift) else math.nan, "u_c": float(v_c * h),
                     "converged": bool(converged), "iterations": its, "percolated": bool(perc),
                     "lift_off": lift,
                     "contact_load_fraction": frac, "X": pr.X, "a": pr.a, "p_hertz_max": pr.pH,
                     "dp_reached": float(pf[0] - pb) if np.isfinite(pf[0]) else math.nan,
                     "theory": theory, "profile": "elastic", "references": list(REFERENCES),
                     "units": {"x": "m", "x_center": "m", "p0": "Pa", "p_cont": "Pa",
                               "p_fluid": "Pa", "p_hertz": "Pa", "u": "m",
                               "sigma_eff": "m^3/(Pa s)", "Q": "m^3/s", "u_c": "m"}})
    return df


class _ElasticProblem:
    """Panels, kernels and the Newton residual of one stiff seal (eqs. 27–30)."""

    def __init__(self, sc, R, fN, E, pb, n, gap, x_extent):
        self.sc, self.R, self.fN, self.E, self.pb, self.n = sc, R, fN, E, pb, n
        h = self.h = sc.h_rms
        a, pH = (float(v) for v in hertz_contact(R, fN, E))
        self.a, self.pH = a, pH
        if x_extent is None:
            target = gap * h / (a * a / (2 * R))
            if _hertz_gap(3.0) <= target:
                X = 3.0 * a
            else:
                X = a * brentq(lambda z: _hertz_gap(z) - target, 1.0, 3.0, xtol=1e-14)
        else:
            X = x_extent
        self.X = X
        d = self.d = 2 * X / n
        xc = self.xc = -X + d * (np.arange(n) + 0.5)
        self.Ke = (2.0 / (math.pi * E * h)) * _log_kernel(xc, d)   # per h_rms, per Pa
        self.xq = xc * xc / (2 * R * h)
        self.phz = pH * np.sqrt(np.clip(1.0 - (xc / a) ** 2, 0.0, 1.0))
        self.lnp, self.dlnp, self.sg, self.dls = (np.empty(n) for _ in range(4))
        self.M = np.tril(np.ones((n, n)), -1) + 0.5 * np.eye(n)   # cumulative midpoint rule
        self.KeM = self.Ke @ self.M                      # once: the flow part is rank-structured

    def _contact(self, v):
        _sigma.contact_of_u(self.sc.tab, self.sc.rec, np.ascontiguousarray(v), self.lnp,
                            self.dlnp, self.sg, self.dls)

    def dry_start(self, tables):
        """Dry Hertz start: rough-contact separation at the Hertz pressure plus the Hertz gap."""
        h, a, n = self.h, self.a, self.n
        pg = np.maximum(self.phz, 1e-4 * self.pH)
        v = np.asarray(tables.mean_separation(pg, self.E), dtype=float).reshape(n) / h
        out_ = np.abs(self.xc) > a
        v[out_] += _hertz_gap(np.abs(self.xc[out_]) / a) * a * a / (2 * self.R * h)
        self._contact(v)
        p0g = self.E * np.exp(self.lnp) + self.pb
        return v, float(np.mean(v - self.xq + self.Ke @ p0g))

    def state(self, v, v_c, dpk):
        """(G, J, p_cont, p_f, p0, W, percolated) at (ū/h, u_c/h), or None off the table."""
        n, d, Ke, pb = self.n, self.d, self.Ke, self.pb
        self._contact(v)
        lnp, dlnp, sg, dls = self.lnp, self.dlnp, self.sg, self.dls
        if not np.all(np.isfinite(lnp)):
            return None
        pc = self.E * np.exp(lnp)
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
                         - dpk * (self.KeM / W - KS[:, None] / W ** 2) * drho[None, :])
            colsum = pc * dlnp - dpk * (self.M.sum(axis=0) / W - S.sum() / W ** 2) * drho
        p0 = pc + pf
        G = np.empty(n + 1)
        G[:n] = v - v_c - self.xq + Ke @ p0
        G[n] = (d * p0.sum() - self.fN) / self.fN * 10.0
        J[:n, n] = -1.0
        J[n, :n] = d * colsum / self.fN * 10.0
        J[n, n] = 0.0
        return G, J, pc, pf, p0, W, blocked.any()

    def newton(self, v, v_c, dpk, tol, max_iter):
        """Damped Newton at fluid pressure difference dpk: (ok, v, v_c, state, iterations)."""
        n = self.n
        st = self.state(v, v_c, dpk)
        if st is None:
            return False, v, v_c, None, 0
        its = 0
        for _ in range(max_iter):
            gn = np.max(np.abs(st[0]))
            if gn < tol * max(1.0, np.max(np.abs(v))):
                return True, v, v_c, st, its
            its += 1
            try:
                delta = np.linalg.solve(st[1], -st[0])
            except np.linalg.LinAlgError:
                return False, v, v_c, st, its
            lam = 1.0
            acc = False
            while lam > 1e-6:
                vt = v + lam * delta[:n]
                if np.all(vt > 0):
                    vct = v_c + lam * delta[n]
                    stt = self.state(vt, vct, dpk)
                    if stt is not None and np.max(np.abs(stt[0])) < (1 - 1e-4 * lam) * gn:
                        v, v_c, st, acc = vt, vct, stt, True
                        break
                lam *= 0.5
            if not acc:
                self.state(v, v_c, dpk)        # restore the work arrays of the kept state
                return gn < 1e3 * tol * max(1.0, np.max(np.abs(v))), v, v_c, st, its
        return False, v, v_c, st, its
