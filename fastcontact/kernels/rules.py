"""Gauss quadrature rules as plain NumPy data (no numba: importing them compiles nothing, so
the surface layer can use them); re-exported by :mod:`fastcontact.kernels.quadrature`, the
package's one source of quadrature nodes."""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

__all__ = ["GL_ORDER", "QuadRule", "gauss_legendre", "gauss_lobatto", "gauss_hermite"]

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
def gauss_lobatto(n: int) -> QuadRule:
    """Gauss–Lobatto nodes and weights of ``n`` >= 3 points on [-1, 1], both ends included
    (exact for polynomials of degree 2n - 3; cached; do not mutate).

    Interior nodes are the roots of P'_{n-1} (polished by Newton on P'_{n-1}), weights
    2/(n(n - 1) P_{n-1}(x)²) (Abramowitz & Stegun 25.4.32). A composite rule of such panels
    shares each panel end with its neighbour, where a caller often has the integrand already.
    """
    n = int(n)
    if n < 3:
        raise ValueError(f"gauss_lobatto: n = {n!r}; valid: n >= 3")
    from numpy.polynomial import legendre as L

    P = L.Legendre.basis(n - 1)
    dP, d2P = P.deriv(), P.deriv(2)
    xi = np.sort(dP.roots().real)
    for _ in range(3):
        xi = xi - dP(xi) / d2P(xi)
    x = np.concatenate(([-1.0], xi, [1.0]))
    w = 2.0 / (n * (n - 1) * P(x) ** 2)
    return QuadRule(np.ascontiguousarray(x), np.ascontiguousarray(w))


@lru_cache(maxsize=None)
def gauss_hermite(n: int) -> QuadRule:
    """Gauss–Hermite nodes and weights (weight e^{-x²} on the real line), cached."""
    x, w = np.polynomial.hermite.hermgauss(int(n))
    return QuadRule(np.ascontiguousarray(x), np.ascontiguousarray(w))
