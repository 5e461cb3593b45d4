"""Issue 14.3: directional conductivities σ_xx, σ_yy for anisotropic roughness.

Reference: ``tests/reference/ext_anisotropy.py`` builds P(u) as -A'(ζ)dζ on a grid in
ln(ζ - 1) (public u1(ζ), closed-form A'(ζ)) and solves the Bruggeman equations with scipy
brentq — a different discretisation and solver. γ_T = 1 must return the isotropic result
exactly; the anisotropic solver forced at γ_T = 1 must agree with the isotropic EMT.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_anisotropy import p_of_u, sigma_fixed, sigma_self_consistent  # noqa: E402

import fastcontact as fc  # noqa: E402
from fastcontact.flow.anisotropy import (  # noqa: E402
    directional_sigma_bar,
    directional_tables,
    directional_threshold,
    precompute_directional,
    sigma_directional,
)
from fastcontact.flow.conductivity import conductivity  # noqa: E402

E_STAR = 1e7


@pytest.fixture(scope="module")
def psd():
    return fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)


@pytest.mark.parametrize("theory", ["emt", "critical_junction", "average"])
@pytest.mark.parametrize("direction", ["x", "y"])
def test_isotropic_is_exact(psd, theory, direction):
    p = np.array([1e3, 1e5, 1e6])
    a = sigma_directional(psd, p, E_STAR, 1e-3, theory, 1.0, direction)
    b = conductivity(psd, p, E_STAR, 1e-3, theory)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


@pytest.mark.parametrize("form", ["self_consistent", "fixed"])
def test_anisotropic_solver_at_gamma_one(psd, form):
    p = np.array([1e-3, 1e2, 1e4, 1e5, 1e6, 1.9e6])       # ū from ~20 h_rms to near percolation
    iso = conductivity(psd, p, E_STAR, 1.0 / 12.0, "emt", tol=1e-12)[0] / psd.h_rms ** 3
    sx, sy = directional_sigma_bar(psd, p / E_STAR, 1.0, form=form)
    np.testing.assert_allclose(sx, iso, rtol=2e-9)
    np.testing.assert_allclose(sy, iso, rtol=2e-9)


@pytest.mark.parametrize("p", [1e3, 1e5, 1e6])
@pytest.mark.parametrize("gamma_t", [1.5, 4.0])
def test_against_reference(psd, p, gamma_t):
    W, sig, A1 = p_of_u(psd, p, E_STAR)
    rf = sigma_fixed(W, sig, A1, gamma_t)
    rs = sigma_self_consistent(W, sig, A1, gamma_t)
    fx, fy = directional_sigma_bar(psd, p / E_STAR, gamma_t, form="fixed")
    sx, sy = directional_sigma_bar(psd, p / E_STAR, gamma_t)
    np.testing.assert_allclose([fx[0], fy[0], sx[0], sy[0]], [*rf, *rs], rtol=2e-8)
    assert sx[0] > sy[0] and fx[0] > fy[0]          # easier along the long correlation length


def test_percolation_thresholds(psd):
    g = 3.0
    # fixed form: σ_yy closes at A(ζ1)/A0 = 1/(1+γ), σ_xx at γ/(1+γ)
    for d, a_thr in (("y", 1 / (1 + g)), ("x", g / (1 + g))):
        assert abs(directional_threshold(0.5, g, d) - a_thr) < 1e-15
        pc = float(fc.contact.percolation_pressure(psd, E_STAR, a_thr))
        s_lo, perc_lo = sigma_directional(psd, pc * 0.999, E_STAR, 1e-3, "emt", g, d, form="fixed")
        s_hi, perc_hi = sigma_directional(psd, pc * 1.001, E_STAR, 1e-3, "emt", g, d, form="fixed")
        assert s_lo > 0 and not perc_lo and s_hi == 0 and perc_hi
    # self-consistent: both close at 1/2, with σ_yy/σ_xx → 1/γ² just before
    pc = float(fc.contact.percolation_pressure(psd, E_STAR, 0.5))
    sx, sy = directional_sigma_bar(psd, np.array([0.97 * pc, 1.001 * pc]) / E_STAR, g)
    assert sx[1] == 0 and sy[1] == 0
    assert abs(sy[0] / sx[0] * g * g - 1) < 0.05


def test_bad_input(psd):
    with pytest.raises(ValueError, match="anisotropy"):
        sigma_directional(psd, 1e4, E_STAR, 1e-3, "emt", 0.5, "x")
    with pytest.raises(ValueError, match="direction"):
        sigma_directional(psd, 1e4, E_STAR, 1e-3, "emt", 2.0, "z")
    with pytest.raises(ValueError, match="form"):
        sigma_directional(psd, 1e4, E_STAR, 1e-3, "critical_junction", 2.0, "x")


def test_table_path(psd):
    tables = fc.precompute(psd, theories=("emt",), points_per_decade=2, refine=False)
    tab = precompute_directional(tables, 3.0, tol=1e-5)
    assert tab.info["interpolation_error"]["x"] <= 1e-5
    rng = np.random.default_rng(7)
    p = np.exp(rng.uniform(math.log(tables.p_range[0] * E_STAR), math.log(1.5e6), 12))
    sx, sy = directional_sigma_bar(psd, p / E_STAR, 3.0)
    np.testing.assert_allclose(tab.sigma_bar(p, E_STAR, "x"), sx, rtol=3e-5)
    np.testing.assert_allclose(tab.sigma_bar(p, E_STAR, "y"), sy, rtol=3e-5)
    pc = float(fc.contact.percolation_pressure(psd, E_STAR, 0.5))
    assert tab.sigma_bar(1.0001 * pc, E_STAR, "x") == 0.0
    np.testing.assert_allclose(tab.conductivity(1e5, E_STAR, 2e-3, "y"),
                               tab.sigma_bar(1e5, E_STAR, "y") * psd.h_rms ** 3 / (12 * 2e-3))

    # the same as ordinary Tables: every engine runs the anisotropic case unchanged
    tx = directional_tables(tables, 3.0, "x", directional=tab)
    assert tx.options["anisotropy"] == 3.0 and tx.options["direction"] == "x"
    np.testing.assert_allclose(tx.sigma_bar(p, E_STAR, "emt"), sx, rtol=3e-5)
    ty = directional_tables(tables, 3.0, "y", directional=tab)
    np.testing.assert_allclose(ty.sigma_bar(p, E_STAR, "emt"), sy, rtol=3e-5)
    sq = fc.squeeze_out(tx, p0=1e5, E_star=E_STAR, R=0.01, eta=1e-3, theory="emt")
    sq_iso = fc.squeeze_out(tables, p0=1e5, E_star=E_STAR, R=0.01, eta=1e-3, theory="emt")
    assert sq.t_star[0] < sq_iso.t_star[0]        # easier flow along the grooves


# ------------------------------------------------------------------ adaptive quadrature in A
@pytest.fixture(scope="module")
def road_psd():
    """A measured-style spectrum: a 48-sample table (kinks at every sample in u1(A))."""
    from fastcontact.surface.roaddb import synthetic_road_psd
    q, C = synthetic_road_psd(np.random.default_rng(7))[-2:]
    return fc.TabulatedPSD(q, C)


@pytest.mark.parametrize("form", ["self_consistent", "fixed"])
@pytest.mark.parametrize("which", ["smooth", "road"])
def test_adaptive_against_fine_fixed_panels(psd, road_psd, form, which):
    """The default (adaptive, tol 1e-8) against 192 fixed Gauss–Legendre panels of order 10,
    from light load to past the directional thresholds (σ̄ > 1e-20 compared; closed
    directions must agree exactly)."""
    s = psd if which == "smooth" else road_psd
    pc = float(fc.contact.percolation_pressure(s, E_STAR, 0.5))
    p = pc * np.geomspace(1e-6, 1.2, 14)
    ax, ay = directional_sigma_bar(s, p / E_STAR, 3.0, form=form)
    fx, fy = directional_sigma_bar(s, p / E_STAR, 3.0, form=form, n_panels=192)
    for a, f in ((ax, fx), (ay, fy)):
        assert np.array_equal(a > 0, f > 0)
        m = f > 1e-20
        np.testing.assert_allclose(a[m], f[m], rtol=3e-8)


@pytest.mark.parametrize("form", ["self_consistent", "fixed"])
def test_fixed_panels_at_gamma_one(psd, form):
    """The fixed-panel reference (48 panels) forced at γ_T = 1 against the isotropic EMT."""
    p = np.array([1e-3, 1e2, 1e4, 1e5, 1e6, 1.9e6])
    iso = conductivity(psd, p, E_STAR, 1.0 / 12.0, "emt", tol=1e-12)[0] / psd.h_rms ** 3
    sx, sy = directional_sigma_bar(psd, p / E_STAR, 1.0, form=form, n_panels=48)
    np.testing.assert_allclose(sx, iso, rtol=2e-9)
    np.testing.assert_allclose(sy, iso, rtol=2e-9)


def test_self_consistent_solution_satisfies_its_definition(road_psd):
    """Λ = γ_T √(σ_yy/σ_xx) with each σ the solution of its own equation at λ = kk Λ^{±1}:
    checked with Λ from the result and the directional solves redone with brentq."""
    from scipy.optimize import brentq

    from fastcontact.flow import directional as dmod
    from fastcontact.flow._anisotropic_kernels import solve_self_consistent

    pc = float(fc.contact.percolation_pressure(road_psd, E_STAR, 0.5))
    W, sig, A1 = dmod._nodes(road_psd, np.array([1e-4, 0.1, 0.7]) * pc / E_STAR, 1.0, 24)
    for i in range(A1.size):
        sx, sy = solve_self_consistent(W[i], sig[i], float(A1[i]), 3.0)
        lam = 3.0 * math.sqrt(sy / sx)
        for s, lm in ((sx, lam), (sy, 1.0 / lam)):
            def f(y):
                v = math.exp(y)
                return float(np.sum(W[i] * (1 + lm) * v / (lm * v + sig[i]))
                             + A1[i] * (1 + lm) / lm - 1)
            y = brentq(f, math.log(s) - 5, math.log(s) + 5, xtol=1e-14, rtol=1e-15)
            assert s == pytest.approx(math.exp(y), rel=1e-11)


def test_adaptive_on_extreme_cases():
    """Random spectra (self-affine and road tables), γ_T 1–100, both forms, A_c 0.4–0.6,
    p̄ from 1e-12 × to 1.6 × the percolation pressure and at it: finite, σ_xx >= σ_yy, closed
    where the 96-panel reference is closed, within 1e-6 of it where σ̄ > 1e-20 (fixed seed)."""
    from fastcontact.flow.directional import _adaptive
    from fastcontact.surface.roaddb import synthetic_road_psd

    rng = np.random.default_rng(20261126)
    for trial in range(8):
        if trial % 2:
            q, C = synthetic_road_psd(np.random.default_rng(int(rng.integers(1 << 30))))[-2:]
            s = fc.TabulatedPSD(q, C)
        else:
            s = fc.SelfAffinePSD(10 ** rng.uniform(-7, -4), rng.uniform(0.3, 0.95),
                                 10 ** rng.uniform(2, 4), 10 ** rng.uniform(6, 9))
        g = float(10 ** rng.uniform(0, 2))
        form = "fixed" if trial % 4 < 2 else "self_consistent"
        a_c = [0.5, 0.4, 0.6][trial % 3]
        pc = float(fc.contact.percolation_pressure(s, 1.0, 0.5))
        pb = pc * np.concatenate((10 ** rng.uniform(-12, 0.2, 10), [0.999, 1.0, 1.001]))
        sx, sy, _, nev = _adaptive(s, pb, g, form, 1.0, a_c / (1 - a_c), 1e-8)[:4]
        rx, ry = directional_sigma_bar(s, pb, g, form=form, n_panels=96, emt_threshold=a_c)
        assert np.all(np.isfinite(sx) & np.isfinite(sy) & (sx >= 0) & (sy >= 0))
        assert np.all(sx >= sy * (1 - 1e-12))
        assert np.array_equal(sx > 0, rx > 0) and np.array_equal(sy > 0, ry > 0)
        assert np.all(nev < 96 * 15)
        for a, r in ((sx, rx), (sy, ry)):
            m = r > 1e-20
            np.testing.assert_allclose(a[m], r[m], rtol=1e-6)
