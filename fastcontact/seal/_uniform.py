"""Flat-ring driver of :func:`fastcontact.seal.seal_leak` (private): validation, then one
parallel numba pass (:func:`fastcontact.seal._leak.uniform_rows`) writing every result column.

Lorenz & Persson (2010), eq. (32) with the fluid feedback p0 = p_cont + p_f (28), for a
uniform nominal pressure: q = (1/L) ∫_{p0−p_a}^{p0−p_b} σ_eff(p) dp.

Inputs that are scalars (or size 1) stay scalars down to the kernel, which also writes their
per-row copies for the result; inputs with one value per row are used as they are (no copy).
"""
from __future__ import annotations

import math

import numpy as np

from .._core.validate import check_positive
from ..kernels.readonly import readonly_fields
from . import _leak

__all__ = ["leak_uniform", "ECHO"]

#: the inputs in the kernel's order, named as result columns
ECHO = ("p0", "L", "dp", "L_y", "E_star", "eta", "p_b", "alpha_cj")


def _rows(arrays):
    """(shape, flat arrays): each input flat, of size 1 or of the broadcast size n (inputs of
    another shape are broadcast and copied, the general NumPy case)."""
    shape = np.broadcast_shapes(*(a.shape for a in arrays))
    n = math.prod(shape)
    flat = []
    for a in arrays:
        if a.size == 1:
            flat.append(np.ascontiguousarray(a, dtype=np.float64).reshape(1))
        elif a.shape == shape:
            flat.append(np.ascontiguousarray(a, dtype=np.float64).reshape(-1))
        else:
            flat.append(np.ascontiguousarray(np.broadcast_to(a, shape), dtype=np.float64)
                        .reshape(-1))
    return shape, n, flat


def leak_uniform(sc, theory, p0, L, com, alpha_cj):
    """Result columns of flat-ring rows (``status`` as int8 codes of ``api.STATUS``).

    Parameters
    ----------
    sc : SealContext
        Context of (tables, theory).
    theory : str
        Flow theory ("critical_junction" rescales σ̄ by (α_cj/α_table)³).
    p0 : array_like
        Nominal contact pressure [Pa], > 0.
    L : array_like
        Seal width [m], > 0.
    com : dict
        Validated dp, L_y, E_star, eta, p_b (``_inputs.common_inputs``).
    alpha_cj : ndarray
        Validated junction factor [-].

    Returns
    -------
    cols : dict
        Column name → 1-D array (n rows).
    shape : tuple
        Broadcast shape of the inputs.
    """
    p0 = check_positive("p0", p0, "[Pa]")
    L = check_positive("L", L, "[m]")
    shape, n, flat = _rows([p0, L, com["dp"], com["L_y"], com["E_star"], com["eta"],
                            com["p_b"], np.asarray(alpha_cj, dtype=np.float64)])
    need = np.array([f.size != n for f in flat], dtype=np.bool_)
    echo = np.empty((len(ECHO), n if need.any() else 0))
    Q = np.empty(n)
    st = np.empty(n, dtype=np.int8)
    p_a = np.empty(n)
    lift = np.empty(n, dtype=np.bool_)
    perc = np.empty(n, dtype=np.bool_)
    open_in = np.empty(n)
    _leak.uniform_rows(sc.tab, sc.rec, readonly_fields(_leak.RingRows(*flat)),
                       theory == "critical_junction", float(sc.alpha_table),
                       _leak.RingOut(Q, st, p_a, lift, perc, open_in, echo), need)
    cols = {name: (echo[j] if need[j] else flat[j]) for j, name in enumerate(ECHO)}
    cols.update(Q=Q, lift_off=lift, percolated=perc, status=st, p_a=p_a, open_inlet=open_in,
                open_outlet=np.zeros(n))
    return cols, shape
