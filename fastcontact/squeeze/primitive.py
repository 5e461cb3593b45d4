"""The time primitive of one (tables, theory): every squeeze-out time is a difference of it.

The squeeze-out ODE dv/dt̃ = -σ̄(π_c(v)) (1 - π_c(v)/π0) (Lorenz & Persson 2010, eqs. (18),
(19), (23); arXiv:1004.1037) is autonomous, so with

    T(x0, v) = ∫_v^∞ dv' / (σ̄(π_c(v')) (1 - π_c(v')/π0)),      x0 = ln π0 = ln(p0/E*),

the time from v_a down to v_b is T(x0, v_b) - T(x0, v_a) (in τ0 = 3ηR²/(2h_rms²p0)).
T is tabulated as ln T on a grid in x0 (nodes uniform in ξ = x0 - ln σ̄(x0), dense where
σ̄ collapses) × z = ln(v/v∞ - 1) (uniform), with its exact z-derivatives from the integrand,
so that z-interpolation is quintic Hermite and x0-interpolation 4-point Lagrange. Below
the grid (the logarithmic singularity at v∞) T = T0 + S (z0 - z) + (h0 - S)(1 - e^{z - z0})
analytically. Between the table top and v_ext σ̄ is the tail fitted to the tables' direct
samples (:mod:`.model`); above v_ext (the flat-film tail, σ̄ = y³ - c y within 1e-8 of that
fit, π_c/π0 < e^-40) T is the closed form ∫dy/(y³ - c y). The inverse (v at a given T) is a
bracketed Halley solve on the same interpolant, so forward and inverse agree to rounding and
ū(t) is monotone.

A primitive is built in one parallel pass (node quadrature, composite Gauss–Lobatto in z),
and can be written to / read from Parquet with its grid and its measured interpolation error.

This module gathers the names of its three parts: the record and its evaluation
(:mod:`._primitive_eval`), the build (:mod:`._primitive_build`) and the on-disk cache
(:mod:`._primitive_store`). Above the trap pressure the film drains towards ū_trap instead of
ū∞; that side has its own primitive of the same form (:mod:`._trap_primitive`), built only
when a call has trapped cases.
"""
from __future__ import annotations

from ._primitive_build import (DXI, DZ, NODE_POINTS, X_END, Z_LO,  # noqa: F401
                               PROFILE_DS, PROFILE_FD, Profile, build, fast_limit,
                               measure_error, profile, verified_top)
from ._primitive_eval import (Primitive, first_row, row_value, row_value_2,  # noqa: F401
                              stencil, t_of_z, z_of_t)
from ._primitive_store import (PRIMITIVE_VERSION, load_or_build, primitive_path,  # noqa: F401
                               read, set_primitive_cache, write)

__all__ = ["Primitive", "load_or_build", "build", "write", "read", "set_primitive_cache",
           "primitive_path", "PRIMITIVE_VERSION", "t_of_z", "z_of_t", "stencil"]
