"""Index clamping shared by the table and bucket-map kernels (numba, ``@njit(cache=True)``),
and the integer constants jitted helpers are called with."""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["clamp_index", "INT0", "INT1"]

#: the integers 0 and 1 as arguments of jitted helpers: numba compiles a helper once per
#: literal int it is called with (``f(0, ...)`` and ``f(1, ...)`` are two compiles of several
#: seconds each, a third for a variable); a NumPy integer is typed int64, as a variable is
INT0, INT1 = np.int64(0), np.int64(1)


@njit(cache=True)
def clamp_index(i, hi):
    """``i`` clamped to [0, hi].

    Parameters
    ----------
    i : int
        Index, e.g. ``int((x - x0) / dx)`` [-].
    hi : int
        Largest valid index [-], >= 0.

    Returns
    -------
    int
        ``min(max(i, 0), hi)``.
    """
    if i < 0:
        i = 0
    if i > hi:
        i = hi
    return i
