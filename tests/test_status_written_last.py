"""A row's status is the last value a per-case kernel writes for it.

A numba worker thread that fails inside a prange body stops without raising: the rows it had
not finished keep whatever their arrays held. Every engine starts its status array at
``NOT_COMPUTED`` and ``check_computed`` raises on any row still holding it, which catches a
failed row only if the kernel writes the row's status after every other step of the row.

These tests run the per-case kernels' Python source (numba's ``py_func``) with one later step
made to fail on one row, skip that row as a failed thread would, and require the engine to
raise the RuntimeError naming it instead of returning the row with status "ok".
"""
from __future__ import annotations

import numpy as np
import pytest

import fastcontact as fc
from fastcontact.squeeze import _kernels as qk
from fastcontact.squeeze import api
from fastcontact.squeeze import tire_piezo
from fastcontact.squeeze import viscosity

P0 = np.array([2e5, 3e5, 4e5])
KW = dict(E_star=1e7, R=0.01, eta=1e-3)


@pytest.fixture(scope="module")
def tables():
    return fc.precompute(fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8),
                         theories=("critical_junction",))


class _FailOnce:
    """A stand-in for a kernel step that raises on its ``nth`` call and otherwise calls the
    compiled step."""

    def __init__(self, step, nth):
        self.step, self.nth, self.calls = step, nth, 0

    def __call__(self, *args):
        self.calls += 1
        if self.calls == self.nth:
            raise ZeroDivisionError("injected failure of one row")
        return self.step(*args)


def _rows_as_threads(case_py, n_of, index_pos):
    """A stand-in for a prange kernel: each row by the case function's Python source, a row
    whose step raises left as it is (as a failed worker thread leaves it)."""
    def kernel(*args):
        for i in range(n_of(args)):
            a = list(args)
            # the scalars record array: attribute access to its fields in Python, the same
            # numba type as the plain structured array
            a[1] = a[1].view(np.recarray)
            a.insert(index_pos, np.int64(i))
            try:
                case_py(*a)
            except ZeroDivisionError:
                pass
    return kernel


def test_base_quadrature_row_failing_after_its_state_is_not_returned(tables, monkeypatch):
    from fastcontact.squeeze import _fastpath as fp

    def kernel(tab, mp, cs, h, tg, quad, out):  # quad_kernel's rows, as its prange body
        sE, sR, seta, sus = fp._case_strides(cs)
        for i in range(cs.p0.size):
            Ri = cs.R[i * sR]
            tau = 3.0 * cs.eta[i * seta] * Ri * Ri / (2.0 * h * h * cs.p0[i])
            try:
                qk.quad_case.py_func(tab, mp, np.log(cs.p0[i] / cs.E[i * sE]),
                                     cs.us[i * sus] / h, tg, tau, h, quad, np.int64(i), out)
            except ZeroDivisionError:
                continue
            fp._flag_overflow(tau, tg, h, np.int64(i), out)
            fp._tau0(tau, np.int64(i), out)
    monkeypatch.setattr(qk, "_case_times", _FailOnce(qk._case_times, 2))
    monkeypatch.setattr(api, "quad_kernel", kernel)
    with pytest.raises(RuntimeError, match="1 of 3 rows were not computed .first: row 1."):
        fc.squeeze_out(tables, p0=P0, theory="critical_junction", method="quad", **KW)


def test_barus_quadrature_row_failing_in_its_time_loop_is_not_returned(tables, monkeypatch):
    # the step that gives ū at each time (it walks exit_w): one call per row here
    monkeypatch.setattr(viscosity, "v_at_time", _FailOnce(viscosity.v_at_time, 2))
    monkeypatch.setattr(viscosity, "_piezo_kernel", _rows_as_threads(
        viscosity._piezo_case.py_func, lambda a: a[2].p0.size, 7))
    with pytest.raises(RuntimeError, match="1 of 3 rows were not computed .first: row 1."):
        fc.squeeze_out(tables, p0=P0, theory="critical_junction", method="quad",
                       alpha_pv=1e-8, times=[1e-3], **KW)


def test_barus_tire_row_failing_at_its_exit_is_not_returned(tables, monkeypatch):
    # _tire_case(tab, sc, cs, alpha, t_fp, h, tg, quad, i, out)
    monkeypatch.setattr(tire_piezo, "v_at_time", _FailOnce(tire_piezo.v_at_time, 3))
    monkeypatch.setattr(tire_piezo, "_tire_kernel", _rows_as_threads(
        tire_piezo._tire_case.py_func, lambda a: a[2].p0.size, 8))
    with pytest.raises(RuntimeError, match="1 of 3 rows were not computed .first: row 2."):
        fc.tire_footprint(tables, p0=P0, theory="critical_junction", method="quad",
                          alpha_pv=1e-8, footprint_length=0.1, speed=20.0, **KW)


def test_unfailing_rows_pass_through_the_same_stand_ins(tables, monkeypatch):
    """The stand-ins themselves compute the rows the compiled kernels compute (so the three
    tests above fail only through the injected step)."""
    ref = fc.squeeze_out(tables, p0=P0, theory="critical_junction", method="quad",
                         alpha_pv=1e-8, times=[1e-3], **KW)
    monkeypatch.setattr(viscosity, "_piezo_kernel", _rows_as_threads(
        viscosity._piezo_case.py_func, lambda a: a[2].p0.size, 7))
    got = fc.squeeze_out(tables, p0=P0, theory="critical_junction", method="quad",
                         alpha_pv=1e-8, times=[1e-3], **KW)
    assert list(got["status"]) == list(ref["status"]) == ["ok"] * 3
    num = ref.select_dtypes("number").columns
    np.testing.assert_allclose(got[num].to_numpy(), ref[num].to_numpy(), rtol=1e-12)
