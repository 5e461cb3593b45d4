"""Accuracy of the BEM + Reynolds reference itself (issue 13): closed forms, Parseval, grids."""
import math
import sys
import warnings

import numpy as np
import pytest

import fastcontact as fc
from fastcontact import contact
from fastcontact.validation import bem, reynolds
from fastcontact.validation.bem import bem_reference, solve_contact, surface_realization
from fastcontact.validation.reynolds import reynolds_conductivity

ETA = 1e-3


# ------------------------------------------------------------------ Reynolds closed forms
def test_flat_channel_is_g3_over_12eta():
    g = 3.7e-6
    s = reynolds_conductivity(np.full((16, 16), g), ETA)
    exact = g ** 3 / (12 * ETA)
    assert s["x"] == pytest.approx(exact, rel=1e-13)
    assert s["y"] == pytest.approx(exact, rel=1e-13)


@pytest.mark.parametrize("frac", [0.25, 0.5, 0.75])
def test_two_strips_series_and_parallel(frac):
    n = 32
    g = np.full((n, n), 1e-6)
    m = int(frac * n)
    g[:m, :] = 2.5e-6  # strips across x: in series for flow along x, parallel along y
    k = g ** 3 / (12 * ETA)
    s = reynolds_conductivity(g, ETA)
    k1, k2 = (2.5e-6) ** 3 / (12 * ETA), (1e-6) ** 3 / (12 * ETA)
    series = 1.0 / (frac / k1 + (1 - frac) / k2)
    parallel = frac * k1 + (1 - frac) * k2
    assert s["x"] == pytest.approx(series, rel=1e-10)
    assert s["y"] == pytest.approx(parallel, rel=1e-10)
    assert s["x"] == pytest.approx(1 / np.mean(1 / k), rel=1e-10)


def test_contact_line_blocks_flow_and_pockets_are_pinned():
    n = 24
    g = np.full((n, n), 1e-6)
    g[:, 7] = 0.0  # a contact line along x: no flow along y, x unchanged but for that row
    s = reynolds_conductivity(g, ETA)
    assert s["y"] == 0.0
    assert s["x"] == pytest.approx((n - 1) / n * 1e-18 / (12 * ETA), rel=1e-10)
    # a closed contact ring around a fluid pocket: still solvable, pocket carries nothing
    g2 = np.full((n, n), 1e-6)
    g2[5:12, 5] = g2[5:12, 11] = g2[5, 5:12] = g2[11, 5:12] = 0.0
    s2 = reynolds_conductivity(g2, ETA)
    assert 0 < s2["x"] < 1e-18 / (12 * ETA)


def test_reynolds_rejects_bad_input():
    with pytest.raises(ValueError, match="gap"):
        reynolds_conductivity(np.full((4, 5), 1e-6), ETA)
    with pytest.raises(ValueError, match="gap"):
        reynolds_conductivity(-np.ones((4, 4)), ETA)
    with pytest.raises(ValueError, match="eta"):
        reynolds_conductivity(np.ones((4, 4)), 0.0)


# ------------------------------------------------------------------ surfaces
def _psd(q1_factor=8, roll=2):
    L = 1e-3
    q0 = 2 * math.pi / L
    return fc.SelfAffinePSD(h_rms=1e-6, hurst=0.8, q0=q0, q1=q1_factor * q0, q_roll=roll * q0), L


def test_parseval_of_the_realization():
    psd, L = _psd(q1_factor=16, roll=4)
    n = 64
    h = surface_realization(psd, n, L, seed=3)
    # independent lattice sum of the PSD: mean(h²) = Σ_{q≠0} C(q) (2π/L)²
    q1d = 2 * math.pi * np.fft.fftfreq(n, L / n)
    q = np.hypot(q1d[:, None], q1d[None, :])
    qr, q0, q1 = psd.q_roll, psd.q0, psd.q1
    # C0 from h_rms² = 2π ∫ q C dq of the rolled-off power law (closed form), H = 0.8
    e = 2 * 1.8
    integral = qr ** -e * (qr ** 2 - q0 ** 2) / 2 + (qr ** (2 - e) - q1 ** (2 - e)) / (e - 2)
    C0 = psd.h_rms ** 2 / (2 * math.pi * integral)
    C = np.where(q < q0 * (1 - 1e-9), 0.0,
                 np.where(q < qr, C0 * qr ** -e, C0 * np.maximum(q, 1e-30) ** -e))
    C = np.where(q > q1 * (1 + 1e-9), 0.0, C)
    lattice = np.sum(C) * (2 * math.pi / L) ** 2
    assert np.mean(h ** 2) == pytest.approx(lattice, rel=1e-10)
    assert abs(h.mean()) < 1e-12 * psd.h_rms
    # the lattice sum approximates the integral (4 lattice modes below the roll-off): 2 %
    assert np.sqrt(np.mean(h ** 2)) == pytest.approx(psd.h_rms, rel=0.02)


@pytest.mark.parametrize("n", [8, 16, 24, 64])
def test_nested_uniform_sets_every_mode_nyquist_included(n):
    # independent reference, one mode at a time: mode (i, j) (signed, fftfreq order) takes its
    # number from the smallest grid m of the chain n, n/2, ... (>= 8) with
    # max(|i|, |j|) <= (m-1)//2, else from the n grid (its Nyquist row and column), generator
    # default_rng([seed, m])
    from fastcontact.validation.bem import _nested_uniform
    seed = 7
    chain = [n]
    while chain[-1] % 2 == 0 and chain[-1] // 2 >= 8:
        chain.append(chain[-1] // 2)
    draws = {m: np.random.default_rng([seed, m]).random((m, m)) for m in chain}
    signed = [k if k < (n + 1) // 2 else k - n for k in range(n)]
    ref = np.empty((n, n))
    for a, i in enumerate(signed):
        for b, j in enumerate(signed):
            m = min([m for m in chain if max(abs(i), abs(j)) <= (m - 1) // 2] + [n])
            ref[a, b] = draws[m][i % m, j % m]
    got = _nested_uniform(n, seed)
    assert np.array_equal(got, ref)  # the Nyquist row/column (i = -n/2) included


def test_realization_past_nyquist_is_finite():
    # q1 beyond the grid's Nyquist wavevector: the Nyquist modes carry power, so an unset
    # phase there would turn the map into NaN (seen on CI before the fix)
    psd, L = _psd(q1_factor=64, roll=2)
    h = surface_realization(psd, 16, L, seed=3)
    assert np.all(np.isfinite(h))
    assert np.sqrt(np.mean(h ** 2)) > 0.5 * psd.h_rms


# ------------------------------------------------------------------ contact: Hertz
def test_hertz_sphere_on_flat():
    n, box, R, E = 64, 1e-3, 5e-3, 1e7
    a_target = 0.25 * box
    F = 4 * E * a_target ** 3 / (3 * R)
    x = (np.arange(n) - n / 2) * box / n
    r2 = x[:, None] ** 2 + x[None, :] ** 2
    h = -r2 / (2 * R)  # rigid sphere, apex at the centre pointing at the elastic flat
    c = solve_contact(h, box, E, F / box ** 2, periodic=False)
    a_hertz = (3 * F * R / (4 * E)) ** (1 / 3)  # Johnson (1985) eq. 4.22
    a_num = math.sqrt(c["area_fraction"] * box ** 2 / math.pi)
    assert a_num == pytest.approx(a_hertz, rel=0.03)
    p_max = 3 * F / (2 * math.pi * a_hertz ** 2)
    assert c["pressure"].sum() * (box / n) ** 2 == pytest.approx(F, rel=1e-6)
    # pixel pressure at the apex vs p0 = 3F/(2πa²) (Johnson eq. 4.23)
    assert c["pressure"].max() == pytest.approx(p_max, rel=0.03)


# ------------------------------------------------------------------ the reference
def test_reference_columns_units_attrs():
    psd, L = _psd()
    E = 1e7
    p = contact.percolation_pressure(psd, E, np.array([0.05, 0.3, 0.7]))
    df = bem_reference(psd, E, p[::-1], n=32, seeds=[0, 1], eta=2e-3, progress=False,
                       stop_bisections=2)
    for col in ("p0", "area_fraction", "u_mean", "sigma_eff", "area_fraction_std", "u_mean_std",
                "sigma_eff_std", "n_flowing", "area_fraction_grid_err", "u_mean_grid_err",
                "sigma_eff_grid_err"):
        assert col in df, col
        assert col in df.attrs["units"], col
    assert np.all(np.diff(df.p0) > 0)
    assert np.all(np.diff(df.area_fraction) > 0) and np.all(np.diff(df.u_mean) < 0)
    assert df.attrs["eta"] == 2e-3 and df.attrs["units"]["sigma_eff"] == "m^3/(Pa s)"
    assert df.sigma_eff.iloc[0] > 0 and df.sigma_eff.iloc[-1] == 0.0
    stop = df.attrs["flow_stop_pressure"]
    assert df.p0.iloc[0] < stop < df.p0.iloc[-1]
    prov = df.attrs["provenance"]
    assert prov["n"] == 32 and prov["seeds"] == [0, 1] and prov["box"] == pytest.approx(L)
    assert prov["psd"]["kind"] == "self_affine" and prov["versions"]["ContactMechanics"]
    # the nominal pressure is carried: mean pixel pressure = p0 (checked via the solver)
    c = solve_contact(surface_realization(psd, 32, L, 0), L, E, float(p[1]))
    assert c["pressure"].mean() == pytest.approx(p[1], rel=1e-8)
    assert c["u_mean"] == pytest.approx(c["gap"].mean())


def test_coarse_vs_fine_grid_converge():
    psd, L = _psd(q1_factor=4, roll=2)
    E = 1e7
    p = contact.percolation_pressure(psd, E, np.array([0.1, 0.2]))
    kw = dict(seeds=[0], progress=False, grid_check=False, stop_bisections=0)
    a = bem_reference(psd, E, p, n=32, **kw)   # 8 pixels per shortest wavelength
    b = bem_reference(psd, E, p, n=64, **kw)   # 16
    assert np.allclose(a.u_mean, b.u_mean, rtol=0.05)
    assert np.allclose(a.area_fraction, b.area_fraction, rtol=0.15)


def test_under_resolution_warns_and_bad_input():
    psd, L = _psd(q1_factor=64)
    with pytest.warns(bem.BEMResolutionWarning, match="pixels per shortest wavelength"):
        bem_reference(psd, 1e7, [1e4], n=16, seeds=[0], progress=False, grid_check=False)
    psd, L = _psd()
    with pytest.raises(ValueError, match="E_star"):
        bem_reference(psd, -1.0, [1e4], n=16, progress=False)
    with pytest.raises(ValueError, match="p0"):
        bem_reference(psd, 1e7, [0.0], n=16, progress=False)
    with pytest.raises(ValueError, match="n = 4"):
        bem_reference(psd, 1e7, [1e4], n=4, progress=False)


def test_missing_extra_is_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "ContactMechanics", None)
    with pytest.raises(ImportError, match=r'pip install "fastcontact\[bem\]"'):
        bem.require_extra()
