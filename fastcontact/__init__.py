"""fastcontact — Persson contact mechanics and Lorenz–Persson fluid squeeze-out and seal leakage.

Public entry points (SI units at every edge):

- surfaces: :class:`SelfAffinePSD`, :class:`TabulatedPSD`, :func:`read_psd`,
  :func:`psd_from_heights`
- materials: :func:`effective_modulus`
- contact mechanics (direct quadrature): :mod:`fastcontact.contact`
- tables: :func:`precompute` → :class:`Tables`
- engines: :func:`squeeze_out`, :func:`squeeze_out_reduced`, :func:`seal_leak`,
  :func:`seal_profile`

Submodules are imported lazily, so ``import fastcontact`` is cheap and compiles nothing.
"""
from __future__ import annotations

import importlib

__version__ = "0.2.0"

_LAZY = {
    "SelfAffinePSD": "surface.psd", "TabulatedPSD": "surface.psd", "PSD": "surface.psd",
    "read_psd": "surface.topography", "write_psd": "surface.topography",
    "psd_from_heights": "surface.topography", "synthetic_heights": "surface.topography",
    "effective_modulus": "contact.elasticity",
    "precompute": "tables", "Tables": "tables",
    "squeeze_out": "squeeze", "squeeze_history": "squeeze", "squeeze_out_reduced": "squeeze.reduced",
    "seal_leak": "seal", "seal_profile": "seal", "seal_elastic": "seal", "hertz_contact": "seal",
}
__all__ = sorted(_LAZY) + ["__version__"]


def __getattr__(name):
    if name in _LAZY:
        mod = importlib.import_module(f".{_LAZY[name]}", __name__)
        return getattr(mod, name)
    raise AttributeError(f"module 'fastcontact' has no attribute {name!r}")


def __dir__():
    return __all__
