"""Numba kernels of the seal engine's σ̄ and leak integral (private): one import place.

The kernels live by what they hold: :mod:`._lookup` (σ̄ and ū in reduced units, the
re-tabulation and its verification, the hot-scalar record ``HS``), :mod:`._primitive` (direct
integrals of σ̄ and the verified primitive, columns ``P_*``) and :mod:`._leak` (the leak
integral, the flat-ring rows and their status codes ``ST_*``). Every name is importable from
here as before.
"""
from __future__ import annotations

from ._leak import (SHORT_RTOL, ST_ABOVE_TABLE, ST_LIFT_OFF, ST_NEAR_PERCOLATION,
                    ST_NOT_CONVERGED, ST_OK, ST_OPEN, ST_PERCOLATED, TAIL_RTOL, invert_uniform,
                    leak_integral, uniform_rows)
from ._lookup import (contact_of_u, retabulate, sig_d, sigma_of_c, sigma_rows, table_sig_d,
                      ubar_of_c, ubar_rows, verify_cells)
from ._lookup import HS_FIELDS, hot_scalars
from ._primitive import ADAPT_RTOL, asym_primitive, build_primitive
from ._primitive import (P_CELL, P_COLS, P_D1, P_D2, P_IH, P_OK, P_PRE, P_SUF,  # noqa: F401
                         P_T)

__all__ = ["sig_d", "table_sig_d", "sigma_of_c", "ubar_of_c", "retabulate", "verify_cells",
           "build_primitive", "leak_integral", "uniform_rows", "sigma_rows", "ubar_rows",
           "invert_uniform", "ST_OK", "ST_LIFT_OFF", "ST_OPEN", "ST_PERCOLATED",
           "ST_ABOVE_TABLE", "ST_NOT_CONVERGED", "ST_NEAR_PERCOLATION", "contact_of_u",
           "asym_primitive", "TAIL_RTOL", "ADAPT_RTOL", "SHORT_RTOL", "P_COLS", "HS_FIELDS",
           "hot_scalars"]
