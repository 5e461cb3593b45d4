"""Issue 14.5: the Barus tire footprint at the base engine's speed — a call of one fluid (α) on
one rubber (E*) runs the base kernels on the Barus time primitive G = T + α p0 S
(``fastcontact/squeeze/_barus_time.py``).

References: the radial Reynolds equation with η(p) integrated directly
(``tests/reference/ext_reynolds.py``, scipy; none of the package's reduction); the per-case
quadrature (``method="quad"``, itself checked against that reference in
test_ext_viscosity.py); at the primitive's level, the base time primitive plus the separately
tabulated correction S (the arithmetic of the per-case Barus kernel, which the primitive
replaces).
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest
from numba import njit

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_reynolds import squeeze_time  # noqa: E402

import fastcontact as fc  # noqa: E402
from fastcontact.squeeze import _barus_primitive as bp  # noqa: E402
from fastcontact.squeeze import _barus_time as btime  # noqa: E402
from fastcontact.squeeze._primitive_eval import row_value, stencil, t_of_z  # noqa: E402
from fastcontact.squeeze.model import squeeze_model  # noqa: E402
from fastcontact.squeeze.tire import tire_footprint  # noqa: E402
from fastcontact.squeeze.viscosity import barus_rate_factor, fast_setup  # noqa: E402

E_STAR, ETA, R = 1e7, 1e-3, 0.01


@pytest.fixture(scope="module")
def tables():
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    return fc.precompute(psd, theories=("critical_junction", "emt"))


def _groups(tables, theory, p0, alpha, u_start, E_star=E_STAR):
    """served_groups of the cases: ([(G primitive, rows it serves), ...], other rows)."""
    m = squeeze_model(tables, theory)
    p0 = np.atleast_1d(np.asarray(p0, dtype=float))
    n = p0.size
    return btime.served_groups(
        m, fast_setup(tables, theory, None), p0,
        *(np.broadcast_to(np.asarray(a, dtype=float), (n,)).copy()
          for a in (E_star, alpha, u_start)), tables.h_rms)


def _served(tables, theory, p0, alpha, u_start):
    """(G primitive or None, rows it serves, other rows) of a call of one fluid."""
    groups, rest = _groups(tables, theory, p0, alpha, u_start)
    assert len(groups) <= 1
    return (*groups[0], rest) if groups else (None, rest[:0], rest)


@njit(cache=True)
def _g_both(pr, prg, bt, c, aE, x0s, zs, out):
    """G by the primitive ``prg`` and by T (base primitive) + A S (correction table)."""
    E = np.empty(bp.K_MAX + 1)
    for i in range(x0s.size):
        x0 = x0s[i]
        st = stencil(pr, x0)
        vinf = math.exp(row_value(pr.lnv, st))
        v = vinf * (1.0 + math.exp(zs[i]))
        A = aE * math.exp(x0)
        K = bp.series_order(c, A)
        bp.shift(c, A, K, E)
        out[i, 0] = t_of_z(prg, stencil(prg, x0), vinf, zs[i])
        out[i, 1] = t_of_z(pr, st, vinf, zs[i]) + A * bp.s_value(bt, E, K, x0, v)[0]


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_primitive_against_base_plus_correction(tables, theory):
    """On random (x0, z) it serves — below the z grid, on it, and on the nodes it adds above
    the base grid (the flat-film tail, G = T_tail/g(A)) — the G primitive is the base
    primitive plus α p0 S within 2e-7 (measured 2-3e-8 at α p0 up to 0.6)."""
    alpha = 2e-6
    bg, idx, _rest = _served(tables, theory, [1e5], alpha, 10.0)
    assert idx.size == 1
    pr, bt, c, _xf = fast_setup(tables, theory, None)
    assert bg.pr.nz > pr.nz                      # a 10 m start lies above the base grid
    rng = np.random.default_rng(1)
    n = 20000
    x0s = rng.uniform(pr.xn[0], bg.x_served, n)
    zs = rng.uniform(-14.0, bg.z_top - 0.5 - float(np.max(pr.lk)), n)
    out = np.empty((n, 2))
    _g_both(pr, bg.pr, bt, c, alpha * E_STAR, x0s, zs, out)
    err = np.abs(out[:, 0] / out[:, 1] - 1.0)
    assert np.all(np.isfinite(out)) and np.max(err) < 2e-7
    assert np.any(x0s > math.log(0.5 / (alpha * E_STAR)))     # α p0 up to 0.6 covered


def _widest_rows(tables, theory):
    """(x0 of the base primitive's widest-spaced row interval below the fast limit and above
    the tables' bottom, its width)."""
    pr, _bt, _c, xf = fast_setup(tables, theory, None)
    xn, d = pr.xn, np.diff(pr.xn)
    inside = (xn[1:] <= xf) & (xn[:-1] > squeeze_model(tables, theory).mp.x_min + 1.0)
    j = int(np.argmax(np.where(inside, d, 0.0)))
    return float(xn[j]), float(d[j])


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_primitive_where_the_rows_are_widest(tables, theory):
    """Where the base rows are widest in x0 (low p0/E*, ~0.09) and A = α p0 reaches 0.6, G's
    x0-dependence through A ∝ e^x0 made the 4-point row interpolation err by 2e-6 (the base T
    there: ~1e-9); the G primitive inserts rows there (interpolated T, exact A S): G within
    2e-8 of T + A S on random (x0, z) in the two units of x0 below its limit."""
    x, dx = _widest_rows(tables, theory)
    assert dx > 0.08                                    # the case this test is about
    aE = 0.6 / math.exp(x + 0.5 * dx)
    pr, bt, c, _xf = fast_setup(tables, theory, None)
    bg, idx, _rest = _served(tables, theory, [math.exp(x) * E_STAR], aE / E_STAR, 10.0)
    assert idx.size == 1 and bg.pr.xn.size > np.count_nonzero(pr.xn <= bg.pr.xn[-1])
    rng = np.random.default_rng(3)
    n = 20000
    x0s = rng.uniform(max(pr.xn[0], bg.x_served - 2.0), bg.x_served, n)
    zs = rng.uniform(-14.0, bg.z_top - 0.5 - float(np.max(pr.lk)), n)
    out = np.empty((n, 2))
    _g_both(pr, bg.pr, bt, c, aE, x0s, zs, out)
    assert np.all(np.isfinite(out)) and np.max(np.abs(out[:, 0] / out[:, 1] - 1.0)) < 2e-8


def test_one_fluid_at_widely_spaced_rows_against_reynolds_reference():
    """The embedded road tables' critical junction at p0/E* = 4.6e-8 (rows 0.083 apart) and
    α p0 = 0.596, one fluid (the G primitive): t(1.1 ū∞) from the default start within 1e-7 of
    the Reynolds reference (was 1.0e-6 off before the G primitive refined its rows there)."""
    from fastcontact.tables.defaults import default_table_path
    T = fc.Tables.from_parquet(default_table_path("asphalt_024mm"))
    E, pbar = 5844370.791008395, 4.623041479785134e-08
    p0 = pbar * E
    alpha = 0.5957149352435938 / p0
    df = fc.squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory="critical_junction",
                        alpha_pv=alpha, ratios=(1.1,), method="fast")
    r = df.iloc[0]
    assert r.status == "ok" and df.attrs["barus_time_primitive"][0]["primitive"] == "Barus G"
    ref = squeeze_time(T, "critical_junction", p0, E, R, ETA, alpha, r.u_start, 1.1 * r.u_inf,
                       r.u_inf, rtol=1e-11)
    assert abs(r["t_ratio_1.1"] / ref - 1) < 1e-7


def test_one_fluid_tire_against_reynolds_reference(tables):
    """A call of one α and one E*: every row from the G primitive; the times to the targets
    and ū at the footprint exit (the reference time from ū(0) to it is the footprint time)
    within 1e-7 of the Reynolds reference."""
    alpha = 2e-6
    p0 = np.array([1e5, 2.5e5])
    us = np.array([30 * tables.h_rms, 20 * tables.h_rms])
    kw = dict(p0=p0, E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1,
              speed=np.array([30.0, 3.0]), theory="emt", u_start=us, alpha_pv=alpha)
    assert _served(tables, "emt", p0, alpha, us)[1].size == 2
    df = tire_footprint(tables, method="fast", **kw)
    assert set(df.status) == {"ok"}
    r = df.iloc[0]
    ref = squeeze_time(tables, "emt", r.p_eval, E_STAR, R, ETA, alpha, r.u_start,
                       1.1 * r.u_inf, r.u_inf)
    assert abs(r["t_ratio_1.1"] / ref - 1) < 1e-7
    r = df.iloc[1]
    assert r.u_exit > 1.001 * r.u_inf                      # the exit mid-squeeze
    t_exit = squeeze_time(tables, "emt", r.p_eval, E_STAR, R, ETA, alpha, r.u_start, r.u_exit,
                          r.u_inf, rtol=1e-10)
    assert abs(t_exit / r.t_footprint - 1) < 1e-7


def test_one_fluid_tire_against_quadrature_random(tables):
    """400 random footprints of one fluid (pressures with α p0 up to 1.2, speeds, starts 1 µm
    to 1 cm): where the G primitive serves, ū_exit − ū∞ within 2e-7 of the quadrature's (or
    1e-8 ū∞) and the target times within 1e-6; the rows it does not serve (α p0 > 0.6, start
    below ū∞) are the per-case Barus engine's numbers, here the quadrature's exactly."""
    rng = np.random.default_rng(2)
    n = 400
    alpha = 1e-6
    p0 = np.exp(rng.uniform(math.log(2e3), math.log(1.2e6), n))
    us = 10 ** rng.uniform(-6, -2, n)
    kw = dict(p0=p0, E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1,
              speed=10 ** rng.uniform(-3, 1.5, n), theory="critical_junction", u_start=us,
              alpha_pv=alpha)
    _bg, idx, rest = _served(tables, "critical_junction", p0, alpha, us)
    assert idx.size > 200 and rest.size > 40
    fast = tire_footprint(tables, method="fast", **kw)
    quad = tire_footprint(tables, method="quad", **kw)
    served = np.zeros(n, dtype=bool)
    served[idx] = True
    ok = served & (fast.status == "ok").to_numpy()
    assert ok.sum() > 150
    u_inf = fast.u_inf.to_numpy()[ok]
    du_f = (fast.u_exit - fast.u_inf).to_numpy()[ok]
    du_q = (quad.u_exit - quad.u_inf).to_numpy()[ok]
    assert np.all(np.abs(du_f - du_q) <= np.maximum(2e-7 * du_q, 1e-8 * u_inf))
    assert np.sum(du_q > 1e-6 * u_inf) > 50
    for c in ("t_star", "t_du", "t_ratio_1.1"):
        a, b = fast[c][ok].to_numpy(), quad[c][ok].to_numpy()
        err = np.abs(a - b) / np.maximum(b, 0.1 * quad.t_star[ok].to_numpy())
        assert np.max(err) < 1e-6, c
    np.testing.assert_array_equal(fast.status.astype(str), quad.status.astype(str))
    other = ~served & (alpha * p0 > 0.6)      # the per-case kernel's quadrature rows
    assert other.sum() > 40
    for c in ("t_star", "u_exit", "u_inf", "t_du"):
        np.testing.assert_array_equal(fast[c][other], quad[c][other])


def test_rows_of_a_mixed_call_equal_the_rows_alone(tables):
    """Rows the G primitive serves give the same numbers in a call with rows it does not
    (α p0 > 0.6: piezo_limit or per-case kernel; p0 outside the tables) as alone; a call of
    two fluids runs the per-case kernel, within its accuracy of the one-fluid numbers."""
    p0 = np.array([5e4, 1.5e5, 2.5e5, 8e5, 1.2e6, 1e9])
    kw = dict(E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1, speed=5.0, theory="emt",
              u_start=30 * tables.h_rms)
    assert list(_served(tables, "emt", p0, 1e-6, kw["u_start"])[1]) == [0, 1, 2]
    mixed = tire_footprint(tables, p0=p0, alpha_pv=1e-6, **kw)
    assert list(mixed.status[3:]) == ["ok", "piezo_limit", "out_of_table"]
    alone = tire_footprint(tables, p0=p0[:3], alpha_pv=1e-6, **kw)
    for c in ("t_star", "t_ratio_1.1", "t_du", "u_exit", "u_inf", "u_start"):
        np.testing.assert_array_equal(mixed[c][:3], alone[c])
    two = tire_footprint(tables, p0=p0[:3], alpha_pv=[1e-6, 1e-6, 1.0000001e-6], **kw)
    np.testing.assert_allclose(two.t_star[:2], alone.t_star[:2], rtol=1e-7)
    np.testing.assert_allclose(two.u_exit[:2] - two.u_inf[:2],
                               alone.u_exit[:2] - alone.u_inf[:2], rtol=1e-6)


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_one_fluid_squeeze_out_against_quadrature_random(tables, theory):
    """squeeze_out of one fluid (300 random pressures, α p0 up to 1.2, the default start and
    given starts, Δu targets, ū at times incl. 0 and inf): where the G primitive serves, the
    target times within 2e-7 of the quadrature's (1e-6 for a start within 0.5 % of a target,
    where a short time is the difference of two long ones), ū − ū∞ at the times within 2e-7
    (or 1e-8 ū∞), the rate factor at the start within 1e-7, the status the quadrature's; one
    time against the Reynolds reference; the other rows the quadrature's numbers exactly."""
    from fastcontact.squeeze.viscosity import squeeze_out_piezo
    rng = np.random.default_rng(4)
    n = 300
    alpha = 1e-6
    p0 = np.exp(rng.uniform(math.log(1e3), math.log(1.2e6), n))
    times = np.array([0.0, 1e-4, 3e-3, 0.1, np.inf])
    for us in (None, 10 ** rng.uniform(-5.5, -2, n)):
        kw = dict(p0=p0, E_star=E_STAR, R=R, eta=ETA, alpha_pv=alpha, theory=theory,
                  ratios=(1.1, 1.001), du=(1e-8,), times=times, u_start=us)
        _bg, idx, _rest = _served(tables, theory, p0, alpha, np.nan if us is None else us)
        fast = squeeze_out_piezo(tables, method="fast", **kw)
        quad = squeeze_out_piezo(tables, method="quad", **kw)
        prov, = fast.attrs["barus_time_primitive"]          # provenance of the served rows
        assert prov["cases_served"] == idx.size and prov["alpha_E_star"] == alpha * E_STAR
        assert list(fast.status) == list(quad.status)
        served = np.zeros(n, dtype=bool)
        served[idx] = True
        ok = served & (fast.status == "ok").to_numpy()
        assert ok.sum() > 150
        for c in ("t_star", "t_ratio_1.1", "t_ratio_1.001", "t_du_1e-08"):
            a, b = fast[c][ok].to_numpy(), quad[c][ok].to_numpy()
            nz = b > 0
            assert np.max(np.abs(a[nz] / b[nz] - 1)) < (2e-7 if us is None else 1e-6), c
            np.testing.assert_array_equal(a[~nz], 0.0)
        np.testing.assert_allclose(fast.rate_factor_start[ok], quad.rate_factor_start[ok],
                                   rtol=1e-7)
        if us is None:  # the default start: p_cont = 1e-3 p0 by definition
            np.testing.assert_allclose(fast.rate_factor_start[ok],
                                       barus_rate_factor(alpha * p0[ok] * (1.0 - 1e-3)),
                                       rtol=1e-11)
        names = [c for c in fast.columns if c.startswith("u_at_")]
        U, Uq = fast[names].to_numpy()[ok], quad[names].to_numpy()[ok]
        u_inf = fast.u_inf.to_numpy()[ok]
        np.testing.assert_array_equal(U[:, 0], fast.u_start.to_numpy()[ok])
        np.testing.assert_array_equal(U[:, -1], u_inf)
        du, duq = U - u_inf[:, None], Uq - quad.u_inf.to_numpy()[ok][:, None]
        assert np.all(np.abs(du - duq) <= np.maximum(2e-7 * duq, 1e-8 * u_inf[:, None]))
        assert np.sum(duq[:, 1:-1] > 1e-3 * u_inf[:, None]) > 100
        other = ~served
        assert other.sum() > 30
        for c in ("t_star", "t_du_1e-08", "u_inf", "rate_factor_start"):
            np.testing.assert_array_equal(fast[c][other], quad[c][other])
    i = int(np.flatnonzero(ok & (alpha * p0 > 0.2))[0])
    r = fast.iloc[i]
    k = int(np.argmax((duq[np.flatnonzero(ok) == i][0] > 1e-2 * r.u_inf) * (times > 0)
                      * np.arange(times.size)))
    t_ref = squeeze_time(tables, theory, p0[i], E_STAR, R, ETA, alpha, r.u_start, r[names[k]],
                         r.u_inf, rtol=1e-10)
    assert abs(t_ref / times[k] - 1) < 1e-6


def test_one_fluid_bounds_of_the_physics(tables):
    """2,000 random footprints of one fluid served by the G primitive: every time lies between
    the constant-viscosity time and twice it (the rate factor g ∈ (1/2, 1]; it only slows the
    squeeze-out, at most by half), ū at the exit between the base engine's and ū(0), ū∞ the
    base engine's (viscosity-free) — bounds of the physics, no reference needed."""
    rng = np.random.default_rng(6)
    n = 2000
    alpha = 1.5e-6
    p0 = np.exp(rng.uniform(math.log(2e3), math.log(0.4 / alpha), n))  # α p0 <= 0.4
    kw = dict(p0=p0, E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1,
              speed=10 ** rng.uniform(-2, 1.5, n), theory="emt",
              u_start=10 ** rng.uniform(-5, -2, n), method="fast")
    _bg, idx, _rest = _served(tables, "emt", p0, alpha, kw["u_start"])
    assert idx.size > 0.9 * n
    g = tire_footprint(tables, alpha_pv=alpha, **kw)
    b = tire_footprint(tables, **kw)
    ok = (g.status == "ok").to_numpy()
    assert ok.sum() > 1500 and list(g.status) == list(b.status)
    np.testing.assert_array_equal(g.u_inf[ok], b.u_inf[ok])
    for c in ("t_star", "t_ratio_1.1", "t_ratio_1.01", "t_du"):
        tg, tb = g[c][ok].to_numpy(), b[c][ok].to_numpy()
        pos = tb > 0
        assert np.all(tg[pos] >= tb[pos] * (1 - 1e-9)) and np.all(tg[pos] <= 2 * tb[pos]), c
    ue, ub, u0 = (x[ok].to_numpy() for x in (g.u_exit, b.u_exit, g.u_start))
    assert np.all(ue >= ub * (1 - 1e-12)) and np.all(ue <= u0)
