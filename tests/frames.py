"""Comparisons of result frames shared by tests (not a reference: no physics here)."""
from __future__ import annotations

import numpy as np


def assert_columns_match(df, full, cols, rtol=1e-7):
    """Each column of ``cols`` in ``df`` equals ``full``'s: floats to ``rtol``, others exactly."""
    for c in cols:
        a, b = df[c].to_numpy(), full[c].to_numpy()
        if a.dtype.kind in "fc":
            np.testing.assert_allclose(a, b, rtol=rtol, err_msg=c)
        else:
            assert (a == b).all(), c
