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
