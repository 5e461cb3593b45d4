"""Leak rate of static seals, many cases at once: :func:`seal_leak` and its column catalogue.

Lorenz & Persson (2010), Sec. 6, eqs. (25)–(33): steady flow across the seal width with the
fluid pressure feeding back on the contact pressure, p0 = p_cont + p_f (28).

Flat ring: q = (1/L) ∫_{p0−p_a}^{p0−p_b} σ_eff(p) dp (eq. 33 with uniform p0), from a tabulated
primitive whose short intervals are integrated directly — never a difference of two large
primitives; relative error <= 1e-7 against direct quadrature of the tables' σ̄ (against σ̄ from
the contact core itself, the tables' interpolation error of σ̄, <= 5e-7, adds: where dp << p0,
Q is proportional to σ̄(p0)). The tables verify σ̄ only down
to their floor (``tables.info["sigma_floor"]``): past π_trust, just below the percolation
pressure ("average" is verified everywhere), σ̄ may be off by orders of magnitude. There Q
uses the bound 0 <= σ̄ <= σ̄(π_trust) and reports the midpoint when the bound moves Q by less
than 1e-9 (``_sigma.TAIL_RTOL``), else Q = NaN with status "near_percolation" (e.g. dp << p0
with p0 − p_b just below the percolation pressure). Hertz and arrays: eq. (33) on adaptive
Gauss–Legendre panels by damped Newton; a profile whose peak contact pressure p_max − p_a lies
past π_trust is "near_percolation" with Q = NaN (the zone's resistance ∫dx/σ̄ is then
dominated by the unverified σ̄: no bound on Q but 0 <= Q; such seals are practically closed).
A profile with p_max − p_a <= π_trust E* < p_max − p_b may still reach it at the peak
(depending on the fluid pressure there) and is solved as before.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .._core.owned import own_columns
from .._core.validate import align_inputs, check_positive
from .._core.vocab import DEFAULT_THEORY
from . import _panels
from ._inputs import (alpha_scale, check_tables, check_theory_for, common_inputs, forbid,
                      hertz_contact, profile_kind, require)
from .context import (EQUALITY_TOL, NEAR_LIFT_OFF, peak_past_trust, seal_context,
                      solve_profile_rows, solver_options)
from ._uniform import leak_uniform
from .hertz import VERIFY_TOL, tabled_W
from .viscosity import seal_leak_piezo  # issue 14: Barus fluid (alpha_pv)

__all__ = ["seal_leak", "columns", "STATUS", "UNITS", "REFERENCES", "EQUALITY_TOL"]

#: row status names, indexed by the kernels' codes (``status`` column, a pandas Categorical)
STATUS = ("ok", "lift_off", "open", "percolated", "above_table", "not_converged",
          "near_percolation")
_ST_NOT_CONVERGED = STATUS.index("not_converged")

#: unit of every result column ("" for flags and text)
UNITS = {"Q": "m^3/s", "p0": "Pa", "dp": "Pa", "p_a": "Pa", "p_b": "Pa", "L": "m", "L_y": "m",
         "E_star": "Pa", "eta": "Pa s", "alpha_cj": "1", "R": "m", "f_N": "N/m", "a": "m",
         "p_max": "Pa", "open_inlet": "m", "open_outlet": "m", "error_estimate": "1",
         "lift_off": "", "percolated": "", "converged": "", "status": ""}

REFERENCES = (
    "B. Lorenz and B.N.J. Persson, Time-dependent fluid squeeze-out between solids with rough "
    "surfaces, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037",
    "B. Lorenz and B.N.J. Persson, Leak rate of seals: effective-medium theory and comparison "
    "with experiment, Eur. Phys. J. E 31, 159 (2010), arXiv:0911.3019",
)


#: the result columns that echo an input (views of the caller's arrays until
#: :func:`~fastcontact._core.owned.own_columns` gives them their own memory)
INPUT_COLUMNS = ("p0", "dp", "p_b", "L", "L_y", "E_star", "eta", "alpha_cj", "R", "f_N",
                 "alpha_pv", "roelands_z", "roelands_p_r", "roelands_eta_inf")

_BASE = ("Q", "lift_off", "percolated", "status")
_COLUMNS = {
    "uniform": _BASE + ("p0", "dp", "p_a", "p_b", "L", "L_y", "E_star", "eta", "alpha_cj",
                        "open_inlet", "open_outlet"),
    "hertz": _BASE + ("R", "f_N", "a", "L", "p_max", "dp", "p_a", "p_b", "L_y", "E_star", "eta",
                      "alpha_cj", "open_inlet", "open_outlet", "converged", "error_estimate"),
    "array": _BASE + ("p_max", "L", "dp", "p_a", "p_b", "L_y", "E_star", "eta", "alpha_cj",
                      "open_inlet", "open_outlet", "converged", "error_estimate"),
}


def columns(profile="uniform"):
    """Result columns of :func:`seal_leak` for a profile kind, with their units.

    Parameters
    ----------
    profile : {"uniform", "hertz", "array"}
        Profile kind (an array profile is "array").

    Returns
    -------
    dict
        Column name → unit string ("" for flags and the status text).
    """
    if profile not in _COLUMNS:
        raise ValueError(f"profile = {profile!r} is invalid: must be one of {sorted(_COLUMNS)}")
    return {c: UNITS[c] for c in _COLUMNS[profile]}


def _flat(*arrays):
    arrs = np.broadcast_arrays(*arrays)
    return arrs[0].shape, [np.ascontiguousarray(a, dtype=np.float64).ravel() for a in arrs]


def _status(codes):
    return pd.Categorical.from_codes(np.asarray(codes, dtype=np.int8), categories=list(STATUS))


# =========================================================================== uniform
def _leak_uniform(sc, theory, p0, L, com, alpha_cj):
    """Flat ring: eq. (32) with the fluid feedback, q = (1/L) ∫_{p0−p_a}^{p0−p_b} σ_eff dp
    (one parallel pass, :func:`._uniform.leak_uniform`)."""
    cols, shape = leak_uniform(sc, theory, p0, L, com, alpha_cj)
    cols["status"] = _status(cols["status"])
    return cols, shape


# =========================================================================== profiles
def _finish_profile(sc, theory, cols, solve, contact, out, E, ell, dp, L_y, eta, alpha):
    """Q, status, converged and error_estimate of profile rows from the solver outputs."""
    st = np.where(out.status == _panels.ST_NEWTON_FAILED, np.nan, out.W)
    W = np.where(solve & (st == 0.0), np.nan, st)        # a zone of zero length: no number
    scale = alpha_scale(sc, theory, alpha)
    with np.errstate(invalid="ignore", divide="ignore"):
        Q = L_y * sc.h_rms ** 3 * E / (12.0 * eta * ell) * (dp / E) / W * scale
    Q = np.where(solve, Q, 0.0)
    Q = np.where(~contact, np.inf, Q)
    code = np.where(~contact, STATUS.index("open"),
                    np.where(cols["lift_off"], STATUS.index("lift_off"), 0))
    code = np.where(cols["percolated"], STATUS.index("percolated"), code)
    code = np.where(solve & np.isnan(Q), _ST_NOT_CONVERGED, code)
    conv = ~solve | (out.status == _panels.ST_OK) | (out.status == _panels.ST_NO_ZONE)
    err = np.where(solve, np.where(out.status == _panels.ST_NEWTON_FAILED, np.nan, out.err), 0.0)
    cols.update(Q=Q, status=_status(code), converged=conv, error_estimate=err)


def _leak_hertz(sc, theory, R, f_N, com, alpha_cj, o):
    """O-ring: Hertz line-contact p0(x) on x ∈ [0, 2a], soft-seal solver."""
    R = check_positive("R", R, "[m]")
    f_N = check_positive("f_N", f_N, "[N/m]")
    shape, (R, f_N, dp, L_y, E, eta, p_b, alpha) = _flat(
        R, f_N, com["dp"], com["L_y"], com["E_star"], com["eta"], com["p_b"], alpha_cj)
    a, pH = hertz_contact(R, f_N, E)
    p_a = p_b + dp
    contact = ~(p_a > pH)
    perc = contact & (pH - p_a >= sc.p_perc * E)
    above = contact & ~perc & ((pH - p_b) / E > sc.p_top * (1 + 1e-13))
    near = peak_past_trust(sc.pi_trust, contact & ~perc & ~above & (dp > 0), pH, p_a, E)
    solve = contact & ~perc & ~above & ~near & (dp > 0)
    idx = np.flatnonzero(solve)
    piH = np.ascontiguousarray(pH / E)
    pia = np.ascontiguousarray(p_a / E)
    pib = np.ascontiguousarray(p_b / E)
    Wt = tabled_W(sc, piH, pia, pib, idx[p_a[idx] != pH[idx]], p_b == 0.0) if o["table"] \
        else None
    if Wt is not None:
        idx = idx[~np.isfinite(Wt[idx])]
    out = solve_profile_rows(sc, o, 0, np.zeros(2), np.zeros(2), piH, pia, pib, idx,
                              p_a[idx] >= (1.0 - NEAR_LIFT_OFF) * pH[idx])
    if Wt is not None:
        fast = np.isfinite(Wt)
        out.W[fast] = Wt[fast]
        out.status[fast] = _panels.ST_OK
        out.err[fast] = VERIFY_TOL
    with np.errstate(invalid="ignore"):
        sa = np.clip(p_a / pH, 0.0, 1.0)
        sb = np.clip(p_b / pH, 0.0, 1.0)
        open_in = np.where(contact, a * (1.0 - np.sqrt(1.0 - sa * sa)), 2 * a)
        open_out = np.where(contact, a * (1.0 - np.sqrt(1.0 - sb * sb)), 0.0)
    cols = {"lift_off": p_a >= pH, "percolated": perc, "R": R, "f_N": f_N, "a": a, "L": 2 * a,
            "p_max": pH, "dp": dp, "p_a": p_a, "p_b": p_b, "L_y": L_y, "E_star": E, "eta": eta,
            "alpha_cj": alpha, "open_inlet": open_in, "open_outlet": open_out}
    _finish_profile(sc, theory, cols, solve, contact, out, E, a, dp, L_y, eta, alpha)
    _mark_nan(cols, above, "above_table", unconverged=True)
    _mark_nan(cols, near, "near_percolation")
    return cols, shape


def _mark_nan(cols, rows, status, unconverged=False):
    """Q = NaN and ``status`` on ``rows`` ("above_table": the contact pressure above the table,
    also not converged; "near_percolation": :func:`~.context.peak_past_trust`)."""
    if rows.any():
        cols["Q"] = np.where(rows, np.nan, cols["Q"])
        codes = np.asarray(cols["status"].codes).copy()
        codes[rows] = STATUS.index(status)
        cols["status"] = _status(codes)
        if unconverged:
            cols["converged"] = cols["converged"] & ~rows


def _leak_array(sc, theory, p0x, x, com, alpha_cj, o):
    """A sampled profile p0(x) (linear between the samples), soft-seal solver."""
    shape, (dp, L_y, E, eta, p_b, alpha) = _flat(
        com["dp"], com["L_y"], com["E_star"], com["eta"], com["p_b"], alpha_cj)
    L = float(x[-1] - x[0])
    xi = np.ascontiguousarray((x - x[0]) / L)
    p_a = p_b + dp
    pmax = float(np.max(p0x))
    contact = ~(p_a > pmax)
    perc = contact & ((pmax - p_a >= sc.p_perc * E) | (p0x[-1] - p_b >= sc.p_perc * E))
    above = contact & ~perc & ((pmax - p_b) / E > sc.p_top * (1 + 1e-13))
    near = peak_past_trust(sc.pi_trust, contact & ~perc & ~above & (dp > 0), pmax, p_a, E)
    solve = contact & ~perc & ~above & ~near & (dp > 0)
    idx = np.flatnonzero(solve)
    out = solve_profile_rows(sc, o, 1, xi, np.ascontiguousarray(p0x, dtype=np.float64),
                              np.ascontiguousarray(1.0 / E), np.ascontiguousarray(p_a / E),
                              np.ascontiguousarray(p_b / E), idx,
                              p_a[idx] >= (1.0 - NEAR_LIFT_OFF) * pmax)
    xs = np.where(solve, out.xs, np.where(contact, 0.0, 1.0))
    xe = np.where(solve, out.xe, 1.0)
    cols = {"lift_off": p_a >= pmax, "percolated": perc, "p_max": np.full(E.size, pmax),
            "L": np.full(E.size, L), "dp": dp, "p_a": p_a, "p_b": p_b, "L_y": L_y, "E_star": E,
            "eta": eta, "alpha_cj": alpha, "open_inlet": xs * L, "open_outlet": (1.0 - xe) * L}
    _finish_profile(sc, theory, cols, solve, contact, out, E, L, dp, L_y, eta, alpha)
    _mark_nan(cols, above, "above_table", unconverged=True)
    _mark_nan(cols, near, "near_percolation")
    return cols, shape


# =========================================================================== public
def seal_leak(tables, *, p0=None, dp, L=None, L_y, E_star, eta, theory=DEFAULT_THEORY,
              alpha_cj=1.0, p_b=0.0, profile="uniform", R=None, f_N=None, x=None, a_perc=None,
              solver=None, alpha_pv=0.0, direction=None, viscosity="barus", roelands_z=None,
              roelands_p_r=None, roelands_eta_inf=None):
    """Leak rate of a static seal, Q = L_y q [m³/s], for many cases at once.

    Steady flow across the seal width with fluid-pressure feedback (Lorenz & Persson 2010,
    eqs. 25–33): Q = L_y Δp / ∫ dx/σ_eff(p_cont(x)) (31), p0 = p_cont + p_f (28). Array
    arguments broadcast against each other; one row per broadcast element (C order).

    Parameters
    ----------
    tables : fastcontact.tables.Tables
        Precomputed tables of the rough surface (must hold ``theory``).
    p0, L : float or array_like, optional
        Flat ring (``profile="uniform"``): nominal contact pressure [Pa] and seal width [m].
    dp : float or array_like
        Pressure difference p_a − p_b across the seal [Pa], >= 0.
    L_y : float or array_like
        Seal length, e.g. the mean circumference of a ring [m].
    E_star, eta : float or array_like
        Effective modulus [Pa] and fluid viscosity [Pa·s].
    theory : {"critical_junction", "emt", "average"}, default DEFAULT_THEORY ("critical_junction")
        Flow-conductivity theory (must be in the tables).
    alpha_cj : float or array_like, default 1.0
        Critical-junction factor [-] (σ ∝ α_cj³; rescales the table's α exactly).
    p_b : float or array_like, default 0.0
        Gauge pressure on the low-pressure side [Pa], >= 0.
    profile : {"uniform", "hertz"} or array_like, default "uniform"
        Nominal pressure profile: a flat ring, an O-ring (Hertz line contact,
        a² = 4 f_N R/(π E*), L = 2a), or p0(x) [Pa] sampled at ``x``.
    R, f_N : float or array_like, optional
        O-ring cross-section radius [m] and load per unit length [N/m] (``"hertz"``).
    x : array_like, optional
        Positions [m] of an array profile's samples (strictly increasing, inlet at x[0]).
    a_perc : float, optional
        If given it must equal the tables' percolation area fraction [-].
    solver : dict, optional
        Knobs of the non-uniform solver (``fastcontact.seal.SOLVER_DEFAULTS``). Rows at or
        within ``NEAR_LIFT_OFF`` (1e-4 relative) below lift-off are solved at the panel
        tolerance EQUALITY_TOL (1e-9) whatever ``tol`` is (Q has a square-root limit there).
        ``table`` (default True): Hertz O-rings read W from the verified tables of
        :mod:`fastcontact.seal.hertz` (``error_estimate`` = VERIFY_TOL, 2e-7 in ln W, on those
        rows), built as far as the rows need and kept: p_b = 0 always, p_b > 0 where
        completing that table costs no more solves than those rows (e.g. 200,000 O-rings of
        p_H/E* within a factor 3; not a few thousand of scattered p_H, until a kept table
        covers them); rows whose cells are not verified (next to lift-off or percolation, and
        p_a, p_b both within ~1 % of p_H) are solved. False: every row by the solver.
    alpha_pv : float or array_like, default 0.0
        Barus coefficient α [1/Pa], η = η0 exp(α(p_f − p_b)); 0 leaves the result unchanged.
    viscosity : {"barus", "roelands"}, default "barus"
        Pressure–viscosity law; α_pv ≠ 0 or "roelands": :func:`.viscosity.seal_leak_piezo`
        ("uniform", "hertz"; ``roelands_z`` [-], ``roelands_p_r`` [Pa], ``roelands_eta_inf``).
    direction : {None, "x", "y"}, default None
        On tables of ``precompute(..., anisotropy=γ_T)``: flow along ("x") or across ("y") the
        grooves (σ_xx, σ_yy; "emt"; "average" has none, "critical_junction" raises); else None.

    Returns
    -------
    pandas.DataFrame
        Columns :func:`columns` of the profile kind: ``Q`` [m³/s]; ``lift_off`` (p_a >= max
        p0: the finite limit at the equality, Q = inf beyond, ``status = "open"``);
        ``percolated`` (Q = 0); ``status`` (:data:`STATUS`; Q = NaN for "above_table" — the
        contact pressure above the table —, "not_converged" and "near_percolation", module
        docstring); the inputs, ``p_a`` [Pa], ``open_inlet``/``open_outlet`` [m]; non-uniform
        profiles ``converged``, ``error_estimate`` [-], Hertz ``a``, ``L`` [m], ``p_max`` [Pa].
        ``attrs``: ``shape``, ``theory``, ``profile``, ``units``, ``references``.

    References
    ----------
    B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037
    """
    if direction is not None:                  # anisotropic roughness (σ_xx, σ_yy)
        tables = _directional(tables, direction, theory)
    if viscosity != "barus" or np.any(np.asarray(alpha_pv, dtype=np.float64) != 0.0):
        return seal_leak_piezo(tables, p0=p0, dp=dp, L=L, L_y=L_y, E_star=E_star, eta=eta,
                               alpha_pv=alpha_pv, theory=theory, alpha_cj=alpha_cj, p_b=p_b,
                               profile=profile, R=R, f_N=f_N, viscosity=viscosity,
                               roelands_z=roelands_z, roelands_p_r=roelands_p_r,
                               roelands_eta_inf=roelands_eta_inf)   # issue 14: η(p) fluids
    check_tables(tables)
    al = align_inputs(p0=p0, dp=dp, L=L, L_y=L_y, E_star=E_star, eta=eta, p_b=p_b, R=R,
                      f_N=f_N)                               # pandas inputs paired by label
    alpha_cj = check_theory_for(tables, theory, alpha_cj, a_perc)
    kind, p0x, xarr = profile_kind(profile, x)
    com = common_inputs(al["dp"], al["L_y"], al["E_star"], al["eta"], al["p_b"])
    cols, shape = _leak_kind(seal_context(tables, theory), theory, kind, al, p0x, xarr, com,
                             alpha_cj, solver)
    return _frame(cols, shape, theory, kind)


def _frame(cols, shape, theory, kind):
    """The result DataFrame of :func:`seal_leak`: the columns of ``kind``, units, references."""
    names = _COLUMNS[kind]
    df = pd.DataFrame(own_columns({c: cols[c] for c in names}, INPUT_COLUMNS), copy=False)
    df.attrs.update({"shape": tuple(shape), "theory": theory, "profile": kind,
                     "units": {c: UNITS[c] for c in names}, "references": list(REFERENCES)})
    return df


def _directional(tables, direction, theory):
    """The tables of σ_xx or σ_yy for ``direction`` (anisotropic roughness, issue 14)."""
    from ..flow.anisotropy import tables_for_direction   # only for directional runs
    return tables_for_direction(check_tables(tables), direction, theory)


def _leak_kind(sc, theory, kind, al, p0x, xarr, com, alpha_cj, solver):
    """(columns, shape) of :func:`seal_leak` for the profile ``kind``, after checking that the
    arguments ``al`` (aligned inputs by name) fit it."""
    if kind == "uniform":
        require(kind, p0=al["p0"], L=al["L"])
        if al["R"] is not None or al["f_N"] is not None:
            name, v = ("R", al["R"]) if al["R"] is not None else ("f_N", al["f_N"])
            raise ValueError(f"{name} = {v!r} is invalid with profile = 'uniform': R and f_N "
                             f"define the Hertz profile (profile='hertz')")
        return _leak_uniform(sc, theory, al["p0"], al["L"], com, alpha_cj)
    if kind == "hertz":
        forbid(kind, p0=al["p0"], L=al["L"])
        require(kind, R=al["R"], f_N=al["f_N"])
        return _leak_hertz(sc, theory, al["R"], al["f_N"], com, alpha_cj, solver_options(solver))
    forbid("array", p0=al["p0"], L=al["L"], R=al["R"], f_N=al["f_N"])
    return _leak_array(sc, theory, p0x, xarr, com, alpha_cj, solver_options(solver))
