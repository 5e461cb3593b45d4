"""Interfacial fluid flow conductivity: :mod:`.conductivity` (wrappers), :mod:`._kernels`."""
