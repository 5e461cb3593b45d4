"""Rows and chains of the soft-seal solver spread over the threads (fastcontact.seal.context).

A parallel loop gives each thread one contiguous block of its iterations; the seal solver's
rows often come sorted (grid lines of a table, chains sorted by p_H), so the rows and chains
go to the loop in the van der Corput order of fastcontact.kernels.balance.spread_order. The
order may change the time a call takes, never a result: each row (each chain) is solved on
its own.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

import fastcontact as fc
from fastcontact.seal import context
from fastcontact.seal.viscosity import seal_leak_piezo

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from spread_checks import runs_sample_the_range  # noqa: E402

E_STAR = 1e7


def _random_chains(rng, nc):
    lens = rng.integers(1, 6, nc)
    bounds = np.zeros(nc + 1, dtype=np.int64)
    np.cumsum(lens, out=bounds[1:])
    rows = rng.permutation(10 * bounds[-1])[:bounds[-1]].astype(np.int64)
    return rows, bounds


def _samples_evenly(where, n, threads):
    """Every static split of ``where`` (original positions in a sorted range of n) into
    1..threads blocks samples the whole range (:func:`spread_checks.runs_sample_the_range`)."""
    for T in range(1, min(threads, n) + 1):
        assert runs_sample_the_range(where, n, T), (T, where)


@pytest.mark.parametrize("nc", [1, 2, 5, 8, 37, 200])
def test_spread_chains_keeps_every_chain_whole_and_spreads_them(nc):
    rng = np.random.default_rng(nc)
    rows, bounds = _random_chains(rng, nc)
    chains = [tuple(rows[bounds[c]:bounds[c + 1]]) for c in range(nc)]
    out, nb = context.spread_chains(rows, bounds)
    assert nb[0] == 0 and nb[-1] == rows.size and np.all(np.diff(nb) > 0)
    got = [tuple(out[nb[c]:nb[c + 1]]) for c in range(nb.size - 1)]
    # the same chains, each whole and in its own order, each exactly once
    assert sorted(got) == sorted(chains)
    # numba's static split: thread t runs one contiguous block of the chains; every block
    # samples the whole sorted range (no thread gets only the costly high-p_H rings)
    _samples_evenly([chains.index(g) for g in got], nc, 4)


@pytest.mark.parametrize("n", [0, 1, 3, 47, 500])
def test_spread_rows_is_a_spread_permutation(n):
    idx = (np.arange(n, dtype=np.int32) + 3) * 7
    got = context.spread_rows(idx)
    assert got.dtype == np.int64 and got.flags.c_contiguous
    assert sorted(got.tolist()) == idx.tolist()
    if n > 2:
        _samples_evenly((got // 7 - 3).tolist(), n, 4)


@pytest.fixture(scope="module")
def tables():
    return fc.precompute(fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8),
                         theories=("emt",))


@pytest.mark.parametrize("law", ["barus", "roelands"])
def test_soft_seal_rows_do_not_depend_on_the_batch_order(tables, law):
    """O-rings of scattered p_H and fluids (each row solved on its own), given sorted by p_H
    and in reverse: Q and the status of every row bit for bit the same."""
    rng = np.random.default_rng(5)
    n = 40
    pH = np.sort(np.exp(rng.uniform(math.log(2e-3), math.log(0.05), n))) * E_STAR
    a = 2e-3 * 2.0 * pH / E_STAR
    kw = dict(profile="hertz", R=2e-3, f_N=math.pi * a * pH / 2.0,
              dp=rng.uniform(0.01, 0.95, n) * pH, L_y=0.1, E_star=E_STAR, eta=1e-3,
              theory="emt", alpha_pv=rng.uniform(1e-6, 5e-6, n))
    if law == "roelands":
        kw.update(viscosity="roelands", roelands_z=rng.uniform(0.5, 0.7, n), roelands_p_r=2e5)
    fwd = seal_leak_piezo(tables, **kw)
    rev = seal_leak_piezo(tables, **{k: v[::-1] if isinstance(v, np.ndarray) else v
                                     for k, v in kw.items()})
    assert (fwd.status == "ok").all()
    assert np.array_equal(fwd.Q.to_numpy(), rev.Q.to_numpy()[::-1])
    assert list(fwd.status) == list(rev.status)[::-1]
