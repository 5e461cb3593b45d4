"""The derived output columns (fastcontact.squeeze._columns) against the NumPy expressions of
their definitions: status flags, ū at the footprint exit relative to ū∞, the inertia estimates
of Sec. 5 (τ' = (D²ρ/(64 p))^{1/2}, t*' = τ' ln(ū(0)/h_rms))."""
from __future__ import annotations

import math

import numpy as np
import pytest

from fastcontact.squeeze import _kernels as qk
from fastcontact.squeeze._columns import exit_columns, inertia_columns, status_flags

RNG = np.random.default_rng(7)
N = 5003  # not a multiple of any block or thread count


def _status():
    st = RNG.integers(0, 5, N).astype(np.int8)
    u_trap = np.where(RNG.random(N) < 0.5, RNG.uniform(1e-7, 1e-5, N), np.nan)
    return st, u_trap


def test_status_flags_are_the_definitions():
    st, u_trap = _status()
    p0, E, x_perc = RNG.uniform(1e3, 1e6, N), 1e7, math.log(3e-2)
    trapped, perc, oot = status_flags(st, u_trap, p0, np.array([E]), x_perc)
    want = (st == qk.ST_TRAPPED) | ((st == qk.ST_OVERFLOW) & np.isfinite(u_trap))
    assert np.array_equal(trapped, want) and trapped.any() and not trapped.all()
    assert np.array_equal(perc, want & (np.log(p0 / E) >= x_perc)) and perc.any()
    assert np.array_equal(oot, st == qk.ST_OUT)
    # per-row E*, no percolation (x_perc not finite), no percolation column asked for
    _, perc2, _ = status_flags(st, u_trap, p0, np.full(N, E), math.nan)
    assert perc2.dtype == bool and not perc2.any()
    t3, perc3, o3 = status_flags(st, u_trap)
    assert perc3 is None and np.array_equal(t3, want) and np.array_equal(o3, oot)


def test_exit_columns_nan_rows_are_not_complete():
    u_inf = RNG.uniform(1e-6, 2e-6, N)
    u_exit = u_inf + RNG.uniform(0.0, 2e-6, N)
    u_exit[::7] = np.nan
    du, done = exit_columns(u_exit, u_inf, 1e-6)
    assert np.array_equal(du, u_exit - u_inf, equal_nan=True)
    with np.errstate(invalid="ignore"):
        assert np.array_equal(done, (u_exit - u_inf) <= 1e-6)
    assert not done[::7].any() and done.any() and not done.all()


@pytest.mark.parametrize("shared", [True, False], ids=["one_u_start", "u_start_per_row"])
def test_inertia_columns_are_sec5_formulas(shared):
    R, rho, h = RNG.uniform(0.005, 0.03, N), 1000.0, 1e-5
    p = RNG.uniform(2e4, 1e6, N)
    u0 = np.array(1e-2) if shared else RNG.uniform(0.2e-5, 1e-2, N)  # some <= h_rms
    tau, ts = inertia_columns(R, np.array(rho), p, u0, h)
    tau_want = np.sqrt((2 * R) ** 2 * rho / (64 * p))
    assert np.allclose(tau, tau_want, rtol=1e-15, atol=0)
    u = np.broadcast_to(u0, (N,))
    with np.errstate(invalid="ignore"):
        ts_want = np.where(u > h, tau_want * np.log(u / h), np.nan)
    assert np.allclose(ts, ts_want, rtol=1e-15, atol=0, equal_nan=True)
    assert np.isnan(ts).any() != shared
    # the paper's example (Sec. 5): D = 2 cm, ρ = 1000 kg/m³, p0 = 0.3 MPa → τ' = 1.4434e-4 s
    one, none = inertia_columns(np.array(0.01), np.array(1000.0), np.array([3e5]), None, h)
    assert one[0] == pytest.approx(1.4434e-4, rel=1e-4) and np.isnan(none).all()


def test_history_columns_are_the_model_and_stefan_law():
    """p_cont/p0 from the model's π_c(v) (the record-passing kernel ``model.p_of_v``,
    tables and the eq. (3) tail above their top), p̄_f = p0 (1 − p_cont/p0), and the
    flat-substrate Stefan law of ``reduced.flat_separation`` (0 at t = inf) — bit for bit,
    for times in order (the blocks' interval hint) and shuffled (hint misses)."""
    from fastcontact.squeeze import squeeze_model
    from fastcontact.squeeze._columns import history_columns
    from fastcontact.squeeze.reduced import flat_separation
    from fastcontact.tables import Tables
    from fastcontact.tables.defaults import default_table_path
    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    model = squeeze_model(T, "emt")
    h = model.h_rms
    p0, E, eta, R, us = 2e5, 13e6, 1e-3, 0.02, 3e-3
    v = np.geomspace(model.mp.v_top * 3.0, 0.5 * math.exp(model.tab.lnu[-1]), 20_000)
    # ^ the tail, the table, below its lowest separation (NaN)
    u = v * h
    t = np.concatenate([[0.0], np.geomspace(1e-8, 1e3, v.size - 2), [np.inf]])
    for order in (np.arange(v.size), RNG.permutation(v.size)):
        ratio, pf, flat = history_columns(model, u[order], t[order], p0, E, eta, R, us)
        want = model.p_of_v(u[order] / h) / (p0 / E)
        assert np.array_equal(ratio, want, equal_nan=True)
        assert np.isnan(ratio).any() and (np.log(v[order][np.isnan(ratio)]) < model.tab.lnu[-1]).all()
        assert np.array_equal(pf, p0 * (1.0 - want), equal_nan=True)
        fin = np.isfinite(t[order])
        f_want = np.where(fin, flat_separation(us, np.where(fin, t[order], 0.0), p0, eta, R), 0.0)
        assert np.array_equal(flat, f_want)
    assert (v > model.mp.v_top).any()


def test_hinted_locate_is_locate():
    """locate_desc_from returns locate_desc's interval whatever the hint (right, off by
    one or more, outside the table), also at the nodes themselves."""
    from numba import njit

    from fastcontact.kernels.locate import build_bucket_map, locate_desc, locate_desc_from

    @njit
    def both(ys, yd, lo, dz, idx, hints, a, b):
        for k in range(ys.size):
            a[k] = locate_desc(ys[k], yd, lo, dz, idx)
            b[k] = locate_desc_from(ys[k], yd, lo, dz, idx, hints[k])

    yd = np.sort(RNG.uniform(-5.0, 3.0, 150))[::-1].copy()
    lo, dz, idx = build_bucket_map(yd)
    ys = np.concatenate([RNG.uniform(-6.0, 4.0, 20_000), yd, [yd[0], yd[-1]]])
    a = np.empty(ys.size, dtype=np.int64)
    b = np.empty_like(a)
    for hints in (np.full(ys.size, -1), RNG.integers(-2, yd.size + 2, ys.size)):
        both(ys, yd, lo, dz, idx, hints, a, b)
        assert np.array_equal(a, b)
    both(ys, yd, lo, dz, idx, np.maximum(a, 0), a, b)  # each its own interval as hint
    assert np.array_equal(a, b) and (a == -1).any()
