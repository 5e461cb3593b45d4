"""Issue 12.4: real surfaces in — contact.engineering downloads, SurfaceTopography objects and
PSD results, windowing of non-periodic data.

The references are independent of fastcontact's spectrum code: the heights' own rms
(Parseval, via the Persson convention h_rms² = 2π∫qC dq), the exact input spectrum of a
synthetic surface, and spectra computed by SurfaceTopography itself (C_ST = (2π)² C).
"""
from __future__ import annotations

import io
import logging
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from fastcontact.surface.io import CE_2D_SERIES, psd_from_surface_topography, read_psd
from fastcontact.surface.psd import SelfAffinePSD
from fastcontact.surface.topography import psd_from_heights, synthetic_heights

# the optional extra is installed in CI (pip install ".[test]" pulls it in): no skip
from SurfaceTopography import NonuniformLineScan, Topography, UniformLineScan  # noqa: E402

from fastcontact.surface.io import read_topography  # noqa: E402

A_UM = 0.5                        # pixel size [µm]
N = 256
Q_LO = 2 * math.pi / (N * A_UM * 1e-6)
Q_NY = math.pi / (A_UM * 1e-6)


@pytest.fixture(scope="module")
def surface():
    """A periodic synthetic map [m] with a resolved roll-off, and its exact spectrum."""
    psd = SelfAffinePSD(0.2e-6, 0.8, Q_LO, Q_NY, 16 * Q_LO)
    h = synthetic_heights(psd, N, A_UM * 1e-6, seed=11)
    return psd, h


@pytest.fixture(scope="module")
def topo(surface):
    _, h = surface
    return Topography(h * 1e6, (N * A_UM, N * A_UM), unit="um", periodic=True)


def _h_rms_of(psd):
    """h_rms of a tabulated Persson spectrum by Parseval, h² = 2π ∫ q C dq (trapezoid in ln q
    on a fine grid — independent of the table's closed-form moments)."""
    q = np.geomspace(psd.q0, psd.q1, 20001)
    f = q * q * psd(q)
    return math.sqrt(2 * math.pi * np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(np.log(q))))


# ------------------------------------------------------------------ contact.engineering files
def _ce_series(topo):
    """The series contact.engineering publishes for a map, computed by SurfaceTopography, in
    SI (x [1/m], y [m³]): 1-D PSDs along x / y and q/π × 2D PSD."""
    qx, cx = topo.power_spectrum_from_profile(reliable=False)
    t = Topography(topo.heights().T.copy(), topo.physical_sizes[::-1], unit="um",
                   periodic=True)
    qy, cy = t.power_spectrum_from_profile(reliable=False)
    q2, c2 = topo.power_spectrum_from_area(reliable=False)
    out = []
    for name, q, y in (("1D PSD along x", qx, cx), ("1D PSD along y", qy, cy),
                       (CE_2D_SERIES, q2, q2 * c2 / np.pi)):
        q, y = np.ma.filled(np.ma.asarray(q, float), np.nan), np.ma.filled(np.ma.asarray(y, float), np.nan)
        out.append((name, q * 1e6, y * 1e-18))                 # 1/µm -> 1/m, µm³ -> m³
    return out


def _write_ce_csv(path, series, sep=";", subjects=("scan A",)):
    """contact.engineering's CSV layout: one row per point, series stacked."""
    frames = []
    for subj in subjects:
        for name, x, y in series:
            frames.append(pd.DataFrame({
                "Subject type": "measurement", "Subject name": subj, "Creator": "me",
                "Instrument name": "AFM", "Instrument type": "microscope-based",
                "Instrument parameters": "{}", "Function name": "Power spectrum",
                "Data series": name, "Wavevector (1/m)": x, "PSD (m³)": y,
                "standard error of PSD (m³)": np.nan, "comment": ""}))
    pd.concat(frames).to_csv(path, sep=sep, index=False)


def _write_ce_txt(path, series):
    """contact.engineering's txt layout: #-commented header, one np.savetxt block per series."""
    f = io.StringIO()
    f.write("# Power-spectral density (PSD)\n# ============================\n")
    f.write("# IF YOU USE THIS DATA IN A PUBLICATION, PLEASE CITE THE FOLLOWING PAPERS:\n"
            "# - 10.1088/2051-672X/aa51f8\n#\n")
    f.write("# topography: scan A\n# ==================\n# Creator: me\n#\n")
    for name, x, y in series:
        np.savetxt(f, np.transpose([x, y]), header=f"{name}\n{'-' * len(name)}\n"
                   f"Columns: Wavevector (1/m), PSD (m³)")
        f.write("\n")
    path.write_text(f.getvalue(), encoding="utf-8")


def _write_ce_xlsx(path, series):
    """contact.engineering's xlsx layout: INDEX sheet, one data sheet per series (header in
    row 10, an index column)."""
    with pd.ExcelWriter(path) as xl:
        index = []
        for k, (name, x, y) in enumerate(series):
            sheet = f"analysis-0-series-{k}"
            pd.DataFrame({"Wavevector (1/m)": x, "PSD (m³)": y}).to_excel(
                xl, sheet_name=sheet, startrow=9)
            ws = xl.sheets[sheet]
            for r, (key, val) in enumerate((("Function name", "Power spectrum"),
                                            ("Subject", "scan A"), ("Subject type", "measurement"),
                                            ("Creator", "me"), ("Instrument name", "AFM"),
                                            ("Instrument type", ""), ("Instrument parameters", "{}"),
                                            ("Data series", name)), start=1):
                ws[f"A{r}"], ws[f"B{r}"] = key, val
            index.append({"Subject name": "scan A", "Subject type": "measurement",
                          "Function name": "Power spectrum", "Data series": name,
                          "Link": f"Click to jump to sheet '{sheet}'"})
        pd.DataFrame(index).to_excel(xl, sheet_name="INDEX", index=False)


@pytest.mark.parametrize("fmt", ["csv;", "csv,", "txt", "xlsx"])
def test_contact_engineering_download_convention(fmt, tmp_path, surface, topo):
    """A download made of SurfaceTopography's own spectra reads back in the Persson
    convention: Parseval against the heights' rms within 5 % (a (2π)² convention error
    would be a factor 6.3), and C equal to SurfaceTopography's C_ST/(2π)² at its nodes."""
    psd_true, h = surface
    series = _ce_series(topo)
    path = tmp_path / ("psd." + fmt[:-1] if fmt.startswith("csv") else "psd." + fmt)
    if fmt.startswith("csv"):
        _write_ce_csv(path, series, sep=fmt[-1])
    elif fmt == "txt":
        _write_ce_txt(path, series)
    else:
        _write_ce_xlsx(path, series)
    psd = read_psd(path)
    assert psd.convention == "persson"
    _, q, y = series[2]
    ok = np.isfinite(y)
    c_st = y[ok] * np.pi / q[ok]                               # C_ST [m^4]
    np.testing.assert_allclose(psd.q_samples, q[ok], rtol=1e-12)
    np.testing.assert_allclose(psd.C_samples, c_st / (2 * np.pi) ** 2, rtol=1e-9)
    assert _h_rms_of(psd) == pytest.approx(np.std(h), rel=0.05)
    # the same file under the wrong convention claim is refused
    with pytest.raises(ValueError, match="convention"):
        read_psd(path, "persson")


def test_contact_engineering_1d_series_refused(tmp_path, topo):
    path = tmp_path / "psd.csv"
    _write_ce_csv(path, _ce_series(topo))
    with pytest.raises(ValueError, match=r"series = '1D PSD along x'.*1-D spectrum"):
        read_psd(path, series="1D PSD along x")
    with pytest.raises(ValueError, match="series = 'nope'"):
        read_psd(path, series="nope")
    only_1d = tmp_path / "line.csv"
    _write_ce_csv(only_1d, _ce_series(topo)[:1])
    with pytest.raises(ValueError, match=r"series = None.*no 'q/π × 2D PSD'"):
        read_psd(only_1d)


def test_contact_engineering_several_measurements(tmp_path, topo):
    path = tmp_path / "psd.csv"
    _write_ce_csv(path, _ce_series(topo), subjects=("scan A", "scan B"))
    with pytest.raises(ValueError, match=r"subject = None.*'scan A', 'scan B'"):
        read_psd(path)
    assert read_psd(path, subject="scan B").q_samples.size > 5


def test_plain_commented_txt_table(tmp_path):
    q = np.geomspace(1e4, 1e8, 9)
    C = 1e-30 * (q / 1e4) ** -3.6
    path = tmp_path / "c.txt"
    np.savetxt(path, np.transpose([q, C]), header="q [1/m]  C [m^4]")
    with pytest.raises(ValueError, match="convention"):
        read_psd(path)
    np.testing.assert_allclose(read_psd(path, "persson").C_samples, C, rtol=1e-15)
    semi = tmp_path / "c.csv"
    pd.DataFrame({"q": q, "C": C}).to_csv(semi, sep=";", index=False)
    np.testing.assert_allclose(read_psd(semi, "surface_topography").C_samples,
                               C / (2 * np.pi) ** 2, rtol=1e-12)


# ------------------------------------------------------------------ SurfaceTopography objects
def test_topography_object_equals_array_in_metres(surface, topo):
    """Spacing, unit (µm -> m) and is_periodic come from the object."""
    _, h = surface
    from_obj = psd_from_heights(topo)
    from_arr = psd_from_heights(h, A_UM * 1e-6, periodic=True)
    np.testing.assert_allclose(from_obj.q_samples, from_arr.q_samples, rtol=1e-12)
    np.testing.assert_allclose(from_obj.C_samples, from_arr.C_samples, rtol=1e-9)
    assert from_obj.window is None and from_obj.periodic is True
    assert abs(from_obj.parseval) < 0.01


def test_nonperiodic_topography_is_windowed(surface, caplog):
    _, h = surface
    t = Topography(h[:128, :160] * 1e9, (128 * A_UM * 1e3, 160 * A_UM * 1e3), unit="nm",
                   periodic=False)
    with caplog.at_level(logging.INFO, logger="fastcontact.surface"):
        psd = psd_from_heights(t)
    assert psd.window == "hann" and psd.periodic is False
    assert "Hann window" in caplog.text
    crop = h[:128, :160]
    assert psd.h_rms_heights == pytest.approx(np.std(crop), rel=1e-9)
    assert abs(psd.parseval) < 0.01


def test_line_scans_from_objects(surface):
    """UniformLineScan and a NonuniformLineScan on the same (here uniform) positions give the
    line-scan spectrum of the plain profile."""
    _, h = surface
    row = h[5]
    ref = psd_from_heights(row, A_UM * 1e-6)                      # non-periodic: Hann
    u = UniformLineScan(row * 1e3, N * A_UM * 1e-3, unit="mm", periodic=False)
    x = np.arange(N) * A_UM
    nu = NonuniformLineScan(x, row * 1e6, unit="um")
    for obj in (u, nu):
        psd = psd_from_heights(obj)
        np.testing.assert_allclose(psd.q_samples[:-1], ref.q_samples[:-1], rtol=1e-9)
        np.testing.assert_allclose(psd.C_samples[:-2], ref.C_samples[:-2], rtol=1e-4)


def test_masked_and_unitless_topographies_refused(surface):
    _, h = surface
    m = np.ma.masked_array(h[:64, :64] * 1e6, mask=np.zeros((64, 64), bool))
    m[3, 4] = np.ma.masked
    t = Topography(m, (32.0, 32.0), unit="um")
    with pytest.raises(ValueError, match=r"heights = Topography is invalid: .*1 undefined"):
        psd_from_heights(t)
    with pytest.raises(ValueError, match="unit = None"):
        psd_from_heights(Topography(h[:64, :64], (32.0, 32.0)))
    with pytest.raises(ValueError, match="spacing"):
        psd_from_heights(Topography(h[:64, :64], (32.0, 32.0), unit="um"), 1e-6)
    with pytest.raises(ValueError, match="masked"):
        psd_from_heights(m, 1e-6)


def test_surface_topography_psd_results(surface, topo):
    """power_spectrum_from_area (dim=2) and _from_profile (dim=1) results, units from the
    container; dim is required and a 2-D spectrum is never guessed."""
    psd_true, h = surface
    q, C = topo.power_spectrum_from_area()
    two = psd_from_surface_topography(q, C, dim=2, unit="um")
    assert _h_rms_of(two) == pytest.approx(np.std(h), rel=0.05)
    q1, C1 = topo.power_spectrum_from_profile()
    one = psd_from_surface_topography(q1, C1, dim=1, unit="um")
    band = (one.q_samples > 2 * 16 * Q_LO) & (one.q_samples < Q_NY / 3)
    ratio = one.C_samples[band] / psd_true(one.q_samples[band])
    assert np.all((ratio > 0.7) & (ratio < 1.4))
    with pytest.raises(TypeError):
        psd_from_surface_topography(q, C)                          # dim is keyword-required
    with pytest.raises(ValueError, match="dim"):
        psd_from_surface_topography(q, C, dim=3)


# ------------------------------------------------------------------ windowing
def test_known_psd_recovered_from_nonperiodic_crops():
    """Crops (256², non-periodic) of large periodic synthetic maps (1024², exact input C with
    roll-off at 8 lattice cells of the crop): with the default Hann window the spectrum is
    unbiased — mean over 16 crops within 10 % of the input C for q ≥ 8·2π/L (measured ≤ 4 %),
    one crop within 35 % for q ≥ 30·2π/L — and h_rms equals the crop's rms to 0.1 %.
    Without a window the same crops are off by ≥ ×1.3 somewhere in that band (leakage)."""
    a, n, m = 1e-6, 1024, 256
    q_lo_big, q_lo = 2 * math.pi / (n * a), 2 * math.pi / (m * a)
    true = SelfAffinePSD(1e-6, 0.8, q_lo_big * 1.0001, math.pi / a, q_roll=32 * q_lo_big)
    logs, raw_worst = [], 0.0
    for seed in range(4):
        big = synthetic_heights(true, n, a, seed=seed)
        for i, j in ((0, 0), (300, 500), (600, 100), (700, 700)):
            crop = big[i:i + m, j:j + m]
            psd = psd_from_heights(crop, a)
            assert psd.window == "hann"
            assert psd.h_rms == pytest.approx(np.std(crop), rel=1e-3)
            q = psd.q_samples
            r = psd.C_samples / true(q)
            far = q >= 30 * q_lo
            assert np.all(np.abs(np.log(r[far])) < math.log(1.35))
            logs.append(np.log(r))
            raw = psd_from_heights(crop, a, window=None)
            raw_worst = max(raw_worst, float(np.max(np.abs(np.log(raw.C_samples[q >= 8 * q_lo]
                                                                 / true(q[q >= 8 * q_lo]))))))
    mean = np.exp(np.mean(logs, axis=0))
    band = q >= 8 * q_lo
    np.testing.assert_allclose(mean[band], 1.0, atol=0.10)
    assert raw_worst > math.log(1.3)


# ------------------------------------------------------------------ measured files
def test_read_topography_file_to_psd(tmp_path, surface):
    """A measured file (NetCDF written by SurfaceTopography, heights in µm, non-periodic)
    -> SurfaceTopography container -> Persson PSD in SI with h_rms of the heights."""
    _, h = surface
    path = tmp_path / "scan.nc"
    Topography(h[:128, :128] * 1e6, (64.0, 64.0), unit="um", periodic=False).to_netcdf(path)
    psd = psd_from_heights(read_topography(path))
    assert psd.window == "hann"
    assert psd.h_rms == pytest.approx(np.std(h[:128, :128]), rel=1e-3)
    assert psd.q1 == pytest.approx(math.pi / 0.5e-6, rel=1e-9)
    with pytest.raises(ValueError, match="no such file"):
        read_topography(tmp_path / "missing.nc")


def test_missing_extra_is_one_line():
    code = ("import sys; sys.modules['SurfaceTopography'] = None\n"
            "from fastcontact.surface.io import read_topography\n"
            "try:\n    read_topography('x.nc')\nexcept ImportError as e:\n    print(e)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.stdout.strip() == ('reading topography files needs SurfaceTopography: '
                                  'pip install "fastcontact[topography]"'), out.stderr


def test_table_header_units_converted_and_1d_refused(tmp_path):
    q = np.geomspace(1e-2, 1e2, 6)                       # [1/µm]
    C = 1e3 * (q / 1e-2) ** -3.6                          # [µm^4]
    path = tmp_path / "t.csv"
    pd.DataFrame({"q (1/um)": q, "C [um^4]": C}).to_csv(path, index=False)
    psd = read_psd(path, "persson", q_col="q (1/um)", C_col="C [um^4]")
    np.testing.assert_allclose(psd.q_samples, q * 1e6, rtol=1e-12)
    np.testing.assert_allclose(psd.C_samples, C * 1e-24, rtol=1e-12)
    one_d = tmp_path / "one.csv"
    pd.DataFrame({"q (1/m)": q, "PSD (m³)": C}).to_csv(one_d, index=False)
    with pytest.raises(ValueError, match=r"^C_col = 'PSD \(m³\)'.*1-D spectrum"):
        read_psd(one_d, "persson", q_col="q (1/m)", C_col="PSD (m³)")
