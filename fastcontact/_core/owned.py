"""Result columns that own their memory (private).

The validated inputs of a call are NumPy views of the caller's arrays wherever no conversion
was needed (a contiguous float64 array is used as is: no copy per call). A result frame built
from them without a copy (``pd.DataFrame(..., copy=False)``, to spare the kernels' output
columns a copy) would then show the caller's memory in its input columns (``p0``, ``E_star``,
``dp``, ``t``, ...): a caller who refills its input buffer for the next study would change
the rows of the study before, silently. The frame builders pass those columns through
:func:`own`; the kernels' outputs are fresh arrays and need nothing.
"""
from __future__ import annotations

import numpy as np

__all__ = ["own", "own_columns"]


def own(a):
    """``a`` if it is not a NumPy array or owns its memory, else a copy of it (a view: of a
    caller's array, or of one of ours; the copy costs one pass over the column)."""
    if isinstance(a, np.ndarray) and not a.flags.owndata:
        return a.copy()
    return a


def own_columns(cols, names):
    """``cols`` (a dict of columns) with the columns ``names`` that it holds passed through
    :func:`own` (in place; returns ``cols``)."""
    for c in names:
        if c in cols:
            cols[c] = own(cols[c])
    return cols
