"""Issue 14.2: Roelands viscosity in the seal engine (no reduced pressure: numerical solution).

Reference: ``tests/reference/ext_roelands.py`` — Hamrock & Dowson's eq. 4.5 written out
(constants 9.67 and 5.1e-9 1/Pa, or a larger c to make the law nonlinear at soft-seal
pressures), the 1-D Reynolds equation with η(p) by solve_bvp (flat ring) and adaptive DOP853
shooting (O-ring), in p itself.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_roelands import hertz_shoot, roelands, seal_bvp  # noqa: E402
from reference.seal_reference import SigmaInterp, hertz_geometry, hertz_reference  # noqa: E402

import fastcontact as fc  # noqa: E402
from fastcontact.flow.piezoviscosity import (  # noqa: E402
    ROELANDS_ETA_INF,
    ROELANDS_P_R,
    roelands_parameters,
    viscosity_ratio,
)
from fastcontact.seal import seal_leak  # noqa: E402

E_STAR, ETA, L_Y = 1e7, 1e-3, 0.1
C, Z = 1e-5, 0.6            # p_r = 1e5 Pa: strongly nonlinear at these pressures


@pytest.fixture(scope="module")
def tables():
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    return fc.precompute(psd, theories=("critical_junction", "emt"))


def _sigma(tables, theory):
    plo = tables.p_range[0] * E_STAR
    return lambda pc: tables.conductivity(np.maximum(pc, plo * (1 + 1e-7)), E_STAR, ETA, theory)


def test_law_is_hamrock_dowson():
    p = np.array([0.0, 1e6, 1e8, 5e8, 1e9])
    for eta0, z in ((0.05, 0.6), (1e-3, 0.4)):
        ref = roelands(eta0, z)(p)
        got = viscosity_ratio(p, "roelands", eta=eta0, roelands_z=z)
        np.testing.assert_allclose(got, ref, rtol=1e-13)
    # initial slope α0 = A Z / p_r: Z from alpha_pv reproduces it
    A, Zs, pr = roelands_parameters(0.05, alpha_pv=2e-8)
    assert pr == ROELANDS_P_R and abs(A - math.log(0.05 / ROELANDS_ETA_INF)) < 1e-14
    eps = 1.0
    slope = math.log(float(viscosity_ratio(eps, "roelands", eta=0.05, alpha_pv=2e-8))) / eps
    assert abs(slope / 2e-8 - 1) < 1e-7
    # below Barus at high pressure for Z < 1 (same initial slope)
    assert viscosity_ratio(1e9, "roelands", eta=0.05, alpha_pv=2e-8) < \
        viscosity_ratio(1e9, "barus", alpha_pv=2e-8)


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_uniform_against_bvp(tables, theory):
    p0, L = 5e4, 5e-3
    for dp in (2e4, 4.5e4):
        q, _ = seal_bvp(_sigma(tables, theory), lambda x: p0 + 0 * x, 0.0, L, dp, 0.0,
                        roelands(ETA, Z, C))
        got = seal_leak(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                        theory=theory, viscosity="roelands", roelands_z=Z, roelands_p_r=1 / C)
        assert got.attrs["viscosity"] == "Roelands"
        assert abs(got.Q[0] / (q * L_Y) - 1) < 1e-8
        base = seal_leak(tables, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                         theory=theory)
        assert got.Q[0] < 0.9 * base.Q[0]                # the viscosity really matters


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_hertz_against_shooting(tables, theory):
    R, f_N = 1e-3, 3.0
    a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
    pH = 2 * f_N / (math.pi * a)
    for dp in (3e4, 6e4):
        ref = hertz_shoot(_sigma(tables, theory), pH, a, dp, 0.0, roelands(ETA, Z, C)) * L_Y
        got = seal_leak(tables, profile="hertz", R=R, f_N=f_N, dp=dp, L_y=L_Y, E_star=E_STAR,
                        eta=ETA, theory=theory, viscosity="roelands", roelands_z=Z,
                        roelands_p_r=1 / C)
        assert bool(got.converged[0]) and got.status[0] == "ok"
        assert abs(got.Q[0] / ref - 1) < 2e-8


def test_limits(tables):
    kw = dict(p0=5e4, dp=np.array([1e4, 4e4]), L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA,
              theory="emt")
    base = seal_leak(tables, **kw)
    # Z = 0: constant viscosity (the η(p) solver reproduces the base engine)
    z0 = seal_leak(tables, viscosity="roelands", roelands_z=0.0, **kw)
    np.testing.assert_allclose(z0.Q, base.Q, rtol=1e-9)
    # α p ≪ ln(η0/η_∞) and p ≪ p_r: Roelands with Z from α tends to Barus with that α; the
    # difference is second order in α (ln η = αp + O((αp)²)) while the Barus effect is first
    rel = []
    for a in (2e-6, 5e-7):
        bar = seal_leak(tables, alpha_pv=a, **kw)
        roe = seal_leak(tables, alpha_pv=a, viscosity="roelands", **kw)
        rel.append(np.abs(roe.Q / bar.Q - 1))
        assert np.all(rel[-1] < 0.02 * np.abs(bar.Q / base.Q - 1))
    assert np.all((rel[1] / rel[0] > 1 / 32) & (rel[1] / rel[0] < 1 / 8))   # ≈ (1/4)²
    # Hertz, Z = 0
    h = dict(profile="hertz", R=1e-3, f_N=3.0, dp=3e4, L_y=L_Y, E_star=E_STAR, eta=ETA,
             theory="emt")
    assert abs(seal_leak(tables, viscosity="roelands", roelands_z=0.0, **h).Q[0]
               / seal_leak(tables, **h).Q[0] - 1) < 3e-8


def test_bad_input(tables):
    kw = dict(p0=5e4, dp=1e4, L=5e-3, L_y=L_Y, E_star=E_STAR, theory="emt")
    with pytest.raises(ValueError, match="viscosity"):
        seal_leak(tables, eta=ETA, viscosity="vogel", **kw)
    with pytest.raises(ValueError, match="eta"):
        seal_leak(tables, eta=5e-5, viscosity="roelands", roelands_z=0.6, **kw)
    with pytest.raises(ValueError, match="roelands_z"):
        seal_leak(tables, eta=ETA, viscosity="roelands", roelands_z=-0.1, **kw)
    with pytest.raises(ValueError, match="roelands_p_r"):
        seal_leak(tables, eta=ETA, viscosity="roelands", roelands_z=0.6, roelands_p_r=0.0, **kw)


@pytest.mark.parametrize("eps", [1e-3, 1e-4, 1e-6])
def test_hertz_next_to_lift_off(tables, eps):
    """The default Roelands O-ring next to lift-off (p_a = p_H(1 - eps)), with Z -> 0
    (η = η0 to 1e-12), against the base seal's independent collocation reference with σ from
    the direct core (no tables): within 1e-7 (measured <= 5.6e-9 by the panel collocation at
    the near-lift-off tolerance; the checked shooting it replaced, <= 3.7e-7; 200 unchecked
    steps were off by up to 4e-5 at eps = 1e-6). (The DOP853 reference of
    reference/ext_roelands.py is itself off by up to 8e-6 at eps = 1e-3, with any law.)"""
    psd = fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)
    sig = SigmaInterp(psd, E_star=E_STAR, eta=ETA, theory="critical_junction",
                      p_lo=1e-16 * E_STAR, p_hi=3e5)
    R, f_N = 1e-3, 3.0
    _, pH = hertz_geometry(R, f_N, E_STAR)
    dp = pH * (1 - eps)
    ref, est, _ = hertz_reference(sig, R=R, f_N=f_N, dp=dp, L_y=L_Y, E_star=E_STAR)
    assert est < 1e-8
    got = seal_leak(tables, profile="hertz", R=R, f_N=f_N, dp=dp, L_y=L_Y, E_star=E_STAR,
                    eta=ETA, theory="critical_junction", viscosity="roelands",
                    roelands_z=1e-14, roelands_p_r=1e5)
    assert got.status[0] == "ok" and bool(got.converged[0])
    assert abs(got.Q[0] / ref - 1) < 1e-7, got.Q[0] / ref - 1


def test_checked_shooting_second_level_reaches_the_cold_root(tables, monkeypatch):
    """The checked shooting (the default O-ring's fallback where the panel Newton fails; here
    forced for every row) starts each level's finer solve from the coarser root and slope
    (one Newton step, then the secant) instead of a coarse solve: the same root as a cold
    ``steps=`` solve, to the secant's 1e-13 (measured <= 8e-14 on 400 random rings) — 200
    steps away from lift-off, 3200 at p_a = 0.999 p_H (where 100 and 200 steps disagree by
    more than FALLBACK_RTOL and the row goes to the second level)."""
    from fastcontact.seal import viscosity
    from fastcontact.seal.viscosity import FALLBACK_STEPS, HERTZ_STEPS, seal_leak_piezo

    def failed(tables, theory, E, *rest):
        return np.full(E.size, np.nan), np.zeros(E.size, dtype=bool)
    monkeypatch.setattr(viscosity, "_roelands_hertz_k", failed)

    R, f_N = 1e-3, 3.0
    _, pH = hertz_geometry(R, f_N, E_STAR)
    kw = dict(profile="hertz", R=R, f_N=f_N, L_y=L_Y, E_star=E_STAR, eta=ETA,
              theory="critical_junction", alpha_pv=C, viscosity="roelands", roelands_z=Z,
              roelands_p_r=1 / C)
    for frac, steps in (([1e-3, 0.1, 0.5, 0.9], HERTZ_STEPS), ([0.999], FALLBACK_STEPS)):
        dp = pH * np.array(frac)
        checked = seal_leak_piezo(tables, dp=dp, **kw)
        cold = seal_leak_piezo(tables, dp=dp, steps=steps, **kw)
        assert (checked.status == "ok").all() and (cold.status == "ok").all()
        np.testing.assert_allclose(checked.Q, cold.Q, rtol=1e-12, atol=0)


def test_reduced_pressure_table_against_quad():
    """ψ(π) = ∫_0^π η0/η dπ' of the Roelands law from the solver's table (quintic Hermite in
    u = ln(1 + π/π_r), :mod:`fastcontact.seal._roelands_psi`) and its inverse, against scipy
    quad of the law written out (``reference.ext_roelands.roelands``), over the pressure drop
    and for laws from Hamrock & Dowson's (p_r = 196 MPa on a 10 MPa seal) to steep soft-seal
    ones (p_r = 0.1 MPa): within 1e-11 (measured <= 2.2e-13 for ψ, 4.0e-12 for the inverse)."""
    from scipy.integrate import quad

    from fastcontact.seal._roelands_psi import fluid_of, psi_of, psi_table

    for eta0, z, pr, dp in ((0.1, 0.6, ROELANDS_P_R, 5e7), (1e-3, 0.6, 1e5, 5e5),
                            (0.5, 0.68, 1e5, 2e5), (1e-3, 0.6, 1e5, 1e3)):
        A = math.log(eta0 / ROELANDS_ETA_INF)
        law = roelands(eta0, z, 1.0 / pr)      # η/η0 at p [Pa], written out
        E = 1e7
        rt = psi_table(A, z, pr / E, dp / E)
        for p in dp * np.concatenate((np.geomspace(1e-8, 1.0, 12), [0.37, 0.81, 1.2])):
            ref = quad(lambda x: 1.0 / law(x), 0.0, p, epsabs=0.0, epsrel=1e-13,
                       limit=200)[0] / E
            assert abs(psi_of(rt, p / E) / ref - 1) < 1e-11, (eta0, z, pr, p)
            assert abs(fluid_of(rt, ref) / (p / E) - 1) < 1e-11, (eta0, z, pr, p)


def test_hertz_default_is_the_panel_collocation(tables, monkeypatch):
    """The default Roelands O-ring is the base seal's panel collocation in the tabulated ψ
    (no shooting unless its Newton fails): against the adaptive DOP853 shooting reference
    from far from lift-off to p_a = 0.99 p_H within 2e-8 (measured <= 7.8e-9; the 200-step
    shooting was off by up to 1.2e-7 at 0.99), with no row sent to the shooting."""
    from fastcontact.seal import viscosity

    def no_shooting(*args, **kwargs):
        raise AssertionError("the default Roelands O-ring must not shoot here")
    monkeypatch.setattr(viscosity, "_checked_shooting", no_shooting)
    R, f_N = 1e-3, 3.0
    a = math.sqrt(4 * f_N * R / (math.pi * E_STAR))
    pH = 2 * f_N / (math.pi * a)
    dp = pH * np.array([0.05, 0.5, 0.95, 0.99])
    for theory in ("critical_junction", "emt"):
        got = seal_leak(tables, profile="hertz", R=R, f_N=f_N, dp=dp, L_y=L_Y, E_star=E_STAR,
                        eta=ETA, theory=theory, viscosity="roelands", roelands_z=Z,
                        roelands_p_r=1 / C)
        assert (got.status == "ok").all() and got.converged.all()
        for k, d in enumerate(dp):
            ref = hertz_shoot(_sigma(tables, theory), pH, a, d, 0.0, roelands(ETA, Z, C)) * L_Y
            assert abs(got.Q[k] / ref - 1) < 2e-8, (theory, d / pH, got.Q[k] / ref - 1)


def test_one_law_drops_share_one_table_against_quad():
    """Rows of one Roelands fluid read ψ(Δπ) from one table reaching the largest drop
    (``psi_drops_one_law``, the O-ring tables' ψ_a), against scipy quad of the law written out,
    from drops 1e-6 of the largest to the largest: within 1e-11; where that one table would
    need more than PSI_MAX_NODES nodes (a steep law over a large drop) ``one_table_fits`` says
    no and each row keeps its own table (``psi_drops``'s values exactly)."""
    from scipy.integrate import quad

    from fastcontact.seal._roelands_psi import (PSI_MAX_NODES, one_table_fits, psi_drops,
                                                psi_drops_one_law, psi_table)

    E = 1e7
    for eta0, z, pr, top in ((1e-3, 0.6, 2e5, 3e5), (0.1, 0.6, ROELANDS_P_R, 5e7),
                             (0.5, 0.68, 1e5, 2e5)):
        A = math.log(eta0 / ROELANDS_ETA_INF)
        law = roelands(eta0, z, 1.0 / pr)
        dp = top * np.concatenate((np.geomspace(1e-6, 1.0, 9), [0.37, 0.81]))
        assert one_table_fits(A, z, pr / E, top / E)
        got = np.empty(dp.size)
        psi_drops_one_law(A, z, pr / E, dp / E, got)
        for p, g in zip(dp, got):
            ref = quad(lambda x: 1.0 / law(x), 0.0, p, epsabs=0.0, epsrel=1e-13,
                       limit=200)[0] / E
            assert abs(g / ref - 1) < 1e-11, (eta0, z, pr, p)
    # steep: p_r = 0.1 MPa, η0 = 0.5 Pa s, over 100 MPa — the largest drop's table is capped
    A = math.log(0.5 / ROELANDS_ETA_INF)
    assert psi_table(A, 0.68, 1e5 / E, 1e8 / E).y.size - 1 == PSI_MAX_NODES
    assert not one_table_fits(A, 0.68, 1e5 / E, 1e8 / E)
    assert one_table_fits(A, 0.68, 1e5 / E, 1e6 / E)
    dpi = np.array([1e6, 1e8]) / E
    own = np.empty(2)
    psi_drops(np.full(2, A), np.full(2, 0.68), np.full(2, 1e5 / E), dpi, own)
    shared = np.empty(2)
    psi_drops_one_law(A, 0.68, 1e5 / E, dpi, shared)   # falls back to each row's own table
    np.testing.assert_array_equal(shared, own)
    law = roelands(0.5, 0.68, 1e-5)
    ref = quad(lambda x: 1.0 / law(x), 0.0, 1e6, epsabs=0.0, epsrel=1e-13, limit=200)[0] / E
    assert abs(own[0] / ref - 1) < 1e-11
