"""Issue 14.2: tire_footprint(alpha_pv=) — a Barus fluid in the tread-block squeeze-out.

References: α = 0 is the base engine bit for bit; α > 0 against
``tests/reference/ext_reynolds.py`` (radial Reynolds equation with η(p) integrated directly,
no reduced pressure; the time between two separations by scipy quad): the times to the
targets, and ū at the footprint exit (the reference time from ū(0) to the engine's ū_exit
must be the footprint time).
"""
from __future__ import annotations

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_reynolds import squeeze_time  # noqa: E402
from frames import assert_columns_match  # noqa: E402

import fastcontact as fc  # noqa: E402
from fastcontact.squeeze.tire import tire_columns, tire_footprint  # noqa: E402

E_STAR, ETA, R = 1e7, 1e-3, 0.01
ALPHA = 2.5e-6                      # α p0 = 0.5 at p0 = 0.2 MPa: the rate factor is ~0.7


@pytest.fixture(scope="module")
def tables():
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    return fc.precompute(psd, theories=("average", "emt"))


def _kw(tables):
    return dict(p0=np.array([1e5, 2e5]), E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1,
                speed=np.array([[30.0], [1.0]]), theory="emt", u_start=20 * tables.h_rms)


@pytest.mark.parametrize("method", [None, "quad", "fast"])
def test_alpha_zero_is_bit_identical(tables, method):
    kw = _kw(tables)
    assert tire_footprint(tables, method=method, **kw).equals(
        tire_footprint(tables, method=method, alpha_pv=0.0, **kw))


def test_against_reynolds_reference(tables):
    df = tire_footprint(tables, alpha_pv=ALPHA, **_kw(tables))
    assert list(df.columns) == tire_columns()
    assert set(df.status) == {"ok"}
    base = tire_footprint(tables, **_kw(tables))
    for i in (1, 2):
        r = df.iloc[i]
        ref = squeeze_time(tables, "emt", r.p_eval, E_STAR, R, ETA, ALPHA, r.u_start,
                           1.1 * r.u_inf, r.u_inf)
        assert abs(r["t_ratio_1.1"] / ref - 1) < 1e-7
        ref_du = squeeze_time(tables, "emt", r.p_eval, E_STAR, R, ETA, ALPHA, r.u_start,
                              r.u_inf + 1e-6, r.u_inf)
        assert abs(r.t_du / ref_du - 1) < 1e-7
        # ū at the exit: the reference time from ū(0) to ū_exit is the footprint time
        assert r.u_exit > r.u_inf
        t_exit = squeeze_time(tables, "emt", r.p_eval, E_STAR, R, ETA, ALPHA, r.u_start,
                              r.u_exit, r.u_inf)
        assert abs(t_exit / r.t_footprint - 1) < 1e-7
        # slower than water of constant viscosity, but at most twice (g >= 1/2)
        b = base.iloc[i]
        assert b["t_ratio_1.1"] < r["t_ratio_1.1"] < 2 * b["t_ratio_1.1"]
        assert r.u_exit > b.u_exit
    np.testing.assert_array_equal(df.u_inf, base.u_inf)   # equilibrium: viscosity-free
    np.testing.assert_allclose(df.du_exit, df.u_exit - df.u_inf, rtol=0)
    assert list(df.squeeze_complete) == list(df.du_exit <= 1e-6)


def test_exit_time_consistency(tables):
    """ū_exit at a footprint time equal to t_ratio_1.1 is 1.1 ū∞ (same quadrature both ways)."""
    one = tire_footprint(tables, alpha_pv=ALPHA, p0=2e5, E_star=E_STAR, R=R, eta=ETA,
                         footprint_length=0.1, speed=30.0, theory="emt",
                         u_start=20 * tables.h_rms)
    t = float(one["t_ratio_1.1"][0])
    again = tire_footprint(tables, alpha_pv=ALPHA, p0=2e5, E_star=E_STAR, R=R, eta=ETA,
                           footprint_length=0.1, speed=0.1 / t, theory="emt",
                           u_start=20 * tables.h_rms)
    assert abs(again.u_exit[0] / (1.1 * again.u_inf[0]) - 1) < 1e-8


def test_mixed_rows_and_flags(tables):
    kw = dict(p0=np.array([1e5, 2e5, 4e5]), E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1,
              speed=3.0, theory="emt", u_start=20 * tables.h_rms)
    base = tire_footprint(tables, **kw)
    mix = tire_footprint(tables, alpha_pv=np.array([0.0, ALPHA, 1e-5]), **kw)
    # α = 0 rows: the base engine's numbers exactly
    for c in ("t_star", "t_du", "u_exit", "u_inf", "t_ratio_1.01"):
        assert mix[c][0] == base[c][0]
    assert mix.status[1] == "ok" and mix.t_star[1] > base.t_star[1]
    # α (p0 - p_cont(ū0)) >= 1: no quasi-static solution, flagged with NaN results
    assert mix.status[2] == "piezo_limit"
    assert np.isnan(mix.t_star[2]) and np.isnan(mix.u_exit[2])
    assert not mix.squeeze_complete[2]
    assert mix.tau_inertia[2] == base.tau_inertia[2]      # the inertia estimate is unchanged
    with pytest.raises(ValueError, match="alpha_pv"):
        tire_footprint(tables, alpha_pv=-1e-8, **kw)


def test_start_below_equilibrium_flagged_trapped_rows_too(tables):
    """A start at or below ū∞ is status "start_below_equilibrium" with NaN times, also where
    p0 is beyond the trap pressure — as the base engine (α = 0) says for the same rows."""
    p_trap = tables.info["percolation_p_over_E"]["emt"] * E_STAR
    p0 = np.array([0.3 * p_trap, 1.5 * p_trap])
    kw = dict(p0=p0, E_star=E_STAR, R=R, eta=ETA, footprint_length=0.1, speed=10.0,
              theory="emt")
    u_inf = tire_footprint(tables, **kw)["u_inf"].to_numpy()
    low = dict(kw, u_start=0.5 * u_inf)
    base = tire_footprint(tables, **low)
    barus = tire_footprint(tables, alpha_pv=1e-9, **low)
    assert list(base.status) == ["start_below_equilibrium"] * 2
    assert list(barus.status) == list(base.status)
    for c in ("t_star", "t_du", "u_exit", "u_trap", "fluid_load_fraction"):
        assert np.all(np.isnan(barus[c])) and np.all(np.isnan(base[c])), c


@pytest.mark.parametrize("engine", ["one fluid", "two fluids", "quad"])
def test_columns_select_what_the_barus_kernel_computes(tables, engine, monkeypatch):
    """With α > 0 a study asking for some columns gets them equal to the full call's, and the
    engine computes only the targets they need (its call is spied on: the ratio targets after
    t_star, the Δu targets and whether footprint times reach it) — the base kernel on the
    Barus time primitive where the call has one α and one E* ("one fluid"), the per-case
    Barus kernel where it has two, the quadrature; rows with α = 0 in the same call (the base
    engine) follow the same selection."""
    import fastcontact.squeeze._barus_fast as bf
    import fastcontact.squeeze._barus_time as bt
    import fastcontact.squeeze.tire_piezo as tp

    rng = np.random.default_rng(5)
    n = 30
    alpha = np.where(rng.random(n) < 0.2, 0.0, ALPHA)
    if engine == "two fluids":
        alpha[rng.random(n) < 0.3] = 0.5 * ALPHA
    method = "quad" if engine == "quad" else "fast"
    kw = dict(p0=rng.uniform(0.05e6, 0.2e6, n), E_star=E_STAR, R=R, eta=ETA,
              footprint_length=0.1, speed=rng.uniform(5, 40, n), theory="emt",
              u_start=20 * tables.h_rms, alpha_pv=alpha, method=method)
    full = tire_footprint(tables, **kw)
    calls = []
    mod, name = {"one fluid": (bt, "tire_rows"), "two fluids": (bf, "tire_kernel"),
                 "quad": (tp, "_tire_kernel")}[engine]
    real = getattr(mod, name)

    def spy(*args):
        if engine == "one fluid":  # (model, bg, cases, t_fp, h, ratios, dvs, ...)
            r, dvs, t_fp = tuple(args[5]), args[6].size, args[3]
        else:
            tg, t_fp = (args[10], args[8]) if method == "fast" else (args[6], args[4])
            r, dvs = tuple(tg.ratios[1:]), tg.dvs.size
        calls.append((r, dvs, t_fp.size > 0))
        return real(*args)

    monkeypatch.setattr(mod, name, spy)
    cases = {("t_star", "status"): ((), 0, False),
             ("t_ratio_1.01", "u_inf"): ((1.01,), 0, False),
             ("t_du", "t_ratio_1.1", "t_ratio_1.001"): ((1.1, 1.001), 1, False),
             ("squeeze_complete",): ((), 0, True),
             ("u_exit", "du_exit", "trapped"): ((), 0, True)}
    for cols, targets in cases.items():
        calls.clear()
        df = tire_footprint(tables, **kw, columns=list(cols))
        assert list(df.columns) == list(cols)
        assert calls == [targets], cols
        assert_columns_match(df, full, cols)
