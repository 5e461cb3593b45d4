"""Leak rate of static seals with fluid-pressure feedback (Lorenz & Persson 2010, Secs. 6–8).

Public entry points
-------------------
:func:`seal_leak`     leak rate Q [m³/s] of many cases (broadcasting), with flags and status
:func:`seal_profile`  p_cont(x), p_fluid(x), ū(x), σ_eff(x) of one case
:func:`seal_elastic`  stiff seals: elastic deformation coupled to the flow (eq. 30), one case
:func:`hertz_contact` half-width and peak pressure of an O-ring (Hertz line contact)

Modules: :mod:`.api` (seal_leak, columns), :mod:`.profile`, :mod:`.elastic`, :mod:`.context`
(the flat kernel records, built once per tables × theory), private kernels ``_sigma``
(σ̄ and its primitive), ``_mesh`` and ``_panels`` (the soft-seal solver). Nothing compiles at
import. References: B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010),
arXiv:1004.1037.
"""
from __future__ import annotations

from ._inputs import hertz_contact
from .api import STATUS, columns, seal_leak
from .context import SOLVER_DEFAULTS, SealContext, seal_context
from .elastic import seal_elastic
from .profile import seal_profile

__all__ = ["seal_leak", "seal_profile", "seal_elastic", "hertz_contact", "columns", "STATUS",
           "SOLVER_DEFAULTS", "seal_context", "SealContext"]
