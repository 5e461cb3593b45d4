"""Gauss quadrature rules as plain NumPy data (no numba: importing them compiles nothing, so
the surface layer can use them); re-exported by :mod:`fastcontact.kernels.quadrature`, the
package's one source of quadrature nodes."""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

__all__ = ["GL_ORDER", "QuadRule", "gauss_legendre", "gauss_hermite"]

#: default Gauss–Legendre order of the contact-mechanics panels
GL_ORDER = 10


class QuadRule(NamedTuple):
    """Nodes ``x`` on [-1, 1] and weights ``w`` of a quadrature rule (contiguous float64)."""

    x: np.ndarray
    w: np.ndarray


@lru_cache(maxsize=None)
def gauss_legendre(n: int = GL_ORDER) -> QuadRule:
    """Gauss–Legendre nodes and weights of order ``n`` on [-1, 1] (cached; do not mutate).

    Parameters
    ----------
    n : int
        Number of nodes, >= 1 (default 10).

    Returns
    -------
    QuadRule
        ``(x, w)``, contiguous float64 arrays; a 2-tuple, so ``x, w = gauss_legendre(n)``.
    """
    x, w = np.polynomial.legendre.leggauss(int(n))
    return QuadRule(np.ascontiguousarray(x), np.ascontiguousarray(w))


@lru_cache(maxsize=None)
def gauss_hermite(n: int) -> QuadRule:
    """Gauss–Hermite nodes and weights (weight e^{-x²} on the real line), cached."""
    x, w = np.polynomial.hermite.hermgauss(int(n))
    return QuadRule(np.ascontiguousarray(x), np.ascontiguousarray(w))
