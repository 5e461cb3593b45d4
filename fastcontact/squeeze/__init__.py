"""Fluid squeeze-out between a flat cylindrical block and a rough substrate, on precomputed
:class:`~fastcontact.tables.Tables` — millions of cases per call.

The film obeys dū/dt = -(8σ_eff/R²)(p0 - p_cont(ū)) (Lorenz & Persson, Eur. Phys. J. E 32,
281 (2010), eqs. (17)–(19); arXiv:1004.1037). In reduced units
(v = ū/h_rms, π = p/E*, σ̄ = 12ησ_eff/h_rms³, eq. (23); t = τ0 t̃, τ0 = 3ηR²/(2h_rms²p0)) the
right-hand side depends on v only, so every time is a difference of one function, the time
primitive T(p0/E*, ū), tabulated once per (tables, theory) (:mod:`.primitive`).

Modules: :mod:`.api` (squeeze_out, squeeze_history, columns), :mod:`.model` (tail, trap,
default start), :mod:`.primitive` (the time primitive), :mod:`._fastpath` and
:mod:`._kernels` (numba kernels), :mod:`.reduced` (Sec. 2 reduced model), :mod:`.tire`
(Sec. 5 tire footprint).
"""
from __future__ import annotations

from .api import (QUAD_ORDER, QUAD_WIDTH, STATUS_NAMES, columns, register_extension,
                  squeeze_history, squeeze_out)
from .model import DEFAULT_P_START, TAIL_EXTENT, ModelPar, SqueezeModel, squeeze_model
from .primitive import DXI as FAST_DXI
from .primitive import set_primitive_cache
from . import viscosity as _viscosity  # noqa: E402,F401  registers squeeze_out(alpha_pv=...) (issue 14)

__all__ = ["squeeze_out", "squeeze_history", "squeeze_model", "columns", "SqueezeModel",
           "ModelPar", "DEFAULT_P_START", "QUAD_ORDER", "QUAD_WIDTH", "FAST_DXI", "TAIL_EXTENT",
           "STATUS_NAMES", "register_extension", "set_primitive_cache"]
