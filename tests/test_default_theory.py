"""One default flow theory across the API (issue 12, point 8).

Every public entry point with a ``theory`` parameter, and every study kind of the scene
schema, takes its default from :data:`fastcontact._core.vocab.DEFAULT_THEORY`.
"""
from __future__ import annotations

import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import fastcontact
from fastcontact._core.vocab import DEFAULT_THEORY, THEORIES

#: public functions with a ``theory`` parameter that keep a default of their own, and why
EXEMPT = {
    # the flow factor and the directional (Bruggeman) conductivity are effective-medium
    # concepts: they default to the effective medium, "emt"
    ("fastcontact.flow.conductivity", "flow_factor"),
    ("fastcontact.flow.anisotropy", "sigma_directional"),
    # the asperity-cascade extension study (its levels use the effective medium by design)
    ("fastcontact.squeeze.asperity", "asperity_levels"),
    ("fastcontact.squeeze.asperity", "asperity_summary"),
}

ENTRY_POINTS = ("squeeze_out", "squeeze_history", "tire_footprint", "tire_history", "seal_leak",
                "seal_profile", "seal_elastic")


def _theory_default(fn):
    p = inspect.signature(fn).parameters.get("theory")
    return None if p is None else p.default


def test_default_theory_is_a_theory():
    assert DEFAULT_THEORY in THEORIES


@pytest.mark.parametrize("name", ENTRY_POINTS)
def test_top_level_entry_point_default(name):
    fn = getattr(fastcontact, name)
    assert _theory_default(fn) == DEFAULT_THEORY, name


def test_every_public_function_with_a_theory_default():
    """Walk every module's ``__all__``: a public callable whose ``theory`` has a default
    uses DEFAULT_THEORY, unless listed in EXEMPT (with its reason)."""
    checked, wrong = set(), []
    for info in pkgutil.walk_packages(fastcontact.__path__, "fastcontact."):
        try:
            mod = importlib.import_module(info.name)
        except ImportError:        # optional extras (SurfaceTopography, ContactMechanics)
            continue
        for attr in getattr(mod, "__all__", ()):
            obj = getattr(mod, attr, None)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            key = (obj.__module__, obj.__name__)
            if key in checked or key in EXEMPT:
                continue
            checked.add(key)
            try:
                default = _theory_default(obj)
            except (TypeError, ValueError):
                continue
            if default is not None and default is not inspect.Parameter.empty \
                    and default != DEFAULT_THEORY:
                wrong.append(f"{key[0]}.{key[1]}: theory={default!r}")
    assert not wrong, wrong
    # the walk did reach the engines (a broken walk would find nothing to complain about)
    assert {("fastcontact.squeeze.api", "squeeze_out"), ("fastcontact.seal.api", "seal_leak"),
            ("fastcontact.squeeze.tire", "tire_footprint")} <= checked


def test_scene_kinds_default_theory():
    from fastcontact.studies.kinds import KINDS
    kinds = {k: v.defaults["theory"] for k, v in KINDS.items()
             if k != "asperity"}          # the asperity cascade: see EXEMPT
    assert {"squeeze", "tire", "seal"} <= set(kinds)
    assert kinds == {k: DEFAULT_THEORY for k in kinds}


def test_scene_without_theory_uses_default():
    from fastcontact.studies.load import load_scene
    sc = load_scene({"study": {"kind": "squeeze", "p0": "0.2 MPa"},
                     "surfaces": {"a": {"table": "asphalt_024mm"}},
                     "material": {"E": "10 MPa", "nu": 0.5}, "fluid": {"eta": "1 mPa s"},
                     "geometry": {"R": "2 cm"}})
    assert sc.axes["theory"] == [DEFAULT_THEORY]
    assert sc.theories == (DEFAULT_THEORY,)


def test_squeeze_out_default_is_the_default_theory_not_average():
    """Behaviour, not only the signature: the default result is the DEFAULT_THEORY result,
    and differs from the average-separation result at this load."""
    from fastcontact.tables.defaults import load_default_tables
    T = load_default_tables("asphalt_024mm")
    kw = dict(p0=np.array([0.2e6, 1e6]), E_star=13.3e6, R=0.02, eta=1e-3, method="quad")
    d = fastcontact.squeeze_out(T, **kw)
    named = fastcontact.squeeze_out(T, theory=DEFAULT_THEORY, **kw)
    avg = fastcontact.squeeze_out(T, theory="average", **kw)
    assert d.attrs["theory"] == DEFAULT_THEORY
    np.testing.assert_array_equal(d["t_star"].to_numpy(), named["t_star"].to_numpy())
    assert not np.allclose(d["t_star"].to_numpy(), avg["t_star"].to_numpy(), rtol=1e-3)
