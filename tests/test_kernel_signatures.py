"""One compiled signature per kernel, whatever arrays a user passes.

numba compiles a kernel once per argument type, and an array's type includes whether it is
writable. Before 2026-11-27 the same squeeze-out call compiled its fused kernel again (50–120 s
on two cores) when p0 was an array instead of a scalar (a read-only broadcast view), a pandas
column (read-only under copy-on-write), or when the tables came from Parquet instead of
``precompute`` — 13 compiles of ``fast_kernel`` in one run of the suite. Every public path
here is called with each of those flavours; each kernel it reaches must hold one signature.
(Signatures a worker compiled or loaded for earlier tests count too: they must be the same.)
"""
from __future__ import annotations

import sys

import numpy as np
import pandas as pd
import pytest

import fastcontact as fc
from fastcontact.tables import Tables
from fastcontact.tables.defaults import default_table_path

E, ETA, R, L_Y = 1e7, 1e-3, 0.02, 0.1


@pytest.fixture(scope="module")
def flavours():
    """The embedded tables as read from Parquet (read-only columns) and the same data as
    writable arrays (as ``precompute`` hands them out)."""
    ro = Tables.from_parquet(default_table_path("asphalt_024mm"))
    rw = Tables(ro.surface, ro.theories, ro.options, ro.grid, ro.zeta_grid,
                {k: np.array(v) for k, v in ro.data.items()}, ro.info)
    assert not ro.data["u_over_h"].flags.writeable and rw.data["u_over_h"].flags.writeable
    return ro, rw


def _inputs(values):
    """The same numbers as a scalar, a writable array, a read-only array and a pandas column."""
    a = np.asarray(values, dtype=np.float64)
    ro = a.copy()
    ro.flags.writeable = False
    col = pd.DataFrame({"v": a})["v"].to_numpy()
    return [float(a[0]), a.copy(), ro, col]


def _parallel_kernels():
    """Every parallel (``prange``) kernel defined in fastcontact: the top-level loops whose
    compiles are the expensive ones."""
    import numba

    return [v for name, mod in sorted(sys.modules.items())
            if name.startswith("fastcontact.") and mod is not None
            for v in vars(mod).values()
            if isinstance(v, numba.core.registry.CPUDispatcher) and v.__module__ == name
            and v.targetoptions.get("parallel")]


def _differences(signatures):
    """Where signatures differ: {argument position: [its type in each signature]}, a named
    tuple's fields expanded (position "3.4" is field 4 of argument 3)."""
    def flat(sig):
        out = {}
        for i, t in enumerate(sig):
            items = getattr(t, "types", None) if hasattr(t, "fields") else None
            if items is None:
                out[str(i)] = str(t)
            else:
                out.update({f"{i}.{j}": str(u) for j, u in enumerate(items)})
        return out
    flats = [flat(s) for s in signatures]
    keys = sorted(set().union(*flats))
    return {k: [f.get(k) for f in flats] for k in keys if len({f.get(k) for f in flats}) > 1}


def _helpers():
    """Helpers the kernels call that were compiled twice before 2026-11-28: once per literal
    int argument (numba specialises a callee on ``f(0, ...)`` and ``f(1, ...)``) or once for a
    prange index (uint64) and once for a block loop's (int64). A helper reached through a
    kernel loaded from the disk cache is not compiled (no signature); where this process
    compiles it (an empty numba cache, as in CI) it must compile once."""
    from fastcontact.seal import _leak, _panels
    from fastcontact.squeeze import _fastpath, _kernels, _primitive_build, tire_piezo, viscosity

    return [_fastpath._slow_row, _kernels.quad_case, viscosity._piezo_case,
            viscosity._no_times, tire_piezo._tire_case, _primitive_build._build_row,
            _panels.solve_case, _panels.solve_robust, _panels.solve_row, _leak._gl_fast]


def _one_signature(*reached):
    """``reached`` compiled (or loaded) exactly once; no parallel kernel, and none of the
    :func:`_helpers`, more than once."""
    many = {f"{k.__module__}.{k.py_func.__qualname__}": _differences(k.signatures)
            for k in set(_parallel_kernels()) | set(_helpers()) | set(reached)
            if len(k.signatures) > 1}
    assert not many, many
    missed = [k.py_func.__qualname__ for k in reached if len(k.signatures) != 1]
    assert not missed, f"not reached by the calls: {missed}"


def test_squeeze_and_tire_kernels(flavours):
    from fastcontact.squeeze import _barus_fast, _fastpath, tire_piezo, viscosity

    for T in flavours:
        for p0 in _inputs([2e5, 3e5]):
            for u0 in (None, 8 * T.h_rms):
                for method in ("fast", "quad"):
                    fc.squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, u_start=u0,
                                   times=(1e-3,), method=method, theory="average")
            for method in ("fast", "quad"):
                for alpha in (1e-6, [1e-6, 2e-6]):  # one fluid (the base kernel on the
                    # Barus time primitive where it serves) and two (the per-case kernel)
                    fc.squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, alpha_pv=alpha,
                                   times=(1e-3,), method=method, theory="average")
                fc.tire_footprint(T, p0=p0, E_star=E, R=R, eta=ETA, footprint_length=0.1,
                                  speed=20.0, method=method, theory="average")
                fc.tire_footprint(T, p0=p0, E_star=E, R=R, eta=ETA, footprint_length=0.1,
                                  speed=20.0, method=method, alpha_pv=1e-6, theory="average")
                # two fluids in one call: the per-case Barus kernel (one fluid: the base kernel
                # on the Barus time primitive — fast_kernel, held to one signature here)
                fc.tire_footprint(T, p0=p0, E_star=E, R=R, eta=ETA, footprint_length=0.1,
                                  speed=20.0, method=method, alpha_pv=[1e-6, 2e-6],
                                  theory="average")
    _one_signature(_fastpath.fast_kernel, _fastpath.quad_kernel, _barus_fast.squeeze_kernel,
                   _barus_fast.tire_kernel, viscosity._piezo_kernel, tire_piezo._tire_kernel)


def test_seal_kernels(flavours):
    from fastcontact.seal import _leak, _panels, _piezo_kernels

    for T in flavours:
        for p0 in _inputs([5e4, 6e4]):
            fc.seal_leak(T, p0=p0, dp=2e4, L=5e-3, L_y=L_Y, E_star=E, eta=ETA)
            fc.seal_leak(T, p0=p0, dp=2e4, L=5e-3, L_y=L_Y, E_star=E, eta=ETA, alpha_pv=1e-7)
        for f_N in _inputs([2.0, 3.0]):
            fc.seal_leak(T, profile="hertz", R=1e-3, f_N=f_N, dp=1e4, L_y=L_Y, E_star=E,
                         eta=ETA)
        # a Δp sweep of one O-ring with a Barus fluid: the chained solver
        fc.seal_leak(T, profile="hertz", R=1e-3, f_N=2.0, dp=np.linspace(1e3, 4e4, 12),
                     L_y=L_Y, E_star=E, eta=ETA, alpha_pv=1e-5)
    _one_signature(_leak.uniform_rows, _panels.solve_rows, _panels.solve_rows_chained,
                   _piezo_kernels._uniform_sweep_kernel)
