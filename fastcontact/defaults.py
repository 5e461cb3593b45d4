"""Former module path, kept so that existing code keeps working: the code lives in
:mod:`fastcontact.tables.defaults`, and ``fastcontact.defaults`` *is* that module."""
import importlib
import sys

sys.modules[__name__] = importlib.import_module("fastcontact.tables.defaults")
