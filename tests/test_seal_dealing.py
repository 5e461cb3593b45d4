"""Rows and chains of the soft-seal solver dealt to the threads (fastcontact.seal.context).

A parallel loop gives each thread one contiguous block of its iterations; the seal solver's
rows often come sorted (grid lines of a table, chains sorted by p_H), so the rows are dealt
(0, T, 2T, ... then 1, T+1, ...) before the loop. Dealing may change the time a call takes,
never a result: each row (each chain) is solved on its own.
"""
from __future__ import annotations

import math

import numba
import numpy as np
import pytest

import fastcontact as fc
from fastcontact.seal import context
from fastcontact.seal.viscosity import seal_leak_piezo

E_STAR = 1e7


def _random_chains(rng, nc):
    lens = rng.integers(1, 6, nc)
    bounds = np.zeros(nc + 1, dtype=np.int64)
    np.cumsum(lens, out=bounds[1:])
    rows = rng.permutation(10 * bounds[-1])[:bounds[-1]].astype(np.int64)
    return rows, bounds


@pytest.mark.parametrize("threads", [2, 3, 4])
@pytest.mark.parametrize("nc", [1, 5, 8, 37])
def test_spread_chains_keeps_every_chain_whole_and_deals_them(threads, nc):
    rng = np.random.default_rng([threads, nc])
    rows, bounds = _random_chains(rng, nc)
    chains = [tuple(rows[bounds[c]:bounds[c + 1]]) for c in range(nc)]
    out, nb = context.spread_chains(rows, bounds, threads)
    assert nb[0] == 0 and nb[-1] == rows.size and np.all(np.diff(nb) > 0)
    got = [tuple(out[nb[c]:nb[c + 1]]) for c in range(nb.size - 1)]
    # the same chains, each whole and in its own order, each exactly once
    assert sorted(got) == sorted(chains)
    if nc < 2 * threads:
        assert got == chains
        return
    where = [chains.index(g) for g in got]  # original (sorted) position of each dealt chain
    # numba's static split: thread t runs the chains of one contiguous block; every block
    # of the dealt order spans the whole sorted range, each block's chains in sorted order
    for blk in np.array_split(np.asarray(where), threads):
        assert blk.min() < threads and blk.max() >= nc - threads
        assert np.all(np.diff(blk) == threads)


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_dealt_is_a_permutation_in_strides(monkeypatch, threads):
    monkeypatch.setattr(numba, "get_num_threads", lambda: threads)
    idx = np.arange(3, 50, dtype=np.int32) * 7
    got = context.dealt(idx)
    assert got.dtype == np.int64 and got.flags.c_contiguous
    assert sorted(got.tolist()) == sorted(idx.tolist())
    head = idx[0::threads] if threads > 1 else idx
    assert np.array_equal(got[:head.size], head)


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
