"""Tire footprint with a pressure-dependent (Barus) viscosity: ``tire_footprint(alpha_pv=α)``.

The tread block's squeeze-out (Lorenz & Persson 2010, Sec. 5, eqs. 17–19) with
η(p_f) = η0 exp(α p_f), p_f the fluid pressure above the ambient. As in
:mod:`fastcontact.squeeze.viscosity` the radial Reynolds flow reduces *exactly* through the
reduced pressure ψ = (1 − e^{−αp})/α (σ0 depends on ū only, which is uniform under the
block), so the squeeze rate is the constant-viscosity rate times g(α(p_eval − p_cont(ū))),
g ∈ (1/2, 1] (docs/theory/extensions.md §2a). Every time column is the quadrature
t = τ0 ∫ dũ/|dũ/dt̃| in w = ln(ū − ū∞) of that engine (Gauss–Legendre panels of width
``QUAD_WIDTH`` in w), and ū at the footprint exit solves t(ū_exit) = t_footprint on the same
quadrature: panels are summed downward from ū(0) until the exit time is passed, and the
last panel's partial integral is inverted by safeguarded Newton (dt/dw = −integrand).

Rows with α = 0 are evaluated by the base engine (bit for bit what ``tire_footprint``
returns without ``alpha_pv``). Rows with α(p_eval − p_cont(ū(0))) >= 1 have no quasi-static
solution (the rigid film cannot carry the load): status ``"piezo_limit"``, NaN results.

References: C. Barus, Am. J. Sci. 45, 87 (1893), doi:10.2475/ajs.s3-45.266.87;
B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
import pandas as pd
from numba import njit, prange

from ..kernels.quadrature import gauss_legendre
from ..kernels.readonly import readonly, readonly_fields
from ._kernels import Cases, Quad, check_computed, new_status, reduced_time
from .api import STATUS_NAMES
from .viscosity import (BarusTargets, _case_head, _case_start, _scalars,
                        _state, _target_times, fast_scratch, fast_setup, flag_overflow,
                        trap_floor_v, v_at_time)

__all__ = ["QUAD_ORDER", "QUAD_WIDTH", "STATUS", "barus_tire_columns"]

QUAD_ORDER = 10
QUAD_WIDTH = 1.0
#: status names of the Barus tire rows (the base engine's, plus "piezo_limit")
STATUS = tuple(STATUS_NAMES) + ("piezo_limit",)
_OK, _TRAPPED, _OUT, _BELOW = (STATUS.index(s) for s in ("ok", "trapped", "out_of_table",
                                                         "start_below_equilibrium"))
_PIEZO = STATUS.index("piezo_limit")
#: outputs of the Barus tire kernel, one column per row: T (nt, n) target times [s], u_exit,
#: u_inf, u_start, u_trap [m], flf (fluid load fraction) [-], status (int8)
TireOut = namedtuple("TireOut", "T u_exit u_inf u_start u_trap flf status")


@njit(cache=True)
def _tire_case(tab, sc, cs, alpha, t_fp, h, tg, quad, i, out):
    """Case i of :func:`_tire_kernel` into row/column i of ``out`` (:data:`TireOut`).

    Stores go through this (non-parallel) helper: a store made inside a prange body into an
    array taken from a record argument is silently lost (numba 0.6x parfor lowering)."""
    T = out.T
    x0, tau, inside = _case_head(cs, sc, h, i)
    for k in range(T.shape[0]):
        T[k, i] = math.nan
    out.u_exit[i] = math.nan
    out.u_trap[i] = math.nan
    out.flf[i] = math.nan
    out.u_inf[i] = math.nan
    out.u_start[i] = cs.us[i]
    if not inside:
        out.status[i] = _OUT
        return
    vinf, vs = _case_start(tab, sc, x0, cs, h, i, out)
    if not (vs * h > vinf * h):  # a given start at or below ū∞, trapped rows too (as reported,
        out.status[i] = _BELOW  # SI; as the base engine and the Barus squeeze-out)
        return
    x_trap = sc[0].x_trap
    trapped = x0 >= x_trap
    vb = trap_floor_v(tab, sc, x0)  # NaN unless trapped
    if trapped:
        out.u_trap[i] = vb * h
        out.flf[i] = -math.expm1(x_trap - x0)
    else:
        out.flf[i] = 0.0
    api = alpha[i] * cs.p0[i]
    lnps, _s = _state(tab, sc, vs)
    if api * (-math.expm1(lnps - x0)) >= 1.0:
        out.status[i] = _PIEZO
        out.flf[i] = math.nan
        out.u_trap[i] = math.nan
        return
    _target_times(tab, sc, x0, api, vinf, vb, vs, tau, tg, quad, T, i)
    if t_fp.size:  # no footprint times: the exit is not asked for
        # tt = inf (τ0 = 0, a row flagged "overflow" afterwards): ū∞, or ū_trap if trapped
        out.u_exit[i] = v_at_time(tab, sc, x0, api, vinf, vb, vs, reduced_time(t_fp[i], tau),
                                  quad) * h
    # last (a failing worker thread stops without raising: the row keeps NOT_COMPUTED)
    out.status[i] = _TRAPPED if trapped else _OK


@njit(parallel=True, cache=True)
def _tire_kernel(tab, sc, cs, alpha, t_fp, h, tg, quad, out):
    """Per case (``cs`` :class:`~fastcontact.squeeze._kernels.Cases`, α [1/Pa] and the
    footprint time t_fp [s] apart): targets (ratios × v∞, then v∞ + dv) and ū at t_fp (t_fp
    of size 0: none, u_exit NaN), SI, into ``out`` (:data:`TireOut`)."""
    for i in prange(cs.p0.size):  # the index as int64, as the fast path's blocks pass it
        _tire_case(tab, sc, cs, alpha, t_fp, h, tg, quad, np.int64(i), out)


def _fast_rows(tables, theory, tab, sc, cs, al, tf, h, tg, quad, res):
    """method "fast": the rows a G primitive serves (the rows of one α E* of a call:
    :func:`._barus_time.served_groups`, the base engine's kernel) and the others by the Barus
    kernel (:func:`._barus_fast.tire_kernel`), into ``res``."""
    from ._barus_fast import ratio_rows, tire_kernel
    from ._barus_time import run_rest, served_groups, tire_rows
    from .model import squeeze_model
    setup = fast_setup(tables, theory, None)
    model = squeeze_model(tables, theory)
    groups, rest = served_groups(model, setup, cs.p0, cs.E, al, cs.us, h)
    for bg, gi in groups:
        tire_rows(model, bg, cs, tf, h, tg.ratios[1:], tg.dvs, quad, res, gi)

    def per_case(sub, part):
        tire_kernel(tab, sc, *setup, Cases(*(sub(a) for a in cs)), sub(al),
                    sub(tf) if tf.size else tf, h, tg, *ratio_rows(*setup[:3], tg), quad, part,
                    fast_scratch())
    if rest.size == cs.p0.size:
        per_case(lambda a: a, res)
    elif rest.size:  # the others as a call of their own
        run_rest(res, rest, per_case)


def barus_tire_columns(tables, b, p_eval, t_fp, theory, ratios, ratio_names, du_complete,
                       alpha, out, base_columns, method="fast", want=None):
    """Fill the squeeze-out columns of :func:`~fastcontact.squeeze.tire.tire_footprint` with
    a Barus fluid (α = ``alpha`` [1/Pa] per row) into ``out``; rows with α = 0 go to
    ``base_columns(tables, b_subset, p_eval_subset, t_fp_subset, out_subset)`` (the base
    engine, bit for bit). ``want`` (a set of column names; None: all) selects what is
    computed, as in the base engine: a ratio target only for its ``t_ratio_<r>`` column, the
    Δu target only for ``t_du``, the exit (ū at the footprint time, a Newton of a few
    inversions: most of a case) only for ``u_exit``, ``du_exit`` or ``squeeze_complete``.
    Returns the base squeeze model (for the frame's attrs)."""
    from .model import squeeze_model
    from .tire import _EXIT_COLUMNS

    n = p_eval.size
    zero = alpha == 0.0
    sel = np.flatnonzero(~zero)
    m = sel.size
    h = float(tables.h_rms)
    keep = [k for k, nm in enumerate(ratio_names) if want is None or nm in want]
    du = want is None or "t_du" in want
    exit_ = want is None or bool(want & _EXIT_COLUMNS)
    r = np.asarray(ratios, dtype=np.float64)[keep]
    vr = np.ascontiguousarray(np.concatenate(([1.01], r)))
    dv = np.array([du_complete / h] if du else [])
    T = np.empty((vr.size + dv.size, m))
    ue, ui, us, ut, fl = (np.empty(m) for _ in range(5))
    st = new_status(m)
    if m:
        us_in = b["u_start"][sel] if "u_start" in b else np.full(m, np.nan)
        x, w = gauss_legendre(QUAD_ORDER)
        p, E, R, eta, al, u0, tf = [readonly(a) for a in
                                    (p_eval[sel], b["E_star"][sel], b["R"][sel], b["eta"][sel],
                                     alpha[sel], us_in, t_fp[sel] if exit_ else t_fp[:0])]
        cs = Cases(p, E, R, eta, u0)
        tg = readonly_fields(BarusTargets(vr, dv, np.empty(0)))
        quad, res = Quad(x, w, QUAD_WIDTH), TireOut(T, ue, ui, us, ut, fl, st)
        tab, sc = tables.kernel_data(theory), _scalars(tables, theory, None)
        if method == "fast":
            _fast_rows(tables, theory, tab, sc, cs, al, tf, h, tg, quad, res)
        else:
            _tire_kernel(tab, sc, cs, al, tf, h, tg, quad, res)
        with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
            tau0 = 3.0 * eta * R * R / (2.0 * h * h * p)  # as the kernels' τ0 [s]
        check_computed(st, "tire_footprint(alpha_pv=...)")
        flag_overflow(st, tau0, T, _OK, _TRAPPED, STATUS.index("overflow"))
    piezo = {"u_inf": ui, "u_start": us, "t_star": T[0], "trapped": st == _TRAPPED,
             "u_trap": ut, "fluid_load_fraction": fl, "out_of_table": st == _OUT}
    if du:
        piezo["t_du"] = T[1 + r.size]
    if exit_:
        with np.errstate(invalid="ignore"):
            piezo.update(u_exit=ue, du_exit=ue - ui, squeeze_complete=(ue - ui) <= du_complete)
    for j, k in enumerate(keep):
        piezo[ratio_names[k]] = T[1 + j]
    if m == n:  # every row Barus: the kernel's arrays are the columns (no copy)
        out.update(piezo)
        out["status"] = pd.Categorical.from_codes(st, categories=list(STATUS))
        return squeeze_model(tables, theory)
    codes = np.empty(n, dtype=np.int8)
    codes[sel] = st
    base = {}
    if np.any(zero):
        base_columns(tables, {k: v[zero] for k, v in b.items()},
                     np.ascontiguousarray(p_eval[zero]), np.ascontiguousarray(t_fp[zero]), base)
        codes[zero] = np.asarray(base.pop("status").codes, dtype=np.int8)  # same first names
    for key, val in piezo.items():
        full = np.empty(n, dtype=val.dtype)
        full[sel] = val
        if base:
            full[zero] = base[key]
        out[key] = full
    out["status"] = pd.Categorical.from_codes(codes, categories=list(STATUS))
    return squeeze_model(tables, theory)
