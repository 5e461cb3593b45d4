"""Issue 14.5: Barus and Roelands O-rings of one fluid on one rubber from a verified table of W.

With one α and one E* (p_b = 0) the reduced resistance W of a Barus O-ring is a function of
(π_H, π_a) alone, so the base O-ring table (``fastcontact/seal/hertz.py``) serves it: built per
α̃ = α E* by the same solver, every cell verified at its centre before use
(``seal_leak_piezo`` → ``_barus_hertz_k_tabled``).

References: the adaptive DOP853 shooting of the Reynolds equation with η(p) written in p
itself (``tests/reference/ext_reynolds.py``: no reduced pressure); the per-row solver
(``TABLE_MIN_ROWS`` raised so that every row is solved), itself checked against that shooting
in test_ext_viscosity.py.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_reynolds import hertz_shoot  # noqa: E402

import fastcontact as fc  # noqa: E402
import fastcontact.seal.hertz as sh  # noqa: E402
import fastcontact.seal.viscosity as sv  # noqa: E402
from fastcontact.seal.viscosity import seal_leak_piezo  # noqa: E402

E_STAR, ETA, L_Y, R = 1e7, 1e-3, 0.1, 2e-3


@pytest.fixture(scope="module")
def tables():
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    return fc.precompute(psd, theories=("critical_junction", "emt"))


def _orings(n, seed, alpha, designs=None):
    """n O-rings of radius R: p_H/E* log-uniform in [2e-3, 0.02] (``designs``: that many
    O-rings, each in a Δp sweep), Δp/p_H in [1e-3, 0.99]."""
    rng = np.random.default_rng(seed)
    lp = rng.uniform(math.log(2e-3), math.log(0.02), designs or n)
    pH = np.exp(lp if designs is None else np.repeat(lp, -(-n // designs))[:n]) * E_STAR
    a = 2.0 * R * pH / E_STAR                  # Hertz line contact: p_H = E* a/(2R)
    f_N = math.pi * a * pH / 2.0
    dp = rng.uniform(1e-3, 0.99, n) * pH
    return dict(dp=dp, L_y=L_Y, E_star=E_STAR, eta=ETA, alpha_pv=alpha, profile="hertz", R=R,
                f_N=f_N), pH, a


def _solver_only(tables, kw, monkeypatch):
    with monkeypatch.context() as m:
        m.setattr(sv, "TABLE_MIN_ROWS", 10 ** 12)
        return seal_leak_piezo(tables, **kw)


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_table_against_the_solver(tables, theory, monkeypatch):
    """Δp sweeps of 4 O-rings of one fluid (6,000 rows, α p_H up to 0.8): Q from the fluid's
    table within 1e-7 of the per-row solver, the same statuses; the table is the one of that
    α̃ and serves most rows; in a call of two fluids (3,000 rows each) the first fluid's rows
    read its kept table (its call's numbers exactly), every row within 1e-7 of the solver; with
    p_b > 0 the solver's, number for number; 600 O-rings of a wide spread of contact pressures, each its own, do not pay
    for a table of their own (solved), and read it once it is kept."""
    alpha = 4e-6
    kw, _pH, _a = _orings(6000, 1, alpha, designs=4)
    kw["theory"] = theory
    calls = []
    real = sh.table_W

    def spy(sc, piH, pia, rows, al=0.0, vis=None, max_solves=None):
        W = real(sc, piH, pia, rows, al, vis, max_solves)
        if W is not None:  # the table was read (None: not worth completing it)
            calls.append((al, int(np.isfinite(W[rows]).sum()), rows.size))
        return W

    monkeypatch.setattr(sh, "table_W", spy)
    got = seal_leak_piezo(tables, **kw)
    assert len(calls) == 1 and calls[0][0] == alpha * E_STAR
    assert calls[0][1] > 0.9 * calls[0][2]                     # most rows from the table
    ref = _solver_only(tables, kw, monkeypatch)
    assert list(got.status) == list(ref.status)
    ok = (ref.status == "ok").to_numpy()
    assert ok.sum() > 5000
    np.testing.assert_allclose(got.Q[ok], ref.Q[ok], rtol=1e-7, atol=0)
    calls.clear()
    even = np.arange(6000) % 2 == 0
    two = dict(kw, alpha_pv=np.where(even, alpha, 0.5 * alpha))   # two fluids, 3,000 rows each
    got2 = seal_leak_piezo(tables, **two)
    assert alpha * E_STAR in [c[0] for c in calls]             # the first fluid's kept table
    np.testing.assert_array_equal(got2.Q[even], got.Q[even])   # its rows as in its own call
    ref2 = _solver_only(tables, two, monkeypatch)
    ok2 = (ref2.status == "ok").to_numpy()
    assert list(got2.status) == list(ref2.status) and ok2.sum() > 5000
    np.testing.assert_allclose(got2.Q[ok2], ref2.Q[ok2], rtol=1e-7, atol=0)
    calls.clear()
    back = dict(kw, p_b=1e3)
    np.testing.assert_array_equal(seal_leak_piezo(tables, **back).Q,
                                  _solver_only(tables, back, monkeypatch).Q)
    assert calls == []                          # neither read a table
    wide, _pH, _a = _orings(600, 4, 0.5 * alpha)
    wide["theory"] = theory
    calls.clear()
    np.testing.assert_array_equal(seal_leak_piezo(tables, **wide).Q,
                                  _solver_only(tables, wide, monkeypatch).Q)
    assert calls == []                                         # not worth a table
    seal_leak_piezo(tables, **dict(wide, dp=np.repeat(wide["dp"], 40),
                                   f_N=np.repeat(wide["f_N"], 40)))  # 24,000 rows: built
    again = seal_leak_piezo(tables, **wide)                           # now read
    assert calls[-1][1] > 0.9 * calls[-1][2]
    np.testing.assert_allclose(again.Q, _solver_only(tables, wide, monkeypatch).Q, rtol=1e-7)


def test_table_against_shooting_reference(tables):
    """Rows from the fluid's table against the DOP853 shooting of the Reynolds equation with
    η(p) in p (no reduced pressure): within 3e-7 (the table's cells are verified to 2e-7 in
    ln W against the solver, whose own error is ~1e-10)."""
    alpha = 2e-5                                   # α p_H from 0.4 to 4
    kw, pH, a = _orings(2500, 2, alpha, designs=2)
    kw["theory"] = "emt"
    got = seal_leak_piezo(tables, **kw)
    ht = sh.hertz_table(sv.seal_context(tables, "emt"), alpha * E_STAR)
    assert ht is not sh.hertz_table(sv.seal_context(tables, "emt"))  # not the base table
    assert ht.built.any() and (ht.cell == 1).any()
    plo = tables.p_range[0] * E_STAR

    def sigma(pc):
        return tables.conductivity(np.maximum(pc, plo * (1 + 1e-7)), E_STAR, ETA, "emt")

    sc = sv.seal_context(tables, "emt")
    rows = np.array([3, 11, 2000])
    W = sh.table_W(sc, pH / E_STAR, (kw["dp"]) / E_STAR, rows, alpha * E_STAR)
    assert np.all(np.isfinite(W[rows]))                        # these rows: from the table
    assert np.unique(pH[rows]).size == 2                       # both O-rings
    for i in rows:
        ref = hertz_shoot(sigma, pH[i], a[i], kw["dp"][i], 0.0, alpha) * L_Y
        assert abs(got.Q[i] / ref - 1) < 3e-7, i


def test_roelands_table_against_the_solver(tables, monkeypatch):
    """A Roelands fluid's O-rings (one law, Δp sweeps of 4 O-rings, 6,000 rows; the table
    keyed by the law (A, Z, p_r/E*)): Q within 1e-7 of the per-row solver, the same
    statuses, most rows from the table; a call of two laws (3,000 rows each): the first law's
    rows from its kept table (its call's numbers to round-off: W is the kept table's, ψ_a is
    read from one ψ table reaching each call's largest drop), every row within 1e-7 of the
    solver."""
    kw, _pH, _a = _orings(6000, 3, 4e-6, designs=4)
    kw.update(theory="emt", viscosity="roelands", roelands_z=0.6, roelands_p_r=2e5)
    calls = []
    real = sh.table_W

    def spy(sc, piH, pia, rows, al=0.0, vis=None, max_solves=None):
        W = real(sc, piH, pia, rows, al, vis, max_solves)
        if W is not None:
            calls.append((vis, int(np.isfinite(W[rows]).sum()), rows.size))
        return W

    monkeypatch.setattr(sh, "table_W", spy)
    got = seal_leak_piezo(tables, **kw)
    assert len(calls) == 1 and calls[0][0] is not None and calls[0][0][1] == 0.6
    assert calls[0][1] > 0.8 * calls[0][2]
    ref = _solver_only(tables, kw, monkeypatch)
    assert list(got.status) == list(ref.status)
    ok = (ref.status == "ok").to_numpy()
    assert ok.sum() > 5000
    np.testing.assert_allclose(got.Q[ok], ref.Q[ok], rtol=1e-7, atol=0)
    calls.clear()
    even = np.arange(6000) % 2 == 0
    two = dict(kw, roelands_z=np.where(even, 0.6, 0.5))          # two laws, 3,000 rows each
    got2 = seal_leak_piezo(tables, **two)
    assert 0.6 in [c[0][1] for c in calls]                     # the first law's kept table
    np.testing.assert_allclose(got2.Q[even], got.Q[even], rtol=1e-13, atol=0)
    ref2 = _solver_only(tables, two, monkeypatch)
    ok2 = (ref2.status == "ok").to_numpy()
    assert list(got2.status) == list(ref2.status) and ok2.sum() > 5000
    np.testing.assert_allclose(got2.Q[ok2], ref2.Q[ok2], rtol=1e-7, atol=0)
