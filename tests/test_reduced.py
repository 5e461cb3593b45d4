"""Tests of fastcontact.reduced (paper Sec. 2 asymptotic model, Stefan law, Sec. 5 inertia).

Precision references are independent of the module: the squeeze-out time is written here as
the plain integral in ū with p_cont = κ⁻¹e^{-αū} evaluated by mpmath at 40 digits (the module
integrates in w = ln(ū - ū∞) with expm1 in double precision), plus the closed-form
exponential-approach asymptote next to equilibrium.
"""
from __future__ import annotations

import math
import struct

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from fastcontact import reduced as rd

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True)


# --------------------------------------------------------------------------- references
def t_between_mp(kappa, alpha, u_lo, u_hi, dps=40, grow=2):
    """∫_{u_lo}^{u_hi} α dū / (ū³ (1 - κ⁻¹ e^{-αū})) by mpmath, split geometrically away
    from the lower limit (the integrand has a simple pole at ū∞ just below it)."""
    with mp.workdps(dps):
        k, a = mp.mpf(kappa), mp.mpf(alpha)
        lo = mp.mpf(u_lo)
        hi = mp.inf if math.isinf(u_hi) else mp.mpf(u_hi)
        u_inf = mp.log(1 / k) / a if kappa < 1 else mp.mpf(0)

        def f(u):
            return a / (u**3 * (1 - mp.exp(-a * u) / k))

        d = lo - u_inf
        pts = [lo]
        while pts[-1] + d < hi and d < 1e3 * (1 + lo):
            pts.append(pts[-1] + d)
            d *= grow
        pts.append(hi)
        return mp.quad(f, pts)


def t_star_mp(kappa, alpha, u_start, ratio=1.01):
    with mp.workdps(40):
        u_star = mp.mpf(ratio) * mp.log(1 / mp.mpf(kappa)) / alpha
        return float(t_between_mp(kappa, alpha, u_star, u_start, grow=4))


KAPPAS = np.concatenate([10.0 ** np.arange(-8.0, 0.0), [0.3, 0.5, 0.7, 0.9, 0.95, 0.99]])


# --------------------------------------------------------------------------- t* accuracy
@pytest.mark.parametrize("alpha", [0.3, 0.5, 1.0])
def test_t_star_against_mpmath(alpha):
    df = rd.squeeze_out_reduced(KAPPAS, alpha)
    assert df.valid.all()
    ref = np.array([t_star_mp(k, alpha, us) for k, us in zip(KAPPAS, df.u_start)])
    rel = np.abs(df.t_star.to_numpy() / ref - 1.0)
    assert rel.max() < 1e-11, rel.max()          # target 1e-10; measured ~5e-16


@pytest.mark.parametrize("ratio", [1.1, 1.001, 1.0 + 1e-9, 3.0, 1e3])
@pytest.mark.parametrize("u_start", [None, np.inf])
def test_t_star_other_ratios_and_infinite_start(ratio, u_start):
    kappas = np.array([1e-8, 1e-3, 0.2, 0.9])
    for alpha in (0.05, 0.5, 4.0):
        u_s = rd.default_u_start_reduced(kappas, alpha) if u_start is None else u_start
        keep = u_s > ratio * np.log(1 / kappas) / alpha * (1 + 1e-9)
        df = rd.squeeze_out_reduced(kappas[keep], alpha, u_start=np.broadcast_to(u_s, kappas.shape)[keep],
                                    ratio=ratio)
        for row in df.itertuples():
            ref = t_star_mp(row.kappa, alpha, row.u_start, ratio)
            assert abs(row.t_star / ref - 1.0) < 1e-11, (row, ref)


@pytest.mark.parametrize("kappa", [1e-8, 1e-2, 0.5, 0.99])
@pytest.mark.parametrize("alpha", [0.3, 1.0])
def test_exponential_approach_asymptote(kappa, alpha):
    """Next to equilibrium, with v = ū - ū∞: dt/dv = ū∞⁻³ [1/v + α/2 - 3/ū∞ + O(v)], so
    t(v1) - t(v2) = ū∞⁻³ [ln(v2/v1) + (α/2 - 3/ū∞)(v2 - v1)] + O(v2²) — the paper's exponential
    approach ū - ū∞ ∝ exp(-ū∞³ t), relax_time = 1/ū∞³."""
    u_inf = math.log(1 / kappa) / alpha
    r1, r2 = 1.0 + 1e-12, 1.0 + 1e-7
    df = rd.squeeze_out_reduced(kappa, alpha, ratio=[r1, r2])
    v1, v2 = (r1 - 1.0) * u_inf, (r2 - 1.0) * u_inf
    expect = (math.log(v2 / v1) + (alpha / 2 - 3 / u_inf) * (v2 - v1)) / u_inf**3
    got = df.t_star[0] - df.t_star[1]
    assert abs(got / expect - 1.0) < 1e-9
    assert df.relax_time[0] == pytest.approx(1 / df.u_inf[0]**3, rel=1e-15)
    assert df.relax_time[0] == pytest.approx(1 / u_inf**3, rel=1e-12)


# --------------------------------------------------------------------------- flags / extremes
def test_extreme_kappa_flags():
    kappas = 10.0 ** np.linspace(-8, 8, 65)
    for alpha in (0.3, 0.5, 1.0, 7.0):
        df = rd.squeeze_out_reduced(kappas, alpha)
        num = df.select_dtypes("number")
        assert not num.isna().any().any()
        valid = df.valid.to_numpy()
        assert np.array_equal(valid, kappas < 1.0)
        # finite numbers exactly where the case is valid; inf only where flagged
        assert np.isfinite(df.t_star[valid]).all() and (df.t_star[valid] > 0).all()
        assert np.isinf(df.t_star[~valid]).all() and np.isinf(df.relax_time[~valid]).all()
        assert (df.status[~valid] == "no_equilibrium").all()
        assert (df.u_inf[~valid] == 0.0).all() and (df.u_star[~valid] == 0.0).all()
        assert np.isfinite(df.u_start).all() and (df.u_start > df.u_star).all()
        # large_separation: the paper's ū > 2 h_rms criterion for law (3)
        assert np.array_equal(df.large_separation, valid & (df.u_inf >= 2.0))
        assert set(df.status[valid]) <= {"ok", "small_separation"}
        # t* grows as κ → 1 (equilibrium separation shrinks, conductivity ∝ ū³)
        assert np.all(np.diff(df.t_star[valid]) > 0)


def test_kappa_one_and_near_one():
    df = rd.squeeze_out_reduced([1.0 - 1e-12, 1.0, 1.0 + 1e-12], 0.5)
    assert list(df.valid) == [True, False, False]
    assert np.isfinite(df.t_star[0]) and df.t_star[0] > 1e30
    assert np.isinf(df.t_star[1:]).all()


def test_default_u_start_is_p_cont_1e_minus_3():
    df = rd.squeeze_out_reduced(KAPPAS, 0.5)
    assert np.allclose(df.p_start, 1e-3, rtol=1e-12)
    assert np.allclose(df.u_start, df.u_inf + math.log(1000) / 0.5, rtol=1e-14)
    assert rd.default_u_start_reduced(10.0, 0.5) == pytest.approx(math.log(1000) / 0.5)


def test_broadcasting_shape_and_columns():
    df = rd.squeeze_out_reduced(np.array([[1e-3], [1e-2]]), np.array([0.3, 0.5, 1.0]))
    assert len(df) == 6
    for col in ("kappa", "alpha", "u_start", "u_inf", "t_star", "u_star", "valid"):
        assert col in df.columns
    assert list(df.kappa) == [1e-3] * 3 + [1e-2] * 3


def test_u_start_below_target_rejected():
    u_inf = math.log(100) / 0.5
    with pytest.raises(ValueError, match=r"u_start = .* must be > ratio\*u_inf"):
        rd.squeeze_out_reduced(1e-2, 0.5, u_start=1.005 * u_inf)
    u_star = rd.squeeze_out_reduced(1e-2, 0.5).u_star[0]
    with pytest.raises(ValueError, match="u_start"):
        rd.squeeze_out_reduced(1e-2, 0.5, u_start=u_star)            # exactly at the target
    with pytest.raises(ValueError, match=r"u_start = .* must be > u_inf"):
        rd.u_of_t_reduced(1e-2, 0.5, 1.0, u_start=0.9 * u_inf)
    # κ ≥ 1: any positive start is fine (t* = inf, flagged)
    assert np.isinf(rd.squeeze_out_reduced(2.0, 0.5, u_start=0.1).t_star[0])


# --------------------------------------------------------------------------- u(t)
def test_u_of_t_round_trip_t_star():
    kappas = 10.0 ** np.linspace(-10, -0.005, 40)
    for alpha in (0.1, 0.5, 3.0):
        for ratio in (1.0 + 1e-10, 1.001, 1.01, 1.5):
            u_s = rd.default_u_start_reduced(kappas, alpha)
            ok = u_s > ratio * np.log(1 / kappas) / alpha * (1 + 1e-9)
            df = rd.squeeze_out_reduced(kappas[ok], alpha, ratio=ratio)
            u = rd.u_of_t_reduced(kappas[ok], alpha, df.t_star.to_numpy())
            assert np.max(np.abs(u / df.u_star.to_numpy() - 1.0)) < 1e-13


@pytest.mark.parametrize("kappa", [1.0, 1.0 + 1e-7, 2.0, 1e8])
@pytest.mark.parametrize("alpha", [0.3, 1.0])
def test_u_of_t_kappa_ge_1_against_mpmath(kappa, alpha):
    """No equilibrium: ū(t) → 0; check t(ū) = ∫_ū^{u_start} … by mpmath."""
    u_s = rd.default_u_start_reduced(kappa, alpha)
    for t in (1e-3, 1.0, 1e4, 1e40):
        u = rd.u_of_t_reduced(kappa, alpha, t)
        assert 0 < u < u_s
        # 1 - e^{-αū}/κ cancels for κ ≈ 1 and tiny ū: carry enough digits
        ref = float(t_between_mp(kappa, alpha, u, u_s, dps=30 + int(-math.log10(u)), grow=16))
        assert abs(ref / t - 1.0) < 1e-11
    assert rd.u_of_t_reduced(kappa, alpha, np.inf) == 0.0


def test_u_of_t_limits():
    u_inf = math.log(2) / 0.5
    u = rd.u_of_t_reduced(0.5, 0.5, [0.0, 1e10, 1e300, np.inf])
    assert u[0] == rd.default_u_start_reduced(0.5, 0.5)
    assert np.all(u[1:] == pytest.approx(u_inf, rel=1e-15))
    # infinite start: the Stefan attractor (α/2t)^{1/2} while contact is negligible
    u = rd.u_of_t_reduced(0.5, 0.5, [1e-300, 1e-10], u_start=np.inf)
    assert np.allclose(u, np.sqrt(0.5 / (2 * np.array([1e-300, 1e-10]))), rtol=1e-14)


@SETTINGS
@given(lk=st.floats(-12, -0.01), alpha=st.floats(0.05, 10.0),
       f1=st.floats(1e-9, 1.0), f2=st.floats(1e-9, 1.0))
def test_t_star_increasing_in_u_start(lk, alpha, f1, f2):
    kappa = 10.0**lk
    u_inf = math.log(1 / kappa) / alpha
    lo = 1.01 * u_inf
    a, b = sorted((lo + f1 * 50.0, lo + f2 * 50.0))
    if b <= a * (1 + 1e-12):
        return
    t = rd.squeeze_out_reduced(kappa, alpha, u_start=[a, b, np.inf]).t_star.to_numpy()
    assert 0 < t[0] < t[1] < t[2]


@SETTINGS
@given(lk=st.floats(-12, 6), alpha=st.floats(0.05, 10.0),
       lt=st.lists(st.floats(-8, 12), min_size=2, max_size=12))
def test_u_of_t_monotone_and_bounded(lk, alpha, lt):
    kappa = 10.0**lk
    t = np.sort(10.0 ** np.asarray(lt))
    u = rd.u_of_t_reduced(kappa, alpha, t)
    u_inf = max(math.log(1 / kappa) / alpha, 0.0)
    u_s = rd.default_u_start_reduced(kappa, alpha)
    assert np.all(np.isfinite(u))
    assert np.all(u >= u_inf) and np.all(u <= u_s)
    # non-increasing in t (to a few ulp: ū is a floating-point number)
    assert np.all(np.diff(u) <= 8 * np.finfo(float).eps * u[:-1])
    # rough surface film stays above the flat-surface film from the same start
    flat = rd.flat_separation_reduced(u_s, t, alpha)
    assert np.all(u >= flat * (1 - 1e-13))


# --------------------------------------------------------------------------- SI ↔ reduced
def test_reduced_rate_matches_si_equation_1():
    """Eq. (10) in reduced units equals eq. (1)+(2)+(3) in SI divided by h_rms/τ."""
    eta, R, h, p0, E_star, alpha, beta = 1e-3, 0.02, 1e-4, 2e5, 1e7, 0.5, 1.0
    tau = rd.time_unit_tau(eta, R, h, p0, alpha)
    kappa = rd.kappa_parameter(p0, E_star, beta)
    assert kappa == pytest.approx(0.02)
    u = np.array([3.0, 8.0, 15.0]) * h
    p_cont = beta * E_star * np.exp(-u / (h / alpha))
    rate_si = -2 * u**3 * (p0 - p_cont) / (3 * eta * R**2)
    rate_red = rd.separation_rate_reduced(u / h, kappa, alpha)
    assert np.allclose(rate_red * h / tau, rate_si, rtol=1e-13)
    assert np.allclose(rd.contact_pressure_reduced(u / h, kappa, alpha), p_cont / p0, rtol=1e-13)
    assert rd.equilibrium_separation_reduced(kappa, alpha) == pytest.approx(
        math.log(beta * E_star / p0) / alpha, rel=1e-15)


def test_flat_law_si_and_reduced():
    u0, p0, eta, R = 50e-6, 2e5, 1e-3, 0.01
    t = np.array([0.0, 1e-6, 1e-3, 1.0, 1e3])
    u = rd.flat_separation(u0, t, p0, eta, R)
    assert u[0] == u0
    assert np.allclose(u, u0 / np.sqrt(1 + 4 * u0**2 * p0 * t / (3 * eta * R**2)), rtol=1e-15)
    # ODE (1) with p_fluid = p0, by central difference
    tm, dt = 1e-3, 1e-9
    du = (rd.flat_separation(u0, tm + dt, p0, eta, R) - rd.flat_separation(u0, tm - dt, p0, eta, R))
    um = rd.flat_separation(u0, tm, p0, eta, R)
    assert du / (2 * dt) == pytest.approx(-2 * um**3 * p0 / (3 * eta * R**2), rel=1e-6)
    # t^{-1/2} tail
    big = rd.flat_separation(u0, 1e12, p0, eta, R)
    assert big == pytest.approx(math.sqrt(3 * eta * R**2 / (4 * p0 * 1e12)), rel=1e-6)
    # reduced counterpart with the same τ
    h, alpha = 10e-6, 0.5
    tau = rd.time_unit_tau(eta, R, h, p0, alpha)
    ured = rd.flat_separation_reduced(u0 / h, t / tau, alpha)
    assert np.allclose(ured * h, u, rtol=1e-14)
    assert rd.flat_separation_reduced(np.inf, 2.0, 0.5) == pytest.approx(math.sqrt(0.5 / 4.0))


def test_rough_tends_to_flat_without_contact():
    """Tiny κ and times short against the contact stage: rough ≈ flat (p_cont ≈ 0)."""
    kappa, alpha = 1e-30, 0.5
    u_s = rd.default_u_start_reduced(kappa, alpha) + 60.0      # p_cont(0) ≈ 1e-3 e^{-30}
    t = np.array([1e-8, 1e-7, 1e-6])
    u = rd.u_of_t_reduced(kappa, alpha, t, u_start=u_s)
    flat = rd.flat_separation_reduced(u_s, t, alpha)
    assert np.allclose(u, flat, rtol=1e-12)


# --------------------------------------------------------------------------- inertia
def test_inertia_closed_forms():
    tp = rd.inertia_time_constant(0.02, 1000.0, 0.3e6)
    assert tp == pytest.approx(1.4434e-4, rel=1e-4)
    assert tp == pytest.approx(math.sqrt(0.02**2 * 1000 / (64 * 0.3e6)), rel=1e-15)
    ts = rd.inertia_squeeze_time(0.02, 1000.0, 0.3e6, 0.01, 0.3e-3)
    assert ts == pytest.approx(tp * math.log(0.01 / 0.3e-3), rel=1e-15)
    assert ts == pytest.approx(5e-4, rel=0.02)                   # paper: t* ≈ 5e-4 s
    u = rd.inertia_separation(np.array([0.0, tp, ts]), 0.01, 0.02, 1000.0, 0.3e6)
    assert np.allclose(u, [0.01, 0.01 / math.e, 0.3e-3], rtol=1e-14)
    with pytest.raises(ValueError, match="u_start"):
        rd.inertia_squeeze_time(0.02, 1000.0, 0.3e6, 1e-4, 0.3e-3)


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, name", [
    (lambda: rd.squeeze_out_reduced(-1.0, 0.5), "kappa"),
    (lambda: rd.squeeze_out_reduced(0.1, 0.0), "alpha"),
    (lambda: rd.squeeze_out_reduced(0.1, np.nan), "alpha"),
    (lambda: rd.squeeze_out_reduced(0.1, 0.5, ratio=1.0), "ratio"),
    (lambda: rd.squeeze_out_reduced(0.1, 0.5, ratio=0.9), "ratio"),
    (lambda: rd.squeeze_out_reduced(0.1, 0.5, u_start=-3.0), "u_start"),
    (lambda: rd.squeeze_out_reduced("abc", 0.5), "kappa"),
    (lambda: rd.u_of_t_reduced(0.1, 0.5, -1.0), "t"),
    (lambda: rd.u_of_t_reduced(0.0, 0.5, 1.0), "kappa"),
    (lambda: rd.u_of_t_reduced(0.1, -0.5, 1.0), "alpha"),
    (lambda: rd.equilibrium_separation_reduced(1.5, 0.5), "kappa"),
    (lambda: rd.contact_pressure_reduced(-1.0, 0.1, 0.5), "u"),
    (lambda: rd.separation_rate_reduced(1.0, 0.1, np.inf), "alpha"),
    (lambda: rd.default_u_start_reduced(0.1, 0.5, p_start=1.0), "p_start"),
    (lambda: rd.time_unit_tau(1e-3, 0.01, 0.0, 1e5, 0.5), "h_rms"),
    (lambda: rd.kappa_parameter(1e5, -1e7), "E_star"),
    (lambda: rd.flat_separation(1e-5, 1.0, 1e5, 1e-3, -0.01), "R"),
    (lambda: rd.flat_separation(1e-5, -1.0, 1e5, 1e-3, 0.01), "t"),
    (lambda: rd.flat_separation_reduced(0.0, 1.0, 0.5), "u0"),
    (lambda: rd.inertia_time_constant(0.02, -1000.0, 3e5), "rho"),
    (lambda: rd.inertia_time_constant(0.0, 1000.0, 3e5), "D"),
    (lambda: rd.inertia_separation(1.0, 0.01, 0.02, 1000.0, 0.0), "p0"),
])
def test_bad_input_names_parameter(call, name):
    with pytest.raises(ValueError, match=rf"^{name} = .* is invalid: "):
        call()


# --------------------------------------------------------------------------- figures
def test_make_reduced_figures(tmp_path):
    from fastcontact.figures.reduced_figures import make_reduced_figures
    paths = make_reduced_figures(tmp_path)
    assert len(paths) == 2
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        w, h = struct.unpack(">II", data[16:24])
        assert w > 500 and h > 500
    assert sorted(x.name for x in tmp_path.iterdir()) == sorted(p.name for p in paths)
