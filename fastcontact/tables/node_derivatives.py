"""Derivatives at tabulation nodes from local polynomials through the nodes themselves.

Used where a tabulated column has no closed-form derivative (the critical-junction and
effective-medium σ̄ of the tables, the directional σ̄_xx, σ̄_yy of anisotropic tables): the
quintic Hermite interpolants need d y/dx and d²y/dx² at the nodes.
"""
from __future__ import annotations

import numpy as np

__all__ = ["NODE_STENCIL", "local_derivatives"]

#: nodes per local polynomial (degree 8) of the tables' σ̄ columns (:mod:`fastcontact.tables.
#: build`) and of their directional columns, chosen in bench/tables_results.md (2026-11-26):
#: against the degree-4 stencils (effective medium) and central differences (critical junction,
#: two more quadratures per pressure) used before, 25 % fewer nodes (the refinement towards
#: percolation needs fewer nodes with better derivatives) and a worst random-point error of
#: σ̄ of 1.5e-7 instead of 5.9e-7 (the critical junction away from percolation: <= 1.5e-7,
#: was <= 1.3e-8)
NODE_STENCIL = 9


def local_derivatives(x, y, ok, width):
    """(dy/dx, d²y/dx²) at the open nodes (``ok``) from the polynomial of degree width - 1
    through the ``width`` nearest open nodes (one-sided at the ends of the open range); 0 at
    the other nodes and everywhere when fewer than 3 nodes are open."""
    d = np.zeros_like(y)
    d2 = np.zeros_like(y)
    idx = np.flatnonzero(ok)
    m = idx.size
    if m < 3:
        return d, d2
    w = min(width, m)
    k = np.arange(m)
    lo = np.clip(k - w // 2, 0, m - w)
    sten = idx[lo[:, None] + np.arange(w)[None, :]]            # (m, w) node indices
    dx = x[sten] - x[idx][:, None]                             # local abscissae
    V = dx[:, :, None] ** np.arange(w)[None, None, :]          # Vandermonde (m, w, w)
    coef = np.linalg.solve(V, y[sten][:, :, None])[:, :, 0]
    d[idx] = coef[:, 1]
    d2[idx] = 2.0 * coef[:, 2]
    return d, d2
