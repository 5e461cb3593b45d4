"""The precompute stage: tabulate one surface's contact and flow columns on an adaptive grid.

:func:`precompute` evaluates the direct quadrature of :mod:`fastcontact.contact` and
:mod:`fastcontact.flow` on a log grid of p̄ = p/E* and refines it until the interpolants of
:mod:`fastcontact.kernels.lookup` meet :data:`TOLERANCE` at every interval midpoint.
"""
from __future__ import annotations

import json
import math
import time

import numpy as np

from .._core.jsonable import json_plain
from .._core.validate import check_positive, check_range
from .._core.vocab import THEORIES
from ..contact import _check_gamma, _check_psd, _separation, asymptote, percolation_pressure
from ..flow.conductivity import (check_anisotropy, check_emt_threshold, check_theory,
                                 emt_sigma_bar_started, sigma_bar)
from ..flow.panel_memory import PanelMemory
from ..kernels.hermite import quintic_np
from ..kernels.locate import Grid
from ..surface.psd import PSD
from .node_derivatives import NODE_STENCIL, local_derivatives
from .store import Tables

__all__ = ["precompute", "default_grid", "TOLERANCE", "DEFAULT_POINTS_PER_DECADE", "SIGMA_FLOOR",
           "verified_top"]

#: default base-grid density in p̄, chosen in bench/tables_results.md ("interpolation error
#: against build cost", base ppd 2-12 at the default tolerances): the refinement adds what the
#: tolerances need, so a coarse base grid costs no accuracy; 4 builds ×0.80-0.87 the time of 8
#: with the same worst errors (8 before the node derivatives of degree 8, 2026-11-26)
DEFAULT_POINTS_PER_DECADE = 4
#: the table reaches from ū = U_TOP h_rms ...
U_TOP = 32.0
#: ... to A(ζ1)/A0 = AREA_TOP
AREA_TOP = 0.999
#: relative interpolation tolerances the adaptive refinement enforces at interval midpoints
TOLERANCE = {"u": 5e-9, "p_of_u": 5e-9, "slope": 5e-8, "sigma": 2e-7}
#: relative tolerance of the effective-medium quadrature in A at the tables' nodes and
#: midpoints (the Kronrod–Gauss estimate; the direct :func:`~fastcontact.flow.conductivity.
#: sigma_bar` keeps EMT_TOL = 1e-8). The refinement's σ̄ tolerance is 2e-7 and the midpoint
#: quadratures start on their neighbours' partitions, finer than a cold start's: against
#: tol = 1e-12 the node values were off by <= 1.5e-8 at 1e-7 (<= 1.1e-8 at 1e-8), and at 200
#: random pressures the six bench spectra's σ̄ errors were the same to two digits at 1e-7 and
#: at 1e-8 (the road spectrum 2.2e-8 vs 1.2e-8; bench/tables_results.md), the builds ×0.80-0.87
TABLE_EMT_TOL = 1e-7
#: σ̄ below this is "at percolation" for the refinement (not resolved further; time scales
#: there exceed 1e20 τ-units)
SIGMA_FLOOR = 1e-24
#: tail samples: direct ū and σ̄ at ln p̄ = (lowest node) - TAIL_STEPS, below the table (ū from
#: 32 to ~340 h_rms), stored in ``info["tail"]`` for the squeeze-out engine's large-separation
#: tail (the effective medium's σ̄/ū³ - 1 ≈ -2.2/ū² has no closed form)
TAIL_STEPS = (1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0)
BOUNDARY_FACTOR = 1e3
MAX_NODES = 6000
MIN_DLNP = 1e-6
#: the theories whose ln σ̄ derivatives at the nodes come from local polynomials through the
#: nodes (:func:`~fastcontact.tables.node_derivatives.local_derivatives`; no closed form), and
#: those columns (not evaluated at midpoints); the average theory's are 3 d ln ū/d ln p̄
DERIVED_AT_NODES = ("critical_junction", "emt")
_DERIVED_COLUMNS = frozenset(f"{d}lnsigma_{th}" for th in DERIVED_AT_NODES for d in ("d", "d2"))


def default_grid(surface: PSD, gamma=1.0, points_per_decade=DEFAULT_POINTS_PER_DECADE) -> Grid:
    """Base p̄ grid from ū ≈ 32 h_rms (asymptote, eq. 3) to A(ζ1)/A0 = 0.999, snapped to 1/ppd decades.

    Parameters
    ----------
    surface : PSD
        Roughness spectrum.
    gamma : float
        Yang–Persson factor in (0, 1] [-].
    points_per_decade : int
        Grid density in log10 p̄.
    """
    u0, beta = asymptote(surface, gamma)
    p_lo = beta * math.exp(-U_TOP * surface.h_rms / u0)
    p_hi = float(percolation_pressure(surface, 1.0, AREA_TOP))
    ppd = int(points_per_decade)
    lo = math.floor(math.log10(p_lo) * ppd) / ppd
    hi = math.ceil(math.log10(p_hi) * ppd) / ppd
    return Grid(lo, hi, int(round((hi - lo) * ppd)) + 1)


#: the constants a calibration sets, with precompute's defaults
CALIBRATED = {"gamma": 1.0, "alpha_cj": 1.0, "a_perc": 0.5, "emt_threshold": 0.5}


def _calibration_block(calibration, given):
    """(constants dict, provenance block) of a calibration; ValueError on a conflict.

    ``calibration`` is duck-typed (attributes gamma, alpha_cj, a_perc, emt_threshold, and
    optionally fitted, provenance) so that tables need not import fastcontact.validation.
    ``given`` holds the options passed to precompute; a value that differs from its default
    and from the calibration's is a conflict.
    """
    missing = [k for k in CALIBRATED if not hasattr(calibration, k)]
    if missing:
        raise ValueError(f"calibration = {calibration!r} is invalid: it lacks {missing}; pass a "
                         f"fastcontact.validation.Calibration (attributes {list(CALIBRATED)})")
    const = {k: float(getattr(calibration, k)) for k in CALIBRATED}
    for k, v in given.items():
        if float(v) != CALIBRATED[k] and float(v) != const[k]:
            raise ValueError(f"{k} = {v!r} is invalid together with calibration: the calibration "
                             f"sets {k} = {const[k]!r} (pass one or the other)")
    block = dict(const, fitted=list(getattr(calibration, "fitted", ()) or ()),
                 provenance=getattr(calibration, "provenance", {}) or {})
    return const, json.loads(json.dumps(block, default=json_plain, sort_keys=True))


def _theory_options(theories, gamma, a_perc, alpha_cj, emt_tol, emt_almqvist, emt_threshold=0.5):
    """(theories in request order without repeats, validated options dict).

    ``emt_threshold`` is recorded only when it differs from 0.5 (so default tables, and
    their digests, are those of earlier releases)."""
    if isinstance(theories, str):
        theories = (theories,)
    theories = tuple(dict.fromkeys(check_theory(t) for t in theories))
    if not theories:
        raise ValueError("theories = () is invalid: request at least one of "
                         f"{list(THEORIES)}")
    return theories, {
        "gamma": _check_gamma(gamma),
        "a_perc": float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True)),
        "alpha_cj": float(check_positive("alpha_cj", alpha_cj, "[-]")),
        "emt_tol": float(check_range("emt_tol", emt_tol, 1e-13, 1e-2, "[-]")),
        "emt_almqvist": bool(emt_almqvist),
    } | ({} if float(check_emt_threshold(emt_threshold)) == 0.5
         else {"emt_threshold": check_emt_threshold(emt_threshold)})


def _check_grid(grid):
    """A user grid ``(log10_min, log10_max, n)`` as a :class:`Grid`, or ValueError."""
    try:
        g = Grid(float(grid[0]), float(grid[1]), int(grid[2]))
        ok = (len(grid) == 3 and math.isfinite(g.log10_min) and math.isfinite(g.log10_max)
              and g.n == grid[2] and g.n >= 5 and g.log10_max > g.log10_min)
    except (TypeError, ValueError, IndexError, OverflowError):
        ok = False
    if not ok:
        raise ValueError(f"grid = {grid!r} is invalid: must be (log10_min, log10_max, n) with "
                         f"finite log10_max > log10_min and integer n >= 5")
    return g


def _check_tolerance(tolerance):
    """:data:`TOLERANCE` updated with the user's overrides (known keys, finite values > 0)."""
    tol = dict(TOLERANCE)
    for key, value in dict(tolerance or {}).items():
        if key not in TOLERANCE:
            raise ValueError(f"tolerance = {{{key!r}: ...}} is invalid: keys must be among "
                             f"{sorted(TOLERANCE)}")
        tol[key] = float(check_range(f"tolerance[{key!r}]", value, 1e-15, 1.0, "[-] (relative)"))
    return tol


def _exact(psd, pbar, theories, sig_opts, memory):
    """Exact columns at reduced pressures pbar (direct quadrature); the effective medium's
    quadrature starts on a recorded neighbour's final partition and records its own in
    ``memory`` (:class:`~fastcontact.flow.panel_memory.PanelMemory`)."""
    pbar = np.ascontiguousarray(pbar, dtype=np.float64)
    u, du, d2u = _separation(psd, pbar, 1.0, 1.0, sig_opts["gamma"], second=True)
    h = psd.h_rms
    out = {"u": u / h, "dlnu": du / u, "d2lnu": d2u / u - (du / u) ** 2}
    for th in theories:
        if th == "average":  # σ̄ = (ū/h_rms)³ from the quadrature above, not a second one
            sb, perc, extra = out["u"] ** 3, np.zeros(pbar.size, dtype=bool), None
        elif th == "emt":
            lnp = np.log(pbar)
            (sb, perc, extra), final, nfinal = emt_sigma_bar_started(
                psd, pbar, *memory.starts(lnp), **sig_opts)
            memory.add(lnp, final, nfinal)
        else:
            sb, perc, extra = sigma_bar(psd, pbar, th, **sig_opts)
        out[f"sigma_{th}"] = sb
        out[f"percolated_{th}"] = perc
        if th == "average":
            out[f"dlnsigma_{th}"] = 3.0 * out["dlnu"]
            out[f"d2lnsigma_{th}"] = 3.0 * out["d2lnu"]
        if th == "critical_junction":
            out["zeta_c"] = extra.zeta_c
            out["u1c_over_h"] = extra.u1c
    return out


def _interval_errors(lnp, cols, mids, theories):
    """Relative midpoint errors of each column's interpolant, per interval (inf: overflow)."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return _interval_errors_raw(lnp, cols, mids, theories)


def _interval_errors_raw(lnp, cols, mids, theories):
    x0, x1 = lnp[:-1], lnp[1:]
    xm = 0.5 * (x0 + x1)
    lnu = np.log(cols["u"])
    du = cols["dlnu"]
    d2 = cols["d2lnu"]
    args = (x0, x1, lnu[:-1], lnu[1:], du[:-1], du[1:], d2[:-1], d2[1:])
    est = quintic_np(xm, *args)
    err = {"u": np.abs(np.expm1(est - np.log(mids["u"])))}
    slope = quintic_np(xm, *args, deriv=True)
    err["slope"] = np.abs(slope / mids["dlnu"] - 1.0)
    lnum = np.log(mids["u"])
    est_p = quintic_np(lnum, lnu[:-1], lnu[1:], x0, x1, 1 / du[:-1], 1 / du[1:],
                       -d2[:-1] / du[:-1] ** 3, -d2[1:] / du[1:] ** 3)
    err["p_of_u"] = np.abs(np.expm1(est_p - xm))
    for th in theories:
        s = cols[f"sigma_{th}"]
        sm = mids[f"sigma_{th}"]
        ok = (s[:-1] > SIGMA_FLOOR) & (s[1:] > SIGMA_FLOOR) & (sm > SIGMA_FLOOR)
        e = np.zeros(xm.size)
        if np.any(ok):
            ds = cols[f"dlnsigma_{th}"]
            d2s = cols[f"d2lnsigma_{th}"]
            est_s = quintic_np(xm[ok], x0[ok], x1[ok], np.log(s[:-1][ok]), np.log(s[1:][ok]),
                               ds[:-1][ok], ds[1:][ok], d2s[:-1][ok], d2s[1:][ok])
            e[ok] = np.abs(np.expm1(est_s - np.log(sm[ok])))
        err[f"sigma_{th}"] = e
    return err


def _sigma_node_derivatives(lnp, cols, theories, gaps):
    """d ln σ̄/d ln p̄ and its derivative of the critical junction and the effective medium at
    the open nodes (σ̄ > SIGMA_FLOOR), from local polynomials through the nodes
    (:data:`NODE_STENCIL`) of y = ln σ̄ · (A_c - A(ζ1)/A0) rather than of ln σ̄ itself, then
    by the chain rule (:func:`_percolation_gap`; ``gaps[theory]`` = (A_c, 1/(2√G(ζ1)))).

    Next to percolation ln σ̄ collapses like -a/(A_c - A(ζ1)/A0) (a ≈ 0.6-1; 2026-11-26 notes
    in bench/tables_results.md), which a polynomial through nine nodes follows poorly; y tends
    to -a there and is smooth, so its local polynomial gives the derivatives the quintic
    Hermite needs, and the refinement needs fewer nodes next to percolation (6 spectra: 8-9 %
    fewer, bench/tables_results.md, 2026-12-02). The interpolated column is ln σ̄, as before."""
    for th in theories:
        if th not in DERIVED_AT_NODES:
            continue
        s = cols[f"sigma_{th}"]
        ok = s > SIGMA_FLOOR
        f, f1, f2 = _percolation_gap(lnp, *gaps[th])
        if not np.all(f[ok] > 0.0):  # (an open node at or past A_c: not expected) plain ln σ̄
            f, f1, f2 = np.ones_like(lnp), np.zeros_like(lnp), np.zeros_like(lnp)
        with np.errstate(divide="ignore"):
            L = np.where(ok, np.log(np.where(ok, s, 1)), 0)
        dy, d2y = local_derivatives(lnp, L * f, ok, NODE_STENCIL)
        d1 = (dy - L * f1) / f
        cols[f"dlnsigma_{th}"] = np.where(ok, d1, 0.0)
        cols[f"d2lnsigma_{th}"] = np.where(ok, (d2y - 2.0 * d1 * f1 - L * f2) / f, 0.0)


def _percolation_gap(lnp, a_c, c):
    """(f, df/d ln p̄, d²f/d(ln p̄)²) of f = A_c - A(ζ1)/A0 = A_c - erf(c p̄) at ln p̄ = lnp
    (eq. A1 at ζ = ζ1; c = 1/(2√G(ζ1)), G in units of E*²)."""
    from scipy.special import erf   # as in _assemble: the run path needs no scipy.special
    z = c * np.exp(lnp)
    g = (2.0 / math.sqrt(math.pi)) * z * np.exp(-z * z)    # d erf(z)/d ln p̄
    return a_c - erf(z), -g, -g * (1.0 - 2.0 * z * z)


def _gaps(psd, theories, sig_opts):
    """{theory: (A_c, 1/(2√G(ζ1)))} of the theories whose σ̄ derivatives come from the nodes:
    the critical junction's a_perc, the effective medium's threshold."""
    c = 1.0 / (2.0 * math.sqrt(0.25 * math.pi * psd.cum3[-1]))
    a_c = {"critical_junction": sig_opts["a_perc"], "emt": sig_opts["emt_threshold"]}
    return {th: (float(a_c[th]), c) for th in theories if th in DERIVED_AT_NODES}


def _flag_intervals(lnp, cols, mids, theories, tol):
    """(intervals to split, midpoint errors): interpolation misses and floor-straddlers."""
    errs = _interval_errors(lnp, cols, mids, theories)
    bad = np.zeros(lnp.size - 1, dtype=bool)
    for c, e in errs.items():
        bad |= e > tol["sigma" if c.startswith("sigma") else c]
    # intervals straddling the σ̄ floor (the super-exponential collapse of u1(ζc) before
    # percolation) are bisected until their open end is within BOUNDARY_FACTOR of it
    for th in theories:
        sg = cols[f"sigma_{th}"]
        above = sg > SIGMA_FLOOR
        straddle = above[:-1] != above[1:]
        open_end = np.maximum(sg[:-1], sg[1:])
        bad |= straddle & (open_end > BOUNDARY_FACTOR * SIGMA_FLOOR)
    bad &= (lnp[1:] - lnp[:-1]) > 2 * MIN_DLNP
    return bad, errs


def _refine(psd, grid, theories, sig_opts, tol, refine, memory):
    """Adaptive bisection of the base grid; returns (ln p̄ nodes, columns, errors, stats).
    The effective medium's quadrature at each midpoint starts on a neighbouring node's final
    partition; ``memory`` (:class:`~fastcontact.flow.panel_memory.PanelMemory`) collects them."""
    lnp = grid.ln_nodes()
    cols = _exact(psd, np.exp(lnp), theories, sig_opts, memory)
    gaps = _gaps(psd, theories, sig_opts)
    mid_cache = {}
    rounds = 0
    while True:
        rounds += 1
        _sigma_node_derivatives(lnp, cols, theories, gaps)
        xm = 0.5 * (lnp[:-1] + lnp[1:])
        need = np.array([x not in mid_cache for x in xm])
        if np.any(need):
            new = _exact(psd, np.exp(xm[need]), theories, sig_opts, memory)
            for k, x in enumerate(xm[need]):
                mid_cache[x] = {c: v[k] for c, v in new.items()}
        mids = {c: np.array([mid_cache[x][c] for x in xm]) for c in cols
                if c not in _DERIVED_COLUMNS}
        if not np.all(np.diff(np.log(np.concatenate(([cols["u"][0]], mids["u"])))) < 0) \
                or not np.all(np.diff(cols["u"]) < 0):
            raise ValueError(f"grid = {tuple(grid)!r} is invalid for this surface: ū(p) is not "
                             f"resolved as strictly decreasing")
        bad, errs = _flag_intervals(lnp, cols, mids, theories, tol)
        if not refine or not np.any(bad) or lnp.size + bad.sum() > MAX_NODES:
            break
        # split: the midpoints become nodes (their exact values are already known)
        add = xm[bad]
        order = np.argsort(np.concatenate((lnp, add)), kind="stable")
        lnp = np.concatenate((lnp, add))[order]
        for c in cols:
            extra = mids[c][bad] if c in mids else np.zeros(int(bad.sum()))
            cols[c] = np.concatenate((cols[c], extra))[order]
    return lnp, cols, errs, {"refinement_rounds": rounds, "exact_evaluations": int(grid.n + len(mid_cache))}


def _assemble(psd, lnp, cols, theories, options):
    """The table columns and percolation pressures from the refined nodes."""
    pbar = np.exp(lnp)
    data = {"p_over_E": pbar, "u_over_h": cols["u"], "dlnu_dlnp": cols["dlnu"],
            "d2lnu_dlnp2": cols["d2lnu"]}
    G1 = 0.25 * math.pi * psd.cum3[-1]
    from scipy.special import erf   # here: loading tables (the run path) needs no scipy.special
    data["area_fraction"] = erf(pbar / (2.0 * math.sqrt(G1)))
    perc_p = {}
    for th in theories:
        open_ = cols[f"sigma_{th}"] > 0
        data[f"sigma_{th}"] = cols[f"sigma_{th}"]
        data[f"dlnsigma_{th}"] = np.where(open_, cols[f"dlnsigma_{th}"], 0.0)
        data[f"d2lnsigma_{th}"] = np.where(open_, cols[f"d2lnsigma_{th}"], 0.0)
        data[f"phi_{th}"] = cols[f"sigma_{th}"] / cols["u"] ** 3
        data[f"percolated_{th}"] = cols[f"percolated_{th}"].astype(bool)
        if th == "critical_junction":
            data["zeta_c"] = cols["zeta_c"]
            data["u1c_over_h"] = cols["u1c_over_h"]
        a_perc = options["a_perc"] if th == "critical_junction" else \
            options.get("emt_threshold", 0.5)
        perc_p[th] = math.inf if th == "average" else float(percolation_pressure(psd, 1.0, a_perc))
    zg = Grid(0.0, math.log10(psd.zeta1), pbar.size)
    zeta = zg.nodes()
    zeta[-1] = psd.zeta1
    data["zeta"] = zeta
    data["G_over_Estar2"] = 0.25 * math.pi * np.asarray(psd.moment(3.0, psd.q0, zeta * psd.q0))
    return {k: np.ascontiguousarray(v) for k, v in data.items()}, perc_p, zg


def precompute(psd, theories=THEORIES, gamma=1.0, a_perc=0.5, alpha_cj=1.0, grid=None, *,
               emt_tol=TABLE_EMT_TOL, emt_almqvist=False, points_per_decade=None, tolerance=None,
               refine=True, emt_threshold=0.5, calibration=None, anisotropy=1.0,
               anisotropy_form="self_consistent"):
    """Tabulate ū (A4), A (A1), u1(ζc) (A3), σ̄ (eq. 23) and φ_p of a surface on a grid of p̄ = p/E*.

    The base grid (uniform in ln p̄) is refined adaptively: every interval whose Hermite
    interpolant misses the exact quadrature at its midpoint by more than ``tolerance``
    (relative; ū, p_cont(ū), the slope d ln ū/d ln p̄ that sets squeeze-out rates near
    equilibrium, and each σ̄ above SIGMA_FLOOR) is split, until all pass.
    The midpoint errors of the final grid are recorded in ``info["interpolation_error"]``.

    Parameters
    ----------
    psd : PSD
        The roughness spectrum (Persson convention).
    theories : sequence of str
        Any of "average", "critical_junction", "emt"; only these are computed (default all).
    gamma : float
        Yang–Persson factor in (0, 1] [-] (1 = the paper's A4).
    a_perc : float
        Critical-junction percolation threshold A(ζc)/A0 in (0, 1) [-] (0.5; 0.42 option).
    alpha_cj : float
        Critical-junction factor on u1(ζc) [-], > 0.
    grid : Grid or (log10_min, log10_max, n), optional
        Base p̄ grid (default: :func:`default_grid`).
    emt_tol : float
        Relative accuracy of the adaptive effective-medium integral at the nodes [-]
        (:data:`TABLE_EMT_TOL`; the direct quadrature's default is 1e-8).
    emt_almqvist : bool
        Almqvist-broadened separation distribution in the effective medium.
    points_per_decade : int, optional
        Density of the default base grid.
    tolerance : dict, optional
        Overrides of :data:`TOLERANCE` ("u", "p_of_u", "slope", "sigma").
    refine : bool
        False: keep the base grid (errors are still measured and recorded).
    emt_threshold : float
        Effective-medium percolation threshold A_c in (0, 1) [-] (0.5: 2-D Bruggeman; see
        :func:`fastcontact.flow.conductivity.conductivity`). Recorded in ``options`` when != 0.5.
    calibration : Calibration, optional
        A :class:`fastcontact.validation.Calibration` (or any object with attributes gamma,
        alpha_cj, a_perc, emt_threshold): sets those four options. An option passed here with
        a non-default value that differs from the calibration's raises ValueError. The
        constants, ``fitted`` and the calibration's ``provenance`` are recorded in
        ``info["calibration"]`` (covered by the file's metadata_sha256).
    anisotropy : float
        Peklenik number γ_T = ξ_x/ξ_y >= 1 [-] of roughness stretched along x; 1 (default):
        isotropic tables, bit for bit. γ_T > 1 (needs "emt") adds the columns ``<stem>_x``,
        ``<stem>_y`` of :data:`~fastcontact.flow.anisotropy.DIRECTIONAL_STEMS` (σ̄_xx, σ̄_yy,
        :func:`~fastcontact.flow.anisotropy.precompute_directional` with this γ and
        emt_threshold), recorded in ``options`` (``anisotropy``, ``anisotropy_form``) and
        ``info["directional"]`` under the metadata digest; the plain "emt" columns stay
        isotropic. Read a direction with ``Tables.conductivity(..., direction=)`` or
        ``seal_leak(..., direction=)`` (docs/theory/extensions.md §3).
    anisotropy_form : {"self_consistent", "fixed"}
        Depolarization form of the anisotropic medium (used only when γ_T != 1).

    Returns
    -------
    Tables
        The tables; ``info`` records the asymptote (eq. 3), percolation pressures, the
        midpoint errors, node count and build time [s] (and the calibration, if any).

    References
    ----------
    B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
    """
    t_start = time.perf_counter()
    _check_psd(psd)
    theories, options, cal_block = _options(theories, gamma, a_perc, alpha_cj, emt_tol,
                                            emt_almqvist, emt_threshold, calibration)
    aniso = _check_anisotropy(anisotropy, anisotropy_form, theories, options)
    grid = _base_grid(psd, options["gamma"], grid, points_per_decade)
    tol = _check_tolerance(tolerance)
    memory = PanelMemory()
    lnp, cols, errs, stats = _refine(psd, grid, theories, _sigma_options(options), tol, refine,
                                     memory)
    data, perc_p, zg = _assemble(psd, lnp, cols, theories, options)
    tail = _tail_samples(psd, float(lnp[0]), theories, _sigma_options(options))
    tables = Tables(psd, theories, options, grid, zg, data, _info(
        psd, options["gamma"], perc_p, errs, tol, lnp.size, stats, t_start, cal_block, tail))
    return tables if aniso is None else _with_directional(tables, aniso, t_start, memory)


def _options(theories, gamma, a_perc, alpha_cj, emt_tol, emt_almqvist, emt_threshold,
             calibration):
    """(theories, validated options, calibration block or None) of precompute's keywords;
    a calibration sets the four :data:`CALIBRATED` constants first."""
    cal_block = None
    if calibration is not None:
        const, cal_block = _calibration_block(calibration, {
            "gamma": gamma, "alpha_cj": alpha_cj, "a_perc": a_perc, "emt_threshold": emt_threshold})
        gamma, alpha_cj, a_perc, emt_threshold = (const[k] for k in CALIBRATED)
    theories, options = _theory_options(theories, gamma, a_perc, alpha_cj, emt_tol, emt_almqvist,
                                        emt_threshold)
    return theories, options, cal_block


def _base_grid(psd, gamma, grid, points_per_decade):
    """The base p̄ :class:`Grid`: the user's ``grid`` checked, else :func:`default_grid`."""
    if grid is not None:
        return _check_grid(grid)
    ppd = DEFAULT_POINTS_PER_DECADE if points_per_decade is None else points_per_decade
    ppd = int(check_range("points_per_decade", ppd, 1, 1000, "[1/decade]"))
    return default_grid(psd, gamma, ppd)


def _sigma_options(options):
    """The keywords of :func:`~fastcontact.flow.conductivity.sigma_bar` from the options."""
    return dict(gamma=options["gamma"], a_perc=options["a_perc"], alpha_cj=options["alpha_cj"],
                tol=options["emt_tol"], almqvist=options["emt_almqvist"],
                emt_threshold=options.get("emt_threshold", 0.5))


def _tail_samples(psd, lnp_lo, theories, sig_opts):
    """Direct ū/h_rms and σ̄ at ln p̄ = lnp_lo - :data:`TAIL_STEPS` (below the table): the data
    the squeeze-out engine fits its large-separation tail σ̄^(1/3) = ū/h_rms + g(h_rms/ū) to.

    Returns a JSON-able dict {"ln_p_over_E": [...], "u_over_h": [...], "sigma_bar": {theory:
    [...]}}; samples where the quadrature is not finite (ū beyond float range) are dropped.
    """
    lnp = lnp_lo - np.asarray(TAIL_STEPS, dtype=np.float64)
    pbar = np.exp(lnp)
    u, _du = _separation(psd, pbar, 1.0, 1.0, sig_opts["gamma"])
    v = u / psd.h_rms
    sig = {}
    for th in theories:
        sig[th] = v ** 3 if th == "average" else sigma_bar(psd, pbar, th, **sig_opts).sigma_bar
    ok = np.isfinite(v) & (v > 0) & np.all([np.isfinite(s) & (s > 0) for s in sig.values()], axis=0)
    return {"ln_p_over_E": lnp[ok].tolist(), "u_over_h": v[ok].tolist(),
            "sigma_bar": {th: np.asarray(s)[ok].tolist() for th, s in sig.items()}}


def _info(psd, gamma, perc_p, errs, tol, nodes, stats, t_start, cal_block, tail):
    """The tables' ``info``: asymptote (eq. 3), percolation pressures, midpoint errors,
    refinement statistics, the tail samples, build time [s] and the calibration block (if
    any)."""
    u0, beta = asymptote(psd, gamma)
    info = {"asymptote_u0_over_h": u0 / psd.h_rms, "asymptote_beta": beta,
            "percolation_p_over_E": perc_p,
            "interpolation_error": {c: float(e.max()) for c, e in errs.items()},
            "tolerance": tol, "sigma_floor": SIGMA_FLOOR, "nodes": int(nodes), **stats,
            "tail": tail, "build_seconds": time.perf_counter() - t_start}
    if cal_block is not None:
        info["calibration"] = cal_block
    return info


def _with_directional(tables, aniso, t_start, memory):
    """``tables`` with the σ̄_xx, σ̄_yy columns of γ_T, form = ``aniso`` on their nodes (the
    directional quadratures started on the isotropic ones' partitions in ``memory``)."""
    from ..flow.anisotropy import directional_columns, precompute_directional
    d = precompute_directional(tables, aniso[0], form=aniso[1], panel_memory=memory)
    data = dict(tables.data, **directional_columns(tables, d))
    options = dict(tables.options, anisotropy=aniso[0], anisotropy_form=aniso[1])
    info = dict(tables.info, directional=dict(d.info))
    info["build_seconds"] = time.perf_counter() - t_start
    return Tables(tables.surface, tables.theories, options, tables.grid, tables.zeta_grid, data,
                  info)


def _check_anisotropy(anisotropy, form, theories, options):
    """None for isotropic tables (γ_T = 1), else (γ_T, form); ValueError naming the problem."""
    g = check_anisotropy(anisotropy)
    if form not in ("self_consistent", "fixed"):
        raise ValueError(f"anisotropy_form = {form!r} is invalid: must be 'self_consistent' or "
                         f"'fixed'")
    if g == 1.0:
        return None
    if "emt" not in theories:
        raise ValueError(f"anisotropy = {anisotropy!r} is invalid with theories = "
                         f"{list(theories)}: the directional conductivities are those of the "
                         f"effective medium, add 'emt' to theories")
    if options["emt_almqvist"]:
        raise ValueError(f"anisotropy = {anisotropy!r} is invalid with emt_almqvist = True: the "
                         f"broadened P(u) is not implemented for the anisotropic medium")
    return g, form


def verified_top(tables, theory):
    """(index, ln p̄, σ̄) of the tables' last node up to which ``theory``'s σ̄ is verified.

    The build checks the σ̄ interpolant only between nodes whose σ̄ is above the tables' σ̄
    floor; past the last such node (the super-exponential collapse before percolation) σ̄ is
    unverified. "average" is σ̄ = (ū/h_rms)³, verified through ū at every node: its whole
    table is trusted."""
    sig = np.asarray(tables.data[f"sigma_{theory}"], dtype=np.float64)
    if theory == "average":
        j = sig.size - 1
    else:
        floor = float(tables.info.get("sigma_floor", SIGMA_FLOOR))
        above = np.flatnonzero(sig > floor)
        j = int(above[-1]) if above.size else 0
    return j, float(np.log(tables.data["p_over_E"][j])), float(sig[j])
