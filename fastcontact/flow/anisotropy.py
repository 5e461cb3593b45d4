"""Directional flow conductivities σ_xx, σ_yy for anisotropic roughness (Tripp/Peklenik γ_T).

The roughness is stretched along x: γ_T = ξ_x/ξ_y >= 1 is the ratio of the correlation
lengths (Peklenik number; "x" = along the grooves of a machined or brushed surface). The
contact mechanics (A(ζ), u1(ζ), P(u)) is that of the angle-averaged spectrum C(q) (Persson
2010: the anisotropy enters the flow, not the area); the non-contact and contact patches
become ellipses of aspect ratio γ_T aligned with x, and the 2-D Bruggeman medium uses their
depolarization factors (docs/theory/extensions.md §3):

``form="self_consistent"`` (default): the depolarization factor of an ellipse in the
    *anisotropic* effective medium (affine map to an isotropic host, Stroud 1975),
    n_x = 1/(1 + λ), λ = γ_T √(σ_yy/σ_xx); two coupled equations
    ∫ P(u) (σ(u) - σ_xx)/(λ σ_xx + σ(u)) du = 0 and the same in y with 1/λ.
    Both conductivities vanish together at A(ζ1)/A0 = 1/2, with σ_yy/σ_xx → 1/γ_T² there
    (the threshold is independent of γ_T, as Persson 2020 finds).
``form="fixed"``: depolarization in an isotropic host, n_x = 1/(1 + γ_T):
    1/σ_xx = ∫ P(u) (1 + γ_T)/(γ_T σ_xx + σ(u)) du (the flow-tensor form of Persson 2010);
    σ_xx percolates at A/A0 = γ_T/(1 + γ_T), σ_yy at 1/(1 + γ_T).

theory "critical_junction" (form "fixed" only): the junction sits where A(ζc)/A0 reaches the
directional threshold, the isotropic a_perc mapped by its odds, a_x/(1 - a_x) =
γ_T a_perc/(1 - a_perc). theory "average": σ = ū³/(12η) carries no direction (returned as is).
γ_T = 1 returns the isotropic :func:`fastcontact.flow.conductivity.conductivity` exactly.
Table path: :func:`precompute_directional` (σ̄_xx, σ̄_yy splines) and
:func:`directional_tables` (an ordinary Tables whose "emt" columns are directional, so every
engine runs the anisotropic case; the choice is recorded in its options/provenance).

References: B.N.J. Persson, J. Phys.: Condens. Matter 22, 265004 (2010),
doi:10.1088/0953-8984/22/26/265004; B.N.J. Persson, Eur. Phys. J. E 43, 25 (2020),
doi:10.1140/epje/i2020-11950-2; D. Stroud, Phys. Rev. B 12, 3368 (1975),
doi:10.1103/PhysRevB.12.3368; J.H. Tripp, J. Lubr. Technol. 105, 458 (1983),
doi:10.1115/1.3254641.
"""
from __future__ import annotations

import math
import time

import numpy as np
from scipy.interpolate import CubicSpline

from .._core.cache import PerObjectCache
from .._core.validate import check_positive
from ..tables.node_derivatives import NODE_STENCIL, local_derivatives
from ..contact import area_fraction, percolation_pressure
from ._kernels import EMT_TOL
from .conductivity import check_emt_threshold, conductivity
from .panel_memory import PanelMemory
from .directional import (FORMS, N_PANELS, _adaptive, _check, _odds, directional_sigma_bar,
                          directional_threshold)

__all__ = [
    "FORMS",
    "N_PANELS",
    "DirectionalTable",
    "directional_sigma_bar",
    "directional_threshold",
    "precompute_directional",
    "directional_tables",
    "directional_columns",
    "tables_for_direction",
    "table_anisotropy",
    "sigma_directional",
    "DIRECTIONAL_STEMS",
]


def sigma_directional(psd, p, E_star, eta, theory="emt", anisotropy=1.0, direction="x", *,
                      form="self_consistent", gamma=1.0, a_perc=0.5, alpha_cj=1.0,
                      n_panels=None, emt_threshold=0.5):
    """Directional interfacial conductivity σ_xx or σ_yy [m³/(Pa·s)] by direct quadrature.

    Parameters
    ----------
    psd : PSD
        Angle-averaged roughness spectrum (Persson convention).
    p : array_like
        Contact pressure p_cont [Pa], > 0.
    E_star : float
        Effective modulus [Pa], > 0.
    eta : float
        Fluid viscosity [Pa·s], > 0.
    theory : {"emt", "critical_junction", "average"}
        Flow theory (module docstring).
    anisotropy : float
        Peklenik/Tripp number γ_T = ξ_x/ξ_y >= 1 [-]; 1 = isotropic (exactly the
        isotropic :func:`~fastcontact.flow.conductivity.conductivity`).
    direction : {"x", "y"}
        Flow along the long correlation length ("x", the grooves) or across it ("y").
    form : {"self_consistent", "fixed"}
        Depolarization factors in the anisotropic effective medium or in an isotropic host.
    gamma, a_perc, alpha_cj, emt_threshold :
        As in :func:`~fastcontact.flow.conductivity.conductivity` (``a_perc``: the critical
        junction's isotropic threshold; ``emt_threshold``: the effective medium's).
    n_panels : int or None
        None (default): the P(u) quadrature in A (EMT) is adaptive (Gauss–Kronrod panels,
        relative error estimate EMT_TOL); an int: that many fixed Gauss–Legendre panels of
        order 10 (the reference the adaptive quadrature is tested against).

    Returns
    -------
    (sigma [m³/(Pa·s)], percolated [bool]) arrays of p's shape.
    """
    g = _check(theory, anisotropy, direction, form)
    p = check_positive("p", p, "[Pa]")
    E_star = float(check_positive("E_star", E_star, "[Pa]"))
    eta = float(check_positive("eta", eta, "[Pa·s]"))
    a_c = float(check_emt_threshold(emt_threshold))
    if g == 1.0 or theory == "average":
        return conductivity(psd, p, E_star, eta, theory, gamma=gamma, a_perc=a_perc,
                            alpha_cj=alpha_cj, emt_threshold=a_c)
    if theory == "critical_junction":
        a_dir = directional_threshold(float(a_perc), g, direction)
        return conductivity(psd, p, E_star, eta, theory, gamma=gamma, a_perc=a_dir,
                            alpha_cj=alpha_cj)
    sx, sy = directional_sigma_bar(psd, np.ravel(p) / E_star, g, form=form, gamma=gamma,
                                   n_panels=n_panels, emt_threshold=a_c)
    sb = (sx if direction == "x" else sy).reshape(np.shape(p))
    a_thr = a_c if form == "self_consistent" else directional_threshold(a_c, g, direction)
    perc = np.asarray(area_fraction(psd, p, E_star)) >= a_thr
    return sb * psd.h_rms ** 3 / (12.0 * eta), perc


# =========================================================================== table path
class DirectionalTable:
    """σ̄_xx(p̄), σ̄_yy(p̄) of one surface and γ_T on the nodes of a :class:`Tables`.

    Interpolation: not-a-knot cubic spline of ln σ̄ in ln p̄ between open nodes; in the last
    interval before the (exact) percolation pressure σ̄^(1/3) falls linearly to 0 (as the
    tables do). ``info["interpolation_error"]`` holds the worst relative midpoint error.
    """

    def __init__(self, tables, anisotropy, theory, form, lnp, lnsig, lnp_perc, info):
        """Built by :func:`precompute_directional`."""
        self.tables = tables
        self.anisotropy = float(anisotropy)
        self.theory = theory
        self.form = form
        self.h_rms = float(tables.h_rms)
        self.lnp = lnp
        self.lnsig = lnsig                 # dict direction -> ln σ̄ (-inf where closed)
        self.lnp_perc = lnp_perc           # dict direction -> ln p̄ of percolation
        self.info = info
        self._spl = {}
        for d in ("x", "y"):
            ok = np.isfinite(lnsig[d])
            self._spl[d] = (CubicSpline(lnp[ok], lnsig[d][ok]), int(ok.sum()))

    def sigma_bar(self, p, E_star, direction="x"):
        """σ̄ [-] in ``direction`` at contact pressure p [Pa]; 0 beyond percolation."""
        if direction not in ("x", "y"):
            raise ValueError(f"direction = {direction!r} is invalid: must be 'x' or 'y'")
        pb = np.asarray(self.tables._pbar("p", p, E_star), dtype=np.float64)
        x = np.log(pb)
        spl, n_open = self._spl[direction]
        lnp = self.lnp
        last = lnp[n_open - 1]
        xp = self.lnp_perc[direction]
        out = np.exp(spl(np.minimum(x, last)))
        tail = (x > last) & (x < xp)
        if np.any(tail):
            c = np.exp(self.lnsig[direction][n_open - 1] / 3.0) * (xp - x[tail]) / (xp - last)
            out = np.where(tail, 0.0, out)
            out[tail] = c ** 3
        return np.where(x >= xp, 0.0, out)[()]

    def conductivity(self, p, E_star, eta, direction="x"):
        """σ [m³/(Pa·s)] in ``direction`` at contact pressure p [Pa]."""
        eta = check_positive("eta", eta, "[Pa·s]")
        return self.sigma_bar(p, E_star, direction) * self.h_rms ** 3 / (12.0 * eta)


def _lnsig(sx, sy, lnp, lnp_perc):
    out = {}
    for d, sv in (("x", sx), ("y", sy)):
        with np.errstate(divide="ignore"):
            ls = np.where(sv > 1e-300, np.log(np.maximum(sv, 1e-300)), -np.inf)
        ls = np.where(lnp >= lnp_perc[d], -np.inf, ls)
        closed = ~np.isfinite(ls)
        if np.any(closed):                  # closed from the first node at/after percolation on
            ls[int(np.argmax(closed)):] = -np.inf
        out[d] = ls
    return out


def precompute_directional(tables, anisotropy, *, form="self_consistent", n_panels=None,
                           tol=1e-6, max_rounds=12, sigma_floor=1e-20, panel_memory=None):
    """Tabulate σ̄_xx, σ̄_yy (effective medium) of ``tables.surface`` with γ_T = ``anisotropy``.

    Starts from the tables' p̄ nodes and bisects every interval whose spline misses the
    direct solver at its midpoint by more than ``tol`` (relative, where σ̄ > sigma_floor),
    up to ``max_rounds`` times; the final midpoint errors go to ``info``. The tables'
    Yang–Persson γ, effective-medium threshold (``options["emt_threshold"]``, 0.5 when
    absent; set by a calibration) and quadrature tolerance (``options["emt_tol"]``) are
    reused: the directional thresholds are derived from the threshold. ``panel_memory`` (a
    :class:`~fastcontact.flow.panel_memory.PanelMemory` of the tables' build, optional) starts
    the adaptive quadratures at the tables' nodes on the isotropic medium's final partitions
    there; each midpoint starts on a neighbouring node's directional partition.

    Returns
    -------
    DirectionalTable
    """
    t0 = time.perf_counter()
    g = _check("emt", anisotropy, "x", form)
    psd = tables.surface
    if tables.options.get("emt_almqvist", False):
        raise ValueError("tables = ... are invalid for the anisotropic medium: they were built "
                         "with emt_almqvist = True (the broadened P(u) is not implemented for "
                         "σ_xx, σ_yy); rebuild them with emt_almqvist = False")
    gamma = float(tables.options.get("gamma", 1.0))
    a_c = float(tables.options.get("emt_threshold", 0.5))
    lnp = np.log(np.asarray(tables.data["p_over_E"], dtype=np.float64))
    thr = {"x": a_c, "y": a_c} if form == "self_consistent" else \
        {d: directional_threshold(a_c, g, d) for d in ("x", "y")}
    lnp_perc = {d: math.log(float(percolation_pressure(psd, 1.0, thr[d]))) for d in thr}
    quad = {"rule": "adaptive Gauss-Kronrod in A" if n_panels is None
            else f"{int(n_panels)} Gauss-Legendre panels of order 10 in A"}
    emt_tol = float(tables.options.get("emt_tol", EMT_TOL))  # the tables' own
    if n_panels is None:
        quad.update(tolerance=emt_tol, max_error_estimate=0.0, u1_evaluations=0)

    memory = PanelMemory()  # the directional partitions, by ln p̄

    def solve(pb, start):
        """(σ̄_xx, σ̄_yy) at p̄ = pb, the adaptive quadratures started from the partitions in
        ``start``; the worst estimate and u1 count are added up in ``quad``."""
        if n_panels is not None:
            return directional_sigma_bar(psd, pb, g, form=form, gamma=gamma,
                                         n_panels=n_panels, emt_threshold=a_c)
        a, b, e, m, final, nfinal = _adaptive(psd, pb, g, form, gamma, _odds(a_c), emt_tol,
                                              start, keep=True)
        memory.add(np.log(pb), final, nfinal)
        quad["max_error_estimate"] = max(quad["max_error_estimate"], float(np.max(e)))
        quad["u1_evaluations"] += int(np.sum(m))
        return a, b

    sx, sy = solve(np.exp(lnp), panel_memory)
    rounds = 0
    cache = {}                  # exact midpoint values: an unsplit interval keeps its midpoint
    while True:
        rounds += 1
        tab = DirectionalTable(tables, g, "emt", form, lnp, _lnsig(sx, sy, lnp, lnp_perc),
                               lnp_perc, {})
        xm = 0.5 * (lnp[:-1] + lnp[1:])
        new = np.array([x not in cache for x in xm.tolist()], dtype=bool)
        if np.any(new):
            nx, ny = solve(np.exp(xm[new]), memory)
            cache.update(zip(xm[new].tolist(), zip(nx.tolist(), ny.tolist())))
        mx = np.array([cache[x][0] for x in xm.tolist()])
        my = np.array([cache[x][1] for x in xm.tolist()])
        bad = np.zeros(xm.size, dtype=bool)
        err = {}
        for d, m in (("x", mx), ("y", my)):
            est = tab.sigma_bar(np.exp(xm), 1.0, d)
            ok = (m > sigma_floor) & (est > 0)
            e = np.where(ok, np.abs(est / np.where(ok, m, 1.0) - 1.0), 0.0)
            err[d] = float(e.max())
            bad |= e > tol
        if not np.any(bad) or rounds >= max_rounds:
            break
        order = np.argsort(np.concatenate((lnp, xm[bad])))
        lnp = np.concatenate((lnp, xm[bad]))[order]
        sx = np.concatenate((sx, mx[bad]))[order]
        sy = np.concatenate((sy, my[bad]))[order]
    tab.info.update({"interpolation_error": err, "tolerance": tol, "nodes": int(lnp.size),
                     "refinement_rounds": rounds,
                     "percolation_p_over_E": {d: math.exp(v) for d, v in lnp_perc.items()},
                     "anisotropy": g, "form": form,
                     "n_panels": "adaptive" if n_panels is None else int(n_panels),
                     "quadrature": quad,
                     "emt_threshold": a_c,
                     "build_seconds": time.perf_counter() - t0})
    return tab


#: the effective-medium columns that carry a direction; tables built with
#: ``precompute(..., anisotropy=γ_T)`` hold each with the suffixes "_x" and "_y"
DIRECTIONAL_STEMS = ("sigma_emt", "dlnsigma_emt", "d2lnsigma_emt", "phi_emt", "percolated_emt")
DIRECTIONS = ("x", "y")


#: the directional columns' derivatives on the tables' nodes come from the local polynomials
#: of the tables' own σ̄ (NODE_STENCIL nodes, degree 8), used at table nodes whose two intervals
#: are at most DIR_POLY_MAX_H wide in ln p̄ (the default grid of 4 points per decade: 0.576),
#: else the spline's derivatives. Measured at random pressures (γ_T = 3): default tables
#: 2.4e-6 with the spline's derivatives, 3e-8 with the polynomials'; an unrefined grid of
#: 2 per decade (intervals 1.15) 1.9e-5 with the spline's, 1.4e-4 with the polynomials'
#: (there the quintic Hermite weighs a second-derivative error by h²)
DIR_POLY_MAX_H = 0.6


def _columns_on_nodes(tables, d, direction):
    """The "emt" columns in ``direction`` on the tables' own p̄ nodes, from the
    :class:`DirectionalTable` ``d`` (σ̄, its first two ln-derivatives, φ_p, percolated).

    The tables' nodes are knots of ``d`` (exact values there); the derivatives come from the
    local polynomials through the knots (NODE_STENCIL nodes, as the tables do for their own
    σ̄) at nodes whose intervals are at most DIR_POLY_MAX_H wide, else from the spline (whose
    derivatives left the quintic Hermite on tables of 4 points per decade off by 2.4e-6 at
    random pressures; now 3e-8, bench/extensions_results.md)."""
    lnp = np.log(np.asarray(tables.data["p_over_E"], dtype=np.float64))
    spl, n_open = d._spl[direction]
    last = d.lnp[n_open - 1]
    sig = d.sigma_bar(np.exp(lnp), 1.0, direction)
    inside = (lnp <= last) & (sig > 0)
    d1, d2 = spl(lnp, 1), spl(lnp, 2)
    ls = d.lnsig[direction]
    open_ = np.isfinite(ls)
    k1, k2 = local_derivatives(d.lnp, np.where(open_, ls, 0.0), open_, NODE_STENCIL)
    h = np.diff(lnp)                       # the wider of each node's two intervals
    fine = np.maximum(np.append(h, 0.0), np.append(0.0, h)) <= DIR_POLY_MAX_H
    j = np.clip(np.searchsorted(d.lnp, lnp), 0, d.lnp.size - 1)
    use = (d.lnp[j] == lnp) & open_[j] & fine
    d1 = np.where(use, k1[j], d1)
    d2 = np.where(use, k2[j], d2)
    return {"sigma_emt": np.ascontiguousarray(sig),
            "dlnsigma_emt": np.ascontiguousarray(np.where(inside, d1, 0.0)),
            "d2lnsigma_emt": np.ascontiguousarray(np.where(inside, d2, 0.0)),
            "phi_emt": np.ascontiguousarray(sig / np.asarray(tables.data["u_over_h"]) ** 3),
            "percolated_emt": lnp >= d.lnp_perc[direction]}


def directional_columns(tables, directional):
    """The columns ``<stem>_x``, ``<stem>_y`` (:data:`DIRECTIONAL_STEMS`) that
    :func:`~fastcontact.tables.precompute` stores for ``anisotropy=γ_T``."""
    out = {}
    for direction in DIRECTIONS:
        for k, v in _columns_on_nodes(tables, directional, direction).items():
            out[f"{k}_{direction}"] = v
    return out


def table_anisotropy(tables):
    """γ_T [-] the tables were built for (1.0: isotropic tables)."""
    return float(tables.options.get("anisotropy", 1.0))


def _stored(tables):
    """True if ``tables`` hold both directions (built with precompute(anisotropy=γ_T))."""
    return "direction" not in tables.options and all(
        f"{k}_{d}" in tables.data for k in DIRECTIONAL_STEMS for d in DIRECTIONS)


def _check_direction(direction):
    if direction not in DIRECTIONS:
        raise ValueError(f"direction = {direction!r} is invalid: must be 'x' (along the long "
                         f"correlation length), 'y' (across it) or None")
    return direction


def _drop_theories(tables, keep):
    drop = [t for t in tables.theories if t not in keep]
    return {k: v for k, v in tables.data.items()
            if not any(k.endswith("_" + t) for t in drop) and k not in ("zeta_c", "u1c_over_h")
            and not (k.endswith(("_x", "_y")) and k[:-2] in DIRECTIONAL_STEMS)}


def _tables_with(tables, keep, data, perc_emt, options, extra_info):
    """A new tables object of the same class as ``tables`` (the flow layer does not import
    the tables layer above it) holding ``data`` for the theories ``keep``."""
    info = dict(tables.info)
    perc = {k: v for k, v in dict(info.get("percolation_p_over_E", {})).items() if k in keep}
    perc["emt"] = perc_emt
    info["percolation_p_over_E"] = perc
    info.update(extra_info)
    return type(tables)(tables.surface, keep, options, tables.grid, tables.zeta_grid, data, info)


_VIEWS = PerObjectCache()


def _stored_view(tables, direction):
    """The one-direction :class:`Tables` of tables that store both directions (cached per
    parent object, so the engines' per-Tables caches are reused across calls)."""
    return _VIEWS.get(tables, direction, lambda: _build_view(tables, direction))


def _build_view(tables, direction):
    """The ``direction`` view of tables that store both directions (uncached)."""
    keep = [t for t in tables.theories if t in ("average", "emt")]
    data = _drop_theories(tables, keep)
    for k in DIRECTIONAL_STEMS:
        data[k] = tables.data[f"{k}_{direction}"]
    d_info = tables.info.get("directional", {})
    perc = float(d_info["percolation_p_over_E"][direction])
    options = dict(tables.options, direction=direction)
    return _tables_with(tables, keep, data, perc, options, {})


def tables_for_direction(tables, direction, theory=None):
    """The tables an engine reads for flow in ``direction`` (None: ``tables`` itself).

    * isotropic tables (no ``options["anisotropy"]``, i.e. γ_T = 1): ``tables`` itself for
      every theory and direction — for isotropic roughness σ_xx = σ_yy = σ exactly, so the
      result is identical to ``direction=None`` (documented choice, not an error);
    * tables built with ``precompute(..., anisotropy=γ_T)``: a one-direction view whose "emt"
      columns are σ̄_xx or σ̄_yy ("average" kept: it carries no direction). ``theory =
      "critical_junction"`` raises ValueError (not tabulated per direction: use
      :func:`sigma_directional` with ``form="fixed"``).
    """
    if direction is None:
        return tables
    _check_direction(direction)
    if table_anisotropy(tables) == 1.0 and "direction" not in tables.options:
        return tables
    if "direction" in tables.options:
        if tables.options["direction"] != direction:
            raise ValueError(f"direction = {direction!r} is invalid for these tables: they are "
                             f"already the {tables.options['direction']!r} view of "
                             f"γ_T = {table_anisotropy(tables):g}")
        return tables
    if theory is not None and theory not in ("emt", "average"):
        raise ValueError(f"direction = {direction!r} is invalid with theory = {theory!r}: the "
                         f"tables hold directional conductivities for 'emt' only ('average' "
                         f"carries no direction); use theory = 'emt'")
    if not _stored(tables):
        raise ValueError(f"tables = {tables!r} are invalid for direction = {direction!r}: "
                         f"options record anisotropy = {table_anisotropy(tables):g} but the "
                         f"directional columns are missing (rebuild with precompute(..., "
                         f"anisotropy=...))")
    return _stored_view(tables, direction)


def directional_tables(tables, anisotropy=None, direction="x", *, form=None,
                       directional=None, n_panels=None):
    """A :class:`~fastcontact.tables.Tables` whose "emt" conductivity is σ_xx or σ_yy.

    Every engine that reads tables (``squeeze_out``, ``seal_leak``, ``tire_footprint``, the
    Barus engines) then runs the anisotropic case unchanged. The "emt" columns (σ̄ and its
    first and second ln-derivatives, φ_p, percolated) are replaced on the tables' own nodes
    from the spline of :func:`precompute_directional` (built here unless ``directional`` is
    given, or taken from the columns stored by ``precompute(..., anisotropy=γ_T)``);
    "average" is kept (it carries no direction), other theories are dropped. The choice is
    recorded in ``options`` (``anisotropy``, ``direction``, ``anisotropy_form``) and so in
    the Parquet provenance.

    Parameters
    ----------
    tables : Tables
        Tables holding "emt"; isotropic, or built with ``anisotropy=γ_T`` (then ``anisotropy``
        may be None or must equal γ_T, and ``form`` must match).
    anisotropy : float or None
        Peklenik number γ_T >= 1 [-].
    direction : {"x", "y"}
    form : {"self_consistent", "fixed"} or None
        Depolarization form (None: the stored one, else "self_consistent").
    directional : DirectionalTable, optional
        A prebuilt :func:`precompute_directional` of these tables.
    """
    if "emt" not in tables.theories:
        raise ValueError(f"tables = {tables!r} is invalid for directional_tables: they must "
                         f"hold the 'emt' theory")
    if _stored(tables) and directional is None:
        g_t = table_anisotropy(tables)
        f_t = tables.options.get("anisotropy_form", "self_consistent")
        if anisotropy is not None and float(anisotropy) != g_t or \
                form is not None and form != f_t:
            raise ValueError(f"anisotropy = {anisotropy!r}, form = {form!r} are invalid for "
                             f"these tables: they were built for γ_T = {g_t:g}, form = {f_t!r} "
                             f"(pass anisotropy=None, or rebuild)")
        return _stored_view(tables, _check_direction(direction))
    if "direction" in tables.options or "anisotropy" in tables.options:
        raise ValueError(f"tables = {tables!r} are invalid for directional_tables: they are "
                         f"already anisotropic (options {tables.options}); start from "
                         f"isotropic tables")
    if anisotropy is None:
        raise ValueError("anisotropy = None is invalid for isotropic tables: give γ_T >= 1, "
                         "or build the tables with precompute(..., anisotropy=γ_T)")
    form = "self_consistent" if form is None else form
    g = _check("emt", anisotropy, direction, form)
    d = directional or precompute_directional(tables, g, form=form, n_panels=n_panels)
    if d.anisotropy != g or d.form != form:
        raise ValueError(f"directional = {d!r} is invalid: built for γ_T = {d.anisotropy}, "
                         f"form = {d.form!r}, not {g}, {form!r}")
    keep = [t for t in tables.theories if t in ("average", "emt")]
    data = _drop_theories(tables, keep)
    data.update(_columns_on_nodes(tables, d, direction))
    options = dict(tables.options, anisotropy=g, direction=direction, anisotropy_form=form)
    return _tables_with(tables, keep, data, math.exp(d.lnp_perc[direction]), options,
                        {"directional": {k: v for k, v in d.info.items()}})
