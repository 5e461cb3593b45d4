"""Parameter entries that many numpydoc docstrings share, written once and filled in.

A docstring line that holds only ``{{name1 name2 ...}}`` becomes the numpydoc entries of
those names from :data:`PARAMS` (``name : type`` at the line's indent, the description
indented below it), when :func:`fill_params` decorates the function. The filled
``__doc__`` is what help() and Sphinx show.
"""
from __future__ import annotations

import re

__all__ = ["PARAMS", "fill_params"]

#: key -> (``name : type`` line, description) of a shared parameter entry
PARAMS = {
    "psd": ("psd : PSD", "Roughness spectrum."),
    "p_nominal": ("p : array_like", "Nominal contact pressure [Pa], > 0."),
    "p_contact": ("p : array_like", "Contact pressure p_cont [Pa], > 0."),
    "E_star": ("E_star : float or array_like", "Effective modulus [Pa], > 0."),
    "E_star_scalar": ("E_star : float", "Effective modulus [Pa], > 0."),
    "eta": ("eta : float", "Fluid viscosity [Pa·s], > 0."),
}

_MARK = re.compile(r"^(\s*)\{\{([\w ]+)\}\}$")


def _expand(line):
    m = _MARK.match(line)
    if m is None:
        return [line]
    indent = m.group(1)
    out = []
    for key in m.group(2).split():
        head, text = PARAMS[key]
        out += [indent + head, indent + "    " + text]
    return out


def fill_params(func):
    """Decorator: expand the ``{{...}}`` lines of ``func.__doc__`` (see the module docstring).

    Parameters
    ----------
    func : callable
        A function whose docstring may hold ``{{key ...}}`` lines, keys of :data:`PARAMS`.

    Returns
    -------
    callable
        ``func`` itself, with the expanded docstring.
    """
    if func.__doc__:
        func.__doc__ = "\n".join(x for line in func.__doc__.split("\n") for x in _expand(line))
    return func
