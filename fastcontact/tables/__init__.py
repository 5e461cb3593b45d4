"""Precomputed contact and flow tables of one surface, in reduced units, and their Parquet form.

One table serves every E* and η: columns are functions of the reduced contact pressure
``p̄ = p/E*`` on a log grid, with separations in units of h_rms and conductivities as
``σ̄ = 12 η σ_eff / h_rms³`` (eq. 23). The grid reaches from ū ≈ 30 h_rms (the
asymptotic regime) to A(ζ1)/A0 = 0.999 (full contact).

Columns (``Tables.data``), all dimensionless:

=====================  ================================================================
p_over_E               p̄ = p_cont/E* (grid nodes)
u_over_h               ū/h_rms                                                 (A4)
dlnu_dlnp              d ln ū / d ln p̄ (exact, from the same quadrature)
d2lnu_dlnp2            d² ln ū / d(ln p̄)² (exact)
area_fraction          A(ζ1)/A0                                                (A1)
sigma_<theory>         σ̄ for each requested theory (0 where percolated)        (23)
dlnsigma_<theory>      d ln σ̄ / d ln p̄ (average: 3 d ln ū/d ln p̄; critical junction and
                       effective medium: local degree-8 polynomial through 9 nodes of
                       ln σ̄ (A_c − A(ζ1)/A0), then the chain rule)
d2lnsigma_<theory>     d² ln σ̄ / d(ln p̄)², likewise
phi_<theory>           pressure flow factor φ_p = σ̄ (h_rms/ū)³               (Sec. 4)
percolated_<theory>    True where the contact percolates (σ_eff = 0, fluid trapped)
zeta_c, u1c_over_h     critical-junction magnification and u1(ζc)/h_rms      (A3)
zeta, G_over_Estar2    G(ζ)/E*² on the log ζ grid (same number of rows)          (A2)
=====================  ================================================================

Interpolation: quintic Hermite in ln p̄ of ln ū (and of the inverse ln p̄(ln ū)) with exact
first and second derivatives; likewise quintic Hermite of ln σ̄; in the one
grid interval that contains a theory's percolation pressure, σ̄^(1/3) is interpolated
linearly in ln p̄ to zero at the exact percolation pressure (closed form from A(ζ1)).
Outside the grid nothing is extrapolated: Python methods raise, kernels return a flag.

Modules: :mod:`.build` (precompute, adaptive refinement), :mod:`.store` (Tables, Parquet),
:mod:`.defaults` (the embedded surfaces); the lookup kernels live in
:mod:`fastcontact.kernels.lookup` and are re-exported here.
"""
from __future__ import annotations

from .._core.vocab import METADATA_KEY  # noqa: F401
from ..kernels.lookup import (TableKernel, k_lnp_of_lnu, k_lnu_of_lnp, k_sigma_of_lnp,
                              k_state_of_lnu)
from .build import (AREA_TOP, BOUNDARY_FACTOR, DEFAULT_POINTS_PER_DECADE, MAX_NODES,  # noqa: F401
                    MIN_DLNP, SIGMA_FLOOR, TOLERANCE, U_TOP, default_grid, precompute)
from .store import REFERENCES, SCHEMA_VERSION, UNITS, TableRangeError, Tables  # noqa: F401

__all__ = ["Tables", "TableRangeError", "TableKernel", "precompute", "default_grid",
           "DEFAULT_POINTS_PER_DECADE", "SCHEMA_VERSION", "TOLERANCE", "k_lnu_of_lnp",
           "k_lnp_of_lnu", "k_sigma_of_lnp", "k_state_of_lnu"]
