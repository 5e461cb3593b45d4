"""The soft-seal solver's records (private): the sealing zone, Newton states, work arrays and
output mesh of :mod:`._panels`, as flat namedtuples of arrays and scalars so that they pass
into numba kernels by name (one argument each instead of two dozen positional arrays).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

__all__ = ["Zone", "State", "Work", "Mesh"]


class Zone(NamedTuple):
    """The sealing zone of one case (one argument instead of seven): profile kind (0 Hertz,
    1 array), zone parameters gp (:func:`._mesh.zone_params`), the array profile's samples
    xg, pg, the reduced pressures π_a, π_b at the ends, the fluid's reduced Barus
    coefficient α̃ = α_pv E* (0: constant viscosity; :mod:`._panels`) and its Roelands law
    vis = (A, Z, π_r = p_r/E*) (A = vis[0] > 0: a Roelands fluid, then al = 0;
    :mod:`._roelands_psi`)."""

    kind: int
    gp: np.ndarray
    xg: np.ndarray
    pg: np.ndarray
    pia: float
    pib: float
    al: float
    vis: np.ndarray


class State(NamedTuple):
    """One Newton state at the nodes: contact pressure c, resistance density r = dξ/dt / σ̄(c),
    D = dr/dc, tail integrals R̃, residuals F and (Roelands fluids only) η/η0 at the nodes'
    fluid pressure, kept from the residual for the Newton matrix."""

    c: np.ndarray
    r: np.ndarray
    D: np.ndarray
    Rt: np.ndarray
    F: np.ndarray
    er: np.ndarray


class Work(NamedTuple):
    """Work arrays of one soft-seal solve, allocated once per case (one argument instead of
    two dozen): node positions t, ξ, dξ/dt, e_a, e_b; Newton's current and trial states
    (:class:`State`); the right-hand sides y1, y2 and the panel blocks Y (n×2), K (n×n); the
    mesh pan and its refinement pan2, panel errors err; the Legendre series coef, after, Pk."""

    t: np.ndarray
    xi: np.ndarray
    dxi: np.ndarray
    ea: np.ndarray
    eb: np.ndarray
    s0: State
    s1: State
    y1: np.ndarray
    y2: np.ndarray
    Y: np.ndarray
    K: np.ndarray
    pan: np.ndarray
    pan2: np.ndarray
    err: np.ndarray
    coef: np.ndarray
    after: np.ndarray
    Pk: np.ndarray


class Mesh(NamedTuple):
    """A solution on its mesh: panel edges pan (PMAX+1), nodal contact pressure c and
    resistance density r (PMAX·n)."""

    pan: np.ndarray
    c: np.ndarray
    r: np.ndarray


@njit(cache=True)
def _state(N):
    return State(np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.empty(N))


@njit(cache=True)
def _work(n, PMAX):
    """The :class:`Work` of a mesh of up to PMAX panels of n nodes."""
    N = PMAX * n
    return Work(np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.empty(N), _state(N),
                _state(N), np.empty(N), np.empty(N), np.empty((n, 2)), np.empty((n, n)),
                np.empty(PMAX + 1), np.empty(PMAX + 1), np.empty(PMAX), np.empty((PMAX, n)),
                np.empty(PMAX), np.empty(n + 1))
