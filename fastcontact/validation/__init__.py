"""Validation and calibration of the theories against a boundary-element reference (issue 13).

- :func:`bem_reference` — random surfaces of a PSD, elastic contact (ContactMechanics) and
  Reynolds flow on the gap field: A/A0, ū, σ_eff and the flow-stop pressure vs p0;
- :func:`compare_theories` — every flow theory beside such a reference: relative errors of
  A, ū, σ_eff, the flow-stop pressure and the propagated squeeze-out time;
- :func:`calibrate` → :class:`Calibration` — joint fit of γ, α_cj, a_perc and the effective
  medium's percolation threshold to a reference (or measured data);
- :func:`emt_conductivity` — generalized (Kirkpatrick) Bruggeman medium with a threshold.

The BEM needs ``pip install "fastcontact[bem]"``; comparison and calibration of an existing
reference table do not. Submodules are imported lazily.
"""
from __future__ import annotations

from .._core.lazy import lazy_getattr

#: submodule -> the names it gives this package (imported on first use)
_SUBMODULE_NAMES = {
    "bem": ("bem_reference", "solve_contact", "surface_realization", "BEMResolutionWarning"),
    "reynolds": ("reynolds_conductivity",),
    "compare": ("compare_theories", "squeeze_time_ratio", "write_reference", "read_reference"),
    "calibration": ("calibrate", "Calibration"),
    "emt": ("emt_conductivity", "emt_sigma_bar"),
}
_LAZY = {name: mod for mod, names in _SUBMODULE_NAMES.items() for name in names}
__all__ = sorted(_LAZY)


__getattr__ = lazy_getattr(__name__, _LAZY)


def __dir__():
    return __all__
