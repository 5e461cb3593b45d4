"""Barus O-rings with one α per row (p_b = 0) from the verified table of W(π_H, π_a, α p_H).

``fastcontact/seal/hertz.py`` (:func:`~fastcontact.seal.hertz.table_W_beta`): a study over
many oils, none with enough rows for a table of its own, reads one table whose third
coordinate is b = α p_H ∈ [0, B_MAX], built line by line for the rows of a call and verified
cell by cell against the solver before use.

References: the per-row solver (``TABLE_MIN_ROWS`` raised so that every row is solved) for
many rows, and for a handful of table rows the adaptive DOP853 shooting of the Reynolds
equation in the fluid pressure itself (``tests/reference/ext_reynolds.py``), independent of
the engine's panel solver and of its tables.
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
from fastcontact.seal.context import seal_context  # noqa: E402

E_STAR, ETA, L_Y, R = 1e7, 1e-3, 0.1, 2e-3
#: Q from the table against the per-row solver and the shooting reference (cells verified to
#: VERIFY_TOL = 2e-7 in ln W against the tight solver)
RTOL = 1e-6
SURFACE = dict(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
PH = 0.01 * E_STAR                   # one O-ring design: p_H = 100 kPa
A = 2.0 * R * PH / E_STAR            # Hertz line contact: p_H = E* a/(2R)


@pytest.fixture()
def tables():
    """Fresh tables for each test: the β table is kept with the seal context."""
    return fc.precompute(fc.SelfAffinePSD(**SURFACE), theories=("critical_junction",))


def _orings(n, seed, b_max=1.0):
    """n O-rings of the design PH with Δp/p_H uniform in [1e-3, 0.99], p_b = 0 and a distinct
    α per row, α p_H log-uniform in [1e-3, b_max]."""
    rng = np.random.default_rng(seed)
    alpha = np.exp(rng.uniform(math.log(1e-3), math.log(b_max), n)) / PH
    dp = rng.uniform(1e-3, 0.99, n) * PH
    return dict(profile="hertz", R=R, f_N=math.pi * A * PH / 2.0, dp=dp, L_y=L_Y,
                E_star=E_STAR, eta=ETA, alpha_pv=alpha)


def _solved(tables, kw, monkeypatch):
    with monkeypatch.context() as m:
        m.setattr(sv, "TABLE_MIN_ROWS", 10 ** 12)
        return fc.seal_leak(tables, **kw)


def _rel(a, b):
    return np.abs(np.asarray(a) / np.asarray(b) - 1.0)


def test_scattered_oils_from_the_table(tables, monkeypatch):
    """6,000 O-rings, each of its own oil (no fluid table pays): the call builds the b table
    (its first rows' solves cost fewer than the rows), every row is read from it (every cell
    verified), Q within 1e-6 of the per-row solver, the same statuses; a second call of other
    oils (2,000 rows) reads the kept table without solving a line again."""
    kw = _orings(6000, 1)
    got = fc.seal_leak(tables, **kw)
    ref = _solved(tables, kw, monkeypatch)
    ht = sh.hertz_beta_table(seal_context(tables, "critical_junction")).rec
    assert ht.built.any() and (ht.cell == 1).sum() > 0 and not (ht.cell == 2).any()
    assert list(got.status) == list(ref.status) and (ref.status == "ok").all()
    assert _rel(got.Q, ref.Q).max() <= RTOL
    assert not np.any(got.Q.to_numpy() == ref.Q.to_numpy())     # not the solver's numbers
    built = ht.built.sum()
    kw2 = _orings(2000, 2)
    got2 = fc.seal_leak(tables, **kw2)
    ref2 = _solved(tables, kw2, monkeypatch)
    assert _rel(got2.Q, ref2.Q).max() <= RTOL
    assert not np.any(got2.Q.to_numpy() == ref2.Q.to_numpy())   # read from the table
    ht = sh.hertz_beta_table(seal_context(tables, "critical_junction")).rec
    assert ht.built.sum() == built                               # no line solved again


def test_table_rows_against_shooting(tables):
    """Rows the table serves against the adaptive DOP853 shooting of the Reynolds equation
    with η = η0 e^{α p_f}: within 1e-6."""
    kw = _orings(6000, 3)
    got = fc.seal_leak(tables, **kw)
    ht = sh.hertz_beta_table(seal_context(tables, "critical_junction")).rec
    assert ht.built.any()
    plo = tables.p_range[0] * E_STAR

    def sigma(pc):
        return tables.conductivity(np.maximum(pc, plo * (1 + 1e-7)), E_STAR, ETA,
                                   "critical_junction")

    for i in np.random.default_rng(4).choice(6000, 4, replace=False):
        q = hertz_shoot(sigma, PH, A, kw["dp"][i], 0.0, kw["alpha_pv"][i]) * L_Y
        assert abs(got.Q[i] / q - 1.0) <= RTOL, (i, got.Q[i], q)


def test_rows_the_table_does_not_take(tables, monkeypatch):
    """Rows past b = α p_H > B_MAX and rows with p_b > 0 are the solver's numbers exactly, in
    a call whose other rows read the table; a call with too few rows to pay for the table
    does not build it (the solver's numbers exactly)."""
    few = _orings(800, 5)
    got = fc.seal_leak(tables, **few)
    assert not sh.hertz_beta_table(seal_context(tables, "critical_junction")).rec.built.any()
    np.testing.assert_array_equal(got.Q, _solved(tables, few, monkeypatch).Q)
    kw = _orings(7000, 6)
    n_out = 300
    kw["alpha_pv"][:n_out] = np.linspace(1.01, 3.0, n_out) * sh.B_MAX / PH      # b > B_MAX
    p_b = np.zeros(7000)
    p_b[n_out:2 * n_out] = 0.1 * kw["dp"][n_out:2 * n_out]                     # p_b > 0
    kw["p_b"] = p_b
    kw["dp"] = kw["dp"] * np.where(p_b > 0, 0.9, 1.0)                        # p_a < p_H
    got = fc.seal_leak(tables, **kw)
    ref = _solved(tables, kw, monkeypatch)
    assert list(got.status) == list(ref.status)
    side = np.arange(7000) < 2 * n_out
    assert sh.hertz_beta_table(seal_context(tables, "critical_junction")).rec.built.any()
    ok = (ref.status == "ok").to_numpy()
    assert _rel(got.Q[ok & ~side], ref.Q[ok & ~side]).max() <= RTOL
    assert not np.any(got.Q[ok & ~side].to_numpy() == ref.Q[ok & ~side].to_numpy())
    solo = _solved(tables, {**kw, **{k: kw[k][side] for k in ("dp", "alpha_pv", "p_b")}},
                   monkeypatch)
    a, b = got.Q[side].to_numpy(), solo.Q.to_numpy()
    assert np.all((a == b) | (np.isnan(a) & np.isnan(b)))
