"""Former module path, kept so that existing code keeps working: the code lives in
:mod:`fastcontact.surface.topography`, and ``fastcontact.topography`` *is* that module."""
import importlib
import sys

sys.modules[__name__] = importlib.import_module("fastcontact.surface.topography")
