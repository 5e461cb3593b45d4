"""Numba kernels: the soft-seal solver for a given nominal pressure p0(x) (private).

Unknown: the contact pressure c = p0 − p_f at the Gauss–Legendre nodes of adaptive panels
on the sealing zone (:mod:`._mesh`). Discrete eq. (33) of Lorenz & Persson (2010) in the
outlet-referenced form

    F_i = (p0_i − p_b) − c_i − Δp R̃_i / W = 0,   R̃_i = ∫_{t_i}^1 r dt,  W = ∫_0^1 r dt,
    r = (dξ/dt) / σ̄(c),

solved by damped Newton (block back-substitution from the outlet, the stable direction, plus
a Sherman–Morrison update for W). Panels whose Legendre tail of r exceeds ``tol``·W are
halved and the solution re-converged. Leak rate per unit length: q = (Δp/W) h³E*/(12ηℓ).
Next to percolation a failed Newton is continued in p_a from an easier problem
(:func:`solve_robust`). ``rule`` is the flat record :class:`fastcontact.seal.context.PanelRule`.

Barus fluid, η = η0 e^{α(p_f − p_b)} (issue 14; zone field ``al`` = α̃ = α E* > 0): the flux
is constant along the zone in the reduced pressure ψ = (1 − e^{−α(p_f − p_b)})/α, so R̃/W is
the remaining fraction of ψ_a = (1 − e^{−α Δp})/α, not of Δp, and

    F_i = (p0_i − p_b) − c_i − P(ψ_a R̃_i / W),   P(ψ) = −ln(1 − α̃ ψ)/α̃,

with q = (ψ_a/W) h³E*/(12η0ℓ). The Newton matrix is the constant-viscosity one with row i's
coupling multiplied by P'(ψ_i) = 1/(1 − α̃ ψ_i) (exact; α̃ = 0 is the base solver, bit for
bit). The contact pressure c = p0 − p_f is still the unknown, so σ̄ sees the fluid
pressure's feedback exactly as in the base engine.

Roelands fluid (zone field ``vis`` = (A, Z, π_r), A > 0): ψ = ∫η0/η dπ is tabulated per solve
(:mod:`._roelands_psi`) and has no closed-form inverse, so the residual is written in ψ and
scaled back to a pressure,

    F_i = (ψ(π_f,i) − ψ_a R̃_i / W) η(π_f,i)/η0,   π_f,i = (p0_i − p_b) − c_i,

the same root, and to first order in F the Barus form above; the Newton matrix is the
constant-viscosity one with row i's coupling multiplied by η(π_f,i)/η0.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..kernels._index import INT0, INT1
from ..kernels.borrow import borrowed
from ._mesh import (array_zone, geometry, interp_series, panel_series, remaining_fraction,
                    solve_small, zone_params)
from ._panel_records import Mesh, State, Work, Zone, _work
from ._roelands_psi import fluid_of, no_psi_table, psi_eta, psi_of, psi_table
from ._lookup import sig_d_cells
from ._sigma import table_sig_d

__all__ = ["solve_case", "solve_robust", "solve_row", "solve_rows", "solve_rows_chained", "ST_OK",
           "ST_NOT_REFINED",
           "ST_NEWTON_FAILED", "ST_NO_ZONE", "Zone", "State", "Work", "Mesh"]

#: status codes of solve_case
ST_OK, ST_NOT_REFINED, ST_NEWTON_FAILED, ST_NO_ZONE = 0, 1, 2, 3
#: int64 0 and 1 for jitted helpers' int arguments (:data:`fastcontact.kernels._index.INT0`)
_I0, _I1 = INT0, INT1


@njit(cache=True, inline="always")
def _psi_drop(dpi, al):
    """ψ_a = (1 − e^{−α̃ Δπ})/α̃ of a reduced pressure drop Δπ (Δπ itself for α̃ = 0)."""
    if al == 0.0:
        return dpi
    return -math.expm1(-al * dpi) / al


@njit(cache=True, inline="always")
def _fluid(psi, al):
    """The fluid pressure above the outlet, π_f − π_b = −ln(1 − α̃ψ)/α̃, of a reduced ψ."""
    if al == 0.0:
        return psi
    return -math.log1p(-al * psi) / al


@njit(cache=True, inline="always")
def _remaining(dpf, psia, al):
    """The remaining fraction ψ/ψ_a of a fluid pressure π_f − π_b = dpf (dpf/Δπ for α̃ = 0)."""
    if al == 0.0:
        return dpf / psia
    return -math.expm1(-al * dpf) / al / psia


@njit(cache=True, inline="always")
def _drop_v(dpi, al, rt):
    """ψ_a of the zone's fluid: :func:`_psi_drop`, or the Roelands table's ψ(Δπ)."""
    if rt.y.size:
        return psi_of(rt, dpi)
    return _psi_drop(dpi, al)


@njit(cache=True, inline="always")
def _fluid_v(psi, al, rt):
    """π_f − π_b of a reduced ψ: :func:`_fluid`, or the Roelands table's inverse."""
    if rt.y.size:
        return fluid_of(rt, psi)
    return _fluid(psi, al)


@njit(cache=True, inline="always")
def _remaining_v(dpf, psia, al, rt):
    """ψ/ψ_a of a fluid pressure π_f − π_b = dpf: :func:`_remaining`, or by the Roelands
    table."""
    if rt.y.size:
        return psi_of(rt, dpf) / psia
    return _remaining(dpf, psia, al)


@njit(cache=True)
def _zone_psi(zone):
    """The :data:`~._roelands_psi.PsiTable` of the zone's Roelands fluid (empty: none)."""
    if zone.vis.size and zone.vis[0] > 0.0:
        return psi_table(zone.vis[0], zone.vis[1], zone.vis[2], zone.pia - zone.pib)
    return no_psi_table()


@njit(cache=True)
def _fill_nodes(zone, rule, wk, P):
    """Nodes t, ξ, dξ/dt, e_a, e_b of the P panels of wk.pan."""
    kind, gp, xg, pg, pia, pib = zone.kind, zone.gp, zone.xg, zone.pg, zone.pia, zone.pib
    m, n, zl, pan = rule.m, rule.n, rule.zl, wk.pan
    t, xi, dxi, ea, eb = wk.t, wk.xi, wk.dxi, wk.ea, wk.eb
    for p in range(P):
        tl = pan[p]
        tr = pan[p + 1]
        for k in range(n):
            i = p * n + k
            tt = tl + 0.5 * (tr - tl) * (zl[k] + 1.0)
            t[i] = tt
            xi[i], dxi[i], ea[i], eb[i] = geometry(kind, gp, xg, pg, tt, m, pia, pib)


@njit(cache=True)
def _resid(tab, sc, rule, st, dxi, eb, dpi, al, rt, pan, P):
    """r = dξ/dt / σ̄(c), D = dr/dc, R̃ and F at c (the :class:`State` st) on the mesh pan;
    returns (W, max|F|, ok). Not the whole :class:`Work`: it is called per line-search step.
    ``dpi`` is ψ_a (= Δπ for a constant viscosity, α̃ = ``al`` = 0). A Roelands fluid (``rt``
    a non-empty :data:`~._roelands_psi.PsiTable`) has no closed-form inverse of ψ: its F is
    written in ψ and scaled back to a pressure, F_i = (ψ(π_f,i) − ψ_a R̃_i/W) η(π_f,i)/η0,
    π_f,i = e_b,i − c_i (the same root; to first order in F the same as e_b − c − P(ψ)).

    ok is False if σ̄ = 0 somewhere (c at/after percolation: infinite resistance)."""
    n, wl, At = rule.n, rule.wl, rule.At
    c, r, D, Rt, F, er_ = st
    N = P * n
    t_lo, t_hi, t_perc, b0, b1, rt0, rh = sc.t_lo, sc.t_hi, sc.t_perc, sc.b0, sc.b1, sc.rt0, sc.rh
    okc, lns, dlns = sc.ok, sc.lns, sc.dlns
    for i in range(N):
        ci = c[i]
        if ci <= 0.0:
            r[i] = 0.0
            D[i] = 0.0
            continue
        lc = math.log(ci)
        # sig_d on the record's fields taken out once (a call with both records per node cost
        # more than the lookup)
        s, dl, hit = sig_d_cells(t_lo, t_hi, t_perc, b0, b1, rt0, rh, okc, lns, dlns, lc)
        if not hit:
            s, dl = table_sig_d(tab, lc)
        if not s > 0.0:
            return 0.0, math.inf, False
        r[i] = dxi[i] / s
        D[i] = -r[i] * dl / ci
    after = 0.0
    for p in range(P - 1, -1, -1):
        hh = 0.5 * (pan[p + 1] - pan[p])
        tot = 0.0
        for k in range(n):
            tot += wl[k] * r[p * n + k]
        for i in range(n):
            acc = 0.0
            for k in range(n):
                acc += At[i, k] * r[p * n + k]
            Rt[p * n + i] = after + hh * acc
        after += hh * tot
    W = after
    if not W > 0.0:
        return W, math.inf, False
    fmax = 0.0
    roel = rt.y.size > 0
    rt = borrowed(rt)  # psi_eta inline: no reference counts per node
    for i in range(N):
        if roel:
            ps, er = psi_eta(rt, eb[i] - c[i])
            F[i] = (ps - dpi * Rt[i] / W) * er
            er_[i] = er
        elif al == 0.0:
            F[i] = eb[i] - c[i] - dpi * Rt[i] / W
        else:
            F[i] = eb[i] - c[i] - _fluid(dpi * Rt[i] / W, al)
        if abs(F[i]) > fmax:
            fmax = abs(F[i])
    return W, fmax, True


@njit(cache=True)
def _newton(tab, sc, rule, wk, dpi, al, rt, P, maxit, ftol):
    """Damped Newton on the current mesh wk.pan from wk.s0; wk.s0.c and wk.s0.r hold the
    result. Returns (W, its, ok). ``dpi`` is ψ_a, ``al`` α̃, ``rt`` the Roelands table
    (:func:`_resid`)."""
    n, wl, At = rule.n, rule.wl, rule.At
    pan, y1, y2, Y, K, dxi, eb = wk.pan, wk.y1, wk.y2, wk.Y, wk.K, wk.dxi, wk.eb
    N = P * n
    W, fmax, ok = _resid(tab, sc, rule, wk.s0, dxi, eb, dpi, al, rt, pan, P)
    if not ok:
        return W, 0, False
    roel = rt.y.size > 0
    cur = 0          # 0: current state in wk.s0; 1: in wk.s1
    its = 0
    conv = False
    while its < maxit:
        if fmax <= ftol:
            conv = True
            break
        its += 1
        now, trial = (wk.s0, wk.s1) if cur == 0 else (wk.s1, wk.s0)
        cc, DD, RR, FF, EE = now.c, now.D, now.Rt, now.F, now.er
        ct = trial.c
        # B̃ y = b for b1 = -F and b2 = u = dπ R̃/W²: block back-substitution from the outlet
        g = dpi / W
        S1 = 0.0
        S2 = 0.0
        for p in range(P - 1, -1, -1):
            hh = 0.5 * (pan[p + 1] - pan[p])
            for i in range(n):
                # Barus: row i's coupling times P'(ψ_i) = 1/(1 − α̃ ψ_i) (1 for α̃ = 0);
                # Roelands: times η/η0 at the node's fluid pressure (F scaled by it)
                if roel:  # η/η0 of the residual that gave this state (the same value)
                    gi = g * EE[p * n + i]
                else:
                    gi = g if al == 0.0 else g / (1.0 - al * g * RR[p * n + i])
                for k in range(n):
                    K[i, k] = -gi * hh * At[i, k] * DD[p * n + k]
                K[i, i] -= 1.0
                Y[i, 0] = -FF[p * n + i] + gi * S1
                Y[i, 1] = gi * RR[p * n + i] / W + gi * S2
            if not solve_small(K, Y, n, 2):
                return W, its, False
            for k in range(n):
                wk_ = hh * wl[k] * DD[p * n + k]
                y1[p * n + k] = Y[k, 0]
                y2[p * n + k] = Y[k, 1]
                S1 += wk_ * Y[k, 0]
                S2 += wk_ * Y[k, 1]
        # Sherman–Morrison: δ = y1 − y2 (vᵀy1)/(1 + vᵀy2), v = w∘D
        den = 1.0 + S2
        if den == 0.0:
            return W, its, False
        fac = S1 / den
        dmax = 0.0
        for i in range(N):
            y1[i] = y1[i] - y2[i] * fac
            if abs(y1[i]) > dmax:
                dmax = abs(y1[i])
        lam = 1.0
        accepted = False
        for ls in range(24):
            for i in range(N):
                ct[i] = cc[i] + lam * y1[i]
            Wt, ft, okt = _resid(tab, sc, rule, trial, dxi, eb, dpi, al, rt, pan, P)
            if okt and ft <= (1.0 - 1e-4 * lam) * fmax:
                accepted = True
                break
            lam *= 0.5
        if not accepted:
            conv = fmax <= 1e3 * ftol      # stagnated at round-off
            break
        cur = 1 - cur
        W = Wt
        fmax = ft
        if lam * dmax <= 1e-3 * ftol:
            conv = True
            break
    if cur == 1:
        c, r, c2, r2 = wk.s0.c, wk.s0.r, wk.s1.c, wk.s1.r
        for i in range(N):
            c[i] = c2[i]
            r[i] = r2[i]
    return W, its, conv


@njit(cache=True)
def _first_guess(zone, rt, m, wk, N, cperc, init_P, init_s):
    """Initial contact pressure c (into wk.s0.c) at the N nodes: c = e_b − Δπ s with
    s = init_s (continuation, init_P > 0) or the fluid pressure linear in ξ across the zone
    (Barus: s the remaining fraction of ψ, c = e_b − P(ψ_a s)),
    capped below percolation. Returns the Newton tolerance on F (1e-13 of the pressure scale)."""
    kind, gp, xg, pg, pia, pib = zone.kind, zone.gp, zone.xg, zone.pg, zone.pia, zone.pib
    xi, eb, c = wk.xi, wk.eb, wk.s0.c
    dpi = pia - pib
    psia = _drop_v(dpi, zone.al, rt)
    scale = dpi
    for i in range(N):
        scale = max(scale, abs(eb[i]))
    g0 = geometry(kind, gp, xg, pg, 0.0, m, pia, pib)[0]
    g1 = geometry(kind, gp, xg, pg, 1.0, m, pia, pib)[0]
    for i in range(N):
        if init_P > 0:
            s = init_s[i]
        else:
            s = (g1 - xi[i]) / (g1 - g0) if g1 > g0 else 0.5
        ci = eb[i] - _fluid_v(psia * s, zone.al, rt)
        if ci > 0.9 * cperc and init_P == 0:
            ci = 0.9 * cperc
        c[i] = ci
    return 1e-13 * scale


@njit(cache=True)
def _indicator(r, pan, P, n, Lp, coef, after, W, tol, err):
    """Error indicator per panel (Legendre tail of r relative to W) into err; returns (number
    of panels above tol, sum of the indicators). Leaves r's panel series in coef/after."""
    panel_series(r, pan, P, n, Lp, coef, after)
    nsplit = 0
    est = 0.0
    for p in range(P):
        e = (abs(coef[p, n - 1]) + abs(coef[p, n - 2])) * (pan[p + 1] - pan[p]) / W
        err[p] = e
        est += e
        if e > tol:
            nsplit += 1
    return nsplit, est


@njit(cache=True)
def _series_at_nodes(pan_new, P_new, rule, pan, P, coef, after, W, Pk, remaining, out):
    """At the Gauss–Legendre nodes of the mesh pan_new (P_new panels), the converged
    solution's remaining fraction s(t) (``remaining``) or its series of r (coef) into out."""
    zl, n = rule.zl, rule.n
    for p in range(P_new):
        tl = pan_new[p]
        tr = pan_new[p + 1]
        for k in range(n):
            tt = tl + 0.5 * (tr - tl) * (zl[k] + 1.0)
            if remaining:
                out[p * n + k] = remaining_fraction(tt, pan, P, n, coef, after, W, Pk)
            else:
                out[p * n + k] = interp_series(tt, pan, P, n, coef, Pk)


@njit(cache=True)
def _halve(pan, P, err, tol, pan2):
    """pan2: the mesh pan with every panel whose err exceeds tol halved; returns its panels."""
    q = 0
    for p in range(P):
        pan2[q] = pan[p]
        q += 1
        if err[p] > tol:
            pan2[q] = 0.5 * (pan[p] + pan[p + 1])
            q += 1
    pan2[q] = 1.0
    return q


@njit(cache=True)
def solve_case(tab, sc, rule, tol, maxit, zone, out, init_P, init_pan, init_s, s_out):
    """Solve one soft seal on its sealing zone (:class:`Zone`; see the module docstring).

    Returns (W, status, panels, error_estimate, newton_iterations), W = ∫ dξ/σ̄ over the
    zone. ``out`` (:class:`Mesh`: pan PMAX+1, c and r PMAX·n) receives the final mesh and the
    nodal contact pressure and resistance density; s_out (optional) the remaining fraction of
    the pressure drop (p_f − p_b)/Δp at the nodes (Barus: of ψ, ψ/ψ_a). With init_P > 0 the
    first mesh is init_pan and the initial guess c = (p0 − p_b) − Δp·init_s at its nodes
    (continuation; Barus: − P(ψ_a init_s)); otherwise P0 uniform panels and a fluid pressure
    linear in x. s_out is filled if it is large enough (pass an empty array to skip).
    """
    n, P0, PMAX = rule.n, rule.P0, rule.PMAX
    Lp = rule.Lp
    al = zone.al
    rt = _zone_psi(zone)
    dpi = _drop_v(zone.pia - zone.pib, al, rt)  # ψ_a: Δπ for a constant viscosity
    wk = _work(n, PMAX)
    pan, pan2, err, coef, after, Pk = wk.pan, wk.pan2, wk.err, wk.coef, wk.after, wk.Pk
    c, r, eb, y1 = wk.s0.c, wk.s0.r, wk.eb, wk.y1
    P = init_P if init_P > 0 else P0
    for p in range(P + 1):
        pan[p] = init_pan[p] if init_P > 0 else p / P
    _fill_nodes(zone, rule, wk, P)
    ftol = _first_guess(zone, rt, rule.m, wk, P * n, sc.p_perc, init_P, init_s)
    status = ST_OK
    total_it = 0
    est = math.inf
    W = 0.0
    polish = False
    for rnd in range(4 * PMAX + 1):
        # intermediate meshes: converge loosely (the indicator needs r to ~1e-9 only); the
        # final mesh: polish to round-off (each round adds a panel: the bound is never reached)
        W, its, conv = _newton(tab, sc, rule, wk, dpi, al, rt, P, maxit,
                               ftol if polish else 1e4 * ftol)
        total_it += its
        if not conv:
            status = ST_NEWTON_FAILED
            break
        if polish:
            break
        nsplit, est = _indicator(r, pan, P, n, Lp, coef, after, W, tol, err)
        if nsplit == 0 or P + nsplit > PMAX:
            if nsplit > 0:
                status = ST_NOT_REFINED
            polish = True
            continue
        Pn = _halve(pan, P, err, tol, pan2)
        # new nodes: remaining fraction s(t) of the converged solution, then c = e_b − Δπ s
        _series_at_nodes(pan2, Pn, rule, pan, P, coef, after, W, Pk, True, y1)
        for p in range(Pn + 1):
            pan[p] = pan2[p]
        P = Pn
        _fill_nodes(zone, rule, wk, P)
        for i in range(P * n):
            c[i] = eb[i] - _fluid_v(dpi * y1[i], al, rt)
    _copy_mesh(P, n, pan, c, r, out.pan, out.c, out.r)
    if s_out.size >= P * n:
        for i in range(P * n):
            s_out[i] = _remaining_v(eb[i] - c[i], dpi, al, rt)
    return W, status, P, est, total_it


@njit(cache=True)
def _copy_mesh(P, n, pan, c, r, pan_out, c_out, r_out):
    """The mesh (P panels of n nodes), c and r into the output arrays."""
    for p in range(P + 1):
        pan_out[p] = pan[p]
    for i in range(P * n):
        c_out[i] = c[i]
        r_out[i] = r[i]


@njit(cache=True)
def _continuation(cperc, pmax, pia, pib):
    """(ok, p_a0, δ0, δ_T) of the continuation in p_a: its start p_a0 where the peak contact
    pressure max p0 − p_a is 0.6 p_perc (δ = p_perc − (max p0 − p_a) from δ0 down to its
    target δ_T), or halfway in p_a without percolation; ok False if no easier start exists."""
    if cperc < math.inf:
        dT = cperc - (pmax - pia)
        d0 = max(dT, 0.4 * cperc, cperc - pmax + pib + 0.5 * (pia - pib))
        if not d0 > dT:
            return False, 0.0, d0, dT
        return True, pmax - cperc + d0, d0, dT
    return True, pib + 0.5 * (pia - pib), 0.0, 0.0


@njit(cache=True)
def _refine_previous(rule, r_prev, pan, P, W_prev, coef, after, Pk, new):
    """After a failed continuation step: halve the previous solution's panels where its
    resistance concentrates (the peak sharpens as δ falls and the Newton needs it resolved);
    if that adds panels (within PMAX), its remaining fraction into new.c and its r (by
    interpolation) into new.r on the new mesh new.pan (:class:`Mesh`). Returns the new panel
    count."""
    n, Lp, PMAX = rule.n, rule.Lp, rule.PMAX
    pan_new = new.pan
    panel_series(r_prev, pan, P, n, Lp, coef, after)
    q = 0
    for p in range(P):
        pan_new[q] = pan[p]
        q += 1
        if (pan[p + 1] - pan[p]) * coef[p, 0] > 0.02 * W_prev and q < PMAX:
            pan_new[q] = 0.5 * (pan[p] + pan[p + 1])
            q += 1
    pan_new[q] = 1.0
    if q > P and q <= PMAX:
        _series_at_nodes(pan_new, q, rule, pan, P, coef, after, W_prev, Pk, True, new.c)
        _series_at_nodes(pan_new, q, rule, pan, P, coef, after, W_prev, Pk, False, new.r)
    return q


@njit(cache=True)
def solve_robust(tab, sc, rule, kind, base, xg, pg, pmax, pia, pib, al, vis, out):
    """solve_case, and if Newton fails from the plain initial guess (close to percolation,
    where ln σ̄ falls by ~10³ per unit ln p), continuation in p_a: start where the peak
    contact pressure max p0 − p_a is 0.6 p_perc (or halfway in p_a for the average theory),
    then step the distance to percolation δ = p_perc − (max p0 − p_a) geometrically down to
    its target, each step starting from the previous solution on the previous mesh.
    ``out`` (:class:`Mesh`) receives the final mesh, c and r; ``al`` α̃ of a Barus fluid (0:
    constant viscosity), ``vis`` the Roelands law (A, Z, π_r) (size 0 or A = 0: none).
    Returns (W, status, panels, error_estimate, newton_iterations, continuation_steps)."""
    n, PMAX = rule.n, rule.PMAX
    gp = np.empty(3)
    if not zone_params(kind, base, xg, pg, pia, pib, gp):
        return 0.0, ST_NO_ZONE, 0, 0.0, 0, 0
    nil = np.empty(0)
    W, st, P, est, its = solve_case(tab, sc, rule, rule.tol, rule.maxit,
                                    Zone(kind, gp, xg, pg, pia, pib, al, vis), out, _I0, nil, nil, nil)
    if st != ST_NEWTON_FAILED:
        return W, st, P, est, its, 0
    cperc = sc.p_perc
    ok, pa0, d0, dT = _continuation(cperc, pmax, pia, pib)
    if not ok:
        return W, st, P, est, its, 0
    NMAX = PMAX * n
    pan = np.empty(PMAX + 1)
    sn = np.empty(NMAX)
    cc = np.empty(NMAX)
    rr = np.empty(NMAX)
    zone_params(kind, base, xg, pg, pa0, pib, gp)
    W, st, P, est, it0 = solve_case(tab, sc, rule, 1e-2, rule.maxit,
                                    Zone(kind, gp, xg, pg, pa0, pib, al, vis), Mesh(pan, cc, rr),
                                    _I0, pan, sn, sn)
    its += it0
    if st == ST_NEWTON_FAILED:
        return W, st, P, est, its, 0
    lam = 0.0
    step = 0.1
    steps = 0
    pan_new = np.empty(PMAX + 1)
    s_new = np.empty(NMAX)
    r_prev = np.empty(NMAX)
    coef = np.empty((PMAX, n))
    after = np.empty(PMAX)
    Pk = np.empty(n + 1)
    for i in range(P * n):
        r_prev[i] = rr[i]
    W_prev = W
    while lam < 1.0 and steps < 80 and its < 4000:
        steps += 1
        lt = min(1.0, lam + step)
        pa = pmax - cperc + d0 * (dT / d0) ** lt if cperc < math.inf else pa0 + lt * (pia - pa0)
        if lt == 1.0:
            pa = pia
        zone_params(kind, base, xg, pg, pa, pib, gp)
        W2, st2, P2, est2, it2 = solve_case(tab, sc, rule, rule.tol, min(rule.maxit, 25),
                                            Zone(kind, gp, xg, pg, pa, pib, al, vis),
                                            Mesh(pan_new, cc, rr), P, pan, sn, s_new)
        its += it2
        if st2 == ST_NEWTON_FAILED:
            # first refine the previous solution, then shorten the step
            q = _refine_previous(rule, r_prev, pan, P, W_prev, coef, after, Pk,
                                 Mesh(pan_new, s_new, rr))
            if q > P and q <= PMAX:
                P = q
                _copy_mesh(P, n, pan_new, s_new, rr, pan, sn, r_prev)
                continue
            step *= 0.5
            if step < 1e-3:
                return W2, ST_NEWTON_FAILED, P2, est2, its, steps
            continue
        lam = lt
        P = P2
        _copy_mesh(P, n, pan_new, s_new, rr, pan, sn, r_prev)
        W, st, est = W2, st2, est2
        W_prev = W
        step = min(2.0 * step, 0.5)
    if lam < 1.0:
        return W, ST_NEWTON_FAILED, P, est, its, steps
    _copy_mesh(P, n, pan, cc, rr, out.pan, out.c, out.r)
    return W, st, P, est, its, steps


@njit(cache=True)
def solve_row(tab, sc, rule, kind, xg, p0n, amp, pia, pib, al, vis, mesh):
    """One soft seal: (W, status, panels, error_estimate, x_s, x_e); ``al`` α̃ = α E* of a
    Barus fluid (0: constant viscosity; W is then the resistance of ψ_a, q ∝ ψ_a/W), ``vis``
    a Roelands law (A, Z, π_r) (size 0: none; W the resistance of its ψ_a).

    kind 0, Hertz: amp = π_H (p0n unused); kind 1, array: p0 = p0n·amp at ξ = xg (p0n [Pa],
    amp = 1/E*). Reduced π_a, π_b. W = ∫dξ/σ̄ over the sealing zone; ``mesh``
    (:class:`Mesh`) receives the final mesh, c and the resistance density (for the profile
    evaluation); x_s, x_e the array profile's sealing zone (NaN for Hertz)."""
    if kind == 0:
        base1 = np.empty(1)
        base1[0] = amp
        W, st, P, est, its, cs = solve_robust(tab, sc, rule, _I0, base1, xg, p0n, amp, pia, pib,
                                              al, vis, mesh)
        xs = math.nan
        xe = math.nan
    else:
        pg = p0n * amp
        xs, xe = array_zone(xg, pg, pia, pib)
        W, st, P, est, its, cs = solve_robust(tab, sc, rule, _I1, pg, xg, pg, pg.max(), pia, pib,
                                              al, vis, mesh)
    return W, st, P, est, xs, xe


@njit(cache=True)
def _store_row(out, i, W, st, P, est, xs, xe):
    """Row i of the batch record ``out`` (W, status, panels, err, xs, xe)."""
    out.xs[i] = xs
    out.xe[i] = xe
    out.W[i] = W
    out.status[i] = st
    out.panels[i] = P
    out.err[i] = est


@njit(cache=True, parallel=True)
def solve_rows(tab, sc, rule, kind, xg, p0n, amp, pia, pib, al, vis, rows, out):
    """Soft seals of the rows listed in ``rows`` (parallel; see :func:`solve_row`) into
    ``out`` (flat record of arrays W, status, panels, err, xs, xe); ``al`` per row (α̃ of a
    Barus fluid, 0: constant viscosity), ``vis`` (rows, 3) the Roelands law (A, Z, π_r) per
    row, or (rows, 0): none."""
    for j in prange(rows.size):
        i = rows[j]
        mesh = Mesh(np.empty(rule.PMAX + 1), np.empty(rule.PMAX * rule.n),
                    np.empty(rule.PMAX * rule.n))
        W, st, P, est, xs, xe = solve_row(tab, sc, rule, kind, xg, p0n, amp[i], pia[i], pib[i],
                                          al[i], vis[i], mesh)
        _store_row(out, i, W, st, P, est, xs, xe)


@njit(cache=True, parallel=True)
def solve_rows_chained(tab, sc, rule, xg, p0n, amp, pia, pib, al, vis, rows, starts, out):
    """Hertz soft seals (kind 0) as :func:`solve_rows`, in chains: rows[starts[c]:starts[c+1]]
    share π_H, π_b and the fluid and rise in π_a (a Δp sweep of one O-ring). A chain's first
    row is solved cold (:func:`solve_robust`); each later row starts its Newton on the
    previous row's final mesh and remaining fraction s = R̃/W (the continuation inputs of
    :func:`solve_case`, as :func:`solve_robust`'s steps in p_a), and is solved cold where that
    fails. The result meets the same tolerance either way; a warm start keeps a mesh refined for
    the previous row, so W can differ from a cold solve by ~1e-8 at the O-rings' panel
    tolerance 1e-6 (~1e-10 at 1e-7), by the chain the row is in."""
    PMAX, n = rule.PMAX, rule.n
    for c in prange(starts.size - 1):
        mesh = Mesh(np.empty(PMAX + 1), np.empty(PMAX * n), np.empty(PMAX * n))
        pan_prev = np.empty(PMAX + 1)
        s_prev = np.empty(PMAX * n)
        coef = np.empty((PMAX, n))
        after = np.empty(PMAX)
        Pk = np.empty(n + 1)
        gp = np.empty(3)
        base1 = np.empty(1)
        nil = np.empty(0)
        P_prev = _I0  # int64 throughout: a literal 0 would reach solve_case as Literal[int](0)
        for j in range(starts[c], starts[c + 1]):
            i = rows[j]
            st = ST_NEWTON_FAILED
            W = 0.0
            P = _I0
            est = 0.0
            base1[0] = amp[i]
            if P_prev > 0 and zone_params(_I0, base1, xg, p0n, pia[i], pib[i], gp):
                W, st, P, est, _its = solve_case(
                    tab, sc, rule, rule.tol, rule.maxit,
                    Zone(0, gp, xg, p0n, pia[i], pib[i], al[i], vis[i]), mesh, P_prev, pan_prev,
                    s_prev, nil)
            if st == ST_NEWTON_FAILED:
                W, st, P, est, _xs, _xe = solve_row(tab, sc, rule, _I0, xg, p0n, amp[i], pia[i],
                                                    pib[i], al[i], vis[i], mesh)
            _store_row(out, i, W, st, P, est, math.nan, math.nan)
            P_prev = _I0
            if st != ST_NEWTON_FAILED and st != ST_NO_ZONE and W > 0.0 and P > 0:
                # the next row's start: this one's mesh and remaining fraction at its nodes
                panel_series(mesh.r, mesh.pan, P, n, rule.Lp, coef, after)
                _series_at_nodes(mesh.pan, P, rule, mesh.pan, P, coef, after, W, Pk, True,
                                 s_prev)
                for p in range(P + 1):
                    pan_prev[p] = mesh.pan[p]
                P_prev = P
