"""Issue 12.3 (input side): quantities with units are converted to SI or refused — never stripped.

pint is a test dependency; fastcontact never imports it (duck typing), which the last test
checks in a fresh interpreter.
"""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import fastcontact
from fastcontact import contact
from fastcontact._core.validate import as_float_array, check_positive, check_range

pint = pytest.importorskip("pint")
UREG = pint.UnitRegistry()
Q_ = UREG.Quantity
E_STAR = 1e7


@pytest.fixture(scope="module")
def psd():
    return fastcontact.SelfAffinePSD(h_rms=10e-6, hurst=0.8, q0=1e4, q1=1e9)


def test_pressure_in_megapascal_is_converted(psd):
    """0.1 MPa is 1e5 Pa (the bug: it computed at 0.1 Pa)."""
    got = contact.mean_separation(psd, Q_(0.1, "MPa"), E_STAR)
    assert got == contact.mean_separation(psd, 1e5, E_STAR)
    assert got != contact.mean_separation(psd, 0.1, E_STAR)
    arr = contact.mean_separation(psd, Q_(np.array([0.1, 0.2]), "MPa"), Q_(10, "MPa"))
    np.testing.assert_array_equal(arr, contact.mean_separation(psd, np.array([1e5, 2e5]), 1e7))


def test_length_in_micrometre_is_converted():
    """h_rms = 10 µm is 1e-5 m (the bug: 10 m)."""
    p = fastcontact.SelfAffinePSD(h_rms=Q_(10, "um"), hurst=0.8, q0=Q_(1, "1/cm"), q1=1e9)
    assert p.h_rms == pytest.approx(1e-5, rel=1e-12)
    assert p.q0 == pytest.approx(100.0, rel=1e-12)


def test_dimensionless_quantities():
    assert float(check_range("hurst", Q_(80, "percent"), 0, 1, "[-]")) == pytest.approx(0.8)
    assert float(check_positive("ratio", Q_(2.0, "dimensionless"), "[-]")) == 2.0


@pytest.mark.parametrize("name, kw", [
    ("h_rms", dict(h_rms=Q_(10, "MPa"), hurst=0.8, q0=1e4, q1=1e9)),
    ("q0", dict(h_rms=1e-5, hurst=0.8, q0=Q_(1e4, "m"), q1=1e9)),
    ("hurst", dict(h_rms=1e-5, hurst=Q_(0.8, "m"), q0=1e4, q1=1e9)),
])
def test_wrong_dimension_refused_by_name(name, kw):
    with pytest.raises(ValueError, match=rf"^{name} = .* cannot be converted") as err:
        fastcontact.SelfAffinePSD(**kw)
    assert "\n" not in str(err.value)


def test_wrong_dimension_in_contact(psd):
    with pytest.raises(ValueError, match=r"^p = 1 meter is invalid.*\[Pa\]"):
        contact.mean_separation(psd, Q_(1, "m"), E_STAR)
    with pytest.raises(ValueError, match=r"^E_star = "):
        contact.mean_separation(psd, 1e5, Q_(1, "s"))


def test_relative_unit_takes_only_dimensionless():
    """A parameter measured in units of another (here [h_rms]) cannot take a length."""
    with pytest.raises(ValueError, match=r"^u = .*only a dimensionless quantity"):
        check_positive("u", Q_(1, "um"), "[h_rms]")
    assert float(check_positive("u", Q_(2, "dimensionless"), "[h_rms]")) == 2.0


def test_unknown_expected_unit_refuses_units():
    with pytest.raises(ValueError, match=r"^x = 3 meter is invalid"):
        as_float_array("x", Q_(3, "m"))


class _AstropyLike:
    """An object with astropy's interface: ``.unit``, ``.to(str)`` and ``.value``."""

    _SCALE = {"Pa": 1.0, "MPa": 1e6}

    def __init__(self, value, unit):
        self.value, self.unit = value, unit

    def to(self, target):
        if target not in self._SCALE:
            raise ValueError(f"cannot convert {self.unit} to {target}")
        return _AstropyLike(self.value * self._SCALE[self.unit] / self._SCALE[target], target)


def test_duck_typed_quantity(psd):
    got = contact.mean_separation(psd, _AstropyLike(0.1, "MPa"), E_STAR)
    assert got == contact.mean_separation(psd, 1e5, E_STAR)
    with pytest.raises(ValueError, match=r"^h_rms = .* cannot be converted"):
        fastcontact.SelfAffinePSD(h_rms=_AstropyLike(1.0, "MPa"), hurst=0.8, q0=1e4, q1=1e9)


def test_pint_is_not_imported_by_fastcontact():
    code = ("import sys, fastcontact; from fastcontact import contact; "
            "p = fastcontact.SelfAffinePSD(1e-5, 0.8, 1e4, 1e9); "
            "contact.mean_separation(p, 1e5, 1e7); print('pint' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


def test_math_helpers_unaffected():
    """Plain numbers take the fast path unchanged."""
    assert float(check_positive("x", 2.5, "[m]")) == 2.5
    assert as_float_array("x", [1, 2]).dtype == np.float64
    assert math.isnan(float(as_float_array("x", float("nan"))))
