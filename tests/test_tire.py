"""Issue 11.2 / 15.1: tire_footprint and tire_history on the time primitive — every column
from one pass with each case's own footprint time, against the per-case quadrature."""
from __future__ import annotations

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from frames import assert_columns_match  # noqa: E402

from fastcontact.squeeze import squeeze_history  # noqa: E402
from fastcontact.tables import Tables  # noqa: E402
from fastcontact.tables.defaults import default_table_path  # noqa: E402
from fastcontact.tire import tire_columns, tire_footprint, tire_history  # noqa: E402

E = 13e6


@pytest.fixture(scope="module")
def T():
    return Tables.from_parquet(default_table_path("asphalt_024mm"))


@pytest.mark.parametrize("theory", ["average", "critical_junction"])
def test_fast_matches_quad_with_distinct_footprints(T, theory):
    rng = np.random.default_rng(5)
    n = 60
    kw = dict(p0=rng.uniform(0.05e6, 0.5e6, n), E_star=E, R=rng.uniform(0.005, 0.03, n),
              eta=10.0 ** rng.uniform(-3, 0, n), footprint_length=rng.uniform(0.05, 0.2, n),
              speed=rng.uniform(5, 40, n), u_start=10.0 ** rng.uniform(-2.5, -2, n), theory=theory)
    f = tire_footprint(T, **kw, method="fast")
    q = tire_footprint(T, **kw, method="quad")
    assert list(f.columns) == tire_columns()
    assert (f["status"] == "ok").all()
    for c in ("u_inf", "t_du", "t_star", "t_ratio_1.1", "t_ratio_1.001"):
        np.testing.assert_allclose(f[c], q[c], rtol=1e-6, err_msg=c)
    ui = q["u_inf"].to_numpy()
    np.testing.assert_array_less(np.abs(f["du_exit"] - q["du_exit"]),
                                 np.maximum(1e-6 * np.abs(q["du_exit"]), 1e-8 * ui) + 1e-300)
    # incomplete squeeze-out (viscous hydroplaning) happens for the viscous fluids
    assert f["squeeze_complete"].any() and not f["squeeze_complete"].all()
    assert (f["squeeze_complete"] == q["squeeze_complete"]).all()


def test_units_status_and_exact_ratio_columns(T):
    df = tire_footprint(T, p0=0.2e6, E_star=E, R=0.02, eta=1e-3, footprint_length=0.1,
                        speed=30.0, ratios=(1.0000001, 1.0000002))
    assert len([c for c in df.columns if c.startswith("t_ratio_")]) == 2
    assert set(df.attrs["units"]) == set(df.columns) and df.attrs["units"]["u_exit"] == "m"
    assert df["status"].iloc[0] == "ok"
    with pytest.raises(ValueError, match="ratios"):
        tire_footprint(T, p0=0.2e6, E_star=E, R=0.02, eta=1e-3, footprint_length=0.1,
                       speed=30.0, ratios=(1.1, 1.1))
    lo, hi = T.p_range
    bad = tire_footprint(T, p0=np.array([0.2e6, 2 * hi * E]), E_star=E, R=0.02, eta=1e-3,
                         footprint_length=0.1, speed=30.0)
    assert list(bad["status"]) == ["ok", "out_of_table"]
    assert np.isnan(bad["u_exit"].iloc[1]) and not bad["squeeze_complete"].iloc[1]


def test_history_matches_squeeze_history(T):
    t = np.geomspace(1e-8, 1e-1, 500)
    a = tire_history(T, p0=0.2e6, E_star=E, R=0.02, eta=1e-3, t=t, theory="average")
    b = squeeze_history(T, 0.2e6, E, 0.02, 1e-3, "average", t=t, u_start=1e-2)
    np.testing.assert_array_equal(a["u"], b["u"])
    assert np.all(np.diff(a["u"]) <= 0) and np.all(a["du"] >= 0)
    assert a.attrs["units"]["du"] == "m"


def test_history_at_infinite_time_is_equilibrium(T):
    """t = +inf is allowed (as in squeeze_history) and gives ū∞ itself; t = 0 the start."""
    t = np.array([1e-7, np.inf, 0.0])
    a = tire_history(T, p0=0.2e6, E_star=E, R=0.02, eta=1e-3, t=t, theory="average")
    b = squeeze_history(T, 0.2e6, E, 0.02, 1e-3, "average", t=t, u_start=1e-2)
    np.testing.assert_array_equal(a["u"], b["u"])
    assert a["u"].iloc[1] == a["u_inf"].iloc[1] and a["du"].iloc[1] == 0.0
    assert a["u"].iloc[2] == 1e-2 and a["u"].iloc[0] > a["u_inf"].iloc[0]
    with pytest.raises(ValueError, match="t"):
        tire_history(T, p0=0.2e6, E_star=E, R=0.02, eta=1e-3, t=[np.nan], theory="average")


@pytest.mark.parametrize("method", ["fast", "quad"])
def test_columns_select_what_the_kernel_computes(T, method, monkeypatch):
    """A study asking for some columns gets them equal to the full call's, and the engine
    computes only the targets they need (the run_cases call is spied on)."""
    import fastcontact.squeeze.tire as tire_mod

    rng = np.random.default_rng(11)
    n = 40
    kw = dict(p0=rng.uniform(0.05e6, 0.5e6, n), E_star=E, R=rng.uniform(0.005, 0.03, n),
              eta=10.0 ** rng.uniform(-3, 0, n), footprint_length=rng.uniform(0.05, 0.2, n),
              speed=rng.uniform(5, 40, n), theory="average", method=method)
    full = tire_footprint(T, **kw)
    calls = []
    real = tire_mod.run_cases

    def spy(model, cs, ratios, dvs, times2d, *a, **k):
        calls.append((tuple(ratios), dvs.size, times2d.shape[0]))
        return real(model, cs, ratios, dvs, times2d, *a, **k)

    monkeypatch.setattr(tire_mod, "run_cases", spy)
    cases = {("t_star", "status"): ((), 0, 0),
             ("t_ratio_1.01", "u_inf"): ((1.01,), 0, 0),
             ("t_du", "t_ratio_1.1", "t_ratio_1.001"): ((1.1, 1.001), 1, 0),
             ("squeeze_complete",): ((), 0, 1),
             ("u_exit", "du_exit", "trapped"): ((), 0, 1),
             ("p_eval", "tau_inertia"): None}
    for cols, targets in cases.items():
        calls.clear()
        df = tire_footprint(T, **kw, columns=list(cols))
        assert list(df.columns) == list(cols)
        assert calls == ([] if targets is None else [targets]), cols
        assert_columns_match(df, full, cols)


@pytest.mark.parametrize("method", ["fast", "quad"])
@pytest.mark.parametrize("u_start", [None, 1e-2, np.nan])
def test_shared_inputs_are_one_value_not_a_million_copies(T, method, u_start):
    """E*, R, η and ū(0) given as one number reach the kernels as one value (size-1 case
    arrays, no array of n copies): every column equals the call with the same values spelled
    out per case — with rows out of the tables (per-case quadrature rows) in the batch."""
    import fastcontact.squeeze.tire as tire_mod

    rng = np.random.default_rng(17)
    n = 400
    lo, hi = T.p_range
    p0 = np.exp(rng.uniform(np.log(0.5 * lo * E), np.log(2.0 * hi * E), n))
    kw = dict(p0=p0, footprint_length=rng.uniform(0.05, 0.2, n), speed=rng.uniform(5, 40, n),
              theory="emt", method=method)
    us = {} if u_start is None else {"u_start": u_start}
    seen = []
    real = tire_mod.run_cases

    def spy(model, cs, *a, **k):
        seen.append((cs.E.size, cs.R.size, cs.eta.size, cs.us.size))
        return real(model, cs, *a, **k)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(tire_mod, "run_cases", spy)
        if u_start is not None and np.isnan(u_start):
            with pytest.raises(ValueError, match="u_start"):
                tire_footprint(T, **kw, E_star=E, R=0.01, eta=1e-3, **us)
            return
        one = tire_footprint(T, **kw, E_star=E, R=0.01, eta=1e-3, **us)
    assert seen == [(1, 1, 1, 1)]
    per_case = {k: np.full(n, v) for k, v in us.items()}
    full = tire_footprint(T, **kw, E_star=np.full(n, E), R=np.full(n, 0.01),
                          eta=np.full(n, 1e-3), **per_case)
    assert set(one["status"]) >= {"ok", "out_of_table"}
    for c in full.columns:
        a, b = one[c].to_numpy(), full[c].to_numpy()
        if a.dtype.kind in "fb":
            np.testing.assert_array_equal(a, b, err_msg=c)
        else:
            assert (one[c] == full[c]).all(), c


def test_case_arrays_of_a_third_size_are_refused(T):
    """A case array with neither one value per case nor one for all is an error, not an
    out-of-bounds read in the kernel."""
    from fastcontact.squeeze import _kernels as qk
    from fastcontact.squeeze.api import QUAD_ORDER, _check_method, run_cases
    from fastcontact.squeeze.model import squeeze_model

    model = squeeze_model(T, "average")
    quad, _ = _check_method("fast", QUAD_ORDER, 1.0, None)
    cs = qk.Cases(np.full(5, 1e5), np.full(3, E), np.full(1, 0.01), np.full(5, 1e-3),
                  np.full(1, np.nan))
    with pytest.raises(ValueError, match="E has 3 values, p0 5"):
        run_cases(model, cs, np.zeros(0), np.zeros(0), np.zeros((0, 1)), "fast", quad)
