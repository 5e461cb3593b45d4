"""Issue #4: squeeze-out on tables (SPEC §4) against the independent direct-core reference
``tests/reference/squeeze_reference.py`` (scipy quad, no tables), the Stefan law, the
paper's copper case, and hypothesis properties.

Tables are built once per module with the default tolerances. The squeeze-out time near
equilibrium is proportional to 1/|dp_cont/dū|, so the tables interpolate ū(p) and its
inverse with quintic Hermite polynomials on exact first and second derivatives and refine
on the slope as well as the value (cubic tables gave t* errors up to 1.6e-6).
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.squeeze_reference import SqueezeReference, flat_stefan_time, tau0  # noqa: E402
from reference.trapped_reference import TrappedReference  # noqa: E402

import fastcontact  # noqa: E402
from fastcontact.squeeze import squeeze_history, squeeze_model, squeeze_out  # noqa: E402
from fastcontact.squeeze.tire import tire_history  # noqa: E402
from fastcontact.tables import precompute  # noqa: E402
from fastcontact._core.vocab import column_name  # noqa: E402

E = 1e7
ETA = 1e-3
R = 0.01
TIGHT = None  # the default table tolerances (quintic tables meet the 1e-6 t* target)


@pytest.fixture(scope="module")
def T():
    psd = fastcontact.SelfAffinePSD(h_rms=1e-5, hurst=0.8, q0=1e4, q1=1e8)
    return precompute(psd, tolerance=TIGHT)


@pytest.fixture(scope="module")
def copper():
    # copper-like stand-in (paper Sec. 3, Figs. 4-5): h_rms = 0.12 mm, H = 0.8; q0 gives
    # beta = 0.0441 (kappa = 1.48 at 0.2 MPa, 10.3 at 1.4 MPa, as the paper quotes);
    # q1 = 1e6 gives rms slope 1.03 and percolation at 1.07 MPa (E = 2.3 MPa, nu = 0.5)
    psd = fastcontact.SelfAffinePSD(h_rms=1.2e-4, hurst=0.8, q0=1.15e3, q1=1e6)
    return precompute(psd, theories=("average", "critical_junction"), tolerance=TIGHT)


def _rel(a, b):
    return abs(a / b - 1.0)


# --------------------------------------------------------------------- vs reference
CASES = [("average", 1e-9), ("average", 1e-6), ("average", 3e-2), ("average", 1.5),
         ("critical_junction", 1e-4), ("critical_junction", 0.2),
         ("critical_junction", 0.39), ("emt", 0.1)]


@pytest.mark.parametrize("theory,pi0", CASES)
def test_times_vs_reference(T, theory, pi0):
    ref = SqueezeReference(T.surface, E, theory, pi0 * E)
    ratios = (1.1, 1.01, 1.001)
    want = {r: ref.t_ratio(r) for r in ratios}
    tau = tau0(ETA, R, T.h_rms, pi0 * E)
    for method in ("fast", "quad"):
        df = squeeze_out(T, p0=pi0 * E, E_star=E, R=R, eta=ETA, theory=theory, method=method)
        assert _rel(df["u_inf"].iloc[0] / T.h_rms, ref.v_inf) < 1e-7
        assert _rel(df["tau0"].iloc[0], tau) < 1e-14
        assert _rel(df["u_start"].iloc[0] / T.h_rms, ref.default_start()) < 1e-7
        for r in ratios:
            got = df[column_name("t_ratio", r)].iloc[0] / tau
            assert _rel(got, want[r]) < 1e-6, (method, r, got, want[r])
        assert df["t_star"].iloc[0] == df["t_ratio_1.01"].iloc[0]
        assert not df["trapped"].iloc[0] and not df["out_of_table"].iloc[0]


def test_du_and_user_start_vs_reference(T):
    pi0 = 1e-3
    ref = SqueezeReference(T.surface, E, "average", pi0 * E)
    tau = tau0(ETA, R, T.h_rms, pi0 * E)
    du = 1e-7  # 0.01 h_rms
    df = squeeze_out(T, p0=pi0 * E, E_star=E, R=R, eta=ETA, du=(du,), ratios=(),
                     theory="average")
    assert _rel(df[column_name("t_du", du)].iloc[0] / tau, ref.t_du(du / T.h_rms)) < 1e-6
    assert "t_star" in df  # t* always computed even if 1.01 is not in ratios
    for vs in (5.0, 1e4):  # inside the table, and far beyond its top (analytic tail)
        df = squeeze_out(T, p0=pi0 * E, E_star=E, R=R, eta=ETA, u_start=vs * T.h_rms,
                         theory="average")
        assert _rel(df["t_star"].iloc[0] / tau, ref.t_ratio(1.01, v_start=vs)) < 1e-6


@pytest.mark.parametrize("theory,dx", [("average", -0.5), ("critical_junction", -0.002)])
def test_u_deep_in_the_exponential_approach_vs_reference(T, theory, dx):
    """ū − ū∞ at 10 and 14 relaxation times past t* (ū − ū∞ ~ 1e-7…1e-9 ū∞, below the
    primitive's z grid) within 1e-6 relative of the reference's, at a pressure between two
    of the primitive's rows dx below the fast path's limit in ln p0. Checked as time: there
    d ln(ū − ū∞)/dt = −1/t_relax, so the reference time from the start to the engine's
    ū − ū∞ (each from its own ū∞) must be t within 1e-6 t_relax. Before 2026-11-27 the slope
    below the grid was interpolated across the rows in S instead of ln S (1.4e-6 to 5.4e-6
    off at 10 t_relax), and the fast path served pressures up to 0.01 below the trap, where
    its last rows were up to 2.4e-6 off. The pressure is dx below min(fast limit, 0.045 below
    the trap pressure and the kink): closer to those the tables' σ̄ and the direct core part
    (at 0.002 below the kink of asphalt_024mm the per-case quadrature of the tables is
    1.4e-6 t_relax off this reference); the fast path is checked there against a reference on
    the tables (test_time_primitive.py, next to the trap pressure)."""
    from fastcontact.squeeze.primitive import fast_limit

    m = squeeze_model(T, theory)
    xn = m.primitive().xn
    top = min(m.x_trap, float(m.tab.lnp[int(m.tab.n_open) - 1]))
    j = int(np.searchsorted(xn, min(fast_limit(m), top - 0.045) + dx)) - 1
    p0 = math.exp(0.5 * (xn[j] + xn[j + 1])) * E
    ref = SqueezeReference(T.surface, E, theory, p0)
    v_start = ref.default_start()
    tau = tau0(ETA, R, T.h_rms, p0)
    base = squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=theory, ratios=())
    t_rel = base["t_relax"].iloc[0]
    times = base["t_star"].iloc[0] + np.array([10.0, 14.0]) * t_rel
    got = []  # (ū - ū∞ [h_rms], time, label) of both engines
    for method in ("fast", "quad"):
        df = squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=theory, ratios=(),
                         times=times, method=method)
        assert df["status"].iloc[0] == "ok"
        names = [c for c in df.columns if c.startswith("u_at_")]
        assert len(names) == 2
        for t, c in zip(times, names):
            dv = (df[c].iloc[0] - df["u_inf"].iloc[0]) / T.h_rms
            assert 1e-10 < dv / ref.v_inf < 1e-6, (method, dv / ref.v_inf)
            got.append((dv, t, (method, c)))
    # the reference time from the start to each ū, integrated piecewise down the sorted ū
    # (one long quadrature instead of four nearly identical ones)
    v_prev, t_ref = v_start, 0.0
    for dv, t, label in sorted(got, reverse=True):
        t_ref += tau * ref.time(ref.v_inf + dv, v_prev)
        v_prev = ref.v_inf + dv
        assert abs(t_ref - t) < 1e-6 * t_rel, (label, (t_ref - t) / t_rel)


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_start_far_beyond_table(T, theory):
    pi0 = 1e-6
    ref = SqueezeReference(T.surface, E, theory, pi0 * E)
    df = squeeze_out(T, p0=pi0 * E, E_star=E, R=R, eta=ETA, theory=theory,
                     u_start=1e4 * T.h_rms, method="quad", quad_order=16, quad_width=0.5)
    tau = tau0(ETA, R, T.h_rms, pi0 * E)
    assert _rel(df["t_star"].iloc[0] / tau, ref.t_ratio(1.01, v_start=1e4)) < 1e-6


# --------------------------------------------------------------------- trapped fluid
def test_trapped_both_sides_of_percolation(T):
    m = squeeze_model(T, "critical_junction")
    pi_trap, pi_perc = math.exp(m.x_trap), math.exp(m.x_perc)
    assert pi_trap < pi_perc < T.p_range[1]
    pis = np.array([0.97 * pi_trap, 0.5 * (pi_trap + pi_perc), 1.05 * pi_perc])
    df = squeeze_out(T, p0=pis * E, E_star=E, R=R, eta=ETA, theory="critical_junction",
                     times=(1.0, math.inf), du=(1e-6,))
    assert list(df["trapped"]) == [False, True, True]
    assert list(df["percolated"]) == [False, False, True]
    ok, tr = df.iloc[0], df.iloc[1:]
    assert np.isfinite(ok["t_star"]) and ok["fluid_load_fraction"] == 0.0
    assert np.all(np.isinf(tr["t_star"])) and np.all(np.isinf(tr["t_ratio_1.001"]))
    assert np.all(tr["u_trap"] > tr["u_inf"])
    np.testing.assert_allclose(tr["fluid_load_fraction"], 1 - pi_trap / pis[1:], rtol=1e-12)
    assert np.all(np.isfinite(tr["t_trap"]) & (tr["t_trap"] > 1e10 * tr["tau0"]))
    # a target above u_trap is reached in finite time, and equals the reference
    assert np.all(np.isfinite(tr["t_du_1e-06"]))
    ref = SqueezeReference(T.surface, E, "critical_junction", pis[1] * E)
    tau = tau0(ETA, R, T.h_rms, pis[1] * E)
    assert _rel(tr["t_du_1e-06"].iloc[0] / tau, ref.t_du(1e-6 / T.h_rms)) < 1e-6
    np.testing.assert_array_equal(tr["u_at_inf"], tr["u_trap"])
    assert ok["u_at_inf"] == ok["u_inf"]


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_t_trap_within_its_stated_tolerance(theory):
    # squeeze_out's docstring: t_trap within 1e-6 of a converged quadrature with either method
    # (asphalt_024mm: the tables' last open node lies above ū_trap, the kink of σ̄ that cost
    # the quadrature 4e-3 before its panels broke there), and >= 1e19 τ0 ("never")
    from fastcontact.tables import Tables
    from fastcontact.tables.defaults import default_table_path

    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    m = squeeze_model(T, theory)
    for dx in (0.02, 0.7):
        x0 = m.x_trap + dx
        vs = 20.0 * m.mp.v_trap
        ref = TrappedReference(m).t_trap(x0, vs)  # converged to 1e-9 (it asserts that)
        for method in ("quad", "fast"):
            df = squeeze_out(T, p0=math.exp(x0) * E, E_star=E, R=R, eta=ETA, theory=theory,
                             u_start=vs * m.h_rms, method=method)
            assert df["status"].iloc[0] == "trapped"
            got = df["t_trap"].iloc[0] / df["tau0"].iloc[0]
            assert got > 1e19
            assert _rel(got, ref) < 1e-6, (dx, method, got, ref)


def test_copper_paper_case(copper):
    E_star = 2.3e6 / (1 - 0.5 ** 2)
    u0, beta = fastcontact.contact.asymptote(copper.surface)
    assert abs(0.2e6 / (beta * E_star) - 1.5) < 0.05
    assert abs(1.4e6 / (beta * E_star) - 10.3) < 0.3
    df = squeeze_out(copper, p0=np.array([0.2e6, 1.4e6]), E_star=E_star, R=0.015, eta=1e-3,
                     theory="critical_junction")
    assert not df["trapped"].iloc[0] and np.isfinite(df["t_star"].iloc[0])
    assert df["trapped"].iloc[1] and df["percolated"].iloc[1]
    assert df["fluid_load_fraction"].iloc[1] > 0.10  # paper: "more than 10 %"
    avg = squeeze_out(copper, p0=1.4e6, E_star=E_star, R=0.015, eta=1e-3, theory="average")
    assert not avg["trapped"].iloc[0] and np.isfinite(avg["t_star"].iloc[0])


# --------------------------------------------------------------------- limits
def test_flat_surface_limit_far_from_equilibrium(T):
    """Far above ū∞ the rough-surface film follows the Stefan law (SPEC §4)."""
    pi0 = 1e-9
    h = T.h_rms
    ua = 1e4 * h
    times = [flat_stefan_time(ua, ub, pi0 * E, ETA, R) for ub in (1e3 * h, 300 * h, 100 * h)]
    df = squeeze_out(T, p0=pi0 * E, E_star=E, R=R, eta=ETA, u_start=ua, times=times,
                     theory="average")
    got = np.array([df[column_name("u_at", t)].iloc[0] for t in times])
    np.testing.assert_allclose(got, [1e3 * h, 300 * h, 100 * h], rtol=1e-6)
    hist = squeeze_history(T, pi0 * E, E, R, ETA, "average", t=np.array(times), u_start=ua)
    np.testing.assert_allclose(hist["u"], hist["u_flat"], rtol=1e-6)
    # ...and near equilibrium it does not: rough stops at ū∞, flat goes on thinning
    late = squeeze_history(T, pi0 * E, E, R, ETA, "average", t=np.array([1e6]), u_start=ua)
    assert late["u"].iloc[0] > late["u_flat"].iloc[0]
    assert _rel(late["u"].iloc[0], late.attrs["u_inf"]) < 1e-3


def test_extreme_parameters_and_out_of_table(T):
    lo, hi = T.p_range
    p0 = np.array([1e-9, 1e-4, 0.3, 0.5 * lo, 1.5 * hi]) * E
    df = squeeze_out(T, p0=p0[:, None], E_star=E, R=np.array([1e-3, 1.0]),
                     eta=np.array([[1e-4], [1e3], [1.0], [1.0], [1.0]]))
    assert len(df) == 10
    oot = df["out_of_table"].to_numpy()
    assert list(oot) == [False] * 6 + [True] * 4
    assert np.all(np.isnan(df.loc[oot, "t_star"])) and np.all(np.isnan(df.loc[oot, "u_inf"]))
    assert np.all(np.isfinite(df.loc[~oot, ["t_star", "u_inf", "t_relax"]].to_numpy()))


def test_validation_errors(T):
    kw = dict(p0=1e4, E_star=E, R=R, eta=ETA)
    for name, bad in (("p0", -1.0), ("E_star", 0.0), ("R", math.nan), ("eta", -2.0)):
        with pytest.raises(ValueError, match=name):
            squeeze_out(T, **{**kw, name: bad})
    with pytest.raises(ValueError, match="ratios"):
        squeeze_out(T, **kw, ratios=(1.0,))
    with pytest.raises(ValueError, match="du"):
        squeeze_out(T, **kw, du=(-1e-6,))
    with pytest.raises(ValueError, match="theory"):
        squeeze_out(T, **kw, theory="bogus")
    # a start below equilibrium is a state, not an input error: NaN and a status (issue 11.6)
    df = squeeze_out(T, **kw, u_start=1e-9)
    assert df["status"].iloc[0] == "start_below_equilibrium" and np.isnan(df["t_star"].iloc[0])
    with pytest.raises(ValueError, match="tables"):
        squeeze_out(None, **kw)
    with pytest.raises(ValueError, match="method"):
        squeeze_out(T, **kw, method="rk45")


def test_fast_matches_quad_on_many_cases(T):
    rng = np.random.default_rng(1)
    for theory in T.theories:
        m = squeeze_model(T, theory)
        top = min(math.exp(m.x_trap), T.p_range[1])
        pis = np.exp(rng.uniform(math.log(1e-9), math.log(0.999 * top), 60))
        kw = dict(p0=pis * E, E_star=E, R=R, eta=ETA, theory=theory, du=(1e-7,))
        f = squeeze_out(T, **kw)
        q = squeeze_out(T, **kw, method="quad", quad_order=20, quad_width=0.25)
        for c in ("t_star", "t_ratio_1.1", "t_ratio_1.001", "t_du_1e-07", "u_inf", "u_start",
                  "t_relax"):
            np.testing.assert_allclose(f[c], q[c], rtol=2e-7, err_msg=f"{theory} {c}")


# --------------------------------------------------------------------- properties
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lp=st.floats(-9, -0.5), le=st.floats(-4, 3), lr=st.floats(-3, 0),
       theory=st.sampled_from(["average", "critical_junction", "emt"]))
def test_properties(T, lp, le, lr, theory):
    pi0 = 10.0 ** lp
    eta, Rr = 10.0 ** le, 10.0 ** lr
    times = np.geomspace(1e-8, 1e12, 9)
    df = squeeze_out(T, p0=pi0 * E, E_star=E, R=Rr, eta=eta, theory=theory, times=times)
    row = df.iloc[0]
    assert not row["out_of_table"]
    u = np.array([row[column_name("u_at", t)] for t in times])
    floor = row["u_trap"] if row["trapped"] else row["u_inf"]
    assert np.all(np.isfinite(u)) and np.all(np.diff(u) <= 0) and np.all(u >= floor)
    assert u[0] <= row["u_start"]
    if not row["trapped"]:
        assert np.isfinite(row["t_star"]) and row["t_star"] > 0
        assert row["t_ratio_1.1"] < row["t_star"] < row["t_ratio_1.001"]
    else:
        assert np.isinf(row["t_star"]) and 0 < row["fluid_load_fraction"] < 1
    # t* ∝ η R² exactly (t = τ0 t̃, τ0 = 3ηR²/(2h²p0))
    d2 = squeeze_out(T, p0=pi0 * E, E_star=E, R=2 * Rr, eta=3 * eta, theory=theory, times=times)
    if np.isfinite(row["t_star"]):
        assert _rel(d2["t_star"].iloc[0], 12 * row["t_star"]) < 1e-13
        f1 = squeeze_out(T, p0=pi0 * E, E_star=E, R=Rr, eta=eta, theory=theory)
        f2 = squeeze_out(T, p0=pi0 * E, E_star=E, R=2 * Rr, eta=3 * eta, theory=theory)
        assert _rel(f2["t_star"].iloc[0], 12 * f1["t_star"].iloc[0]) < 1e-13


def test_tstar_decreasing_in_p0_in_asymptotic_regime(T):
    """t* falls with p0 while ū∞ is large (τ ∝ 1/p0 dominates); past a minimum near
    p0/E* ~ 1e-3 it rises again as σ̄(ū∞) collapses — that is physics, not a bug."""
    pis = np.geomspace(1e-9, 1e-4, 30)
    for theory in T.theories:
        t = squeeze_out(T, p0=pis * E, E_star=E, R=R, eta=ETA, theory=theory)["t_star"].to_numpy()
        assert np.all(np.diff(t) < 0), theory
    pis = np.geomspace(1e-2, 0.3, 10)
    t = squeeze_out(T, p0=pis * E, E_star=E, R=R, eta=ETA, theory="average")["t_star"].to_numpy()
    assert np.all(np.diff(t) > 0)


def test_history_of_a_case_without_one_names_the_parameter_its_value_and_range(T):
    """squeeze_history (and tire_history through it) of a start at or below ū∞, or of a
    pressure outside the tables: a ValueError with the value and the valid range; ū∞ and the
    range checked against the tables' own ū(p) and p_range."""
    import re
    p0 = 1e5
    u_inf = float(T.mean_separation(p0, E))
    with pytest.raises(ValueError) as e:
        squeeze_history(T, p0, E, R, ETA, "average", t=[0.0, 1.0], u_start=0.5 * u_inf)
    m = re.search(r"u_start = ([^ ]+) m is invalid for p0 = ([^ ]+) Pa.*must be > u_inf = "
                  r"([^ ]+) m", str(e.value))
    assert m and float(m.group(1)) == 0.5 * u_inf and float(m.group(2)) == p0
    assert abs(float(m.group(3)) / u_inf - 1) < 1e-6
    lo, hi = T.p_range
    for pbar in (0.1 * lo, 10.0 * hi):
        with pytest.raises(ValueError) as e:
            tire_history(T, p0=pbar * E, E_star=E, R=R, eta=ETA, t=[0.0, 1.0])
        m = re.search(r"p0 = ([^ ]+) Pa is invalid .* must be in \[([^,]+), ([^\]]+)\]",
                      str(e.value))
        assert m and float(m.group(1)) == pbar * E
        assert abs(float(m.group(2)) / lo - 1) < 1e-5 and abs(float(m.group(3)) / hi - 1) < 1e-5


def test_history_columns(T):
    t = np.geomspace(1e-6, 1e3, 25)
    h = squeeze_history(T, 1e4, E, R, ETA, "critical_junction", t=t)
    assert list(h.columns) == ["t", "u", "p_cont_over_p0", "p_fluid_mean", "u_flat"]
    assert np.all(np.diff(h["u"]) <= 0) and np.all(np.diff(h["p_cont_over_p0"]) >= 0)
    np.testing.assert_allclose(h["p_fluid_mean"], 1e4 * (1 - h["p_cont_over_p0"]), rtol=1e-12)
    assert abs(h["p_cont_over_p0"].iloc[-1] - 1) < 1e-6
    with pytest.raises(ValueError, match="p0"):
        squeeze_history(T, np.array([1e4, 2e4]), E, R, ETA, "average", t=t)
