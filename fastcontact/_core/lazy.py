"""Lazy attributes of a package (PEP 562 ``__getattr__``): names imported from their modules
on first use, so that importing the package compiles and loads nothing."""
from __future__ import annotations

import importlib

__all__ = ["lazy_getattr"]


def lazy_getattr(package, names, subpackages=()):
    """A module ``__getattr__`` for ``package``.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    names : dict
        Attribute name -> module path relative to ``package`` (``"surface.psd"``) or absolute
        (``"fastcontact.studies.run"``).
    subpackages : sequence of str
        Sub-packages returned as attributes themselves.
    """
    def __getattr__(name):
        if name in names:
            mod = names[name]
            mod = importlib.import_module(mod if mod.startswith(package.split(".")[0] + ".")
                                          else f".{mod}", package)
            return getattr(mod, name)
        if name in subpackages:
            return importlib.import_module(f".{name}", package)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")
    return __getattr__
