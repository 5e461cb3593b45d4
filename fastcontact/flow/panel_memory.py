"""Warm starts of the effective-medium quadrature during a table build (private).

The adaptive Gauss–Kronrod quadrature in A of :func:`fastcontact.flow.conductivity.sigma_bar`
starts each pressure on four equal panels and halves the worst panel until its error estimate
meets the tolerance; every halving discards the 15 u1 quadratures of the halved panel. The
table build evaluates σ̄ at the midpoints of its intervals, between two nodes already known:
:class:`PanelMemory` keeps each computed pressure's final partition and starts a new pressure
on a neighbour's, so the splits already made there are not repeated. The stopping rule is the
same, so the result meets the same tolerance; only the order of the splits differs.
"""
from __future__ import annotations

import numpy as np

from ._kernels import EMT_MAX_PANELS

__all__ = ["PanelMemory"]


class PanelMemory:
    """Final partitions of the effective-medium quadrature by ln p̄ (sorted)."""

    def __init__(self):
        self.lnp = np.empty(0)
        self.breaks = np.zeros((0, EMT_MAX_PANELS + 1))
        self.count = np.zeros(0, dtype=np.int64)

    def starts(self, lnp):
        """(start, nstart) for the pressures ln p̄ = lnp: a neighbour's final partition."""
        if self.lnp.size == 0:
            return np.zeros((lnp.size, EMT_MAX_PANELS + 1)), np.zeros(lnp.size, dtype=np.int64)
        j = np.searchsorted(self.lnp, lnp)
        left = np.clip(j - 1, 0, self.lnp.size - 1)
        right = np.clip(j, 0, self.lnp.size - 1)
        cl, cr = self.count[left], self.count[right]
        # the neighbour with fewer panels (a start with more panels than this pressure needs
        # computes nodes no split would have asked for); a percolated neighbour (0) never; the
        # pressure itself where it is recorded (another quadrature of the same u1 nodes)
        pick = np.where(((cl <= cr) & (cl > 0)) | (cr == 0), left, right)
        pick = np.where(self.lnp[right] == lnp, right, pick)
        return self.breaks[pick], self.count[pick]  # copies (fancy indexing)

    def add(self, lnp, breaks, count):
        """Record the final partitions of the pressures ln p̄ = lnp."""
        lnp_all = np.concatenate((self.lnp, lnp))
        order = np.argsort(lnp_all, kind="stable")
        self.lnp = lnp_all[order]
        self.breaks = np.concatenate((self.breaks, breaks))[order]
        self.count = np.concatenate((self.count, count))[order]
