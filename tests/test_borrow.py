"""Borrowed views of kernel records (fastcontact.kernels.borrow): same data, no refcounts."""
import sys
from collections import namedtuple

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from fastcontact.kernels.borrow import borrowed

Rec = namedtuple("Rec", "a scale C inner")
Inner = namedtuple("Inner", "b n")


@njit(cache=True, inline="always")
def _weighted(rec, i):
    return rec.scale * rec.a[i] + rec.C[i % rec.C.shape[0], 1, 0] + rec.inner.b[i] * rec.inner.n


@njit(cache=True)
def _sum_plain(rec):
    s = 0.0
    for i in range(rec.a.size):
        s += _weighted(rec, i)
    return s


@njit(cache=True)
def _sum_borrowed(rec):
    return _sum_plain(borrowed(rec))


@njit(cache=True)
def _array_view(a):
    b = borrowed(a)
    return b[3] + b.sum(), b.shape[0], b.ctypes.data == a.ctypes.data


def _rec():
    rng = np.random.default_rng(5)
    return Rec(rng.random(1000), 1.5, rng.random((7, 3, 2)), Inner(rng.random(1000), 4))


def test_borrowed_record_reads_the_same_data():
    rec = _rec()
    # independent value: the same sum in NumPy
    ref = float(np.sum(rec.scale * rec.a + rec.C[np.arange(1000) % 7, 1, 0]
                       + rec.inner.b * rec.inner.n))
    assert _sum_plain(rec) == pytest.approx(ref, rel=1e-13)
    assert _sum_borrowed(rec) == _sum_plain(rec)


def test_borrowed_leaves_reference_counts_unchanged():
    rec = _rec()
    _sum_borrowed(rec)
    before = [sys.getrefcount(x) for x in (rec.a, rec.C, rec.inner.b)]
    for _ in range(50):
        _sum_borrowed(rec)
        _array_view(rec.a)
    assert [sys.getrefcount(x) for x in (rec.a, rec.C, rec.inner.b)] == before


def test_borrowed_array_is_a_view_of_the_same_memory():
    a = np.arange(10.0)
    val, n, same = _array_view(a)
    assert val == 3.0 + 45.0 and n == 10 and same


def test_borrowed_refuses_a_scalar():
    @njit
    def f(x):
        return borrowed(x)

    with pytest.raises(TypingError):
        f(1.0)
