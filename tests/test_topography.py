"""Tests of fastcontact.topography: heights → C(q), spectrum files, synthetic surfaces.

Physics: the Persson convention of C(q) (B. Lorenz & B.N.J. Persson, Eur. Phys. J. E 32, 281
(2010), App. A), the (2π)² convention trap, Parseval, line scans.
Tolerances are justified where they are set; the measured values quoted come from 20 seeds
of the same construction (see the module doc of fastcontact.topography).
"""
from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from scipy.integrate import quad
from scipy.special import gamma

from fastcontact.psd import SelfAffinePSD, TabulatedPSD
from fastcontact.topography import (CONVENTION_KEY, abel_forward, abel_invert, line_psd,
                                    line_scans, psd_from_heights, read_psd,
                                    synthetic_heights, write_psd)

A = 1.0e-6                       # grid spacing [m]
N = 512                          # map size
Q_LO = 2.0 * math.pi / (N * A)   # smallest wavevector of the map [1/m]
Q_NY = math.pi / A               # Nyquist wavevector [1/m]
Q_R = 16.0 * Q_LO                # roll-off


def rms(h):
    return float(np.sqrt(np.mean(np.square(h))))


@pytest.fixture(scope="module")
def sa_psd():
    """Self-affine, H = 0.8, roll-off at 16·q_lo, resolved up to the Nyquist wavevector."""
    return SelfAffinePSD(1.0e-6, 0.8, Q_LO, Q_NY, Q_R)


@pytest.fixture(scope="module")
def gauss_map(sa_psd):
    return synthetic_heights(sa_psd, N, A, seed=1)


@pytest.fixture(scope="module")
def exact_map(sa_psd):
    """Random phases, exact amplitudes: periodogram = C at every lattice point (no scatter)."""
    return synthetic_heights(sa_psd, N, A, seed=2, random_amplitudes=False)


# ============================================================================ synthetic
def test_synthetic_heights_normalisation(sa_psd, exact_map):
    h = exact_map
    assert h.shape == (N, N) and h.dtype == np.float64
    assert abs(h.mean()) < 1e-12 * rms(h)
    # Persson normalisation: mean(h²) = Σ_{k≠0} C(q_k) Δq², exactly for exact amplitudes
    qs = 2 * math.pi * np.fft.fftfreq(N, A)
    qk = np.hypot(qs[:, None], qs[None, :])
    qk[np.abs(qk / Q_LO - 1) < 1e-9] = Q_LO
    lattice = float(np.sum(sa_psd(qk))) * Q_LO ** 2
    assert np.mean(h * h) == pytest.approx(lattice, rel=1e-10)
    # ... and the lattice sum is the integral h_rms² = 2π∫qC dq up to 0.12 % here
    assert rms(h) == pytest.approx(sa_psd.h_rms, rel=2e-3)


def test_synthetic_heights_expected_variance():
    """Gaussian surfaces: E[mean(h²)] = h_rms² (200 maps of 64²: std of the mean ~0.6 %)."""
    n = 64
    q_lo = 2 * math.pi / (n * A)
    psd = SelfAffinePSD(2e-7, 0.5, q_lo, math.pi / A, 8 * q_lo)
    var = [np.mean(synthetic_heights(psd, n, A, seed=s) ** 2) for s in range(200)]
    assert np.mean(var) == pytest.approx(psd.h_rms ** 2, rel=0.03)
    assert synthetic_heights(psd, n, A, seed=7) == pytest.approx(
        synthetic_heights(psd, n, A, seed=7), abs=0)


# ============================================================================ Parseval, 2-D
@pytest.mark.parametrize("case", ["gauss", "exact", "H0.3", "nonsquare", "q_roll8"])
def test_parseval_2d(case, sa_psd, gauss_map, exact_map):
    """rms(heights) = psd.h_rms within 1 % (measured ≤ 0.21 % on 20 seeds, ≤ 0.7 % for a
    roll-off at only 8·q_lo)."""
    if case == "gauss":
        h = gauss_map
    elif case == "exact":
        h = exact_map
    elif case == "H0.3":
        h = synthetic_heights(SelfAffinePSD(3e-7, 0.3, Q_LO, Q_NY, 32 * Q_LO), N, A, seed=3)
    elif case == "nonsquare":
        h = synthetic_heights(sa_psd, N, A, seed=4)[:256, :]
    else:
        h = synthetic_heights(SelfAffinePSD(1e-6, 0.8, Q_LO, Q_NY, 8 * Q_LO), N, A, seed=5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")            # no Parseval warning either
        psd = psd_from_heights(h, A, periodic=True)
    assert isinstance(psd, TabulatedPSD) and psd.convention == "persson"
    # the band starts at the equal-area radius of the origin's lattice cell (the cells of the
    # lowest shell at 2π/L reach down to it), √(Δqx Δqy / π) ≈ 0.56·2π/L for a square map
    cell = (2 * math.pi / (h.shape[0] * A)) * (2 * math.pi / (h.shape[1] * A))
    assert psd.q0 == pytest.approx(math.sqrt(cell / math.pi), rel=1e-12)
    assert psd.q1 == pytest.approx(Q_NY, rel=1e-12)
    assert psd.h_rms == pytest.approx(rms(h - h.mean()), rel=0.01)


def test_parseval_2d_detrend_plane(gauss_map):
    """A tilt added to the map is removed by detrend='plane' (the mean alone would not)."""
    y, x = np.mgrid[0:N, 0:N] * A
    tilted = gauss_map + 0.02 * x - 0.01 * y + 3e-6
    psd = psd_from_heights(tilted, A, detrend="plane", periodic=True)
    assert psd.h_rms == pytest.approx(rms(gauss_map), rel=0.01)


@pytest.mark.parametrize("hurst, seed", [(0.8, 0), (0.5, 1), (0.3, 2)])
def test_parseval_holds_without_a_resolved_roll_off(hurst, seed):
    """No roll-off: the few lowest lattice shells hold most of the variance; with equal-area
    bin edges near the origin their energy is still carried exactly (measured ≤ 0.07 %)."""
    psd = SelfAffinePSD(1e-6, hurst, Q_LO, Q_NY)
    h = synthetic_heights(psd, 256, A * 2, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = psd_from_heights(h, A * 2, periodic=True)
    assert out.h_rms == pytest.approx(rms(h - h.mean()), rel=0.01)


def test_parseval_warning_when_roughness_lies_beyond_nyquist():
    """White noise: a fifth of the variance sits in the FFT corners beyond π/a, which an
    isotropic spectrum up to the Nyquist wavevector cannot hold -> RuntimeWarning."""
    h = np.random.default_rng(0).standard_normal((256, 256)) * 1e-6
    with pytest.warns(RuntimeWarning, match="h_rms"):
        psd_from_heights(h, A, periodic=True)


def test_hann_window_keeps_variance_on_average(gauss_map):
    """mean(w²) = 1 normalisation: h_rms within 10 % (measured -1.3 … +5 % on 8 seeds)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        psd = psd_from_heights(gauss_map, A, window="hann")
    assert psd.h_rms == pytest.approx(rms(gauss_map), rel=0.10)


# ============================================================================ C(q) recovered
def test_exact_map_recovers_input_psd(sa_psd, exact_map):
    """No statistical scatter: the area-preserving table reproduces C(q) — power law and
    roll-off kink included — to 1.5 % from q_lo up to the last bin below q_Ny."""
    psd = psd_from_heights(exact_map, A, periodic=True)
    q, c = psd.q_samples[:-1], psd.C_samples[:-1]
    inside = q >= Q_LO * (1 - 1e-12)          # the input spectrum starts at 2π/L
    np.testing.assert_allclose(c[inside] / sa_psd(q[inside]), 1.0, atol=0.015)
    # below 2π/L (down to the equal-area radius) the table is flat at C(2π/L)
    np.testing.assert_allclose(c[~inside] / sa_psd(Q_LO), 1.0, atol=0.015)


def test_gaussian_map_follows_input_psd(sa_psd, gauss_map):
    """Well-resolved band 2·q_r … q_Ny/2 (bins of ≥ ~1900 lattice points, ≥ ~950
    independent |Z|² values since Z(-q) = Z(q)*): the relative scatter of a bin mean is
    ≤ 1/√950 = 3.3 %, ×~1.3 after the area-preserving deconvolution, so 20 % is > 4σ
    (measured max deviation 2.6–9.9 % on 20 seeds); the band average is within 4 % (measured
    ≤ 2.2 % on 16 seeds)."""
    psd = psd_from_heights(gauss_map, A, periodic=True)
    q, c = psd.q_samples, psd.C_samples
    band = (q >= 2 * Q_R) & (q <= Q_NY / 2)
    assert band.sum() >= 5
    ratio = c[band] / sa_psd(q[band])
    assert np.max(np.abs(ratio - 1)) < 0.20
    assert abs(np.exp(np.mean(np.log(ratio))) - 1) < 0.04


def test_band_limited_map_is_trimmed_not_garbage():
    """A synthetic map with q0 > 2π/L and q1 < π/a has round-off-level bins (~1e-30 of the
    peak) outside [q0, q1]: they are dropped, so the table ends at the bins holding q0 / q1,
    Parseval still holds, and the line-scan fit is not thrown off by 30 decades of noise."""
    n = 256
    q_lo = 2 * math.pi / (n * A)
    psd = SelfAffinePSD(1e-6, 0.8, 4 * q_lo, Q_NY / 4, 16 * q_lo)
    h = synthetic_heights(psd, n, A, seed=0)
    fit = psd_from_heights(h, A, periodic=True)
    assert 0.85 * psd.q0 < fit.q0 <= psd.q0 and psd.q1 <= fit.q1 < 1.3 * psd.q1
    assert fit.h_rms == pytest.approx(rms(h), rel=0.01)
    lines = psd_from_heights(h, A, line_scans=True, periodic=True)
    assert lines.q1 < 1.3 * psd.q1
    assert lines.h_rms == pytest.approx(rms(h), rel=0.05)


def test_n_bins_changes_resolution_not_parseval(gauss_map):
    coarse = psd_from_heights(gauss_map, A, n_bins=8, periodic=True)
    fine = psd_from_heights(gauss_map, A, n_bins=60, periodic=True)
    assert coarse.q_samples.size < fine.q_samples.size
    for psd in (coarse, fine):
        assert psd.h_rms == pytest.approx(rms(gauss_map), rel=0.01)


# ============================================================================ line scans
def test_abel_power_law_factor():
    """Power law: C = Γ(1+H)/(√π Γ(H+½)) C1D/q for C1D ∝ q^-(1+2H) — the direct inversion is exact
    for a pure power law (closed-form tail)."""
    q = np.geomspace(1e4, 1e7, 31)
    for H in (0.2, 0.5, 0.8, 0.95):
        d = 1e-20 * (q / 1e4) ** (-(1 + 2 * H))
        C, fallback = abel_invert(q, d)
        expected = gamma(1 + H) / (math.sqrt(math.pi) * gamma(H + 0.5)) * d / q
        assert not fallback.any()
        np.testing.assert_allclose(C, expected, rtol=1e-6)


def test_abel_forward_matches_quadrature(sa_psd):
    """C1D(qx) = ∫ dqy C(√(qx²+qy²)) for a roll-off spectrum (kink on a node), tail included."""
    psd = SelfAffinePSD(1e-6, 0.8, 1e4, 1e10, 1e5)
    q = np.unique(np.concatenate((np.geomspace(1e4, 1e7, 25), [1e5])))
    D = abel_forward(q, psd(q), s_tail=-3.6)

    def ref(qx):
        f = lambda qy: float(psd(math.hypot(qx, qy)))  # noqa: E731
        pts = [math.sqrt(1e10 - qx * qx)] if qx < 1e5 else None
        return 2 * quad(f, 0, math.sqrt(1e20 - qx * qx), points=pts, limit=500,
                        epsrel=1e-10)[0]

    for i in (0, 3, 8, 12, 20, 24):
        assert D[i] == pytest.approx(ref(q[i]), rel=1e-5)


def test_abel_forward_inverse_round_trip():
    """Noise-free C1D of a roll-off spectrum -> direct inversion: exact in the power-law
    part, ≤ 10 % next to the kink (measured 8.5 %: log-log interpolation of the smooth C1D
    at 13 nodes per decade), ≤ 2 % on the plateau 0.4 decade below it."""
    psd = SelfAffinePSD(1e-6, 0.8, 1e4, 1e12, 1e5)
    q = np.unique(np.concatenate((np.geomspace(1e4, 1e7, 40), [1e5])))
    C, _ = abel_invert(q, abel_forward(q, psd(q), s_tail=-3.6))
    r = C / psd(q)
    assert np.max(np.abs(r[q > 1.5e5] - 1)) < 1e-3
    assert np.max(np.abs(r - 1)) < 0.10
    assert np.max(np.abs(r[q < 0.4e5] - 1)) < 0.02


def test_line_scans_exact_map(sa_psd, exact_map):
    """Rows of an isotropic map without amplitude scatter: the regularised Abel fit recovers
    the 2-D C(q) to 2 % in the self-affine band 2·q_r … q_Ny/3 (measured 0.2 %), along either
    axis."""
    for axis in (0, 1):
        psd = psd_from_heights(line_scans(exact_map, axis=axis), A, line_scans=True, periodic=True)
        q = psd.q_samples
        band = (q >= 2 * Q_R) & (q <= Q_NY / 3)
        np.testing.assert_allclose(psd.C_samples[band] / sa_psd(q[band]), 1.0, atol=0.02)


def test_line_scans_gaussian_map(sa_psd, gauss_map):
    """All 512 rows of a Gaussian isotropic map: self-affine band within 20 % (measured max
    deviation ≤ 11 % on 16 seeds). h_rms: the 2-D spectrum contains the roughness
    perpendicular to the scans that every profile misses (its mean is removed), so psd.h_rms
    exceeds the profiles' rms — by +1.9 … +5.5 % measured on 16 seeds — and matches the
    map's rms to 6 % (measured ≤ 4.3 %)."""
    psd = psd_from_heights(gauss_map, A, line_scans=True, periodic=True)
    q = psd.q_samples
    band = (q >= 2 * Q_R) & (q <= Q_NY / 3)
    ratio = psd.C_samples[band] / sa_psd(q[band])
    assert np.max(np.abs(ratio - 1)) < 0.20
    profiles = gauss_map - gauss_map.mean(axis=1, keepdims=True)
    assert 0.0 < psd.h_rms / rms(profiles) - 1 < 0.08
    assert psd.h_rms == pytest.approx(rms(gauss_map), rel=0.06)


def test_single_line_scan(sa_psd, gauss_map):
    """One 1-D profile: a valid spectrum on [2π/L, π/a]; the self-affine band within a factor
    1.75 (one scan of 512 points: rms scatter ~15 %, worst node a factor 1.5 on 16 seeds)."""
    psd = psd_from_heights(gauss_map[7], A, periodic=True)
    assert psd.q0 == pytest.approx(Q_LO) and psd.q1 == pytest.approx(Q_NY)
    q = psd.q_samples
    band = (q >= 2 * Q_R) & (q <= Q_NY / 3)
    ratio = psd.C_samples[band] / sa_psd(q[band])
    assert np.all((ratio > 1 / 1.75) & (ratio < 1.75))


def test_line_psd_parseval(gauss_map):
    """1-D spectrum normalisation h_rms² = 2∫C1D dq: the table on [2π/L, π/a] holds the
    profiles' variance except half of the lowest lattice cell (2-3 % here; 2.5 ± 0.75 % on
    16 seeds)."""
    q, d = line_psd(gauss_map, A, periodic=True)
    energy = 2 * TabulatedPSD(q, d).moment(0.0)
    profiles = gauss_map - gauss_map.mean(axis=1, keepdims=True)
    assert energy / np.mean(profiles ** 2) == pytest.approx(0.975, abs=0.015)


def test_line_scans_helper():
    h = np.arange(24.0).reshape(3, 8)
    assert np.array_equal(line_scans(h, axis=1), h)
    assert np.array_equal(line_scans(h, axis=0), h.T)
    assert line_scans(h, axis=0).flags.c_contiguous
    assert line_scans(h[0]).shape == (1, 8)
    with pytest.raises(ValueError, match="axis"):
        line_scans(h, axis=2)


# ============================================================================ files
@pytest.fixture(scope="module")
def measured_psd(gauss_map):
    return psd_from_heights(gauss_map, A, periodic=True)


@pytest.mark.parametrize("suffix", [".csv", ".csv.gz", ".parquet"])
@pytest.mark.parametrize("convention", ["persson", "surface_topography"])
def test_round_trip(tmp_path, measured_psd, sa_psd, suffix, convention):
    for psd in (measured_psd, sa_psd):
        path = tmp_path / f"spectrum{suffix}"
        write_psd(psd, path, convention=convention)
        back = read_psd(path, convention)
        assert back.convention == convention
        q = np.geomspace(psd.q0, psd.q1, 301)
        np.testing.assert_allclose(back(q), psd(q), rtol=1e-12)
        assert back.h_rms == pytest.approx(psd.h_rms, rel=1e-12)
        assert back.q0 == psd.q0 and back.q1 == psd.q1
        assert os.listdir(tmp_path) == [path.name]          # no temporary file left


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_convention_trap(tmp_path, measured_psd, suffix):
    """A contact.engineering-style file ((2π)² Persson) read as such gives the same h_rms;
    read as Persson it gives 2π times the h_rms (C (2π)² too large)."""
    path = tmp_path / f"st{suffix}"
    write_psd(measured_psd, path, convention="surface_topography")
    raw = (pd.read_csv(path) if suffix == ".csv" else pq.read_table(path).to_pandas())
    np.testing.assert_allclose(raw["C"].to_numpy(),
                               (2 * math.pi) ** 2 * measured_psd.C_samples, rtol=1e-14)
    same = read_psd(path, "surface_topography")
    assert same.h_rms == pytest.approx(measured_psd.h_rms, rel=1e-12)
    if suffix == ".csv":
        wrong = read_psd(path, "persson")          # a CSV carries no convention: trusted
        assert wrong.h_rms == pytest.approx(2 * math.pi * measured_psd.h_rms, rel=1e-12)
    else:                                          # Parquet metadata catches the mistake
        with pytest.raises(ValueError, match="convention"):
            read_psd(path, "persson")


def test_parquet_metadata(tmp_path, measured_psd):
    path = tmp_path / "p.parquet"
    write_psd(measured_psd, path)
    assert pq.read_schema(path).metadata[CONVENTION_KEY] == b"persson"
    # a Parquet file without the key: the given convention is used
    bare = tmp_path / "bare.pq"
    pq.write_table(pa.table({"q": [1.0, 2.0, 4.0], "C": [8.0, 4.0, 1.0]}), bare)
    assert read_psd(bare, "surface_topography").C_samples[0] == pytest.approx(
        8.0 / (2 * math.pi) ** 2)


def test_custom_columns_and_comments(tmp_path):
    path = tmp_path / "export.csv"
    path.write_text("# exported by some tool\nwavevector (1/m), psd (m^4)\n"
                    "1e5, 1e-30\n2e5, 2e-31\n4e5, 3e-32\n")
    psd = read_psd(path, "persson", q_col="wavevector (1/m)", C_col="psd (m^4)")
    np.testing.assert_allclose(psd.q_samples, [1e5, 2e5, 4e5])
    np.testing.assert_allclose(psd.C_samples, [1e-30, 2e-31, 3e-32])
    with pytest.raises(ValueError, match="q_col"):
        read_psd(path, "persson")                  # default column "q" absent


def test_write_is_atomic(tmp_path, measured_psd, sa_psd, monkeypatch):
    path = tmp_path / "s.parquet"
    write_psd(sa_psd, path)
    before = path.read_bytes()

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(pq, "write_table", boom)
    with pytest.raises(OSError, match="disk full"):
        write_psd(measured_psd, path)
    assert path.read_bytes() == before             # the old file is intact
    assert os.listdir(tmp_path) == ["s.parquet"]   # and the temporary file is gone


# ============================================================================ errors
@pytest.mark.parametrize("convention", [None, "Persson", "st", 1.0])
def test_read_psd_requires_convention(tmp_path, measured_psd, convention):
    path = tmp_path / "c.csv"
    write_psd(measured_psd, path)
    with pytest.raises(ValueError, match="convention") as err:
        read_psd(path, convention)
    assert "persson" in str(err.value) and "surface_topography" in str(err.value)
    with pytest.raises(ValueError, match="convention"):
        read_psd(path)                             # missing
    with pytest.raises(ValueError, match="convention"):
        write_psd(measured_psd, path, convention=convention)


@pytest.mark.parametrize("qs, kind", [([1.0, 3.0, 2.0], "unsorted"),
                                      ([1.0, 2.0, 2.0], "duplicated")])
def test_read_psd_bad_q(tmp_path, qs, kind):
    path = tmp_path / "bad.csv"
    pd.DataFrame({"q": qs, "C": [3.0, 2.0, 1.0]}).to_csv(path, index=False)
    with pytest.raises(ValueError, match=rf"q = .*{kind}") as err:
        read_psd(path, "persson")
    assert "bad.csv" in str(err.value)


@pytest.mark.parametrize("C, name", [([1.0, float("nan"), 1.0], "C"), ([1.0, -2.0, 1.0], "C"),
                                     (["a", "b", "c"], "C")])
def test_read_psd_bad_C(tmp_path, C, name):
    path = tmp_path / "bad.csv"
    pd.DataFrame({"q": [1.0, 2.0, 3.0], "C": C}).to_csv(path, index=False)
    with pytest.raises(ValueError, match=rf"^{name} = "):
        read_psd(path, "persson")


def test_file_errors(tmp_path, measured_psd):
    with pytest.raises(ValueError, match="path"):
        read_psd(tmp_path / "missing.csv", "persson")
    with pytest.raises(ValueError, match="path"):
        read_psd(tmp_path / "x.txt", "persson")
    with pytest.raises(ValueError, match="path"):
        write_psd(measured_psd, tmp_path / "x.json")
    with pytest.raises(ValueError, match="path"):
        write_psd(measured_psd, tmp_path / "no_such_dir" / "x.csv")
    with pytest.raises(ValueError, match="psd"):
        write_psd("not a psd", tmp_path / "x.csv")
    garbage = tmp_path / "garbage.parquet"
    garbage.write_bytes(b"not parquet at all")
    with pytest.raises(ValueError, match="path"):
        read_psd(garbage, "persson")


@pytest.mark.parametrize("heights, match", [
    (np.full((16, 16), np.nan), r"heights = nan"),
    (np.where(np.eye(16) > 0, np.inf, 0.0), r"heights = inf"),
    (np.zeros((4, 16)), r"heights has shape \(4, 16\)"),
    (np.zeros(5), r"heights has shape \(5,\)"),
    (np.zeros((8, 8, 8)), r"heights has shape"),
    (np.ones((16, 16)), r"heights = constant"),
    ("abc", r"heights = "),
])
def test_bad_heights(heights, match):
    with pytest.raises(ValueError, match=match):
        psd_from_heights(heights, A)


def test_bad_options(gauss_map):
    h = gauss_map[:64, :64]
    for spacing in (0.0, -1e-6, float("nan"), float("inf"), "x", [1e-6, 2e-6]):
        with pytest.raises(ValueError, match="spacing"):
            psd_from_heights(h, spacing)
    for n_bins in (1, 2.5, True, "10"):
        with pytest.raises(ValueError, match="n_bins"):
            psd_from_heights(h, A, n_bins=n_bins)
    with pytest.raises(ValueError, match="window"):
        psd_from_heights(h, A, window="hamming")
    with pytest.raises(ValueError, match="detrend"):
        psd_from_heights(h, A, detrend="quadratic")
    with pytest.raises(ValueError, match="line_scans"):
        psd_from_heights(h, A, line_scans="yes")
    with pytest.raises(ValueError, match="heights"):
        psd_from_heights(np.zeros((3, 5)), A, line_scans=True)   # scans shorter than 8


def test_synthetic_heights_errors(sa_psd):
    with pytest.raises(ValueError, match="psd"):
        synthetic_heights("psd", 64, A)
    for n in (4, 64.0, True):
        with pytest.raises(ValueError, match=r"^n = "):
            synthetic_heights(sa_psd, n, A)
    with pytest.raises(ValueError, match="spacing"):
        synthetic_heights(sa_psd, 64, -A)
