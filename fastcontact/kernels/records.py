"""Named scalar records for numba kernels (private).

A kernel that needs a dozen scalars of one kind (a table's bounds, a seal's re-tabulation
origin and step, ...) takes them as one *record*: a one-element, aligned NumPy structured
array whose fields carry the names. Kernels read ``rec[0].name``; the record passes by
reference, so it costs what a float array indexed by slot constants cost, without the slots.

Why not a namedtuple of scalars: numba 0.68's parfor lowering fails when a namedtuple of
scalars is captured by a ``prange`` body (AttributeError in ``_create_gufunc_for_parfor_body``),
and the records here reach the innermost loops of parallel kernels. A structured array does
not have that limit (tests/test_records.py checks it, a helper called in a prange body too).
"""
from __future__ import annotations

import numpy as np

__all__ = ["scalar_record", "record_dtype"]


def record_dtype(names, ints=()) -> np.dtype:
    """The aligned structured dtype of a record: float64 fields, int64 for ``ints``."""
    names = tuple(names)
    unknown = set(ints) - set(names)
    if unknown:
        raise ValueError(f"ints names fields the record does not have: {sorted(unknown)}")
    return np.dtype([(n, np.int64 if n in ints else np.float64) for n in names], align=True)


def scalar_record(fields, ints=()) -> np.ndarray:
    """A one-element structured array holding ``fields`` (a mapping name -> value), in order.

    Parameters
    ----------
    fields : mapping of str to float
        The record's fields and values; float64 unless named in ``ints`` (int64).
    ints : iterable of str
        Names of the integer fields.

    Returns
    -------
    numpy.ndarray
        Shape (1,), aligned structured dtype; read in kernels as ``rec[0].name``.
    """
    rec = np.zeros(1, dtype=record_dtype(fields.keys(), ints))
    for name, value in fields.items():
        rec[0][name] = value
    return rec
