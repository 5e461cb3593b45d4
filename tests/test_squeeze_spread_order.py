"""Blocks of cases of the squeeze-out kernels spread over the threads.

numba's parallel loop gives each thread one contiguous run of its iterations. The fast
squeeze-out and tire kernels (and the Barus ones) work on blocks of 128 cases; a study sorted
by pressure puts every row the primitive does not serve (quadrature: trapped fluid, pressures
beyond the primitive) in the last blocks, i.e. on one thread. The blocks are therefore visited
in van der Corput order (fastcontact.kernels.balance.spread_blocks). The order may change how
long a call takes, never a result: each case is computed on its own, so sorted, reversed and
shuffled inputs give the same rows bit for bit.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

from fastcontact.kernels.balance import spread_blocks, spread_order
from fastcontact.squeeze import squeeze_out
from fastcontact.squeeze.tire import tire_footprint
from fastcontact.tables import Tables
from fastcontact.tables.defaults import default_table_path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from frames import assert_columns_match  # noqa: E402
from spread_checks import runs_sample_the_range  # noqa: E402

E_STAR = 13e6


def _van_der_corput(n):
    """Independent definition: range(n) sorted by the bit-reversed value of each index over
    the bits of n - 1 (written with string reversal, not the library's bit arithmetic)."""
    if n <= 2:
        return list(range(n))
    bits = (n - 1).bit_length()
    return sorted(range(n), key=lambda i: int(format(i, f"0{bits}b")[::-1], 2))


@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 5, 7, 8, 9, 100, 127, 128, 129, 1000, 7813])
def test_spread_blocks_is_the_van_der_corput_order(n):
    got = spread_blocks(n)
    assert got.dtype == np.int64
    assert got.tolist() == _van_der_corput(n)
    assert np.array_equal(got, spread_order(n))


@pytest.mark.parametrize("n", [64, 300, 7813])
def test_every_static_run_of_blocks_samples_the_whole_range(n):
    order = spread_blocks(n)
    for threads in (2, 3, 4):
        assert runs_sample_the_range(order, n, threads), threads
        # the blocks in their own order fail the check (one thread, the last blocks)
        assert not runs_sample_the_range(np.arange(n), n, threads)


@pytest.fixture(scope="module")
def tables():
    return Tables.from_parquet(default_table_path("asphalt_024mm"))


def _pressures(tables, n, seed):
    """n pressures [Pa] sorted over the whole table and somewhat beyond its top (rows out of
    the table, trapped rows and rows the primitive does not serve are in the last blocks)."""
    lo, hi = tables.p_range
    rng = np.random.default_rng(seed)
    return np.sort(np.exp(rng.uniform(math.log(lo * E_STAR * 1.01), math.log(hi * E_STAR * 3.0),
                                      n)))


def _same_rows(a, b):
    """Bit for bit: the same columns, floats equal (NaN where NaN), others exactly."""
    assert list(a.columns) == list(b.columns)
    assert_columns_match(a, b, b.columns, rtol=0.0)


def _orders(n, seed):
    rng = np.random.default_rng(seed)
    return {"reversed": np.arange(n)[::-1].copy(), "shuffled": rng.permutation(n)}


def test_squeeze_out_rows_do_not_depend_on_the_order(tables):
    n = 3000  # 24 blocks
    p0 = _pressures(tables, n, 1)
    R = np.linspace(0.005, 0.03, n)
    kw = dict(E_star=E_STAR, eta=1e-3, theory="critical_junction", method="fast")
    ref = squeeze_out(tables, p0=p0, R=R, **kw)
    st = ref["status"].to_numpy()
    # the sorted input does put the special rows at the end
    assert (st[-n // 10:] != "ok").any() and (st[: n // 2] == "ok").all()
    assert np.isfinite(ref["t_star"].to_numpy()[st == "ok"]).all()
    for name, perm in _orders(n, 2).items():
        got = squeeze_out(tables, p0=p0[perm], R=R[perm], **kw)
        inv = np.argsort(perm)
        _same_rows(got.iloc[inv].reset_index(drop=True), ref)


def test_tire_footprint_rows_do_not_depend_on_the_order(tables):
    n = 2000
    p0 = _pressures(tables, n, 3)
    rng = np.random.default_rng(4)
    fl, sp = rng.uniform(0.05, 0.2, n), rng.uniform(5.0, 40.0, n)
    kw = dict(E_star=E_STAR, R=0.01, eta=1e-3, theory="critical_junction", method="fast",
              u_start=1e-3)
    ref = tire_footprint(tables, p0=p0, footprint_length=fl, speed=sp, **kw)
    assert (ref["status"].to_numpy() != "ok").any()
    for name, perm in _orders(n, 5).items():
        got = tire_footprint(tables, p0=p0[perm], footprint_length=fl[perm], speed=sp[perm],
                             **kw)
        _same_rows(got.iloc[np.argsort(perm)].reset_index(drop=True), ref)


def test_barus_squeeze_rows_do_not_depend_on_the_order(tables):
    n = 1500
    p0 = _pressures(tables, n, 6)
    alpha = np.geomspace(1e-9, 1e-8, n)  # every row its own fluid: the per-case Barus kernel
    kw = dict(E_star=E_STAR, R=0.01, eta=1e-3, theory="critical_junction", method="fast")
    ref = squeeze_out(tables, p0=p0, alpha_pv=alpha, **kw)
    assert (ref["status"].to_numpy() == "ok").sum() > n // 2
    perm = _orders(n, 7)["shuffled"]
    got = squeeze_out(tables, p0=p0[perm], alpha_pv=alpha[perm], **kw)
    _same_rows(got.iloc[np.argsort(perm)].reset_index(drop=True), ref)
