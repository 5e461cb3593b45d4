"""Cubic and quintic Hermite interpolation, numba kernels and their NumPy twins (one copy).

On an interval [x0, x1] with values y, first derivatives d and (quintic) second derivatives s
given at both ends, the interpolant reproduces all of them; the error is O(h⁴) (cubic) and
O(h⁶) (quintic).
"""
from __future__ import annotations

from numba import njit

from ._index import clamp_index

__all__ = ["cubic_basis", "cubic_uniform", "quintic_interval", "quintic_unit", "quintic_np"]


@njit(cache=True, inline="always")
def cubic_basis(t, h):
    """Cubic Hermite basis at t = (x - x0)/h in [0, 1] on an interval of width h: the weights
    (h00, h10, h01, h11) of y0, d0, y1, d1 (d the derivatives in x)."""
    t2 = t * t
    t3 = t2 * t
    return (2.0 * t3 - 3.0 * t2 + 1.0, (t3 - 2.0 * t2 + t) * h, -2.0 * t3 + 3.0 * t2,
            (t3 - t2) * h)


@njit(cache=True)
def cubic_uniform(t, t0, dt, val, der):
    """Cubic Hermite on the uniform grid ``t0 + i dt`` with values and d/dt (clamped ends)."""
    x = (t - t0) / dt
    i = clamp_index(int(x), val.size - 2)
    u = x - i
    u2 = u * u
    u3 = u2 * u
    return ((2 * u3 - 3 * u2 + 1) * val[i] + (u3 - 2 * u2 + u) * dt * der[i]
            + (-2 * u3 + 3 * u2) * val[i + 1] + (u3 - u2) * dt * der[i + 1])


@njit(cache=True, inline="always")
def _quintic_value(t, h, y0, d0, s0, y1, d1, s1):
    """The quintic Hermite polynomial at t = (x - x0)/h in [0, 1] (one copy for both kernels).

    Parameters
    ----------
    t : float
        Unit variable (x - x0)/h [-].
    h : float
        Interval width x1 - x0 [units of x].
    y0, d0, s0 : float
        Value, d/dx and d²/dx² at x0.
    y1, d1, s1 : float
        Value, d/dx and d²/dx² at x1.

    Returns
    -------
    float
        The interpolant [units of y].
    """
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    t5 = t4 * t
    return ((1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5) * y0
            + (t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5) * h * d0
            + 0.5 * (t2 - 3.0 * t3 + 3.0 * t4 - t5) * h * h * s0
            + (10.0 * t3 - 15.0 * t4 + 6.0 * t5) * y1
            + (-4.0 * t3 + 7.0 * t4 - 3.0 * t5) * h * d1
            + 0.5 * (t3 - 2.0 * t4 + t5) * h * h * s1)


@njit(cache=True)
def quintic_interval(x, x0, x1, y0, y1, d0, d1, s0, s1):
    """Quintic Hermite at ``x`` on [x0, x1] from values y, first derivatives d, second s."""
    h = x1 - x0
    return _quintic_value((x - x0) / h, h, y0, d0, s0, y1, d1, s1)


@njit(cache=True, inline="always")
def quintic_unit(t, h, y0, d0, s0, y1, d1, s1):
    """(value, d/dx) of the quintic Hermite at t = (x - x0)/h in [0, 1], interval width h.

    Same polynomial as :func:`quintic_interval` (written in the unit variable t), plus its slope.
    """
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    val = _quintic_value(t, h, y0, d0, s0, y1, d1, s1)
    der = ((-30.0 * t2 + 60.0 * t3 - 30.0 * t4) * y0
           + (1.0 - 18.0 * t2 + 32.0 * t3 - 15.0 * t4) * h * d0
           + 0.5 * (2.0 * t - 9.0 * t2 + 12.0 * t3 - 5.0 * t4) * h * h * s0
           + (30.0 * t2 - 60.0 * t3 + 30.0 * t4) * y1
           + (-12.0 * t2 + 28.0 * t3 - 15.0 * t4) * h * d1
           + 0.5 * (3.0 * t2 - 8.0 * t3 + 5.0 * t4) * h * h * s1)
    return val, der / h


def quintic_np(x, x0, x1, y0, y1, d0, d1, s0, s1, deriv=False):
    """NumPy twin of :func:`quintic_interval` (broadcasts); ``deriv=True``: its d/dx."""
    h = x1 - x0
    t = (x - x0) / h
    if deriv:
        return ((-30 * t ** 2 + 60 * t ** 3 - 30 * t ** 4) * y0 / h
                + (1 - 18 * t ** 2 + 32 * t ** 3 - 15 * t ** 4) * d0
                + 0.5 * (2 * t - 9 * t ** 2 + 12 * t ** 3 - 5 * t ** 4) * h * s0
                + (30 * t ** 2 - 60 * t ** 3 + 30 * t ** 4) * y1 / h
                + (-12 * t ** 2 + 28 * t ** 3 - 15 * t ** 4) * d1
                + 0.5 * (3 * t ** 2 - 8 * t ** 3 + 5 * t ** 4) * h * s1)
    return ((1 - 10 * t ** 3 + 15 * t ** 4 - 6 * t ** 5) * y0
            + (t - 6 * t ** 3 + 8 * t ** 4 - 3 * t ** 5) * h * d0
            + 0.5 * (t ** 2 - 3 * t ** 3 + 3 * t ** 4 - t ** 5) * h * h * s0
            + (10 * t ** 3 - 15 * t ** 4 + 6 * t ** 5) * y1
            + (-4 * t ** 3 + 7 * t ** 4 - 3 * t ** 5) * h * d1
            + 0.5 * (t ** 3 - 2 * t ** 4 + t ** 5) * h * h * s1)
