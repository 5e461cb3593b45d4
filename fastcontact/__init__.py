"""fastcontact — Persson contact mechanics and Lorenz–Persson fluid squeeze-out and seal leakage.

Public entry points (SI units at every edge), all reachable as ``fastcontact.<name>``:

- surfaces: :class:`SelfAffinePSD`, :class:`TabulatedPSD`, :func:`read_psd`,
  :func:`psd_from_heights`, :func:`synthetic_heights`
- materials: :func:`effective_modulus`
- contact mechanics (direct quadrature): :mod:`fastcontact.contact`; flow: :mod:`fastcontact.flow`
- tables: :func:`precompute` → :class:`Tables`; :func:`load_default_tables`
- engines: :func:`squeeze_out`, :func:`squeeze_history`, :func:`tire_footprint`,
  :func:`tire_history`, :func:`squeeze_out_reduced`, :func:`seal_leak`, :func:`seal_profile`
- studies: :func:`load_scene`, :func:`run_scene`, :func:`run_sweep`, :func:`read_sweep`
- validation (``fastcontact[bem]``): :func:`bem_reference`, :func:`compare_theories`,
  :func:`calibrate`, :class:`Calibration`

Names and sub-packages are imported lazily: ``import fastcontact`` is cheap and compiles nothing.

Reference: B. Lorenz and B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), arXiv:1004.1037.
"""
from __future__ import annotations

from ._core.lazy import lazy_getattr

__version__ = "0.2.0"

_LAZY = {
    "SelfAffinePSD": "surface.psd", "TabulatedPSD": "surface.psd", "PSD": "surface.psd",
    "read_psd": "surface.topography", "write_psd": "surface.topography",
    "psd_from_heights": "surface.topography", "synthetic_heights": "surface.topography",
    "read_topography": "surface.io", "psd_from_surface_topography": "surface.io",
    "effective_modulus": "contact.elasticity",
    "precompute": "tables", "Tables": "tables", "load_default_tables": "tables.defaults",
    "squeeze_out": "squeeze", "squeeze_history": "squeeze", "squeeze_out_reduced": "squeeze.reduced",
    "tire_footprint": "squeeze.tire", "tire_history": "squeeze.tire",
    "seal_leak": "seal", "seal_profile": "seal", "seal_elastic": "seal", "hertz_contact": "seal",
    "load_scene": "studies.scene", "run_scene": "studies.scene",
    "run_sweep": "studies.sweep", "read_sweep": "studies.sweep",
    "bem_reference": "validation", "compare_theories": "validation", "calibrate": "validation",
    "Calibration": "validation",
    "DEFAULT_THEORY": "_core.vocab", "THEORIES": "_core.vocab",
}
#: sub-packages reachable as attributes (``fastcontact.contact``) without an explicit import
_SUBPACKAGES = ("contact", "flow", "kernels", "seal", "squeeze", "studies", "surface", "tables",
                "validation", "figures", "cli")
__all__ = sorted(_LAZY) + ["__version__"]


__getattr__ = lazy_getattr(__name__, _LAZY, _SUBPACKAGES)


def __dir__():
    return __all__ + list(_SUBPACKAGES)
