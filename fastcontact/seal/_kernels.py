"""Former home of the seal kernels (private): they now live in ``_sigma`` (σ̄, primitive,
flat-ring driver), ``_mesh`` (zone geometry, panel helpers) and ``_panels`` (soft-seal solver)."""
from __future__ import annotations

from ._mesh import *  # noqa: F401,F403
from ._panels import *  # noqa: F401,F403
from ._sigma import *  # noqa: F401,F403
