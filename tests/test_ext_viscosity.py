"""Issue 14.2: pressure-dependent (Barus) viscosity in squeeze-out and seals.

References: ``tests/reference/ext_reynolds.py`` integrates the Reynolds equation with η(p)
directly (scipy solve_ivp / solve_bvp / brentq / quad), without the reduced-pressure ψ
reduction the package uses; α = 0 must reproduce the base engines exactly.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_reynolds import (
    barus,
    hertz_shoot,
    radial_mean_pressure,
    seal_bvp,
    squeeze_time,
)

import fastcontact as fc
from fastcontact.seal import seal_leak
from fastcontact.seal.viscosity import seal_leak_piezo
from fastcontact.squeeze import squeeze_out
from fastcontact.squeeze.viscosity import (
    barus_mean_pressure,
    barus_rate_factor,
    squeeze_out_piezo,
)

E_STAR = 1e7
ETA = 1e-3
L_Y = 0.1


@pytest.fixture(scope="module")
def tables():
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    return fc.precompute(psd, theories=("average", "critical_junction", "emt"))


@pytest.fixture(autouse=True)
def _no_kept_beta_tables():
    """Every test starts without the β tables earlier calls kept (which path a batch takes
    must not depend on the order the tests run in)."""
    import fastcontact.seal.viscosity as sv

    sv._BETA_TABLES.clear()


def _sigma(tables, theory):
    plo = tables.p_range[0] * E_STAR
    return lambda pc: tables.conductivity(np.maximum(pc, plo * (1 + 1e-7)), E_STAR, ETA, theory)


# --------------------------------------------------------------------------- closed forms
@pytest.mark.parametrize("alpha,K", [(1e-9, 1e4), (1e-9, 1e6), (1e-8, 3e7), (1e-8, 1.9e8),
                                     (3e-8, 6.6e7), (3e-8, 1e3)])
def test_mean_pressure_matches_radial_reynolds(alpha, K):
    ref = radial_mean_pressure(K, barus(alpha))
    assert abs(barus_mean_pressure(K / 2, alpha) / ref - 1) < 1e-9


def test_mean_pressure_limits():
    assert barus_mean_pressure(2e5, 0.0) == 1e5
    # α → 0 continuously (series branch vs the exact branch)
    assert abs(barus_mean_pressure(2e5, 1e-12) / 1e5 - 1) < 1e-6
    # b → 1: p̄_f → 1/α; beyond: NaN (no solution)
    assert abs(barus_mean_pressure(1e8 * (1 - 1e-12), 1e-8) * 1e-8 - 1) < 1e-9
    assert np.isnan(barus_mean_pressure(1.01e8, 1e-8))


def test_rate_factor_limits_and_monotone():
    a = np.linspace(0, 0.999999, 2001)
    g = barus_rate_factor(a)
    assert g[0] == 1.0
    assert np.all(np.diff(g) < 0)
    assert abs(g[-1] - 0.5) < 1e-3
    # g(a) = Φ⁻¹(a)/(2a) with the closed-form Φ: check by composition
    b = 2 * a[1:] * g[1:]
    phi = 1 + (1 - b) * np.log1p(-b) / b
    assert np.max(np.abs(phi - a[1:])) < 1e-12
    small = np.array([1e-7, 9.9e-6, 1.01e-5])     # series branch and its neighbour agree
    assert np.allclose(barus_rate_factor(small), 1 - 2 * small / 3 + 2 * small ** 2 / 9,
                       rtol=1e-13)
    assert np.isnan(barus_rate_factor(1.0))


def test_rate_factor_against_mpmath():
    """g(a) (tabulated inverse) against an independent 40-digit solve of c/expm1(c) = 1 - a,
    g = (1 - e^-c)/(2a): within 1e-12 relative from the series' edge to a = 1 - 1e-15."""
    import mpmath as mp

    mp.mp.dps = 40

    def g_mp(a):
        a = mp.mpf(a)
        c = mp.findroot(lambda c: c / mp.expm1(c) - (1 - a),
                        2 * a if a < 0.5 else -mp.log(1 - a))
        return -mp.expm1(-c) / (2 * a)

    rng = np.random.default_rng(3)
    a = np.concatenate([np.geomspace(1.0001e-5, 0.5, 40), 1 - np.geomspace(0.5, 1e-15, 30),
                        rng.uniform(0.0, 1.0, 30)])
    g = barus_rate_factor(a)
    err = max(abs(float(gi / g_mp(x) - 1)) for x, gi in zip(a, g))
    assert err < 1e-12


# --------------------------------------------------------------------------- squeeze-out
@pytest.mark.parametrize("theory", ["average", "emt"])
def test_squeeze_alpha_zero_is_base(tables, theory):
    kw = dict(p0=np.array([2e4, 1e5, 4e5]), E_star=E_STAR, R=0.01, eta=ETA, theory=theory,
              ratios=(1.1, 1.001))
    a = squeeze_out(tables, method="quad", **kw)
    b = squeeze_out_piezo(tables, alpha_pv=0.0, method="quad", **kw)
    for c in ("u_start", "u_inf", "t_star", "t_ratio_1.1", "t_ratio_1.001"):
        np.testing.assert_allclose(b[c], a[c], rtol=1e-12)
    # the fast path at α = 0: the base primitive's numbers (its start and ū∞ exactly; the
    # times from t_of_z at both ends instead of the row tables: within the primitive's error)
    a = squeeze_out(tables, method="fast", **kw)
    b = squeeze_out_piezo(tables, alpha_pv=0.0, method="fast", **kw)
    assert b.attrs["method"] == "fast" and set(b.status) == {"ok"}
    for c in ("u_start", "u_inf"):
        np.testing.assert_array_equal(b[c], a[c])
    for c in ("t_star", "t_ratio_1.1", "t_ratio_1.001"):
        np.testing.assert_allclose(b[c], a[c], rtol=1e-8)


@pytest.mark.parametrize("p0,alpha", [(1e5, 3e-6), (4e5, 2e-6)])
def test_squeeze_against_reynolds_reference(tables, p0, alpha):
    df = squeeze_out_piezo(tables, p0=p0, E_star=E_STAR, R=0.01, eta=ETA, alpha_pv=alpha,
                           theory="emt", ratios=(1.1,))
    r = df.iloc[0]
    assert 0.5 < r.rate_factor_start < 0.9          # the viscosity really is pressure dependent
    ref = squeeze_time(tables, "emt", p0, E_STAR, 0.01, ETA, alpha, r.u_start, 1.1 * r.u_inf,
                       r.u_inf)
    assert abs(r["t_ratio_1.1"] / ref - 1) < 1e-7
    base = squeeze_out_piezo(tables, p0=p0, E_star=E_STAR, R=0.01, eta=ETA, alpha_pv=0.0,
                             theory="emt", ratios=(1.1,))
    assert 1.0 < r["t_ratio_1.1"] / base["t_ratio_1.1"][0] < 2.0     # g ∈ (1/2, 1]


def test_squeeze_piezo_limit_flagged(tables):
    df = squeeze_out_piezo(tables, p0=4e5, E_star=E_STAR, R=0.01, eta=ETA,
                           alpha_pv=[1e-6, 3e-6], theory="average")
    assert list(df.piezo_limit) == [False, True]
    assert np.isnan(df.t_star[1]) and np.isfinite(df.t_star[0])


def test_squeeze_start_below_equilibrium_flagged(tables):
    """A given start at or below ū∞ is one row's status (NaN times), not an error for the
    batch (issue 11.6); the other rows are what they are alone, and the flagged row's
    ū∞ is still reported."""
    kw = dict(E_star=E_STAR, R=0.01, eta=ETA, alpha_pv=2e-6, theory="emt", ratios=(1.1,),
              du=(1e-7,))
    good = squeeze_out_piezo(tables, p0=np.array([1e5, 4e5]), **kw)
    u_inf = good.u_inf.to_numpy()
    starts = np.array([3.0 * u_inf[0], u_inf[1], 0.5 * u_inf[1]])
    df = squeeze_out_piezo(tables, p0=np.array([1e5, 4e5, 4e5]), u_start=starts, **kw)
    assert list(df.status) == ["ok", "start_below_equilibrium", "start_below_equilibrium"]
    for c in ("t_star", "t_ratio_1.1", "t_du_1e-07", "rate_factor_start"):
        assert np.all(np.isnan(df[c][1:]))
    assert np.array_equal(df.u_inf[1:], [u_inf[1], u_inf[1]])
    alone = squeeze_out_piezo(tables, p0=1e5, u_start=starts[0], **kw)
    for c in ("u_inf", "t_star", "t_ratio_1.1", "t_du_1e-07", "rate_factor_start"):
        assert df[c][0] == alone[c][0]
    ref = squeeze_time(tables, "emt", 1e5, E_STAR, 0.01, ETA, 2e-6, starts[0],
                       1.1 * u_inf[0], u_inf[0])
    assert abs(df["t_ratio_1.1"][0] / ref - 1) < 1e-7


def test_squeeze_bad_alpha(tables):
    with pytest.raises(ValueError, match="alpha_pv"):
        squeeze_out_piezo(tables, p0=1e5, E_star=E_STAR, R=0.01, eta=ETA, alpha_pv=-1e-8)


# --------------------------------------------------------------------------- seals
@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_seal_uniform(tables, theory):
    p0, L = 5e4, 5e-3
    dp = np.array([1e3, 2e4, 4.5e4])
    base = seal_leak(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA, theory=theory)
    zero = seal_leak_piezo(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                           alpha_pv=0.0, theory=theory)
    np.testing.assert_allclose(zero.Q, base.Q, rtol=1e-9)
    if theory == "critical_junction":                   # σ ∝ α_cj³ carried exactly
        b54 = seal_leak(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                        theory=theory, alpha_cj=0.54)
        z54 = seal_leak_piezo(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                              alpha_pv=0.0, theory=theory, alpha_cj=0.54)
        np.testing.assert_allclose(z54.Q, b54.Q, rtol=1e-9)
    for d, al in [(2e4, 3e-5), (4.5e4, 3e-5)]:
        q, _ = seal_bvp(_sigma(tables, theory), lambda x: p0 + 0 * x, 0.0, L, d, 0.0, al)
        got = seal_leak_piezo(tables, p0=p0, dp=d, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                              alpha_pv=al, theory=theory).Q[0]
        assert abs(got / (q * L_Y) - 1) < 1e-8


@pytest.mark.parametrize("law", ["barus", "roelands"])
def test_seal_uniform_sweep_matches_per_row(tables, law):
    """A batch of flat rings (runs of shared p0, p_b, E*, α, each a Δp sweep, plus rows of
    their own, shuffled) equals every row's integral on its own (the per-row kernel, the
    sweep's reference, with panels 10x narrower and 16 Gauss points) to 5e-11, as the
    per-row default rule (GL 10, panels 0.5) does (measured 1.4e-11 and 2.2e-11), and a few
    rows the separate BVP reference to 1e-8."""
    from fastcontact.kernels.quadrature import gauss_legendre
    from fastcontact.seal._piezo_kernels import Quad, _uniform_kernel
    from fastcontact.seal.viscosity import SWEEP_CHUNK

    rng = np.random.default_rng(3)
    runs = [(5e4, 0.0, 3e-5, 700), (5e4, 1e3, 3e-5, 300), (3e4, 0.0, 1e-5, 40)]
    p0, pb, al = [], [], []
    for a, b, c, m in runs:
        p0 += [a] * m
        pb += [b] * m
        al += [c] * m
    m = 25  # rows of their own
    p0 += list(rng.uniform(2e4, 6e4, m))
    pb += list(rng.uniform(0.0, 1e3, m))
    al += list(rng.uniform(1e-6, 4e-5, m))
    p0, pb, al = np.array(p0), np.array(pb), np.array(al)
    dp = (p0 - pb) * rng.uniform(1e-6, 0.999, p0.size)
    dp[:5] = 0.999 * (p0[:5] - pb[:5])  # ties and the widest rows of the first run
    perm = rng.permutation(p0.size)
    p0, pb, al, dp = p0[perm], pb[perm], al[perm], dp[perm]
    assert 700 > SWEEP_CHUNK  # the first run spans several chunks
    kw = dict(p0=p0, dp=dp, p_b=pb, L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=al,
              theory="emt", viscosity=law)
    if law == "roelands":
        kw["roelands_z"] = 0.6
    got = seal_leak_piezo(tables, **kw)
    assert (got.status == "ok").all()
    # the reference: the per-row kernel on the same rows and the same law
    import fastcontact.seal.viscosity as sv

    captured = {}
    real = sv._uniform_sweep_kernel

    def spy(tab, sc, rows, pr, quad, short, starts, out):
        captured.update(tab=tab, sc=sc, rows=rows, pr=pr, quad=quad, starts=starts)
        real(tab, sc, rows, pr, quad, short, starts, out)
        captured["out"] = out.copy()

    sv._uniform_sweep_kernel = spy
    try:
        seal_leak_piezo(tables, **kw)
    finally:
        sv._uniform_sweep_kernel = real
    c = captured
    assert c["starts"].size - 1 >= 3 + m  # runs, their chunks and the single rows
    ref = np.empty(c["rows"].p0.size)
    x, w = gauss_legendre(16)
    _uniform_kernel(c["tab"], c["sc"], c["rows"], c["pr"], Quad(x, w, 0.1 * c["quad"].width),
                    ref)
    per_row = np.empty_like(ref)
    _uniform_kernel(c["tab"], c["sc"], c["rows"], c["pr"], c["quad"], per_row)
    err_sweep = np.max(np.abs(c["out"] / ref - 1))
    err_row = np.max(np.abs(per_row / ref - 1))
    assert err_sweep < 5e-11 and err_row < 5e-11, (err_sweep, err_row)  # measured 1.4, 2.2e-11
    # rows with an integrand of their own, alone in a batch (no run found: no sort), are
    # the same numbers bit for bit
    own = np.flatnonzero(perm >= p0.size - m)
    alone = seal_leak_piezo(tables, **dict(kw, p0=p0[own], dp=dp[own], p_b=pb[own],
                                           alpha_pv=al[own]))
    np.testing.assert_array_equal(alone.Q.to_numpy(), got.Q.to_numpy()[own])
    if law == "barus":
        p = 5e4
        for i in np.flatnonzero((p0 == p) & (pb == 0.0))[:3]:
            q, _ = seal_bvp(_sigma(tables, "emt"), lambda xx: p + 0 * xx, 0.0, 5e-3, dp[i],
                            0.0, 3e-5)
            assert abs(got.Q[i] / (q * L_Y) - 1) < 1e-8


def _table_calls(tables, kw):
    """(seal_leak_piezo(tables, **kw), the calls it made of the cumulative-table kernel: each
    a dict of its table record, scalars, rows, table and output)."""
    import fastcontact.seal.viscosity as sv

    calls = []
    real = sv._cells_rows

    def spy(tab, sc, rows, bc, short, full, out):
        real(tab, sc, rows, bc, short, full, out)
        calls.append(dict(tab=tab, sc=sc, rows=rows, out=out.copy(), bc=bc))

    sv._cells_rows = spy
    try:
        return seal_leak_piezo(tables, **kw), calls
    finally:
        sv._cells_rows = real


@pytest.mark.parametrize("theory", ["emt", "critical_junction"])
def test_seal_barus_cells_match_per_row(tables, theory):
    """Barus flat rings of distinct p0 that share α E* take the cumulative table (whole cells
    from prefix/suffix sums, the two partial cells from the cell's Legendre series, or by
    Gauss points where a σ̄ node lies inside the cell): equal to every row's own integral
    with 10x narrower panels and 16 Gauss points to 5e-11 (measured 2.1e-11 next to
    percolation, ~1e-12 elsewhere), including Δp within one cell, inlets at the tail cut,
    rings next to percolation and rows of a rarer α (the per-row path); a long Δp sweep takes
    the table too; a few rows equal the separate BVP reference to 1e-8; a group whose weight
    e^{α p_cont} would span more than e^200 keeps the per-row path."""
    from fastcontact.kernels.quadrature import gauss_legendre
    from fastcontact.kernels.readonly import readonly_fields
    from fastcontact.seal._piezo_kernels import Quad, UniformRows, _uniform_kernel
    import fastcontact.seal.viscosity as sv

    rng = np.random.default_rng(7)
    n = sv.BARUS_TABLE_ROWS + 500
    p_perc = float(tables.info["percolation_p_over_E"][theory]) * E_STAR
    p0 = np.exp(rng.uniform(math.log(2e3), math.log(0.999 * p_perc), n))
    pb = rng.uniform(0.0, 1e3, n) * (p0 > 1e4)
    frac = np.where(rng.random(n) < 0.3, 10 ** rng.uniform(-9, -4, n), rng.uniform(1e-3, 1.0, n))
    dp = (p0 - pb) * frac
    dp[:40] = (p0[:40] - pb[:40]) * (1 - 1e-12)  # inlet contact pressure near 0: the tail cut
    al = np.full(n, 2e-6)
    al[-300:] = rng.uniform(1e-6, 4e-6, 300)  # rows of their own α: the per-row path
    kw = dict(p0=p0, dp=dp, p_b=pb, L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=al,
              theory=theory)
    got, calls = _table_calls(tables, kw)
    # rows whose outlet end reaches the tables' unverified σ̄ next to percolation by enough to
    # matter are "near_percolation", as the constant-viscosity ring flags them (Q = NaN)
    base = fc.seal_leak(tables, **{k: v for k, v in kw.items() if k != "alpha_pv"})
    near = base.status.astype(str).to_numpy() == "near_percolation"
    assert np.array_equal(got.status.astype(str).to_numpy() == "near_percolation", near)
    assert (got.status[~near] == "ok").all() and np.isnan(got.Q[near]).all()
    assert len(calls) == 1 and calls[0]["rows"].p0.size >= n - 300  # the shared α's rows
    c = calls[0]
    assert c["bc"].ok.mean() > 0.8  # most partial cells are Legendre sums
    x, w = gauss_legendre(16)
    ref = np.empty(c["out"].size)
    _uniform_kernel(c["tab"], c["sc"], c["rows"], 0.0, Quad(x, w, 0.05), ref)
    assert np.all(ref > 0)
    err = np.max(np.abs(c["out"] / ref - 1))
    assert err < 5e-11, err
    # a Δp sweep of one ring long enough for the table (every 97th row checked)
    m = sv.SWEEP_TABLE_ROWS
    p_s = 0.5 * p_perc
    dps = p_s * np.sort(np.concatenate([10 ** rng.uniform(-9, -3, m // 4),
                                        rng.uniform(1e-3, 0.999, m - m // 4)]))
    sweep, calls = _table_calls(tables, dict(kw, p0=p_s, dp=dps, p_b=0.0, alpha_pv=2e-6))
    assert len(calls) == 1 and calls[0]["rows"].p0.size == m
    pick = np.arange(0, m, 97)
    rows_s = readonly_fields(UniformRows(*(a[pick] for a in calls[0]["rows"])))  # as passed
    ref_s = np.empty(pick.size)
    _uniform_kernel(c["tab"], c["sc"], rows_s, 0.0, Quad(x, w, 0.05), ref_s)
    err_s = np.max(np.abs(calls[0]["out"][pick] / ref_s - 1))
    assert err_s < 5e-11, err_s
    assert np.all(np.diff(sweep.Q.to_numpy()) > 0)  # Q rises with Δp
    # the whole batch (table rows and per-row rows) against the same reference, through Q
    # (every row back in its place); the per-row default rule (panels 0.5 wide, not split at
    # the σ̄ table's nodes) is off by up to ~2e-8 next to percolation (measured 1.9e-8)
    sub = readonly_fields(UniformRows(*(np.ascontiguousarray(a, dtype=np.float64) for a in (
        p0, np.full(n, 5e-3), pb + dp, pb, np.full(n, E_STAR), al, np.zeros(n)))))
    ref_all = np.empty(n)
    _uniform_kernel(c["tab"], c["sc"], sub, 0.0, Quad(x, w, 0.05), ref_all)
    q_ref = L_Y * ref_all * float(tables.h_rms) ** 3 / (12.0 * ETA)
    np.testing.assert_allclose(got.Q.to_numpy()[~near], q_ref[~near], rtol=5e-8, atol=0)
    for i in np.flatnonzero((frac > 0.1) & (p0 < 0.3 * p_perc))[40:43]:  # separate BVP
        p = p0[i]
        q, _ = seal_bvp(_sigma(tables, theory), lambda xx: p + 0 * xx, 0.0, 5e-3, pb[i] + dp[i],
                        pb[i], al[i])
        assert abs(got.Q[i] / (q * L_Y) - 1) < 1e-8
    # weights beyond e^200 over the table: the per-row path, same numbers
    got_big, calls = _table_calls(tables, dict(kw, alpha_pv=np.full(n, 1e-4)))
    # (with Q lowered by the weight, the unverified tail's bound matters on more rows: a
    # superset of the constant-viscosity ring's "near_percolation" rows)
    st_big = got_big.status.astype(str).to_numpy()
    assert not calls and set(st_big) <= {"ok", "near_percolation"}
    assert np.all(st_big[near] == "near_percolation") and np.all(got_big.Q[st_big == "ok"] > 0)


def test_seal_barus_tables_kept_across_calls(tables, monkeypatch):
    """A β table built by one call serves later calls sharing α E* (same theory and rule) with
    any number of rows: a short call (no table of its own) reads it, its rings equal to the
    per-row reference (10x narrower panels, 16 Gauss points) to 5e-11 and to the separate BVP
    to 1e-8; another theory or rule builds its own; at most BETA_MEMO are kept (the oldest
    dropped); they go with their Tables object."""
    import gc

    from fastcontact.kernels.quadrature import gauss_legendre
    from fastcontact.seal._piezo_kernels import Quad, _uniform_kernel
    import fastcontact.seal.viscosity as sv

    builds = []
    real = sv._ring_cells

    def counted(*args, **kwargs):
        builds.append(args[4:])
        return real(*args, **kwargs)

    monkeypatch.setattr(sv, "_ring_cells", counted)
    rng = np.random.default_rng(11)
    n = sv.BARUS_TABLE_ROWS + 10
    p0 = rng.uniform(2e4, 6e4, n)
    kw = dict(p0=p0, dp=0.5 * p0, L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=3e-5,
              theory="emt")
    seal_leak_piezo(tables, **kw)
    assert len(builds) == 1
    # a short Δp sweep of one ring: alone it would take the sweep kernel, now the kept table
    dps = np.linspace(1e3, 4.5e4, 40)
    short = dict(kw, p0=5e4, dp=dps)
    got, calls = _table_calls(tables, short)
    assert len(builds) == 1 and len(calls) == 1 and calls[0]["rows"].p0.size == dps.size
    x, w = gauss_legendre(16)
    ref = np.empty(dps.size)
    c = calls[0]
    _uniform_kernel(c["tab"], c["sc"], c["rows"], 0.0, Quad(x, w, 0.05), ref)
    err = np.max(np.abs(c["out"] / ref - 1))
    assert err < 5e-11, err
    for i in (5, 30):
        q, _ = seal_bvp(_sigma(tables, "emt"), lambda xx: 5e4 + 0 * xx, 0.0, 5e-3, dps[i], 0.0,
                        3e-5)
        assert abs(got.Q[i] / (q * L_Y) - 1) < 1e-8
    # the same short sweep with no table kept: the sweep kernel, the same Q to 5e-11
    sv._BETA_TABLES.clear()
    fresh, calls = _table_calls(tables, short)
    assert not calls and len(builds) == 1
    np.testing.assert_allclose(got.Q.to_numpy(), fresh.Q.to_numpy(), rtol=5e-11, atol=0)
    # another theory or another rule: tables of their own
    seal_leak_piezo(tables, **kw)
    seal_leak_piezo(tables, **dict(kw, theory="critical_junction"))
    seal_leak_piezo(tables, **dict(kw, quad_order=12))
    assert len(builds) == 4
    _, calls = _table_calls(tables, dict(short, theory="critical_junction"))
    assert len(calls) == 1 and len(builds) == 4
    # at most BETA_MEMO kept, the oldest dropped (the first emt table: a short call no longer
    # finds it)
    for k in range(sv.BETA_MEMO):
        seal_leak_piezo(tables, **dict(kw, alpha_pv=1e-5 * (1 + k / 64)))
    memo = sv._beta_memo(tables)
    assert len(memo) == sv.BETA_MEMO
    _, calls = _table_calls(tables, short)
    assert not calls
    # kept per Tables object, dropped with it
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    other = fc.precompute(psd, theories=("emt",))
    seal_leak_piezo(other, **kw)
    assert len(sv._BETA_TABLES) == 2
    del other
    gc.collect()
    assert len(sv._BETA_TABLES) == 1


def test_seal_barus_kept_tables_under_threads(tables, monkeypatch):
    """Calls from several threads at once, each building and reading β tables while others
    evict them (a memo of 2): every call returns what it returns alone."""
    from concurrent.futures import ThreadPoolExecutor

    import fastcontact.seal.viscosity as sv

    monkeypatch.setattr(sv, "BETA_MEMO", 2)
    n = sv.BARUS_TABLE_ROWS + 10
    p0 = np.random.default_rng(12).uniform(2e4, 6e4, n)
    alphas = [1e-5 * (1 + k / 8) for k in range(6)] * 3

    def leak(al):
        return seal_leak_piezo(tables, p0=p0, dp=0.5 * p0, L=5e-3, L_y=L_Y, E_star=E_STAR,
                               eta=ETA, alpha_pv=al, theory="emt").Q.to_numpy()

    alone = {al: leak(al) for al in alphas[:6]}
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(leak, alphas))
    for al, q in zip(alphas, got):
        np.testing.assert_array_equal(q, alone[al])
    assert len(sv._beta_memo(tables)) == 2


@pytest.mark.parametrize("theory", ["emt", "critical_junction"])
def test_seal_run_table_matches_per_row(tables, theory):
    """A long Δp sweep of one Roelands ring next to percolation (SWEEP_TABLE_ROWS rows or more,
    shuffled, beside a short sweep and rings of their own) reads a cumulative table of its
    run: equal to every row's own integral with 100x narrower panels and 16 Gauss points to
    5e-11 (every 61st row checked), the short sweep and the single rings (the sweep kernel) to
    the same kernel with 10x narrower panels to 5e-8 (its panels are not split at the σ̄ nodes
    next to percolation), Q rising with Δp."""
    from fastcontact.kernels.quadrature import gauss_legendre
    from fastcontact.kernels.readonly import readonly_fields
    from fastcontact.seal._piezo_kernels import Quad, _uniform_kernel
    import fastcontact.seal.viscosity as sv

    rng = np.random.default_rng(9)
    m = sv.SWEEP_TABLE_ROWS + 100
    p_perc = float(tables.info["percolation_p_over_E"][theory]) * E_STAR
    p_s = 0.95 * p_perc  # next to percolation: σ̄ nodes dense, cells with nodes inside
    frac = np.concatenate([10 ** rng.uniform(-9, -3, m // 4), rng.uniform(1e-3, 0.999, m - m // 4),
                           rng.uniform(1e-3, 0.999, 300), rng.uniform(1e-3, 0.999, 20)])
    p0 = np.concatenate([np.full(m, p_s), np.full(300, 0.3 * p_perc),
                         rng.uniform(0.1, 0.9, 20) * p_perc])
    perm = rng.permutation(p0.size)
    p0, dp = p0[perm], (p0 * frac)[perm]
    kw = dict(p0=p0, dp=dp, L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=1e-7,
              theory=theory, viscosity="roelands", roelands_z=0.6)
    got, calls = _table_calls(tables, kw)
    assert (got.status == "ok").all()
    assert len(calls) == 1 and calls[0]["rows"].p0.size == m and calls[0]["bc"].run == 1
    c = calls[0]
    x, w = gauss_legendre(16)
    pick = np.arange(0, m, 61)
    rows = readonly_fields(type(c["rows"])(*(a[pick] for a in c["rows"])))  # as passed
    ref = np.empty(pick.size)
    pr = float(c["bc"].pr)
    _uniform_kernel(c["tab"], c["sc"], rows, pr, Quad(x, w, 0.005), ref)
    err = np.max(np.abs(c["out"][pick] / ref - 1))
    assert err < 5e-11, err  # measured 4.6e-13 (panels of 0.05 are themselves off by 6e-11)
    # every row in its place: the other rows and a sample of the run against the same
    # reference through Q
    chk = np.union1d(np.flatnonzero(p0 != p_s), np.arange(0, p0.size, 37))
    k = chk.size
    sub = readonly_fields(type(c["rows"])(*(np.ascontiguousarray(a, dtype=np.float64) for a in (
        p0[chk], np.full(k, 5e-3), dp[chk], np.zeros(k), np.full(k, E_STAR),
        np.full(k, c["bc"].A), np.full(k, c["bc"].Z)))))
    ref_all = np.empty(k)
    _uniform_kernel(c["tab"], c["sc"], sub, pr, Quad(x, w, 0.05), ref_all)
    q_ref = L_Y * ref_all * float(tables.h_rms) ** 3 / (12.0 * ETA)
    np.testing.assert_allclose(got.Q.to_numpy()[chk], q_ref, rtol=5e-8, atol=0)
    run = p0 == p_s
    order = np.argsort(dp[run])
    assert np.all(np.diff(got.Q.to_numpy()[run][order]) > 0)


@pytest.mark.parametrize("steps", [None, 200])  # panel collocation (default), shooting
@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_seal_hertz(tables, theory, steps):
    R, f_N = 1e-3, 3.0
    a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
    pH = 2 * f_N / (math.pi * a)
    base = seal_leak(tables, profile="hertz", R=R, f_N=f_N, dp=3e4, L_y=L_Y, E_star=E_STAR,
                     eta=ETA, theory=theory)
    zero = seal_leak_piezo(tables, profile="hertz", R=R, f_N=f_N, dp=3e4, L_y=L_Y,
                           E_star=E_STAR, eta=ETA, alpha_pv=0.0, theory=theory)
    assert abs(zero.Q[0] / base.Q[0] - 1) < 3e-8
    dp, al = 6e4, 3e-5
    ref = hertz_shoot(_sigma(tables, theory), pH, a, dp, 0.0, al) * L_Y
    got = seal_leak_piezo(tables, profile="hertz", R=R, f_N=f_N, dp=dp, L_y=L_Y,
                          E_star=E_STAR, eta=ETA, alpha_pv=al, theory=theory, steps=steps)
    assert bool(got.converged[0])
    assert abs(got.Q[0] / ref - 1) < 3e-8


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_seal_hertz_panels_random(tables, theory):
    """The Barus O-ring's default solver (the base engine's panel collocation in ψ) against
    the adaptive DOP853 shooting of the Reynolds equation with η(p) in p itself
    (tests/reference/ext_reynolds.py), on random O-rings: α p_H 0.01–3, p_b > 0 on half,
    p_a up to 0.95 p_H. Measured <= 7e-10 (critical junction) and <= 6e-8 (EMT, where the
    200-step shooting is off by as much: the reference reads σ̄ from the tables' own
    interpolant, the solvers from the seal engine's verified re-tabulation)."""
    rng = np.random.default_rng(7)
    for j in range(6):
        R, f_N = 10 ** rng.uniform(-3.5, -2.5), 10 ** rng.uniform(0.0, 1.5)
        a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
        pH = 2 * f_N / (math.pi * a)
        pb = pH * rng.uniform(0.0, 0.3) if j % 2 else 0.0
        pa = pb + (pH - pb) * rng.uniform(0.05, 0.95)
        al = rng.uniform(0.01, 3.0) / pH
        ref = hertz_shoot(_sigma(tables, theory), pH, a, pa, pb, al) * L_Y
        got = seal_leak_piezo(tables, profile="hertz", R=R, f_N=f_N, dp=pa - pb, p_b=pb,
                              L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=al, theory=theory)
        assert got.status[0] == "ok" and bool(got.converged[0])
        assert abs(got.Q[0] / ref - 1) < 2e-7, (j, got.Q[0], ref)


@pytest.mark.parametrize("law", ["barus", "roelands"])
def test_seal_hertz_sweep_chains_match_single_rows(tables, law, monkeypatch):
    """A batch of O-rings is solved in chains (rows sharing p_H, p_b and the fluid, rising in
    p_a; each row's Newton started on the previous row's solution). A shuffled batch of two
    O-rings' Δp sweeps (up to 0.98 p_H, and next to lift-off) equals each row solved on its
    own (a batch of one: a cold solve) within 5e-9 (at the panel tolerance 1e-6 a warm start
    keeps a mesh refined for the previous row: measured <= 1.3e-9 here; 60-row sweeps of 64
    O-rings on the embedded surfaces were <= 1e-8 from the DOP853 reference, their cold
    solves <= 1.1e-9), and chains of more than one row did run; three rows also against the
    DOP853 reference (within 3e-8; the Barus one of tests/reference/ext_reynolds.py,
    Roelands' of ext_roelands.py)."""
    from fastcontact.seal import context
    from reference.ext_roelands import hertz_shoot as hertz_shoot_r
    from reference.ext_roelands import roelands

    spied = []
    orig = context._panels.solve_rows_chained

    def spy(*args):
        spied.append(np.diff(args[-2]).max())
        return orig(*args)
    monkeypatch.setattr(context._panels, "solve_rows_chained", spy)
    rows = []
    for R, f_N in ((1e-3, 3.0), (2e-3, 5.0)):
        a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
        pH = 2 * f_N / (math.pi * a)
        for frac in np.concatenate((np.linspace(0.02, 0.98, 40), [1 - 1e-4, 1 - 1e-6])):
            rows.append((R, f_N, a, pH, frac * pH))
    rows = [rows[k] for k in np.random.default_rng(3).permutation(len(rows))]
    R, f_N, a, pH, dp = (np.array(c) for c in zip(*rows))
    kw = dict(profile="hertz", L_y=L_Y, E_star=E_STAR, eta=ETA, theory="emt")
    kw.update(dict(alpha_pv=1e-5) if law == "barus" else
              dict(alpha_pv=0.0, viscosity="roelands", roelands_z=0.6, roelands_p_r=1e5))
    batch = seal_leak_piezo(tables, R=R, f_N=f_N, dp=dp, **kw)
    assert (batch.status == "ok").all() and max(spied) > 1
    for k in range(dp.size):
        one = seal_leak_piezo(tables, R=R[k], f_N=f_N[k], dp=dp[k], **kw)
        assert abs(batch.Q[k] / one.Q[0] - 1) < 5e-9, (k, batch.Q[k] / one.Q[0] - 1)
    for k in np.flatnonzero(dp <= 0.98 * pH)[:3]:
        if law == "barus":
            ref = hertz_shoot(_sigma(tables, "emt"), pH[k], a[k], dp[k], 0.0, 1e-5)
        else:
            ref = hertz_shoot_r(_sigma(tables, "emt"), pH[k], a[k], dp[k], 0.0,
                                roelands(ETA, 0.6, 1e-5))
        assert abs(batch.Q[k] / (ref * L_Y) - 1) < 3e-8, (k, batch.Q[k] / (ref * L_Y) - 1)


def test_seal_hertz_lift_off_equality_and_shooting(tables):
    """At the lift-off equality p_a = p_H the panel solve (tolerance 1e-9 there) gives the
    finite limit, flagged lift_off, continuous with p_a a relative 1e-9 below it (Q varies
    like the square root of the distance there: measured 3.5e-4); the shooting does not
    converge at the equality (NaN, not_converged). Away from it the two solvers agree."""
    R, f_N = 1e-3, 3.0
    a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
    pH = 2 * f_N / (math.pi * a)
    kw = dict(profile="hertz", R=R, f_N=f_N, L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=2e-5,
              theory="emt")
    got = seal_leak_piezo(tables, dp=[pH, pH * (1 - 1e-9), 0.5 * pH], **kw)
    assert list(got.status) == ["lift_off", "ok", "ok"] and np.all(np.isfinite(got.Q))
    assert abs(got.Q[0] / got.Q[1] - 1) < 1e-3 and got.Q[0] > got.Q[1]
    sh = seal_leak_piezo(tables, dp=0.5 * pH, steps=400, **kw)
    assert abs(got.Q[2] / sh.Q[0] - 1) < 1e-6


def test_seal_hertz_panel_failure_falls_back_to_shooting(tables):
    """Where the panel Newton fails (α p_H ~ 12 next to lift-off, EMT) the row is solved by the
    checked shooting (the number of steps=FALLBACK_STEPS to 1e-12), at the lift-off equality too
    (a finite limit, flagged lift_off, continuous with p_a 1e-9 p_H below: square-root limit,
    measured 7.4e-5). Where neither solver converges (the equality at α p_H = 7 here), Q is
    NaN and the status says "not_converged" (not "lift_off")."""
    from fastcontact.seal.viscosity import FALLBACK_STEPS, _barus_hertz_k
    R, f_N = 1e-3, 3.0
    a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
    pH = 2 * f_N / (math.pi * a)
    kw = dict(profile="hertz", R=R, f_N=f_N, L_y=L_Y, E_star=E_STAR, eta=ETA, theory="emt")
    al = 12.0 / pH
    _, ok = _barus_hertz_k(tables, "emt", *(np.array([v]) for v in
                                            (E_STAR, pH, a, pH * (1 - 1e-3), 0.0, al)))
    assert not ok[0]                                      # the panel solve fails here
    got = seal_leak_piezo(tables, dp=[pH * (1 - 1e-3), pH, pH * (1 - 1e-9)], alpha_pv=al, **kw)
    sh = seal_leak_piezo(tables, dp=pH * (1 - 1e-3), steps=FALLBACK_STEPS, alpha_pv=al, **kw)
    # the same 3200-step root; the checked shooting starts it from the 1600-step root, the
    # steps= call from a coarse solve: both converge to 1e-13 (measured apart by 9e-15)
    assert got.status[0] == "ok" and math.isfinite(got.Q[0])
    assert abs(got.Q[0] / sh.Q[0] - 1.0) < 1e-12
    assert list(got.status[1:]) == ["lift_off", "ok"]
    assert 0 < got.Q[1] / got.Q[2] - 1 < 1e-3
    al = 7.0 / pH
    _, ok = _barus_hertz_k(tables, "emt", *(np.array([v]) for v in (E_STAR, pH, a, pH, 0.0, al)))
    sh = seal_leak_piezo(tables, dp=pH, steps=FALLBACK_STEPS, alpha_pv=al, **kw)
    assert not ok[0] and not bool(sh.converged[0])       # neither solver converges here
    got = seal_leak_piezo(tables, dp=pH, alpha_pv=al, **kw)
    assert got.status[0] == "not_converged" and math.isnan(got.Q[0]) and bool(got.lift_off[0])


def test_seal_hertz_fallback_rows_against_reference(tables):
    """The rows whose panel Newton fails (α p_H 5-7, p_a within 1e-3..1e-6 of p_H; which ones
    fail is erratic) against the adaptive DOP853 shooting reference: the checked shooting is
    within 1e-6 (measured <= 3.2e-7, the part of it shared with the panel rows being the
    reference's σ̄ read from the tables' interpolant); the 200-step shooting used before was
    off by 5e-6 to 3e-5 there."""
    from fastcontact.seal.viscosity import _barus_hertz_k
    R, f_N = 1e-3, 3.0
    a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
    pH = 2 * f_N / (math.pi * a)
    checked = 0
    for theory in ("critical_junction", "emt"):
        for aph in (5.0, 7.0):
            for off in (1e-3, 1e-4, 1e-6):
                pa, al = pH * (1 - off), aph / pH
                _, ok = _barus_hertz_k(tables, theory, *(np.array([v]) for v in
                                                         (E_STAR, pH, a, pa, 0.0, al)))
                if ok[0]:
                    continue
                ref = hertz_shoot(_sigma(tables, theory), pH, a, pa, 0.0, al) * L_Y
                got = seal_leak_piezo(tables, profile="hertz", R=R, f_N=f_N, dp=pa, L_y=L_Y,
                                      E_star=E_STAR, eta=ETA, alpha_pv=al, theory=theory)
                assert got.status[0] == "ok", (theory, aph, off)
                assert abs(got.Q[0] / ref - 1) < 1e-6, (theory, aph, off, got.Q[0] / ref - 1)
                checked += 1
    assert checked >= 2     # the fallback was exercised


def test_seal_flags(tables):
    df = seal_leak_piezo(tables, p0=5e4, dp=[0.0, 6e4], L=5e-3, L_y=L_Y, E_star=E_STAR,
                         eta=ETA, alpha_pv=1e-5)
    assert df.Q[0] == 0.0 and df.Q[1] == math.inf and bool(df.lift_off[1])
    with pytest.raises(ValueError, match="alpha_pv"):
        seal_leak_piezo(tables, p0=5e4, dp=1e3, L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA,
                        alpha_pv=float("nan"))


def test_squeeze_out_keyword(tables):
    """squeeze_out(..., alpha_pv=) dispatches: 0 → the base engine unchanged, > 0 → Barus."""
    kw = dict(p0=np.array([1e5, 4e5]), E_star=E_STAR, R=0.01, eta=ETA, theory="emt")
    base = squeeze_out(tables, **kw)
    zero = squeeze_out(tables, alpha_pv=0.0, **kw)
    assert base.equals(zero)
    got = squeeze_out(tables, alpha_pv=2e-6, **kw)
    ref = squeeze_out_piezo(tables, alpha_pv=2e-6, **kw)
    assert got.equals(ref)
    # ū at times: the Barus engine's u_at columns [m]
    got = squeeze_out(tables, alpha_pv=2e-6, times=(0.0, 1e-3), **kw)
    assert got.attrs["units"]["u_at_0.001"] == "m"
    np.testing.assert_array_equal(got["u_at_0"], got.u_start)
    assert np.all(got["u_at_0.001"] < got.u_start) and np.all(got["u_at_0.001"] > got.u_inf)
    with pytest.raises(ValueError, match="times"):
        squeeze_out(tables, alpha_pv=2e-6, times=(-1e-3,), **kw)


def test_seal_leak_keyword(tables):
    """seal_leak(..., alpha_pv=): 0 → unchanged, > 0 → the Barus engine."""
    kw = dict(p0=5e4, dp=np.array([1e4, 3e4]), L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA,
              theory="emt")
    assert seal_leak(tables, **kw).equals(seal_leak(tables, alpha_pv=0.0, **kw))
    got = seal_leak(tables, alpha_pv=1e-5, **kw)
    ref = seal_leak_piezo(tables, alpha_pv=1e-5, **kw)
    assert got.equals(ref)
