"""Steady Reynolds flow on a periodic gap field: the effective conductivity σ_eff [m³/(Pa·s)].

The thin-film (lubrication) equation for an incompressible Newtonian fluid in a gap g(x)

    ∇·( σ(x) ∇p ) = 0,      σ(x) = g(x)³ / (12 η)                                  (R1)

is solved by cell-centred finite volumes on an n×n periodic grid of spacing ``a`` with an
imposed mean pressure gradient: p = -G·x + p̃ with p̃ periodic. The conductance of a face
between two cells is the harmonic mean of the cell conductivities,

    k_f = 2 σ_i σ_j / (σ_i + σ_j)        (k_f = 0 if either cell is in contact),      (R2)

which makes the scheme exact for strips in series (σ_eff = 1/⟨1/σ⟩) and in parallel
(σ_eff = ⟨σ⟩) and blocks flow through every contact pixel. The effective conductivity in the
direction of the gradient is the area-averaged flux density divided by G:

    σ_xx = (1/N) Σ_{x-faces} k_f (1 + (p̃_i - p̃_{i+x}) / (G a)).                   (R3)

Cells that no open face connects to the rest (trapped fluid pockets, contact pixels) form
separate components of the sparse graph; p̃ is pinned to 0 at one cell of every component so
that the (symmetric, positive semi-definite) system is solved exactly by a sparse direct
factorisation (:func:`scipy.sparse.linalg.spsolve`).

References: O. Reynolds, Phil. Trans. R. Soc. 177, 157 (1886), doi:10.1098/rstl.1886.0005;
N. Patir & H.S. Cheng, J. Lubr. Technol. 100, 12 (1978), doi:10.1115/1.3453103 (flow factors
from the gap field); W.B. Dapp, A. Lücke, B.N.J. Persson & M.H. Müser, Phys. Rev. Lett. 108,
244301 (2012), doi:10.1103/PhysRevLett.108.244301 (the same construction on a BEM gap field).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["reynolds_conductivity", "FLOW_ZERO"]

#: σ_ii below FLOW_ZERO·⟨σ_cell⟩ is reported as exactly 0 (no percolating open channel; the
#: direct solve leaves round-off of ~1e-16 there)
FLOW_ZERO = 1e-11


def _check_gap(gap):
    g = np.asarray(gap, dtype=np.float64)
    if g.ndim != 2 or g.shape[0] != g.shape[1] or g.shape[0] < 2:
        raise ValueError(f"gap with shape {g.shape} is invalid: must be a square n×n array, "
                         f"n >= 2 [m]")
    if not np.all(np.isfinite(g)) or np.any(g < 0.0):
        raise ValueError("gap is invalid: must be finite and >= 0 everywhere [m] "
                         f"(min {np.nanmin(g):.6g})")
    return g


def _harmonic(a, b):
    s = a + b
    out = np.zeros_like(s)
    np.divide(2.0 * a * b, s, out=out, where=s > 0.0)
    return out


def _solve(k_cells, axes):
    """σ_ii / scale for a gradient along each of ``axes`` (0 = x, 1 = y), one factorisation."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    from scipy.sparse.linalg import splu

    n = k_cells.shape[0]
    N = n * n
    idx = np.arange(N).reshape(n, n)
    kf = [_harmonic(k_cells, np.roll(k_cells, -1, axis=ax)) for ax in (0, 1)]
    rows = np.concatenate([idx.ravel(), idx.ravel()])
    cols = np.concatenate([np.roll(idx, -1, axis=0).ravel(), np.roll(idx, -1, axis=1).ravel()])
    vals = np.concatenate([kf[0].ravel(), kf[1].ravel()])
    keep = vals > 0.0
    if not keep.any():
        return [0.0 for _ in axes]
    off = sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(N, N)).tocsr()
    off = off + off.T
    diag = np.asarray(off.sum(axis=1)).ravel()
    A = (sp.diags(diag) - off).tocsr()
    # pin p̃ = 0 at one cell of every connected component (isolated cells included)
    _, labels = connected_components(off, directed=False)
    _, first = np.unique(labels, return_index=True)
    free = np.ones(N, dtype=bool)
    free[first] = False
    lu = splu(A[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A") if free.any() else None
    out = []
    for ax in axes:
        kg = kf[ax]
        # right-hand side for G·a = 1: b_i = -(k_f(i, i+1) - k_f(i-1, i))
        b = -(kg - np.roll(kg, 1, axis=ax)).ravel()
        pt = np.zeros(N)
        if lu is not None:
            pt[free] = lu.solve(b[free])
        pt = pt.reshape(n, n)
        out.append(float(np.mean(kg * (1.0 + pt - np.roll(pt, -1, axis=ax)))))
    return out


def reynolds_conductivity(gap, eta, *, directions=("x", "y")):
    """Effective conductivity of a periodic gap field by the Reynolds equation (R1)–(R3).

    Parameters
    ----------
    gap : (n, n) array_like
        Local gap g ≥ 0 [m] on a square periodic grid (contact pixels: g = 0). The grid spacing
        cancels in (R3): σ_eff of a square periodic cell does not depend on it.
    eta : float
        Fluid viscosity η [Pa·s], > 0.
    directions : tuple of {"x", "y"}
        Directions of the imposed mean pressure gradient (x = axis 0, y = axis 1).

    Returns
    -------
    dict
        ``{"x": σ_xx, "y": σ_yy}`` [m³/(Pa·s)] for the requested directions. A direction in
        which no open channel percolates returns exactly 0.0 (values below
        ``FLOW_ZERO``·⟨σ_cell⟩ are round-off of the direct solve).
    """
    g = _check_gap(gap)
    eta = float(eta)
    if not (eta > 0.0 and math.isfinite(eta)):
        raise ValueError(f"eta = {eta!r} is invalid: must be finite and > 0 [Pa·s]")
    for d in directions:
        if d not in ("x", "y"):
            raise ValueError(f"directions = {directions!r} is invalid: entries must be 'x' or 'y'")
    gmax = float(g.max())
    if gmax <= 0.0:
        return {d: 0.0 for d in directions}
    k = (g / gmax) ** 3  # scaled: σ = k · gmax³/(12η)
    scale = gmax ** 3 / (12.0 * eta)
    kmean = float(k.mean())
    vals = _solve(k, [0 if d == "x" else 1 for d in directions])
    return {d: (0.0 if s <= FLOW_ZERO * kmean else s * scale) for d, s in zip(directions, vals)}
