"""Test-session set-up: the suite runs on every core through pytest-xdist (``addopts`` in
pyproject.toml: ``-n auto --dist loadfile``, installed by the ``test`` extra).

Where pytest-xdist is not loaded (pytest alone, e.g. a core install plus pytest, or
``-p no:xdist``), its two
options are accepted and ignored, so that ``pytest`` still runs the suite, in one process,
instead of stopping at "unrecognized arguments: -n"; the report header says so.
"""
from __future__ import annotations

_ABSENT = False  # set when pytest-xdist is not loaded


def pytest_addoption(parser, pluginmanager):
    global _ABSENT
    if pluginmanager.hasplugin("xdist"):
        return
    _ABSENT = True
    group = parser.getgroup("xdist (not installed)")
    # pytest reserves lowercase short options for plugins; _addoption is how pytest-xdist
    # itself registers -n
    group._addoption("-n", "--numprocesses", dest="numprocesses", default=None,
                     help="ignored: pytest-xdist is not loaded (tests run in one process)")
    group._addoption("--dist", dest="dist", default="no",
                     help="ignored: pytest-xdist is not loaded")


def pytest_report_header(config):
    if _ABSENT:
        return ("pytest-xdist is not loaded: the tests run in one process "
                "(pip install '.[test]' installs it)")
    return None
