"""Numba kernels of the seal engine with a pressure-dependent viscosity (private).

Uniform ring: ``q L = ∫_{p_b}^{p_a} σ0(p0 - p) η0/η(p) dp`` by composite Gauss–Legendre in
ln p_cont (Barus is the p_r = 0 case of the Roelands weight). Hertz O-ring: shooting on
k = 12 η0 q / h³ with RK4 on steps graded towards both zone ends, in the reduced pressure ψ
(Barus) or in p_f itself (Roelands), bracketed secant iteration in k started from the root of
a coarse (25-step) shooting — both laws' O-rings when ``steps`` is given, and the rows whose
default, the base engine's panel collocation in ψ (:mod:`fastcontact.seal._panels`), fails.
The wrapper and the equations: :mod:`fastcontact.seal.viscosity`. ``sc`` is the scalar record of
:func:`fastcontact.seal.viscosity._scalars` (read as ``sc[0].x_lo``).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from ..flow.piezoviscosity import ln_roelands
from ..tables import k_sigma_of_lnp

__all__ = ["TAIL_CUT", "Quad", "UniformRows", "HertzRows", "HertzCase", "RingCells"]

#: the uniform-ring quadrature starts TAIL_CUT below ln(p_cont_min/E*) of the table (integrand ∝ p_cont)
TAIL_CUT = 60.0


class Quad(NamedTuple):
    """The uniform-ring rule (one argument instead of three): Gauss–Legendre nodes ``x`` and
    weights ``w`` on [-1, 1], panel ``width`` in ln p_cont."""

    x: np.ndarray
    w: np.ndarray
    width: float


class UniformRows(NamedTuple):
    """Per-row inputs of :func:`_uniform_kernel` (contiguous float64, one value per ring): p0,
    L, p_a, p_b, E* [SI]; the viscosity law's A and Z (:func:`_ln_eta`)."""

    p0: np.ndarray
    L: np.ndarray
    pa: np.ndarray
    pb: np.ndarray
    E: np.ndarray
    A: np.ndarray
    Z: np.ndarray


class RingCells(NamedTuple):
    """A cumulative table of a flat ring's integral ∫ σ̄ e^x W(x) dx in x = ln(p_cont/E*)
    (:func:`_cells_kernel`), for every ring that shares the weight W:

    * ``run`` = 0 (Barus, one table per β = α E*): W = e^{β(e^x - top)}, ``top`` = e^{x_top};
      q L = E* e^{β top - α(p0 - p_b)} ∫_{x_a}^{x_b} σ̄ e^x W dx (p0 apart);
    * ``run`` = 1 (one table per run of rings sharing E*, p0 - p_b = ``P`` E* and the viscosity
      law ``A``, ``Z``, ``pr`` as in :func:`_ln_eta`: a Δp sweep): W = η0/η(E*(P - e^x));
      q L = E* ∫_{x_a}^{x_b} σ̄ e^x W dx.

    Cells: ``nt`` of width ``wt`` from ``x0`` up to ``xm`` (the ū³ tail below the σ̄ table),
    then cells of at most ``w`` from ``xm``, on a grid of spacing ``w`` cut at the σ̄ table's
    nodes (so that σ̄ is smooth inside every cell); ``cs`` (nc + 1) the cells' bounds,
    ``first`` the cell holding each grid point xm + k w; prefix sums ``pre`` (pre[c] = Σ of
    cells below c) and suffix sums ``suf`` (suf[c] = Σ of cells c and above) of the cells' integrals
    ``cells``; ``leg`` (nc, m): the integrand's Legendre coefficients a_k on each cell (from
    its m Gauss points, u = 2(x - x_c)/w - 1), divided by 2k + 1 for k >= 1; ``ra``, ``rb``
    (m): (2k + 1)/(k + 1) and k/(k + 1); ``ok`` (nc): 1 where they represent the integrand
    (verified at the cell's midpoint), so that a partial cell is a Legendre sum instead of new
    σ̄ evaluations."""

    x0: float
    wt: float
    nt: int
    xm: float
    w: float
    run: int
    top: float
    beta: float
    E: float
    P: float
    A: float
    Z: float
    pr: float
    cs: np.ndarray
    first: np.ndarray
    pre: np.ndarray
    suf: np.ndarray
    cells: np.ndarray
    leg: np.ndarray
    ok: np.ndarray
    ra: np.ndarray
    rb: np.ndarray


class HertzRows(NamedTuple):
    """Per-row inputs of :func:`_hertz_kernel_r` (contiguous float64): E*, p_H [Pa], a [m],
    p_a, p_b [Pa], the Roelands A and Z."""

    E: np.ndarray
    pH: np.ndarray
    a: np.ndarray
    pa: np.ndarray
    pb: np.ndarray
    A: np.ndarray
    Z: np.ndarray


class HertzCase(NamedTuple):
    """One O-ring of the shooting (one argument instead of a dozen; built per case inside the
    kernel, never captured by a prange body): E*, p_H, a, p_a, p_b, ψ_a [SI], Barus α [1/Pa],
    Roelands A, Z, p_r, the sealing zone's first angle θ_s and its span θ_e − θ_s [rad]."""

    E: float
    pH: float
    a: float
    pa: float
    pb: float
    psi_a: float
    alpha: float
    A: float
    Z: float
    pr: float
    th_s: float
    span: float


@njit(cache=True)
def _sigma(tab, sc, x):
    """σ̄ at ln p̄ = x: the tables, or below them the eq. (3) tail with σ̄ ∝ ū³."""
    s = sc[0]
    if x < s.x_lo:
        v = s.u_lo + s.du_lo * (s.x_lo - x)
        return math.exp(s.lnsig_lo) * (v / s.u_lo) ** 3
    if x >= s.x_perc:
        return 0.0
    return k_sigma_of_lnp(tab, x)


@njit(cache=True)
def _ln_eta(p, A, Z, pr):
    """ln(η/η0) at p >= 0 above the outlet: Barus (pr = 0: A = α, ln = α p) or Roelands."""
    if pr == 0.0:
        return A * p
    return ln_roelands(p, A, Z, pr)


@njit(cache=True)
def _x_ends(sc, E, p0, pa, pb):
    """(x_a, x_b): the uniform-ring integral's ends in x = ln(p_cont/E*) (p_cont = p0 - p at
    the inlet and the outlet); the inlet end at most TAIL_CUT below the table's bottom."""
    xb = math.log((p0 - pb) / E)
    if pa >= p0:
        return sc[0].x_lo - TAIL_CUT, xb
    return max(math.log((p0 - pa) / E), sc[0].x_lo - TAIL_CUT), xb


@njit(cache=True)
def _panels(tab, sc, E, p0, pb, A, Z, pr, quad, xa, xb):
    """∫_{xa}^{xb} σ̄ p_c η0/η dx by the composite rule: equal panels no wider than quad.width,
    Gauss–Legendre on each (0 if xb <= xa)."""
    if not xb > xa:
        return 0.0
    glx, glw, width = quad.x, quad.w, quad.width
    m = max(1, int(math.ceil((xb - xa) / width)))
    hw = (xb - xa) / m
    s = 0.0
    for k in range(m):
        mid = xa + (k + 0.5) * hw
        for j in range(glx.size):
            x = mid + 0.5 * hw * glx[j]
            pc = E * math.exp(x)
            s += 0.5 * hw * glw[j] * _sigma(tab, sc, x) * pc * math.exp(
                -_ln_eta(max(p0 - pb - pc, 0.0), A, Z, pr))
    return s


@njit(cache=True)
def _uniform_integral(tab, sc, E, p0, pa, pb, A, Z, pr, quad):
    """∫_{p_b}^{p_a} σ̄(p0 - p) η0/η(p - p_b) dp [Pa], in x = ln((p0 - p)/E*); the viscosity law
    as in :func:`_ln_eta` (Barus: e^{-α(p - p_b)}); ``quad`` the composite rule (:class:`Quad`)."""
    xa, xb = _x_ends(sc, E, p0, pa, pb)
    return _panels(tab, sc, E, p0, pb, A, Z, pr, quad, xa, xb)


@njit(parallel=True, cache=True)
def _uniform_kernel(tab, sc, rows, pr, quad, out):
    """q = (1/L) ∫ σ̄ η0/η dp of each ring (:class:`UniformRows`; pr = 0: Barus with A = α,
    Z unused), every row's integral on its own: the reference of
    :func:`_uniform_sweep_kernel`."""
    for i in prange(rows.p0.size):
        out[i] = _uniform_integral(tab, sc, rows.E[i], rows.p0[i], rows.pa[i], rows.pb[i],
                                   rows.A[i], rows.Z[i], pr, quad) / rows.L[i]


@njit(parallel=True, cache=True)
def _uniform_sweep_kernel(tab, sc, rows, pr, quad, short, starts, out):
    """:func:`_uniform_kernel` for rows sorted into runs that share E*, p0, p_b, A and Z (the
    integrand), each run in ascending p_a; ``starts`` the first row of each chunk of a run
    (and the row count last). A chunk integrates its first row from the outlet end x_b, then
    each next row only over [x_a, previous x_a] (its integral is the previous one plus that
    piece): a Δp sweep costs a panel or two per row instead of the whole range. A piece no
    wider than ``short.width`` takes the short rule ``short`` (fewer Gauss points)."""
    for c in prange(starts.size - 1):
        i0 = starts[c]
        E = rows.E[i0]  # one per statement (parfor lowering and tuple unpacking)
        p0 = rows.p0[i0]
        pb = rows.pb[i0]
        A = rows.A[i0]
        Z = rows.Z[i0]
        acc = 0.0
        x_hi = _x_ends(sc, E, p0, rows.pa[i0], pb)[1]  # the outlet end, shared by the run
        for i in range(i0, starts[c + 1]):
            xa = _x_ends(sc, E, p0, rows.pa[i], pb)[0]
            if xa < x_hi:
                rule = short if x_hi - xa <= short.width else quad
                acc += _panels(tab, sc, E, p0, pb, A, Z, pr, rule, xa, x_hi)
                x_hi = xa
            out[i] = acc / rows.L[i]


@njit(cache=True, inline="always")
def _weight(bc, ex):
    """The weight W of the :class:`RingCells` ``bc`` at e^x = ex."""
    if bc.run == 0:
        return math.exp(bc.beta * (ex - bc.top))
    return math.exp(-_ln_eta(max(bc.P - ex, 0.0) * bc.E, bc.A, bc.Z, bc.pr))


@njit(cache=True, inline="always")
def _ring_gl(tab, sc, bc, quad, a, b):
    """∫_a^b σ̄ e^x W dx, one Gauss–Legendre panel (``quad``'s points)."""
    half = 0.5 * (b - a)
    mid = a + half
    s = 0.0
    for j in range(quad.x.size):
        x = mid + half * quad.x[j]
        ex = math.exp(x)
        s += quad.w[j] * _sigma(tab, sc, x) * ex * _weight(bc, ex)
    return half * s


#: a cell's Legendre series is trusted where it reproduces the integrand at the cell's
#: midpoint to this relative tolerance (the series' error is largest there; ~1e-15 on cells
#: where ln σ̄ is smooth and |d ln f/dx| w <= 0.3)
LEGENDRE_MID_RTOL = 1e-12


@njit(cache=True, inline="always")
def _cell_of(bc, x):
    """(c, start, width) of the cell of :class:`RingCells` ``bc`` holding x (clamped)."""
    cs = bc.cs
    if x < bc.xm:
        c = min(max(int((x - bc.x0) / bc.wt), 0), bc.nt - 1)
        return c, cs[c], cs[c + 1] - cs[c]
    c = bc.first[min(int((x - bc.xm) / bc.w), bc.first.size - 1)]
    while c + 2 < cs.size and cs[c + 1] <= x:  # a node cut between the grid point and x
        c += 1
    return c, cs[c], cs[c + 1] - cs[c]


@njit(parallel=True, cache=True)
def _cells_kernel(tab, sc, bc, quad, lt, pmid):
    """bc.cells[c] = ∫ over cell c of σ̄ e^x W dx (:class:`RingCells`; the rule
    ``quad`` on each cell: the cells are cut at the σ̄ table's nodes), the integrand's Legendre
    coefficients bc.leg[c] from its values at the rule's points (``lt`` (m, m): a_k = Σ_j
    lt[k, j] f_j) and bc.ok[c] (``pmid``: P_k(0), the midpoint check)."""
    m = quad.x.size
    cells = bc.cells
    leg = bc.leg
    ok = bc.ok
    for c in prange(cells.size):
        a = bc.cs[c]
        w = bc.cs[c + 1] - a
        f = np.empty(m)
        s = 0.0
        for j in range(m):
            x = a + 0.5 * w * (1.0 + quad.x[j])
            ex = math.exp(x)
            f[j] = _sigma(tab, sc, x) * ex * _weight(bc, ex)
            s += quad.w[j] * f[j]
        vm = 0.0
        for k in range(m):
            ak = 0.0
            for j in range(m):
                ak += lt[k, j] * f[j]
            leg[c, k] = ak if k == 0 else ak / (2 * k + 1)
            vm += ak * pmid[k]
        cells[c] = 0.5 * w * s
        xm = a + 0.5 * w
        em = math.exp(xm)
        fm = _sigma(tab, sc, xm) * em * _weight(bc, em)
        ok[c] = 1.0 if abs(vm - fm) <= LEGENDRE_MID_RTOL * fm else 0.0


@njit(cache=True, inline="always")
def _leg_partial(bc, c, u):
    """∫_{-1}^{u} Σ_k a_k P_k(v) dv of cell c's Legendre series, a_0 (u + 1) + Σ_{k>=1} a_k
    (P_{k+1}(u) - P_{k-1}(u))/(2k + 1) (bc.leg holds a_k/(2k + 1) for k >= 1, bc.ra, bc.rb the
    recurrence P_{k+1} = ra_k u P_k - rb_k P_{k-1}: no division); times w/2 it is the cell's
    integral up to u."""
    leg = bc.leg
    ra = bc.ra
    rb = bc.rb
    s = leg[c, 0] * (u + 1.0)
    pm = 1.0
    p = u
    for k in range(1, leg.shape[1]):
        pn = ra[k] * u * p - rb[k] * pm
        s += leg[c, k] * (pn - pm)
        pm = p
        p = pn
    return s


@njit(cache=True, inline="always")
def _cells_sum(bc, c0, c1):
    """Σ of cells c0 .. c1 - 1 from the prefix or the suffix sums, whichever difference has
    the smaller terms (less cancellation)."""
    if c1 <= c0:
        return 0.0
    if bc.pre[c1] <= bc.suf[c0]:
        return bc.pre[c1] - bc.pre[c0]
    return bc.suf[c0] - bc.suf[c1]


@njit(cache=True, inline="always")
def _rule(bc, c, short, full):
    """The Gauss rule of a piece in cell c: ``short`` where the cell's Legendre series is
    trusted (a smooth integrand), else ``full`` (next to percolation ln σ̄ bends sharply
    between its nodes: 4 points were off by 1.4e-10 there, 10 by 5e-13)."""
    return short if bc.ok[c] != 0.0 else full


@njit(parallel=True, cache=True)
def _cells_rows(tab, sc, rows, bc, short, full, out):
    """Flat rings (:class:`UniformRows`, all sharing the weight of ``bc``) from the cumulative
    table ``bc`` (:class:`RingCells`): q L = F ∫_{x_a}^{x_b} σ̄ e^x W dx (F = E* e^{β top -
    α(p0 - p_b)} for a Barus table, E* for a run's), the whole cells between the ends from the
    prefix or suffix sums, the two partial cells from their Legendre series where trusted,
    else by Gauss–Legendre (:func:`_rule`; σ̄ is smooth inside a cell; so too a ring inside
    one cell, and one whose end cells hold more than 8 times its integral: there the
    partials' round-off would count)."""
    cells = bc.cells
    for i in prange(rows.p0.size):
        E = rows.E[i]
        p0 = rows.p0[i]
        pb = rows.pb[i]
        xa, xb = _x_ends(sc, E, p0, rows.pa[i], pb)
        if not xb > xa:
            out[i] = 0.0
            continue
        ca, sa, wa = _cell_of(bc, xa)
        cb, sb, wb = _cell_of(bc, xb)
        if ca == cb:
            s = _ring_gl(tab, sc, bc, _rule(bc, ca, short, full), xa, xb)
        else:
            ea = sa + wa
            if bc.ok[ca] != 0.0:
                lo = cells[ca] - 0.5 * wa * _leg_partial(bc, ca, 2.0 * (xa - sa) / wa - 1.0)
            else:
                lo = _ring_gl(tab, sc, bc, full, xa, ea)
            if bc.ok[cb] != 0.0:
                hi = 0.5 * wb * _leg_partial(bc, cb, 2.0 * (xb - sb) / wb - 1.0)
            else:
                hi = _ring_gl(tab, sc, bc, full, sb, xb)
            s = lo + _cells_sum(bc, ca + 1, cb) + hi
            if cells[ca] + cells[cb] > 8.0 * s:
                s = (_ring_gl(tab, sc, bc, _rule(bc, ca, short, full), xa, ea)
                     + _cells_sum(bc, ca + 1, cb)
                     + _ring_gl(tab, sc, bc, _rule(bc, cb, short, full), sb, xb))
        f = E if bc.run != 0 else E * math.exp(bc.beta * bc.top - rows.A[i] * (p0 - pb))
        out[i] = f * s / rows.L[i]


@njit(cache=True)
def _pf(psi, pb, alpha):
    if alpha == 0.0:
        return pb + psi
    return pb - math.log1p(-alpha * psi) / alpha


@njit(cache=True)
def _case(E, pH, a, pa, pb, psi_a, alpha, A, Z, pr):
    """The :class:`HertzCase` of one O-ring: its sealing zone θ_s..θ_e from p_a, p_b and p_H."""
    th_s = math.asin(min(1.0, pa / pH))
    th_e = math.pi - math.asin(min(1.0, pb / pH))
    return HertzCase(E, pH, a, pa, pb, psi_a, alpha, A, Z, pr, th_s, th_e - th_s)


@njit(cache=True, inline="always")
def _pocket_sigma(tab, sc, pc, E):
    """σ̄ at the contact pressure pc [Pa]; -inf in an open pocket (pc <= 0)."""
    if pc <= 0.0:
        return -math.inf
    return _sigma(tab, sc, math.log(pc / E))


@njit(cache=True, inline="always")
def _rhs(tab, sc, cs, th, psi, k):
    """dψ/dθ = -k a sin θ / σ̄((p0(θ) - p_f(ψ))/E*); 0 in an open pocket (p_cont <= 0)."""
    s = _pocket_sigma(tab, sc, cs.pH * math.sin(th) - _pf(psi, cs.pb, cs.alpha), cs.E)
    if s <= 0.0:
        return 0.0 if s == -math.inf else -1e300
    return -k * cs.a * math.sin(th) / s


@njit(cache=True)
def _shoot(tab, sc, cs, k, n):
    """ψ at the outlet end θ_e for flux parameter k = 12η0 q/h³ [Pa/m].

    RK4 with n steps in t ∈ [0, 1], θ = θ_s + (θ_e - θ_s)(3t² - 2t³): the steps shrink
    quadratically at both zone ends, where p_cont → 0 and σ0 grows like ln³(1/p_cont).
    """
    h = 1.0 / n
    psi_a = cs.psi_a
    psi = psi_a
    for i in range(n):
        t0 = i * h
        k1 = _rhs_t(tab, sc, cs, t0, psi, k)
        k2 = _rhs_t(tab, sc, cs, t0 + 0.5 * h, psi + 0.5 * h * k1, k)
        k3 = _rhs_t(tab, sc, cs, t0 + 0.5 * h, psi + 0.5 * h * k2, k)
        k4 = _rhs_t(tab, sc, cs, t0 + h, psi + h * k3, k)
        psi += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
        if psi < -10.0 * psi_a or psi != psi:
            return -10.0 * psi_a
    return psi


@njit(cache=True, inline="always")
def _rhs_t(tab, sc, cs, t, psi, k):
    span = cs.span
    th = cs.th_s + span * t * t * (3.0 - 2.0 * t)
    return _rhs(tab, sc, cs, th, psi, k) * span * 6.0 * t * (1.0 - t)


@njit(cache=True)
def _mismatch(tab, sc, cs, roelands, y, n):
    """Outlet value of the shooting for k = e^y: ψ (Barus, from ψ_a) or p_f − p_b (Roelands,
    from p_a); 0 is the outlet condition."""
    if roelands:
        return _shoot_r(tab, sc, cs, math.exp(y), n)
    return _shoot(tab, sc, cs, math.exp(y), n)


#: nodes of the start estimate of :func:`_solve_k` (midpoints in the graded t of the shooting)
START_NODES = 24


@njit(cache=True)
def _k_start(tab, sc, cs, roelands):
    """First k of the shooting: the pressure scale over the resistance along a straight-line
    guess of the solution (Barus: ∫ a sin θ/σ̄ dθ with ψ falling linearly in t from ψ_a to 0;
    Roelands: ∫ a sin θ (η/η0)/σ̄ dθ with p_f falling linearly from p_a to p_b), midpoint rule
    on the graded t of :func:`_shoot` (START_NODES nodes). Falls back to the resistance at the
    mid pressure where the guess meets an open pocket or percolation."""
    pH, pa, pb = cs.pH, cs.pa, cs.pb
    scale = pa - pb if roelands else cs.psi_a
    span = cs.span
    w = 0.0
    for m in range(START_NODES):
        t = (m + 0.5) / START_NODES
        th = cs.th_s + span * t * t * (3.0 - 2.0 * t)
        if roelands:   # p_f linear in t; dp_f/dθ carries η/η0
            p = pa + (pb - pa) * t
            visc = math.exp(_ln_eta(p - pb, cs.A, cs.Z, cs.pr))
        else:          # ψ linear in t; dψ/dθ carries no viscosity
            p = _pf(scale * (1.0 - t), pb, cs.alpha)
            visc = 1.0
        sg = _pocket_sigma(tab, sc, pH * math.sin(th) - p, cs.E)
        if not (sg > 0.0):
            w = -1.0
            break
        w += cs.a * math.sin(th) * visc / sg * span * 6.0 * t * (1.0 - t) / START_NODES
    if not (w > 0.0 and w < math.inf):
        smid = _sigma(tab, sc, math.log(max(pH - 0.5 * (pa + pb), 1e-300) / cs.E))
        return scale * max(smid, 1e-300) / (2.0 * cs.a)
    return scale / w


#: RK4 steps of the coarse shooting that starts the fine one in :func:`_solve_k`
COARSE_STEPS = 25


@njit(cache=True)
def _secant(tab, sc, cs, roelands, n, k, slope, tol):
    """(k, converged, slope) of the shooting with n steps: the root of the outlet value f(k)
    (:func:`_mismatch`) from k; ``slope`` an estimate of f'(k) for the first step (< 0, or NaN:
    none, the chord through (0, f(0)) instead), the slope of the last two points returned.

    f falls with k from f(0) = the pressure scale (ψ_a for Barus, p_a − p_b for Roelands: no
    flux, no drop); a k far above the root makes the shot run away (f = −10 × scale,
    "clamped"). Secant steps through the last two unclamped points inside a bracket
    [k_lo, k_hi] with f(k_lo) > 0 > f(k_hi) that every shot narrows; a step leaving the
    bracket is replaced by doubling k (no upper end yet) or by bisection in ln k. Converged
    when |f| <= tol × scale or a step changes k by <= tol × k."""
    scale = cs.pa - cs.pb if roelands else cs.psi_a
    klo, khi = 0.0, math.inf
    k1, f1 = 0.0, scale                       # the last two unclamped points
    k2, f2 = math.nan, math.nan
    first = slope < 0.0
    for _ in range(200):
        f = _mismatch(tab, sc, cs, roelands, math.log(k), n)
        if not (f == f):
            return math.nan, False, math.nan
        if f > 0.0:
            klo = k
        else:
            khi = k
        if f > -9.999999 * scale:             # not clamped: a point of the secant
            k2, f2 = k1, f1
            k1, f1 = k, f
        if first:                             # Newton with the given slope
            kn = k - f / slope
            first = False
        else:
            kn = k1 - f1 * (k1 - k2) / (f1 - f2) if f1 != f2 else math.nan
        if abs(f) <= tol * scale:
            return k, True, (f1 - f2) / (k1 - k2)
        if not (klo < kn < khi):
            if khi == math.inf:
                kn = 2.0 * k
            elif klo == 0.0:
                kn = 0.5 * khi
            else:
                kn = math.sqrt(klo * khi)
        if abs(kn - k) <= tol * k:
            return kn, True, (f1 - f2) / (k1 - k2)
        k = kn
    return k, False, math.nan


@njit(cache=True)
def _solve_k(tab, sc, cs, roelands, n, k_guess, slope_guess):
    """(k, converged, slope) of one Hertz case ``cs`` (:class:`HertzCase`), k = 12 η0 q / h³
    [Pa/m], and the outlet value's slope df/dk at the root.

    The root of the n-step shooting (:func:`_secant`, to 1e-13), started at the root of the
    same shooting with COARSE_STEPS steps (from :func:`_k_start`, to 1e-10) and that root's
    slope: the coarse solve costs about one fine shot, and the fine one then takes ~3–4 shots
    instead of ~10 from the straight-line start (strong contact feedback makes f(k) concave
    and the first steps overshoot into runaway shots). A finite ``k_guess`` > 0 with
    ``slope_guess`` < 0 (the root and slope of the same case with fewer steps) replaces the
    coarse solve: one Newton step from there, then the secant."""
    if k_guess > 0.0 and k_guess < math.inf and slope_guess < 0.0:
        return _secant(tab, sc, cs, roelands, n, k_guess, slope_guess, 1e-13)
    k0 = _k_start(tab, sc, cs, roelands)
    if n > 2 * COARSE_STEPS:
        kc, okc, slope = _secant(tab, sc, cs, roelands, COARSE_STEPS, k0, math.nan, 1e-10)
        if okc and kc > 0.0 and kc < math.inf:
            k0 = kc
        else:
            slope = math.nan
    else:
        slope = math.nan
    return _secant(tab, sc, cs, roelands, n, k0, slope, 1e-13)


@njit(cache=True)
def _hertz_case(tab, sc, E, pH, a, pa, pb, alpha, n, k_guess, slope_guess):
    """(k, converged, slope) for one Hertz case with a Barus fluid; k = 12 η0 q / h³ [Pa/m]
    (:func:`_solve_k`)."""
    psi_a = pa - pb if alpha == 0.0 else -math.expm1(-alpha * (pa - pb)) / alpha
    return _solve_k(tab, sc, _case(E, pH, a, pa, pb, psi_a, alpha, 0.0, 0.0, 0.0), False, n,
                    k_guess, slope_guess)


@njit(parallel=True, cache=True)
def _hertz_kernel(tab, sc, E, pH, a, pa, pb, alpha, n, k_guess, slope_guess, k, ok, slope):
    """(k, converged, slope) of each O-ring with a Barus fluid by n-step shooting, started
    from (k_guess, slope_guess) where they are usable (:func:`_solve_k`)."""
    for i in prange(E.size):
        k[i], ok[i], slope[i] = _hertz_case(tab, sc, E[i], pH[i], a[i], pa[i], pb[i], alpha[i],
                                            n, k_guess[i], slope_guess[i])


# =========================================================================== Roelands
@njit(cache=True, inline="always")
def _rhs_r(tab, sc, cs, t, p, k):
    """dp_f/dt = -k a sin θ (η/η0)/σ̄(p0(θ) - p_f) dθ/dt; 0 in an open pocket."""
    span = cs.span
    th = cs.th_s + span * t * t * (3.0 - 2.0 * t)
    s = _pocket_sigma(tab, sc, cs.pH * math.sin(th) - p, cs.E)
    if s <= 0.0:
        return 0.0 if s == -math.inf else -1e300
    lv = ln_roelands(max(p - cs.pb, 0.0), cs.A, cs.Z, cs.pr)
    return -k * cs.a * math.sin(th) * math.exp(lv) / s * span * 6.0 * t * (1.0 - t)


@njit(cache=True)
def _shoot_r(tab, sc, cs, k, n):
    """p_f - p_b at the outlet end θ_e for k = 12 η0 q / h³ (RK4 on the graded t of _shoot)."""
    h = 1.0 / n
    pa, pb = cs.pa, cs.pb
    p = pa
    floor = pb - 10.0 * (pa - pb)
    for i in range(n):
        t0 = i * h
        k1 = _rhs_r(tab, sc, cs, t0, p, k)
        k2 = _rhs_r(tab, sc, cs, t0 + 0.5 * h, p + 0.5 * h * k1, k)
        k3 = _rhs_r(tab, sc, cs, t0 + 0.5 * h, p + 0.5 * h * k2, k)
        k4 = _rhs_r(tab, sc, cs, t0 + h, p + h * k3, k)
        p += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
        if p < floor or p != p:
            return floor - pb
    return p - pb


@njit(cache=True)
def _hertz_case_r(tab, sc, E, pH, a, pa, pb, A, Z, pr, n, k_guess, slope_guess):
    """(k, converged, slope) of one Hertz case with a Roelands fluid (:func:`_solve_k`)."""
    return _solve_k(tab, sc, _case(E, pH, a, pa, pb, 0.0, 0.0, A, Z, pr), True, n, k_guess,
                    slope_guess)


@njit(parallel=True, cache=True)
def _hertz_kernel_r(tab, sc, rows, pr, n, k_guess, slope_guess, k, ok, slope):
    """(k, converged, slope) of each O-ring with a Roelands fluid (:class:`HertzRows`),
    started from (k_guess, slope_guess) where they are usable (:func:`_solve_k`)."""
    for i in prange(rows.E.size):
        k[i], ok[i], slope[i] = _hertz_case_r(tab, sc, rows.E[i], rows.pH[i], rows.a[i],
                                              rows.pa[i], rows.pb[i], rows.A[i], rows.Z[i], pr,
                                              n, k_guess[i], slope_guess[i])
