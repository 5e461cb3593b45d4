"""Named scalar records (fastcontact.kernels.records) in serial and parallel numba kernels."""
import numpy as np
import pytest
from numba import njit, prange

from fastcontact.kernels.records import record_dtype, scalar_record


@njit(cache=True)
def _affine(rec, x):
    return rec.a * x + rec.b + rec.n


@njit(cache=True, parallel=True)
def _affine_rows(rec, x, out):
    for i in prange(x.size):
        out[i] = _affine(rec[0], x[i]) * rec[0].a


def test_fields_keep_order_values_and_kinds():
    rec = scalar_record({"a": 2.5, "b": -1.0, "n": 3}, ints=("n",))
    assert rec.shape == (1,)
    assert rec.dtype.names == ("a", "b", "n")
    assert rec.dtype["n"] == np.int64 and rec.dtype["a"] == np.float64
    assert rec[0]["a"] == 2.5 and rec[0]["b"] == -1.0 and rec[0]["n"] == 3


def test_record_reaches_a_helper_inside_prange():
    rec = scalar_record({"a": 2.0, "b": 0.25, "n": 3}, ints=("n",))
    x = np.linspace(-1.0, 1.0, 1001)
    out = np.full(x.size, np.nan)
    _affine_rows(rec, x, out)
    np.testing.assert_array_equal(out, (2.0 * x + 0.25 + 3.0) * 2.0)


def test_unknown_int_field_is_refused():
    with pytest.raises(ValueError, match="ints"):
        record_dtype(("a",), ints=("b",))
