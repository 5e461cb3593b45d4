"""Issue 14.1: asperity-scale squeeze-out at magnification ζ and the cascade.

Checks: ζ = 1 is the base squeeze-out exactly; each level's inputs follow from (A1), the
restricted spectrum and the region rule; one level's t* against an independent quadrature of
dū/dt = -(2ū³/(3ηR²))(p(ζ) - p_cont(ū)) with the direct contact core (no tables);
cascade bookkeeping and trapping.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

import fastcontact as fc
from fastcontact.contact import area_fraction, contact_pressure, mean_separation
from fastcontact.squeeze import squeeze_out
from fastcontact.squeeze.asperity import asperity_levels, region_radius

E_STAR, ETA, R = 1e7, 1e-3, 5e-3


@pytest.fixture(scope="module")
def psd():
    return fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e7)


@pytest.fixture(scope="module")
def levels(psd):
    return asperity_levels(psd, p0=2e5, E_star=E_STAR, R=R, eta=ETA, theory="average",
                           zetas=[1.0, 4.0, 16.0])


def test_zeta_one_is_base(psd, levels):
    base = squeeze_out(fc.precompute(psd, theories=("average",)), p0=2e5, E_star=E_STAR, R=R,
                       eta=ETA, theory="average", ratios=(1.1,))
    for c in ("u_inf", "u_start", "t_star", "t_ratio_1.1"):
        assert levels[c][0] == base[c][0]


def test_level_inputs(psd, levels):
    z = levels["zeta"].to_numpy()
    A = np.array([1.0] + [float(area_fraction(psd, 2e5, E_STAR, x)) for x in z[1:]])
    np.testing.assert_allclose(levels["p_zeta"], 2e5 / A, rtol=1e-14)
    np.testing.assert_allclose(levels["R_zeta"][1:], math.pi / (2 * z[1:] * psd.q0), rtol=1e-15)
    np.testing.assert_allclose(levels["R_zeta"][1:], region_radius(z[1:], psd.q0), rtol=0)
    np.testing.assert_allclose(levels["h_rms_zeta"], psd.h_rms_above(z), rtol=1e-12)


def test_level_against_direct_quadrature(psd, levels):
    row = levels.iloc[1]                                  # ζ = 4
    sub = psd.restricted(4.0 * psd.q0)
    pz, Rz = row.p_zeta, row.R_zeta
    u_inf = float(mean_separation(sub, pz, E_STAR))
    u_start = float(mean_separation(sub, 1e-3 * pz, E_STAR))

    def integrand(w):
        u = u_inf + math.exp(w)
        rate = 2 * u ** 3 * (pz - float(contact_pressure(sub, u, E_STAR))) / (3 * ETA * Rz ** 2)
        return math.exp(w) / rate

    t_ref, _ = integrate.quad(integrand, math.log(0.01 * u_inf), math.log(u_start - u_inf),
                              epsrel=1e-10, limit=200)
    assert abs(row.u_inf / u_inf - 1) < 1e-7
    assert abs(row.t_star / t_ref - 1) < 1e-6


def test_cascade_bookkeeping(levels):
    t = levels["t_star"].to_numpy()
    np.testing.assert_allclose(levels["t_sequential"], np.cumsum(t), rtol=1e-15)
    np.testing.assert_allclose(levels["t_parallel"], np.maximum.accumulate(t), rtol=0)
    assert not levels["trapped"].any() and levels.attrs["zeta_trap"] == math.inf


def test_trapping_at_high_magnification(psd):
    # heavy load: the restricted contact percolates at a higher level, fluid is sealed off
    df = asperity_levels(psd, p0=5e5, E_star=E_STAR, R=R, eta=ETA, theory="emt",
                         zetas=[1.0, 8.0, 64.0], tables_kwargs=dict(points_per_decade=4))
    assert df["area_restricted"].is_monotonic_increasing
    trapped = df["trapped"].to_numpy()
    assert trapped[-1] and not trapped[0]
    k = int(np.argmax(trapped))
    assert df.attrs["zeta_trap"] == df["zeta"][k]
    assert np.isinf(df["t_sequential"][k]) and np.isinf(df["t_parallel"][k])


def test_bad_levels(psd):
    with pytest.raises(ValueError, match="zetas"):
        asperity_levels(psd, p0=2e5, E_star=E_STAR, R=R, eta=ETA, zetas=[2.0, 4.0])
    with pytest.raises(ValueError, match="level_ratio"):
        asperity_levels(psd, p0=2e5, E_star=E_STAR, R=R, eta=ETA, level_ratio=1.0)


def test_threshold_from_the_tables(psd):
    """The trap criterion uses the tables' percolation area (a calibrated emt_threshold = 0.3
    here), not a hard-coded 0.5; the levels inherit the base tables' options."""
    kw = dict(p0=2e5, E_star=E_STAR, R=R, eta=ETA, theory="emt", zetas=[1.0, 8.0, 64.0])
    cal = fc.precompute(psd, theories=("emt",), points_per_decade=4, emt_threshold=0.3)
    df = asperity_levels(tables=cal, **kw)
    assert df.attrs["level_options"]["emt_threshold"] == 0.3
    np.testing.assert_array_equal(df["area_threshold"], 0.3)
    a = df["area_restricted"].to_numpy()
    assert a[1] >= 0.3 > a[0] and a[1] < 0.5          # trapped at ζ = 8 only through 0.3
    assert list(df["trapped"]) == [False, True, True] and df.attrs["zeta_trap"] == 8.0
    default = asperity_levels(psd, tables_kwargs=dict(points_per_decade=4), **kw)
    np.testing.assert_array_equal(default["area_threshold"], 0.5)
    assert list(default["trapped"]) == [False, False, True]
    # level ζ = 1 runs on the given tables themselves
    base = squeeze_out(cal, p0=2e5, E_star=E_STAR, R=R, eta=ETA, theory="emt", ratios=(1.1,))
    assert df["t_star"][0] == base["t_star"][0]


def test_summary_matches_levels(psd):
    from fastcontact.squeeze.asperity import asperity_summary
    T = fc.precompute(psd, theories=("average",))
    p0 = np.array([1e5, 2e5])
    s = asperity_summary(T, p0=p0, E_star=E_STAR, R=R, eta=ETA, theory="average",
                         level_ratio=4.0, zeta_max=64.0)
    for i, p in enumerate(p0):
        lv = asperity_levels(tables=T, p0=p, E_star=E_STAR, R=R, eta=ETA, theory="average",
                             level_ratio=4.0, zeta_max=64.0)
        assert s["n_levels"][i] == len(lv) and s["zeta_top"][i] == lv["zeta"].iloc[-1]
        np.testing.assert_allclose([s["t_sequential"][i], s["t_parallel"][i],
                                    s["t_star_base"][i], s["t_star_top"][i]],
                                   [lv["t_sequential"].iloc[-1], lv["t_parallel"].iloc[-1],
                                    lv["t_star"].iloc[0], lv["t_star"].iloc[-1]], rtol=1e-12)
        assert s["zeta_trap"][i] == lv.attrs["zeta_trap"] == math.inf


def test_asperity_figure(levels, tmp_path):
    """The t*(ζ) figure (in the figures layer) draws every level and both cascade bounds."""
    from fastcontact.figures.asperity_figures import plot_asperity_tstar

    path = tmp_path / "tstar.png"
    fig = plot_asperity_tstar({"s": levels}, path, title="t")
    lines = fig.axes[0].get_lines()
    ok = ~levels["trapped"].to_numpy()
    assert np.array_equal(lines[0].get_xdata(), levels["zeta"][ok].to_numpy())
    assert np.array_equal(lines[0].get_ydata(), levels["t_star"][ok].to_numpy())
    assert np.array_equal(lines[1].get_ydata(), levels["t_sequential"].to_numpy())
    assert np.array_equal(lines[2].get_ydata(), levels["t_parallel"].to_numpy())
    assert path.stat().st_size > 1000
