"""Issue 14.5: a call of several fluids or rubbers — each group of rows of one α E* on its own
Barus time primitive G (``fastcontact/squeeze/_barus_time.py``: ``served_groups``), the rows of
α = 0 on the constant-viscosity primitive.

References: the per-case quadrature (``method="quad"``, checked against the radial Reynolds
equation with η(p) in test_ext_viscosity.py and test_ext_barus_time.py); the base engine
(``squeeze_out`` without ``alpha_pv``) for the rows of α = 0; and each group's rows as a call
of their own (one fluid: every row on its G primitive), which a call of several must equal.
"""
from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
import pytest

import fastcontact as fc
from fastcontact.squeeze import _barus_fast as bfast
from fastcontact.squeeze import _barus_time as btime
from fastcontact.squeeze.model import squeeze_model
from fastcontact.squeeze.tire import tire_footprint
from fastcontact.squeeze.viscosity import fast_setup, squeeze_out_piezo

E1, ETA, R = 1e7, 1e-3, 0.01
A1, A2 = 1e-6, 2e-6


@pytest.fixture(scope="module")
def tables():
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    return fc.precompute(psd, theories=("critical_junction", "emt"))


@pytest.fixture
def fresh_memo(monkeypatch):
    """An empty memo of G primitives (none kept from other tests)."""
    monkeypatch.setattr(btime, "_MEMO", OrderedDict())


def _cases(rng, n, tables):
    """Random footprints: α p0 <= 0.5 at the largest α E* below, starts 30-300 h_rms."""
    return dict(p0=np.exp(rng.uniform(math.log(5e3), math.log(2.4e5), n)),
                u_start=tables.h_rms * 10 ** rng.uniform(1.5, 2.5, n),
                speed=10 ** rng.uniform(-1.5, 1.5, n))


def _fluids(n):
    """Four sets of rows: (α1, E1), (α2, E1), (α2/2, 2 E1) — the same α E* as the second —
    and α = 0 on two moduli."""
    k = np.arange(n) % 4
    alpha = np.choose(k, [A1, A2, 0.5 * A2, 0.0])
    E = np.choose(k, [E1, E1, 2 * E1, np.where(np.arange(n) % 8 == 3, E1, 3 * E1)])
    return alpha, E, k


def test_groups_are_the_rows_of_one_alpha_times_E_star(tables, fresh_memo, monkeypatch):
    """Rows group by α E* (the second and third sets share one primitive), α = 0 rows form
    one group whatever their modulus (the constant-viscosity primitive, α E* = 0); groups
    below MIN_GROUP_ROWS are served only once their primitive is kept."""
    n = 160
    alpha, E, k = _fluids(n)
    p0 = np.full(n, 1e5)
    args = (squeeze_model(tables, "emt"), fast_setup(tables, "emt", None), p0, E, alpha,
            np.full(n, np.nan), tables.h_rms)
    groups, rest = btime.served_groups(*args)
    assert [g[0].aE for g in groups] == [0.0] and rest.size == 120   # 40 rows < 20,000
    np.testing.assert_array_equal(groups[0][1], np.flatnonzero(k == 3))
    assert groups[0][0].pr is args[1][0]                            # the base primitive
    monkeypatch.setattr(btime, "MIN_GROUP_ROWS", 40)
    groups, rest = btime.served_groups(*args)
    assert rest.size == 0
    got = {g[0].aE: g[1] for g in groups}
    assert sorted(got) == [0.0, A1 * E1, A2 * E1]
    np.testing.assert_array_equal(got[A2 * E1], np.flatnonzero((k == 1) | (k == 2)))
    monkeypatch.setattr(btime, "MIN_GROUP_ROWS", 10**9)                 # now kept: served
    groups, rest = btime.served_groups(*args)
    assert sorted(g[0].aE for g in groups) == [0.0, A1 * E1, A2 * E1] and rest.size == 0


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_tire_of_several_fluids(tables, theory, fresh_memo, monkeypatch):
    """A tire call of three α E* groups and α = 0 rows: every group on its primitive (the
    per-case Barus kernel is never called), each group's rows equal to those rows as a call of
    their own (one fluid) in every column, bit for bit, and within 2e-7 of the quadrature in
    ū_exit − ū∞ (or 1e-8 ū∞) and 1e-6 in the target times."""
    monkeypatch.setattr(btime, "MIN_GROUP_ROWS", 50)
    rng = np.random.default_rng(11)
    n = 400
    alpha, E, k = _fluids(n)
    kw = dict(_cases(rng, n, tables), R=R, eta=ETA, footprint_length=0.1, theory=theory)

    def per_case(*args):
        raise AssertionError("the per-case Barus kernel ran")
    real = bfast.tire_kernel
    monkeypatch.setattr(bfast, "tire_kernel", per_case)
    mixed = tire_footprint(tables, E_star=E, alpha_pv=alpha, method="fast", **kw)
    monkeypatch.setattr(bfast, "tire_kernel", real)
    assert (mixed.status == "ok").all()
    cols = ["u_inf", "u_start", "t_star", "t_ratio_1.1", "t_du", "u_exit", "status"]
    for sel in (k == 0, (k == 1) | (k == 2), k == 3):
        sub = {key: (v[sel] if np.ndim(v) else v) for key, v in kw.items()}
        alone = tire_footprint(tables, E_star=E[sel], alpha_pv=alpha[sel], method="fast", **sub)
        for c in cols:
            np.testing.assert_array_equal(mixed[c][sel].to_numpy(), alone[c].to_numpy(), c)
    quad = tire_footprint(tables, E_star=E, alpha_pv=alpha, method="quad", **kw)
    u_inf = mixed.u_inf.to_numpy()
    du_f, du_q = (mixed.u_exit - mixed.u_inf).to_numpy(), (quad.u_exit - quad.u_inf).to_numpy()
    assert np.all(np.abs(du_f - du_q) <= np.maximum(2e-7 * du_q, 1e-8 * u_inf))
    assert np.sum(du_q > 1e-4 * u_inf) > 100                        # exits mid-squeeze
    for c in ("t_star", "t_du", "t_ratio_1.1"):
        a, b = mixed[c].to_numpy(), quad[c].to_numpy()
        assert np.max(np.abs(a - b) / np.maximum(b, 0.1 * quad.t_star.to_numpy())) < 1e-6, c


def test_squeeze_out_rows_of_alpha_zero_are_the_base_engine(tables, fresh_memo, monkeypatch):
    """squeeze_out with α per case: the α = 0 rows (two moduli) are the base engine's numbers
    bit for bit (the constant-viscosity primitive, rate factor 1 exactly); the groups of
    α > 0 within 2e-7 of the quadrature in the target times and in ū − ū∞ at the times;
    the provenance lists each group's primitive."""
    monkeypatch.setattr(btime, "MIN_GROUP_ROWS", 50)
    rng = np.random.default_rng(12)
    n = 400
    alpha, E, k = _fluids(n)
    c = _cases(rng, n, tables)
    kw = dict(p0=c["p0"], E_star=E, R=R, eta=ETA, theory="emt", ratios=(1.1,),
              du=(1e-8,), times=(0.0, 1e-4, 3e-3, np.inf))
    fast = squeeze_out_piezo(tables, alpha_pv=alpha, method="fast", **kw)
    prov = fast.attrs["barus_time_primitive"]
    assert sorted(g["alpha_E_star"] for g in prov) == [0.0, A1 * E1, A2 * E1]
    assert sum(g["cases_served"] for g in prov) == n
    z = k == 3
    base = fc.squeeze_out(tables, **{**kw, "p0": kw["p0"][z], "E_star": E[z]})
    names = ["u_inf", "u_start", "t_star", "t_ratio_1.1", "t_du_1e-08", "u_at_0.0001",
             "u_at_0.003"]
    for col in names:
        np.testing.assert_array_equal(fast[col][z].to_numpy(), base[col].to_numpy(), col)
    np.testing.assert_array_equal(fast.rate_factor_start[z], 1.0)
    quad = squeeze_out_piezo(tables, alpha_pv=alpha, method="quad", **kw)
    assert list(fast.status) == list(quad.status) and (fast.status == "ok").all()
    for col in ("t_star", "t_ratio_1.1", "t_du_1e-08"):
        np.testing.assert_allclose(fast[col], quad[col], rtol=2e-7, err_msg=col)
    u_inf = fast.u_inf.to_numpy()
    for col in ("u_at_0.0001", "u_at_0.003"):
        du, duq = fast[col].to_numpy() - u_inf, quad[col].to_numpy() - quad.u_inf.to_numpy()
        assert np.all(np.abs(du - duq) <= np.maximum(2e-7 * duq, 1e-8 * u_inf)), col


def test_row_groups_against_a_plain_grouping():
    """fastcontact._core.groups.row_groups against a dict of tuples built row by row: the same
    groups (keys and rows) for the groups large enough or kept, largest first, at most
    ``most``; a kept key of a small group is served, an absent one changes nothing."""
    from fastcontact._core.groups import row_groups

    rng = np.random.default_rng(3)
    n = 5000
    a = rng.choice([1e-6, 2e-6, 3e-6, 4e-6], n, p=[0.5, 0.3, 0.15, 0.05])
    b = rng.choice([1e7, 2e7], n, p=[0.8, 0.2])
    plain = {}
    for i, key in enumerate(zip(a.tolist(), b.tolist())):
        plain.setdefault(key, []).append(i)
    for min_rows, most, kept in ((300, 8, ()), (300, 2, ()), (10**6, 8, [(4e-6, 2e7)]),
                                 (10**6, 8, [(5e-6, 1e7)])):
        got = row_groups([a, b], min_rows, most, kept)
        want = sorted(((k, v) for k, v in plain.items() if len(v) >= min_rows or k in kept),
                      key=lambda kv: -len(kv[1]))[:most]
        assert [g[0] for g in got] == [k for k, _ in want]
        for (_k, rows), (_k2, v) in zip(got, want):
            np.testing.assert_array_equal(rows, v)
    assert row_groups([a[:0], b[:0]], 1, 8) == []
