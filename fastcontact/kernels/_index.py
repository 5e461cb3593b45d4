"""Index clamping shared by the table and bucket-map kernels (numba, ``@njit(cache=True)``)."""
from __future__ import annotations

from numba import njit

__all__ = ["clamp_index"]


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
