"""A result never shares memory with the caller's input arrays.

The validated inputs are views of the caller's arrays where no conversion was needed, and the
result frames are built without a copy of the kernels' outputs. Before the fix the input
columns (``p0``, ``E_star``, ``R``, ``eta``, ``dp``, ``t``, ``p_eval``, ...) were those views:
a caller who refilled its input buffer for the next study changed the rows of the study
before, silently (every engine below did). Each call here keeps a deep copy of its result,
overwrites every input array in place and checks that the result did not move.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from fastcontact import seal_leak, squeeze_history, squeeze_out, tire_footprint, tire_history
from fastcontact.tables.defaults import load_default_tables


@pytest.fixture(scope="module")
def T():
    return load_default_tables("asphalt_024mm")


def _a(*v):
    return np.array(v, dtype=np.float64)


def _squeeze(method, **extra):
    return lambda T, a: squeeze_out(T, method=method, **a, **extra), dict(
        p0=_a(2e5, 3e5, 4e5), E_star=_a(13e6, 13e6, 14e6), R=_a(0.02, 0.02, 0.03),
        eta=_a(1e-3, 1e-3, 2e-3), u_start=_a(1e-3, 1e-3, 2e-3))


def _tire(**extra):
    return lambda T, a: tire_footprint(T, **a, **extra), dict(
        p0=_a(2e5, 3e5, 4e5), E_star=_a(13e6, 13e6, 14e6), R=_a(0.02, 0.02, 0.03),
        eta=_a(1e-3, 1e-3, 2e-3), footprint_length=_a(0.1, 0.1, 0.2), speed=_a(30.0, 20.0, 10.0),
        rho=_a(1e3, 1e3, 1e3), u_start=_a(1e-2, 1e-2, 2e-2))


def _flat_ring(**extra):
    return lambda T, a: seal_leak(T, **a, **extra), dict(
        p0=_a(2e6, 3e6, 4e6), dp=_a(1e5, 2e5, 3e5), L=_a(1e-3, 1e-3, 2e-3),
        L_y=_a(0.1, 0.1, 0.2), E_star=_a(13e6, 13e6, 14e6), eta=_a(1e-3, 1e-3, 2e-3),
        p_b=_a(0.0, 1e4, 0.0))


def _o_ring(**extra):
    return lambda T, a: seal_leak(T, profile="hertz", **a, **extra), dict(
        dp=_a(1e4, 2e4, 3e4), L_y=_a(0.1, 0.1, 0.2), E_star=_a(13e6, 13e6, 14e6),
        eta=_a(1e-3, 1e-3, 2e-3), R=_a(1e-3, 1e-3, 2e-3), f_N=_a(100.0, 200.0, 300.0),
        p_b=_a(0.0, 1e3, 0.0))


_T_HIST = np.geomspace(1e-6, 1.0, 5)
CALLS = {
    "squeeze_out fast": _squeeze("fast"),
    "squeeze_out quad": _squeeze("quad"),
    "squeeze_out Barus": _squeeze("fast", alpha_pv=_a(1e-8, 2e-8, 1e-8)),
    "squeeze_out Barus quad": _squeeze("quad", alpha_pv=_a(1e-8, 2e-8, 1e-8)),
    "tire_footprint": _tire(),
    "tire_footprint Barus": _tire(alpha_pv=_a(1e-8, 1e-8, 2e-8)),
    "tire_history": (lambda T, a: tire_history(T, p0=2e5, E_star=13e6, R=0.02, eta=1e-3, **a),
                     dict(t=_T_HIST.copy())),
    "squeeze_history": (lambda T, a: squeeze_history(T, 2e5, 13e6, 0.02, 1e-3,
                                                     "critical_junction", **a),
                        dict(t=_T_HIST.copy())),
    "seal_leak flat ring": _flat_ring(),
    "seal_leak flat ring Barus": _flat_ring(alpha_pv=_a(1e-8, 1e-8, 2e-8)),
    "seal_leak flat ring Roelands": _flat_ring(viscosity="roelands",
                                               alpha_pv=_a(1e-8, 1e-8, 2e-8)),
    "seal_leak O-ring": _o_ring(),
    "seal_leak O-ring Barus": _o_ring(alpha_pv=_a(1e-8, 1e-8, 2e-8)),
}


@pytest.mark.parametrize("name", list(CALLS))
def test_result_does_not_change_when_the_inputs_are_refilled(T, name):
    call, inputs = CALLS[name]
    df = call(T, inputs)
    kept = df.copy(deep=True)
    for c in df.columns:
        if df[c].dtype.kind in "fbiu":
            col = df[c].to_numpy()
            for k, v in inputs.items():
                assert not np.shares_memory(col, v), (name, c, k)
    for v in inputs.values():
        v *= 3.0  # the caller's next study in the same buffers
        v += 1.0
    pd.testing.assert_frame_equal(df, kept)
