"""Building the time primitive of one (tables, theory) in one parallel pass.

Part of :mod:`fastcontact.squeeze.primitive`. The x0-independent state (ln π_c, ln σ̄ and
their ln v-derivatives) is tabulated once on a fine grid in ln v (:func:`profile`); each x0
row then integrates T(x0, v) = ∫_v^∞ dv'/(σ̄ (1 - π_c/π0)) (Lorenz & Persson 2010, eqs. (18),
(19), (23); arXiv:1004.1037) with composite Gauss–Lobatto panels in z = ln(v/v∞ - 1) between
the nodes (the panel ends are the nodes, whose integrand the derivatives need anyway), and
:func:`measure_error` checks the interpolant against direct quadrature at cell centres.
"""
from __future__ import annotations

import math
import time as _clock
from collections import namedtuple

import numpy as np
from numba import njit, prange

from ..kernels.balance import spread_order
from ..kernels.hermite import cubic_basis, quintic_unit
from ..kernels.locate import locate_asc, locate_desc
from ..kernels.lookup import sigma_interval_resolved, sigma_linear
from ..kernels.quadrature import gauss_legendre, gauss_lobatto
from ..kernels.readonly import readonly_fields
from ..tables.build import verified_top as _tables_verified_top
from . import _kernels as qk
from ._primitive_eval import (Primitive, _index_map, lagrange_denominators, one_plus_exp,
                              row_value, stencil, t_of_z)

__all__ = ["build", "measure_error", "profile", "fast_limit", "Profile", "DXI", "Z_LO", "DZ",
           "NODE_POINTS", "THEORY_NODE_POINTS", "node_points", "CHECK_ORDER", "X_END",
           "verified_top"]

#: grid spacing in ξ = x0 - ln σ̄(x0) of the x0 rows. The rows also carry ln v∞, which the
#: 4-point stencil keeps within ~4e-9 of the tables' inverse (at 0.15: 2.2e-8, more than the
#: ū - ū∞ tolerance of 1e-8 ū∞ close to equilibrium)
DXI = 0.1
#: z = ln(v/v∞ - 1) grid: lower end and spacing (below: analytic log singularity). The
#: spacing sets the quintic's error in z: on the embedded road tables' critical-junction
#: primitive, every served cell centre, 1.1e-6 at 0.25, 3.7e-7 at 0.2 (EMT 8e-8, average 2e-8)
Z_LO = -10.0
DZ = 0.2
#: Gauss–Lobatto points per z panel of the node quadrature (:data:`THEORY_NODE_POINTS` per
#: theory); a panel's ends are the nodes, whose integrand each node computes anyway, so 7
#: points cost 5 new integrand values a node (6-point Gauss–Legendre, before 2026-12-02: 6).
#: Node ln T against 12-point Gauss–Legendre panels, critical junction and EMT on six spectra
#: (the embedded four, a synthetic road, a self-affine one of 5 decades): 2.1e-8–1.1e-7 at 7
#: points, 2.0e-8–1.5e-7 with the 6 Gauss–Legendre points (the integrand is only piecewise
#: smooth: the profile is a C¹ cubic), 1e-6–2e-5 at 4
NODE_POINTS = 7
#: theories whose node quadrature converges with fewer points: the average theory's σ̄ is
#: smooth, its node ln T at 5 points within 1.1e-10–3.3e-10 of 12-point Gauss–Legendre on the
#: same spectra (the cell-centre interpolation error is ~1e-8); its build has the most rows
THEORY_NODE_POINTS = {"average": 5}
#: Gauss–Legendre order of :func:`measure_error`'s direct quadrature (panels of dz/4)
CHECK_ORDER = 6


def node_points(theory):
    """Gauss–Lobatto points per z panel of the primitive's node quadrature for ``theory``."""
    return THEORY_NODE_POINTS.get(theory, NODE_POINTS)


#: x0-independent state along s = ln v (cubic Hermite on a fine uniform grid, below the table
#: top): ell = ln π_c, lam = ln σ̄ and their s-derivatives; above v_top the analytic tail
Profile = namedtuple("Profile", "s0 ds A")  # A[i] = (ell, dell, lam, dlam) at s0 + i ds
#: spacing of the profile grid in ln v (see :data:`X_END`: 0.004 left 7.6e-7 in t next to
#: the kink; the profile build costs the same) and the central-difference step of its
#: derivatives where the tables' interpolants give none (:func:`_profile_kernel`)
PROFILE_DS = 0.001
PROFILE_FD = 1e-5


@njit(cache=True)
def _state_fd(tab, s):
    """(ln π_c, ln σ̄) of the tables at ln v = s."""
    lp = qk.k_lnp_of_lnu(tab, s)
    return lp, math.log(qk.k_sigma_of_lnp(tab, lp))


@njit(cache=True)
def _state_slopes(tab, s):
    """(ln π_c, d ln π_c/ds, ln σ̄, d ln σ̄/ds, exact) of the tables' interpolants at ln v = s:
    the same values as :func:`_state_fd` and the interpolants' own slopes (the inverse
    quintic of ln π_c in ln ū; ln σ̄'s quintic, or its line across an unresolved interval, in
    ln π_c). ``exact`` False beyond the last open node or outside the table (the caller
    differences :func:`_state_fd` there)."""
    i = locate_desc(s, tab.lnu, tab.bu_lo, tab.bu_dz, tab.bu_idx)
    if i < 0:
        return math.nan, math.nan, math.nan, math.nan, False
    lnp, lnu, a, d2 = tab.lnp, tab.lnu, tab.dlnu, tab.d2lnu
    h = lnu[i + 1] - lnu[i]
    lp, dlp = quintic_unit((s - lnu[i]) / h, h, lnp[i], 1.0 / a[i], -d2[i] / a[i] ** 3,
                           lnp[i + 1], 1.0 / a[i + 1], -d2[i + 1] / a[i + 1] ** 3)
    k = locate_asc(lp, lnp, tab.bp_lo, tab.bp_dz, tab.bp_idx)
    if k < 0 or lp >= tab.lnp_perc or k + 1 >= tab.n_open:
        return lp, dlp, math.nan, math.nan, False
    x0, x1 = lnp[k], lnp[k + 1]
    y0, y1 = tab.lnsig[k], tab.lnsig[k + 1]
    m0, m1 = tab.dlnsig[k], tab.dlnsig[k + 1]
    if sigma_interval_resolved(x0, x1, y0, y1, m0, m1):
        hp = x1 - x0
        ls, dls = quintic_unit((lp - x0) / hp, hp, y0, m0, tab.d2lnsig[k], y1, m1,
                               tab.d2lnsig[k + 1])
    else:
        ls, dls = sigma_linear(lp, x0, x1, y0, y1), (y1 - y0) / (x1 - x0)
    return lp, dlp, ls, dls * dlp, True


@njit(parallel=True, cache=True)
def _profile_kernel(tab, s0, ds, A):
    """The :data:`Profile` samples: values and exact slopes of the tables' interpolants where
    :func:`_state_slopes` has them (one evaluation a sample), central differences of step
    PROFILE_FD elsewhere (one-sided at the ends)."""
    n = A.shape[0]
    hh = PROFILE_FD
    for i in prange(n):
        s = s0 + i * ds
        lp, dlp, ls, dls, exact = _state_slopes(tab, s)
        if exact:
            A[i, 0] = lp
            A[i, 1] = dlp
            A[i, 2] = ls
            A[i, 3] = dls
            continue
        lp, ls = _state_fd(tab, s)
        A[i, 0] = lp
        A[i, 2] = ls
        if 0 < i < n - 1:
            la, lsa = _state_fd(tab, s - hh)
            lb, lsb = _state_fd(tab, s + hh)
            A[i, 1] = (lb - la) / (2.0 * hh)
            A[i, 3] = (lsb - lsa) / (2.0 * hh)
        else:  # one-sided, second order, inside the table
            sg = 1.0 if i == 0 else -1.0
            la, lsa = _state_fd(tab, s + sg * hh)
            lb, lsb = _state_fd(tab, s + 2.0 * sg * hh)
            A[i, 1] = sg * (-3.0 * lp + 4.0 * la - lb) / (2.0 * hh)
            A[i, 3] = sg * (-3.0 * ls + 4.0 * lsa - lsb) / (2.0 * hh)


@njit(cache=True)
def _pstate(pf, mp, v):
    """(ln π_c, ln σ̄, d ln π_c/d ln v, d ln σ̄/d ln v) at v: the profile below the table
    top, the analytic tail above."""
    if v > mp.v_top:
        sig, dls = qk.tail_sigma(mp, v)
        return mp.x_min - (v - mp.v_top) / mp.u0, math.log(sig), -v / mp.u0, dls
    u = (math.log(v) - pf.s0) / pf.ds
    i = int(u)
    A = pf.A
    n = A.shape[0]
    if i < 0:
        i = 0
    if i > n - 2:
        i = n - 2
    t = u - i
    h = pf.ds
    t2 = t * t
    h00, h10, h01, h11 = cubic_basis(t, h)
    g00 = (6.0 * t2 - 6.0 * t) / h
    g10 = 3.0 * t2 - 4.0 * t + 1.0
    g11 = 3.0 * t2 - 2.0 * t
    e0, de0, l0, dl0 = A[i, 0], A[i, 1], A[i, 2], A[i, 3]
    e1, de1, l1, dl1 = A[i + 1, 0], A[i + 1, 1], A[i + 1, 2], A[i + 1, 3]
    return (h00 * e0 + h10 * de0 + h01 * e1 + h11 * de1,
            h00 * l0 + h10 * dl0 + h01 * l1 + h11 * dl1,
            g00 * (e0 - e1) + g10 * de0 + g11 * de1,
            g00 * (l0 - l1) + g10 * dl0 + g11 * dl1)


@njit(cache=True)
def _plnv(pf, mp, x):
    """ln v with ln π_c(v) = x on the profile (Newton; the tail above the table top)."""
    if x <= mp.x_min:
        return math.log(mp.v_top + mp.u0 * (mp.x_min - x))
    # start: bisection bracket over the grid (ell decreases with s)
    lo = 0
    hi = pf.A.shape[0] - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if pf.A[mid, 0] > x:
            lo = mid
        else:
            hi = mid
    s = pf.s0 + (lo + 0.5) * pf.ds
    for _ in range(50):
        e, lm, de, dl = _pstate(pf, mp, math.exp(s))
        step = (e - x) / de
        s -= step
        if abs(step) < 1e-15:
            break
    return s


@njit(cache=True)
def _h(pf, mp, x0, vinf, z):
    """dT/d(-z) at z: the integrand (v - v∞)/(σ̄ (1 - π_c/π0)) in z."""
    e = vinf * math.exp(z)
    lp, lm, de, dl = _pstate(pf, mp, vinf + e)
    return e / (math.exp(lm) * -math.expm1(lp - x0))


@njit(cache=True)
def _h_dlnh(pf, mp, x0, vinf, e):
    """(h, d ln h/dz) at e = v∞ e^z (exact derivative of the profile's h)."""
    v = vinf + e
    lp, lm, de, dl = _pstate(pf, mp, v)
    dd = -math.expm1(lp - x0)
    q = 1.0 - dd  # π_c/π0 (its absolute error ~1e-16 only scales an O(1) term below)
    r = e / v
    return e / (math.exp(lm) * dd), 1.0 - r * dl + r * q * de / dd


@njit(cache=True)
def _panel(pf, mp, x0, vinf, za, zb, glx, glw):
    """∫_{za}^{zb} h dz, one Gauss–Legendre panel."""
    if not (zb > za):
        return 0.0
    hw = 0.5 * (zb - za)
    mid = 0.5 * (za + zb)
    acc = 0.0
    for j in range(glx.size):
        acc += glw[j] * _h(pf, mp, x0, vinf, mid + hw * glx[j])
    return acc * hw


@njit(cache=True)
def _h_at(pf, mp, x0, vinf, lv, z, e):
    """:func:`_h` where the caller has e = v∞ e^z (lv = ln v∞): e/σ̄ as one exponential."""
    lp, lm, de, dl = _pstate(pf, mp, vinf + e)
    return math.exp(lv + z - lm) / -math.expm1(lp - x0)


@njit(cache=True)
def _lobatto_panel(pf, mp, x0, vinf, lv, za, zb, ea, ha, hb, lbx, lbw, er, full):
    """∫_{za}^{zb} h dz, one Gauss–Lobatto panel whose end values ha = h(za), hb = h(zb) the
    caller has (lbx, lbw the rule on [-1, 1], ends included). ``ea`` = v∞ e^za; ``er`` the
    interior points' e^(z - za) on a panel of the grid's width, used where ``full``."""
    hw = 0.5 * (zb - za)
    n = lbx.size
    acc = lbw[0] * ha + lbw[n - 1] * hb
    for j in range(1, n - 1):
        z = za + hw * (1.0 + lbx[j])
        e = ea * er[j - 1] if full else vinf * math.exp(z)
        acc += lbw[j] * _h_at(pf, mp, x0, vinf, lv, z, e)
    return acc * hw


@njit(cache=True)
def _build_row(pf, mp, x0, vinf, lk, z0, dz, lbx, lbw, er, C, j):
    """ln T and its z-derivatives at the ζ nodes (z = ζ - lk) of row j: T summed downward from
    the closed-form tail over Gauss–Lobatto panels between the nodes, whose ends take the h
    each node computes for its derivatives (n - 2 new integrand values a panel; ``er`` their
    e^(z - z_node) on a full panel, :func:`_lobatto_panel`)."""
    nz = C.shape[1]
    lv = math.log(vinf)
    z_ext = math.log(mp.v_ext / vinf - 1.0) if mp.v_ext > vinf else -math.inf
    z_prev = z_ext
    T_prev = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
    h_prev = _h(pf, mp, x0, vinf, z_ext) if z_ext > -math.inf else 0.0
    for k in range(nz - 1, -1, -1):
        z = z0 + k * dz - lk
        e = vinf * math.exp(z)
        h, dlnh = _h_dlnh(pf, mp, x0, vinf, e)
        if z >= z_ext:
            T = qk._tail_int(mp.c, vinf * one_plus_exp(z) + mp.d, math.inf)
        else:
            full = z_prev < z_ext  # a panel between two nodes (the first one ends at z_ext)
            T = T_prev + _lobatto_panel(pf, mp, x0, vinf, lv, z, z_prev, e, h, h_prev, lbx,
                                        lbw, er, full)
            z_prev = z
            T_prev = T
            h_prev = h
        C[j, k, 0] = math.log(T)
        C[j, k, 1] = -h / T
        C[j, k, 2] = -h * dlnh / T - (h / T) ** 2


@njit(cache=True)
def _lnkappa(pf, mp, vinf):
    """ln κ of the row with equilibrium vinf (see :data:`Primitive`)."""
    e, lm, de, dl = _pstate(pf, mp, vinf)
    return 0.5 * math.log(1.0 + de * de + dl * dl)


@njit(parallel=True, cache=True)
def _rows_kernel(pf, mp, xn, lnv, lk, lnS, zs):
    """Per x0 node: ln v∞, ln κ, ln S (the slope below the grid) and the default start's z."""
    for j in prange(xn.size):
        x0 = xn[j]
        lv = _plnv(pf, mp, x0)
        vinf = math.exp(lv)
        lnv[j] = lv
        lk[j] = _lnkappa(pf, mp, vinf)
        e, lm, de, dl = _pstate(pf, mp, vinf)
        lnS[j] = lv - math.log(-de) - lm  # S = v∞ |d ln v/d ln π| / σ̄(π0): dT/d(-z) at ū∞
        vs = math.exp(_plnv(pf, mp, x0 + mp.lnp_start))
        zs[j] = math.log(vs / vinf - 1.0)


@njit(parallel=True, cache=True)
def _build_kernel(pf, mp, pr, lbx, lbw, er, rows):
    """Fill ln T and its z-derivatives at the ζ nodes (C) of the rows of ``pr`` (a
    :data:`Primitive` with its arrays allocated, ln v∞ and ln κ filled by
    :func:`_rows_kernel`); ``lbx``, ``lbw`` the Gauss–Lobatto rule of each panel and ``er``
    its interior points' e^(z - z_node) on the grid's spacing. The rows are visited in the
    order ``rows`` (:func:`~fastcontact.kernels.balance.spread_order`): a row's cost grows
    with its z nodes below the closed-form tail, i.e. along x0, and numba gives each thread a
    contiguous block."""
    # the output arrays as locals, one per statement, outside the loop: a store inside a prange
    # body into an array taken from a record argument is lost (numba 0.6x parfor lowering)
    xn = pr.xn
    C = pr.C
    lnv = pr.lnv
    lk = pr.lk
    z0 = pr.z0
    dz = pr.dz
    for jj in prange(xn.size):
        j = rows[jj]
        _build_row(pf, mp, xn[j], math.exp(lnv[j]), lk[j], z0, dz, lbx, lbw, er, C,
                   np.int64(j))  # one type


@njit(parallel=True, cache=True)
def _check_kernel(pf, mp, pr, xm, zm, glx, glw, err):
    """Relative error of the interpolated T at (xm[i], zm[i]) against direct quadrature."""
    for i in prange(xm.size):
        x0 = xm[i]
        vinf = math.exp(_plnv(pf, mp, x0))
        st = stencil(pr, x0)
        z = zm[i] - row_value(pr.lk, st)
        v = vinf * one_plus_exp(z)
        z_ext = math.log(mp.v_ext / vinf - 1.0)
        if z >= z_ext:
            T = qk._tail_int(mp.c, v + mp.d, math.inf)
        else:
            T = qk._tail_int(mp.c, mp.v_ext + mp.d, math.inf)
            m = int(math.ceil((z_ext - z) / (0.25 * pr.dz)))
            hw = (z_ext - z) / m
            for q in range(m):
                T += _panel(pf, mp, x0, vinf, z + q * hw, z + (q + 1) * hw, glx, glw)
        err[i] = abs(t_of_z(pr, st, vinf, z) / T - 1.0)


def profile(model, v_lo):
    """The x0-independent state on s = ln v ∈ [ln v_lo, ln v_top] (see :data:`Profile`)."""
    lnu = model.tables.u_range
    s0 = max(math.log(v_lo) - 4 * PROFILE_DS, math.log(lnu[0]) + 1e-13)
    s1 = math.log(lnu[1]) - 1e-13
    n = int(math.ceil((s1 - s0) / PROFILE_DS)) + 1
    ds = (s1 - s0) / (n - 1)
    A = np.empty((n, 4))
    _profile_kernel(model.tab, s0, ds, A)
    return Profile(s0, ds, A)


#: rows end X_END below the trap pressure and the tables' kink (:func:`_kink`), and at the
#: tables' last verified node (:func:`fast_limit`); the primitive serves cases up to its last
#: row, the per-case quadrature those above (up to the trap pressure, and between the kink
#: and the trap pressure). Until 2026-12-07 the rows ended 0.005 below min(trap, kink) and
#: served up to 0.045 below it: with the profile at 0.004 in ln v, ū − ū∞ deep in the
#: exponential approach and t at ū = 1.001 ū∞ were off the per-case quadrature by up to
#: 2.4e-6 there. Two causes, both removed: the profile's cubic cells (t up to 7.6e-7 off
#: 0.002 below the kink of asphalt_024mm at 0.004, 4e-9 at 0.001), and a 4-point stencil
#: straddling the last table node below the trap (1.9e-6 of T at cell centres 0.003 below
#: the trap of asphalt_072mm, where σ̄ falls from 1e-22.5 to 1e-90 in one table interval).
#: Now, on the four embedded tables × (critical junction, EMT), from 0.06 below the top to
#: the last row: t within 1.7e-8 and ū − ū∞ within 2e-8 of the quadrature at
#: t* + (0 … 15) t_relax
X_END = 1e-4


def _kink(model):
    """ln p̄ of the tables' last node with σ̄ > 0: beyond it σ̄^(1/3) is linear to the exact
    percolation pressure, so ln σ̄ has a kink there that no smooth grid may straddle."""
    lnp, n_open = model.tab.lnp, int(model.tab.n_open)
    return float(lnp[n_open - 1]) if n_open < lnp.size else math.inf


def verified_top(model):
    """ln p̄ of the tables' last node whose σ̄ the build verified
    (:func:`fastcontact.tables.build.verified_top`: σ̄ above the tables' σ̄ floor); inf for a
    theory without percolation ("average", verified at every node)."""
    if not math.isfinite(model.x_perc):
        return math.inf
    return _tables_verified_top(model.tables, model.theory)[1]


def fast_limit(model):
    """Largest ln(p0/E*) the primitive serves, its last row (above: per-case quadrature):
    X_END below the trap pressure and the tables' kink, and not beyond the tables' last
    verified node (:func:`verified_top`). With the default trap floor (the tables' σ̄ floor)
    the trap pressure lies in the interval after that node, where σ̄ falls by tens of decades
    (1e-22.5 to 1e-90 on asphalt_072mm): T(x0) is only C² across the node, too little for a
    4-point stencil, so the rows end there and the stencil never straddles it."""
    return min(model.x_trap - X_END, _kink(model) - X_END, verified_top(model), model.x_max)


@njit(parallel=True, cache=True)
def _sigma_samples(tab, xs, out):
    """σ̄ of the tables at ln π = xs (:func:`~._kernels.sigma_kernel` on the threads)."""
    for i in prange(xs.size):
        out[i] = qk.k_sigma_of_lnp(tab, xs[i])


def _x_nodes(model, dxi):
    """x0 nodes uniform in ξ = x0 - ln σ̄(x0) on [x_min, x_hi]."""
    x_hi = fast_limit(model)
    xs = np.linspace(model.x_min, x_hi, 20001)
    sig = np.empty(xs.size)
    _sigma_samples(model.tab, xs, sig)
    xi = np.maximum.accumulate(xs - np.log(sig))
    n = max(int(math.ceil((xi[-1] - xi[0]) / dxi)) + 1, 8)
    xn = np.interp(np.linspace(xi[0], xi[-1], n), xi, xs)
    xn[0], xn[-1] = model.x_min, x_hi
    return np.ascontiguousarray(np.unique(xn))


def build(model, dxi=DXI, z_lo=Z_LO, dz=DZ, points=None, check=True):
    """Build the primitive of ``model`` (a :class:`~fastcontact.squeeze.model.SqueezeModel`).

    ``points``: Gauss–Lobatto points per z panel of the node quadrature (None:
    :func:`node_points` of the model's theory). Returns ``(Primitive, info)``; ``info`` holds
    the grid sizes, build time and the measured maximum relative interpolation error of T at
    cell centres (``max_rel_err_T``).
    """
    t0 = _clock.perf_counter()
    points = node_points(model.theory) if points is None else int(points)
    mp, tab = model.mp, model.tab
    xn = _x_nodes(model, dxi)
    lnv_lo = np.empty(1)
    qk.lnv_of_lnp_kernel(tab, mp, np.array([xn[-1]]), lnv_lo)
    pf = profile(model, math.exp(lnv_lo[0]))
    nx = xn.size
    lnv, lk, lnS, zs = (np.empty(nx) for _ in range(4))
    _rows_kernel(pf, mp, xn, lnv, lk, lnS, zs)
    z_hi = math.log(mp.v_ext / math.exp(lnv_lo[0]) - 1.0) + float(np.max(lk))
    nz = int(math.ceil((z_hi - z_lo) / dz)) + 2
    pr = Primitive(xn, *_index_map(xn), lagrange_denominators(xn), float(z_lo), float(dz), nz,
                   np.empty((nx, nz, 3)), lnv, lnS, zs, lk, float(mp.v_ext), float(mp.c),
                   float(mp.d))
    lbx, lbw = gauss_lobatto(points)
    er = np.exp(0.5 * float(dz) * (1.0 + lbx[1:-1]))
    _build_kernel(pf, mp, pr, lbx, lbw, er, spread_order(nx))
    pr = readonly_fields(pr)  # written once above; every reader takes it read-only
    info = {"nx": int(nx), "nz": int(nz), "dxi": float(dxi), "node_points": points,
            "build_seconds": _clock.perf_counter() - t0}
    if check:
        info.update(measure_error(model, pr, pf))
    return pr, info


def measure_error(model, pr, pf, n_x=64, order=CHECK_ORDER):
    """Max relative error of the interpolated T at cell centres (n_x random x0 cells and the
    last four the fast path serves, × all z cells)."""
    rng = np.random.default_rng(0)
    served = int(np.searchsorted(pr.xn, fast_limit(model), side="right")) - 1
    cells = np.unique(np.concatenate([rng.integers(0, max(served, 1), n_x),  # served cells,
                                      np.arange(max(served - 4, 0), served)]))  # the top 4
    xm = 0.5 * (pr.xn[cells] + pr.xn[cells + 1])
    zc = pr.z0 + (np.arange(pr.nz - 1) + 0.5) * pr.dz
    X, Z = np.meshgrid(xm, zc, indexing="ij")
    err = np.empty(X.size)
    glx, glw = gauss_legendre(order)
    _check_kernel(pf, model.mp, pr, np.ascontiguousarray(X.ravel()),
                  np.ascontiguousarray(Z.ravel()), glx, glw, err)
    return {"max_rel_err_T": float(np.max(err)), "checked_points": int(err.size)}

