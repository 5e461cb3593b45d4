"""Issue 15.3: bad input to the engines is refused by name, in one readable line.

Fuzzes every numeric parameter of ``squeeze_out``, ``seal_leak`` (uniform and Hertz) and
``tire_footprint`` with values that are not real numbers (bools, dates, timedeltas, complex,
strings, bytes, objects, None, pd.NA) or not valid (NaN), and checks that the engine raises
``ValueError`` (or ``TypeError``) whose message is one line and names the parameter as a word.
Masked arrays must be honoured (the masked row is not computed from the hidden value) or
refused; pandas inputs must be aligned by index label or refused; result column names must
be unique and exact (no rounding collisions).
"""
from __future__ import annotations

import datetime
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import fastcontact
from fastcontact.seal import seal_leak
from fastcontact.squeeze import squeeze_out
from fastcontact.squeeze.tire import tire_footprint
from fastcontact.tables import Tables

TABLE = Path(__file__).resolve().parent.parent / "tables" / "pmma_34um.parquet"

BAD_VALUES = {
    "True": True,
    "False": False,
    "np.True_": np.bool_(True),
    "bool_array": np.array([True, False]),
    "datetime64": np.datetime64("2020-01-01"),
    "datetime64_array": np.array(["2020-01-01", "2021-01-01"], dtype="datetime64[D]"),
    "timedelta64": np.timedelta64(5, "s"),
    "datetime": datetime.datetime(2020, 1, 1),
    "pd.Timestamp": pd.Timestamp("2020-01-01"),
    "complex": 1e4 + 0j,
    "complex_array": np.array([1e4 + 1j, 2e4]),
    "string": "1e4",
    "bytes": b"1e4",
    "object": object(),
    "object_array": np.array([1e4, object()], dtype=object),
    "None": None,
    "pd.NA": pd.NA,
    "nan": math.nan,
    "nan_array": np.array([1e4, math.nan]),
    "list_of_str": ["1e4", "2e4"],
    "dict": {"a": 1.0},
}

SQUEEZE_OK = dict(p0=1e4, E_star=1e7, R=0.01, eta=1e-3)
SEAL_OK = dict(p0=1e5, dp=1e4, L=1e-3, L_y=0.1, E_star=1e7, eta=1e-3)
HERTZ_OK = dict(R=1e-3, f_N=10.0, dp=1e4, L_y=0.1, E_star=1e7, eta=1e-3, profile="hertz")
TIRE_OK = dict(p0=2e5, E_star=1e7, R=0.02, eta=1e-3, footprint_length=0.1, speed=30.0)


@pytest.fixture(scope="module")
def tab():
    return Tables.from_parquet(TABLE)


def _names(name, msg):
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])", msg) is not None


def refused_by_name(name, fn):
    """fn() must raise ValueError/TypeError with a one-line message naming ``name``."""
    try:
        fn()
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        assert "\n" not in msg.strip(), f"message is not one line: {msg!r}"
        assert _names(name, msg), f"message does not name {name!r}: {msg!r}"
        assert len(msg) < 400, f"message too long to read: {msg!r}"
        return
    except Exception as exc:  # noqa: BLE001 - any other exception is a failure
        pytest.fail(f"{name}: raised {type(exc).__name__}: {exc}", pytrace=False)
    pytest.fail(f"{name}: bad input accepted silently", pytrace=False)


def _cases(ok, skip=()):
    out = []
    for p in ok:
        if p in skip or isinstance(ok[p], str):
            continue
        for label, val in BAD_VALUES.items():
            if p == "u_start" and label == "None":
                continue
            out.append((p, label))
    return out


@pytest.mark.parametrize("param,label", _cases(dict(SQUEEZE_OK, u_start=1e-3)))
def test_squeeze_out_bad(tab, param, label):
    kw = dict(SQUEEZE_OK, **{param: BAD_VALUES[label]})
    refused_by_name(param, lambda: squeeze_out(tab, method="quad", **kw))


@pytest.mark.parametrize("param,label", _cases(dict(SEAL_OK, p_b=0.0, alpha_cj=1.0)))
def test_seal_uniform_bad(tab, param, label):
    kw = dict(SEAL_OK, **{param: BAD_VALUES[label]})
    refused_by_name(param, lambda: seal_leak(tab, theory="critical_junction", **kw))


# (R = None / f_N = None is the documented "not given", refused by name as "required")
@pytest.mark.parametrize("param,label", _cases(HERTZ_OK, skip=("profile",)))
def test_seal_hertz_bad(tab, param, label):
    kw = dict(HERTZ_OK, **{param: BAD_VALUES[label]})
    refused_by_name(param, lambda: seal_leak(tab, theory="critical_junction", **kw))


@pytest.mark.parametrize("param,label", _cases(dict(TIRE_OK, rho=1000.0, du_complete=1e-6)))
def test_tire_bad(tab, param, label):
    kw = dict(TIRE_OK, **{param: BAD_VALUES[label]})
    refused_by_name(param, lambda: tire_footprint(tab, **kw))


# ------------------------------------------------------------------ option parameters
@pytest.mark.parametrize("param,value", [
    ("quad_order", math.nan), ("quad_order", 2.5), ("quad_order", True), ("quad_order", "10"),
    ("quad_order", 0), ("quad_order", 10 ** 6),
    ("quad_width", math.nan), ("quad_width", -1.0), ("quad_width", True),
    ("sigma_trap", math.nan), ("sigma_trap", True), ("sigma_trap", -1e-24),
    ("method", "spline"), ("method", None), ("theory", "bruggeman"), ("theory", None),
    ("ratios", (1.0,)), ("ratios", (math.nan,)), ("ratios", (True,)), ("ratios", ("1.1",)),
    ("ratios", (0.5,)), ("du", (-1e-6,)), ("du", (math.nan,)), ("du", (0.0,)),
    ("du", (True,)), ("times", (-1.0,)), ("times", (math.nan,)), ("times", (True,)),
    ("times", (np.datetime64("2020-01-01"),)),
])
def test_squeeze_options_bad(tab, param, value):
    kw = dict(SQUEEZE_OK, **{param: value})
    refused_by_name(param, lambda: squeeze_out(tab, **kw))


@pytest.mark.parametrize("method", ["fast", "quad"])
def test_du_below_resolution(tab, method):
    """du = 1e-20 m (below double resolution of ū∞ + du): refused naming ``du``, or a result
    whose every non-finite value is flagged (never a traceback, never an unflagged NaN)."""
    p0 = np.array([1e2, 1e4, 1e6])
    try:
        df = squeeze_out(tab, p0=p0, E_star=1e7, R=0.01, eta=1e-3, du=[1e-20], method=method)
    except (ValueError, TypeError) as exc:
        assert "\n" not in str(exc).strip() and _names("du", str(exc)), str(exc)
        return
    except Exception as exc:  # noqa: BLE001
        pytest.fail(f"du=[1e-20]: {type(exc).__name__}: {exc}", pytrace=False)
    from test_invariants import check_squeeze
    v = check_squeeze(df, ratios=(1.1, 1.01, 1.001), du=(1e-20,))
    bad = {k: int(np.sum(m)) for k, m in v.items() if np.any(m)}
    assert not bad, f"du=[1e-20] ({method}): {bad}\n{df.to_dict('records')}"


def test_precompute_grid_bad():
    psd = fastcontact.SelfAffinePSD(h_rms=1e-5, hurst=0.8, q0=1e4, q1=1e8)
    for grid in ((1, 2), (1, 2, 3, 4), (-12, 0, math.nan), (-12, 0, 2.5), (0, -12, 50),
                 (-12, math.inf, 50), "grid", (True, 0, 50)):
        refused_by_name("grid", lambda: fastcontact.precompute(psd, theories=("average",),
                                                               grid=grid))


# ------------------------------------------------------------------ columns
@pytest.mark.parametrize("method", ["fast", "quad"])
def test_ratio_columns_unique_and_exact(tab, method):
    ratios = (1.0000001, 1.0000002)
    df = squeeze_out(tab, **SQUEEZE_OK, ratios=ratios, method=method)
    cols = [c for c in df.columns if str(c).startswith("t_ratio_")]
    assert len(cols) == 2 and len(set(cols)) == 2, cols
    for c, r in zip(cols, ratios):
        assert float(c[len("t_ratio_"):]) == r, (c, r)
    assert not pd.Index(df.columns).duplicated().any()
    t = df[cols].to_numpy(float)[0]
    assert t[1] < t[0], "the lower target ratio must take longer"


def test_du_and_times_columns_unique_and_exact(tab):
    du = (1.0000001e-6, 1.0000002e-6)
    times = (1.0000001e-3, 1.0000002e-3)
    df = squeeze_out(tab, **SQUEEZE_OK, du=du, times=times, method="quad")
    dc = [c for c in df.columns if str(c).startswith("t_du_")]
    uc = [c for c in df.columns if str(c).startswith("u_at_")]
    assert len(set(dc)) == 2 and len(set(uc)) == 2, (dc, uc)
    for c, d in zip(dc, du):
        assert float(c[len("t_du_"):]) == d, (c, d)
    for c, t in zip(uc, times):
        assert float(c[len("u_at_"):]) == t, (c, t)


def test_tire_ratio_columns_unique(tab):
    df = tire_footprint(tab, **TIRE_OK, ratios=(1.0000001, 1.0000002))
    cols = [c for c in df.columns if str(c).startswith("t_ratio_")]
    assert len(set(cols)) == 2, cols


# ------------------------------------------------------------------ masked / pandas
def test_masked_array_honoured_or_refused(tab):
    p0 = np.ma.array([1e4, 2e4, 3e4], mask=[False, True, False])
    try:
        df = squeeze_out(tab, p0=p0, E_star=1e7, R=0.01, eta=1e-3, method="quad")
    except (ValueError, TypeError) as exc:
        assert _names("p0", str(exc)) and "\n" not in str(exc).strip(), str(exc)
        return
    ref = squeeze_out(tab, p0=np.array([2e4]), E_star=1e7, R=0.01, eta=1e-3, method="quad")
    if len(df) == 2:
        return                                            # masked row dropped: honoured
    assert len(df) == 3
    assert not (df["t_star"].iloc[1] == ref["t_star"].iloc[0]), \
        "the masked value was used as if it were not masked"


def test_seal_masked_array_honoured_or_refused(tab):
    dp = np.ma.array([1e3, 2e3], mask=[False, True])
    try:
        df = seal_leak(tab, **dict(SEAL_OK, dp=dp))
    except (ValueError, TypeError) as exc:
        assert _names("dp", str(exc)) and "\n" not in str(exc).strip(), str(exc)
        return
    ref = seal_leak(tab, **dict(SEAL_OK, dp=2e3))
    assert len(df) == 1 or not (df["Q"].iloc[1] == ref["Q"].iloc[0]), \
        "the masked value was used as if it were not masked"


def _aligned_or_refused(fn, a_name, a, b_name, b, out_a, out_b):
    try:
        df = fn()
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        assert "\n" not in msg.strip(), msg
        assert _names(a_name, msg) or _names(b_name, msg), msg
        return
    got = set(zip(df[out_a].to_numpy(float).tolist(), df[out_b].to_numpy(float).tolist()))
    want = {(float(a[k]), float(b[k])) for k in a.index}
    assert got == want, f"pandas inputs paired by position, not by index label: {got} != {want}"


def test_squeeze_pandas_aligned_by_label(tab):
    p0 = pd.Series([1e4, 2e4, 3e4], index=["a", "b", "c"])
    R = pd.Series([0.01, 0.02, 0.03], index=["c", "a", "b"])
    _aligned_or_refused(lambda: squeeze_out(tab, p0=p0, E_star=1e7, R=R, eta=1e-3, method="quad"),
                        "p0", p0, "R", R, "p0", "R")


def test_seal_pandas_aligned_by_label(tab):
    p0 = pd.Series([1e5, 2e5, 3e5], index=[0, 1, 2])
    dp = pd.Series([1e3, 2e3, 3e3], index=[2, 0, 1])
    _aligned_or_refused(lambda: seal_leak(tab, **dict(SEAL_OK, p0=p0, dp=dp)),
                        "p0", p0, "dp", dp, "p0", "dp")


def test_pandas_disjoint_labels_refused(tab):
    p0 = pd.Series([1e4, 2e4], index=[0, 1])
    R = pd.Series([0.01, 0.02], index=[5, 6])
    refused = False
    try:
        df = squeeze_out(tab, p0=p0, E_star=1e7, R=R, eta=1e-3, method="quad")
    except (ValueError, TypeError) as exc:
        refused = _names("p0", str(exc)) or _names("R", str(exc))
    if not refused:
        pytest.fail(f"Series with disjoint labels were paired silently: {df[['p0', 'R']]}",
                    pytrace=False)
