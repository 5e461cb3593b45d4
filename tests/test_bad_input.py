"""Issue #2: every bad input raises ValueError whose message names the parameter."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

import fastcontact
from fastcontact import contact

NAN = float("nan")
GOOD_PSD = dict(h_rms=10e-6, hurst=0.8, q0=1e4, q1=1e9)
E_STAR = 1e7


def _psd():
    return fastcontact.SelfAffinePSD(**GOOD_PSD)


def _raises_naming(name, fn):
    with pytest.raises(ValueError) as exc:
        fn()
    msg = str(exc.value)
    # the parameter name as a whole word (so "p" is not satisfied by "pressure", "E" not by "E_star")
    assert re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", msg), \
        f"ValueError message does not name {name!r}: {msg!r}"


# ------------------------------------------------------------- SelfAffinePSD
def _sa_cases():
    cases = []
    for bad in (-1e-6, 0.0, NAN):
        cases.append(("h_rms", dict(GOOD_PSD, h_rms=bad)))
    for bad in (0.0, 1.0, -0.2, 1.3, NAN):
        cases.append(("hurst", dict(GOOD_PSD, hurst=bad)))
    for bad in (-1e4, 0.0, NAN):
        cases.append(("q0", dict(GOOD_PSD, q0=bad)))
    for bad in (-1e9, 0.0, NAN, 1e4, 5e3):  # last two: q1 == q0 and q1 < q0
        cases.append(("q1", dict(GOOD_PSD, q1=bad)))
    for bad in (-1e5, 0.0, NAN):
        cases.append(("q_roll", dict(GOOD_PSD, q_roll=bad)))
    return cases


@pytest.mark.parametrize("name,kw", _sa_cases(), ids=[f"{n}={kw[n]!r}" for n, kw in _sa_cases()])
def test_self_affine_psd_bad(name, kw):
    _raises_naming(name, lambda: fastcontact.SelfAffinePSD(**kw))


# -------------------------------------------------------------- TabulatedPSD
_Q = np.geomspace(1e4, 1e8, 8)
_C = 1e-30 * (_Q / 1e4) ** -3.6


def _tab_cases():
    q_unsorted = _Q.copy(); q_unsorted[[2, 5]] = q_unsorted[[5, 2]]
    q_dup = _Q.copy(); q_dup[4] = q_dup[3]
    q_neg = _Q.copy(); q_neg[0] = -1e4
    q_zero = _Q.copy(); q_zero[0] = 0.0
    q_nan = _Q.copy(); q_nan[3] = NAN
    c_zero = _C.copy(); c_zero[2] = 0.0
    c_neg = _C.copy(); c_neg[2] = -1e-35
    c_nan = _C.copy(); c_nan[5] = NAN
    c_inf = _C.copy(); c_inf[5] = np.inf
    return [
        ("q", q_unsorted, _C, "persson"),
        ("q", q_unsorted[::-1].copy(), _C, "persson"),
        ("q", q_dup, _C, "persson"),
        ("q", q_neg, _C, "persson"),
        ("q", q_zero, _C, "persson"),
        ("q", q_nan, _C, "persson"),
        ("C", _Q, c_zero, "persson"),
        ("C", _Q, c_neg, "persson"),
        ("C", _Q, c_nan, "persson"),
        ("C", _Q, c_inf, "surface_topography"),
        ("convention", _Q, _C, "Persson-ish"),
        ("convention", _Q, _C, None),
    ]


@pytest.mark.parametrize("name,q,C,conv", _tab_cases())
def test_tabulated_psd_bad(name, q, C, conv):
    _raises_naming(name, lambda: fastcontact.TabulatedPSD(q, C, convention=conv))


@pytest.mark.parametrize("conv", [None, "", "st", "contact.engineering"])
def test_read_psd_needs_convention(tmp_path, conv):
    path = tmp_path / "psd.txt"
    np.savetxt(path, np.column_stack([_Q, _C]), header="q [1/m]  C [m^4]")
    _raises_naming("convention", lambda: fastcontact.read_psd(path, conv))
    _raises_naming("convention", lambda: fastcontact.read_psd(str(path), conv))


@pytest.mark.parametrize("bad", [-1e-6, 0.0, NAN])
def test_psd_from_heights_bad_spacing(bad):
    h = np.random.default_rng(0).standard_normal((16, 16)) * 1e-6
    _raises_naming("spacing", lambda: fastcontact.psd_from_heights(h, bad))


# --------------------------------------------------------- effective_modulus
@pytest.mark.parametrize("name,args", [
    ("E", dict(E=-1e7, nu=0.3)), ("E", dict(E=0.0, nu=0.3)), ("E", dict(E=NAN, nu=0.3)),
    ("nu", dict(E=1e7, nu=-0.1)), ("nu", dict(E=1e7, nu=0.51)), ("nu", dict(E=1e7, nu=NAN)),
    ("E2", dict(E=1e7, nu=0.3, E2=-1e9, nu2=0.3)), ("E2", dict(E=1e7, nu=0.3, E2=0.0, nu2=0.3)),
    ("E2", dict(E=1e7, nu=0.3, E2=NAN, nu2=0.3)),
    ("nu2", dict(E=1e7, nu=0.3, E2=1e9, nu2=-0.01)), ("nu2", dict(E=1e7, nu=0.3, E2=1e9, nu2=0.7)),
    ("nu2", dict(E=1e7, nu=0.3, E2=1e9, nu2=NAN)),
])
def test_effective_modulus_bad(name, args):
    _raises_naming(name, lambda: fastcontact.effective_modulus(**args))


# ------------------------------------------------------ contact functions
_CONTACT_P_FUNCS = {
    "area_fraction": lambda psd, p, E: contact.area_fraction(psd, p, E),
    "mean_separation": lambda psd, p, E: contact.mean_separation(psd, p, E),
    "mean_separation_gamma": lambda psd, p, E: contact.mean_separation(psd, p, E, gamma=0.45),
    "u1": lambda psd, p, E: contact.u1(psd, p, E, 2.0),
    "critical_magnification": lambda psd, p, E: contact.critical_magnification(psd, p, E),
}


@pytest.mark.parametrize("bad", [-1e7, 0.0, NAN])
@pytest.mark.parametrize("func", list(_CONTACT_P_FUNCS))
def test_contact_bad_E_star(func, bad):
    _raises_naming("E_star", lambda: _CONTACT_P_FUNCS[func](_psd(), 1e4, bad))


@pytest.mark.parametrize("bad", [-1e3, 0.0, NAN, np.array([1e3, -1e3, 1e4]), np.array([1e3, NAN])],
                         ids=["neg", "zero", "nan", "array-neg", "array-nan"])
@pytest.mark.parametrize("func", list(_CONTACT_P_FUNCS))
def test_contact_bad_pressure(func, bad):
    _raises_naming("p", lambda: _CONTACT_P_FUNCS[func](_psd(), bad, E_STAR))


@pytest.mark.parametrize("bad", [-1e-6, 0.0, NAN, np.array([1e-5, -1e-6])],
                         ids=["neg", "zero", "nan", "array-neg"])
def test_contact_pressure_bad_separation(bad):
    _raises_naming("u", lambda: contact.contact_pressure(_psd(), bad, E_STAR))


@pytest.mark.parametrize("bad", [-1e7, 0.0, NAN])
def test_contact_pressure_bad_E_star(bad):
    _raises_naming("E_star", lambda: contact.contact_pressure(_psd(), 1e-5, bad))
