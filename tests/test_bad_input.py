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


# ------------------------------------------------- issue 15.3: types refused by name
import datetime as _dt  # noqa: E402

import pandas as pd  # noqa: E402

from fastcontact._core.validate import align_inputs, check_positive  # noqa: E402

_BAD_TYPES = [
    True, False, np.bool_(True), np.array([True, False]), [1e5, True],
    np.datetime64("2024-01-01"), np.timedelta64(3, "s"), _dt.datetime(2024, 1, 1),
    _dt.timedelta(seconds=1), 1 + 2j, np.complex128(1.0), np.array([1.0 + 0j]),
    "1e5", np.array(["1e5"]), b"1e5", None, object(), {"p": 1e5}, [1e5, [2e5, 3e5]],
    pd.Series([1e5, pd.NA], dtype="Float64"),
]
_IDS = ["True", "False", "np.bool_", "bool-array", "list-with-True", "datetime64",
        "timedelta64", "datetime", "timedelta", "complex", "complex128", "complex-array",
        "str", "str-array", "bytes", "None", "object", "dict", "ragged", "pd.NA"]


def _one_line_naming(name, fn):
    with pytest.raises(ValueError) as exc:
        fn()
    msg = str(exc.value)
    assert msg.startswith(f"{name} = "), msg
    assert "\n" not in msg and "is invalid" in msg, msg


@pytest.mark.parametrize("bad", _BAD_TYPES, ids=_IDS)
def test_bad_types_refused_in_contact(bad):
    _one_line_naming("p", lambda: contact.mean_separation(_psd(), bad, E_STAR))
    _one_line_naming("E_star", lambda: contact.mean_separation(_psd(), 1e5, bad))


@pytest.mark.parametrize("bad", _BAD_TYPES, ids=_IDS)
def test_bad_types_refused_in_psd(bad):
    _one_line_naming("h_rms", lambda: fastcontact.SelfAffinePSD(**dict(GOOD_PSD, h_rms=bad)))


def test_bool_message_says_why():
    with pytest.raises(ValueError, match=r"^E_star = True is invalid: must be a real number .*"
                                         r"\[Pa\]; it is a boolean"):
        contact.mean_separation(_psd(), 1e5, True)


def test_masked_arrays_honoured():
    p = np.ma.masked_array([1e4, 2e4, 3e4], mask=[False, True, False])
    with pytest.raises(ValueError, match=r"^p = .* is invalid: must have no masked values; 1 masked value\(s\), first at "
                                         r"index \(1,\)"):
        contact.mean_separation(_psd(), p, E_STAR)
    clean = np.ma.masked_array([1e4, 3e4], mask=[False, False])
    np.testing.assert_array_equal(contact.mean_separation(_psd(), clean, E_STAR),
                                  contact.mean_separation(_psd(), np.array([1e4, 3e4]), E_STAR))
    with pytest.raises(ValueError, match="masked"):
        fastcontact.TabulatedPSD(np.ma.masked_array(_Q, mask=_Q > 1e7), _C)


def test_tabulated_psd_refuses_2d():
    with pytest.raises(ValueError, match=r"^q has shape \(2, 4\).*never flattened"):
        fastcontact.TabulatedPSD(_Q.reshape(2, 4), _C.reshape(2, 4))
    with pytest.raises(ValueError, match=r"^C has shape \(8, 1\)"):
        fastcontact.TabulatedPSD(_Q, _C.reshape(8, 1))


def test_nan_refused_where_invalid():
    _one_line_naming("p", lambda: contact.mean_separation(_psd(), np.array([1e4, NAN]), E_STAR))
    _one_line_naming("C", lambda: fastcontact.TabulatedPSD(_Q, np.where(_Q > 1e6, NAN, _C)))


def test_pandas_series_accepted_and_aligned_by_label():
    s = pd.Series([1e4, 2e4], index=["a", "b"])
    np.testing.assert_array_equal(contact.mean_separation(_psd(), s, E_STAR),
                                  contact.mean_separation(_psd(), np.array([1e4, 2e4]), E_STAR))
    p0 = pd.Series([1.0, 2.0, 3.0], index=["x", "y", "z"])
    eta = pd.Series([30.0, 10.0, 20.0], index=["z", "x", "y"])
    out = align_inputs(p0=p0, eta=eta, R=0.01)
    assert out["eta"].tolist() == [10.0, 20.0, 30.0] and out["R"] == 0.01
    with pytest.raises(ValueError, match=r"^p0 and eta are pandas Series whose index labels "
                                         r"disagree \(only in p0: \['z'\]; only in eta: \['w'\]\)"):
        align_inputs(p0=p0, eta=pd.Series([1.0, 2.0, 3.0], index=["x", "y", "w"]))
    with pytest.raises(ValueError, match="duplicated labels"):
        align_inputs(p0=p0, eta=pd.Series([1.0, 2.0, 3.0], index=["x", "x", "y"]))


def test_every_message_is_one_line():
    h = np.random.default_rng(0).standard_normal((16, 16)) * 1e-6
    for fn in (lambda: check_positive("x", "abc", "[m]"),
               lambda: fastcontact.psd_from_heights(h, True),
               lambda: fastcontact.psd_from_heights(h, 1e-6, n_bins=True),
               lambda: fastcontact.psd_from_heights(np.ma.masked_invalid(h * np.nan), 1e-6)):
        with pytest.raises(ValueError) as exc:
            fn()
        assert "\n" not in str(exc.value)
